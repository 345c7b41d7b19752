// SPDX-License-Identifier: BSD-3-Clause
// Choosing the value on the page, in Chromium, served by Python/serve.py:
// - a NIfTI the test writes (float32, 40x36x30 at 1.5 x 1.5 x 2 mm, RAS sform with an offset): the
//   signed distance to a sphere of radius 9 mm centred at LPS (8, -6, 6) mm from the volume's
//   middle (the patient's left, anterior, superior). Not Hounsfield units: the page opens with
//   one surface at Otsu's threshold, equal (1e-9) to the test's own Otsu over the test's own
//   counts of its values, which equal the page's histogram bin for bin;
// - the contours at 0: on each view every contour point lies on the slice's plane and on the
//   sphere's circle in it within 0.3 mm (a voxel is 1.5-2 mm), and the contour's pixels, in the
//   surface's colour on the canvas, centre on the crosshair (the sphere's centre) within 2 px;
// - orientation: with the crosshair at the middle of the volume, the contour is drawn right and
//   up of it on the axial (seen from the feet: L right, A up) and coronal (L right, S up) views,
//   left and up on the sagittal (seen from the left: A left, S up); the views' labels say so;
// - a click on the axial slice 25 px right of the crosshair moves it 25 px x mm/px to the
//   patient's left, the sagittal slice with it, the coronal and axial slices staying; a
//   right-drag on the coronal view widens its window only; the window presets set the window;
// - a click on the sphere in the 3D view (anterior view) puts the crosshair on its front: 9 mm
//   from the centre within 0.5 mm, on the anterior side;
// - the histogram: dragging the surface's marker 30 px to the right changes the isovalue to the
//   value under the pointer (within one pixel's worth), the box in the list shows it and the 3D
//   view's surface shrinks (fewer triangles); a press away from every marker changes nothing;
// - the phantom (CT-like, Hounsfield units): skin -500 (translucent) and bone 400 first, the CT
//   presets add contrast vessels at 200, the slices open with the soft-tissue window (W 400 L 40);
// - layout: on a wide window the three views stand right of the 3D view, on a narrow one (600 px,
//   pixel ratio 2) under it, each at least 100 x 80 CSS pixels within the window, their backing
//   stores their CSS size times the ratio.
import { mkdtempSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import path from "node:path";
import { Checks, launchBrowser, niftiBytes, openPage, startServer } from "./webserver-harness.mjs";

const checks = new Checks();
const fmt = (a) => "(" + a.map((x) => x.toFixed(3)).join(", ") + ")";
const sub = (a, b) => a.map((x, i) => x - b[i]);
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const len = (a) => Math.hypot(...a);

// --- the sphere NIfTI ------------------------------------------------------------------------------
const DIMS = [40, 36, 30], SPACING = [1.5, 1.5, 2], OFFSET = [-30, -27, -30]; // RAS mm of voxel 0
const RADIUS = 9;
const rasOf = (i, j, k) => [OFFSET[0] + SPACING[0] * i, OFFSET[1] + SPACING[1] * j, OFFSET[2] + SPACING[2] * k];
const lpsOf = (ras) => [-ras[0], -ras[1], ras[2]];
const MIDDLE = lpsOf(rasOf(...DIMS.map((n) => (n - 1) / 2)));
const CENTRE = [MIDDLE[0] + 8, MIDDLE[1] - 6, MIDDLE[2] + 6]; // LPS: left, anterior, superior
const values = new Float32Array(DIMS[0] * DIMS[1] * DIMS[2]);
for (let k = 0; k < DIMS[2]; ++k) {
  for (let j = 0; j < DIMS[1]; ++j) {
    for (let i = 0; i < DIMS[0]; ++i) {
      values[i + DIMS[0] * (j + DIMS[1] * k)] = RADIUS - len(sub(lpsOf(rasOf(i, j, k)), CENTRE));
    }
  }
}
function writeNIfTI(file) {
  const sform = [0, 1, 2].map((r) => [0, 1, 2, 3].map((c) => c === 3 ? OFFSET[r] : (r === c ? SPACING[r] : 0)));
  writeFileSync(file, niftiBytes(DIMS, SPACING, sform, values));
}
const folder = mkdtempSync(path.join(tmpdir(), "mediso-slices-"));
const nifti = path.join(folder, "sphere.nii");
writeNIfTI(nifti);

// The first isovalue's rule, written here from its description (Filters/Core/HistogramThreshold.h):
// 256 equal bins over [min, max] for float data, Otsu's split maximising w0 w1 (m0 - m1)^2.
function reference() {
  let lo = Infinity, hi = -Infinity;
  for (const v of values) {
    lo = Math.min(lo, v);
    hi = Math.max(hi, v);
  }
  const count = 256, width = (hi - lo) / count;
  const counts = new Array(count).fill(0);
  for (const v of values) {
    const at = Math.floor((v - lo) / width);
    ++counts[at > 0 ? Math.min(at, count - 1) : 0];
  }
  let total = 0, moment = 0;
  counts.forEach((c, i) => { total += c; moment += i * c; });
  let below = 0, belowMoment = 0, best = -1, split = 0;
  for (let k = 0; k + 1 < count; ++k) {
    below += counts[k];
    belowMoment += k * counts[k];
    const above = total - below;
    if (below === 0 || above === 0) {
      continue;
    }
    const d = belowMoment / below - (moment - belowMoment) / above;
    if (below * above * d * d > best) {
      best = below * above * d * d;
      split = k;
    }
  }
  return { low: lo, width, counts, otsu: lo + (split + 1) * width };
}

// Two animation frames, then the viewer's frame of the last change (it may draw in a worker).
const frame = (page) => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))
  .then(() => window.mediso.drawn()));

// The centroid of a view's pixels of `color` (within 40 per channel), relative to its crosshair,
// in CSS pixels (x right, y down), and how many.
const coloured = (page, name, color) => page.evaluate(([name, color]) => {
  const view = window.mediso.slices().find((v) => v.name === name);
  const canvas = document.querySelector('#slices .slice[data-view="' + name + '"] canvas');
  const pixels = canvas.getContext("2d").getImageData(0, 0, canvas.width, canvas.height).data;
  const ratio = canvas.width / canvas.clientWidth;
  let n = 0, sx = 0, sy = 0;
  for (let y = 0; y < canvas.height; ++y) {
    for (let x = 0; x < canvas.width; ++x) {
      const o = 4 * (x + canvas.width * y);
      if (Math.abs(pixels[o] - 255 * color[0]) + Math.abs(pixels[o + 1] - 255 * color[1]) +
          Math.abs(pixels[o + 2] - 255 * color[2]) < 40) {
        ++n;
        sx += (x + 0.5) / ratio;
        sy += (y + 0.5) / ratio;
      }
    }
  }
  return { n, x: n ? sx / n - view.crosshair[0] : 0, y: n ? sy / n - view.crosshair[1] : 0 };
}, [name, color]);

const server = await startServer([nifti]);
const phantomServer = await startServer(["phantom:48"]);
const browser = await launchBrowser();

// --- the sphere: first value, contours, orientation, crosshair, window, pick, histogram -------------
{
  const context = await browser.newContext({ viewport: { width: 1400, height: 900 } });
  const page = await context.newPage();
  await openPage(page, server);
  const ref = reference();
  const first = await page.evaluate(() => ({ s: window.mediso.getSurfaces(), h: window.mediso.histogram() }));
  checks.check(first.h.count === 256 && Math.abs(first.h.low - ref.low) < 1e-9 &&
    first.h.counts.every((c, i) => c === ref.counts[i]),
    "the page's histogram is the test's own counts of the values (256 bins from " + ref.low.toFixed(3) + ")");
  checks.check(first.s.length === 1 && Math.abs(first.s[0].value - ref.otsu) < 1e-9 && Math.abs(first.h.otsu - ref.otsu) < 1e-9,
    "not Hounsfield units: one first surface at Otsu's threshold " + first.s.map((s) => s.value).join() +
    " (the test's: " + ref.otsu + ")");

  // Contours at 0 on slices off the sphere's centre.
  const RED = [1, 0, 0];
  await page.evaluate((red) => window.mediso.setSurfaces([{ value: 0, color: red, opacity: 1 }]), RED);
  await page.evaluate((p) => window.mediso.setCrosshair(p), [CENTRE[0] - 3, CENTRE[1] + 4, CENTRE[2] + 4]);
  const views = await page.evaluate(() => window.mediso.slices({ contours: true }));
  for (const view of views) {
    const axis = { axial: 2, coronal: 1, sagittal: 0 }[view.name];
    const points = view.contours[0].points;
    const plane = points.length ? points[0][axis] : NaN;
    let worst = 0, offPlane = 0;
    for (const p of points) {
      offPlane = Math.max(offPlane, Math.abs(p[axis] - plane));
      const inPlane = sub(p, CENTRE).map((x, a) => (a === axis ? 0 : x));
      const circle = Math.sqrt(RADIUS * RADIUS - (plane - CENTRE[axis]) ** 2);
      worst = Math.max(worst, Math.abs(len(inPlane) - circle));
    }
    checks.check(points.length >= 30 && offPlane < 1e-6 && worst < 0.3,
      view.name + ": " + points.length + " contour points on the plane at " + plane.toFixed(2) +
      " mm, on the sphere's circle within " + worst.toFixed(3) + " mm");
  }
  await page.evaluate((p) => window.mediso.setCrosshair(p), CENTRE);
  for (const name of ["axial", "coronal", "sagittal"]) {
    const c = await coloured(page, name, RED);
    checks.check(c.n > 60 && Math.hypot(c.x, c.y) < 2,
      name + ": the contour drawn in the surface's colour around the crosshair on the sphere's centre: " + JSON.stringify(c));
  }

  // Orientation: the sphere is left, anterior and superior of the middle.
  await page.evaluate((p) => window.mediso.setCrosshair(p), MIDDLE);
  const labels = await page.evaluate(() => window.mediso.slices().map((v) => v.name + ":" + Object.values(v.labels).join("")));
  checks.check(labels.join() === "axial:RLAP,coronal:RLSI,sagittal:APSI",
    "the views' labels (left, right, top, bottom): " + labels.join(" "));
  const expect = { axial: [1, -1], coronal: [1, -1], sagittal: [-1, -1] };
  for (const name of ["axial", "coronal", "sagittal"]) {
    const c = await coloured(page, name, RED);
    checks.check(c.n > 20 && Math.sign(c.x) === expect[name][0] && Math.sign(c.y) === expect[name][1] &&
      Math.abs(c.x) > 3 && Math.abs(c.y) > 3,
      name + ": the sphere (left, anterior, superior) drawn " + (expect[name][0] > 0 ? "right" : "left") +
      " and up of the middle: " + JSON.stringify(c));
  }

  // A click on the axial view moves the crosshair to the patient's left (from a grid point, on
  // the axial slice's plane).
  await page.evaluate((p) => window.mediso.setCrosshair(p), lpsOf(rasOf(20, 18, 15)));
  const before = await page.evaluate(() => ({ s: window.mediso.slices(), c: window.mediso.getCrosshair().point }));
  const axial = before.s[0];
  const clickX = Math.round(axial.canvas.left + axial.crosshair[0]) + 25, clickY = Math.round(axial.canvas.top + axial.crosshair[1]);
  await page.mouse.click(clickX, clickY);
  const after = await page.evaluate(() => ({ s: window.mediso.slices(), c: window.mediso.getCrosshair().point }));
  const expectedX = before.c[0] + (clickX - axial.canvas.left - axial.crosshair[0]) * axial.mmPerPixel;
  const expectedY = before.c[1] + (clickY - axial.canvas.top - axial.crosshair[1]) * axial.mmPerPixel;
  checks.check(Math.abs(after.c[0] - expectedX) < 1e-6 && Math.abs(after.c[1] - expectedY) < 1e-6 &&
    Math.abs(after.c[2] - before.c[2]) < 1e-6,
    "a click on the axial view moves the crosshair " + fmt(before.c) + " -> " + fmt(after.c) + " (x expected " + expectedX.toFixed(3) + ")");
  const indexOf = (c) => [(-c[0] - OFFSET[0]) / SPACING[0], (-c[1] - OFFSET[1]) / SPACING[1], (c[2] - OFFSET[2]) / SPACING[2]];
  checks.check(after.s[2].index === Math.round(indexOf(after.c)[0]) && after.s[2].index !== before.s[2].index &&
    after.s[0].index === before.s[0].index && after.s[1].index === before.s[1].index,
    "the sagittal slice follows (" + before.s[2].index + " -> " + after.s[2].index + "), the axial and coronal stay");
  // The clicked view has the focus: the up key steps its slice (superior), the 3D view stays.
  const viewBefore = await page.evaluate(() => window.mediso.getView().world.direction);
  await page.keyboard.press("ArrowUp");
  const stepped = await page.evaluate(() => ({ s: window.mediso.slices(), d: window.mediso.getView().world.direction }));
  checks.check(stepped.s[0].index === after.s[0].index + 1 && stepped.d.every((x, i) => x === viewBefore[i]),
    "the up key on the focused axial view steps its slice " + after.s[0].index + " -> " + stepped.s[0].index +
    ", the 3D view not turned");

  // Window: a right-drag on the coronal view widens its window only; presets set it.
  const coronal = after.s[1];
  const cx = coronal.canvas.left + coronal.canvas.width / 2, cy = coronal.canvas.top + coronal.canvas.height / 2;
  await page.mouse.move(cx, cy);
  await page.mouse.down({ button: "right" });
  await page.mouse.move(cx + 25, cy);
  await page.mouse.move(cx + 50, cy);
  await page.mouse.up({ button: "right" });
  const windowed = await page.evaluate(() => window.mediso.slices());
  const range = (await page.evaluate(() => window.mediso.histogram())).width * 256;
  checks.check(Math.abs(windowed[1].window.width - (after.s[1].window.width + 50 * range / 400)) < 1e-6 * range &&
    Math.abs(windowed[1].window.level - after.s[1].window.level) < 1e-9 &&
    windowed[0].window.width === after.s[0].window.width,
    "a right-drag of 50 px widens the coronal window " + after.s[1].window.width.toFixed(3) + " -> " +
    windowed[1].window.width.toFixed(3) + ", the axial's stays");
  const axialWindow = '#slices .slice[data-view="axial"] select';
  await page.selectOption(axialWindow, await page.$eval(axialWindow, (select) =>
    [...select.options].find((o) => o.textContent.startsWith("Full range")).value));
  const full = (await page.evaluate(() => window.mediso.slices()))[0].window;
  checks.check(Math.abs(full.width - range) < 1e-6 * range, "the Full range preset: W " + full.width.toFixed(3));
  // The view keeps its slice's picture while the values, the slice and the window stay (slices.js,
  // slicePicture): another window redraws it, and the first window again gives the first pixels
  // (above the window's own line of text, at the bottom, which changes whether the picture does or not).
  const axialPixels = () => page.evaluate(() => {
    const canvas = document.querySelector('#slices .slice[data-view="axial"] canvas');
    const above = canvas.height - Math.ceil(20 * canvas.width / canvas.clientWidth);
    const data = canvas.getContext("2d").getImageData(0, 0, canvas.width, above).data;
    let hash = 0;
    for (let i = 0; i < data.length; ++i) {
      hash = (Math.imul(hash, 31) + data[i]) | 0;
    }
    return hash;
  });
  const fullPixels = await axialPixels();
  const otherChoice = await page.$eval(axialWindow, (select) =>
    [...select.options].find((o) => !o.textContent.startsWith("Full range")).value);
  await page.selectOption(axialWindow, otherChoice);
  const otherPixels = await axialPixels();
  await page.selectOption(axialWindow, await page.$eval(axialWindow, (select) =>
    [...select.options].find((o) => o.textContent.startsWith("Full range")).value));
  const againPixels = await axialPixels();
  checks.check(otherPixels !== fullPixels && againPixels === fullPixels,
    "the axial picture redrawn for another window (" + (otherPixels !== fullPixels) + ") and the same again " +
    "for the Full range window (" + (againPixels === fullPixels) + ")");

  // A click on the sphere in the 3D view (anterior view) puts the crosshair on its front.
  const v = await page.evaluate(() => window.mediso.getView());
  const box = await page.locator("#view").boundingBox();
  const w = v.world, toP = sub(CENTRE, w.position);
  const right = [w.direction[1] * w.viewUp[2] - w.direction[2] * w.viewUp[1],
    w.direction[2] * w.viewUp[0] - w.direction[0] * w.viewUp[2], w.direction[0] * w.viewUp[1] - w.direction[1] * w.viewUp[0]];
  const tan = Math.tan(v.viewAngle * Math.PI / 360), depth = dot(toP, w.direction);
  const px = box.x + box.width / 2 + (dot(toP, right) / depth / tan) * box.height / 2;
  const py = box.y + box.height / 2 - (dot(toP, w.viewUp) / depth / tan) * box.height / 2;
  await page.mouse.click(px, py);
  const picked = await page.evaluate(() => window.mediso.getCrosshair().point);
  checks.check(Math.abs(len(sub(picked, CENTRE)) - RADIUS) < 0.5 && picked[1] < CENTRE[1] - 7,
    "a click on the sphere in the 3D view: the crosshair at " + fmt(picked) + ", " + len(sub(picked, CENTRE)).toFixed(3) +
    " mm from the centre, on its anterior side");

  // The histogram: drag the marker.
  const h0 = await page.evaluate(() => ({ h: window.mediso.histogram(), st: window.mediso.stats() }));
  const mx = h0.h.canvas.left + h0.h.markers[0].x, my = h0.h.canvas.top + h0.h.canvas.height / 2;
  await page.mouse.move(mx + 60, my); // away from the marker: nothing moves
  await page.mouse.down();
  await page.mouse.move(mx + 90, my);
  await page.mouse.up();
  checks.check((await page.evaluate(() => window.mediso.getSurfaces()[0].value)) === 0,
    "a press away from every marker leaves the isovalue");
  await page.mouse.move(mx, my);
  await page.mouse.down();
  for (let s = 1; s <= 3; ++s) {
    await page.mouse.move(mx + 10 * s, my);
  }
  await page.mouse.up();
  await frame(page);
  const h1 = await page.evaluate(() => ({ s: window.mediso.getSurfaces(), st: window.mediso.stats(),
    box: document.querySelector("#surfaces .surface input.isovalue").value, h: window.mediso.histogram() }));
  const perPixel = (h0.h.width * h0.h.count) / h0.h.canvas.width;
  const expectedValue = h0.h.low + (h0.h.markers[0].x + 30) * perPixel;
  const drawn = (st) => st.triangles + st.primitives;
  checks.check(Math.abs(h1.s[0].value - expectedValue) <= perPixel && Number(h1.box) === h1.s[0].value &&
    Math.abs(h1.h.markers[0].x - (h0.h.markers[0].x + 30)) <= 1,
    "dragging the marker 30 px: isovalue 0 -> " + h1.s[0].value + " (" + expectedValue.toFixed(4) + " under the pointer), the box shows " + h1.box);
  checks.check(drawn(h1.st) > 0 && drawn(h1.st) < drawn(h0.st),
    "the 3D view follows: " + drawn(h0.st) + " -> " + drawn(h1.st) + " " + (h1.st.path === "cpu" ? "triangles" : "primitives") +
    " (a smaller sphere)");
  await context.close();
}

// --- the phantom: CT defaults and presets -------------------------------------------------------------
{
  const context = await browser.newContext({ viewport: { width: 1400, height: 900 } });
  const page = await context.newPage();
  await openPage(page, phantomServer);
  const s = await page.evaluate(() => window.mediso.getSurfaces());
  checks.check(s.length === 2 && s[0].value === -500 && s[0].opacity < 1 && s[1].value === 400 && s[1].opacity === 1,
    "a CT in Hounsfield units opens with translucent skin at -500 and bone at 400: " + JSON.stringify(s.map((x) => [x.value, x.opacity])));
  await page.click('#presets button[data-preset="Contrast vessels"]');
  await page.evaluate(() => window.mediso.drawn()); // the slices redraw after the (worker's) frame
  const added = await page.evaluate(() => window.mediso.getSurfaces().map((x) => x.value));
  checks.check(added.join() === "-500,400,200", "the Contrast vessels preset adds 200 HU: " + added.join());
  const windows = await page.evaluate(() => window.mediso.slices().map((v) => v.window));
  checks.check(windows.every((w) => w.width === 400 && w.level === 40), "the slices open with the soft-tissue window: " +
    JSON.stringify(windows.map((w) => [w.width, w.level])));
  const contours = await page.evaluate(() => window.mediso.slices({ contours: true })
    .map((v) => v.contours.map((c) => c.points.length)));
  checks.check(contours.every((c) => c.length === 3 && c[0] > 0 && c[1] > 0),
    "skin and bone contours on every view: " + JSON.stringify(contours));
  await context.close();
}

// --- layout ------------------------------------------------------------------------------------------
for (const [width, height, ratio] of [[1400, 900, 1], [600, 800, 2]]) {
  const context = await browser.newContext({ viewport: { width, height }, deviceScaleFactor: ratio });
  const page = await context.newPage();
  await openPage(page, phantomServer);
  await frame(page);
  const got = await page.evaluate(() => ({ views: window.mediso.slices(), view: document.getElementById("view").getBoundingClientRect().toJSON() }));
  const beside = got.views.every((v) => v.canvas.left >= got.view.right - 1);
  const below = got.views.every((v) => v.canvas.top >= got.view.bottom - 1);
  const visible = got.views.every((v) => v.canvas.width >= 100 && v.canvas.height >= 80 &&
    v.canvas.left >= 0 && v.canvas.left + v.canvas.width <= width + 1 && v.canvas.top + v.canvas.height <= height + 1);
  const sharp = got.views.every((v) => Math.abs(v.backingStore[0] - v.canvas.width * ratio) <= 1 &&
    Math.abs(v.backingStore[1] - v.canvas.height * ratio) <= 1);
  checks.check((width > 1000 ? beside : below) && visible && sharp,
    width + "x" + height + " at ratio " + ratio + ": the slices " + (width > 1000 ? "right of" : "under") + " the 3D view, " +
    got.views.map((v) => Math.round(v.canvas.width) + "x" + Math.round(v.canvas.height) + " (" + v.backingStore.join("x") + ")").join(", "));
  await context.close();
}

await checks.finish(browser, server, phantomServer);
