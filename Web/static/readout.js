// SPDX-License-Identifier: BSD-3-Clause
// The readout: what the page tells the user of what it does. The stats table and the frame
// rate over the canvas, the dataset's line, the note on the path and the level, and, in place
// of the page, why it cannot run here. It reads the state and changes none of it.

import { $, state } from "./state.js";
import { streamNote } from "./stream.js";

// The window of the frame rate, ms.
const FPS_WINDOW_MS = 2000;

/**
 * Frames per second: the frames drawn in the FPS_WINDOW_MS before the last frame (or since the
 * first frame, when that is sooner) divided by that time: a rate over the last frames, not one
 * frame's inverse. It is measured up to the last frame, so a view at rest keeps the rate of the
 * frames it last drew rather than falling towards 0; `idle` says whether nothing has been drawn
 * for a whole window.
 */
export function fps(now = performance.now()) {
  const times = state.frameTimes;
  if (!times.length) {
    return 0;
  }
  const last = times[times.length - 1].at;
  const from = Math.max(last - FPS_WINDOW_MS, times[0].at - times[0].ms);
  const drawn = times.filter((f) => f.at > from && f.at <= last).length;
  return last > from ? drawn / ((last - from) / 1000) : 0;
}

function idle(now = performance.now()) {
  const times = state.frameTimes;
  return !times.length || now - times[times.length - 1].at > FPS_WINDOW_MS;
}

function fpsText() {
  return fps().toFixed(1) + " fps" + (idle() ? " (last frames; at rest)" : "");
}

export function updateReadout() {
  const rows = [
    ["path", state.path.toUpperCase() + (state.reason ? " (" + state.reason + ")" : "")],
    ["frames per second", fpsText()],
    ["threads", String(state.threads)],
    !(state.lastChangeMs > 0) ? ["last isovalue change", "none yet"]
      : state.remote ? ["last isovalue change", state.lastChangeMs.toFixed(1) + " ms to the first frame, " +
        state.lastRefinedMs.toFixed(1) + " ms to the full level"]
      : ["last isovalue change", state.lastChangeMs.toFixed(1) + " ms (change + frame)"],
    state.path === "gpu" ? ["primitives", String(state.primitives)]
                         : ["triangles", String(state.triangles) + " (level " + state.cpuLevel +
                           (state.interactive ? ", while dragging" : state.settled ? "" : ", refining") + ")"],
    ...(state.frameNote ? [["this frame", state.frameNote]] : []),
    ...(bricksText() ? [["GPU volume", bricksText()]] : []),
    ...(state.stream ? [["streaming", streamNote()]] : []),
    ["bytes received", state.bytesReceived.toLocaleString()],
    ["bytes sent", state.bytesSent.toLocaleString()],
  ];
  $("readout").replaceChildren(...rows.map(([k, v]) => {
    const tr = document.createElement("tr");
    tr.innerHTML = "<td></td><td></td>";
    tr.children[0].textContent = k;
    tr.children[1].textContent = v;
    return tr;
  }));
  $("overlay").textContent = fpsText();
}

/**
 * How the GPU path holds a volume it keeps as bricks (over the texture limit or the GPU budget:
 * docs/web.md, Paths): the bricks, those the isovalues cross, and whether they are drawn from
 * the one pool texture with one pyramid or each as its own pyramid, and why not from the pool
 * (stats().poolReason). "" for one texture.
 */
function bricksText() {
  const s = (state.path === "gpu" && state.viewer && state.viewer.stats()) || {};
  if (!(s.bricks > 0)) {
    return "";
  }
  return s.bricks + " bricks of " + s.brickPoints + " points, " + s.activeBricks + " crossed, " +
    s.residentBricks + " resident; " + (s.poolSlots > 0
    ? "drawn from a pool of " + s.poolSlots + " slots (one pyramid)"
    : "each crossed brick drawn as its own pyramid (" + s.brickPyramidBuilds + ")" +
      (s.poolReason ? ": " + s.poolReason : ""));
}

/** The dataset's line: name, size, type, bytes and range. */
export function showDataset(d) {
  $("dataset").textContent = d.name + ": " + d.dims.join("x") + " " + d.type + ", " +
    (d.bytes / 1e6).toFixed(1) + " MB, range " + d.range[0] + ".." + d.range[1];
}

/** The note under the path's controls: which path, why, and the level's note. */
export function showPathNote(path, why, levelWhy) {
  $("why").textContent = (path === "gpu" ? "GPU path" : "CPU path") + " (" + why + "). " + levelWhy;
}

/** Says, in place of the page, why it cannot run here; the start then fails with that text. */
export function unsupported(text) {
  $("app").hidden = true;
  const box = $("unsupported");
  box.hidden = false;
  box.textContent = text;
  return new Error(text);
}
