// SPDX-License-Identifier: BSD-3-Clause
// The page's state, declared once: every field, what it holds and the one module that changes
// it (docs/web.md, The page's modules). Other modules read it. The object is sealed, so that
// writing a field not declared here fails at once instead of adding a global by another name.

/** The page's URL parameters (token, path, size, budget, threads). */
export const params = new URLSearchParams(location.search);

/** The page's element of that id. */
export const $ = (id) => document.getElementById(id);

export const state = Object.seal({
  // viewer.js, once at the start: the WebAssembly module, its viewer on the canvas, and what
  // the module states for the page (facts: scalar types, levels of detail, isovalue limit,
  // the GPU path's memory of a volume), so that the page writes none of them itself.
  module: null,
  viewer: null,
  facts: null,
  threads: null, // threads of the CPU path (1 unless the page is cross-origin isolated)
  software: false, // the WebGL2 renderer is a software one
  unmaskedRenderer: "",
  remote: false, // the viewer draws in a worker (remote.js, render-worker.js)
  rendererNote: "", // where the viewer draws, and why there

  // app.js, once: the dataset shown (/api/datasets' first).
  dataset: null,

  // volume.js: the fetched volume in the module's memory (0 while a stream is under way: stream.js
  // puts the level there at its end), its level, and the bytes the page moved (its requests, and
  // the server panel's WebSocket frames counted through volume.js).
  volumePointer: 0,
  level: null,
  // volume.js too: the page's own copy of the fetched level's values (a typed array of its
  // scalar type) and its grid {dims, spacing, origin}: the slices and the histogram read them
  // (slices.js, histogram.js), never the module's memory.
  values: null,
  grid: null,
  bytesSent: 0,
  bytesReceived: 0,

  // path.js: the path asked for ("auto", "gpu", "cpu"; app.js sets it once from the URL's
  // fragment, before the first applyPath), the path drawn, and why.
  requestedPath: params.get("path") || "auto",
  path: "gpu",
  reason: "",
  levelNote: "",
  // {dataset, why}: the GPU path refused this dataset's surfaces (the bricks they cross exceed
  // its GPU budget), so the CPU path draws it.
  gpuRefused: null,

  // surfaces.js (and app.js's automation, through surfaces.js): the isosurfaces
  // [{value, color: [r, g, b], opacity}], and hidden: true on the source of a server result
  // while the result is shown (operations.js, through app.js).
  surfaces: [],

  // viewer.js, at each frame: its times and what it drew.
  frameTimes: [], // [{at, ms}] of the last 120 frames
  lastChangeMs: 0, // the last change + frame
  lastFrameMs: 0,
  buildMs: 0, // the part of the last frame that built the pyramid or the surfaces
  primitives: 0,
  triangles: 0,
  cpuLevel: null, // the CPU path's level of detail of the fetched volume
  pending: null, // the animation frame requested by interaction
  // viewer.js, with the viewer in a worker: the frame's kind and the refinements.
  interacting: false, // interaction.js: a drag is under way (its frames are interactive)
  interactive: false, // the last frame was a drag's (a coarser level)
  settled: true, // the last frame is at the full level
  refinementsSkipped: 0, // refinements a newer change made obsolete
  refinementsAborted: 0, // refinements a newer change stopped while they ran
  abortable: false, // the worker can stop a running refinement (cross-origin isolated)
  abortNote: "", // the worker's word on it
  lastRefinedMs: 0, // the last change to its full-level frame
  sampleDistance: 1, // the GPU path's image sample distance of the last frame
  gpuLevel: 3, // the GPU path's volume level of the last frame (3: the volume; 2, 1: sampled)
  frameNote: "", // why the last frame is coarser than the full one ("" when it is not)
  // stream.js (docs/web.md, Streaming): the stream of the full level's bricks (null when the
  // volume came whole), each drawn surface's level of the whole volume, and the fraction of the
  // level's bytes received.
  stream: null,
  surfaceLevels: [],
  received: 0,
  framesLogged: 0, // frames drawn since the page began: the newest frame's `seq`
  frameLog: [], // the last 200 frames: [{seq, values, cpuLevel, triangles, primitives, sampleDistance, interactive, settled, ms, predictedMs, buildMs, uploadMs, programsCompiled}]
});
