// SPDX-License-Identifier: BSD-3-Clause
// The brick pool on the page's GPU path in Chromium (issue 31 point 5; docs/histopyramid.md, The
// brick pool; docs/web.md, Paths): the plugin's phantom at 72^3 on the GPU path (SwiftShader's
// WebGL2, the viewer in the worker) under a forced texture limit of 64 and a 3 MB GPU budget, so
// that the core keeps it as 27 bricks of 24 points in 32-point slots of one pool texture:
// - the page stays on the GPU path (no fallback), says in its readout that it draws from a pool,
//   and stats() says one pyramid over the pool (poolSlots >= activeBricks, brickPyramidBuilds 1);
// - for bone alone, skin (translucent) over bone, and a change to a third value, the primitives
//   are exactly the CPU model's count on the dense volume, and the image is the dense page's
//   within TestWebPage's thresholds (at most 2% of the pixels off by more than 32 levels);
// - the same page with ?brickPool=0 draws each crossed brick as its own pyramid (poolSlots 0,
//   brickPyramidBuilds = activeBricks) with the same primitives: the checks above tell the two
//   apart, so a page whose pool is off or miscounts fails.
import { Checks, launchBrowser, openInContext, startServer } from "./webserver-harness.mjs";

const checks = new Checks();
const server = await startServer(["phantom:72"]);
const browser = await launchBrowser();
const BONE = { value: 400, color: [0.9, 0.82, 0.65], opacity: 1 };
const SKIN = { value: -500, color: [0.93, 0.75, 0.62], opacity: 0.4 };
const SCENES = [{ name: "bone", surfaces: [BONE] }, { name: "skin over bone", surfaces: [SKIN, BONE] },
  { name: "a change to 900", surfaces: [{ ...BONE, value: 900 }] }];
const GPU = "&path=gpu&size=320x240";
const FORCED = "&maxTextureSize=64&gpuBudgetMB=3";

/** Each scene drawn: its stats, the CPU model's count on the volume, and a shot of the canvas. */
async function drawScenes(query) {
  const page = await openInContext(browser, server.url + query);
  // what is drawn over the canvas (the frame rate, the slice views' crosshair) is not the GPU
  // path's: hidden, not compared
  await page.addStyleTag({ content: "#overlay, #crosshair3d { visibility: hidden !important; }" });
  const drawn = [];
  for (const scene of SCENES) {
    const stats = await page.evaluate((s) => window.mediso.setSurfaces(s), scene.surfaces);
    const count = await page.evaluate((v) => window.mediso.cpuCount(v), scene.surfaces.map((s) => s.value));
    const readout = await page.evaluate(() => [...document.querySelectorAll("#readout tr")]
      .map((tr) => tr.children[0].textContent + ": " + tr.children[1].textContent)
      .find((row) => row.startsWith("GPU volume")) || "");
    drawn.push({ scene: scene.name, stats, count, readout, shot: await page.locator("#view").screenshot() });
  }
  await page.context().close();
  return drawn;
}

// Pixels of two PNGs compared in the browser: how many differ by more than 32 levels in a channel.
const comparer = await browser.newPage();
const differing = (a, b) => comparer.evaluate(async ([a64, b64]) => {
  const pixels = async (b64) => {
    const bitmap = await createImageBitmap(await (await fetch("data:image/png;base64," + b64)).blob());
    const g = new OffscreenCanvas(bitmap.width, bitmap.height).getContext("2d");
    g.drawImage(bitmap, 0, 0);
    return g.getImageData(0, 0, bitmap.width, bitmap.height);
  };
  const [x, y] = [await pixels(a64), await pixels(b64)];
  if (x.width !== y.width || x.height !== y.height) {
    return { ratio: 1, note: "sizes differ" };
  }
  let n = 0, largest = 0;
  for (let p = 0; p < x.data.length; p += 4) {
    const d = Math.max(...[0, 1, 2].map((c) => Math.abs(x.data[p + c] - y.data[p + c])));
    largest = Math.max(largest, d);
    n += d > 32;
  }
  return { ratio: n / (x.width * x.height), note: n + " pixels, largest difference " + largest };
}, [a.toString("base64"), b.toString("base64")]);

const dense = await drawScenes(GPU);
const pooled = await drawScenes(GPU + FORCED);
const perBrick = await drawScenes(GPU + FORCED + "&brickPool=0");

const brickFields = (s) => JSON.stringify({ path: s.path, primitives: s.primitives, bricks: s.bricks,
  brickPoints: s.brickPoints, activeBricks: s.activeBricks, residentBricks: s.residentBricks,
  poolSlots: s.poolSlots, brickPyramidBuilds: s.brickPyramidBuilds });
for (const [i, d] of dense.entries()) {
  const p = pooled[i], b = perBrick[i];
  console.log(d.scene + ": dense " + brickFields(d.stats) + "; pool " + brickFields(p.stats) +
    "; per brick " + brickFields(b.stats) + "; CPU count " + d.count);
  checks.check(d.stats.path === "gpu" && d.stats.bricks === 0 && d.stats.primitives === d.count && d.count > 0,
    d.scene + ": the dense page draws one texture on the GPU path with the CPU model's count (" +
    d.stats.primitives + ", " + d.count + ")");
  checks.check(p.stats.path === "gpu" && p.stats.reason === "chosen by the user" && p.stats.level === 3,
    d.scene + ": under the forced limit and budget the page stays on the GPU path at the full level (" +
    p.stats.path + ", level " + p.stats.level + ", " + p.stats.reason + ")");
  checks.check(p.stats.bricks === 27 && p.stats.brickPoints === 24 && p.stats.activeBricks > 0 &&
    p.stats.poolSlots >= p.stats.activeBricks && p.stats.brickPyramidBuilds === 1,
    d.scene + ": the volume is 27 bricks of 24 drawn from one pool of " + p.stats.poolSlots +
    " slots with one pyramid (" + p.stats.activeBricks + " active, " + p.stats.brickPyramidBuilds + " built)");
  checks.check(/drawn from a pool of \d+ slots \(one pyramid\)/.test(p.readout),
    d.scene + ": the readout says the pool (" + p.readout + ")");
  checks.check(p.stats.primitives === d.count && p.count === d.count,
    d.scene + ": the pool's primitives (" + p.stats.primitives + ") are the CPU model's count on the dense " +
    "volume (" + d.count + ")");
  const r = await differing(d.shot, p.shot);
  checks.check(r.ratio <= 0.02, d.scene + ": the pool's image against the dense page's: " +
    (100 * r.ratio).toFixed(2) + "% of pixels off by more than 32 levels (at most 2%; " + r.note + ")");
  checks.check(b.stats.path === "gpu" && b.stats.bricks === 27 && b.stats.poolSlots === 0 &&
    b.stats.brickPyramidBuilds === b.stats.activeBricks && b.stats.activeBricks === p.stats.activeBricks,
    d.scene + ": with ?brickPool=0 each of the " + b.stats.activeBricks + " crossed bricks is its own " +
    "pyramid (" + b.stats.brickPyramidBuilds + " built, no pool)");
  checks.check(/each crossed brick drawn as its own pyramid \(\d+\): the brick pool is off/.test(b.readout),
    d.scene + ": the readout says so, and why (" + b.readout + ")");
  checks.check(b.stats.primitives === d.count,
    d.scene + ": per brick, the primitives (" + b.stats.primitives + ") are the same count (" + d.count + ")");
  const rb = await differing(d.shot, b.shot);
  checks.check(rb.ratio <= 0.02, d.scene + ": the per-brick image against the dense page's: " +
    (100 * rb.ratio).toFixed(2) + "% (" + rb.note + ")");
  const pb = await differing(p.shot, b.shot);
  console.log(d.scene + ": the pool's image against the per-brick one: " + pb.note);
}
await checks.finish(browser, server);
