// SPDX-License-Identifier: BSD-3-Clause
// The interactive benchmark's browser side (Python/benchmark_web.py --interactive runs it): in one
// Chromium, each page (the main branch's, drawing on the main thread, and this one's, drawing in
// a worker) on each path takes the same isovalue changes and the same mouse drag; measured in the
// page: the time to the first visible answer of a change (its first frame) and to the full level,
// the frames of the drag (their times, their level or sample distance, the rate), and the longest
// main-thread task (PerformanceObserver longtask) over the changes and the drag.
//   node bench-interactive.mjs CONFIG.json OUT.json
// CONFIG: {pages: {name: url}, paths: ["cpu", "gpu"], size: [w, h], isovalues: [...], moves,
//          surfaces (optional: [{value, opacity}], drawn before the drag: e.g. skin 0.3 over bone),
//          stills (optional: still frames after the drag, the camera turned 2 degrees each),
//          moveMs (optional: the wait after each mouse move, 30 by default),
//          dragAfterMs (optional: [ms, ...]: the idle wait between the scene's settled frame and
//          the drag, [0] by default; each further wait: the scene changed again (each value 10
//          up), settled, that long idle, and the same drag, run.laterDrags),
//          trace (optional: Chromium's trace over the measured window, each main-thread task over
//          50 ms named in run.traced: longtasks.mjs)}
import { explain, longTasks, resetLongTasks, traceStart, traceStop, watchLongTasks } from "./longtasks.mjs";
import { frameMark, framesSince, launch, turnStills } from "./page.mjs";
import { readFileSync, writeFileSync } from "node:fs";

const [configFile, outFile] = process.argv.slice(2);
const config = JSON.parse(readFileSync(configFile, "utf8"));
const browser = await launch();
const result = { runs: [] };
const median = (a) => {
  const s = [...a].sort((x, y) => x - y);
  return s.length ? (s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2) : NaN;
};

// A mouse drag of config.moves moves on `page`'s view, then its settled still frame: the drag's
// frames (their median, rate, levels, the steady ones) and its first frame apart; `run` gets
// dragPrepared (the frame made ready ahead, as the page said at the first move).
async function dragOnce(page, path, run) {
  const before = await frameMark(page);
  const box = await page.locator("#view").boundingBox();
  const x = box.x + box.width / 2, y = box.y + box.height / 2;
  await page.mouse.move(x, y);
  await page.mouse.down();
  const sampled = [];
  const t0 = Date.now();
  const movedAt = await page.evaluate(() => performance.now()); // the drag's first move, in the page's clock
  for (let i = 1; i <= config.moves; ++i) {
    await page.mouse.move(x + 4 * i, y + i);
    await page.waitForTimeout(config.moveMs || 30);
    sampled.push(await page.evaluate(() => window.mediso.stats().lastFrameMs));
    if (i === 1) {
      // the drag's frame made ready after the scene's change (render-worker.js), if it was
      run.dragPrepared = await page.evaluate(() => window.mediso.stats().dragPrepared);
    }
  }
  await page.mouse.up();
  const dragSeconds = (Date.now() - t0) / 1000;
  if (run.phases) {
    run.phases.drag = movedAt;
    run.phases.release = await page.evaluate(() => performance.now());
  }
  await page.waitForFunction(() => window.mediso.stats().settled !== false, null, { timeout: 300000 });
  await page.waitForTimeout(500);
  const frames = await framesSince(page, before);
  let drag;
  if (frames) {
    const dragged = frames.filter((f) => f.interactive);
    // steady: without each (level, sample distance)'s first drag frame, which may build the
    // level's pyramid or compile its program (one-off work a longer drag does not repeat)
    const seen = new Set();
    const steady = dragged.filter((f) => {
      const key = [f.cpuLevel, f.gpuLevel, f.sampleDistance].join();
      return seen.has(key) || !seen.add(key);
    });
    drag = { frameMs: median(dragged.map((f) => f.ms)), frames: dragged.length, rate: dragged.length / dragSeconds,
      steadyMs: median(steady.map((f) => f.ms)), steadyFrames: steady.length,
      levels: [...new Set(dragged.map((f) => f.cpuLevel))], sampleDistances: [...new Set(dragged.map((f) => f.sampleDistance))],
      gpuLevels: [...new Set(dragged.map((f) => f.gpuLevel).filter((k) => k !== undefined))],
      predictionError: median(dragged.filter((f) => f.predictedMs > 0).map((f) => Math.abs(f.predictedMs - f.ms) / f.ms)),
      // each drag frame as drawn and as predicted (what the error above is a median of)
      frameList: dragged.map((f) => ({ level: f.cpuLevel, gpuLevel: f.gpuLevel, sampleDistance: f.sampleDistance,
        elements: path === "gpu" ? f.primitives : f.triangles, ms: f.ms, predictedMs: f.predictedMs })) };
    // the drag's first frame (after the scene's change: the first on its level for these
    // isovalues), apart: its time in the worker, the prediction, whether it built a pyramid,
    // and its wait from the first mouse move to its answer (what the user waits for)
    const first = dragged[0];
    drag.first = first && { ms: first.ms, predictedMs: first.predictedMs, pyramidBuilt: first.pyramidBuilt,
      level: path === "gpu" ? first.gpuLevel : first.cpuLevel, sampleDistance: first.sampleDistance,
      waitMs: first.answeredAt !== undefined ? first.answeredAt - movedAt : null };
  } else {
    drag = { frameMs: median(sampled), frames: null, rate: null, levels: null, sampleDistances: [1] };
  }
  drag.dragPrepared = run.dragPrepared;
  return drag;
}

for (const path of config.paths) {
  for (const [name, url] of Object.entries(config.pages)) {
    const page = await browser.newPage({ viewport: { width: config.size[0] + 420, height: config.size[1] + 100 } });
    page.on("pageerror", (e) => console.log(name + " pageerror: " + e.message));
    await watchLongTasks(page);
    await page.goto(url + "&path=" + path + "&size=" + config.size.join("x"), { waitUntil: "commit" });
    await page.waitForFunction(() => window.mediso, null, { timeout: 300000 });
    await page.evaluate(() => window.mediso.ready);
    // the volume whole (a large one streams its bricks first: until then no frame is coarse)
    await page.waitForFunction(() => (window.mediso.stats().received ?? 1) >= 1, null, { timeout: 600000 });
    // the load's own tasks left out: a first change, a second's rest
    await page.evaluate((v) => window.mediso.setIsovalues([v]), config.isovalues[0]);
    await page.waitForTimeout(1000);
    // the measured window: from here (the timed changes, the drag's scene, the drag, its
    // refinement) to the long tasks' read below; with config.trace, Chromium's trace of it names
    // what ran in each long task (longtasks.mjs)
    const trace = config.trace && (await traceStart(page));
    const anchor = await resetLongTasks(page);
    const run = { page: name, path, changes: [], drag: {}, phases: { window: anchor } };
    for (const v of config.isovalues.slice(1)) {
      const s = await page.evaluate((value) => window.mediso.setIsovalues([value]), v);
      run.changes.push({ value: v, firstMs: s.lastChangeMs, fullMs: s.lastRefinedMs || s.lastChangeMs,
        level: s.cpuLevel, elements: path === "gpu" ? s.primitives : s.triangles });
    }
    run.phases.scene = await page.evaluate(() => performance.now());
    if (config.surfaces) {
      // the drag's scene (issue 30's: skin 0.3 over bone), drawn at its full level first
      await page.evaluate((surfaces) => window.mediso.setSurfaces(surfaces), config.surfaces);
      await page.waitForFunction(() => window.mediso.stats().settled !== false, null, { timeout: 300000 });
    }
    const afterMs = config.dragAfterMs || [0];
    await page.waitForTimeout(afterMs[0]);
    run.drag = await dragOnce(page, path, run);
    run.drag.afterMs = afterMs[0];
    run.longTasks = await longTasks(page);
    run.phases.end = await page.evaluate(() => performance.now());
    run.longestTaskMs = Math.max(0, ...run.longTasks.map((t) => t.ms));
    if (trace) {
      run.traced = explain(await traceStop(trace), anchor);
    }
    if (config.stills) {
      // still frames of the same scene: the camera turned about its view-up by 2 degrees each,
      // every frame awaited at its full level (the frames' own times, as the drag's)
      const stills = await turnStills(page, config.stills);
      run.still = { frameMs: median(stills.map((f) => f.ms)), frames: stills.length,
        levels: [...new Set(stills.map((f) => (path === "gpu" ? f.gpuLevel : f.cpuLevel)))],
        sampleDistances: [...new Set(stills.map((f) => f.sampleDistance))] };
    }
    // Each further wait of dragAfterMs: the scene changed again (each value 10 up, so that every
    // level is to be built anew), settled, that long idle, then the same drag: its first frame
    // (run.laterDrags) against the first drag's, begun at once.
    for (const [k, wait] of afterMs.slice(1).entries()) {
      if (!config.surfaces) {
        break;
      }
      const moved = config.surfaces.map((s) => Object.assign({}, s, { value: s.value + 10 * (k + 1) }));
      await page.evaluate((surfaces) => window.mediso.setSurfaces(surfaces), moved);
      await page.waitForFunction(() => window.mediso.stats().settled !== false, null, { timeout: 300000 });
      await page.waitForTimeout(wait);
      const later = await dragOnce(page, path, {});
      run.laterDrags = (run.laterDrags || []).concat([{ afterMs: wait, first: later.first,
        steadyMs: later.steadyMs, dragPrepared: later.dragPrepared }]);
    }
    run.stats = await page.evaluate(() => window.mediso.stats());
    // every frame the page drew (its log keeps the last 200), in order, as the frame-time model
    // observed them: what each drew, its time, its pyramid build and its prediction
    run.allFrames = ((await framesSince(page, { length: 0, seq: 0 })) || []).map((f) => ({
      seq: f.seq, interactive: f.interactive, settled: f.settled, gpuLevel: f.gpuLevel, cpuLevel: f.cpuLevel,
      sampleDistance: f.sampleDistance, primitives: f.primitives, triangles: f.triangles, ms: f.ms,
      buildMs: f.buildMs, programsCompiled: f.programsCompiled, pyramidBuilt: f.pyramidBuilt, predictedMs: f.predictedMs,
      values: f.values }));
    console.log(JSON.stringify({ page: name, path, first: median(run.changes.map((c) => c.firstMs)),
      drag: run.drag.frameMs, still: run.still ? run.still.frameMs : null, longest: run.longestTaskMs }));
    result.runs.push(run);
    await page.close();
  }
}
writeFileSync(outFile, JSON.stringify(result, null, 1));
await browser.close();
