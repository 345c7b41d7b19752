// SPDX-License-Identifier: BSD-3-Clause
// The surface list: one row per isosurface (value, colour, opacity, remove, a slider over the
// dataset's range), the "Add a surface" button, and the server panel's choice of surface. Every
// change draws at once (viewer.js's change: change + frame, timed).

import { countHistogram } from "./histogram.js";
import { BONE, firstSurfaces } from "./presets.js";
import { $, state } from "./state.js";
import { change } from "./viewer.js";

/**
 * The surfaces a dataset opens with (presets.js): skin and bone for a CT in Hounsfield units,
 * else Otsu's threshold of the fetched volume's histogram.
 */
export function defaultSurfaces(d) {
  return firstSurfaces(d, countHistogram());
}

function hex(color) {
  return "#" + color.map((c) => Math.round(255 * c).toString(16).padStart(2, "0")).join("");
}

function fromHex(text) {
  return [1, 3, 5].map((i) => parseInt(text.substr(i, 2), 16) / 255);
}

// A control with its visible label.
function labelled(text, control) {
  const label = document.createElement("label");
  label.append(text + " ", control);
  return label;
}

/**
 * Reads a number box: the number when it is one within [lo, hi], else null with the reason
 * shown in `message` beside it and the box marked invalid (the surface keeps its last value).
 */
function checked(box, message, what, lo, hi) {
  const text = box.value.trim();
  const x = Number(text);
  const ok = text !== "" && Number.isFinite(x) && x >= lo && x <= hi;
  box.setAttribute("aria-invalid", String(!ok));
  message.textContent = ok ? "" : (text === "" ? "An empty " + what + " is not used" :
    JSON.stringify(text) + " is not used") + ": the " + what + " is a number within " + lo +
    ".." + hi + ".";
  return ok ? x : null;
}

/** The rows of the list, made again from state.surfaces. */
export function buildSurfaceList() {
  const d = state.dataset;
  const box = $("surfaces");
  box.replaceChildren();
  state.surfaces.forEach((s, i) => {
    const row = document.createElement("div");
    row.className = "surface";
    const value = Object.assign(document.createElement("input"),
      { type: "number", step: "any", min: d.range[0], max: d.range[1], value: s.value,
        className: "isovalue" });
    const color = Object.assign(document.createElement("input"),
      { type: "color", value: hex(s.color), className: "color" });
    const opacity = Object.assign(document.createElement("input"),
      { type: "number", min: 0, max: 1, step: 0.05, value: s.opacity, className: "opacity" });
    const remove = Object.assign(document.createElement("button"),
      { textContent: "Remove", title: "Remove surface " + (i + 1) });
    const slider = Object.assign(document.createElement("input"),
      { type: "range", min: d.range[0], max: d.range[1], step: "any", value: s.value });
    slider.setAttribute("aria-label", "Isovalue of surface " + (i + 1) + ", " + d.range[0] + " to " + d.range[1]);
    const message = Object.assign(document.createElement("div"), { className: "message", role: "alert" });
    value.oninput = () => {
      const x = checked(value, message, "isovalue", d.range[0], d.range[1]);
      if (x !== null) {
        change(() => { s.value = x; slider.value = String(x); });
        updateServerChoice();
      }
    };
    slider.oninput = () => {
      change(() => {
        s.value = Number(slider.value);
        value.value = slider.value;
        checked(value, message, "isovalue", d.range[0], d.range[1]);
      });
      updateServerChoice();
    };
    color.oninput = () => change(() => { s.color = fromHex(color.value); });
    opacity.oninput = () => {
      const x = checked(opacity, message, "opacity", 0, 1);
      if (x !== null) {
        change(() => { s.opacity = x; });
      }
    };
    remove.onclick = () => change(() => { state.surfaces.splice(i, 1); buildSurfaceList(); });
    row.append(labelled("Isovalue", value), labelled("Colour", color), labelled("Opacity", opacity),
      remove, slider, message);
    box.append(row);
  });
  updateServerChoice();
}

/**
 * The server panel's surface choice: one option per surface, its current isovalue, the choice
 * kept where the surface still is (an isovalue changed in its box or slider shows here at once).
 */
function updateServerChoice() {
  const pick = $("op-surface");
  const chosen = pick.value;
  pick.replaceChildren(...state.surfaces.map((s, i) =>
    Object.assign(document.createElement("option"), { value: i, textContent: String(s.value) })));
  if (chosen !== "" && Number(chosen) < state.surfaces.length) {
    pick.value = chosen;
  }
}

/** The dataset's default surfaces in the list, and the "Add a surface" button. */
export function setupSurfaceList() {
  const d = state.dataset;
  state.surfaces = defaultSurfaces(d);
  buildSurfaceList();
  $("add").onclick = () => change(() => {
    state.surfaces.push({ value: d.range[0] + 0.5 * (d.range[1] - d.range[0]), color: BONE, opacity: 1 });
    buildSurfaceList();
  });
}

/**
 * New surfaces, drawn (automation): [{value, color, opacity}], a missing colour or opacity
 * taken from the surface at the same place in the list when `keepLooks`, else bone and opaque.
 */
export function replaceSurfaces(surfaces, keepLooks) {
  change(() => {
    state.surfaces = surfaces.map((s, i) => {
      const old = keepLooks ? state.surfaces[i] || {} : {};
      return { value: s.value, color: s.color || old.color || BONE, opacity: s.opacity ?? old.opacity ?? 1 };
    });
    buildSurfaceList();
  });
}
