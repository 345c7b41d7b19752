// SPDX-License-Identifier: BSD-3-Clause
// Path choice (docs/web.md, Paths): the GPU path (the pyramid on WebGL2) or the CPU path (the
// BlockLOD core), and the level of the volume each can afford. The levels, their strides and
// what the GPU path takes of a volume come from the module (state.facts), not from here.

import { showPathNote } from "./readout.js";
import { $, state } from "./state.js";
import { hasVolume, loadVolume } from "./volume.js";
import { canStream, prefetchStream, startStream, stopStream } from "./stream.js";
import { renderNow } from "./viewer.js";

// The CPU path keeps the volume within 1 / CPU_VOLUME_SHARE of the budget: its surfaces and
// their cache take the rest.
const CPU_VOLUME_SHARE = 2;

/** 1st, 2nd, 3rd, 4th, ..., 11th, 12th, 13th, ..., 21st. */
export function ordinal(n) {
  const tens = n % 100, ones = n % 10;
  const suffix = tens >= 11 && tens <= 13 ? "th" : ["th", "st", "nd", "rd"][ones] || "th";
  return n + suffix;
}

// The finest level of the volume a path can afford. GPU: the volume itself within the budget
// (the core keeps a volume over the 3D texture limit or its GPU budget as bricks, only those the
// isovalues cross on the GPU; where even those exceed its budget it says so at the frame, and
// the page falls back: fallBackFromGPU below). CPU: the volume within its share.
function chooseLevel(dataset, info, budgetMB, path) {
  const { count, strides } = state.facts.levels;
  const full = count - 1;
  for (let k = full; k >= 0; --k) {
    const level = dataset.levels[k];
    const d = level.dims;
    const bytes = path === "cpu" ? CPU_VOLUME_SHARE * level.bytes : level.bytes;
    if (bytes <= budgetMB * 1e6) {
      const why = k === full ? "" :
        "The volume is sent at level " + k + " (every " + ordinal(strides[k]) + " point, " +
        d.join("x") + "): the full " + dataset.dims.join("x") + " volume exceeds the memory budget.";
      return { level: k, why };
    }
  }
  return { level: 0, why: "Even level 0 of the volume exceeds the memory budget." };
}

// The path: what the user asked for, else from what the browser has. Both draw with WebGL2; the
// GPU path ray-casts every covered pixel, which a software rasteriser does on the CPU, where the
// CPU path's triangles are cheaper.
function choosePath(requested, info, dataset, budgetMB) {
  const gpu = chooseLevel(dataset, info, budgetMB, "gpu");
  const cpu = chooseLevel(dataset, info, budgetMB, "cpu");
  // The GPU path refused this dataset's surfaces (the bricks they cross exceed its GPU budget):
  // the CPU path, with the core's reason, whatever was asked for.
  if (state.gpuRefused && state.gpuRefused.dataset === dataset) {
    return { path: "cpu", level: cpu, why: "the GPU path cannot draw these surfaces: " +
      state.gpuRefused.why };
  }
  if (requested === "gpu" || requested === "cpu") {
    return { path: requested, level: requested === "gpu" ? gpu : cpu, why: "chosen by the user" };
  }
  if (state.software) {
    return { path: "cpu", level: cpu,
      why: "auto: the WebGL2 renderer is software (" + state.unmaskedRenderer + "), where the " +
        "triangles of the CPU path draw faster than per-pixel ray casting" };
  }
  if (gpu.level < cpu.level) {
    return { path: "cpu", level: cpu,
      why: "auto: the GPU path would need a coarser volume (" + gpu.why + ")" };
  }
  return { path: "gpu", level: gpu, why: "auto: WebGL2 on " + state.unmaskedRenderer };
}

/**
 * The page's start-up (app.js, docs/web.md): where the page will stream `dataset` (the path and
 * level applyPath will choose, the path asked for being `requested`), its first requests are
 * sent now, before the viewer is ready, and applyPath's stream takes their answers.
 */
export function prefetchPath(dataset, requested) {
  const budgetMB = Number($("budget").value) || 1024;
  const choice = choosePath(requested, null, dataset, budgetMB);
  if (canStream(choice.path, choice.level.level)) {
    performance.mark("mediso:prefetch");
    prefetchStream(dataset, choice.level.level);
  }
}

/** Sets the path and fetches the volume again only if the path needs another level of it. */
export async function applyPath() {
  const budgetMB = Number($("budget").value) || 1024;
  const choice = choosePath(state.requestedPath, state.viewer.info(), state.dataset, budgetMB);
  state.path = choice.path;
  state.reason = choice.why;
  state.levelNote = choice.level.why;
  showPathNote(choice.path, choice.why, choice.level.why);
  $("path").value = state.requestedPath;
  state.viewer.setPath(choice.path);
  const had = hasVolume();
  if (!had || (state.level !== choice.level.level && !state.stream) ||
      (state.stream && (state.stream.level !== choice.level.level || choice.path !== state.stream.path))) {
    stopStream();
    // Streamed (stream.js: level 0 first, then the bricks) where the path allows it.
    await (canStream(choice.path, choice.level.level) && !had
      ? startStream(choice.level.level) : loadVolume(choice.level.level));
  }
  const volumeBytes = state.dataset.levels[state.stream ? state.stream.level : state.level].bytes;
  state.viewer.setBudget(Math.max(0, budgetMB * 1e6 - volumeBytes));
}

/**
 * The core refused a GPU frame (the bricks the isovalues cross exceed the GPU budget; viewer.js):
 * the CPU path for this dataset, the reason said in the path note, and the frame again.
 */
export function fallBackFromGPU(why) {
  if (state.path !== "gpu" || (state.gpuRefused && state.gpuRefused.dataset === state.dataset)) {
    return;
  }
  state.gpuRefused = { dataset: state.dataset, why };
  applyPath().then(() => renderNow());
}

/** A new requested path ("auto", "gpu" or "cpu"), applied. */
export async function requestPath(path) {
  state.requestedPath = path;
  await applyPath();
}

/**
 * The level of the whole volume the page's surfaces are drawn at: the fetched level on the GPU
 * path; on the CPU path its own level of the fetched volume (the strides multiply), level 0
 * where that is coarser still.
 */
export function drawnLevel() {
  if (state.path !== "cpu") {
    return state.level;
  }
  const strides = state.facts.levels.strides;
  return Math.max(0, strides.indexOf(strides[state.cpuLevel] * strides[state.level]));
}
