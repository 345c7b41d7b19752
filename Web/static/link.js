// SPDX-License-Identifier: BSD-3-Clause
// The view in the URL's fragment (docs/web.md, State in the URL): the surfaces, the camera and
// the path, written as they change with history.replaceState (one entry, however many changes),
// and read at the start, so that a reload or a shared link shows the same view. The fragment
// never reaches the server. A value that cannot be used is left out with a note; the rest applies.
//
//   #iso=VALUE,RRGGBB,OPACITY;VALUE,RRGGBB,OPACITY&cam=PX,PY,PZ,FX,FY,FZ,UX,UY,UZ,ANGLE&xh=X,Y,Z&path=cpu
//
// xh: the slice views' crosshair (LPS mm), kept within the volume when applied.
//
// The camera is in patient space (LPS millimetres, orientation.js), so that a link means the same
// view of the same scan whatever the module's scene frame.

import { lpsFromDrawnPoint, lpsFromDrawnVector, sceneView, vec } from "./orientation.js";
import { crosshairInfo } from "./slices.js";
import { state } from "./state.js";
import { hasVolume } from "./volume.js";

const PATHS = ["auto", "gpu", "cpu"];
const hex = (color) => color.map((c) => Math.round(255 * c).toString(16).padStart(2, "0")).join("");
const number = (x) => Number(x.toPrecision(7));

/**
 * What the fragment asks for: {surfaces, camera (LPS), path, notes}. `range` is the dataset's
 * [min, max]; `maximum` the number of surfaces the module draws.
 */
export function readLink(hash, range, maximum) {
  const fields = new URLSearchParams(hash.replace(/^#/, ""));
  const out = { surfaces: null, camera: null, crosshair: null, path: null, notes: [] };
  if (fields.has("iso")) {
    const surfaces = [];
    for (const text of fields.get("iso").split(";").filter((t) => t !== "")) {
      const [v, c = "", o = "1"] = text.split(",");
      const value = Number(v), opacity = Number(o);
      if (v.trim() === "" || !Number.isFinite(value) || value < range[0] || value > range[1]) {
        out.notes.push("isovalue " + JSON.stringify(v) + " is not a number within " + range[0] +
          ".." + range[1]);
        continue;
      }
      const surface = { value };
      if (/^[0-9a-f]{6}$/i.test(c)) {
        surface.color = [0, 2, 4].map((i) => parseInt(c.substr(i, 2), 16) / 255);
      } else if (c !== "") {
        out.notes.push("colour " + JSON.stringify(c) + " is not RRGGBB");
      }
      if (Number.isFinite(opacity) && opacity >= 0 && opacity <= 1) {
        surface.opacity = opacity;
      } else {
        out.notes.push("opacity " + JSON.stringify(o) + " is not within 0..1");
      }
      surfaces.push(surface);
    }
    if (surfaces.length > maximum) {
      out.notes.push("only the first " + maximum + " of " + surfaces.length + " surfaces are drawn");
      surfaces.length = maximum;
    }
    out.surfaces = surfaces.length ? surfaces : null;
  }
  if (fields.has("cam")) {
    const n = fields.get("cam").split(",").map((t) => (t.trim() === "" ? NaN : Number(t)));
    const position = n.slice(0, 3), focalPoint = n.slice(3, 6), viewUp = n.slice(6, 9);
    const forward = vec.sub(focalPoint, position);
    const ok = (n.length === 9 || n.length === 10) && n.every(Number.isFinite) &&
      vec.norm(forward) > 0 && vec.norm(vec.cross(forward, viewUp)) > 1e-9 * vec.norm(forward) &&
      (n.length === 9 || (n[9] > 0 && n[9] < 180));
    if (ok) {
      out.camera = { position, focalPoint, viewUp, viewAngle: n[9] };
    } else {
      out.notes.push("the camera (" + fields.get("cam") + ") is not 9 numbers with distinct " +
        "position and focal point and a view up off the view direction, and a view angle 0-180");
    }
  }
  if (fields.has("xh")) {
    const n = fields.get("xh").split(",").map((t) => (t.trim() === "" ? NaN : Number(t)));
    if (n.length === 3 && n.every(Number.isFinite)) {
      out.crosshair = n;
    } else {
      out.notes.push("the crosshair (" + fields.get("xh") + ") is not 3 numbers");
    }
  }
  if (fields.has("path")) {
    if (PATHS.includes(fields.get("path"))) {
      out.path = fields.get("path");
    } else {
      out.notes.push("path " + JSON.stringify(fields.get("path")) + " is not auto, gpu or cpu");
    }
  }
  return out;
}

/** The camera of a link as the module's view (scene coordinates). */
export function linkedView(camera) {
  const view = sceneView(camera);
  if (camera.viewAngle !== undefined) {
    view.viewAngle = camera.viewAngle;
  }
  return view;
}

/** The fragment for the page's state now. */
export function writeLink() {
  const iso = state.surfaces.map((s) => number(s.value) + "," + hex(s.color) + "," + number(s.opacity));
  const v = state.viewer.getView();
  const cam = [...lpsFromDrawnPoint(v.position), ...lpsFromDrawnPoint(v.focalPoint),
    ...lpsFromDrawnVector(v.viewUp), v.viewAngle].map(number);
  let xh = "";
  try {
    xh = "&xh=" + crosshairInfo().point.map(number).join(",");
  } catch { /* no slice views yet */ }
  return "#iso=" + iso.join(";") + "&cam=" + cam.join(",") + xh + "&path=" + state.requestedPath;
}

let timer = 0;

/** Writes the fragment soon (once for a burst of changes), replacing the history entry. */
export function scheduleLink() {
  clearTimeout(timer);
  timer = setTimeout(() => {
    if (state.viewer && hasVolume()) {
      history.replaceState(history.state, "", writeLink());
    }
  }, 150);
}
