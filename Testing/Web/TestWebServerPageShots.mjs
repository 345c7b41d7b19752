// SPDX-License-Identifier: BSD-3-Clause
// The page's pictures in Chromium (SwiftShader), on volumes this test writes itself:
// - a mirrored volume drawn the right way: a MetaImage whose TransformMatrix is a mirror
//   (diag(1, -1, 1) in LPS, as the cached ct_head.mha's; determinant -1) and its twin with the
//   same voxels in patient space, its values flipped along j and an identity matrix. A cube on
//   the patient's left (+x, LPS) is drawn right of the centre in the anterior view (the page's
//   convention is the radiological one: facing the patient, the patient's left on the picture's
//   right), on both; the two pictures agree (at most 0.5% of the pixels off by more than 40 in a
//   channel) on the CPU and the GPU path, with the same triangle count; the space line says the
//   grid is drawn reflected, and no longer that left and right are swapped.
// - screenshots against baselines (Testing/Data/Baseline/TestWebServerPageShots-*.png): the
//   anterior view with its orientation marker on the phantom (RAS), a NIfTI in RAS and a DICOM
//   series in LPS (Python/write_dicom_series.py, DCMTK) of the same synthetic head; the page laid
//   out wide (1100x620: the slice views in a column) and narrow (600x760: the panel under the
//   view), its changing readouts hidden, and no blank band in its panel (no gap of PANEL_GAP_PX
//   between what the panel shows, in the shot and as its user sees it); a view set through the
//   URL, reloaded: the image after the reload equals the one before (at most 0.1% of the pixels off by more than 40) and the
//   baseline; the crosshair (moved off the centre) drawn in the 3D view where the camera projects
//   it (within 1 px of the test's own projection) and brought back by the URL (xh=).
// - two fingers (Chromium's touch events through CDP, pointers of type "touch"): spread from 100 to
//   200 px they zoom 2x (within 2%) at their midpoint, which pans, and do not turn the view. Each shot against its baseline: at most 0.5% of the pixels off by more than 40 in a
//   channel (the GUI tests' threshold), and the same size.
// MEDISO_REGENERATE_BASELINES=1 writes the baselines instead of comparing (look at each before
// committing it); every shot is also written to MEDISO_SHOTS_DIR (default: the working folder's
// shots/). MEDISO_DOC_SHOTS=FOLDER also writes the documentation's pictures there (docs/images).
import { spawnSync } from "node:child_process";
import { existsSync, mkdirSync, mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import path from "node:path";
import { Checks, ROOT, drawnCentroid, launchBrowser, niftiBytes, openPage, startServer } from "./webserver-harness.mjs";

const checks = new Checks();
const BASELINES = path.join(ROOT, "Testing", "Data", "Baseline");
const OUT = process.env.MEDISO_SHOTS_DIR || path.join(process.cwd(), "shots");
const REGENERATE = process.env.MEDISO_REGENERATE_BASELINES === "1";
const DOCS = process.env.MEDISO_DOC_SHOTS || "";
mkdirSync(OUT, { recursive: true });
const folder = mkdtempSync(path.join(tmpdir(), "mediso-shots-"));

// --- the synthetic head: int16, NX x NY x NZ at 2 mm, in LPS index order (i: +x, the patient's
// left; j: +y, posterior; k: +z, superior). An ellipsoid head (1000), a nose in front (1000), a
// cube inside on the patient's left (2000) and an ear on the right (1000).
const [NX, NY, NZ] = [40, 44, 48];
const S = 2;
function head() {
  const values = new Int16Array(NX * NY * NZ);
  const c = [(NX - 1) / 2, (NY - 1) / 2, (NZ - 1) / 2];
  for (let k = 0; k < NZ; ++k) {
    for (let j = 0; j < NY; ++j) {
      for (let i = 0; i < NX; ++i) {
        const x = (i - c[0]) / 15, y = (j - c[1]) / 17, z = (k - c[2]) / 20;
        let v = x * x + y * y + z * z <= 1 ? 1000 : 0;
        if (j < c[1] - 14 && j > 2 && Math.abs(i - c[0]) <= 2 && k > c[2] - 2 && k < c[2] + 6) {
          v = 1000; // the nose: anterior (low j)
        }
        if (i <= 3 && Math.abs(j - c[1]) <= 3 && Math.abs(k - c[2] - 2) <= 4) {
          v = 1000; // an ear on the patient's right (low i)
        }
        if (i >= 24 && i <= 30 && j >= 16 && j <= 22 && k >= 28 && k <= 34) {
          v = 2000; // the cube: left, superior
        }
        values[i + NX * (j + NY * k)] = v;
      }
    }
  }
  return values;
}
const HEAD = head();

function writeMetaImage(file, values, matrix, offset) {
  writeFileSync(file, Buffer.concat([Buffer.from(["ObjectType = Image", "NDims = 3",
    "BinaryData = True", "BinaryDataByteOrderMSB = False", "CompressedData = False",
    "TransformMatrix = " + matrix.join(" "), "Offset = " + offset.join(" "), "ElementSpacing = 2 2 2",
    "DimSize = " + [NX, NY, NZ].join(" "), "ElementType = MET_SHORT", "ElementDataFile = LOCAL", ""].join("\n")),
    Buffer.from(values.buffer, values.byteOffset, values.byteLength)]));
}

// The same head in RAS index order for NIfTI: i towards the patient's right... as a scanner in
// RAS stores it, i: +x (right), j: +y (anterior), k: +z (superior); the sform an identity at 2 mm.
function writeNIfTI(file) {
  // RAS (i', j', k) = LPS (NX-1-i', NY-1-j', k): left-right and anterior-posterior reversed.
  const data = new Int16Array(NX * NY * NZ);
  for (let k = 0; k < NZ; ++k) {
    for (let j = 0; j < NY; ++j) {
      for (let i = 0; i < NX; ++i) {
        data[i + NX * (j + NY * k)] = HEAD[(NX - 1 - i) + NX * ((NY - 1 - j) + NY * k)];
      }
    }
  }
  writeFileSync(file, niftiBytes([NX, NY, NZ], [S, S, S], [[S, 0, 0, 0], [0, S, 0, 0], [0, 0, S, 0]], data));
}

// The mirrored MetaImage: its voxels flipped along j in memory (j anterior now), with a
// TransformMatrix diag(1, -1, 1) that puts them back where the head is; the twin: the head as
// it is, an identity matrix, its Offset where the mirrored grid's j = NY - 1 lies.
const mirroredFile = path.join(folder, "mirrored.mha");
const twinFile = path.join(folder, "twin.mha");
{
  const flipped = new Int16Array(NX * NY * NZ);
  for (let k = 0; k < NZ; ++k) {
    for (let j = 0; j < NY; ++j) {
      for (let i = 0; i < NX; ++i) {
        flipped[i + NX * (j + NY * k)] = HEAD[i + NX * ((NY - 1 - j) + NY * k)];
      }
    }
  }
  writeMetaImage(mirroredFile, flipped, [1, 0, 0, 0, -1, 0, 0, 0, 1], [0, 0, 0]);
  writeMetaImage(twinFile, HEAD, [1, 0, 0, 0, 1, 0, 0, 0, 1], [0, -S * (NY - 1), 0]);
}
const niftiFile = path.join(folder, "head.nii");
writeNIfTI(niftiFile);
// The DICOM series (LPS): the head as a MetaImage, then DCMTK's slices.
const dicomFolder = path.join(folder, "head-dicom");
{
  const mha = path.join(folder, "head.mha");
  writeMetaImage(mha, HEAD, [1, 0, 0, 0, 1, 0, 0, 0, 1], [0, 0, 0]);
  const written = spawnSync("python3", [path.join(ROOT, "Python", "write_dicom_series.py"), "--mha", mha,
    "--out", dicomFolder], { encoding: "utf8" });
  checks.check(written.status === 0, "the DICOM series written by write_dicom_series.py (exit " + written.status +
    ")" + (written.status ? ": " + written.stderr.trim() : ""));
}

// --- pictures ---------------------------------------------------------------------------------------
const settle = (page) => page.evaluate(async () => {
  await window.mediso.drawn();
  // the slice views and the histogram redraw in their own tasks after a frame
  await new Promise((r) => setTimeout(r, 300));
  await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
});
// What changes from run to run (frames per second, timings, bytes) is hidden, not masked: the
// layout stays as it is. The notes under the path's controls (#why: the path and the WebGL2
// renderer; #renderer: the worker) are the same at every run in this browser and stay shown:
// hidden, they left a blank band in the wide layout's panel where its user reads them.
const HIDE = "#overlay, #readout { visibility: hidden !important; }";

// The largest vertical gap between what the panel shows (text, controls, canvases) within the
// window, in CSS px, and what comes below it: a box that keeps its height with nothing shown in it
// (a note hidden, an empty row) is a blank band in the panel. Line spacing and the margins above
// a heading leave less than PANEL_GAP_PX.
const PANEL_GAP_PX = 40;
const panelGap = (page) => page.evaluate(() => {
  const panel = document.getElementById("panel");
  const box = panel.getBoundingClientRect();
  const top = Math.max(box.top, 0), bottom = Math.min(box.bottom, innerHeight);
  const shown = (e) => getComputedStyle(e).visibility === "visible";
  const spans = [];
  const add = (r, e) => {
    const a = Math.max(r.top, top), b = Math.min(r.bottom, bottom);
    if (r.width > 0 && b > a) {
      spans.push([a, b, e]);
    }
  };
  const walker = document.createTreeWalker(panel, NodeFilter.SHOW_ELEMENT | NodeFilter.SHOW_TEXT);
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    if (n.nodeType === Node.TEXT_NODE) {
      if (n.textContent.trim() && shown(n.parentElement)) {
        const range = document.createRange();
        range.selectNodeContents(n);
        for (const r of range.getClientRects()) {
          add(r, n.parentElement);
        }
      }
    } else if (n.matches("input, select, button, canvas, progress, textarea") && shown(n)) {
      add(n.getBoundingClientRect(), n);
    }
  }
  spans.sort((x, y) => x[0] - y[0]);
  let reach = spans.length ? spans[0][1] : top;
  let gap = { px: 0, at: 0, above: "" };
  for (const [a, b, e] of spans) {
    if (a - reach > gap.px) {
      gap = { px: a - reach, at: reach, above: e.id || e.textContent.trim().slice(0, 30) || e.tagName };
    }
    reach = Math.max(reach, b);
  }
  return gap;
});

async function stageShot(page) {
  await page.addStyleTag({ content: HIDE });
  await settle(page);
  return page.locator("#stage").screenshot({ animations: "disabled" });
}

let comparer = null;
/** Pixels of two PNGs compared in the browser: size, and how many differ by more than 40. */
async function compare(a, b) {
  return comparer.evaluate(async ([a64, b64]) => {
    const load = async (b64) => {
      const bitmap = await createImageBitmap(await (await fetch("data:image/png;base64," + b64)).blob());
      const c = new OffscreenCanvas(bitmap.width, bitmap.height);
      const g = c.getContext("2d");
      g.drawImage(bitmap, 0, 0);
      return { w: bitmap.width, h: bitmap.height, d: g.getImageData(0, 0, bitmap.width, bitmap.height).data };
    };
    const [x, y] = [await load(a64), await load(b64)];
    if (x.w !== y.w || x.h !== y.h) {
      return { sameSize: false, size: [x.w, x.h, y.w, y.h], ratio: 1 };
    }
    let differing = 0;
    for (let p = 0; p < x.d.length; p += 4) {
      const largest = Math.max(Math.abs(x.d[p] - y.d[p]), Math.abs(x.d[p + 1] - y.d[p + 1]),
        Math.abs(x.d[p + 2] - y.d[p + 2]));
      differing += largest > 40;
    }
    return { sameSize: true, size: [x.w, x.h], differing, ratio: differing / (x.w * x.h) };
  }, [a.toString("base64"), b.toString("base64")]);
}

const BASELINE_RATIO = 0.005;
async function againstBaseline(name, png) {
  const file = "TestWebServerPageShots-" + name + ".png";
  writeFileSync(path.join(OUT, file), png);
  const baseline = path.join(BASELINES, file);
  if (REGENERATE) {
    writeFileSync(baseline, png);
    console.log("baseline written: " + baseline + " (" + png.length + " bytes): look at it before committing it");
    return;
  }
  if (!existsSync(baseline)) {
    checks.check(false, name + ": no baseline " + baseline + " (the shot is " + path.join(OUT, file) +
      "; MEDISO_REGENERATE_BASELINES=1 writes it)");
    return;
  }
  const r = await compare(readFileSync(baseline), png);
  checks.check(r.sameSize && r.ratio <= BASELINE_RATIO, name + " against its baseline: " + (r.sameSize
    ? r.differing + " pixels of " + r.size.join("x") + " off by more than 40 (" + (100 * r.ratio).toFixed(3) +
      "%, at most " + 100 * BASELINE_RATIO + "%)"
    : "sizes differ " + JSON.stringify(r.size)) + "; the shot: " + path.join(OUT, file));
}

const browser = await launchBrowser();
comparer = await browser.newPage();
const servers = [];
async function serve(data) {
  const server = await startServer([data]);
  servers.push(server);
  return server;
}
const SURFACES = [{ value: 500, color: [0.93, 0.75, 0.62], opacity: 0.35 }, { value: 1500, color: [0.95, 0.3, 0.25], opacity: 1 }];

// --- a mirrored volume, drawn unmirrored ----------------------------------------------------------
{
  const mirrorServer = await serve(mirroredFile);
  const twinServer = await serve(twinFile);
  const pictures = {};
  for (const [name, server] of [["mirrored", mirrorServer], ["twin", twinServer]]) {
    const context = await browser.newContext({ viewport: { width: 900, height: 600 } });
    const page = await context.newPage();
    await openPage(page, server);
    const space = (await page.evaluate(() => window.mediso.orientation())).space;
    if (name === "mirrored") {
      checks.check(/mirror image/.test(space) && /drawn reflected/.test(space) && !/swapped/.test(space),
        "the mirrored MetaImage's space line: " + space);
    }
    const view = await page.evaluate(() => window.mediso.getView());
    checks.check(Math.abs(view.world.direction[1] - 1) < 1e-6 && Math.abs(view.world.viewUp[2] - 1) < 1e-6,
      name + ": opens in the anterior view (looking " + view.world.direction.map((x) => x.toFixed(3)) + ")");
    pictures[name] = {};
    await page.addStyleTag({ content: HIDE });
    for (const pathName of ["cpu", "gpu"]) {
      // The cube alone (where the patient's left is in the picture), set before the path.
      await page.evaluate(() => window.mediso.setSurfaces([{ value: 1500, color: [1, 1, 1], opacity: 1 }]));
      await page.evaluate((p) => window.mediso.setPath(p), pathName);
      await settle(page);
      const cube = await drawnCentroid(page);
      checks.check(cube.n > 100 && cube.x > 20 && cube.y > 10, name + ", " + pathName +
        " path: the cube on the patient's left (and superior) is drawn right of the centre (and up) in the anterior view: " +
        JSON.stringify(cube));
      await page.evaluate((s) => window.mediso.setSurfaces(s), SURFACES);
      await settle(page);
      const stats = await page.evaluate(() => window.mediso.stats());
      pictures[name][pathName] = { png: await page.locator("#view").screenshot(), stats };
    }
    await context.close();
  }
  for (const pathName of ["cpu", "gpu"]) {
    const a = pictures.mirrored[pathName], b = pictures.twin[pathName];
    writeFileSync(path.join(OUT, "mirrored-" + pathName + ".png"), a.png);
    writeFileSync(path.join(OUT, "twin-" + pathName + ".png"), b.png);
    const r = await compare(a.png, b.png);
    checks.check(r.sameSize && r.ratio <= 0.005, pathName + " path: the mirrored volume's picture equals its twin's " +
      "(values flipped, identity matrix): " + r.differing + " pixels of " + r.size.join("x") +
      " off by more than 40 (" + (100 * r.ratio).toFixed(3) + "%, at most 0.5%)");
    const count = pathName === "cpu" ? "triangles" : "primitives";
    checks.check(a.stats[count] > 0 && a.stats[count] === b.stats[count], pathName + " path: the same " + count +
      " (" + a.stats[count] + ", " + b.stats[count] + ")");
  }
  await mirrorServer.stop();
  await twinServer.stop();
}

// --- the anterior view with its labels: the phantom, the NIfTI (RAS), the DICOM series (LPS) -----
const phantomServer = await serve("phantom:48");
for (const [name, data] of [["phantom", null], ["nifti", niftiFile], ["dicom", dicomFolder]]) {
  if (name === "dicom" && !existsSync(path.join(dicomFolder, "slice_000.dcm"))) {
    continue; // said above
  }
  const server = data ? await serve(data) : phantomServer;
  const context = await browser.newContext({ viewport: { width: 900, height: 600 } });
  const page = await context.newPage();
  await openPage(page, server);
  const marker = await page.evaluate(() => window.mediso.orientation());
  const l = marker.labels;
  checks.check(l.S.y > 0.99 && l.L.x > 0.99 && l.A.toward > 0.99, name + ": the marker in the anterior view: S up, " +
    "L right, A towards the viewer (" + marker.space + ")");
  if (name !== "phantom") {
    await page.evaluate(() => window.mediso.setSurfaces([{ value: 1500, color: [1, 1, 1], opacity: 1 }]));
    await settle(page);
    const cube = await drawnCentroid(page);
    checks.check(cube.n > 100 && cube.x > 20, name + ": the cube on the patient's left is drawn right of the centre: " +
      JSON.stringify(cube));
    await page.evaluate((s) => window.mediso.setSurfaces(s), SURFACES);
  }
  await againstBaseline("anterior-" + name, await stageShot(page));
  await context.close();
  if (data) {
    await server.stop();
  }
}

// --- the layouts: wide and narrow ----------------------------------------------------------------
for (const [name, width, height] of [["wide", 1100, 620], ["narrow", 600, 760]]) {
  const context = await browser.newContext({ viewport: { width, height } });
  const page = await context.newPage();
  await openPage(page, phantomServer);
  const hidden = await page.addStyleTag({ content: HIDE });
  await settle(page);
  await againstBaseline("layout-" + name, await page.screenshot({ animations: "disabled" }));
  for (const [what, shown] of [["as in its shot", true], ["as its user sees it", false]]) {
    if (!shown) {
      await hidden.evaluate((e) => e.remove());
    }
    const gap = await panelGap(page);
    checks.check(gap.px < PANEL_GAP_PX, name + " layout, " + what + ": no blank band in the panel (largest " +
      "gap " + gap.px.toFixed(0) + " px, at y " + gap.at.toFixed(0) + " above " + JSON.stringify(gap.above) +
      "; less than " + PANEL_GAP_PX + ")");
  }
  if (DOCS) { // the page as its user sees it, readouts and all; the wide one 1024x576 (a smaller file)
    if (name === "wide") {
      await page.setViewportSize({ width: 1024, height: 576 });
      await page.waitForFunction(() => Math.abs(document.getElementById("view").width -
        document.getElementById("view").clientWidth * devicePixelRatio) <= 1, null, { timeout: 10000 }).catch(() => {});
      await settle(page);
    }
    mkdirSync(DOCS, { recursive: true });
    writeFileSync(path.join(DOCS, "web-" + name + ".png"), await page.screenshot({ animations: "disabled" }));
  }
  await context.close();
}

// --- the URL round trip: a view set, the page reloaded, the same picture ----------------------------
{
  const context = await browser.newContext({ viewport: { width: 900, height: 600 } });
  const page = await context.newPage();
  await openPage(page, phantomServer);
  await page.evaluate(() => window.mediso.setSurfaces([{ value: -500, color: [0.93, 0.75, 0.62], opacity: 0.35 },
    { value: 400, color: [0.2, 0.6, 1], opacity: 1 }]));
  await page.evaluate(() => window.mediso.setNamedView("left"));
  await page.evaluate(() => {
    const v = window.mediso.getView();
    const w = v.world;
    // 30 degrees towards the front, about the focal point, in patient space
    const d = w.position.map((x, i) => x - w.focalPoint[i]);
    const c = Math.cos(Math.PI / 6), s = Math.sin(Math.PI / 6);
    const turned = [c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]];
    return window.mediso.setView({ world: { position: turned.map((x, i) => x + w.focalPoint[i]),
      focalPoint: w.focalPoint, viewUp: w.viewUp } });
  });
  // the crosshair moved off the centre, to the patient's left and up
  const crosshair = await page.evaluate(() => {
    const c = window.mediso.getCrosshair().point;
    window.mediso.setCrosshair([c[0] + 10, c[1], c[2] + 15]);
    return window.mediso.getCrosshair().point;
  });
  await page.waitForFunction(() => location.hash.includes("iso=-500") && location.hash.includes("xh="), null,
    { timeout: 10000 });
  await page.waitForTimeout(400); // the fragment's last write
  const cross = () => page.evaluate(() => {
    // where the test projects the crosshair with the camera, and where the page drew its cross
    const w = window.mediso.getView().world, v = window.mediso.getView();
    const p = window.mediso.getCrosshair().point;
    const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const f = w.direction, up = w.viewUp;
    const right = [f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]];
    const d = p.map((x, i) => x - w.position[i]);
    const depth = dot(d, f), tan = Math.tan(v.viewAngle * Math.PI / 360);
    const view = document.getElementById("view");
    const W = view.clientWidth, H = view.clientHeight;
    const expected = [W / 2 * (1 + dot(d, right) / (depth * tan * W / H)), H / 2 * (1 - dot(d, up) / (depth * tan))];
    const overlay = document.getElementById("crosshair3d");
    const at = (overlay.dataset.at || "").split(",").map(Number);
    const g = overlay.getContext("2d");
    const r = devicePixelRatio;
    const arm = g.getImageData(Math.round((at[0] + 6) * r), Math.round(at[1] * r), 1, 1).data[3];
    const centre = g.getImageData(Math.round(at[0] * r), Math.round(at[1] * r), 1, 1).data[3];
    return { expected, at, arm, centre, hash: location.hash };
  });
  const shown = await cross();
  checks.check(shown.at.length === 2 && Math.hypot(shown.at[0] - shown.expected[0], shown.at[1] - shown.expected[1]) < 1 &&
    shown.arm > 0 && shown.centre === 0, "the crosshair drawn in the 3D view where the camera projects it: at " +
    shown.at + ", the test's projection " + shown.expected.map((x) => x.toFixed(1)) + " (an arm drawn, the centre left open)");
  checks.check(/xh=[-0-9.e]+,[-0-9.e]+,[-0-9.e]+/.test(shown.hash), "the crosshair in the URL: " + shown.hash);
  const before = await stageShot(page);
  await page.reload({ waitUntil: "commit" });
  await page.waitForFunction(() => window.mediso !== undefined, null, { timeout: 120000 });
  await page.evaluate(() => window.mediso.ready);
  const after = await stageShot(page);
  const back = await page.evaluate(() => window.mediso.getCrosshair().point);
  checks.check(back.every((x, i) => Math.abs(x - crosshair[i]) < 1e-4), "the crosshair comes back from the URL: " +
    JSON.stringify(back) + " (set " + JSON.stringify(crosshair) + ")");
  const r = await compare(before, after);
  checks.check(r.sameSize && r.ratio <= 0.001, "the URL round trip: the picture after the reload equals the one before: " +
    r.differing + " pixels of " + r.size.join("x") + " off by more than 40 (at most 0.1%)");
  await againstBaseline("url-reloaded", after);
  await context.close();
}

// --- two fingers on a touch screen: pan and zoom at once, no turn ---------------------------------
{
  const context = await browser.newContext({ viewport: { width: 900, height: 600 }, hasTouch: true });
  const page = await context.newPage();
  await openPage(page, phantomServer);
  const box = await page.locator("#view").boundingBox();
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  const cdp = await context.newCDPSession(page);
  const touch = (type, points) => cdp.send("Input.dispatchTouchEvent", { type,
    touchPoints: points.map(([x, y], id) => ({ x, y, id, radiusX: 1, radiusY: 1, force: 1 })) });
  const before = await page.evaluate(() => window.mediso.getView());
  await touch("touchStart", [[cx - 50, cy], [cx + 50, cy]]);
  for (let s = 1; s <= 5; ++s) { // the spread from 100 to 200 px, the midpoint 30 px right and 20 down
    const spread = 50 + (50 * s) / 5, mx = cx + (30 * s) / 5, my = cy + (20 * s) / 5;
    await touch("touchMove", [[mx - spread, my], [mx + spread, my]]);
  }
  await touch("touchEnd", []);
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const after = await page.evaluate(() => window.mediso.getView());
  const len = (a) => Math.hypot(...a);
  const sub = (a, b) => a.map((x, i) => x - b[i]);
  const d0 = len(sub(before.world.position, before.world.focalPoint));
  const d1 = len(sub(after.world.position, after.world.focalPoint));
  const dot = after.world.direction.reduce((t, x, i) => t + x * before.world.direction[i], 0);
  const turn = Math.acos(Math.min(1, dot)) * 180 / Math.PI;
  const moved = len(sub(after.world.focalPoint, before.world.focalPoint));
  checks.check(Math.abs(d0 / d1 - 2) < 0.02 && turn < 1e-3 && moved > 0,
    "two fingers spread from 100 to 200 px zoom 2x (" + (d0 / d1).toFixed(3) + "x), pan (the focal point moved " +
    moved.toFixed(2) + " mm) and do not turn (" + turn.toExponential(2) + " degrees)");
  await context.close();
}

await checks.finish(browser, ...servers);
