// SPDX-License-Identifier: BSD-3-Clause
// The renderer glue: the WebAssembly module (Web/wasm/WebViewer.cxx: the GPU core and the
// BlockLOD core compiled for the browser), its viewer on the canvas, and the frames. The module
// also states the facts the page needs of the cores (scalar types, levels of detail and their
// strides, the isovalue limit, the GPU path's memory of a volume), read once into state.facts.

import { parsePLY } from "./ply.js";
import { updateReadout } from "./readout.js";
import { params, state } from "./state.js";

// The module: with threads where the page is cross-origin isolated (the server sends the
// headers), else on one thread.
async function loadModule() {
  const threads = window.crossOriginIsolated && params.get("threads") !== "0";
  const name = threads ? "mediso-mt" : "mediso";
  await new Promise((resolve, reject) => {
    const script = Object.assign(document.createElement("script"), { src: "static/" + name + ".js" });
    script.onload = resolve;
    script.onerror = () => reject(new Error("static/" + name + ".js cannot be loaded"));
    document.head.append(script);
  });
  state.threads = threads ? navigator.hardwareConcurrency : 1;
  const create = threads ? window.createMedisoThreads : window.createMediso;
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
 * when given). `probe` is a WebGL2 context of the page's, which names the renderer.
 */
export async function startViewer(canvas, probe) {
  state.module = await loadModule();
  state.facts = readFacts(state.module);
  if (params.get("size")) { // WIDTHxHEIGHT (tests, benchmarks): a fixed backing store
    [canvas.width, canvas.height] = params.get("size").split("x").map(Number);
    canvas.classList.add("fixed");
  } else {
    [canvas.width, canvas.height] = backingStore(canvas.getBoundingClientRect());
  }
  state.viewer = new state.module.WebViewer("#view");
  state.viewer.resize(canvas.width, canvas.height);
  if (!state.viewer.ready()) {
    return false;
  }
  const debug = probe.getExtension("WEBGL_debug_renderer_info");
  state.unmaskedRenderer = debug ? probe.getParameter(debug.UNMASKED_RENDERER_WEBGL)
                                 : state.viewer.info().renderer;
  state.software = /SwiftShader|llvmpipe|softpipe|Software/i.test(state.unmaskedRenderer);
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
    if (state.volumePointer) {
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

/** Draws now and waits for the GPU: the time of a change + frame. */
export function renderNow() {
  const viewer = state.viewer;
  // A surface hidden (the source of a server result shown, operations.js) is not drawn.
  viewer.setSurfaces(state.surfaces.filter((s) => !s.hidden));
  const start = performance.now();
  if (!viewer.render()) {
    throw new Error("render failed: " + viewer.stats().error);
  }
  viewer.finish();
  const ms = performance.now() - start;
  state.frameTimes.push({ at: performance.now(), ms });
  if (state.frameTimes.length > 120) {
    state.frameTimes.shift();
  }
  state.lastFrameMs = ms;
  const stats = viewer.stats();
  state.buildMs = stats.buildMs;
  state.primitives = stats.primitives;
  state.triangles = stats.triangles;
  state.cpuLevel = stats.cpuLevel;
  updateReadout();
  for (const call of afterFrame) {
    call();
  }
  return ms;
}

/** A change (`apply` changes what is drawn), then its frame, timed. */
export function change(apply) {
  apply();
  state.lastChangeMs = renderNow();
  updateReadout();
}

/** Frames on request (interaction), at most one per animation frame. */
export function requestFrame() {
  if (!state.pending) {
    state.pending = requestAnimationFrame(() => {
      state.pending = null;
      renderNow();
    });
  }
}

/** Draws a surface the server made (a binary PLY) beside the isosurfaces. */
export function showMesh(ply, color, opacity) {
  const mesh = parsePLY(ply);
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
