// SPDX-License-Identifier: BSD-3-Clause
// The slice views' crosshair (slices.js: a point in LPS mm) shown in the 3D view: a small cross
// on a 2D canvas over the view, where the camera projects the point, redrawn after every frame
// (the camera moved) and when the crosshair moves (slices.js's "mediso:crosshair" event). It is
// drawn over the surfaces, not hidden by them: the point is inside the volume, usually behind a
// surface, and the cross says where it is, as the slice views do.

import { withWorld, vec } from "./orientation.js";
import { crosshairInfo } from "./slices.js";
import { state } from "./state.js";

let overlay = null;
let view3d = null;

/**
 * Where the camera draws an LPS point on the 3D view: {x, y} in CSS pixels from its top left,
 * or null behind the camera. The inverse of slices.js's pick ray (a perspective camera).
 */
export function projectToView(point) {
  const v = withWorld(state.viewer.getView());
  const w = v.world;
  const forward = w.direction;
  const up = vec.unit(vec.sub(w.viewUp, vec.scale(forward, vec.dot(w.viewUp, forward))));
  const right = vec.cross(forward, up);
  const d = vec.sub(point, w.position);
  const depth = vec.dot(d, forward);
  if (!(depth > 0)) {
    return null;
  }
  const width = view3d.clientWidth, height = view3d.clientHeight;
  const tan = Math.tan((v.viewAngle * Math.PI) / 360);
  return {
    x: (width / 2) * (1 + vec.dot(d, right) / (depth * tan * (width / height))),
    y: (height / 2) * (1 - vec.dot(d, up) / (depth * tan)),
  };
}

/** Draws the cross where the crosshair is (nothing before the slice views have one). */
export function drawCrosshair3D() {
  if (!overlay || !state.viewer || !state.grid) {
    return;
  }
  const dpr = window.devicePixelRatio || 1;
  const width = view3d.clientWidth, height = view3d.clientHeight;
  // over the view's box (which ?size=WxH fixes and centres)
  Object.assign(overlay.style, { left: view3d.offsetLeft + "px", top: view3d.offsetTop + "px",
    width: width + "px", height: height + "px" });
  if (overlay.width !== Math.round(width * dpr) || overlay.height !== Math.round(height * dpr)) {
    overlay.width = Math.round(width * dpr);
    overlay.height = Math.round(height * dpr);
  }
  const g = overlay.getContext("2d");
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  g.clearRect(0, 0, width, height);
  let point;
  try {
    point = crosshairInfo().point;
  } catch {
    return; // the slice views are not set up yet
  }
  const p = point && projectToView(point);
  overlay.dataset.at = p ? p.x.toFixed(1) + "," + p.y.toFixed(1) : "";
  if (!p) {
    return;
  }
  // a cross with a gap at its centre, dark under light, so that it shows on any surface
  for (const [color, lineWidth] of [["rgba(0, 0, 0, 0.7)", 3], ["#ffd34d", 1.5]]) {
    g.strokeStyle = color;
    g.lineWidth = lineWidth;
    g.beginPath();
    for (const [dx, dy] of [[1, 0], [-1, 0], [0, 1], [0, -1]]) {
      g.moveTo(p.x + 3 * dx, p.y + 3 * dy);
      g.lineTo(p.x + 10 * dx, p.y + 10 * dy);
    }
    g.stroke();
  }
}

/** The overlay over the 3D view `canvas` (in its #stage), redrawn when the crosshair moves. */
export function setupCrosshair3D(canvas, moved) {
  view3d = canvas;
  overlay = document.createElement("canvas");
  overlay.id = "crosshair3d";
  overlay.setAttribute("aria-hidden", "true");
  overlay.style.cssText = "position: absolute; pointer-events: none;";
  canvas.after(overlay);
  document.addEventListener("mediso:crosshair", () => {
    drawCrosshair3D();
    moved();
  });
}
