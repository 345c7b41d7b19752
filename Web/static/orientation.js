// SPDX-License-Identifier: BSD-3-Clause
// Orientation: where the patient is in the picture (docs/web.md, Orientation).
//
// The module draws a volume in its *scene* frame: point (i, j, k) at origin + (i, j, k) * spacing,
// the direction matrix left out (the cores take an axis-aligned grid). The server states each
// volume's origin, spacing and direction matrix (/api/datasets), so the page knows where the scene
// lies in the source's world: world = origin + direction * (scene - origin). The source's world is
// NIfTI's RAS for a NIfTI file (and the plugin's phantom, written in the same frame), DICOM's LPS
// for a series, and ITK's LPS for MetaImage and the rest. The page states everything in patient
// space as DICOM and ITK do, LPS (x to the patient's left, y posterior, z superior): a RAS world
// is turned into LPS by negating x and y. The views, the marker, getView().world and the camera
// in the URL are all in LPS millimetres.
//
// The module's camera looks at the *drawn* frame: the scene itself, or, for a volume whose axes
// are a mirror image of patient space (determinant -1), the scene reflected along its first axis
// about the origin (the module's setDirection). Drawn so, the grid lies in patient space by a
// rotation, and the picture is the patient as seen, not a mirror image. The camera's conversions
// below go through the drawn frame; the slice views' through the scene (grid) frame.

import { state } from "./state.js";

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const norm = (a) => Math.hypot(a[0], a[1], a[2]);
const unit = (a) => scale(a, 1 / (norm(a) || 1));

export const vec = { dot, cross, add, sub, scale, norm, unit };

// The camera, per view: the direction from the focal point to the camera and the view up, in LPS.
// Anterior: the camera in front of the patient, the head up, the patient's left on the right of
// the picture (as when facing the patient). Superior and inferior: the nose up.
export const VIEWS = {
  anterior: { toCamera: [0, -1, 0], up: [0, 0, 1] },
  posterior: { toCamera: [0, 1, 0], up: [0, 0, 1] },
  left: { toCamera: [1, 0, 0], up: [0, 0, 1] },
  right: { toCamera: [-1, 0, 0], up: [0, 0, 1] },
  superior: { toCamera: [0, 0, 1], up: [0, -1, 0] },
  inferior: { toCamera: [0, 0, -1], up: [0, -1, 0] },
};

// The patient's axes, each end labelled (LPS: +x left, +y posterior, +z superior).
export const AXES = [
  { label: "L", to: [1, 0, 0], color: "#ff7a6b" }, { label: "R", to: [-1, 0, 0], color: "#ff7a6b" },
  { label: "P", to: [0, 1, 0], color: "#7bdc7b" }, { label: "A", to: [0, -1, 0], color: "#7bdc7b" },
  { label: "S", to: [0, 0, 1], color: "#82b4ff" }, { label: "I", to: [0, 0, -1], color: "#82b4ff" },
];

// The placement of the dataset shown: {origin, rows (scene -> LPS rotation, 3x3 row-major as
// arrays), source, space line}. Set once per dataset by setDataset.
let frame = null;

/**
 * What the source's world frame is: the server states it (the dataset's `format`: {name, space},
 * docs/web.md). Older servers state no format: then it is guessed from the dataset's name (a
 * NIfTI suffix RAS, the phantom RAS, a folder a DICOM series, the rest LPS), and the space line
 * says it was guessed.
 */
export function sourceFrame(d) {
  const stated = d.format && (d.format.space === "RAS" || d.format.space === "LPS");
  if (stated) {
    const name = d.format.name === "phantom" ? "the phantom" : d.format.name;
    return { world: d.format.space, source: name + " (" + d.format.space + ")" };
  }
  const name = String(d.name || "");
  const guessed = (frame) => ({ world: frame.world, source: frame.source + ", guessed from the name" });
  if (/\.nii(\.gz)?$/i.test(name)) {
    return guessed({ world: "RAS", source: "NIfTI (RAS)" });
  }
  if (/^MedicalPhantom/.test(name)) {
    return guessed({ world: "RAS", source: "the phantom (RAS, as NIfTI)" });
  }
  if (/\.(mha|mhd)$/i.test(name)) {
    return guessed({ world: "LPS", source: "MetaImage (taken as LPS, as ITK)" });
  }
  if (!/\.[a-z0-9]{2,4}$/i.test(name)) { // a folder: a DICOM series
    return guessed({ world: "LPS", source: "DICOM (LPS)" });
  }
  return guessed({ world: "LPS", source: "taken as LPS" });
}

/** The dataset's placement; returns a note when its direction matrix cannot be used. */
export function setDataset(d) {
  const { world, source } = sourceFrame(d);
  let m = Array.isArray(d.direction) && d.direction.length === 9 ? d.direction.map(Number) : null;
  let note = "";
  if (m) {
    const rows = [m.slice(0, 3), m.slice(3, 6), m.slice(6, 9)];
    const cols = [0, 1, 2].map((c) => rows.map((r) => r[c]));
    const orthonormal = cols.every((c, i) => cols.every((e, j) =>
      Math.abs(dot(c, e) - (i === j ? 1 : 0)) < 1e-3));
    if (!orthonormal || !m.every(Number.isFinite)) {
      note = "the direction matrix is not a rotation; the volume is shown unrotated";
      m = null;
    }
  }
  if (!m) {
    m = [1, 0, 0, 0, 1, 0, 0, 0, 1];
  }
  // LPS = F * world, F = diag(-1, -1, 1) for a RAS world.
  const f = world === "RAS" ? [-1, -1, 1] : [1, 1, 1];
  const rows = [0, 1, 2].map((r) => [0, 1, 2].map((c) => f[r] * m[3 * r + c]));
  // Axes that are a mirror image of patient space (determinant -1: a series read with its rows
  // flipped, as the cached ct_head.mha, or a NIfTI stored left to right) are drawn reflected
  // along the grid's first axis, so that the drawn frame is patient space turned, not mirrored.
  const mirrored = !note && dot(rows[0], cross(rows[1], rows[2])) < 0;
  frame = { origin: d.origin.map(Number), rows, flip: f, world, source, mirror: mirrored ? 0 : -1 };
  const drawn = [1, 0, 0, 0, 1, 0, 0, 0, 1];
  if (mirrored) {
    drawn[0] = -1;
  }
  if (state.viewer && state.viewer.setDirection) {
    state.viewer.setDirection(drawn);
  }
  const space = "patient space (LPS) from " + source +
    (mirrored ? "; its grid's axes are a mirror image of patient space, drawn reflected along i" : "");
  return { space, note };
}

// A vector in the scene as a vector in LPS, and back (the rotation's transpose).
export function lpsFromSceneVector(v) {
  return frame.rows.map((r) => dot(r, v));
}
export function sceneFromLPSVector(v) {
  return [0, 1, 2].map((c) => frame.rows[0][c] * v[0] + frame.rows[1][c] * v[1] + frame.rows[2][c] * v[2]);
}
// Points: LPS = F * (origin + D * (scene - origin)).
export function lpsFromScenePoint(p) {
  const o = frame.origin;
  return add(lpsFromSceneVector(sub(p, o)), [0, 1, 2].map((a) => frame.flip[a] * o[a]));
}
export function sceneFromLPSPoint(p) {
  const o = frame.origin;
  return add(o, sceneFromLPSVector(sub(p, [0, 1, 2].map((a) => frame.flip[a] * o[a]))));
}

// The drawn frame (the module's camera) and the scene: the same, or reflected along the grid's
// first axis about its origin (an involution: each direction is the same function).
export function sceneFromDrawnVector(v) {
  return frame.mirror < 0 ? v.slice() : v.map((x, a) => (a === frame.mirror ? -x : x));
}
export function sceneFromDrawnPoint(p) {
  const o = frame.origin;
  return frame.mirror < 0 ? p.slice() : p.map((x, a) => (a === frame.mirror ? 2 * o[a] - x : x));
}
export const lpsFromDrawnVector = (v) => lpsFromSceneVector(sceneFromDrawnVector(v));
export const lpsFromDrawnPoint = (p) => lpsFromScenePoint(sceneFromDrawnPoint(p));
export const drawnFromLPSVector = (v) => sceneFromDrawnVector(sceneFromLPSVector(v));
export const drawnFromLPSPoint = (p) => sceneFromDrawnPoint(sceneFromLPSPoint(p));

/** The module's view (drawn frame) with its world (LPS) placement added. */
export function withWorld(view) {
  const position = lpsFromDrawnPoint(view.position);
  const focalPoint = lpsFromDrawnPoint(view.focalPoint);
  return Object.assign({}, view, {
    world: {
      space: "LPS", position, focalPoint,
      viewUp: lpsFromDrawnVector(view.viewUp),
      direction: unit(sub(focalPoint, position)), // of projection: from the camera to the focal point
    },
  });
}

/** A view given in LPS ({position, focalPoint, viewUp}) as the module's (drawn frame) view. */
export function sceneView(world) {
  return {
    position: drawnFromLPSPoint(world.position),
    focalPoint: drawnFromLPSPoint(world.focalPoint),
    viewUp: drawnFromLPSVector(world.viewUp),
  };
}

/** The camera looking at the whole volume from `name` (VIEWS), at the reset camera's distance. */
export function applyNamedView(name) {
  const viewer = state.viewer;
  const preset = VIEWS[name];
  viewer.resetCamera();
  const v = viewer.getView();
  const distance = norm(sub(v.position, v.focalPoint));
  viewer.setView({
    position: add(v.focalPoint, scale(drawnFromLPSVector(preset.toCamera), distance)),
    focalPoint: v.focalPoint,
    viewUp: drawnFromLPSVector(preset.up),
  });
}

/** The camera's axes in the scene: right, up (orthogonal), from-camera direction, distance. */
export function cameraBasis(view) {
  const towards = sub(view.focalPoint, view.position);
  const distance = norm(towards);
  const forward = unit(towards);
  const up = unit(sub(view.viewUp, scale(forward, dot(view.viewUp, forward))));
  return { right: cross(forward, up), up, forward, distance };
}

/**
 * The patient's axes as the camera sees them: for each label, x (right) and y (up) on the
 * picture and `toward` (to the viewer), each the component of the unit axis.
 */
export function markerLabels(view) {
  const { right, up, forward } = cameraBasis(view);
  const out = {};
  for (const axis of AXES) {
    const s = drawnFromLPSVector(axis.to);
    out[axis.label] = { x: dot(s, right), y: dot(s, up), toward: -dot(s, forward) };
  }
  return out;
}

/** Draws the orientation marker (labelled axes) on its 2D canvas overlay. */
export function drawMarker(canvas, view) {
  const dpr = window.devicePixelRatio || 1;
  const size = canvas.clientWidth || 96;
  if (canvas.width !== Math.round(size * dpr)) {
    canvas.width = canvas.height = Math.round(size * dpr);
  }
  const g = canvas.getContext("2d");
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  g.clearRect(0, 0, size, size);
  const labels = markerLabels(view);
  const c = size / 2, r = size * 0.32;
  // Farthest first, so that the ends towards the viewer are drawn over the others.
  const order = AXES.slice().sort((a, b) => labels[a.label].toward - labels[b.label].toward);
  g.font = "bold " + Math.round(size * 0.14) + "px system-ui, sans-serif";
  g.textAlign = "center";
  g.textBaseline = "middle";
  for (const axis of order) {
    const p = labels[axis.label];
    const x = c + r * p.x, y = c - r * p.y;
    g.globalAlpha = p.toward < -0.2 ? 0.45 : 1;
    g.strokeStyle = axis.color;
    g.lineWidth = 2;
    g.beginPath();
    g.moveTo(c, c);
    g.lineTo(x, y);
    g.stroke();
    g.fillStyle = axis.color;
    g.fillText(axis.label, c + (r + size * 0.1) * p.x, c - (r + size * 0.1) * p.y);
  }
  g.globalAlpha = 1;
}
