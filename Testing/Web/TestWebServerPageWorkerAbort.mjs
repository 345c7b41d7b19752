// SPDX-License-Identifier: BSD-3-Clause
// A refinement that is running when a newer change comes is stopped (issue 30 point 3; docs/web.md,
// The worker), in Chromium (SwiftShader), in the threaded module (the generation word in its
// shared memory) and the one-thread one (?threads=0: a SharedArrayBuffer of the worker's):
// - ?frameBudget=1 draws a change at level 0 first; ?slowExtraction=MS makes the refinement that
//   follows last at least MS (it waits, still watching, in its plan, or with &slowPass=2 before
//   it writes the surface), so that the newer change surely finds it running in that pass,
//   whatever the machine's speed;
// - the newer change, typed into the isovalue box while it runs, stops it: stats().refinementsAborted
//   counts it, the obsolete surface is never shown at a finer level, and the worker draws the newer
//   change without waiting for the old refinement's end;
// - the newer change ends at level 3 with the triangles of level 3 on the main-thread page (the
//   same core, not in a worker);
// - without the generation word (?abort=0, as on a page that is not cross-origin isolated),
//   stats() says a refinement runs to its end, and it does (the hook then holds the refinement in
//   the worker, which reads no message meanwhile).
import { Checks, installIsovalueTyping, launchBrowser, framesAfter, lastFrameSeq, openInContext, pageStats,
  startServer } from "./webserver-harness.mjs";

const checks = new Checks();
const server = await startServer(["phantom:64"]);
const browser = await launchBrowser();
const SLOW_MS = 6000;

const open = (query) => openInContext(browser, server.url + query);
const stats = pageStats;

// The main thread's triangles at level 3 (the reference).
const main = await open("&path=cpu&worker=0");
await main.evaluate(() => window.mediso.setCPULevel(3));
const reference = await main.evaluate(() =>
  window.mediso.setSurfaces([{ value: 350, color: [1, 1, 1], opacity: 1 }]));

const MODES = { "threaded module": "", "one-thread module": "&threads=0",
  "threaded module, aborted while writing the surface": "&slowPass=2" };
for (const [name, mode] of Object.entries(MODES)) {
  const page = await open("&path=cpu&frameBudget=1&slowExtraction=" + SLOW_MS + mode);
  await page.evaluate(() => window.mediso.setCPULevel(-1));
  // One surface, as on the main thread; resolves once it is refined (the hook's time).
  await page.evaluate(() => window.mediso.setSurfaces([{ value: 300, color: [1, 1, 1], opacity: 1 }]));
  const s0 = await stats(page);
  checks.check(s0.renderer === "worker" && s0.abortable === true && /stops/.test(s0.abortNote),
    name + ": the worker can stop a running refinement (cross-origin isolated): " +
    JSON.stringify({ renderer: s0.renderer, abortable: s0.abortable, abortNote: s0.abortNote }));
  const before = await lastFrameSeq(page);
  await installIsovalueTyping(page);
  const timing = await page.evaluate(async () => {
    const { type, waitFor } = window.medisoTyping;
    type(250);
    await waitFor((f) => f.values[0] === 250);
    // The coarse frame of 250 is shown; its refinement starts 40 ms later and lasts the hook's
    // time at least: a second from now it is running.
    await new Promise((resolve) => setTimeout(resolve, 1000));
    const typed = performance.now();
    type(350);
    await waitFor((f) => f.values[0] === 350);
    return { firstMs: performance.now() - typed };
  });
  await page.waitForFunction(() => {
    const f = window.mediso.frames();
    return f.length && f[f.length - 1].values[0] === 350 && f[f.length - 1].settled;
  }, null, { timeout: 120000 });
  await page.waitForTimeout(300); // nothing owed may still come
  const steps = await framesAfter(page, before);
  const s = await stats(page);
  console.log(name + ": frames " + JSON.stringify(steps.map((f) => [f.values, f.cpuLevel, f.settled])) +
    "; the newer change's first frame " + Math.round(timing.firstMs) + " ms after it");
  const abortedNow = s.refinementsAborted - s0.refinementsAborted;
  const skippedNow = s.refinementsSkipped - s0.refinementsSkipped;
  checks.check(abortedNow === 1 && skippedNow === 0,
    name + ": the running refinement was aborted, not skipped (aborted " + abortedNow +
    ", skipped " + skippedNow + ")");
  checks.check(steps.some((f) => f.values[0] === 250 && f.cpuLevel === 0) &&
    !steps.some((f) => f.values[0] === 250 && (f.settled || f.cpuLevel > 0)),
    name + ": the obsolete change was shown at level 0 only, never refined");
  // Its refinement would have lasted SLOW_MS: the newer change's first frame came before.
  checks.check(timing.firstMs < SLOW_MS,
    name + ": the worker went on to the newer change at once (" + Math.round(timing.firstMs) +
    " ms, the old refinement would have lasted " + SLOW_MS + " ms)");
  const last = steps[steps.length - 1];
  checks.check(last.values[0] === 350 && last.settled && last.cpuLevel === 3 &&
    s.triangles === reference.triangles && s.triangles > 0,
    name + ": the newer change ends at level 3 with " + s.triangles + " triangles (" +
    reference.triangles + " at level 3 on the main thread)");
  await page.context().close();
}

// Without the word (?abort=0, as where the page is not cross-origin isolated): stats() says a
// refinement runs to its end, and the superseded change's refinement does (no abort counted).
// ?slowExtraction holds each refinement 3 s in the worker before it draws (without the word
// the hook is the worker's), so that the newer change, typed a second after the older one's
// coarse frame, surely comes while the older one's refinement runs.
{
  const page = await open("&path=cpu&frameBudget=1&abort=0&slowExtraction=3000");
  await page.evaluate(() => window.mediso.setCPULevel(-1));
  await page.evaluate(() => window.mediso.setSurfaces([{ value: 300, color: [1, 1, 1], opacity: 1 }]));
  const s0 = await stats(page);
  checks.check(s0.abortable === false && /runs to its end/.test(s0.abortNote),
    "without the word, stats() says a refinement runs to its end: " + JSON.stringify(s0.abortNote));
  const before = await lastFrameSeq(page);
  await installIsovalueTyping(page);
  await page.evaluate(async () => {
    const { type, waitFor } = window.medisoTyping;
    type(250);
    await waitFor((f) => f.values[0] === 250);
    await new Promise((resolve) => setTimeout(resolve, 1000));
    type(350);
  });
  await page.waitForFunction(() => {
    const f = window.mediso.frames();
    return f.length && f[f.length - 1].values[0] === 350 && f[f.length - 1].settled;
  }, null, { timeout: 120000 });
  const steps = await framesAfter(page, before);
  const s = await stats(page);
  const refined = steps.findIndex((f) => f.values[0] === 250 && f.cpuLevel === 3);
  checks.check(s.refinementsAborted === 0 && refined >= 0 && steps.findIndex((f) => f.values[0] === 350) > refined,
    "without the word nothing is aborted and the older change was refined before the newer one was drawn (" +
    JSON.stringify(steps.map((f) => [f.values, f.cpuLevel, f.settled])) + ")");
  await page.context().close();
}

await checks.finish(browser, server);
