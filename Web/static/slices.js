// SPDX-License-Identifier: BSD-3-Clause
// The slice views (docs/web.md, Choosing the value): axial, coronal and sagittal slices of the
// fetched volume beside the 3D view, in patient orientation as radiologists read them (axial seen
// from the feet, coronal from the front, sagittal from the patient's left), each with its window
// and level, a crosshair shared by the three and by a click on a surface in the 3D view, and each
// isosurface's contour on the slice in the surface's colour.
//
// Everything here reads the page's own copy of the volume (state.values, state.grid: volume.js),
// not the WebAssembly module, which may live elsewhere (a worker). A slice is a plane of the
// volume's grid: for each view the index axis nearest its patient axis (exact for the
// permutations and flips NIfTI and DICOM files have; a rotated grid is shown along its nearest
// axes, and the page says so). The contours are marching squares on the slice's grid points at
// each isovalue: where the slice lies on grid points, as it does here, they are the marching cubes
// surface's own intersection with the plane (its vertices on the plane's edges, interpolated the
// same way), so a contour on a slice is where the 3D surface cuts it.

import { AXES, lpsFromScenePoint, lpsFromSceneVector, sceneFromDrawnPoint, sceneFromDrawnVector, sceneFromLPSPoint, vec }
  from "./orientation.js";
import { CT_WINDOWS, isHounsfield } from "./presets.js";
import { $, state } from "./state.js";

// Each view: the patient axis it looks along (its normal), and the patient directions of the
// picture's right and down (LPS: +x left, +y posterior, +z superior).
const VIEW_DEFS = [
  { name: "axial", title: "Axial (from the feet)", normal: [0, 0, 1], right: [1, 0, 0], down: [0, 1, 0] },
  { name: "coronal", title: "Coronal (from the front)", normal: [0, 1, 0], right: [1, 0, 0], down: [0, 0, -1] },
  { name: "sagittal", title: "Sagittal (from the left)", normal: [1, 0, 0], right: [0, 1, 0], down: [0, 0, -1] },
];

const CROSSHAIR = "rgba(255, 214, 74, 0.8)";

let views = []; // per view: {def, canvas, select, axes, index, window}
let crosshair = null; // the crosshair's point, LPS mm
let geometry = null; // the grid the axes were chosen for
let note = "";

// The label of the patient direction `v` (one of AXES' ends).
const labelOf = (v) => AXES.find((a) => vec.dot(a.to, v) > 0.5).label;

// ---------------------------------------------------------------------------- the grid
// Continuous index coordinates of an LPS point, and back (the fetched level's grid).
function indexOf(p) {
  const { origin, spacing } = state.grid;
  const s = sceneFromLPSPoint(p);
  return [0, 1, 2].map((a) => (s[a] - origin[a]) / spacing[a]);
}
function pointOf(idx) {
  const { origin, spacing } = state.grid;
  return lpsFromScenePoint([0, 1, 2].map((a) => origin[a] + idx[a] * spacing[a]));
}

// For each view: which index axis is its normal (n), its picture's right (u) and down (v), and
// whether each runs along the patient direction (+1) or against it (-1).
function chooseAxes() {
  const columns = [0, 1, 2].map((a) => lpsFromSceneVector([0, 1, 2].map((b) => (a === b ? 1 : 0))));
  let oblique = false;
  for (const view of views) {
    const def = view.def;
    const along = (v, free) => free.reduce((best, a) =>
      Math.abs(vec.dot(columns[a], v)) > Math.abs(vec.dot(columns[best], v)) ? a : best, free[0]);
    const n = along(def.normal, [0, 1, 2]);
    const u = along(def.right, [0, 1, 2].filter((a) => a !== n));
    const v = [0, 1, 2].find((a) => a !== n && a !== u);
    oblique ||= [[n, def.normal], [u, def.right], [v, def.down]].some(([a, d]) =>
      Math.abs(Math.abs(vec.dot(columns[a], d)) - 1) > 1e-3);
    view.axes = { n, u, v, su: Math.sign(vec.dot(columns[u], def.right)) || 1,
      sv: Math.sign(vec.dot(columns[v], def.down)) || 1 };
  }
  note = oblique ? "The volume's grid is rotated in patient space: the slices are its grid planes " +
    "nearest to axial, coronal and sagittal." : "";
  geometry = state.grid;
}

// A view's picture coordinates (u right, v down; grid points at integers) of index coordinates.
function pictureOf(view, idx) {
  const { u, v, su, sv } = view.axes;
  const [nu, nv] = [state.grid.dims[u], state.grid.dims[v]];
  return [su > 0 ? idx[u] : nu - 1 - idx[u], sv > 0 ? idx[v] : nv - 1 - idx[v]];
}
function indexOfPicture(view, pu, pv) {
  const { n, u, v, su, sv } = view.axes;
  const idx = [0, 0, 0];
  idx[n] = view.index;
  idx[u] = su > 0 ? pu : state.grid.dims[u] - 1 - pu;
  idx[v] = sv > 0 ? pv : state.grid.dims[v] - 1 - pv;
  return idx;
}

// The slice's values in picture order (row by row, top to bottom), and its size.
function sliceValues(view) {
  const { dims } = state.grid;
  const { n, u, v, su, sv } = view.axes;
  const stride = [1, dims[0], dims[0] * dims[1]];
  const nu = dims[u], nv = dims[v];
  const out = new Float32Array(nu * nv);
  const values = state.values;
  const base = view.index * stride[n];
  for (let pv = 0; pv < nv; ++pv) {
    const row = base + (sv > 0 ? pv : nv - 1 - pv) * stride[v];
    const first = su > 0 ? row : row + (nu - 1) * stride[u];
    const step = su > 0 ? stride[u] : -stride[u];
    for (let pu = 0, o = pv * nu, at = first; pu < nu; ++pu, ++o, at += step) {
      out[o] = values[at];
    }
  }
  return { values: out, nu, nv };
}

// ---------------------------------------------------------------------------- contours
// Marching squares: for each cell of four grid points, the segments where the bilinear field
// crosses `iso`, their ends on the cell's edges by linear interpolation (as marching cubes puts
// its vertices). Corners at or above the value are inside; a saddle (two opposite corners in) is
// joined as the cell's centre, the mean of its corners, says. Returns [u0, v0, u1, v1, ...].
// Nothing is allocated per cell: a 512-wide slice has a quarter of a million cells per isovalue,
// and a small array per cell (its corners, each crossing) made the contours the larger part of a
// slice view's redraw, a main-thread task after every change (docs/web.md, The worker).
function marchingSquares(values, nu, nv, iso) {
  const out = [];
  // the crossing on edge e (0: corners 0-1, 1: 1-2, 2: 2-3, 3: 3-0) of the cell at (pu, pv),
  // corners counter-clockwise on the picture: 0 (u, v), 1 (u+1, v), 2 (u+1, v+1), 3 (u, v+1)
  const at = (e, pu, pv, c0, c1, c2, c3) => {
    switch (e) {
      case 0:
        out.push(pu + (iso - c0) / (c1 - c0), pv);
        break;
      case 1:
        out.push(pu + 1, pv + (iso - c1) / (c2 - c1));
        break;
      case 2:
        out.push(pu + 1 - (iso - c2) / (c3 - c2), pv + 1);
        break;
      default:
        out.push(pu, pv + 1 - (iso - c3) / (c0 - c3));
    }
  };
  for (let pv = 0; pv + 1 < nv; ++pv) {
    for (let pu = 0, o = pv * nu; pu + 1 < nu; ++pu, ++o) {
      const c0 = values[o], c1 = values[o + 1], c2 = values[o + nu + 1], c3 = values[o + nu];
      if (!(c0 === c0 && c1 === c1 && c2 === c2 && c3 === c3)) {
        continue; // NaN: no surface through the cell
      }
      const code = (c0 >= iso) | ((c1 >= iso) << 1) | ((c2 >= iso) << 2) | ((c3 >= iso) << 3);
      if (code === 0 || code === 15) {
        continue;
      }
      let e0 = -1, e1 = -1;
      switch (code) {
        case 1: case 14: e0 = 3; e1 = 0; break;
        case 2: case 13: e0 = 0; e1 = 1; break;
        case 3: case 12: e0 = 3; e1 = 1; break;
        case 4: case 11: e0 = 1; e1 = 2; break;
        case 6: case 9: e0 = 0; e1 = 2; break;
        case 7: case 8: e0 = 2; e1 = 3; break;
        default: { // 5, 10
          const centreIn = (c0 + c1 + c2 + c3) / 4 >= iso;
          // 5: corners 0 and 2 in. Centre in: the two are joined, cut off corners 1 and 3.
          if ((code === 5) === centreIn) {
            at(0, pu, pv, c0, c1, c2, c3);
            at(1, pu, pv, c0, c1, c2, c3);
            e0 = 2; e1 = 3;
          } else {
            at(3, pu, pv, c0, c1, c2, c3);
            at(0, pu, pv, c0, c1, c2, c3);
            e0 = 1; e1 = 2;
          }
        }
      }
      at(e0, pu, pv, c0, c1, c2, c3);
      at(e1, pu, pv, c0, c1, c2, c3);
    }
  }
  return out;
}

// ---------------------------------------------------------------------------- drawing
// Where the picture lies on the canvas (CSS pixels): the slice fitted, its voxels at their
// spacing's aspect; x = left + (u + 0.5) * du.
function placement(view) {
  const { u, v } = view.axes;
  const { dims, spacing } = state.grid;
  const width = view.canvas.clientWidth, height = view.canvas.clientHeight;
  const mmU = dims[u] * spacing[u], mmV = dims[v] * spacing[v];
  const scale = 0.9 * Math.min(width / mmU, (height - 16) / mmV); // CSS pixels per mm
  const du = spacing[u] * scale, dv = spacing[v] * scale;
  return { left: (width - mmU * scale) / 2, top: 8 + (height - 16 - mmV * scale) / 2, du, dv, mmPerPixel: 1 / scale };
}
function toCanvas(place, pu, pv) {
  return [place.left + (pu + 0.5) * place.du, place.top + (pv + 0.5) * place.dv];
}

function css(color) {
  return "rgb(" + color.map((c) => Math.round(255 * c)).join(",") + ")";
}

/**
 * The view's slice values (sliceValues) and its picture in `view.picture` at the view's window,
 * kept while the values, the slice and the window stay (state.values is never written in place:
 * a new level is a new array). A change of the surfaces, which redraws every view, then only
 * draws their contours: the slice's copy and picture were most of a 512-wide view's redraw, a
 * main-thread task after every change (docs/web.md, The worker).
 */
function slicePicture(view) {
  const { n, u, v, su, sv } = view.axes;
  const key = [view.index, n, u, v, su, sv].join();
  let slice = view.slice;
  if (!slice || slice.of !== state.values || slice.key !== key) {
    slice = view.slice = { of: state.values, key, window: "", ...sliceValues(view) };
  }
  const { values, nu, nv } = slice;
  const windowKey = view.window.level + "/" + view.window.width;
  if (slice.window !== windowKey) {
    const image = new ImageData(nu, nv);
    const low = view.window.level - view.window.width / 2, perValue = 255 / view.window.width;
    for (let i = 0; i < values.length; ++i) {
      const grey = (values[i] - low) * perValue; // NaN draws black
      image.data[4 * i] = image.data[4 * i + 1] = image.data[4 * i + 2] = grey;
      image.data[4 * i + 3] = 255;
    }
    view.picture.width = nu;
    view.picture.height = nv;
    view.picture.getContext("2d").putImageData(image, 0, 0);
    slice.window = windowKey;
  }
  return slice;
}

function drawView(view) {
  const canvas = view.canvas;
  const dpr = window.devicePixelRatio || 1;
  const width = canvas.clientWidth, height = canvas.clientHeight;
  if (!width || !height) {
    return;
  }
  const bw = Math.round(width * dpr), bh = Math.round(height * dpr);
  if (canvas.width !== bw || canvas.height !== bh) {
    canvas.width = bw;
    canvas.height = bh;
  }
  const g = canvas.getContext("2d");
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  g.fillStyle = "#000";
  g.fillRect(0, 0, width, height);
  const { values, nu, nv } = slicePicture(view);
  const place = placement(view);
  g.imageSmoothingEnabled = false; // voxels as they are
  g.drawImage(view.picture, place.left, place.top, nu * place.du, nv * place.dv);
  // the contours, each surface in its colour
  view.contours = state.surfaces.map((s) => ({ surface: s, segments: marchingSquares(values, nu, nv, s.value) }));
  g.lineWidth = 1.5;
  for (const { surface, segments } of view.contours) {
    g.strokeStyle = css(surface.color);
    g.beginPath();
    const { left, top, du, dv } = place; // toCanvas, without an array per point
    for (let i = 0; i < segments.length; i += 4) {
      g.moveTo(left + (segments[i] + 0.5) * du, top + (segments[i + 1] + 0.5) * dv);
      g.lineTo(left + (segments[i + 2] + 0.5) * du, top + (segments[i + 3] + 0.5) * dv);
    }
    g.stroke();
  }
  // the crosshair
  const [cu, cv] = pictureOf(view, indexOf(crosshair));
  const [cx, cy] = toCanvas(place, cu, cv);
  g.strokeStyle = CROSSHAIR;
  g.lineWidth = 1;
  g.setLineDash([4, 3]);
  g.beginPath();
  g.moveTo(cx, 0);
  g.lineTo(cx, height);
  g.moveTo(0, cy);
  g.lineTo(width, cy);
  g.stroke();
  g.setLineDash([]);
  // the patient's directions at the picture's edges, and what the view is
  g.fillStyle = "#ffcf8a";
  g.font = "bold 13px system-ui, sans-serif";
  g.textBaseline = "middle";
  const def = view.def, mid = height / 2;
  g.textAlign = "left";
  g.fillText(labelOf(vec.scale(def.right, -1)), 4, mid);
  g.textAlign = "right";
  g.fillText(labelOf(def.right), width - 4, mid);
  g.textAlign = "center"; // under the title's line, over the window's
  g.fillText(labelOf(vec.scale(def.down, -1)), width / 2, 24);
  g.fillText(labelOf(def.down), width / 2, height - 30);
  g.font = "11px system-ui, sans-serif";
  g.fillStyle = "#b8c0cc";
  g.textAlign = "left";
  g.textBaseline = "top";
  g.fillText(def.name + " " + view.index + "/" + (state.grid.dims[view.axes.n] - 1), 4, 2);
  g.textBaseline = "bottom";
  g.fillText("W " + round(view.window.width) + " L " + round(view.window.level), 4, height - 2);
  view.place = place;
}

const round = (x) => Number(x.toPrecision(4));

/** Draws the three views (after a frame: the surfaces may have changed). */
export function drawSlices() {
  if (!state.values || !views.length) {
    return;
  }
  if (geometry !== state.grid) {
    chooseAxes();
  }
  for (const view of views) {
    drawAtCrosshair(view);
  }
}

function drawAtCrosshair(view) {
  view.index = Math.min(state.grid.dims[view.axes.n] - 1,
    Math.max(0, Math.round(indexOf(crosshair)[view.axes.n])));
  drawView(view);
}

/**
 * drawSlices, each view in a task of its own (after a frame whose surfaces changed): on a 512^3
 * volume the three views' pictures and contours in one task made the page's one main-thread
 * task over the longtask budget during isovalue changes (docs/web.md, The worker).
 */
export function drawSlicesApart() {
  for (const view of views) {
    setTimeout(() => {
      if (state.values && views.includes(view)) {
        if (geometry !== state.grid) {
          chooseAxes();
        }
        drawAtCrosshair(view);
      }
    });
  }
}

// ---------------------------------------------------------------------------- the crosshair
/** Moves the crosshair (and so the slices) to an LPS point, kept within the volume. */
export function setCrosshair(p) {
  const idx = indexOf(p).map((x, a) => Math.min(state.grid.dims[a] - 1, Math.max(0, x)));
  crosshair = pointOf(idx);
  drawSlices();
  document.dispatchEvent(new CustomEvent("mediso:crosshair")); // the 3D view's cross, the URL
}

// The first point along the ray from the camera through (x, y) (CSS pixels of the 3D canvas)
// where the volume crosses a drawn isovalue, LPS mm; null where the ray meets none. The ray is
// marched in the fetched volume, half a voxel at a time, trilinearly, and the crossing placed
// by linear interpolation between the two samples around it.
export function pick(canvas, x, y) {
  const view = state.viewer.getView();
  const { origin, spacing, dims } = state.grid;
  const forward = vec.unit(vec.sub(view.focalPoint, view.position));
  const up0 = view.viewUp;
  const up = vec.unit(vec.sub(up0, vec.scale(forward, vec.dot(up0, forward))));
  const right = vec.cross(forward, up);
  const w = canvas.clientWidth, h = canvas.clientHeight;
  const tan = Math.tan((view.viewAngle * Math.PI) / 360);
  // the ray in the module's (drawn) frame, then in the grid's scene frame (a mirrored grid is
  // drawn reflected: orientation.js)
  const ray = sceneFromDrawnVector(vec.unit(vec.add(forward, vec.add(vec.scale(right, ((2 * x) / w - 1) * tan * (w / h)),
    vec.scale(up, (1 - (2 * y) / h) * tan)))));
  const eye = sceneFromDrawnPoint(view.position);
  // the ray's stretch inside the volume's box (scene frame)
  let t0 = 0, t1 = Infinity;
  for (let a = 0; a < 3; ++a) {
    const lo = origin[a], hi = origin[a] + (dims[a] - 1) * spacing[a];
    if (Math.abs(ray[a]) < 1e-12) {
      if (eye[a] < lo || eye[a] > hi) {
        return null;
      }
      continue;
    }
    let ta = (lo - eye[a]) / ray[a], tb = (hi - eye[a]) / ray[a];
    if (ta > tb) {
      [ta, tb] = [tb, ta];
    }
    t0 = Math.max(t0, ta);
    t1 = Math.min(t1, tb);
  }
  if (!(t0 < t1)) {
    return null;
  }
  const isovalues = state.surfaces.filter((s) => s.opacity > 0).map((s) => s.value);
  const step = 0.5 * Math.min(...spacing);
  const sample = (t) => trilinear([0, 1, 2].map((a) => (eye[a] + t * ray[a] - origin[a]) / spacing[a]));
  let previous = sample(t0);
  for (let t = t0 + step; t <= t1 + 1e-9; t += step) {
    const value = sample(Math.min(t, t1));
    for (const iso of isovalues) {
      if ((previous - iso) * (value - iso) <= 0 && previous !== value) {
        const at = t - step + ((iso - previous) / (value - previous)) * step;
        return lpsFromScenePoint([0, 1, 2].map((a) => eye[a] + at * ray[a]));
      }
    }
    previous = value;
  }
  return null;
}

function trilinear(idx) {
  const { dims } = state.grid;
  const values = state.values;
  const i0 = [0, 1, 2].map((a) => Math.min(dims[a] - 2, Math.max(0, Math.floor(idx[a]))));
  const f = [0, 1, 2].map((a) => (dims[a] < 2 ? 0 : Math.min(1, Math.max(0, idx[a] - i0[a]))));
  const sx = 1, sy = dims[0], sz = dims[0] * dims[1];
  const at = (i, j, k) => values[Math.max(0, i0[0] + i) * sx + Math.max(0, i0[1] + j) * sy + Math.max(0, i0[2] + k) * sz];
  const lerp = (a, b, t) => a + (b - a) * t;
  const x00 = lerp(at(0, 0, 0), at(1, 0, 0), f[0]), x10 = lerp(at(0, 1, 0), at(1, 1, 0), f[0]);
  const x01 = lerp(at(0, 0, 1), at(1, 0, 1), f[0]), x11 = lerp(at(0, 1, 1), at(1, 1, 1), f[0]);
  return lerp(lerp(x00, x10, f[1]), lerp(x01, x11, f[1]), f[2]);
}

// ---------------------------------------------------------------------------- windows
// The windows a view offers: the CT presets on a CT, the whole range, and the middle 99% of the
// values (from the histogram's counts).
function windowChoices(histogram) {
  const d = state.dataset;
  const choices = isHounsfield(d) ? CT_WINDOWS.map((w) => Object.assign({}, w)) : [];
  choices.push({ name: "Full range", width: d.range[1] - d.range[0] || 1, level: (d.range[0] + d.range[1]) / 2 });
  if (histogram) {
    const total = histogram.counts.reduce((a, b) => a + b, 0);
    const quantile = (q) => {
      let seen = 0;
      for (let i = 0; i < histogram.count; ++i) {
        seen += histogram.counts[i];
        if (seen >= q * total) {
          return histogram.low + (i + 0.5) * histogram.width;
        }
      }
      return d.range[1];
    };
    const lo = quantile(0.005), hi = quantile(0.995);
    choices.push({ name: "Middle 99%", width: hi - lo || 1, level: (lo + hi) / 2 });
  }
  return choices;
}

function setWindow(view, window) {
  view.window = { width: Math.max(1e-6, window.width), level: window.level };
  const match = view.choices.findIndex((c) => c.width === view.window.width && c.level === view.window.level);
  view.select.value = match >= 0 ? String(match) : "custom";
  drawView(view);
}

// ---------------------------------------------------------------------------- setup
/**
 * Makes the three views in #slices. `histogram` (histogram.js's counts) gives the non-CT
 * window; `changed` is called when the crosshair moves (the URL's state, if it keeps it).
 */
export function setupSlices(histogram) {
  const box = $("slices");
  const choices = windowChoices(histogram);
  views = VIEW_DEFS.map((def) => {
    const panel = Object.assign(document.createElement("div"), { className: "slice" });
    panel.dataset.view = def.name;
    const canvas = document.createElement("canvas");
    canvas.setAttribute("aria-label", def.title + " slice: click or drag to move the crosshair, " +
      "right- or shift-drag for the window (horizontal) and level (vertical), wheel or arrow keys to step");
    canvas.tabIndex = 0;
    const select = document.createElement("select");
    select.append(...choices.map((c, i) => Object.assign(document.createElement("option"),
      { value: String(i), textContent: c.name, title: "W " + round(c.width) + " L " + round(c.level) })),
    Object.assign(document.createElement("option"), { value: "custom", textContent: "dragged", disabled: true }));
    select.className = "window";
    select.setAttribute("aria-label", def.title + " window (width and level)");
    panel.append(canvas, select);
    box.append(panel);
    const view = { def, canvas, select, choices, picture: document.createElement("canvas"),
      index: 0, window: Object.assign({}, choices[0]), axes: null, place: null, contours: [] };
    select.onchange = () => setWindow(view, view.choices[Number(select.value)]);
    attach(view);
    return view;
  });
  for (const view of views) {
    view.select.value = "0";
  }
  const { dims } = state.grid;
  crosshair = pointOf(dims.map((n) => Math.floor((n - 1) / 2)));
  chooseAxes();
  if (note) {
    box.title = note;
  }
  new ResizeObserver(() => drawSlices()).observe(box);
  // A click on a surface in the 3D view (not a drag) moves the crosshair there.
  const view3d = $("view");
  let down = null;
  view3d.addEventListener("pointerdown", (e) => {
    down = e.button === 0 && !e.shiftKey ? [e.clientX, e.clientY] : null;
  });
  view3d.addEventListener("pointerup", (e) => {
    if (down && Math.hypot(e.clientX - down[0], e.clientY - down[1]) < 4) {
      const box3d = view3d.getBoundingClientRect();
      const hit = pick(view3d, e.clientX - box3d.left, e.clientY - box3d.top);
      if (hit) {
        setCrosshair(hit);
      }
    }
    down = null;
  });
  drawSlices();
}

/**
 * Another volume in the views (a local file: local.js): its windows (`histogram`: its counts),
 * the crosshair at its centre, its axes.
 */
export function resetSlices(histogram) {
  const choices = windowChoices(histogram);
  for (const view of views) {
    view.choices = choices;
    view.window = Object.assign({}, choices[0]);
    view.select.replaceChildren(...choices.map((c, i) => Object.assign(document.createElement("option"),
      { value: String(i), textContent: c.name, title: "W " + round(c.width) + " L " + round(c.level) })),
    Object.assign(document.createElement("option"), { value: "custom", textContent: "dragged", disabled: true }));
    view.select.value = "0";
  }
  geometry = null;
  chooseAxes();
  crosshair = pointOf(state.grid.dims.map((n) => Math.floor((n - 1) / 2)));
  $("slices").title = note;
  drawSlices();
}

// Mouse on a slice: left-click or drag moves the crosshair; right- or shift-drag sets the window
// (right: wider) and the level (up: higher); the wheel, and the up and down keys while the view
// has the focus, step through the slices.
function attach(view) {
  const canvas = view.canvas;
  let dragging = null;
  const moveTo = (e) => {
    const box = canvas.getBoundingClientRect();
    const place = view.place;
    const pu = (e.clientX - box.left - place.left) / place.du - 0.5;
    const pv = (e.clientY - box.top - place.top) / place.dv - 0.5;
    setCrosshair(pointOf(indexOfPicture(view, pu, pv)));
  };
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  canvas.addEventListener("pointerdown", (e) => {
    canvas.setPointerCapture(e.pointerId);
    canvas.focus({ preventScroll: true });
    if (e.button === 2 || e.shiftKey) {
      dragging = { window: true, x: e.clientX, y: e.clientY, start: Object.assign({}, view.window) };
    } else if (e.button === 0) {
      dragging = { window: false };
      moveTo(e);
    }
  });
  canvas.addEventListener("pointermove", (e) => {
    if (!dragging) {
      return;
    }
    if (!dragging.window) {
      moveTo(e);
      return;
    }
    const d = state.dataset;
    const perPixel = (d.range[1] - d.range[0]) / 400;
    setWindow(view, { width: Math.max(perPixel, dragging.start.width + (e.clientX - dragging.x) * perPixel),
      level: dragging.start.level - (e.clientY - dragging.y) * perPixel });
  });
  const end = () => { dragging = null; };
  canvas.addEventListener("pointerup", end);
  canvas.addEventListener("pointercancel", end);
  const step = (by) => {
    const idx = indexOf(crosshair);
    idx[view.axes.n] = Math.round(idx[view.axes.n]) + by;
    setCrosshair(pointOf(idx));
  };
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    step(Math.sign(e.deltaY));
  }, { passive: false });
  // A focused view keeps the arrow keys (not the 3D view's turns): up and down step its slices.
  canvas.addEventListener("keydown", (e) => {
    const by = { ArrowUp: 1, ArrowDown: -1, PageUp: 10, PageDown: -10 }[e.key];
    if (by !== undefined) {
      e.preventDefault();
      e.stopPropagation();
      step(by);
    }
  });
}

// ---------------------------------------------------------------------------- automation
/**
 * The views as drawn: for each, its name, labels (left, right, top, bottom), the index axis it
 * slices and the slice's index, its window, the crosshair's place on its canvas (CSS pixels),
 * the millimetres per CSS pixel, and (withContours) each surface's contour points in LPS mm.
 */
export function slicesInfo(withContours = false) {
  return views.map((view) => {
    const def = view.def;
    const place = view.place;
    const [cu, cv] = pictureOf(view, indexOf(crosshair));
    const out = {
      name: def.name, title: def.title,
      labels: { left: labelOf(vec.scale(def.right, -1)), right: labelOf(def.right),
        top: labelOf(vec.scale(def.down, -1)), bottom: labelOf(def.down) },
      axis: view.axes.n, index: view.index, count: state.grid.dims[view.axes.n],
      window: Object.assign({}, view.window), windowChoice: view.select.value,
      crosshair: toCanvas(place, cu, cv), mmPerPixel: place.mmPerPixel,
      canvas: (({ left, top, width, height }) => ({ left, top, width, height }))(view.canvas.getBoundingClientRect()),
      backingStore: [view.canvas.width, view.canvas.height],
    };
    if (withContours) {
      out.contours = view.contours.map(({ surface, segments }) => {
        const points = [];
        for (let i = 0; i < segments.length; i += 2) {
          points.push(pointOf(indexOfPicture(view, segments[i], segments[i + 1])));
        }
        return { value: surface.value, color: [...surface.color], points };
      });
    }
    return out;
  });
}

/** {point (LPS mm), note}: the crosshair, and what the page says of the slices' planes. */
export function crosshairInfo() {
  return { point: [...crosshair], note };
}

/** A view's window by its preset's name or as {width, level}. */
export function setSliceWindow(name, window) {
  const view = views.find((v) => v.def.name === name);
  if (!view) {
    throw new Error(name + " is not one of " + views.map((v) => v.def.name).join(", "));
  }
  const chosen = typeof window === "string" ? view.choices.find((c) => c.name === window) : window;
  if (!chosen) {
    throw new Error(window + " is not one of " + view.choices.map((c) => c.name).join(", "));
  }
  setWindow(view, chosen);
}
