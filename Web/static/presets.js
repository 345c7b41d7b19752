// SPDX-License-Identifier: BSD-3-Clause
// Choosing the value (docs/web.md, Choosing the value): the surfaces a volume opens with, the
// CT surface presets in Hounsfield units and the slice views' CT windows.
//
// The first surfaces follow the ParaView side's rule (Filters/Core/HistogramThreshold.h, handed
// over by the WebAssembly module as state.facts.hounsfield and .otsuThreshold): a range that
// looks like Hounsfield units (the minimum near air, the maximum above soft tissue) opens with
// translucent skin and opaque bone; anything else with Otsu's threshold of the volume's
// histogram (histogram.js), in the volume's own unit, rather than the middle of the range.

import { state } from "./state.js";

export const SKIN = [0.93, 0.75, 0.62];
export const BONE = [0.97, 0.95, 0.88];
const SOFT = [0.86, 0.45, 0.42];
const VESSELS = [0.85, 0.16, 0.2];

/** Whether the dataset's range is a CT's in Hounsfield units (the cores' rule). */
export function isHounsfield(d) {
  return state.facts.hounsfield.looksLike(d.range[0], d.range[1]);
}

/**
 * The CT surfaces one click adds (Hounsfield units): skin and bone from the cores' constants,
 * soft tissue and contrast-filled vessels (about 200 HU: above muscle, below cortical bone).
 */
export function surfacePresets() {
  const h = state.facts.hounsfield;
  return [
    { name: "Skin", value: h.skin, color: SKIN, opacity: 0.35 },
    { name: "Soft tissue", value: 40, color: SOFT, opacity: 0.5 },
    { name: "Contrast vessels", value: 200, color: VESSELS, opacity: 1 },
    { name: "Bone", value: h.bone, color: BONE, opacity: 1 },
  ];
}

/** The slice views' windows for a CT (width and level in Hounsfield units). */
export const CT_WINDOWS = [
  { name: "Soft tissue", width: 400, level: 40 },
  { name: "Brain", width: 80, level: 40 },
  { name: "Lung", width: 1500, level: -600 },
  { name: "Bone", width: 1800, level: 400 },
];

/**
 * The surfaces a dataset opens with: skin (translucent) and bone on a CT; otherwise one surface
 * at Otsu's threshold of `histogram` (histogram.js's counts of the fetched volume), or at the
 * middle of the range where the histogram has nothing to split.
 */
export function firstSurfaces(d, histogram) {
  const presets = surfacePresets();
  if (isHounsfield(d)) {
    return [presets[0], presets[3]].map(({ value, color, opacity }) => ({ value, color, opacity }));
  }
  const otsu = histogram ? histogram.otsu : NaN;
  const value = Number.isFinite(otsu) ? otsu : d.range[0] + 0.5 * (d.range[1] - d.range[0]);
  return [{ value, color: SKIN, opacity: 1 }];
}

/**
 * The CT preset buttons in #presets: each adds its surface (through `add`, app.js's
 * replaceSurfaces), up to the module's limit of surfaces. On a volume that is not in Hounsfield
 * units the row says why there are none.
 */
export function setupPresets(add) {
  const box = document.getElementById("presets");
  const d = state.dataset;
  if (!isHounsfield(d)) {
    box.textContent = "CT presets: none, the range " + d.range.join("..") + " is not a CT's in Hounsfield units.";
    return;
  }
  box.replaceChildren("CT presets (HU): ", ...surfacePresets().map((preset) => {
    const button = Object.assign(document.createElement("button"), {
      textContent: preset.name, title: "Add a surface at " + preset.value + " HU (" + preset.name.toLowerCase() + ")" });
    button.dataset.preset = preset.name;
    button.onclick = () => {
      if (state.surfaces.length < state.facts.maximumIsovalues) {
        add([...state.surfaces, { value: preset.value, color: preset.color, opacity: preset.opacity }]);
      }
    };
    return button;
  }));
}
