// SPDX-License-Identifier: BSD-3-Clause
// The page's renderer off the main thread (docs/web.md, The worker): the WebAssembly module and
// its WebViewer run here, drawing into the page's canvas handed over as an OffscreenCanvas, so
// that an extraction or a slow software frame never holds the page's main thread (input, the
// panel, typing). The main thread keeps the camera (ViewCamera, the same C++ camera) and the
// volume's values, and sends what changes; this worker answers every frame with the viewer's
// stats. A classic worker, not a module: it loads the Emscripten module with importScripts.
//
// Messages in (each applied in the order sent):
//   {op: "load", threads}                                begin loading the module (index.html)
//   {op: "init", canvas, base, threads}                 load the module (unless begun), make the viewer
//   {op: "call", method, args, id?}                      a WebViewer call; with id, its answer
//   {op: "volume", type, bytes, dims, spacing, origin}   the volume's values (transferred)
//   {op: "mesh", points, triangles, color, opacity}      a surface the server made
//   {op: "stream", type, dims, spacing, origin, brick, coarse}, {op: "bricks", ids, body, predictor},
//   {op: "streamEnd", id}                                streaming (stream.js, startStream here;
//                                                        streamEnd answers the level's bytes)
//   {op: "frame", id, surfaces, view, interactive, generation}  the frame wanted now
// Messages out: {op: "ready", ok, error, info, generation, startup}, {op: "answer", id, value},
//   {op: "frame", id, stats, settled}, {op: "error", message},
//   {op: "prepared", value, count} (a drag's frame made ready ahead: before a GPU change's
//   refinement, refineNow, or with ?prepareDrag=1 after a settled frame, schedulePrepare).
//
// Frames. Only the newest frame wanted is drawn: messages that arrived while a frame was drawn
// are all applied first, and the frames they asked for collapse into the last one. On the CPU
// path, with the estimator choosing the level (setCPULevel(-1)), a new set of isovalues is drawn
// first at the finest level whose predicted frame fits the frame budget, and refined to the
// level the memory budget allows in a later task (the GPU path likewise: first on the volume
// level and sample distance whose pyramid build and frame fit, then the full volume), which a
// newer change makes obsolete: the
// refinement is then skipped (counted in stats.refinementsSkipped); one already running is
// aborted where the page is cross-origin isolated (the generation word, below; counted in
// stats.refinementsAborted), else it runs to its end. During a drag
// (interactive: true) the same coarse level is drawn; the still frame after it is the full one.
"use strict";

let M = null;
let viewer = null;
let wanted = null; // the newest frame asked for, not drawn yet
let refine = null; // {id, surfacesKey}: the full-level frame owed after a coarse one
let scheduled = false;
let requestedLevel = -1; // the page's setCPULevel (-1: the estimator's, within the budget)
let path = "gpu";
let shownKey = ""; // the isovalues of the last frame drawn
let skipped = 0;
let volumeBytes = 0; // the pointer of the volume in this module's memory
let streaming = false; // stream.js's bricks are arriving: each surface at level 0 or 3, no coarse first answer
let coarseBytes = 0; // the pointer of the streamed level 0
let streamGrid = null; // {dims, brick, size, length, scratch}: the streamed level (writeBricks)
let streamTimes = null; // where a stream's time goes in this worker (noteStreamFrame; stats().streamTimes)

// The generation word (an Int32Array of one, shared with the page's main thread, which adds one
// to it on every new set of isovalues and every drag frame before it sends the frame): a running
// refinement whose frame's generation is no longer the word's is obsolete, and the module's
// abort stops it between blocks. null where the page is not cross-origin isolated (no
// SharedArrayBuffer): a refinement begun then runs to its end.
let generationWord = null;
let aborted = 0;
let abortNote = ""; // what stats() says about it
// Without the word, the page's ?slowExtraction=MS holds each refinement MS before it draws, the
// worker not reading its messages meanwhile, as a long refinement would (a test hook: a newer
// change then surely comes while a refinement runs, however fast or loaded the machine).
let unwatchedRefinementMs = 0;

// The canvas's new size, applied with the next frame drawn: resizing clears the canvas, and a
// worker's OffscreenCanvas is shown at the end of each of its tasks, so a resize in one task and
// its frame in a later one showed a blank canvas of the new size in between (a test that read
// the view once its size had followed found nothing drawn).
let pendingSize = null;

function applySize() {
  if (pendingSize) {
    viewer.resize(...pendingSize);
    pendingSize = null;
  }
}

// The frame budget of interactive frames and of a change's first frame (the page's
// ?frameBudget=MS, else 100 ms), and how long a coarse frame waits before its refinement starts,
// so that the next change of a burst (typing, a slider) finds it not yet begun (the page's
// ?refineDelay=MS, a test hook: a test's next change then surely comes before it begins).
let budgetSeconds = 0.1;
let refineDelayMs = 40;
// The first frame of a drag is shown this much later (the page's ?slowFirstDragFrame=MS, a test
// hook): on the GPU path that frame builds its volume level's pyramid and first uses its
// programs, which took seconds on a loaded machine, longer than the whole drag.
let slowFirstDragFrameMs = 0;
let dragging = false; // the last frame drawn was a drag's

// The GPU frame a drag would be drawn as, made ready (WebViewer.prepareDragStep: its volume
// level's pyramid built for the current isovalues, its programs compiled, nothing shown), so
// that the first drag frame after a change does not pay for them: {level, sampleDistance, ms,
// longestStepMs, steps, values} of the last time it made anything, and how many times it did.
// When (the page's ?prepareDrag=):
// - "refine" (the default: any value but "0" and "1"): after a GPU change's first answer, before
//   its refinement (refineNow), in steps of their own. A drag begun the moment the refinement
//   settles then finds its level made: on the 512^3 phantom its first frame compiled volume
//   level -1's program for the scene's looks for 0.6 s (docs/web.md, "A drag begun the moment
//   the refinement settles"). The refinement (the full volume's build, seconds) waits for the
//   steps, which are what that drag's first frame would otherwise do.
// - "1": in the idle time after a settled frame (schedulePrepare). A drag begun soon after the
//   settled frame waited for it (0.7 s on the head CT at 1024x768 on SwiftShader), and one begun
//   at once found nothing made yet.
// - "0": never; the drag's first frame is chosen on its whole frame (ChooseOnWholeFrame).
let prepareDragOn = false;
let prepareBeforeRefine = true;
let prepared = null;
let preparedCount = 0;
let prepareTimer = 0;

function post(message, transfer) {
  self.postMessage(message, transfer || []);
}

// The worker's start-up (the page's marks "mediso:worker-*", docs/web.md "The page's start-up"):
// this script running, index.html's load message in, the module's wasm asked for, the init
// message in, the module's script loaded, the module compiled and instantiated (its wasm
// fetched), the viewer made (the WebGL2 context, the probe); the epoch's ms.
const startup = { script: performance.timeOrigin + performance.now() };

// The module (threaded or not), loading: begun by "load" (index.html starts this worker before
// the page's modules have arrived, docs/web.md "The page's start-up") or else by "init".
let loading = null;
function load(base, threads) {
  if (!loading) {
    loading = (async () => {
      const name = threads ? "mediso-mt" : "mediso";
      // The module's wasm asked for now, beside its script (which importScripts waits for), not
      // after it: one round trip less on the first image's path (docs/web.md, "The first image
      // at 30 Mbit/s: the third pass"). Compiled as it arrives, as the module would.
      const wasm = fetch(base + name + ".wasm", { credentials: "same-origin" });
      wasm.catch(() => {}); // said by instantiate's fallback
      startup.wasm = now();
      importScripts(base + name + ".js");
      startup.imported = now();
      const create = threads ? self.createMedisoThreads : self.createMediso;
      let failed = null;
      const failure = new Promise((resolve, reject) => { failed = reject; });
      const instantiate = (imports) => wasm
        .then((response) => WebAssembly.instantiateStreaming(response, imports))
        .catch(() => fetch(base + name + ".wasm", { credentials: "same-origin" })
          .then((response) => response.arrayBuffer())
          .then((bytes) => WebAssembly.instantiate(bytes, imports)));
      const module = await Promise.race([failure, create({ locateFile: (f) => base + f,
        mainScriptUrlOrBlob: base + name + ".js",
        // Emscripten's hook: the exports come later, through `done`.
        instantiateWasm: (imports, done) => {
          instantiate(imports).then((result) => done(result.instance, result.module), failed);
          return {};
        } })]);
      startup.module = now();
      return module;
    })();
    loading.catch(() => {}); // "init" awaits it and says why
  }
  return loading;
}

async function init(m) {
  startup.init = now();
  M = await load(m.base, m.threads);
  if (!M.specialHTMLTargets) {
    post({ op: "ready", ok: false, error: "the module cannot be given an OffscreenCanvas" });
    return;
  }
  M.specialHTMLTargets["#view"] = m.canvas;
  if (m.budgetMs > 0) {
    budgetSeconds = m.budgetMs / 1000;
  }
  if (m.refineDelayMs > 0) {
    refineDelayMs = m.refineDelayMs;
  }
  if (m.slowFirstDragFrameMs > 0) {
    slowFirstDragFrameMs = m.slowFirstDragFrameMs;
  }
  prepareDragOn = m.prepareDrag === "1" || m.prepareDrag === true;
  prepareBeforeRefine = !prepareDragOn && m.prepareDrag !== "0" && m.prepareDrag !== false;
  viewer = new M.WebViewer("#view");
  startup.viewer = now();
  shareGeneration(m.abort !== false, m.slowExtractionMs, m.slowPass);
  post({ op: "ready", ok: viewer.ready(), error: viewer.error(), info: viewer.info(),
    generation: generationWord, startup });
}

// The generation word: in the threaded module's (shared) memory, where the module reads it from
// any of its threads; else, where this worker may make a SharedArrayBuffer, one of its own,
// which the one-thread module reads on this thread (self.medisoGenerationWord).
// `abort` false: none (the page's ?abort=0, to measure without it); `slowExtractionMs`: the
// page's ?slowExtraction=MS&slowPass=P test hook (WebViewer.setSlowExtraction).
function shareGeneration(abort, slowExtractionMs, slowPass) {
  const address = viewer.ready() ? viewer.generationWord() : 0;
  if (!abort) {
    abortNote = "A refinement that has begun runs to its end (asked for by ?abort=0).";
    unwatchedRefinementMs = slowExtractionMs > 0 ? slowExtractionMs : 0;
    return;
  }
  if (address && M.HEAPU8.buffer instanceof SharedArrayBuffer) {
    generationWord = new Int32Array(M.HEAPU8.buffer, address, 1);
  } else if (!address && self.crossOriginIsolated && typeof SharedArrayBuffer === "function") {
    generationWord = new Int32Array(new SharedArrayBuffer(4));
    self.medisoGenerationWord = generationWord;
  }
  if (generationWord && slowExtractionMs > 0) {
    viewer.setSlowExtraction(slowExtractionMs, slowPass || 1);
  }
  abortNote = generationWord ? "A newer change stops a refinement that is running."
    : "A refinement that has begun runs to its end: the page is not cross-origin isolated " +
      "(no SharedArrayBuffer to tell the worker of a newer change).";
}

function schedule() {
  if (!scheduled) {
    scheduled = true;
    setTimeout(pump, 0);
  }
}

// The frame that fits the budget on this client: WebViewer.chooseFrame, from the cores' frame-time
// model (mediso::FrameTimeModel, fitted from this viewer's frames) and the estimator's seconds of
// an extraction: {level, sampleDistance, predictedMs, fullMs, memoryLevel}.
function choose(frame) {
  applySize();
  viewer.setSurfaces(frame.surfaces);
  viewer.setCPULevel(requestedLevel);
  return viewer.chooseFrame(budgetSeconds, !!frame.interactive);
}

function keyOf(surfaces) {
  return JSON.stringify(surfaces.map((s) => s.value));
}

// Draws `frame` at CPU level `level` (-1: the estimator's within the memory budget), sample
// distance `distance` and GPU volume level `gpuLevel` (the full volume when not given); the
// viewer's stats with the frame's time and what it was.
function draw(frame, level, distance, gpuLevel = M.NumberOfLevels - 1) {
  applySize();
  viewer.setSurfaces(frame.surfaces);
  viewer.setView(frame.view);
  if (path === "cpu") {
    viewer.setCPULevel(level);
  }
  viewer.setSampleDistance(distance);
  viewer.setGPULevel(gpuLevel);
  const start = performance.now();
  const ok = viewer.render();
  if (ok) {
    viewer.finish();
  }
  const ms = performance.now() - start;
  const stats = viewer.stats();
  stats.ok = ok;
  stats.ms = ms;
  stats.values = frame.surfaces.map((s) => s.value);
  stats.refinementsSkipped = skipped;
  stats.refinementsAborted = aborted;
  stats.abortable = !!generationWord;
  stats.abortNote = abortNote;
  stats.budgetMs = 1000 * budgetSeconds;
  stats.dragPrepared = prepared;
  stats.dragPreparedCount = preparedCount;
  if (slowFirstDragFrameMs > 0 && frame.interactive && !dragging) {
    pause(slowFirstDragFrameMs);
  }
  dragging = !!frame.interactive;
  return stats;
}

// Holds this worker for `ms` (slowFirstDragFrameMs): asleep where it may wait on a
// SharedArrayBuffer, else busy.
function pause(ms) {
  if (self.crossOriginIsolated && typeof SharedArrayBuffer === "function") {
    Atomics.wait(new Int32Array(new SharedArrayBuffer(4)), 0, 0, ms);
    return;
  }
  for (const end = performance.now() + ms; performance.now() < end;) {
    // waiting
  }
}

function pump() {
  scheduled = false;
  if (!viewer || !volumeBytes) {
    return;
  }
  if (wanted) {
    const frame = wanted;
    wanted = null;
    cancelPrepare(); // a newer frame: the steps left wait for the next settled one
    const key = keyOf(frame.surfaces);
    if (refine) {
      // A newer frame: a change or a drag makes the owed refinement obsolete (skipped); a still
      // frame of the same surfaces draws the full level itself.
      if (refine.key !== key || frame.interactive) {
        ++skipped;
      }
      clearTimeout(refine.timer);
      refine = null;
    }
    const auto = path === "cpu" && requestedLevel < 0;
    const coarse = auto && !streaming && (frame.interactive || key !== shownKey);
    // The GPU path's change: its first answer on the volume level and sample distance that fit
    // the budget, its pyramid build counted (chooseFrame), the full volume in the refinement.
    const gpuChange = path === "gpu" && !streaming && !frame.interactive && key !== shownKey;
    let level = requestedLevel, distance = 1, gpuLevel = M.NumberOfLevels - 1, note = "";
    let choice = null;
    if (coarse || gpuChange || (path === "gpu" && frame.interactive)) {
      choice = choose(frame);
      level = path === "cpu" ? choice.level : requestedLevel;
      distance = choice.sampleDistance; // CPU path: above 1 only for a drag's level 0
      gpuLevel = path === "gpu" ? choice.level : gpuLevel;
    }
    const stats = draw(frame, level, distance, gpuLevel);
    if (choice) {
      stats.predictedMs = choice.predictedMs;
      const over = "the full frame would take about " + Math.round(choice.fullMs) + " ms on this " +
        "client, over the " + Math.round(1000 * budgetSeconds) + " ms budget";
      if (path === "cpu" && stats.cpuLevel < choice.memoryLevel) {
        note = (frame.interactive ? "While dragging" : "First answer") + ": level " + stats.cpuLevel +
          (distance > 1 ? ", one pixel in " + distance + " along each axis, scaled up" : "") +
          " (" + over + ")" + (frame.interactive ? "." : "; refining.");
      } else if (path === "gpu" && (distance > 1 || stats.gpuLevel < M.NumberOfLevels - 1)) {
        note = (frame.interactive ? "While dragging: " : "First answer: ") +
          gpuFrameNote(stats.gpuLevel, distance) + " (" + over + ")" +
          (frame.interactive ? "." : "; refining.");
      }
    }
    shownKey = key;
    stats.interactive = !!frame.interactive;
    // A coarse level that is the one the memory allows leaves nothing to refine.
    stats.settled = !frame.interactive && (!coarse || stats.cpuLevel >= choice.memoryLevel) &&
      (!gpuChange || (stats.gpuLevel >= M.NumberOfLevels - 1 && distance === 1));
    stats.note = note;
    if (!stats.settled && !frame.interactive && stats.ok) {
      refine = { id: frame.id, key, frame };
      refine.timer = setTimeout(refineNow, refineDelayMs);
    }
    noteStreamFrame(stats);
    post({ op: "frame", id: frame.id, stats });
    if (stats.settled && stats.ok) {
      schedulePrepare(frame);
    }
  }
}

// After a settled GPU frame, in tasks of their own from prepareDelayMs later: the frame a drag
// would be drawn as, made ready (WebViewer.prepareDragStep: its volume level's pyramid in one
// step, its programs in the next), one step per task, so that a frame asked for meanwhile (a
// drag, a change) is read and drawn before the next step, which is then dropped: the next
// settled frame schedules the preparation again, and it goes on from what is made. Before each
// step: dropped where a newer frame is asked for (its message here, or the page's generation word
// moved on, which the page adds to before it sends a drag frame or a change). A drag that comes
// during a step waits for that step only. The delay lets the settled frame reach the page first
// (the worker's canvas is shown after the task that drew it, and a task queued at once could run
// before that) and lets a burst of still frames (keys held, a slider) pass without one.
const prepareDelayMs = 100;
function schedulePrepare(frame) {
  cancelPrepare();
  if (!prepareDragOn || path !== "gpu" || streaming) {
    return;
  }
  const job = { frame, ms: 0, steps: [] };
  prepareTimer = setTimeout(() => prepareStep(job), prepareDelayMs);
}

function cancelPrepare() {
  clearTimeout(prepareTimer);
  prepareTimer = 0;
}

function prepareStep(job) {
  prepareTimer = 0;
  const frame = job.frame;
  if (wanted || refine || scheduled || path !== "gpu" || streaming || superseded(frame)) {
    return;
  }
  if (makeReadyStep(job)) {
    prepareTimer = setTimeout(() => prepareStep(job), 0);
  }
}

// Whether the page asked for a newer frame than `frame` (a change or a drag: it adds to the
// generation word before it sends one), even if its message has not arrived.
function superseded(frame) {
  return !!generationWord && Atomics.load(generationWord, 0) !== (frame.generation | 0);
}

// One step of making the drag's frame ready for job.frame's surfaces (WebViewer.prepareDragStep);
// true when a step is left. The last step says what was made (stats().dragPrepared).
function makeReadyStep(job) {
  const frame = job.frame;
  const r = viewer.prepareDragStep(budgetSeconds);
  if (r.error) {
    post({ op: "error", message: "preparing the drag's frame: " + r.error });
    return false;
  }
  if (r.step) {
    job.ms += r.ms;
    job.steps.push({ step: r.step, level: r.level, ms: r.ms });
  }
  if (!r.done) {
    return true;
  }
  if (job.steps.length) {
    ++preparedCount;
    // ms: this preparation's steps together; longestStepMs: the longest a drag could wait for
    prepared = { level: r.level, sampleDistance: r.sampleDistance, ms: job.ms,
      longestStepMs: Math.max(...job.steps.map((t) => t.ms)), steps: job.steps,
      values: frame.surfaces.map((s) => s.value) };
    post({ op: "prepared", value: prepared, count: preparedCount });
  }
  return false;
}

// What a coarse GPU frame drew: the volume level (every stride-th point) and the sample distance.
function gpuFrameNote(gpuLevel, distance) {
  const parts = [];
  if (gpuLevel < M.NumberOfLevels - 1) {
    parts.push("volume level " + gpuLevel + ", one point in " + M.gpuLevelStride(gpuLevel) +
      " along each axis");
  }
  if (distance > 1) {
    parts.push("one pixel in " + distance + " along each axis, scaled up");
  }
  return parts.join("; ");
}

// The full level owed after a coarse frame (skipped when a newer frame made it obsolete).
function refineNow() {
  if (!refine) {
    return;
  }
  if (wanted) { // a newer frame came in first: pump decides
    return;
  }
  if (prepareBeforeRefine && path === "gpu" && !streaming) {
    // The drag's frame made ready first, a step per task (prepareDragOn's steps, before the
    // refinement instead of after it): a newer frame that comes between steps makes the
    // refinement obsolete (pump) and drops the steps left.
    if (superseded(refine.frame)) {
      return; // the newer frame's message is next; pump skips this refinement
    }
    refine.job = refine.job || { frame: refine.frame, ms: 0, steps: [] };
    if (!refine.job.done) {
      refine.job.done = !makeReadyStep(refine.job);
      refine.timer = setTimeout(refineNow, 0);
      return;
    }
  }
  const { id, frame } = refine;
  refine = null;
  if (unwatchedRefinementMs > 0) {
    pause(unwatchedRefinementMs);
  }
  const stats = drawWatched(frame);
  if (!stats) {
    return; // obsolete: the newer frame's message is next
  }
  stats.interactive = false;
  stats.settled = true;
  stats.note = "";
  noteStreamFrame(stats);
  post({ op: "frame", id, stats });
  if (stats.ok) {
    schedulePrepare(frame);
  }
}

// A refinement's frame drawn with the module watching the generation word: null when a newer
// change made it obsolete while it ran (its extraction stopped, nothing drawn: the coarse frame
// stays on the canvas until the newer change's).
function drawWatched(frame) {
  // The GPU path's refinement (the full volume's pyramid) cannot be stopped once begun (the build
  // is GL passes the module does not poll between); one whose frame a newer change or drag made
  // obsolete before it began is skipped, even when that change's message has not arrived yet.
  if (path === "gpu" && generationWord && Atomics.load(generationWord, 0) !== (frame.generation | 0)) {
    ++skipped;
    return null;
  }
  const watch = !!generationWord && path === "cpu";
  viewer.watchGeneration(watch, watch ? frame.generation | 0 : 0);
  try {
    const stats = draw(frame, -1, 1);
    if (!stats.ok && viewer.aborted()) {
      ++aborted;
      return null;
    }
    return stats;
  } finally {
    viewer.watchGeneration(false, 0);
  }
}

// Streaming (stream.js): the full level's buffer, empty, as the viewer's volume, whose bricks
// arrive later ({op: "bricks"}), and level 0 as its coarse volume.
function startStream(m) {
  for (const p of [volumeBytes, coarseBytes]) {
    if (p) {
      M._free(p);
    }
  }
  const size = M.scalarTypes().find((t) => t.value === m.type).bytes;
  const length = size * m.dims[0] * m.dims[1] * m.dims[2];
  // Zeros where the memory was in use before: the part the heap has just grown by is zero
  // already (WebAssembly's new pages), and writing it would hold the first frame. No point of it
  // is read before its brick arrives (the BlockLOD core's residency; the GPU scene takes the
  // buffer after the last brick: WebViewer's UpdateSceneVolume), so a view of the memory older
  // than a pthread's growth costs nothing.
  const setup = [performance.now()]; // the set-up's steps (streamTimes.setupMs)
  const end = M.HEAPU8.length;
  volumeBytes = M._malloc(length);
  if (volumeBytes && volumeBytes < end) {
    M.HEAPU8.fill(0, volumeBytes, Math.min(end, volumeBytes + length));
  }
  const coarse = new Uint8Array(m.coarse.bytes);
  coarseBytes = M._malloc(coarse.length);
  M.HEAPU8.set(coarse, coarseBytes);
  setup.push(performance.now());
  // Streaming from the start: no BlockLOD ranges read from the empty buffer (setVolume's).
  let ok = viewer.setStreamingVolume(m.type, volumeBytes, m.dims, m.spacing, m.origin, m.brick);
  setup.push(performance.now());
  ok = ok && viewer.setCoarseVolume(m.type, coarseBytes, m.coarse.dims, m.coarse.spacing, m.coarse.origin);
  setup.push(performance.now());
  streaming = ok;
  freeScratch();
  streamGrid = { dims: m.dims, brick: m.brick, size, length, scratch: 0 };
  // setupMs: the buffers allocated, setStreamingVolume, setCoarseVolume
  streamTimes = { begun: now(), batches: 0, bricks: 0, decodeMs: 0, writeMs: 0, firstBricks: 0,
    lastBricks: 0, frames: [], ended: 0, setupMs: setup.slice(1).map((t, i) => t - setup[i]) };
  shownKey = "";
  refine = null;
  post({ op: "answer", id: m.id, value: ok ? "" : viewer.stats().error || "the volume cannot be streamed" });
}

// A batch of bricks as fetched by stream.js (one answer of /api/bricks: the bricks one after the
// other, each as the server encoded it) decoded here, one at a time, into a scratch brick in the
// module's memory and written into the volume (WebViewer.writeBrick): the page's main thread
// does nothing per brick, and the bytes are copied once on their way into the volume.
function writeBricks(m) {
  if (!self.medisoBricks) {
    importScripts("brick-decode.js");
  }
  const g = streamGrid;
  const { decodeBrickInto, ownedBox } = self.medisoBricks;
  if (!g.scratch) {
    g.scratch = M._malloc(g.size * g.brick * g.brick * g.brick);
  }
  const body = new Uint8Array(m.body);
  const t = streamTimes;
  t.firstBricks = t.firstBricks || now();
  let offset = 0;
  for (const id of m.ids) {
    const box = ownedBox(g.dims, g.brick, id);
    const length = g.size * (box[1] - box[0]) * (box[3] - box[2]) * (box[5] - box[4]);
    const start = performance.now();
    // A view taken now: the memory may have grown (and been replaced) since the last brick.
    decodeBrickInto(body.subarray(offset, offset + length), g.size, m.predictor, box,
      new Uint8Array(M.HEAPU8.buffer, g.scratch, length));
    offset += length;
    const decoded = performance.now();
    if (!viewer.writeBrick(id, g.scratch)) {
      throw new Error(viewer.stats().error || "brick " + id + " cannot be written");
    }
    t.decodeMs += decoded - start;
    t.writeMs += performance.now() - decoded;
  }
  ++t.batches;
  t.bricks += m.ids.length;
  t.lastBricks = now();
}

// Where a stream's time goes in this worker, for the page's stats().streamTimes (the streaming
// benchmark's table of parts, docs/web.md): the bricks' decoding and their writing (WebViewer's
// writeBrick: the copy into the volume, the BlockLOD residency and the extraction ahead), the
// first and last batch, and each frame (when it began, its time, the part that made and uploaded
// the surfaces and the upload's own part of it, how many surfaces came from level 0). Times are
// timeOrigin + now(); the page takes them from `begun`, the stream's start, which it saw answered.
function now() {
  return performance.timeOrigin + performance.now();
}

function noteStreamFrame(stats) {
  const t = streamTimes;
  if (t && !t.ended) {
    t.frames.push({ at: now() - stats.ms, ms: stats.ms, buildMs: stats.buildMs || 0,
      uploadMs: stats.uploadMs || 0, triangles: stats.triangles || 0, coarse: (stats.coarse || []).filter(Boolean).length });
  }
  if (t) {
    stats.streamTimes = Object.assign({}, t, { frames: t.frames.slice() });
  }
}

function freeScratch() {
  if (streamGrid && streamGrid.scratch) {
    M._free(streamGrid.scratch);
  }
  streamGrid = null;
}

self.onmessage = async (event) => {
  const m = event.data;
  try {
    if (m.op === "load") {
      startup.load = now();
      load(new URL(".", self.location.href).href, m.threads);
    } else if (m.op === "init") {
      await init(m);
    } else if (m.op === "call") {
      if (m.method === "setPath") {
        path = m.args[0];
      } else if (m.method === "setCPULevel") {
        requestedLevel = m.args[0];
      } else if (m.method === "resize" && volumeBytes) {
        pendingSize = m.args; // the page asks for the frame next (fitCanvas)
        return;
      }
      const value = viewer[m.method](...m.args);
      if (m.id !== undefined) {
        post({ op: "answer", id: m.id, value });
      }
    } else if (m.op === "volume") {
      streaming = false;
      streamTimes = null;
      freeScratch();
      if (coarseBytes) {
        viewer.setCoarseVolume(0, 0, [], [], []);
        M._free(coarseBytes);
        coarseBytes = 0;
      }
      if (volumeBytes) {
        M._free(volumeBytes);
      }
      const bytes = new Uint8Array(m.bytes);
      volumeBytes = M._malloc(bytes.length);
      M.HEAPU8.set(bytes, volumeBytes);
      const ok = viewer.setVolume(m.type, volumeBytes, m.dims, m.spacing, m.origin);
      shownKey = "";
      refine = null;
      post({ op: "answer", id: m.id, value: ok ? "" : viewer.stats().error || "the volume cannot be uploaded" });
    } else if (m.op === "stream") {
      startStream(m);
    } else if (m.op === "bricks") {
      writeBricks(m);
      // A frame asked for before these bricks is drawn now: where bricks come faster than they
      // are written (loopback), its timer's turn came only after the last of them.
      if (scheduled) {
        pump();
      }
    } else if (m.op === "streamEnd") {
      if (streamTimes) {
        streamTimes.ended = now();
      }
      viewer.endStreaming();
      streaming = false;
      const length = streamGrid ? streamGrid.length : 0;
      freeScratch();
      if (coarseBytes) {
        M._free(coarseBytes);
        coarseBytes = 0;
      }
      // The level as it arrived, for the page's own copy (its slices, histogram and CPU count),
      // which the main thread no longer writes brick by brick: one copy, transferred.
      const copy = M.HEAPU8.slice(volumeBytes, volumeBytes + length);
      post({ op: "answer", id: m.id, value: copy.buffer }, [copy.buffer]);
    } else if (m.op === "mesh") {
      const points = M._malloc(m.points.byteLength);
      const triangles = M._malloc(m.triangles.byteLength);
      M.HEAPU8.set(new Uint8Array(m.points.buffer, m.points.byteOffset, m.points.byteLength), points);
      M.HEAPU8.set(new Uint8Array(m.triangles.buffer, m.triangles.byteOffset, m.triangles.byteLength), triangles);
      viewer.setResultMesh(points, m.points.length / 3, triangles, m.triangles.length / 3, m.color, m.opacity);
      M._free(points);
      M._free(triangles);
    } else if (m.op === "frame") {
      wanted = m;
      schedule();
    }
  } catch (error) {
    const message = String(error && error.message || error);
    // A failed start answers the page's wait for "ready" (it then says why it cannot draw).
    post(m.op === "init" ? { op: "ready", ok: false, error: message } : { op: "error", message });
  }
};
