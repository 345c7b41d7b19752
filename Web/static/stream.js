// SPDX-License-Identifier: BSD-3-Clause
// Streaming (docs/web.md, Streaming): with the viewer in a worker (either path), the page does
// not wait for the whole level. It fetches the server's level 0 (1/512 of the points) and draws
// every surface from it at once, then fetches the full level's bricks (/api/bricks, the cores'
// BrickGrid bricks; the brick size is the server's manifest's) a few requests at a time, the
// bricks the current isovalues need first (one a request, kept by the browser), decodes each
// (decodeBrick: the server's predictor undone), writes it into the full level's buffer
// (allocated once, in this thread's module and in the worker's, where WebViewer.writeBrick
// completes the BlockLOD ranges of what arrived) and draws each surface at the full level as soon
// as every brick it needs is there. What goes up is the isovalues (the need query) and the list
// of bricks; every point comes once.
//
// An isovalue needs the bricks holding the points that the cells and gradients of the core's
// blocks crossing it read: the server answers which (askExact); until it has, the page takes a
// superset from the manifest's brick ranges (the bricks whose range holds the value, min < v <=
// max, and all their neighbours).

import { drawnLevel } from "./path.js";
import { updateReadout } from "./readout.js";
import { params, state } from "./state.js";
import { afterFrame, beforeFrame, renderNow } from "./viewer.js";
import { fetchLevel, levelURL, loadVolume, mallocZeros, prefetch, request, requestJSON, typedValues,
  unshuffle } from "./volume.js";

// Requests in flight at once (a browser opens 6 connections to a host over HTTP/1.1). Each asks
// for one brick: its URL is then the same at every load, so the browser keeps it and a reload
// revalidates it (304) instead of fetching it again.
const IN_FLIGHT = 6;

/**
 * Whether the page streams level `level` on `path` (?stream=0: the whole level at once). Both
 * paths stream in the worker: the GPU path's scene takes each brick into its texture and draws a
 * frame at level 0 until every current surface's bricks are there (docs/web.md, Streaming).
 */
export function canStream(path, level) {
  return (path === "cpu" || path === "gpu") && state.remote && level > 0 &&
    params.get("stream") !== "0" &&
    !(state.dataset && state.dataset.local); // a local file is in the page already
}

// The URL of the manifest of level `level`'s bricks.
function manifestURL(d, level) {
  return "/api/bricks/" + d.id + "?level=" + level;
}

/**
 * What startStream(level) asks for first (the manifest and level 0), sent now (the page's
 * start-up, path.js: while the modules load); startStream takes the answers.
 */
export function prefetchStream(d, level) {
  prefetch(manifestURL(d, level));
  prefetch(levelURL(d, 0), "no-cache");
}

/** Stops a stream under way (a new level or path replaces the volume). */
export function stopStream() {
  state.stream = null;
}

function currentValues() {
  return state.surfaces.filter((s) => !s.hidden && s.opacity > 0).map((s) => s.value);
}

// The bricks isovalue `v` needs (a Set of ids): the server's exact set once it has answered the
// need query (askExact), until then a superset: every brick whose range holds v, then their
// neighbours (whose points the cells and gradients at a brick's faces read).
function needed(s, v) {
  return s.exact.get(v) || superset(s, v);
}

function superset(s, v) {
  if (s.need.has(v)) {
    return s.need.get(v);
  }
  const m = s.manifest;
  const [nx, ny, nz] = m.bricks;
  const holding = [];
  m.ranges.forEach((range, id) => {
    if (range && range[0] < v && v <= range[1]) {
      holding.push(id);
    }
  });
  const ids = new Set(holding); // the bricks that hold v first, in the order of requests
  for (const id of holding) {
    const bx = id % nx, by = Math.floor(id / nx) % ny, bz = Math.floor(id / (nx * ny));
    for (let z = Math.max(0, bz - 1); z <= Math.min(nz - 1, bz + 1); ++z) {
      for (let y = Math.max(0, by - 1); y <= Math.min(ny - 1, by + 1); ++y) {
        for (let x = Math.max(0, bx - 1); x <= Math.min(nx - 1, bx + 1); ++x) {
          ids.add((z * ny + y) * nx + x);
        }
      }
    }
  }
  s.need.set(v, ids);
  return ids;
}

// Asks the server which bricks the current isovalues need exactly (the bricks holding the points
// that the core's blocks crossing each value read: far fewer than the neighbours of every brick
// that holds it); the answer also moves those bricks to the front of the server's encoding.
function askExact(s) {
  const values = currentValues().filter((v) => !s.exact.has(v) && !s.asked.has(v));
  if (!values.length) {
    return;
  }
  values.forEach((v) => s.asked.add(v));
  requestJSON("/api/bricks/" + state.dataset.id + "?level=" + s.level + "&need=" + values.join(","))
    .then((answer) => {
      values.forEach((v, i) => s.exact.set(v, new Set(answer.need[i])));
      if (state.stream === s) {
        redrawIfReady(s);
      }
    })
    .catch((error) => {
      // The supersets stay: the surfaces come later, never wrong.
      values.forEach((v) => s.asked.delete(v));
      console.error("streaming: the bricks the isovalues need: " + error.message);
    });
}

// A surface whose bricks have all arrived is drawn again, at the full level: one frame for
// everything that arrived since the last (completions are coalesced, not drawn brick by brick),
// and none where no surface has become ready (a change draws its own frame). Where the other
// surfaces lack no more bricks than one round of requests brings, the frame waits for them: a
// frame at the full level costs seconds on a software renderer, and the surfaces of a CT (skin
// and bone) need nearly the same bricks.
function redrawIfReady(s) {
  const values = currentValues();
  const key = values.filter((v) => ready(s, v)).join();
  if (!key || key === s.readyKey) {
    s.readyKey = key;
    return false;
  }
  const missing = new Set();
  for (const v of values) {
    for (const id of needed(s, v)) {
      if (!s.resident[id]) {
        missing.add(id);
      }
    }
  }
  if (missing.size && missing.size <= IN_FLIGHT && !s.error) {
    return false; // the last of them redraws (a brick that failed: no waiting)
  }
  s.readyKey = key;
  renderNow();
  return true;
}

function ready(s, v) {
  for (const id of needed(s, v)) {
    if (!s.resident[id]) {
      return false;
    }
  }
  return true;
}

/**
 * Starts streaming level `level`: level 0 and the manifest are fetched and handed to the viewer
 * (the first frame can then be drawn); the bricks follow in the background. A level of one brick
 * is fetched whole instead.
 */
export async function startStream(level) {
  const d = state.dataset;
  state.stream = null;
  const manifest = await requestJSON(manifestURL(d, level));
  if (manifest.ranges.length < 2) {
    await loadVolume(level); // one brick: nothing comes sooner by streaming it
    return;
  }
  const coarse = await fetchLevel(0);
  const type = coarse.type;
  const dims = manifest.dims;
  const M = state.module;
  const pointerBefore = state.volumePointer;
  const kept = pointerBefore ? state.viewer.getView() : null;
  if (pointerBefore) {
    M._free(pointerBefore);
  }
  state.volumePointer = mallocZeros(M, type.bytes * dims[0] * dims[1] * dims[2]);
  // The page's own copy (slices, histogram) is level 0 until the full level has arrived.
  state.values = coarse.values;
  state.grid = { dims: coarse.dims, spacing: coarse.spacing, origin: coarse.origin };
  state.level = 0;
  const refused = await state.viewer.beginStream({ type: type.value, pointer: state.volumePointer,
    dims, spacing: d.levels[level].spacing, origin: coarse.origin, brick: manifest.brick,
    coarse: { bytes: coarse.bytes, dims: coarse.dims, spacing: coarse.spacing, origin: coarse.origin } });
  if (refused) {
    // The GPU path's volume kept as bricks (over the texture limit or GPU budget) does not stream.
    console.warn("streaming: the whole level instead (" + refused + ")");
    await loadVolume(level);
    return;
  }
  if (kept) {
    state.viewer.setView(kept);
  }
  const count = manifest.ranges.length;
  state.stream = { level, path: state.path, manifest, type, dims, resident: new Uint8Array(count),
    pending: new Set(Array.from({ length: count }, (_, i) => i)), inFlight: 0, received: 0,
    total: manifest.bytes.reduce((a, b) => a + b, 0), need: new Map(), exact: new Map(),
    asked: new Set(), requested: [], readyKey: "", error: "", started: false };
  state.received = 0;
  // The bricks are asked for once the first frame (level 0's) is drawn (afterEach): on a fast
  // link they would otherwise come first, and their writing and the server's encoding would
  // hold that frame (the page's start-up, docs/web.md). The bricks the first surfaces need are
  // asked of the server before that frame (beforeEach), so that the first requests are theirs;
  // a timer in case no frame comes.
  const s = state.stream;
  setTimeout(() => begin(s), 1000);
}

function begin(s) {
  if (s && state.stream === s && !s.started) {
    s.started = true;
    askExact(s);
    fetchMore();
  }
}

// The next brick: one the current isovalues need first, else the next in order.
function nextBatch(s) {
  for (const v of currentValues()) {
    for (const id of needed(s, v)) {
      if (s.pending.has(id)) {
        s.pending.delete(id);
        return [id];
      }
    }
  }
  const id = s.pending.values().next().value;
  s.pending.delete(id);
  return [id];
}

function fetchMore() {
  const s = state.stream;
  while (s && state.stream === s && s.inFlight < IN_FLIGHT && s.pending.size) {
    const batch = nextBatch(s);
    s.requested.push({ ids: batch, values: currentValues() });
    ++s.inFlight;
    fetchBatch(s, batch).catch((error) => {
      // Said in the readout; the surfaces that need the brick stay at level 0.
      s.error = "brick " + batch.join(", ") + ": " + error.message;
      console.error("streaming: " + s.error);
      updateReadout();
      fetchMore();
    });
  }
}

// The points brick `id` owns: [x0, x1) x [y0, y1) x [z0, z1).
function ownedBox(s, id) {
  const [nx, ny] = s.manifest.bricks;
  const B = s.manifest.brick;
  const [dx, dy, dz] = s.dims;
  const bx = id % nx, by = Math.floor(id / nx) % ny, bz = Math.floor(id / (nx * ny));
  return [bx * B, Math.min(dx, bx * B + B), by * B, Math.min(dy, by * B + B),
    bz * B, Math.min(dz, bz * B + B)];
}

// A brick's owned points (x fastest) into this thread's copy of the full level.
function writeHere(s, id, brick) {
  const [x0, x1, y0, y1, z0, z1] = ownedBox(s, id);
  const size = s.type.bytes;
  const [dx, dy] = s.dims;
  const row = (x1 - x0) * size;
  const heap = state.module.HEAPU8;
  let from = 0;
  for (let z = z0; z < z1; ++z) {
    for (let y = y0; y < y1; ++y, from += row) {
      heap.set(brick.subarray(from, from + row), state.volumePointer + ((z * dy + y) * dx + x0) * size);
    }
  }
}

const UNSIGNED = { 1: Uint8Array, 2: Uint16Array, 4: Uint32Array };
const SIGNED = { 1: Int8Array, 2: Int16Array, 4: Int32Array };

/**
 * One brick as the server encoded it (serve_bricks.py): byte-shuffled, and for integer values the
 * zigzag'd residuals of `predictor` ("xyz": differences along x, then y, then z; "x": along x;
 * "none") in the type's width. Gives its owned points' bytes (x fastest) in a buffer of their own.
 * Running sums undo the differences (in any order: they commute); a typed array's store wraps
 * as the server's differences did.
 */
export function decodeBrick(encoded, size, predictor, box) {
  const n = encoded.length / size;
  let raw, d;
  if (size === 2) {
    // The common case (int16, uint16) in one pass: the two byte planes joined and unzigzag'd.
    d = new Int16Array(n);
    raw = new Uint8Array(d.buffer);
    const lo = encoded.subarray(0, n), hi = encoded.subarray(n);
    if (predictor === "none") {
      for (let i = 0; i < n; ++i) {
        d[i] = lo[i] | (hi[i] << 8);
      }
      return raw;
    }
    for (let i = 0; i < n; ++i) {
      const z = lo[i] | (hi[i] << 8);
      d[i] = (z >>> 1) ^ -(z & 1);
    }
  } else {
    raw = size === 1 ? encoded.slice() : unshuffle(encoded, size);
    if (predictor === "none") {
      return raw;
    }
    const u = new UNSIGNED[size](raw.buffer, raw.byteOffset, n);
    d = new SIGNED[size](raw.buffer, raw.byteOffset, n);
    for (let i = 0; i < n; ++i) {
      const z = u[i];
      d[i] = (z >>> 1) ^ -(z & 1);
    }
  }
  const [x0, x1, y0, y1, z0, z1] = box;
  const nx = x1 - x0, ny = y1 - y0, nz = z1 - z0;
  for (let r = 0; r < n; r += nx) {
    let sum = 0;
    for (let i = r; i < r + nx; ++i) {
      sum += d[i];
      d[i] = sum;
    }
  }
  if (predictor === "xyz") {
    const plane = nx * ny;
    for (let z = 0; z < nz; ++z) {
      for (let i = z * plane + nx; i < (z + 1) * plane; ++i) {
        d[i] += d[i - nx];
      }
    }
    for (let i = plane; i < n; ++i) {
      d[i] += d[i - plane];
    }
  }
  return raw;
}

async function fetchBatch(s, ids) {
  let response, body;
  try {
    ({ response, body } = await request("/api/bricks/" + state.dataset.id + "?level=" + s.level +
      "&ids=" + ids.join(","), "no-cache"));
  } finally {
    --s.inFlight;
  }
  if (state.stream !== s) {
    return; // another volume since
  }
  // The next request goes out before this one is decoded: the link stays busy while the main
  // thread works (on a loaded machine its decoding was what the requests waited for).
  fetchMore();
  const predictor = response.headers.get("X-Mediso-Predictor") || "none";
  const encoded = new Uint8Array(body);
  const list = [];
  let offset = 0;
  for (const id of ids) {
    const length = s.manifest.bytes[id];
    const brick = decodeBrick(encoded.subarray(offset, offset + length), s.type.bytes, predictor,
      ownedBox(s, id));
    offset += length;
    writeHere(s, id, brick);
    s.resident[id] = 1;
    s.received += brick.length;
    list.push({ id, bytes: brick.buffer });
  }
  state.viewer.writeBricks(list);
  state.received = s.received / s.total;
  if (!s.pending.size && !s.inFlight) { // (every other answer was handled when it came)
    finish(s);
    return;
  }
  if (!redrawIfReady(s)) {
    updateReadout();
  }
}

// The last stream's manifest and type (brickRanges, after the end).
let lastStream = null;

/**
 * For tests, after the end: the manifest's brick ranges (the server's, numpy) and the cores'
 * (ComputeBrickRanges over the page's copy of the level, through the module), or null.
 */
export function brickRanges() {
  const s = lastStream;
  if (!s || state.stream) {
    return null;
  }
  return { server: s.manifest.ranges, core: state.module.brickRanges(s.type.value, state.volumePointer,
    s.dims, s.manifest.brick, s.manifest.apron) };
}

// Every brick is here: the viewer's buffer is the full level, the page's copy too.
function finish(s) {
  lastStream = s;
  state.viewer.endStream();
  const bytes = state.module.HEAPU8.slice(state.volumePointer,
    state.volumePointer + s.type.bytes * s.dims[0] * s.dims[1] * s.dims[2]);
  state.values = typedValues(bytes, s.type.name);
  state.grid = { dims: s.dims, spacing: state.dataset.levels[s.level].spacing,
    origin: state.grid.origin };
  state.level = s.level;
  state.stream = null;
  state.received = 1;
  renderNow();
}

/** Installs the frame hooks (app.js, once, before the volume). */
export function setupStream() {
  beforeFrame.push(beforeEach);
  afterFrame.push(afterEach);
}

// Before each frame: the isovalues whose bricks are not all here are drawn from level 0.
function beforeEach() {
  const s = state.stream;
  if (s) {
    askExact(s);
    state.viewer.setCoarseValues(currentValues().filter((v) => !ready(s, v)));
  }
}

// After each frame: each surface's level of the whole volume; whenFull's waiters.
let waiting = [];
function fullNow() {
  const stats = state.viewer.stats();
  const drawnValues = stats.surfaceValues || [];
  const values = currentValues();
  return state.settled && !state.interactive && !(stats.coarse || []).some(Boolean) &&
    drawnValues.length === values.length &&
    drawnValues.every((v, i) => v === values[i]);
}
function afterEach() {
  if (state.stream && !state.stream.started) {
    begin(state.stream);
  }
  const stats = state.viewer.stats();
  const drawn = stats.surfaceValues || [];
  const full = state.stream ? state.stream.level : drawnLevel();
  state.surfaceLevels = currentValues().map((v) => ((stats.coarse || [])[drawn.indexOf(v)] ? 0 : full));
  if (waiting.length && fullNow()) {
    const resolve = waiting;
    waiting = [];
    resolve.forEach((r) => r());
  }
}

/** Resolves when every current surface is drawn at the full level (automation). */
export function whenFull() {
  return new Promise((resolve) => {
    if (fullNow() && state.frameLog.length) {
      resolve();
    } else {
      waiting.push(resolve);
    }
  });
}

/** The readout's line while streaming: the fraction received and each surface's level. */
export function streamNote() {
  const levels = state.surfaceLevels.length ? state.surfaceLevels.join(", ") : "-";
  if (!state.stream) {
    return "";
  }
  return Math.round(100 * state.received) + "% of level " + state.stream.level + " received; " +
    "surfaces at level " + levels + " (level 0 is the coarse one, every 8th point)" +
    (state.stream.error ? "; not received: " + state.stream.error : "");
}

/**
 * For tests: the bricks asked for so far ([{ids, values}]), the bricks values need, whether that
 * is the server's exact answer, and the size of the superset the manifest's ranges give.
 */
export function streamInfo(values = []) {
  const s = state.stream;
  if (!s) {
    return null;
  }
  return { level: s.level, brick: s.manifest.brick, bricks: [...s.manifest.bricks],
    requested: s.requested.map((r) => ({ ids: [...r.ids], values: [...r.values] })),
    resident: s.resident.reduce((a, b) => a + b, 0), error: s.error,
    needed: values.map((v) => [...needed(s, v)]), exact: values.map((v) => s.exact.has(v)),
    superset: values.map((v) => superset(s, v).size) };
}
