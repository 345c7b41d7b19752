// SPDX-License-Identifier: BSD-3-Clause
// Interaction on the canvas: left-drag turns the camera about the focal point (azimuth,
// elevation); right-drag, middle-drag and shift-drag pan (the camera and its focal point move
// together in the picture's plane); the wheel dollies towards the point under the cursor; the
// arrow keys turn by 5 degrees and `r` resets to the anterior view; two fingers on a touch screen
// pan (their midpoint) and zoom (their spread) at once (twoFingers). Each asks for one frame at the
// next animation frame. Pan and zoom are computed here from the camera's own view (setView), so
// the module needs no camera operation of its own for them.

import { cameraBasis, vec } from "./orientation.js";
import { state } from "./state.js";
import { requestFrame } from "./viewer.js";

// World units per CSS pixel in the focal plane (perspective: the view angle is vertical).
function unitsPerPixel(canvas, view, distance) {
  const height = canvas.clientHeight || canvas.height;
  return 2 * distance * Math.tan((view.viewAngle * Math.PI) / 360) / height;
}

/** Moves the picture by (dx, dy) CSS pixels (right, down) without turning it. */
export function pan(canvas, dx, dy) {
  const view = state.viewer.getView();
  const { right, up, distance } = cameraBasis(view);
  const s = unitsPerPixel(canvas, view, distance);
  const t = vec.add(vec.scale(right, -dx * s), vec.scale(up, dy * s));
  state.viewer.setView({ position: vec.add(view.position, t), focalPoint: vec.add(view.focalPoint, t),
    viewUp: view.viewUp });
}

/**
 * Dollies by `factor` (> 1 nearer) towards the point of the focal plane under (x, y), CSS pixels
 * from the canvas's top left: that point stays under the cursor.
 */
export function zoomAt(canvas, x, y, factor) {
  const view = state.viewer.getView();
  const { right, up, forward, distance } = cameraBasis(view);
  const s = unitsPerPixel(canvas, view, distance);
  const w = canvas.clientWidth || canvas.width, h = canvas.clientHeight || canvas.height;
  const offset = vec.add(vec.scale(right, (x - w / 2) * s), vec.scale(up, (h / 2 - y) * s));
  const focal = vec.add(view.focalPoint, vec.scale(offset, 1 - 1 / factor));
  state.viewer.setView({ position: vec.sub(focal, vec.scale(forward, distance / factor)),
    focalPoint: focal, viewUp: view.viewUp });
}

/** `changed` is called after every camera change (the URL's state). */
export function interact(canvas, { reset, changed }) {
  let last = null, panning = false;
  const moved = () => {
    requestFrame();
    changed();
  };
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  canvas.addEventListener("pointerdown", (e) => {
    last = [e.clientX, e.clientY];
    panning = e.button === 2 || e.button === 1 || e.shiftKey;
    canvas.setPointerCapture(e.pointerId);
    canvas.focus({ preventScroll: true });
  });
  // The frames of a drag are interactive (a coarser level, viewer.js); its end asks for the
  // full frame.
  const release = () => {
    last = null;
    if (state.interacting) {
      state.interacting = false;
      requestFrame();
    }
  };
  canvas.addEventListener("pointerup", release);
  canvas.addEventListener("pointercancel", release);
  const fingers = twoFingers(canvas, moved);
  canvas.addEventListener("pointermove", (e) => {
    if (!last || fingers.active()) {
      return;
    }
    const dx = e.clientX - last[0], dy = e.clientY - last[1];
    last = [e.clientX, e.clientY];
    state.interacting = true;
    if (panning) {
      pan(canvas, dx, dy);
    } else {
      state.viewer.azimuth(-0.4 * dx);
      state.viewer.elevation(0.4 * dy);
    }
    moved();
  });
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    const box = canvas.getBoundingClientRect();
    zoomAt(canvas, e.clientX - box.left, e.clientY - box.top, Math.pow(1.1, -e.deltaY / 100));
    moved();
  }, { passive: false });
  // Keys anywhere on the page but in a box or a list (the buttons keep them: after a view button,
  // the arrows turn that view).
  document.addEventListener("keydown", (e) => {
    if (e.ctrlKey || e.metaKey || e.altKey || e.target.closest?.("input, select, textarea")) {
      return;
    }
    const turns = { ArrowLeft: [5, 0], ArrowRight: [-5, 0], ArrowUp: [0, 5], ArrowDown: [0, -5] };
    if (e.key === "r" || e.key === "R") {
      reset();
    } else if (turns[e.key]) {
      state.viewer.azimuth(turns[e.key][0]);
      state.viewer.elevation(turns[e.key][1]);
    } else {
      return;
    }
    e.preventDefault();
    moved();
  });
}

/**
 * Two touches on the canvas: the picture follows their midpoint (pan) and their spread (zoom at
 * the midpoint, the distance between the fingers' ratio), as on a map; while two are down the
 * one-finger turn is left alone (`active`). Pointer events: a touch is a pointer of type "touch".
 */
function twoFingers(canvas, moved) {
  const touches = new Map(); // pointerId -> [x, y] (CSS pixels of the canvas)
  const at = (e) => {
    const box = canvas.getBoundingClientRect();
    return [e.clientX - box.left, e.clientY - box.top];
  };
  const pair = () => {
    const [a, b] = [...touches.values()];
    return { mid: [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2], spread: Math.hypot(a[0] - b[0], a[1] - b[1]) };
  };
  canvas.addEventListener("pointerdown", (e) => {
    if (e.pointerType === "touch") {
      touches.set(e.pointerId, at(e));
    }
  });
  const lift = (e) => touches.delete(e.pointerId);
  canvas.addEventListener("pointerup", lift);
  canvas.addEventListener("pointercancel", lift);
  canvas.addEventListener("pointermove", (e) => {
    if (e.pointerType !== "touch" || !touches.has(e.pointerId) || touches.size !== 2) {
      return;
    }
    const before = pair();
    touches.set(e.pointerId, at(e));
    const after = pair();
    state.interacting = true;
    pan(canvas, after.mid[0] - before.mid[0], after.mid[1] - before.mid[1]);
    if (before.spread > 0 && after.spread > 0) {
      zoomAt(canvas, after.mid[0], after.mid[1], after.spread / before.spread);
    }
    moved();
  });
  return { active: () => touches.size >= 2 };
}
