// SPDX-License-Identifier: BSD-3-Clause
// Interaction on the canvas: dragging turns the camera about the focal point (azimuth,
// elevation), the wheel dollies; each asks for one frame at the next animation frame.

import { state } from "./state.js";
import { requestFrame } from "./viewer.js";

export function interact(canvas) {
  let last = null;
  canvas.addEventListener("pointerdown", (e) => {
    last = [e.clientX, e.clientY];
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener("pointerup", () => { last = null; });
  canvas.addEventListener("pointermove", (e) => {
    if (!last) {
      return;
    }
    const dx = e.clientX - last[0], dy = e.clientY - last[1];
    last = [e.clientX, e.clientY];
    state.viewer.azimuth(-0.4 * dx);
    state.viewer.elevation(0.4 * dy);
    requestFrame();
  });
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    state.viewer.dolly(Math.pow(1.1, -e.deltaY / 100));
    requestFrame();
  }, { passive: false });
}
