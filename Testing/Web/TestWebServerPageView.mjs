// SPDX-License-Identifier: BSD-3-Clause
// The page as a viewer, in Chromium, served by Python/serve.py:
// - orientation: a NIfTI the test writes (32^3, 2 mm, its sform turned 90 degrees about z, one
//   bright cube in the patient's superior-left-anterior corner) opens in the anterior view: the
//   camera looks posterior in patient space (getView().world, LPS) and, in the module's frame,
//   along -i (the file's i axis points anterior); the marker puts S up and L right (components
//   above 0.99); and in the picture the cube is drawn up and right of the centre (anterior view)
//   and left of it (left view: anterior is on the left). The phantom (RAS, nose at +y) opens the
//   same way. A MetaImage with a mirroring TransformMatrix (diag(1, -1, 1), as the cached
//   ct_head.mha's) opens in the anterior view by the matrix the server states, and the page says
//   that its grid is a mirror image drawn reflected (TestWebServerPageShots checks the picture).
// - navigation: a right-drag and a shift-drag of 120 px move the focal point by 120 px of the
//   focal plane (within 5%) across the view, and turn it by less than 0.001 degree; a left-drag
//   does turn it (more than 10 degrees); a wheel step 100 px off the centre dollies 1.1x nearer
//   and moves the focal point 1 - 1/1.1 of the way to the point under the cursor (within 2%); `r`
//   gives the anterior view and the first focal point back.
// - the canvas fills the window at the device pixel ratio: at 1920x1080 (ratio 1) and 800x600
//   (ratio 2) its backing store is its CSS size times the ratio (within 1 pixel), the view keeps
//   at least 400x400 CSS pixels at 800x600 (the slice views under it), the window resized follows
//   (a narrow window puts the panel below the view), and hiding the panel gives the view and the
//   slice views (beside it on a wide window) the window's width, and the view more room.
// - the URL: surfaces and a camera set, the page reloaded: getSurfaces() and getView().world the
//   same (values within 1e-6 relative, colours within 1/255, camera within 1e-4 of its distance),
//   history not grown by the changes; a fragment with bad values opens with a note, the good
//   values applied and the bad ones left out.
// - a bad isovalue (outside the range, or empty) is refused with a message beside its box and
//   the surface keeps its value; a good one clears the message and is drawn.
// - the GPU path after the CPU path: the skin (translucent) over the bone on the CPU path, then
//   the GPU path and the bone alone, equals the bone on a page that never left the GPU path.
import { mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import path from "node:path";
import { Checks, drawnCentroid, launchBrowser, niftiBytes, openPage, startServer } from "./webserver-harness.mjs";

const checks = new Checks();
const near = (a, b, tol) => a.every((x, i) => Math.abs(x - b[i]) <= tol);
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const sub = (a, b) => a.map((x, i) => x - b[i]);
const len = (a) => Math.hypot(...a);
const fmt = (a) => "(" + a.map((x) => x.toFixed(4)).join(", ") + ")";

// --- the NIfTI: NIfTI-1, int16, sform_code 1 ----------------------------------------------------
// sform: x = -2 j, y = 2 i, z = 2 k (RAS mm): i anterior, j towards the patient's right... of
// RAS x negative, that is left; k superior. The cube at high i, j, k: anterior, left, superior.
const N = 32;
function writeNIfTI(file) {
  const data = Buffer.alloc(2 * N * N * N);
  for (let k = 0; k < N; ++k) {
    for (let j = 0; j < N; ++j) {
      for (let i = 0; i < N; ++i) {
        const inCube = i >= 22 && i <= 28 && j >= 22 && j <= 28 && k >= 22 && k <= 28;
        data.writeInt16LE(inCube ? 1000 : 0, 2 * (i + N * (j + N * k)));
      }
    }
  }
  writeFileSync(file, niftiBytes([N, N, N], [2, 2, 2], [[0, -2, 0, 0], [2, 0, 0, 0], [0, 0, 2, 0]], data));
}
const folder = mkdtempSync(path.join(tmpdir(), "mediso-view-"));
const nifti = path.join(folder, "turned.nii");
writeNIfTI(nifti);

const server = await startServer([nifti]);
const browser = await launchBrowser();

// --- orientation on the turned NIfTI ------------------------------------------------------------
{
  const context = await browser.newContext({ viewport: { width: 1200, height: 800 } });
  const page = await context.newPage();
  await openPage(page, server); // the first dataset: the NIfTI
  const view = await page.evaluate(() => window.mediso.getView());
  const marker = await page.evaluate(() => window.mediso.orientation());
  const space = marker.space;
  checks.check(/LPS/.test(space) && /NIfTI/.test(space), "the page says the space: " + space);
  checks.check(!/guessed/.test(space), "... from the format the server states, not the name");
  checks.check(near(view.world.direction, [0, 1, 0], 1e-6) && near(view.world.viewUp, [0, 0, 1], 1e-6),
    "anterior view in patient space: looking " + fmt(view.world.direction) + " (posterior: 0, 1, 0), up " +
    fmt(view.world.viewUp) + " (superior: 0, 0, 1)");
  const forward = sub(view.focalPoint, view.position).map((x) => x / len(sub(view.focalPoint, view.position)));
  checks.check(near(forward, [-1, 0, 0], 1e-6) && near(view.viewUp, [0, 0, 1], 1e-6),
    "in the module's frame the camera looks along -i " + fmt(forward) + " (the file's i axis is anterior)");
  const l = marker.labels;
  checks.check(l.S.y > 0.99 && l.L.x > 0.99 && l.A.toward > 0.99 && l.I.y < -0.99 && l.R.x < -0.99,
    "the marker: S up (" + l.S.y.toFixed(3) + "), L right (" + l.L.x.toFixed(3) + "), A towards the viewer (" +
    l.A.toward.toFixed(3) + ")");
  await page.evaluate(() => window.mediso.setSurfaces([{ value: 500, color: [1, 1, 1], opacity: 1 }]));
  const front = await drawnCentroid(page);
  checks.check(front.n > 200 && front.x > 20 && front.y > 20,
    "anterior view: the superior-left cube is drawn up and right of the centre: " + JSON.stringify(front));
  await page.evaluate(() => window.mediso.setNamedView("left"));
  const side = await drawnCentroid(page);
  checks.check(side.n > 200 && side.x < -20 && side.y > 20,
    "left view: the anterior-superior cube is drawn up and left of the centre: " + JSON.stringify(side));
  await context.close();
}

// --- a MetaImage whose TransformMatrix is a mirror (as the cached ct_head.mha's) -----------------
// The server states the header's matrix; the page places the volume by it, draws the grid
// reflected along i so that the picture is not a mirror image, and says so.
const mirrored = path.join(folder, "mirrored.mha");
let mirrorServer;
{
  const values = readFileSync(nifti).subarray(352);
  writeFileSync(mirrored, Buffer.concat([Buffer.from(["ObjectType = Image", "NDims = 3",
    "BinaryData = True", "BinaryDataByteOrderMSB = False", "CompressedData = False",
    "TransformMatrix = 1 0 0 0 -1 0 0 0 1", "Offset = 0 0 0", "ElementSpacing = 2 2 2",
    "DimSize = " + [N, N, N].join(" "), "ElementType = MET_SHORT", "ElementDataFile = LOCAL", ""].join("\n")),
    values]));
  mirrorServer = await startServer([mirrored]);
  const context = await browser.newContext({ viewport: { width: 1200, height: 800 } });
  const page = await context.newPage();
  await openPage(page, mirrorServer);
  const space = (await page.evaluate(() => window.mediso.orientation())).space;
  const view = await page.evaluate(() => window.mediso.getView());
  const forward = sub(view.focalPoint, view.position).map((x) => x / len(sub(view.focalPoint, view.position)));
  checks.check(/MetaImage \(LPS\)/.test(space) && /mirror image/.test(space) && /drawn reflected/.test(space),
    "a mirrored MetaImage: " + space);
  checks.check(near(view.world.direction, [0, 1, 0], 1e-6) && near(forward, [0, -1, 0], 1e-6),
    "... opens in the anterior view, in the module's frame looking along -j " + fmt(forward) +
    " (the header puts +j anterior)");
  await context.close();
}

// --- the phantom: navigation, resize, URL, values -------------------------------------------------
async function openPhantom(context, hash = "") {
  const page = await context.newPage();
  // The page shows /api/datasets' first: the phantom is served alone by a second server.
  await openPage(page, { url: phantomServer.url + hash });
  return page;
}
const phantomServer = await startServer(["phantom:48"]);
{
  const context = await browser.newContext({ viewport: { width: 1200, height: 800 } });
  const page = await openPhantom(context);
  const first = await page.evaluate(() => window.mediso.getView());
  checks.check(near(first.world.direction, [0, 1, 0], 1e-6) && near(first.world.viewUp, [0, 0, 1], 1e-6),
    "the phantom (RAS) opens in the anterior view too: looking " + fmt(first.world.direction));

  const box = await page.locator("#view").boundingBox();
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  const perPixel = 2 * len(sub(first.position, first.focalPoint)) * Math.tan(first.viewAngle * Math.PI / 360) /
    box.height;
  async function drag(dx, options) {
    if (options.shift) {
      await page.keyboard.down("Shift");
    }
    await page.mouse.move(cx, cy);
    await page.mouse.down({ button: options.button });
    for (let s = 1; s <= 4; ++s) {
      await page.mouse.move(cx + (dx * s) / 4, cy);
    }
    await page.mouse.up({ button: options.button });
    if (options.shift) {
      await page.keyboard.up("Shift");
    }
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    return page.evaluate(() => window.mediso.getView());
  }
  let before = first;
  for (const [what, options] of [["right-drag", { button: "right" }], ["shift-drag", { button: "left", shift: true }]]) {
    const after = await drag(120, options);
    const turn = Math.acos(Math.min(1, dot(after.world.direction, before.world.direction))) * 180 / Math.PI;
    const moved = sub(after.world.focalPoint, before.world.focalPoint);
    checks.check(turn < 1e-3 && near(after.world.viewUp, before.world.viewUp, 1e-6) &&
      Math.abs(len(moved) / (120 * perPixel) - 1) < 0.05 && Math.abs(dot(moved, after.world.direction)) < 1e-6 * len(moved),
      what + " pans: turned " + turn.toExponential(2) + " degrees, the focal point moved " + len(moved).toFixed(2) +
      " mm across the view (120 px = " + (120 * perPixel).toFixed(2) + " mm)");
    before = after;
  }
  const turned = await drag(120, { button: "left" });
  const turn = Math.acos(Math.min(1, dot(turned.world.direction, before.world.direction))) * 180 / Math.PI;
  checks.check(turn > 10, "a left-drag turns the view (" + turn.toFixed(1) + " degrees)");
  // The wheel at a point off the centre: nearer, and the focal point moved towards that point
  // (the point under the cursor stays: the focal point moves by (1 - 1/f) of its offset).
  const beforeWheel = await page.evaluate(() => window.mediso.getView());
  await page.mouse.move(cx + 100, cy);
  await page.mouse.wheel(0, -100);
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const wheeled = await page.evaluate(() => window.mediso.getView());
  const d0 = len(sub(beforeWheel.position, beforeWheel.focalPoint)), d1 = len(sub(wheeled.position, wheeled.focalPoint));
  const shift = len(sub(wheeled.focalPoint, beforeWheel.focalPoint));
  const perPixelNow = 2 * d0 * Math.tan(beforeWheel.viewAngle * Math.PI / 360) / box.height;
  const expected = 100 * perPixelNow * (1 - 1 / 1.1);
  const w = beforeWheel.world, right = [
    w.direction[1] * w.viewUp[2] - w.direction[2] * w.viewUp[1],
    w.direction[2] * w.viewUp[0] - w.direction[0] * w.viewUp[2],
    w.direction[0] * w.viewUp[1] - w.direction[1] * w.viewUp[0]];
  const along = dot(sub(wheeled.world.focalPoint, w.focalPoint), right) / (shift || 1);
  checks.check(Math.abs(d0 / d1 - 1.1) < 1e-3 && Math.abs(shift / expected - 1) < 0.02 && along > 0.999,
    "the wheel zooms at the cursor: distance " + d0.toFixed(1) + " -> " + d1.toFixed(1) + " mm, the focal point moved " +
    shift.toFixed(2) + " mm towards it (" + expected.toFixed(2) + " expected)");
  await page.locator("#view").focus();
  await page.keyboard.press("r");
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const reset = await page.evaluate(() => window.mediso.getView());
  checks.check(near(reset.world.direction, [0, 1, 0], 1e-6) && near(reset.world.focalPoint, first.world.focalPoint, 1e-6) &&
    near(reset.world.position, first.world.position, 1e-6), "r resets to the first anterior view");

  // The URL: surfaces and a camera, kept across a reload.
  const historyBefore = await page.evaluate(() => history.length);
  const surfaces = [{ value: 300.5, color: [1, 0, 0], opacity: 0.5 }, { value: -250, color: [0.2, 0.4, 1], opacity: 1 }];
  await page.evaluate((s) => window.mediso.setSurfaces(s), surfaces);
  await page.evaluate(() => window.mediso.setNamedView("left"));
  await drag(60, { button: "right" });
  await drag(40, { button: "left" });
  await page.waitForFunction(() => location.hash.includes("iso=300.5"), null, { timeout: 10000 });
  await page.waitForTimeout(400); // the last change's fragment written
  const set = await page.evaluate(() => ({ s: window.mediso.getSurfaces(), v: window.mediso.getView(), h: history.length }));
  checks.check(set.h === historyBefore, "the changes replaced the history entry (" + set.h + " entries, " + historyBefore + " before)");
  await page.reload({ waitUntil: "commit" });
  await page.waitForFunction(() => window.mediso !== undefined, null, { timeout: 120000 });
  await page.evaluate(() => window.mediso.ready);
  const back = await page.evaluate(() => ({ s: window.mediso.getSurfaces(), v: window.mediso.getView(), hash: location.hash }));
  const distance = len(sub(set.v.world.position, set.v.world.focalPoint));
  checks.check(back.s.length === 2 && back.s.every((s, i) => Math.abs(s.value - set.s[i].value) <= 1e-6 * Math.abs(set.s[i].value) &&
    near(s.color, set.s[i].color, 1 / 255) && s.opacity === set.s[i].opacity),
    "the surfaces come back from the URL: " + JSON.stringify(back.s));
  checks.check(["position", "focalPoint", "viewUp"].every((k) => near(back.v.world[k], set.v.world[k], 1e-4 * distance)),
    "the camera comes back from the URL: " + fmt(back.v.world.position) + " against " + fmt(set.v.world.position));

  // A bad isovalue in the box: refused with a message.
  const message = () => page.locator(".surface .message").first().textContent();
  await page.locator(".surface input.isovalue").first().fill("99999");
  const refused = await page.evaluate(() => window.mediso.getSurfaces()[0].value);
  const said = await message();
  checks.check(refused === 300.5 && /within -1000\.\.\d+/.test(said),
    "an isovalue outside the range is refused with a message: " + JSON.stringify(said));
  await page.locator(".surface input.isovalue").first().fill("");
  checks.check(/empty/i.test(await message()) && (await page.evaluate(() => window.mediso.getSurfaces()[0].value)) === 300.5,
    "an empty isovalue is refused with a message: " + JSON.stringify(await message()));
  await page.locator(".surface input.isovalue").first().fill("350");
  checks.check((await message()) === "" && (await page.evaluate(() => window.mediso.getSurfaces()[0].value)) === 350,
    "a good isovalue clears the message and is drawn");
  const unlabelled = await page.evaluate(() => [...document.querySelectorAll("input, select, button")]
    .filter((e) => !e.closest("label") && !e.getAttribute("aria-label") && !e.textContent.trim() && !e.title)
    .map((e) => e.id || e.className || e.type));
  checks.check(unlabelled.length === 0, "every control has a label: " + JSON.stringify(unlabelled));
  await context.close();
}
{
  // A fragment with bad values: the page opens, says so, and uses the good ones.
  const context = await browser.newContext({ viewport: { width: 1200, height: 800 } });
  const page = await openPhantom(context, "#iso=abc,zz,5;300;-300,00ff00,7&cam=1,2,3&path=fast");
  const got = await page.evaluate(() => ({ s: window.mediso.getSurfaces(), v: window.mediso.getView(),
    note: document.getElementById("link-note").hidden ? "" : document.getElementById("link-note").textContent }));
  checks.check(got.s.map((s) => s.value).join() === "300,-300" && got.s[1].color[1] === 1,
    "the good surfaces of a bad fragment apply: " + JSON.stringify(got.s));
  checks.check(/abc/.test(got.note) && /camera/.test(got.note) && /fast/.test(got.note) && /opacity/.test(got.note),
    "the bad values are said: " + got.note);
  checks.check(near(got.v.world.direction, [0, 1, 0], 1e-6), "a bad camera gives the anterior view");
  await context.close();
}

// --- the GPU path after the CPU path's translucent frame -------------------------------------------
// The phantom's translucent skin over its bone on the CPU path, then the GPU path, then the bone
// alone: the picture must equal the bone alone on a page that never left the GPU path (at most
// 0.5% of the pixels off by more than 40, TestWebServerPageShots' bound). The CPU path's meshes
// of its last frame were drawn over the GPU path's frames (the skin showed over the bone).
{
  const SKIN = { value: -500, color: [0.93, 0.75, 0.62], opacity: 0.35 };
  const BONE = { value: 400, color: [0.3, 0.5, 1], opacity: 1 }; // unlike the skin: seen through it
  const context = await browser.newContext({ viewport: { width: 900, height: 600 } });
  // The view's pixels once the newest frame is drawn and shown (a PNG data URL).
  const picture = (page) => page.evaluate(async () => {
    await window.mediso.drawn();
    await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
    const view = document.getElementById("view");
    const copy = Object.assign(document.createElement("canvas"), { width: view.width, height: view.height });
    copy.getContext("2d").drawImage(view, 0, 0);
    return copy.toDataURL("image/png");
  });
  const page = await openPhantom(context);
  await page.evaluate(() => window.mediso.setPath("cpu"));
  await page.evaluate((s) => window.mediso.setSurfaces(s), [SKIN, BONE]);
  const cpu = await page.evaluate(() => window.mediso.stats());
  await page.evaluate(() => window.mediso.setPath("gpu"));
  await page.evaluate((s) => window.mediso.setSurfaces(s), [BONE]);
  const after = await picture(page);
  const gpu = await page.evaluate(() => window.mediso.stats());
  const fresh = await openPhantom(context, "#path=gpu&iso=400");
  await fresh.evaluate((s) => window.mediso.setSurfaces(s), [BONE]);
  const r = await fresh.evaluate(async ([url, expected]) => {
    const load = async (source) => {
      const image = await createImageBitmap(await (await fetch(source)).blob());
      const c = Object.assign(document.createElement("canvas"), { width: image.width, height: image.height });
      const g = c.getContext("2d");
      g.drawImage(image, 0, 0);
      return g.getImageData(0, 0, image.width, image.height);
    };
    const a = await load(url);
    const b = await load(expected);
    if (a.width !== b.width || a.height !== b.height) {
      return { sameSize: false, differing: -1, ratio: 1, drawn: 0 };
    }
    let differing = 0, drawn = 0;
    for (let p = 0; p < a.data.length; p += 4) {
      const off = (x, y) => Math.max(Math.abs(x[p] - y[0]), Math.abs(x[p + 1] - y[1]), Math.abs(x[p + 2] - y[2]));
      differing += off(a.data, [b.data[p], b.data[p + 1], b.data[p + 2]]) > 40;
      drawn += off(b.data, [b.data[0], b.data[1], b.data[2]]) > 30;
    }
    return { sameSize: true, differing, ratio: differing / (a.width * a.height), drawn };
  }, [after, await picture(fresh)]);
  checks.check(cpu.path === "cpu" && cpu.triangles > 0 && gpu.path === "gpu" && gpu.primitives > 0 && r.drawn > 1000,
    "the skin and bone drawn on the CPU path (" + cpu.triangles + " triangles), then the bone on the GPU path (" +
    gpu.primitives + " primitives; " + r.drawn + " pixels of bone on a fresh GPU page)");
  checks.check(r.sameSize && r.ratio <= 0.005, "the GPU path's opaque frame after the CPU path's translucent one equals " +
    "a fresh GPU page's: " + r.differing + " pixels off by more than 40 (" + (100 * r.ratio).toFixed(3) + "%, at most 0.5%)");
  await context.close();
}

// --- the window ------------------------------------------------------------------------------------
for (const [width, height, ratio] of [[1920, 1080, 1], [800, 600, 2]]) {
  const context = await browser.newContext({ viewport: { width, height }, deviceScaleFactor: ratio });
  const page = await openPhantom(context);
  const size = () => page.evaluate(() => {
    const v = document.getElementById("view");
    const b = v.getBoundingClientRect();
    const slices = document.getElementById("slices").getBoundingClientRect();
    const beside = slices.left >= b.right - 1 ? slices.width : 0; // the slice views right of the view
    return { width: v.width, height: v.height, css: [b.width, b.height], dpr: devicePixelRatio, beside };
  });
  const fits = (s) => Math.abs(s.width - s.css[0] * s.dpr) <= 1 && Math.abs(s.height - s.css[1] * s.dpr) <= 1;
  // After a resize: the backing store given up to 10 s to follow (a frame on a loaded machine
  // can take longer than the 300 ms this waited before; with the viewer in a worker the size
  // follows with the worker's next frame), then checked.
  const settled = () => page.waitForFunction(() => {
    const v = document.getElementById("view");
    const b = v.getBoundingClientRect();
    return Math.abs(v.width - b.width * devicePixelRatio) <= 1 && Math.abs(v.height - b.height * devicePixelRatio) <= 1;
  }, null, { timeout: 10000 }).catch(() => {});
  const s = await size();
  checks.check(fits(s) && s.dpr === ratio, width + "x" + height + " at ratio " + ratio + ": backing store " + s.width + "x" +
    s.height + " for " + s.css.join("x") + " CSS pixels");
  checks.check(width < 1000 ? s.css[0] >= 400 && s.css[1] >= 400 : s.css[0] + s.beside >= 1500,
    width + "x" + height + ": the view takes " + s.css.map(Math.round).join("x") + " CSS pixels");
  await page.setViewportSize({ width: Math.round(width * 0.75), height: Math.round(height * 0.9) });
  await page.waitForTimeout(300);
  await settled();
  const r = await size();
  checks.check(fits(r) && r.css[1] < s.css[1], "resized window: backing store " + r.width + "x" + r.height + " for " +
    r.css.join("x"));
  await page.click("#toggle-panel");
  await page.waitForTimeout(300);
  await settled();
  const hidden = await size();
  checks.check(fits(hidden) && Math.abs(hidden.css[0] + hidden.beside - Math.round(width * 0.75)) <= 1 &&
    hidden.css[0] * hidden.css[1] > 1.1 * r.css[0] * r.css[1],
    "panel hidden: the view is the window's width and larger (" + hidden.css.join("x") + ")");
  // The frame asked for by the last resize drawn (the size follows with it, see above).
  await page.evaluate(() => window.mediso.drawn());
  const drawn = await drawnCentroid(page);
  checks.check(drawn.n > 1000, "the view is drawn after resizing (" + drawn.n + " pixels)");
  await context.close();
}

await checks.finish(browser, server, phantomServer, mirrorServer);
