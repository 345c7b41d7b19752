// SPDX-License-Identifier: BSD-3-Clause
// The histogram of the volume (docs/web.md, Choosing the value): the values of the fetched level
// (the page's own copy, state.values) counted in the bins the cores' first-isovalue rule uses
// (state.facts.histogramBins: one bin per integer for small integer ranges, else 256 equal bins
// over the dataset's range), drawn with log counts, each isosurface's value marked in its colour.
// Dragging a marker changes that isovalue through its box in the surface list, the path typing
// a value takes (surfaces.js: checked, then drawn), once per animation frame.

import { $, state } from "./state.js";

let histogram = null; // {low, width, count, counts, otsu, level}
let drag = null; // {index, value}: the marker held and the value it goes to

const INTEGRAL = /^u?int/;

/** Counts the fetched level's values; the counts, their bins and Otsu's threshold. */
export function countHistogram() {
  const d = state.dataset;
  const bins = state.facts.histogramBins(d.range[0], d.range[1], INTEGRAL.test(d.type));
  const counts = new Float64Array(bins.count);
  const values = state.values;
  const last = bins.count - 1;
  for (let i = 0; i < values.length; ++i) {
    const v = values[i];
    if (v === v) { // NaN is not counted, as in the cores
      const at = Math.floor((v - bins.low) / bins.width); // HistogramBins::BinOf, ends clamped
      ++counts[at > 0 ? (at >= last ? last : at) : 0];
    }
  }
  const list = Array.from(counts);
  histogram = { low: bins.low, width: bins.width, count: bins.count, counts: list,
    otsu: state.facts.otsuThreshold(list, bins), level: state.level, values };
  return histogram;
}

function current() {
  // Counted again for another level, or another volume (a local file: local.js).
  return histogram && histogram.level === state.level && histogram.values === state.values
    ? histogram : countHistogram();
}

// CSS pixels of the canvas per value, and back.
function xOf(canvas, value) {
  const h = current();
  return ((value - h.low) / (h.width * h.count)) * canvas.clientWidth;
}
function valueAt(canvas, x) {
  const h = current();
  return h.low + (x / canvas.clientWidth) * h.width * h.count;
}

function css(color) {
  return "rgb(" + color.map((c) => Math.round(255 * c)).join(",") + ")";
}

/** Draws the histogram and the isovalues' markers at the canvas's size times the pixel ratio. */
export function drawHistogram() {
  const canvas = $("histogram");
  if (!canvas || !state.values || !canvas.clientWidth) {
    return;
  }
  const h = current();
  const dpr = window.devicePixelRatio || 1;
  const w = Math.round(canvas.clientWidth * dpr), ht = Math.round(canvas.clientHeight * dpr);
  if (canvas.width !== w || canvas.height !== ht) {
    canvas.width = w;
    canvas.height = ht;
  }
  const g = canvas.getContext("2d");
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  const width = canvas.clientWidth, height = canvas.clientHeight, top = 12;
  g.clearRect(0, 0, width, height);
  g.fillStyle = "#151a22";
  g.fillRect(0, 0, width, height);
  const logMax = Math.log1p(Math.max(...h.counts)) || 1;
  g.fillStyle = "#8c98aa";
  for (let i = 0; i < h.count; ++i) {
    if (h.counts[i] > 0) {
      const x0 = (i / h.count) * width, x1 = ((i + 1) / h.count) * width;
      const bar = (Math.log1p(h.counts[i]) / logMax) * (height - top);
      g.fillRect(x0, height - bar, Math.max(1 / dpr, x1 - x0), bar);
    }
  }
  state.surfaces.forEach((s, i) => {
    const x = xOf(canvas, drag && drag.index === i ? drag.value : s.value);
    g.strokeStyle = g.fillStyle = css(s.color);
    g.lineWidth = 2;
    g.beginPath();
    g.moveTo(x, top);
    g.lineTo(x, height);
    g.stroke();
    g.beginPath(); // the handle
    g.moveTo(x - 6, 0);
    g.lineTo(x + 6, 0);
    g.lineTo(x, top);
    g.closePath();
    g.fill();
  });
}

// The value a marker dragged to x is given: an integer for integer data, else 5 digits.
function rounded(value) {
  const d = state.dataset;
  const v = Math.min(d.range[1], Math.max(d.range[0], value));
  return INTEGRAL.test(d.type) ? Math.round(v) : Number(v.toPrecision(5));
}

// The marker's value typed into its box: the surface list checks it and draws it.
function apply(index, value) {
  const box = document.querySelectorAll("#surfaces .surface input.isovalue")[index];
  if (box) {
    box.value = String(value);
    box.dispatchEvent(new Event("input", { bubbles: true }));
  }
}

/** The histogram's canvas: markers dragged, redrawn with its size. */
export function setupHistogram() {
  const canvas = $("histogram");
  current();
  let frame = 0;
  canvas.addEventListener("pointerdown", (e) => {
    const box = canvas.getBoundingClientRect();
    const x = e.clientX - box.left;
    let best = -1, bestDistance = 8; // CSS pixels
    state.surfaces.forEach((s, i) => {
      const distance = Math.abs(xOf(canvas, s.value) - x);
      if (distance <= bestDistance) {
        best = i;
        bestDistance = distance;
      }
    });
    if (best >= 0) {
      drag = { index: best, value: state.surfaces[best].value };
      canvas.setPointerCapture(e.pointerId);
      e.preventDefault();
    }
  });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag) {
      canvas.style.cursor = state.surfaces.some((s) =>
        Math.abs(xOf(canvas, s.value) - (e.clientX - canvas.getBoundingClientRect().left)) <= 8)
        ? "ew-resize" : "default";
      return;
    }
    drag.value = rounded(valueAt(canvas, e.clientX - canvas.getBoundingClientRect().left));
    if (!frame) {
      frame = requestAnimationFrame(() => {
        frame = 0;
        if (drag) {
          apply(drag.index, drag.value);
        }
      });
    }
  });
  const release = () => {
    if (drag) {
      const { index, value } = drag;
      drag = null;
      if (frame) {
        cancelAnimationFrame(frame);
        frame = 0;
      }
      apply(index, value);
    }
  };
  canvas.addEventListener("pointerup", release);
  canvas.addEventListener("pointercancel", release);
  new ResizeObserver(drawHistogram).observe(canvas);
}

/** The histogram for automation: bins, counts, Otsu's threshold, each marker's x (CSS pixels). */
export function histogramInfo() {
  const canvas = $("histogram");
  const h = current();
  const box = canvas.getBoundingClientRect();
  return {
    low: h.low, width: h.width, count: h.count, counts: [...h.counts], otsu: h.otsu,
    level: h.level,
    canvas: { left: box.left, top: box.top, width: box.width, height: box.height },
    markers: state.surfaces.map((s) => ({ value: s.value, x: xOf(canvas, s.value) })),
  };
}
