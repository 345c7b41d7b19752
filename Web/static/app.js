// SPDX-License-Identifier: BSD-3-Clause
// The web client (docs/web.md): the volume is fetched once; isosurfaces are then computed and
// drawn in this browser by the same C++ core the ParaView plugin runs, compiled to WebAssembly
// (mediso.js / mediso.wasm). Changing an isovalue, a colour or the camera sends nothing; the
// server is asked only for what needs its libraries (further operations on a surface).

import { setupOperations } from "./operations.js";

const TYPES = ["int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"];
const SIZES = [1, 1, 2, 2, 4, 4, 4, 8];
const SKIN = [0.93, 0.75, 0.62];
const BONE = [0.97, 0.95, 0.88];

const params = new URLSearchParams(location.search);
const token = params.get("token") || "";
const $ = (id) => document.getElementById(id);

const state = {
  module: null,
  viewer: null,
  dataset: null,
  surfaces: [],
  path: "gpu",
  requestedPath: params.get("path") || "auto",
  reason: "",
  software: false,
  unmaskedRenderer: "",
  level: 3,
  levelNote: "",
  bytesSent: 0,
  bytesReceived: 0,
  frameTimes: [],
  lastChangeMs: 0,
  lastFrameMs: 0,
  buildMs: 0,
  primitives: 0,
  triangles: 0,
  pending: null,
};

function withToken(url) {
  return url + (url.includes("?") ? "&" : "?") + "token=" + encodeURIComponent(token);
}

// Every request of the page's own goes through here, so that the bytes are counted.
async function request(url) {
  const full = withToken(url);
  state.bytesSent += full.length + 64; // the request line and the few headers a browser adds
  const response = await fetch(full, { cache: "no-store" });
  if (!response.ok) {
    throw new Error(url + ": " + response.status + " " + (await response.text()));
  }
  const wire = Number(response.headers.get("Content-Length") || 0);
  const body = await response.arrayBuffer();
  state.bytesReceived += (wire || body.byteLength) + 200;
  return { response, body };
}

async function requestJSON(url) {
  const { body } = await request(url);
  return JSON.parse(new TextDecoder().decode(body));
}

// Says, in place of the page, why it cannot run here; the start then fails with that text.
function unsupported(text) {
  $("app").hidden = true;
  const box = $("unsupported");
  box.hidden = false;
  box.textContent = text;
  return new Error(text);
}

// ---------------------------------------------------------------------------- the volume
function unshuffle(shuffled, size) {
  if (size === 1) {
    return shuffled;
  }
  const n = shuffled.length / size;
  const out = new Uint8Array(shuffled.length);
  for (let b = 0; b < size; ++b) {
    const plane = shuffled.subarray(b * n, (b + 1) * n);
    for (let i = 0, o = b; i < n; ++i, o += size) {
      out[o] = plane[i];
    }
  }
  return out;
}

// The finest level (3: full) of the volume a path can afford. GPU: its texture within the
// WebGL limits, the volume and the pyramid (about 1.1x the volume) within the budget. CPU: the
// volume within half the budget (the surfaces and their cache take the rest).
function chooseLevel(dataset, info, budgetMB, path) {
  for (let k = 3; k >= 0; --k) {
    const level = dataset.levels[k];
    const d = level.dims;
    const fitsGL = path === "cpu" || Math.max(Math.ceil(d[0] / 4), d[1], d[2]) <= info.max3DTextureSize;
    const fitsBudget = (path === "cpu" ? 2 : 1.1) * level.bytes <= budgetMB * 1e6;
    if (fitsGL && fitsBudget) {
      const why = k === 3 ? "" :
        "The volume is sent at level " + k + " (every " + (1 << (3 - k)) + "th point, " +
        d.join("x") + "): the full " + dataset.dims.join("x") + " volume exceeds " +
        (fitsGL ? "the memory budget." : "this WebGL's 3D texture limit.");
      return { level: k, why };
    }
  }
  return { level: 0, why: "Even level 0 of the volume exceeds the memory budget." };
}

// The path: what the user asked for, else from what the browser has. Both draw with WebGL2; the
// GPU path ray-casts every covered pixel, which a software rasteriser does on the CPU, where the
// CPU path's triangles are cheaper.
function choosePath(requested, info, dataset, budgetMB) {
  const gpu = chooseLevel(dataset, info, budgetMB, "gpu");
  const cpu = chooseLevel(dataset, info, budgetMB, "cpu");
  if (requested === "gpu" || requested === "cpu") {
    return { path: requested, level: requested === "gpu" ? gpu : cpu, why: "chosen by the user" };
  }
  if (state.software) {
    return { path: "cpu", level: cpu,
      why: "auto: the WebGL2 renderer is software (" + state.unmaskedRenderer + "), where the " +
        "triangles of the CPU path draw faster than per-pixel ray casting" };
  }
  if (gpu.level < cpu.level) {
    return { path: "cpu", level: cpu,
      why: "auto: the GPU path would need a coarser volume (" + gpu.why + ")" };
  }
  return { path: "gpu", level: gpu, why: "auto: WebGL2 on " + state.unmaskedRenderer };
}

// Sets the path and fetches the volume again only if the path needs another level of it.
async function applyPath() {
  const budgetMB = Number($("budget").value) || 1024;
  const choice = choosePath(state.requestedPath, state.viewer.info(), state.dataset, budgetMB);
  state.path = choice.path;
  state.reason = choice.why;
  state.levelNote = choice.level.why;
  $("why").textContent = (choice.path === "gpu" ? "GPU path" : "CPU path") + " (" + choice.why +
    "). " + choice.level.why;
  $("path").value = state.requestedPath;
  state.viewer.setPath(choice.path);
  if (!state.volumePointer || state.level !== choice.level.level) {
    await loadVolume(choice.level.level);
  }
  const volumeBytes = state.dataset.levels[state.level].bytes;
  state.viewer.setBudget(Math.max(0, budgetMB * 1e6 - volumeBytes));
}

async function loadVolume(level) {
  const d = state.dataset;
  const { response, body } = await request("/api/volume/" + d.id + "?level=" + level);
  const type = TYPES.indexOf(response.headers.get("X-Mediso-Type"));
  const dims = response.headers.get("X-Mediso-Dims").split(",").map(Number);
  const spacing = response.headers.get("X-Mediso-Spacing").split(",").map(Number);
  const origin = response.headers.get("X-Mediso-Origin").split(",").map(Number);
  const bytes = unshuffle(new Uint8Array(body), SIZES[type]);
  const M = state.module;
  if (state.volumePointer) {
    M._free(state.volumePointer);
  }
  state.volumePointer = M._malloc(bytes.length);
  M.HEAPU8.set(bytes, state.volumePointer);
  state.level = level;
  if (!state.viewer.setVolume(type, state.volumePointer, dims, spacing, origin)) {
    throw new Error("the volume cannot be uploaded: " + state.viewer.stats().error);
  }
}

// ---------------------------------------------------------------------------- rendering
function defaultSurfaces(d) {
  if (d.range[0] <= -900 && d.range[1] >= 400) { // a CT in Hounsfield units
    return [{ value: -500, color: SKIN, opacity: 0.35 }, { value: 400, color: BONE, opacity: 1 }];
  }
  const v = d.range[0] + 0.3 * (d.range[1] - d.range[0]);
  return [{ value: Number(v.toPrecision(4)), color: SKIN, opacity: 1 }];
}

// Draws now and waits for the GPU: the time of a change + frame.
function renderNow() {
  const viewer = state.viewer;
  viewer.setSurfaces(state.surfaces);
  const start = performance.now();
  if (!viewer.render()) {
    throw new Error("render failed: " + viewer.stats().error);
  }
  viewer.finish();
  const ms = performance.now() - start;
  state.frameTimes.push({ at: performance.now(), ms });
  if (state.frameTimes.length > 120) {
    state.frameTimes.shift();
  }
  state.lastFrameMs = ms;
  const stats = viewer.stats();
  state.buildMs = stats.buildMs;
  state.primitives = stats.primitives;
  state.triangles = stats.triangles;
  state.cpuLevel = stats.cpuLevel;
  updateReadout();
  return ms;
}

// Frames on request (interaction), at most one per animation frame.
function requestFrame() {
  if (!state.pending) {
    state.pending = requestAnimationFrame(() => {
      state.pending = null;
      renderNow();
    });
  }
}

function fps() {
  const now = performance.now();
  const recent = state.frameTimes.filter((f) => now - f.at < 1000);
  if (recent.length >= 2) {
    return recent.length / ((recent[recent.length - 1].at - recent[0].at) / 1000 || 1);
  }
  const last = state.frameTimes[state.frameTimes.length - 1];
  return last ? 1000 / last.ms : 0;
}

function updateReadout() {
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

// ---------------------------------------------------------------------------- the panel
function hex(color) {
  return "#" + color.map((c) => Math.round(255 * c).toString(16).padStart(2, "0")).join("");
}

function fromHex(text) {
  return [1, 3, 5].map((i) => parseInt(text.substr(i, 2), 16) / 255);
}

function change(apply) {
  apply();
  state.lastChangeMs = renderNow();
  updateReadout();
}

function buildSurfaceList() {
  const d = state.dataset;
  const box = $("surfaces");
  box.replaceChildren();
  state.surfaces.forEach((s, i) => {
    const row = document.createElement("div");
    row.className = "surface";
    const value = Object.assign(document.createElement("input"),
      { type: "number", step: "any", value: s.value });
    const color = Object.assign(document.createElement("input"), { type: "color", value: hex(s.color) });
    const opacity = Object.assign(document.createElement("input"),
      { type: "number", min: 0, max: 1, step: 0.05, value: s.opacity, title: "opacity" });
    const remove = Object.assign(document.createElement("button"), { textContent: "x" });
    const slider = Object.assign(document.createElement("input"),
      { type: "range", min: d.range[0], max: d.range[1], step: "any", value: s.value });
    value.oninput = () => change(() => { s.value = Number(value.value); slider.value = value.value; });
    slider.oninput = () => change(() => { s.value = Number(slider.value); value.value = slider.value; });
    color.oninput = () => change(() => { s.color = fromHex(color.value); });
    opacity.oninput = () => change(() => { s.opacity = Math.min(1, Math.max(0, Number(opacity.value))); });
    remove.onclick = () => change(() => { state.surfaces.splice(i, 1); buildSurfaceList(); });
    row.append(value, color, opacity, remove, slider);
    box.append(row);
  });
  const pick = $("op-surface");
  pick.replaceChildren(...state.surfaces.map((s, i) =>
    Object.assign(document.createElement("option"), { value: i, textContent: String(s.value) })));
}

function interact(canvas) {
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

// ---------------------------------------------------------------------------- start
// The WebAssembly module: with threads where the page is cross-origin isolated (the server
// sends the headers), else on one thread.
async function loadModule() {
  const threads = window.crossOriginIsolated && params.get("threads") !== "0";
  const name = threads ? "mediso-mt" : "mediso";
  await new Promise((resolve, reject) => {
    const script = Object.assign(document.createElement("script"), { src: "static/" + name + ".js" });
    script.onload = resolve;
    script.onerror = () => reject(new Error("static/" + name + ".js cannot be loaded"));
    document.head.append(script);
  });
  state.threads = threads ? navigator.hardwareConcurrency : 1;
  const create = threads ? window.createMedisoThreads : window.createMediso;
  return create({ locateFile: (f) => "static/" + f });
}

async function start() {
  const probe = document.createElement("canvas").getContext("webgl2");
  if (typeof WebAssembly !== "object" || !probe) {
    throw unsupported("This page computes isosurfaces in the browser with WebAssembly and WebGL2, " +
      "and this browser has " + (typeof WebAssembly !== "object" ? "no WebAssembly" : "no WebGL2") +
      ". Use a current Chrome, Edge, Firefox or Safari with hardware acceleration on.");
  }
  $("app").hidden = false;
  state.module = await loadModule();
  const canvas = $("view");
  if (params.get("size")) { // WIDTHxHEIGHT (tests, benchmarks)
    [canvas.width, canvas.height] = params.get("size").split("x").map(Number);
  }
  state.viewer = new state.module.WebViewer("#view");
  state.viewer.resize(canvas.width, canvas.height);
  if (!state.viewer.ready()) {
    throw unsupported("WebGL2 is here but cannot run the GPU path: " + state.viewer.error());
  }
  const debug = probe.getExtension("WEBGL_debug_renderer_info");
  state.unmaskedRenderer = debug ? probe.getParameter(debug.UNMASKED_RENDERER_WEBGL)
                                 : state.viewer.info().renderer;
  state.software = /SwiftShader|llvmpipe|softpipe|Software/i.test(state.unmaskedRenderer);
  if (params.get("budget")) {
    $("budget").value = params.get("budget");
  }
  const list = await requestJSON("/api/datasets");
  state.dataset = list.datasets[0];
  const d = state.dataset;
  $("dataset").textContent = d.name + ": " + d.dims.join("x") + " " + d.type + ", " +
    (d.bytes / 1e6).toFixed(1) + " MB, range " + d.range[0] + ".." + d.range[1];
  await applyPath();
  $("path").onchange = async () => {
    state.requestedPath = $("path").value;
    await applyPath();
    change(() => {});
  };
  $("budget").onchange = async () => {
    await applyPath();
    change(() => {});
  };
  state.surfaces = defaultSurfaces(d);
  buildSurfaceList();
  interact(canvas);
  $("add").onclick = () => change(() => {
    state.surfaces.push({ value: d.range[0] + 0.5 * (d.range[1] - d.range[0]), color: BONE, opacity: 1 });
    buildSurfaceList();
  });
  renderNow();
  // The "On the server" panel (Web/static/operations.js) is given what it needs here.
  setupOperations({
    dataset: d,
    token,
    surfaces: () => state.surfaces,
    // The page's surfaces as a level of the whole volume: the GPU path draws the fetched level
    // in full, the CPU path its own level of that.
    level: () => (state.path === "cpu" ? Math.max(0, state.cpuLevel + state.level - 3) : state.level),
    request,
    count(sent, received) {
      state.bytesSent += sent;
      state.bytesReceived += received;
      updateReadout();
    },
  });
}

// ---------------------------------------------------------------------------- automation
let resolveReady, rejectReady;
const ready = new Promise((resolve, reject) => { resolveReady = resolve; rejectReady = reject; });
ready.catch(() => {}); // said on the page; automation awaits it and gets the reason

window.mediso = {
  ready,
  async setIsovalues(values) {
    change(() => {
      state.surfaces = values.map((v, i) => ({
        value: v,
        color: (state.surfaces[i] || {}).color || BONE,
        opacity: (state.surfaces[i] || {}).opacity ?? 1,
      }));
      buildSurfaceList();
    });
    return window.mediso.stats();
  },
  async setSurfaces(surfaces) {
    change(() => {
      state.surfaces = surfaces.map((s) => ({ value: s.value, color: s.color || BONE, opacity: s.opacity ?? 1 }));
      buildSurfaceList();
    });
    return window.mediso.stats();
  },
  async setView(view) {
    state.viewer.setView(view);
    renderNow();
    return state.viewer.getView();
  },
  getView: () => state.viewer.getView(),
  // Lighting material and background (tests match them with ParaView's).
  async setLook({ ambient, diffuse, specular, specularPower, background }) {
    if (ambient !== undefined) {
      state.viewer.setMaterial(ambient, diffuse, specular, specularPower);
    }
    if (background) {
      state.viewer.setBackground(...background);
    }
    renderNow();
  },
  stats: () => ({
    path: state.path,
    reason: state.reason,
    cpuLevel: state.cpuLevel,
    threads: state.threads,
    level: state.level,
    levelNote: state.levelNote,
    primitives: state.primitives,
    triangles: state.triangles,
    fps: fps(),
    lastChangeMs: state.lastChangeMs,
    // the last frame's time, and the part of it that built the pyramid or the surfaces (0 when
    // only the camera or the looks changed)
    lastFrameMs: state.lastFrameMs,
    buildMs: state.buildMs,
    bytesSent: state.bytesSent,
    bytesReceived: state.bytesReceived,
    view: state.viewer ? state.viewer.getView() : null,
    info: state.viewer ? state.viewer.info() : null,
  }),
  cpuCount: (values) => state.viewer.countOnCPU(values),
  async setPath(path) {
    state.requestedPath = path;
    await applyPath();
    state.lastChangeMs = renderNow();
    return window.mediso.stats();
  },
  estimates: () => state.viewer.estimates(),
  // The CPU path's level of detail: 0-3, or -1 for the estimator's choice within the budget.
  setCPULevel(level) {
    state.viewer.setCPULevel(level);
    state.lastChangeMs = renderNow();
    return window.mediso.stats();
  },
  // A surface the server made: binary PLY (vertex x, y, z; faces as index lists).
  showMesh(ply, color = [0.55, 0.8, 1.0], opacity = 1) {
    const mesh = parsePLY(ply);
    const M = state.module;
    const points = M._malloc(mesh.points.byteLength);
    const triangles = M._malloc(mesh.triangles.byteLength);
    M.HEAPU8.set(new Uint8Array(mesh.points.buffer), points);
    M.HEAPU8.set(new Uint8Array(mesh.triangles.buffer), triangles);
    state.viewer.setResultMesh(points, mesh.points.length / 3, triangles, mesh.triangles.length / 3,
      color, opacity);
    M._free(points);
    M._free(triangles);
    renderNow();
    return { points: mesh.points.length / 3, triangles: mesh.triangles.length / 3 };
  },
  clearMesh() {
    state.viewer.clearResultMesh();
    renderNow();
  },
};

// A binary little-endian PLY: float32 points and triangles (polygons fanned).
function parsePLY(buffer) {
  const bytes = new Uint8Array(buffer);
  const text = new TextDecoder("latin1").decode(bytes.subarray(0, Math.min(bytes.length, 4096)));
  const end = text.indexOf("end_header\n");
  if (!text.startsWith("ply") || end < 0 || !text.includes("format binary_little_endian")) {
    throw new Error("not a binary little-endian PLY file");
  }
  const sizes = { char: 1, uchar: 1, int8: 1, uint8: 1, short: 2, ushort: 2, int16: 2, uint16: 2,
    int: 4, uint: 4, int32: 4, uint32: 4, float: 4, float32: 4, double: 8, float64: 8 };
  const elements = [];
  for (const line of text.substring(0, end).split("\n")) {
    const w = line.trim().split(/\s+/);
    if (w[0] === "element") {
      elements.push({ name: w[1], count: Number(w[2]), properties: [] });
    } else if (w[0] === "property") {
      elements[elements.length - 1].properties.push(w[1] === "list"
        ? { list: true, countType: w[2], type: w[3], name: w[4] } : { type: w[1], name: w[2] });
    }
  }
  const view = new DataView(buffer, end + "end_header\n".length);
  let at = 0;
  const read = (type) => {
    let v;
    switch (type) {
      case "char": case "int8": v = view.getInt8(at); break;
      case "uchar": case "uint8": v = view.getUint8(at); break;
      case "short": case "int16": v = view.getInt16(at, true); break;
      case "ushort": case "uint16": v = view.getUint16(at, true); break;
      case "int": case "int32": v = view.getInt32(at, true); break;
      case "uint": case "uint32": v = view.getUint32(at, true); break;
      case "float": case "float32": v = view.getFloat32(at, true); break;
      default: v = view.getFloat64(at, true);
    }
    at += sizes[type];
    return v;
  };
  let points = new Float32Array(0);
  const triangles = [];
  for (const e of elements) {
    if (e.name === "vertex") {
      points = new Float32Array(3 * e.count);
      const axis = { x: 0, y: 1, z: 2 };
      for (let i = 0; i < e.count; ++i) {
        for (const p of e.properties) {
          const v = read(p.type);
          if (p.name in axis) {
            points[3 * i + axis[p.name]] = v;
          }
        }
      }
    } else {
      for (let i = 0; i < e.count; ++i) {
        for (const p of e.properties) {
          if (!p.list) {
            read(p.type);
            continue;
          }
          const n = read(p.countType);
          const ids = [];
          for (let k = 0; k < n; ++k) {
            ids.push(read(p.type));
          }
          if (e.name === "face") {
            for (let k = 1; k + 1 < n; ++k) {
              triangles.push(ids[0], ids[k], ids[k + 1]);
            }
          }
        }
      }
    }
  }
  return { points, triangles: Uint32Array.from(triangles) };
}

start().then(resolveReady, (error) => {
  if ($("unsupported").hidden) {
    unsupported("The page could not start: " + error.message);
  }
  rejectReady(error);
});
