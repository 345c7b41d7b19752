// SPDX-License-Identifier: BSD-3-Clause
// The readout: what the page tells the user of what it does. The stats table and the frame
// rate over the canvas, the dataset's line, the note on the path and the level, and, in place
// of the page, why it cannot run here. It reads the state and changes none of it.

import { $, state } from "./state.js";

/** Frames per second: over the last second's frames, else from the last frame's time. */
export function fps() {
  const now = performance.now();
  const recent = state.frameTimes.filter((f) => now - f.at < 1000);
  if (recent.length >= 2) {
    return recent.length / ((recent[recent.length - 1].at - recent[0].at) / 1000 || 1);
  }
  const last = state.frameTimes[state.frameTimes.length - 1];
  return last ? 1000 / last.ms : 0;
}

export function updateReadout() {
  const rows = [
    ["path", state.path.toUpperCase() + (state.reason ? " (" + state.reason + ")" : "")],
    ["frames per second", fps().toFixed(1)],
    ["threads", String(state.threads)],
    ["last isovalue change", state.lastChangeMs.toFixed(1) + " ms (change + frame)"],
    state.path === "gpu" ? ["primitives", String(state.primitives)]
                         : ["triangles", String(state.triangles) + " (level " + state.cpuLevel + ")"],
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
  $("overlay").textContent = fps().toFixed(1) + " fps";
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
