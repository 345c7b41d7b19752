// SPDX-License-Identifier: BSD-3-Clause
// The page's viewer in a worker (issue 30; docs/web.md, The worker), in Chromium (SwiftShader):
// - the worker path draws the CPU path's triangles of the main-thread path at every level, and
//   the GPU path's primitives are the CPU model's count;
// - a change is drawn first at a coarse level and refined to the full level (?frameBudget=1: no
//   level fits 1 ms, so the first answer is level 0);
// - a change superseded while its refinement is owed never shows the old surface at the end,
//   and the refinement is skipped;
// - a drag draws coarser (CPU path: a level, then level 0 on fewer pixels; GPU path: an image
//   sample distance and a coarse volume level, the volume sampled every 2nd, 4th, 8th or 16th
//   point, whose primitives are the CPU model's count on that level's samples), says so in
//   window.mediso.stats(), and the still frame after it is back at full level and every pixel;
// - on the GPU path a change is drawn first on a coarse volume level (its primitives the CPU
//   model's count on the level's samples) and refined to the full volume, and a change superseded
//   while that refinement is owed is never refined.
// How long the main thread is busy is a timing, so it is measured by the benchmark
// (Python/benchmark_web.py --interactive: the longest main-thread task, PerformanceObserver
// "longtask"), not asserted here.
import { Checks, installIsovalueTyping, launchBrowser, framesAfter, lastFrameSeq, openInContext, pageStats,
  startServer }
  from "./webserver-harness.mjs";

const checks = new Checks();
const small = await startServer(["phantom:64"]);
const browser = await launchBrowser();

// The page, with `query` after the token.
const open = (server, query) => openInContext(browser, server.url + query);
const stats = pageStats;
const settle = (page) => page.waitForFunction(() => window.mediso.stats().settled, null, { timeout: 120000 });
const BONE = { value: 400, color: [1, 1, 1], opacity: 1 };

// --- counts: the worker against the main thread and the CPU model ----------------------------------
const worker = await open(small, "&path=cpu");
const main = await open(small, "&path=cpu&worker=0");
checks.check((await stats(worker)).renderer === "worker" && (await stats(main)).renderer === "main",
  "the page draws in a worker where it can, on the main thread with ?worker=0");
checks.check(/worker/.test(await worker.locator("#renderer").textContent()) &&
  /main thread/.test(await main.locator("#renderer").textContent()), "the page says where it draws");
const mainCounts = {};
for (const page of [worker, main]) {
  await page.evaluate((s) => window.mediso.setSurfaces([s]), BONE);
}
for (const level of [0, 1, 2, 3]) {
  const w = await worker.evaluate((k) => window.mediso.setCPULevel(k), level);
  const m = await main.evaluate((k) => window.mediso.setCPULevel(k), level);
  mainCounts[level] = m.triangles;
  checks.check(w.cpuLevel === level && m.cpuLevel === level && w.triangles === m.triangles && w.triangles > 0,
    "level " + level + ": the worker's triangles (" + w.triangles + ") are the main thread's (" + m.triangles + ")");
}
{
  const gpu = await worker.evaluate(() => window.mediso.setPath("gpu"));
  const count = await worker.evaluate((v) => window.mediso.cpuCount([v]), BONE.value);
  checks.check(gpu.path === "gpu" && gpu.primitives === count && count > 0,
    "GPU path in the worker: primitives " + gpu.primitives + " = the CPU model's count " + count);
}
await worker.close();

// --- refinement: a coarse first answer, then the full level ------------------------------------------
// ?refineDelay=2000: a coarse frame's refinement waits 2 s before it begins (40 ms otherwise), so
// that the superseding change below surely comes first, however loaded the machine (a running
// refinement would be aborted instead: TestWebServerPageWorkerAbort). ?prepareDrag=1: the GPU
// drag's level made ready after a settled frame (off by default; checked below).
const fast = await open(small, "&path=cpu&frameBudget=1&refineDelay=2000&prepareDrag=1");
await fast.evaluate(() => window.mediso.setCPULevel(-1));
{
  const before = await lastFrameSeq(fast);
  const s = await fast.evaluate((v) => window.mediso.setSurfaces([Object.assign({}, v, { value: 300 })]), BONE);
  const steps = await framesAfter(fast, before);
  const m = await main.evaluate(() => window.mediso.setSurfaces([{ value: 300, color: [1, 1, 1], opacity: 1 }]));
  const full = await main.evaluate(() => window.mediso.setCPULevel(3));
  console.log("refinement frames [values, level, settled, predicted ms]: " +
    JSON.stringify(steps.map((f) => [f.values, f.cpuLevel, f.settled, Math.round(f.predictedMs * 10) / 10])));
  checks.check(steps.length >= 2 && steps[0].values[0] === 300 && steps[0].cpuLevel < 3 && !steps[0].settled,
    "a change is drawn first at a coarse level (" + (steps[0] || {}).cpuLevel + ") within a 1 ms budget");
  checks.check(s.settled && s.cpuLevel === 3 && s.triangles === full.triangles && m.path === "cpu",
    "the refinement reaches the full level: level " + s.cpuLevel + ", " + s.triangles + " triangles (" +
    full.triangles + " drawn at level 3 on the main thread)");
}

// --- a change superseded while its refinement is owed ---------------------------------------------
// `first` typed in the first isovalue box, then, once its coarse frame is shown and its refinement
// owed, `second`; waits for the frame of `second` settled, and 300 ms more (nothing owed may still
// come). The frames from `first` on, the stats after, and the refinements skipped before.
async function supersede(page, first, second) {
  const skippedBefore = (await stats(page)).refinementsSkipped;
  const before = await lastFrameSeq(page);
  await installIsovalueTyping(page);
  await page.evaluate(async ([a, b]) => {
    window.medisoTyping.type(a);
    await window.medisoTyping.waitFor((f) => f.values[0] === a);
    window.medisoTyping.type(b);
  }, [first, second]);
  await page.waitForFunction((b) => {
    const f = window.mediso.frames();
    return f.length && f[f.length - 1].values[0] === b && f[f.length - 1].settled;
  }, second, { timeout: 120000 });
  await page.waitForTimeout(300);
  return { skippedBefore, steps: await framesAfter(page, before), s: await stats(page) };
}
{
  const { skippedBefore, steps, s } = await supersede(fast, 250, 350);
  const m = await main.evaluate(() => window.mediso.setSurfaces([{ value: 350, color: [1, 1, 1], opacity: 1 }]));
  console.log("superseded frames [values, level, settled, predicted ms]: " +
    JSON.stringify(steps.map((f) => [f.values, f.cpuLevel, f.settled, Math.round(f.predictedMs * 10) / 10])));
  checks.check(steps.length && steps[0].values[0] === 250 && steps[0].cpuLevel < 3 && !steps[0].settled,
    "the older change is drawn first at a coarse level (" + (steps[0] || {}).cpuLevel + "), its refinement owed");
  const last = steps[steps.length - 1];
  checks.check(last.values[0] === 350 && last.settled && last.cpuLevel === 3 && s.triangles === m.triangles,
    "the last frame is the newer change's surface at the full level (" + s.triangles + " triangles, " +
    m.triangles + " on the main thread)");
  checks.check(!steps.some((f) => f.values[0] === 250 && f.settled),
    "the superseded change's surface is never refined nor shown after the newer one");
  checks.check(s.refinementsSkipped > skippedBefore,
    "the superseded refinement was skipped (" + skippedBefore + " -> " + s.refinementsSkipped + ")");
}

// --- a drag: coarser while it lasts, the full frame after it --------------------------------------------
async function drag(page, moves = 12) {
  const box = await page.locator("#view").boundingBox();
  const x = box.x + box.width / 2, y = box.y + box.height / 2;
  await page.mouse.move(x, y);
  await page.mouse.down();
  const during = [];
  for (let i = 1; i <= moves; ++i) {
    await page.mouse.move(x + 6 * i, y + 2 * i);
    await page.waitForTimeout(40);
    during.push(await stats(page));
  }
  await page.mouse.up();
  return during;
}
{
  const before = await lastFrameSeq(fast);
  const during = await drag(fast);
  await settle(fast);
  await fast.waitForTimeout(200);
  const steps = await framesAfter(fast, before);
  const s = await stats(fast);
  const coarse = steps.filter((f) => f.interactive && f.cpuLevel < 3);
  const said = during.find((d) => d.interactive && d.cpuLevel < 3 && /dragging/.test(d.frameNote));
  checks.check(coarse.length > 0 && !!said, "CPU path: " + coarse.length + " of the drag's " +
    steps.filter((f) => f.interactive).length + " frames at a coarser level, said in stats(): " +
    JSON.stringify(said && { interactive: said.interactive, cpuLevel: said.cpuLevel, frameNote: said.frameNote }));
  // A 1 ms budget: no frame fits, so the drag ends on the CPU path's coarsest candidate, level 0
  // on one pixel in 8 along each axis, and says so; a change's first answer is never sampled.
  const sampledDrag = steps.filter((f) => f.interactive && f.cpuLevel === 0 && f.sampleDistance === 8);
  const saidSampled = during.find((d) => d.interactive && /one pixel in 8/.test(d.frameNote));
  checks.check(sampledDrag.length > 0 && !!saidSampled &&
    steps.every((f) => f.interactive || f.sampleDistance === 1),
    "CPU path: " + sampledDrag.length + " of the drag's frames at level 0 on one pixel in 8, said in stats(): " +
    JSON.stringify(saidSampled && saidSampled.frameNote) + "; frames not of the drag at every pixel");
  checks.check(!s.interactive && s.settled && s.cpuLevel === 3 && s.sampleDistance === 1,
    "CPU path: the still frame after the drag is at level " + s.cpuLevel + ", sample distance " + s.sampleDistance);
}
{
  // The first GPU frame of these isovalues is the full volume's (the change was on the CPU path);
  // the drag's level (volume level -1: no frame fits 1 ms) is made ready after it, in the worker's
  // idle time (stats().dragPrepared), so the drag's first frame builds no pyramid (before, it
  // built that level's pyramid and first used its programs: seconds on a loaded machine).
  const preparedBefore = (await stats(fast)).dragPreparedCount || 0;
  const switched = await fast.evaluate(() => window.mediso.setPath("gpu"));
  const prepared = await fast.waitForFunction((n) => window.mediso.stats().dragPreparedCount > n,
    preparedBefore, { timeout: 120000 }).then(() => stats(fast), () => null);
  const before = await lastFrameSeq(fast);
  const during = await drag(fast, 16);
  await settle(fast);
  await fast.waitForTimeout(200);
  const steps = await framesAfter(fast, before);
  const s = await stats(fast);
  const sampled = steps.filter((f) => f.interactive && f.sampleDistance > 1);
  const said = during.find((d) => d.interactive && d.sampleDistance > 1);
  checks.check(sampled.length > 0 && !!said, "GPU path: " + sampled.length + " of the drag's frames at " +
    "an image sample distance above 1 (largest " + Math.max(1, ...steps.map((f) => f.sampleDistance)).toFixed(2) +
    "), said in stats()");
  checks.check(!s.interactive && s.sampleDistance === 1, "GPU path: the still frame after the drag has every pixel");
  // A 1 ms budget: no frame fits, so the drag draws the coarsest candidate, volume level -1 (the
  // volume sampled every 16th point; below level 0, the coarsest Block LOD level).
  const level = steps.filter((f) => f.interactive && f.gpuLevel < 3);
  const saidLevel = during.find((d) => d.interactive && d.gpuLevel === -1 &&
    /volume level -1, one point in 16 along each axis/.test(d.frameNote));
  const last = level[level.length - 1];
  const coarseCount = last ? await fast.evaluate(([v, k]) => window.mediso.cpuCount(v, k),
    [last.values, last.gpuLevel]) : -1;
  const fullCount = await fast.evaluate((v) => window.mediso.cpuCount(v), steps[steps.length - 1].values);
  console.log("GPU drag frames [gpuLevel, sampleDistance, primitives]: " +
    JSON.stringify(steps.map((f) => [f.gpuLevel, f.sampleDistance, f.primitives])));
  checks.check(level.length > 0 && !!saidLevel && last.gpuLevel === -1,
    "GPU path: " + level.length + " of the drag's frames on a coarse volume level (" + (last || {}).gpuLevel +
    "), said in stats(): " + JSON.stringify(saidLevel && { gpuLevel: saidLevel.gpuLevel, frameNote: saidLevel.frameNote }));
  checks.check(last && last.primitives === coarseCount && coarseCount > 0 && coarseCount < fullCount,
    "GPU path: a coarse frame's primitives (" + (last || {}).primitives + ") are the CPU model's count on " +
    "the level's samples (" + coarseCount + "; the volume's: " + fullCount + ")");
  checks.check(s.gpuLevel === 3 && s.primitives === fullCount,
    "GPU path: the still frame after the drag draws the full volume (level " + s.gpuLevel + ", " +
    s.primitives + " primitives)");
  const firstDrag = steps.find((f) => f.interactive) || {};
  const made = (prepared || {}).dragPrepared || {};
  console.log("GPU drag made ready: " + JSON.stringify(made) + "; its first frame: " +
    JSON.stringify({ gpuLevel: firstDrag.gpuLevel, sampleDistance: firstDrag.sampleDistance,
      pyramidBuilt: firstDrag.pyramidBuilt, ms: firstDrag.ms }));
  checks.check(switched.gpuLevel === 3 && made.level === -1 &&
    JSON.stringify(made.values) === JSON.stringify(firstDrag.values) &&
    firstDrag.gpuLevel === made.level && firstDrag.pyramidBuilt === false,
    "GPU path: the drag's level (" + made.level + ") was made ready for these isovalues after the still " +
    "frame, and the drag's first frame (level " + firstDrag.gpuLevel + ") built no pyramid (" +
    firstDrag.pyramidBuilt + ")");
  // In steps, each in a task of its own (the worker reads its messages between them, so that a
  // drag that comes meanwhile waits for one step only): the level's pyramid, then its programs.
  checks.check(JSON.stringify((made.steps || []).map((t) => [t.step, t.level])) ===
    JSON.stringify([["pyramid", -1], ["programs", -1]]) && made.longestStepMs <= made.ms,
    "GPU path: the drag's level was made in two steps, its pyramid then its programs: " +
    JSON.stringify(made.steps));
}

// --- the GPU path's change: a coarse volume level first, then the full volume ------------------------
// ?frameBudget=1: no frame fits 1 ms, so a change's first answer is the coarsest candidate (volume
// level -1: its pyramid built, not the volume's); the refinement builds and draws the full volume.
{
  const before = await lastFrameSeq(fast);
  const s = await fast.evaluate((v) => window.mediso.setSurfaces([Object.assign({}, v, { value: 300 })]), BONE);
  const steps = await framesAfter(fast, before);
  const first = steps[0] || {};
  const coarseCount = Number.isInteger(first.gpuLevel) ? await fast.evaluate(([v, k]) => window.mediso.cpuCount(v, k),
    [[300], first.gpuLevel]) : -1;
  const fullCount = await fast.evaluate(() => window.mediso.cpuCount([300]));
  console.log("GPU change frames [values, gpuLevel, sampleDistance, primitives, settled]: " +
    JSON.stringify(steps.map((f) => [f.values, f.gpuLevel, f.sampleDistance, f.primitives, f.settled])));
  checks.check(first.values && first.values[0] === 300 && first.gpuLevel < 3 && !first.settled &&
    !first.interactive && first.primitives === coarseCount && coarseCount > 0,
    "GPU path: a change is drawn first on a coarse volume level (" + first.gpuLevel + ", " + first.primitives +
    " primitives; the CPU model's count on its samples: " + coarseCount + ")");
  checks.check(s.settled && s.gpuLevel === 3 && s.sampleDistance === 1 && s.primitives === fullCount,
    "GPU path: the refinement reaches the full volume (level " + s.gpuLevel + ", " + s.primitives +
    " primitives; the CPU model's count: " + fullCount + ")");
}
// A change typed while that refinement is owed: the old one is skipped, the newer one refined.
{
  const { skippedBefore, steps, s } = await supersede(fast, 250, 350);
  const fullCount = await fast.evaluate(() => window.mediso.cpuCount([350]));
  console.log("GPU superseded frames: " + JSON.stringify(steps.map((f) => [f.values, f.gpuLevel, f.settled])));
  checks.check(steps.length > 0 && steps[0].values[0] === 250 && steps[0].gpuLevel < 3 &&
    !steps.some((f) => f.values[0] === 250 && (f.settled || f.gpuLevel === 3)),
    "GPU path: the superseded change was drawn coarse only, never refined");
  checks.check(s.settled && s.gpuLevel === 3 && s.primitives === fullCount && s.refinementsSkipped > skippedBefore,
    "GPU path: the newer change ends on the full volume (" + s.primitives + " primitives, " + fullCount +
    " by the CPU model), the older refinement skipped (" + skippedBefore + " -> " + s.refinementsSkipped + ")");
}

// --- a GPU drag whose first frame outlasts the drag ------------------------------------------------
// The first drag frame on a volume level builds that level's pyramid and first uses its programs:
// on a loaded machine seconds, longer than the whole drag. ?slowFirstDragFrame=3000 makes it so:
// stats().settled must stay false until the frame after the drag is drawn (it said true from the
// frame before the drag, and a test that waited for it found none of the drag's frames), and the
// drag's late frame comes before the still frame.
{
  const slow = await open(small, "&path=gpu&frameBudget=1&slowFirstDragFrame=3000");
  await slow.evaluate((s) => window.mediso.setSurfaces([s]), BONE);
  const before = await lastFrameSeq(slow);
  // Asked for and read in one task of the page, so its answer cannot have come in between.
  const owed = await slow.evaluate(() => {
    document.dispatchEvent(new KeyboardEvent("keydown", { key: "ArrowLeft" }));
    return window.mediso.stats().settled;
  });
  checks.check(owed === false, "a frame asked for and not yet drawn: stats().settled is " + owed);
  await settle(slow);
  await slow.waitForFunction((n) => window.mediso.frames().some((f) => f.seq > n), before); // the turn's frame
  const turned = await lastFrameSeq(slow);
  await drag(slow, 6);
  await settle(slow);
  const steps = await framesAfter(slow, turned);
  const s = await stats(slow);
  console.log("slow GPU drag frames [interactive, gpuLevel, sampleDistance, settled]: " +
    JSON.stringify(steps.map((f) => [f.interactive, f.gpuLevel, f.sampleDistance, f.settled])));
  const last = steps[steps.length - 1] || {};
  checks.check(steps.some((f) => f.interactive && f.gpuLevel < 3) &&
    !last.interactive && last.settled && last.gpuLevel === 3 && s.settled && !s.interactive,
    "GPU path, a drag whose first frame outlasts it: " + steps.filter((f) => f.interactive).length +
    " drag frame(s), then the still frame (level " + last.gpuLevel + "), before stats() says settled");
  await slow.close();
}

await checks.finish(browser, small);
