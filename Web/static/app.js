// SPDX-License-Identifier: BSD-3-Clause
// The web client (docs/web.md): the volume is fetched once; isosurfaces are then computed and
// drawn in this browser by the same C++ core the ParaView plugin runs, compiled to WebAssembly
// (mediso.js / mediso.wasm). Changing an isovalue, a colour or the camera sends nothing; the
// server is asked only for what needs its libraries (further operations on a surface).
//
// This module puts the page together and holds its automation API (window.mediso). The parts,
// one module each, share one declared state (state.js):
//   volume.js       the counted requests and the volume, fetched once per level
//   path.js         the GPU or the CPU path, and the level of the volume each can afford
//   viewer.js       the WebAssembly module, its viewer, the frames; the facts the module states
//   interaction.js  mouse, wheel, two fingers and keys on the canvas (turn, pan, zoom at the cursor, reset)
//   orientation.js  patient space (LPS): the views, the orientation marker, getView().world
//   link.js         the surfaces, camera, crosshair and path in the URL's fragment
//   surfaces.js     the surface list
//   readout.js      the stats, the notes, and why the page cannot run
//   operations.js   the "On the server" panel
//   ply.js          the server's surfaces, read
//   slices.js       the axial, coronal and sagittal views: window, crosshair, contours
//   crosshair3d.js  the crosshair drawn over the 3D view
//   histogram.js    the volume's histogram, its isovalue markers dragged
//   presets.js      the first surfaces (Hounsfield units or Otsu), the CT presets
//   stream.js       level 0 first, then the full level's bricks (CPU path, in the worker)
//   local.js        a local file dropped or picked, read in the page by the module

import { interact } from "./interaction.js";
import { linkedView, readLink, scheduleLink } from "./link.js";
import { setupOperations } from "./operations.js";
import { VIEWS, applyNamedView, drawMarker, markerLabels, sceneView, setDataset, withWorld }
  from "./orientation.js";
import { applyPath, drawnLevel, prefetchPath, requestPath } from "./path.js";
import { drawHistogram, histogramInfo, setupHistogram } from "./histogram.js";
import { serverDataset, setupLocalFiles } from "./local.js";
import { setupPresets } from "./presets.js";
import { fps, showDataset, unsupported, updateReadout } from "./readout.js";
import { $, params, state } from "./state.js";
import { drawCrosshair3D, setupCrosshair3D } from "./crosshair3d.js";
import { crosshairInfo, drawSlicesApart, pick, resetSlices, setCrosshair, setSliceWindow, setupSlices,
  slicesInfo } from "./slices.js";
import { replaceSurfaces, setupSurfaceList } from "./surfaces.js";
import { afterFrame, change, clearMesh, drawn, fitCanvas, renderNow, requestFrame, showMesh, startViewer }
  from "./viewer.js";
import { countBytes, request, requestJSON, sessionToken } from "./volume.js";
import { brickRanges, setupStream, stopStream, streamInfo, streamTimes, whenFull } from "./stream.js";

async function start() {
  const probe = document.createElement("canvas").getContext("webgl2");
  if (typeof WebAssembly !== "object" || !probe) {
    throw unsupported("This page computes isosurfaces in the browser with WebAssembly and WebGL2, " +
      "and this browser has " + (typeof WebAssembly !== "object" ? "no WebAssembly" : "no WebGL2") +
      ". Use a current Chrome, Edge, Firefox or Safari with hardware acceleration on.");
  }
  $("app").hidden = false;
  const canvas = $("view");
  if (params.get("budget")) {
    $("budget").value = params.get("budget");
  }
  // The page's start-up (docs/web.md): the datasets, this thread's module and the worker's are
  // asked for at once; once the dataset and the module's facts are known, the first requests of
  // the stream the path will choose (level 0, the bricks' manifest), while the worker starts.
  const datasets = requestJSON("/api/datasets");
  datasets.catch(() => {}); // awaited below
  const prefetch = () => datasets.then((list) => {
    const d = list.datasets[0];
    prefetchPath(d, readLink(location.hash, d.range, state.facts.maximumIsovalues).path ||
      state.requestedPath);
  }).catch(() => {});
  if (!(await startViewer(canvas, probe, prefetch))) {
    throw unsupported("WebGL2 is here but cannot run the GPU path: " + state.viewer.error());
  }
  $("renderer").textContent = state.rendererNote;
  const list = await datasets;
  state.dataset = list.datasets[0];
  const d = state.dataset;
  showDataset(d);
  const placement = setDataset(d);
  $("space").textContent = "Shown in " + placement.space + "." +
    (placement.note ? " Note: " + placement.note + "." : "");
  // The view a reload or a shared link asks for (link.js); what cannot be used is said.
  const link = readLink(location.hash, d.range, state.facts.maximumIsovalues);
  if (link.notes.length) {
    $("link-note").hidden = false;
    $("link-note").textContent = "Ignored in the link: " + link.notes.join("; ") + ". (Click to close.)";
    $("link-note").onclick = () => { $("link-note").hidden = true; };
  }
  if (link.path) {
    state.requestedPath = link.path;
  }
  fitCanvas(canvas);
  setupStream();
  await applyPath();
  if (link.camera) {
    state.viewer.setView(linkedView(link.camera));
  } else {
    applyNamedView("anterior");
  }
  $("path").onchange = async () => {
    await requestPath($("path").value);
    change(() => {});
  };
  $("budget").onchange = async () => {
    await applyPath();
    change(() => {});
  };
  setupSurfaceList();
  if (link.surfaces) {
    replaceSurfaces(link.surfaces, true);
  }
  // With the worker, the first frame is asked for now: the worker draws it while this thread
  // sets up the panel, slices and histogram below (in this same task, so that every afterFrame
  // call is there before its answer comes). On this thread, at the end.
  if (state.remote) {
    renderNow();
  }
  // Choosing the value: the CT presets, the histogram and the slice views, redrawn after a frame
  // whose surfaces or volume level changed.
  setupPresets((surfaces) => replaceSurfaces(surfaces, false));
  setupHistogram();
  setupSlices(histogramInfo());
  setupCrosshair3D(canvas, scheduleLink);
  afterFrame.push(drawCrosshair3D);
  if (link.crosshair) {
    setCrosshair(link.crosshair);
  }
  let drawnKey = "";
  afterFrame.push(() => {
    const key = JSON.stringify([state.surfaces, state.level]);
    if (key !== drawnKey) {
      drawnKey = key;
      // Each in its own task (each slice view too), so that none adds to the frame's answer a
      // main-thread task of all (the longtask budget: docs/web.md, The worker).
      drawSlicesApart();
      setTimeout(drawHistogram);
    }
  });
  const reset = () => applyNamedView("anterior");
  interact(canvas, { reset, changed: scheduleLink });
  for (const button of document.querySelectorAll("#views [data-view]")) {
    button.onclick = () => {
      applyNamedView(button.dataset.view);
      requestFrame();
    };
  }
  $("reset").onclick = () => {
    reset();
    requestFrame();
  };
  $("toggle-panel").onclick = () => {
    const collapsed = $("app").classList.toggle("collapsed");
    $("toggle-panel").textContent = collapsed ? "Show panel" : "Hide panel";
    $("toggle-panel").setAttribute("aria-expanded", String(!collapsed));
  };
  // After every frame: the marker for the camera drawn, and the URL's state written soon.
  afterFrame.push(() => {
    drawMarker($("marker"), state.viewer.getView());
    scheduleLink();
  });
  if (!state.remote) {
    renderNow();
  }
  await drawn(); // ready after the first frame (the worker's answer)
  performance.mark("mediso:ready");
  // The "On the server" panel (Web/static/operations.js) is given what it needs here.
  setupOperations({
    get dataset() { return state.dataset; }, // a local file's once it is opened
    serverDataset: () => serverDataset(state.dataset),
    token: sessionToken(),
    surfaces: () => state.surfaces,
    levels: state.facts.levels.count,
    // The page's surfaces as a level of the whole volume: the GPU path draws the fetched level
    // in full, the CPU path its own level of that.
    level: drawnLevel,
    request,
    count(sent, received) {
      countBytes(sent, received);
      updateReadout();
    },
    showSurface(surface, shown) {
      change(() => { surface.hidden = !shown; });
    },
  });
  setupLocalFiles(openLocal);
}

// A local file's volume (local.js) in place of the one shown: placed, fetched from the page's own
// levels at the level the path affords, in the anterior view with its first surfaces.
async function openLocal(d) {
  state.dataset = d;
  showDataset(d);
  const placement = setDataset(d);
  $("space").textContent = "Shown in " + placement.space + "." +
    (placement.note ? " Note: " + placement.note + "." : "");
  state.level = null; // another volume: its level is loaded whatever the last one's was
  stopStream(); // a served volume's bricks still on their way are not this volume's
  await applyPath();
  applyNamedView("anterior");
  setupSurfaceList();
  setupPresets((surfaces) => replaceSurfaces(surfaces, false));
  resetSlices(histogramInfo());
  renderNow();
  await drawn();
}

// ---------------------------------------------------------------------------- automation
let resolveReady, rejectReady;
const ready = new Promise((resolve, reject) => { resolveReady = resolve; rejectReady = reject; });
ready.catch(() => {}); // said on the page; automation awaits it and gets the reason

window.mediso = {
  ready,
  async setIsovalues(values) {
    replaceSurfaces(values.map((value) => ({ value })), true);
    await drawn();
    return window.mediso.stats();
  },
  async setSurfaces(surfaces) {
    replaceSurfaces(surfaces, false);
    await drawn();
    return window.mediso.stats();
  },
  // The camera in the module's scene frame (VTK's conventions; the fields ParaView's camera
  // has), or, given {world: {position, focalPoint, viewUp}}, in patient space (LPS mm).
  async setView(view) {
    const scene = view.world ? Object.assign({}, view, sceneView(view.world)) : view;
    state.viewer.setView(scene);
    renderNow();
    await drawn();
    return window.mediso.getView();
  },
  // {position, focalPoint, viewUp, viewAngle, parallelScale} in the scene frame, and world:
  // {space: "LPS", position, focalPoint, viewUp, direction (of projection, unit)} in patient
  // space (orientation.js).
  getView: () => withWorld(state.viewer.getView()),
  // One of VIEWS' names (anterior, posterior, left, right, superior, inferior), drawn.
  async setNamedView(name) {
    if (!VIEWS[name]) {
      throw new Error(name + " is not one of " + Object.keys(VIEWS).join(", "));
    }
    applyNamedView(name);
    renderNow();
    await drawn();
    return window.mediso.getView();
  },
  // The orientation marker as drawn: each label's x (right), y (up) and toward (the viewer).
  orientation: () => ({ space: $("space").textContent, labels: markerLabels(state.viewer.getView()) }),
  // The surfaces drawn now: [{value, color: [r, g, b], opacity}].
  getSurfaces: () => state.surfaces.map((s) => ({ value: s.value, color: [...s.color], opacity: s.opacity })),
  // Lighting material and background (tests match them with ParaView's).
  async setLook({ ambient, diffuse, specular, specularPower, background }) {
    if (ambient !== undefined) {
      state.viewer.setMaterial(ambient, diffuse, specular, specularPower);
    }
    if (background) {
      state.viewer.setBackground(...background);
    }
    renderNow();
    await drawn();
  },
  stats: () => ({
    path: state.path,
    reason: state.reason,
    cpuLevel: state.cpuLevel,
    threads: state.threads,
    level: state.level,
    levelNote: state.levelNote,
    // where the viewer draws ("worker" or "main"); with the worker, whether the last frame was
    // a drag's (interactive: a coarser level), whether it is at the full level, and the
    // refinements a newer change made obsolete
    renderer: state.remote ? "worker" : "main",
    interactive: state.interactive,
    settled: state.settled,
    refinementsSkipped: state.refinementsSkipped,
    // refinements a newer change stopped while they ran, and whether it can (docs/web.md)
    refinementsAborted: state.refinementsAborted,
    abortable: state.abortable,
    abortNote: state.abortNote,
    lastRefinedMs: state.lastRefinedMs,
    sampleDistance: state.sampleDistance,
    gpuLevel: state.gpuLevel,
    frameNote: state.frameNote,
    primitives: state.primitives,
    triangles: state.triangles,
    fps: fps(),
    lastChangeMs: state.lastChangeMs,
    // the last frame's time, and the part of it that built the pyramid or the surfaces (0 when
    // only the camera or the looks changed)
    lastFrameMs: state.lastFrameMs,
    buildMs: state.buildMs,
    bytesSent: state.bytesSent,
    bytesReceived: state.bytesReceived,
    // each surface's level of the whole volume (0 while drawn from the streamed level 0), and
    // the fraction of the level's bytes received (stream.js; 1 once it came whole)
    levels: [...state.surfaceLevels],
    // each current surface's triangles as drawn (CPU path)
    surfaceTriangles: state.surfaces.map((s) => {
      const drawn = (state.viewer && state.viewer.stats()) || {};
      return (drawn.surfaceTriangles || [])[(drawn.surfaceValues || []).indexOf(s.value)];
    }),
    received: state.stream ? state.received : 1,
    // the CPU path's surfaces of this stream taken made from the extraction ahead (docs/web.md,
    // Streaming), not extracted at their frame
    takenAhead: ((state.viewer && state.viewer.stats()) || {}).takenAhead || 0,
    // the GPU frame a drag would be drawn as, made ready after the last settled frame
    // (render-worker.js: {level, sampleDistance, ms, values}, null before any), and how often
    dragPrepared: ((state.viewer && state.viewer.stats()) || {}).dragPrepared || null,
    dragPreparedCount: ((state.viewer && state.viewer.stats()) || {}).dragPreparedCount || 0,
    // where the last stream's time went (stream.js's streamTimes; null where the level came whole)
    streamTimes: streamTimes(),
    // the GPU path's bricks (0: the volume is one texture), those the isovalues cross and those
    // on the GPU (docs/web.md, Paths), their edge, the pool's slots (0: each active brick its own
    // pyramid) and the pyramids the last build built; its whole uploads and streamed regions
    ...Object.fromEntries(["bricks", "activeBricks", "residentBricks", "brickPoints", "poolSlots",
      "brickPyramidBuilds", "volumeUploads", "regionUploads"].map((k) =>
      [k, ((state.viewer && state.viewer.stats()) || {})[k] || 0])),
    view: state.viewer ? state.viewer.getView() : null,
    info: state.viewer ? state.viewer.info() : null,
  }),
  // the CPU model's count on the volume, or on its samples of volume level `level` (the GPU
  // path's coarse levels: stats().gpuLevel)
  cpuCount: (values, level = state.facts.levels.count - 1) => state.viewer.countOnCPU(values, level),
  // The dataset shown, as /api/datasets describes it (a local file's as the module read it:
  // local.js), without its values.
  dataset: () => {
    const { local, ...d } = state.dataset || {};
    return Object.assign(JSON.parse(JSON.stringify(d)), { local: Boolean(local) });
  },
  // The stats once the newest frame asked for is drawn at its full level (with the viewer in a
  // worker, frames come after the change that asked for them; on the main thread, at once).
  async drawn() {
    await drawn();
    return window.mediso.stats();
  },
  // Resolves with the stats when every current surface is drawn at the full level (streaming).
  async whenFull() {
    await whenFull();
    return window.mediso.stats();
  },
  // Streaming (tests): the bricks asked for so far and the bricks `values` need; null after it.
  streamInfo: (values) => streamInfo(values),
  // After a stream (tests): {server, core}: the manifest's brick ranges and the cores'.
  brickRanges: () => brickRanges(),
  // The last frames drawn, oldest first (tests: a drag's levels, a refinement's steps).
  frames: () => state.frameLog.map((f) => Object.assign({}, f)),
  async setPath(path) {
    await requestPath(path);
    change(() => {});
    await drawn();
    return window.mediso.stats();
  },
  estimates: () => state.viewer.estimates(),
  // The CPU path's level of detail: 0-3, or -1 for the estimator's choice within the budget.
  // Resolves after the frame (with the viewer in a worker; the page's tests await it).
  async setCPULevel(level) {
    change(() => state.viewer.setCPULevel(level));
    await drawn();
    return window.mediso.stats();
  },
  // A surface the server made: binary PLY (vertex x, y, z; faces as index lists).
  showMesh: (ply, color = [0.55, 0.8, 1.0], opacity = 1) => showMesh(ply, color, opacity),
  clearMesh: async () => {
    clearMesh();
    await drawn();
  },
  // The slice views (slices.js): for each, its name, labels, index axis and slice index, window,
  // the crosshair on its canvas (CSS pixels), mm per CSS pixel; with {contours: true} each
  // surface's contour points on the slice (LPS mm).
  slices: (options = {}) => slicesInfo(Boolean(options.contours)),
  // The crosshair (LPS mm) moved, the slices with it; the point is kept within the volume.
  setCrosshair(point) {
    setCrosshair(point);
    return window.mediso.slices();
  },
  getCrosshair: () => crosshairInfo(),
  // A view's window: a preset's name ("Soft tissue", "Bone", "Full range", ...) or {width, level}.
  setSliceWindow(view, choice) {
    setSliceWindow(view, choice);
    return window.mediso.slices();
  },
  // The first point of a drawn surface under (x, y), CSS pixels of the 3D view, LPS mm; null.
  pick: (x, y) => pick($("view"), x, y),
  // The histogram (histogram.js): bins {low, width, count}, counts, Otsu's threshold, each
  // isovalue's marker (x in CSS pixels of the histogram's canvas).
  histogram: () => histogramInfo(),
  // What the WebAssembly module states for the page (scalar types, levels of detail and their
  // strides, the isovalue limit), as plain data.
  facts: () => ({
    scalarTypes: [...state.facts.scalarTypes.values()],
    levels: { count: state.facts.levels.count, strides: [...state.facts.levels.strides] },
    maximumIsovalues: state.facts.maximumIsovalues,
  }),
};

start().then(resolveReady, (error) => {
  if ($("unsupported").hidden) {
    unsupported("The page could not start: " + error.message);
  }
  rejectReady(error);
});
