// SPDX-License-Identifier: BSD-3-Clause
// The brick benchmark's browser side (Python/benchmark_web.py --bricks runs it): in one Chromium,
// the page's GPU path on one volume kept as one texture and, under forced texture limits and GPU
// budgets (?maxTextureSize, ?gpuBudgetMB), as bricks drawn from the pool and each as its own
// pyramid (?brickPool=0); each configuration in a fresh context, the volume fetched whole
// (?stream=0). Measured in the page: each isovalue change to its full-level frame, the part of it
// that built the pyramids, and still frames with the camera turned 2 degrees each (the frames' own
// times, as bench-interactive.mjs's stills).
//   node bench-bricks.mjs CONFIG.json OUT.json
// CONFIG: {url, size: [w, h], configs: [{name, query}], isovalues: [...], stills}
import { launch, turnStills } from "./page.mjs";
import { readFileSync, writeFileSync } from "node:fs";

const [configFile, outFile] = process.argv.slice(2);
const config = JSON.parse(readFileSync(configFile, "utf8"));
const browser = await launch();
const median = (a) => {
  const s = [...a].sort((x, y) => x - y);
  return s.length ? (s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2) : NaN;
};
const result = { runs: [] };
for (const { name, query } of config.configs) {
  const context = await browser.newContext({ viewport: { width: config.size[0] + 420, height: config.size[1] + 100 } });
  const page = await context.newPage();
  page.on("pageerror", (e) => console.log(name + " pageerror: " + e.message));
  const opened = Date.now();
  await page.goto(config.url + "&path=gpu&stream=0&size=" + config.size.join("x") + query, { waitUntil: "commit" });
  await page.waitForFunction(() => window.mediso, null, { timeout: 300000 });
  await page.evaluate(() => window.mediso.ready);
  const run = { name, query, firstImageMs: Date.now() - opened, changes: [] };
  // the first change builds the programs: not timed
  await page.evaluate((v) => window.mediso.setIsovalues([v]), config.isovalues[0]);
  for (const v of config.isovalues.slice(1)) {
    const s = await page.evaluate((value) => window.mediso.setIsovalues([value]), v);
    run.changes.push({ value: v, ms: s.lastRefinedMs || s.lastChangeMs, buildMs: s.buildMs,
      primitives: s.primitives, activeBricks: s.activeBricks, poolSlots: s.poolSlots,
      brickPyramidBuilds: s.brickPyramidBuilds, path: s.path });
  }
  const stills = await turnStills(page, config.stills);
  run.still = { frameMs: median(stills.map((f) => f.ms)), frames: stills.length };
  run.changeMs = median(run.changes.map((c) => c.ms));
  run.buildMs = median(run.changes.map((c) => c.buildMs));
  run.stats = await page.evaluate(() => window.mediso.stats());
  console.log(JSON.stringify({ name, change: run.changeMs, build: run.buildMs, still: run.still.frameMs,
    path: run.stats.path, bricks: run.stats.bricks, poolSlots: run.stats.poolSlots }));
  result.runs.push(run);
  await context.close();
}
writeFileSync(outFile, JSON.stringify(result, null, 1));
await browser.close();
