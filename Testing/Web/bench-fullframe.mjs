// SPDX-License-Identifier: BSD-3-Clause
// The full-level frame's parts on SwiftShader (Python/benchmark_web.py --fullframe runs it; issue
// 31, docs/web.md "The full-level frame on SwiftShader"): in one Chromium, for each page URL
// (each a server with its own WebAssembly module: the A/B) and each canvas size, the page on the
// CPU path with its level whole (?stream=0), once every surface is at the full level:
//   draw      still frames of all the surfaces (the camera turned 2 degrees each), nothing uploaded
//   upload    the surfaces cleared, then set again: taken from the cache and uploaded (buildMs:
//             the take and the upload's calls; uploadMs: the upload's calls), drawn; then one
//             still frame after it
//   each      each surface alone (uploaded, then still frames); a translucent one also opaque
// Pages alternate URL by URL `repeats` times, each in a fresh context.
//   node bench-fullframe.mjs CONFIG.json OUT.json
// CONFIG: {urls: {label: url}, sizes: [[w, h]], stills, repeats, each (false: not each surface alone)}
import { launch, turnStills } from "./page.mjs";
import { readFileSync, writeFileSync } from "node:fs";

const [configFile, outFile] = process.argv.slice(2);
const config = JSON.parse(readFileSync(configFile, "utf8"));
const browser = await launch();
const stills = config.stills || 4;
const median = (v) => { const s = [...v].sort((a, b) => a - b); return s.length ? s[(s.length - 1) >> 1] : 0; };
const runs = [];

async function stillMs(page) {
  const frames = await turnStills(page, stills);
  return { ms: median(frames.map((f) => f.ms)), all: frames.map((f) => Math.round(f.ms)),
    triangles: frames.length ? frames[frames.length - 1].triangles : 0 };
}

// The surfaces set, and the frame that uploaded them (the last frame drawn by then).
async function setAndTake(page, surfaces) {
  await page.evaluate((s) => window.mediso.setSurfaces(s), surfaces);
  const f = await page.evaluate(() => { const l = window.mediso.frames(); return l[l.length - 1]; });
  return { ms: Math.round(f.ms), buildMs: Math.round(f.buildMs || 0), uploadMs: Math.round(f.uploadMs || 0),
    triangles: f.triangles };
}

for (let repeat = 0; repeat < (config.repeats || 1); ++repeat) {
  for (const size of config.sizes) {
    for (const [label, url] of Object.entries(config.urls)) {
      const context = await browser.newContext({ viewport: { width: size[0] + 420, height: size[1] + 100 } });
      const page = await context.newPage();
      page.on("pageerror", (e) => console.log(label + " pageerror: " + e.message));
      await page.goto(url + "&path=cpu&stream=0&size=" + size.join("x"), { waitUntil: "commit" });
      await page.waitForFunction(() => window.mediso, null, { timeout: 600000 });
      await page.evaluate(() => window.mediso.ready);
      await page.evaluate(() => window.mediso.whenFull());
      await page.waitForFunction(() => window.mediso.stats().received === 1, null, { timeout: 600000, polling: 50 });
      const surfaces = await page.evaluate(() => window.mediso.getSurfaces());
      const run = { label, size, repeat, surfaces: surfaces.map((s) => [s.value, s.opacity]) };
      run.draw = await stillMs(page);
      run.upload = [];
      for (let i = 0; i < 2; ++i) {
        await page.evaluate(() => window.mediso.setSurfaces([]));
        const taken = await setAndTake(page, surfaces);
        taken.next = (await stillMs(page)).all[0];
        run.upload.push(taken);
      }
      run.each = [];
      for (const s of config.each === false ? [] : surfaces) {
        const looks = s.opacity < 1 ? [s, Object.assign({}, s, { opacity: 1 })] : [s];
        for (const look of looks) {
          const taken = await setAndTake(page, [look]);
          run.each.push({ value: look.value, opacity: look.opacity, uploadFrame: taken, draw: await stillMs(page) });
        }
      }
      await page.evaluate((s) => window.mediso.setSurfaces(s), surfaces);
      runs.push(run);
      console.log(JSON.stringify(run));
      await context.close();
    }
  }
}
await browser.close();
writeFileSync(outFile, JSON.stringify({ runs }));
