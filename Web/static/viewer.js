// SPDX-License-Identifier: BSD-3-Clause
// The renderer glue: the WebAssembly module (Web/wasm/WebViewer.cxx: the GPU core and the
// BlockLOD core compiled for the browser), its viewer on the canvas, and the frames. The module
// also states the facts the page needs of the cores (scalar types, levels of detail and their
// strides, the isovalue limit, the GPU path's memory of a volume), read once into state.facts.

import { fallBackFromGPU } from "./path.js";
import { parsePLY } from "./ply.js";
import { RemoteViewer, offscreenWebGL2 } from "./remote.js";
import { updateReadout } from "./readout.js";
import { params, state } from "./state.js";
import { hasVolume } from "./volume.js";

// Threads where the page is cross-origin isolated (the server sends the headers) and not
// declined (?threads=0).
function withThreads() {
  return window.crossOriginIsolated && params.get("threads") !== "0";
}

// The module: with threads where withThreads(), else on one thread. Where the viewer runs in a
// worker (remote.js), this thread's module only keeps the camera and counts: one thread; the
// worker loads the threaded one.
async function loadModule(inWorker) {
  const threads = withThreads();
  const name = threads && !inWorker ? "mediso-mt" : "mediso";
  await new Promise((resolve, reject) => {
    const script = Object.assign(document.createElement("script"), { src: "static/" + name + ".js" });
    script.onload = resolve;
    script.onerror = () => reject(new Error("static/" + name + ".js cannot be loaded"));
    document.head.append(script);
  });
  state.threads = threads ? navigator.hardwareConcurrency : 1;
  const create = name === "mediso-mt" ? window.createMedisoThreads : window.createMediso;
  return create({ locateFile: (f) => "static/" + f });
}

// What the module states for the page, as the page uses it.
function readFacts(M) {
  const count = M.NumberOfLevels;
  return {
    // name (the server's X-Mediso-Type) -> {name, value (for setVolume), bytes}
    scalarTypes: new Map(M.scalarTypes().map((t) => [t.name, t])),
    // level k samples every strides[k]-th point; count - 1 is the full volume
    levels: { count, strides: Array.from({ length: count }, (_, k) => M.levelStride(k)) },
    maximumIsovalues: M.MaximumIsovalues,
    // {bytes, texture: [x, y, z] texels} of a volume of ScalarType value `type` on the GPU path
    gpuVolume: (type, dims) => M.gpuVolume(type, dims),
    // The first isovalue's rule of the ParaView side (Filters/Core/HistogramThreshold.h):
    // whether a range is a CT's in Hounsfield units, skin and bone, the bins a range is counted
    // in ({low, width, count}) and Otsu's threshold of such counts (NaN: nothing to split).
    hounsfield: { skin: M.SkinHounsfield, bone: M.BoneHounsfield,
      looksLike: (lo, hi) => M.looksLikeHounsfieldUnits(lo, hi) },
    histogramBins: (lo, hi, integral) => M.histogramBins(lo, hi, integral),
    otsuThreshold: (counts, bins) => M.otsuThreshold(counts, bins.low, bins.width),
  };
}

/**
 * Loads the module and makes its viewer on `canvas` (sized by the size=WIDTHxHEIGHT parameter
 * when given). `probe` is a WebGL2 context of the page's, which names the renderer. With the
 * viewer in a worker, the worker loads its module while this thread loads its own (the page's
 * start-up, docs/web.md); `moduleLoaded` is called once this thread's module and state.facts
 * are there, before the worker is waited for.
 */
export async function startViewer(canvas, probe, moduleLoaded = () => {}) {
  // The viewer in a worker where the browser can draw WebGL2 there (?worker=0: on this thread).
  const inWorker = params.get("worker") !== "0" && offscreenWebGL2();
  // The canvas's size first: once handed to the worker, it is sized there.
  if (params.get("size")) { // WIDTHxHEIGHT (tests, benchmarks): a fixed backing store
    [canvas.width, canvas.height] = params.get("size").split("x").map(Number);
    canvas.classList.add("fixed");
  } else {
    [canvas.width, canvas.height] = backingStore(canvas.getBoundingClientRect());
  }
  const launched = inWorker && RemoteViewer.launch(canvas,
    { threads: withThreads() && navigator.hardwareConcurrency > 1,
      budgetMs: Number(params.get("frameBudget")) || 0, abort: params.get("abort") !== "0",
      slowExtractionMs: Number(params.get("slowExtraction")) || 0,
      slowPass: Number(params.get("slowPass")) || 1,
      refineDelayMs: Number(params.get("refineDelay")) || 0,
      slowFirstDragFrameMs: Number(params.get("slowFirstDragFrame")) || 0,
      prepareDrag: params.get("prepareDrag") });
  if (!inWorker) {
    RemoteViewer.takeEarlyWorker(); // the worker index.html started, ended
  }
  state.remote = inWorker;
  const debug = probe.getExtension("WEBGL_debug_renderer_info");
  state.unmaskedRenderer = debug ? probe.getParameter(debug.UNMASKED_RENDERER_WEBGL) : "";
  state.software = /SwiftShader|llvmpipe|softpipe|Software/i.test(state.unmaskedRenderer);
  state.module = await loadModule(inWorker);
  state.facts = readFacts(state.module);
  performance.mark("mediso:module");
  moduleLoaded();
  if (inWorker) {
    state.viewer = await RemoteViewer.start(launched, state.module, frameAnswered);
    performance.mark("mediso:worker");
    state.rendererNote = "Drawn in a worker (OffscreenCanvas): turning, typing and the panel do " +
      "not wait for an extraction or a frame.";
  } else {
    state.viewer = new state.module.WebViewer("#view");
    state.rendererNote = "Drawn on the page's main thread (" + (params.get("worker") === "0"
      ? "asked for by ?worker=0" : "this browser cannot draw WebGL2 in a worker") +
      "): the page waits for each extraction and frame.";
  }
  state.viewer.resize(canvas.width, canvas.height);
  // The readout says when the view has come to rest.
  setInterval(() => state.frameTimes.length && updateReadout(), 1000);
  if (!state.viewer.ready()) {
    return false;
  }
  // Where the GPU path keeps the volume as bricks (tests): a texture limit below the context's
  // and a GPU budget in MB (the core's defaults otherwise: the context's limit, 1 GiB).
  if (params.get("maxTextureSize")) {
    state.viewer.setMaxTextureSize(Number(params.get("maxTextureSize")) || 0);
  }
  if (params.get("gpuBudgetMB")) {
    state.viewer.setGPUBudget(1e6 * (Number(params.get("gpuBudgetMB")) || 0));
  }
  // Such bricks drawn each as its own pyramid instead of from the one pool texture (tests and
  // benchmarks: the pool against per-brick drawing).
  if (params.get("brickPool") === "0") {
    state.viewer.setBrickPool(false);
  }
  if (!debug) { // the renderer as the module's context names it
    state.unmaskedRenderer = state.viewer.info().renderer;
    state.software = /SwiftShader|llvmpipe|softpipe|Software/i.test(state.unmaskedRenderer);
  }
  return true;
}

// The canvas's backing store for a CSS box: its size times the device pixel ratio.
function backingStore(box, dpr = window.devicePixelRatio || 1) {
  return [Math.max(1, Math.round(box.width * dpr)), Math.max(1, Math.round(box.height * dpr))];
}

/**
 * Keeps the canvas's backing store at its CSS size times the device pixel ratio (the window
 * resized, the panel hidden, the page zoomed or moved to another screen), redrawing at once: a
 * resized canvas is cleared. Not with the size= parameter, which fixes it. The size is the CSS
 * box times devicePixelRatio rather than the observer's device-pixel box, which Chromium's
 * emulated pixel ratios (tests) leave in CSS pixels.
 */
export function fitCanvas(canvas) {
  if (params.get("size")) {
    return;
  }
  const fit = () => {
    const [width, height] = backingStore(canvas.getBoundingClientRect());
    if (width === canvas.width && height === canvas.height) {
      return;
    }
    state.viewer.resize(width, height);
    if (hasVolume()) {
      renderNow();
    }
  };
  new ResizeObserver(fit).observe(canvas);
  // The pixel ratio alone changed (zoom, another screen): the CSS box may stay the same.
  const watchRatio = () => {
    matchMedia("(resolution: " + window.devicePixelRatio + "dppx)").addEventListener("change", () => {
      fit();
      watchRatio();
    }, { once: true });
  };
  watchRatio();
}

/** Called after every frame with the module's view (the orientation marker). */
export const afterFrame = [];
/** Called before every frame is asked for (stream.js: the surfaces drawn from level 0). */
export const beforeFrame = [];

// A frame drawn: its time and what it drew, into the state and the readout.
function recordFrame(ms, stats) {
  state.frameTimes.push({ at: performance.now(), ms });
  if (state.frameTimes.length > 120) {
    state.frameTimes.shift();
  }
  state.lastFrameMs = ms;
  state.buildMs = stats.buildMs;
  state.primitives = stats.primitives;
  state.triangles = stats.triangles;
  state.cpuLevel = stats.cpuLevel;
  state.interactive = !!stats.interactive;
  state.settled = stats.settled !== false && !frameOwed(stats);
  state.refinementsSkipped = stats.refinementsSkipped || 0;
  state.refinementsAborted = stats.refinementsAborted || 0;
  state.abortable = !!stats.abortable;
  state.abortNote = stats.abortNote || "";
  state.sampleDistance = stats.sampleDistance || 1;
  state.gpuLevel = stats.gpuLevel ?? state.facts.levels.count - 1;
  state.frameNote = stats.note || "";
  state.frameLog.push({ seq: ++state.framesLogged, id: stats.id, values: stats.values, cpuLevel: stats.cpuLevel,
    triangles: stats.triangles, primitives: stats.primitives, sampleDistance: state.sampleDistance,
    gpuLevel: state.gpuLevel,
    interactive: state.interactive, settled: stats.settled !== false, ms, predictedMs: stats.predictedMs || 0,
    pyramidBuilt: !!stats.pyramidBuilt, buildMs: stats.buildMs || 0, uploadMs: stats.uploadMs || 0,
    programsCompiled: stats.programsCompiled || 0, answeredAt: performance.now(),
    surfaceValues: stats.surfaceValues || [], coarse: stats.coarse || [],
    surfaceTriangles: stats.surfaceTriangles || [] });
  if (state.frameLog.length > 200) {
    state.frameLog.shift();
  }
  updateReadout();
  for (const call of afterFrame) {
    call();
  }
}

// A frame the GPU path refused because the bricks the isovalues cross exceed its GPU budget:
// path.js falls back to the CPU path, saying why (the core's reason).
function refusedOnGPU(stats) {
  if (stats.overBudget) {
    fallBackFromGPU(stats.error);
  }
}

// The worker's answer to a frame (remote.js).
function frameAnswered(stats) {
  if (state.framesLogged === 0) {
    performance.mark("mediso:first-answer");
  }
  recordFrame(stats.ms, stats);
  if (!stats.ok) {
    refusedOnGPU(stats);
  }
}

// The newest frame asked of the worker ({id, first, settled}: remote.js).
let latest = null;

// Whether a frame newer than the one `stats` answers is still owed: one waiting for its animation
// frame, or asked of the worker and not answered yet. The view is not at rest then, whatever that
// frame was: stats().settled said true from the still frame before a drag until the drag's first
// answer, and a GPU drag's first frame (its volume level's first pyramid build and first use of
// its programs) took longer than the whole drag on a loaded machine, so a test that waited for
// settled after the drag found none of the drag's frames (docs/web.md, The worker).
function frameOwed(stats) {
  return state.remote && (!!state.pending || (!!latest && !(stats.id >= latest.id)));
}

/**
 * Draws now. On this thread: waits for the GPU and returns the time of the frame. With the
 * viewer in a worker: asks for the frame (`interactive` during a drag) and returns at once
 * {id, first, settled}, promises of the frame's first answer and of its full level.
 */
export function renderNow(interactive = false) {
  const viewer = state.viewer;
  // A surface hidden (the source of a server result shown, operations.js) is not drawn.
  viewer.setSurfaces(state.surfaces.filter((s) => !s.hidden));
  for (const call of beforeFrame) {
    call();
  }
  if (state.remote) {
    if (!latest) {
      performance.mark("mediso:first-asked");
    }
    latest = viewer.frame(interactive);
    state.settled = false; // until its answer (frameOwed)
    return latest;
  }
  const start = performance.now();
  if (!viewer.render()) {
    const stats = viewer.stats();
    if (stats.overBudget) {
      refusedOnGPU(stats);
      return 0;
    }
    throw new Error("render failed: " + stats.error);
  }
  viewer.finish();
  const ms = performance.now() - start;
  recordFrame(ms, viewer.stats());
  return ms;
}

/**
 * Resolves when the newest frame asked for is drawn at its full level and shown (automation).
 * The worker's canvas reaches this page's canvas when the worker's task that drew it ends, which
 * can be after its answer has arrived here: a screenshot taken at the answer could show the frame
 * before (TestWebServerPageView's left view once read the anterior view's picture). Two animation
 * frames after the answer, the page has shown it.
 */
export async function drawn() {
  if (state.remote && latest) {
    await latest.settled;
    await new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve)));
  }
}

/**
 * A change (`apply` changes what is drawn), then its frame, timed: on this thread the change
 * and the frame; with the worker, from the change to its first frame answered (the first
 * visible answer), and to the full level in state.lastRefinedMs.
 */
export function change(apply) {
  apply();
  if (state.remote) {
    const start = performance.now();
    const frame = renderNow();
    frame.first.then(() => {
      state.lastChangeMs = performance.now() - start;
      updateReadout();
    });
    frame.settled.then(() => {
      state.lastRefinedMs = performance.now() - start;
      updateReadout();
    });
    return;
  }
  state.lastChangeMs = renderNow();
  updateReadout();
}

/** Frames on request (interaction), at most one per animation frame. */
export function requestFrame() {
  if (!state.pending) {
    state.settled = state.settled && !state.remote; // a frame owed (frameOwed)
    state.pending = requestAnimationFrame(() => {
      state.pending = null;
      renderNow(state.interacting);
    });
  }
}

/** Draws a surface the server made (a binary PLY) beside the isosurfaces. */
export function showMesh(ply, color, opacity) {
  const mesh = parsePLY(ply);
  if (state.remote) {
    state.viewer.setResultArrays(mesh.points, mesh.triangles, color, opacity);
    renderNow();
    return { points: mesh.points.length / 3, triangles: mesh.triangles.length / 3 };
  }
  const M = state.module;
  const points = M._malloc(mesh.points.byteLength);
  const triangles = M._malloc(mesh.triangles.byteLength);
  M.HEAPU8.set(new Uint8Array(mesh.points.buffer), points);
  M.HEAPU8.set(new Uint8Array(mesh.triangles.buffer), triangles);
  state.viewer.setResultMesh(points, mesh.points.length / 3, triangles, mesh.triangles.length / 3,
    color, opacity);
  M._free(points);
  M._free(triangles);
  renderNow();
  return { points: mesh.points.length / 3, triangles: mesh.triangles.length / 3 };
}

export function clearMesh() {
  state.viewer.clearResultMesh();
  renderNow();
}
