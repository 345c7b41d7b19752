// SPDX-License-Identifier: BSD-3-Clause
// Streaming (docs/web.md, Streaming): with the viewer in a worker (either path), the page does
// not wait for the whole level. It fetches the server's level 0 (1/512 of the points) and draws
// every surface from it at once, then fetches the full level's bricks (/api/bricks, the cores'
// BrickGrid bricks; the brick size is the server's manifest's) a few requests at a time, the
// bricks the current isovalues need first (one a request, kept by the browser), writes each into the full level's buffer (allocated
// once, in this thread's module and in the worker's, where WebViewer.writeBrick completes the
// BlockLOD ranges of what arrived) and draws each surface at the full level as soon as every
// brick it needs is there. What goes up is the list of bricks; every point comes once.
//
// A brick needs: the bricks whose range (over the points its cells and gradients read, the
// manifest's) holds the isovalue (min < v <= max) and their neighbours (whose points those
// cells and gradients read).

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

// The bricks isovalue `v` needs (a Set of ids), kept per value.
function needed(s, v) {
  if (s.need.has(v)) {
    return s.need.get(v);
  }
  const m = s.manifest;
  const [nx, ny, nz] = m.bricks;
  const ids = new Set();
  m.ranges.forEach((range, id) => {
    if (!range || !(range[0] < v && v <= range[1])) {
      return;
    }
    const bx = id % nx, by = Math.floor(id / nx) % ny, bz = Math.floor(id / (nx * ny));
    for (let z = Math.max(0, bz - 1); z <= Math.min(nz - 1, bz + 1); ++z) {
      for (let y = Math.max(0, by - 1); y <= Math.min(ny - 1, by + 1); ++y) {
        for (let x = Math.max(0, bx - 1); x <= Math.min(nx - 1, bx + 1); ++x) {
          ids.add((z * ny + y) * nx + x);
        }
      }
    }
  });
  s.need.set(v, ids);
  return ids;
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
    total: manifest.bytes.reduce((a, b) => a + b, 0), need: new Map(), requested: [],
    readyKey: "", error: "", afterFirstFrame: true };
  state.received = 0;
  // The bricks are asked for once the first frame (level 0's) is drawn (afterEach): on a fast
  // link they would otherwise come first, and their writing and the server's encoding would
  // hold that frame (the page's start-up, docs/web.md).
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
      --s.inFlight;
      console.error("streaming: " + s.error);
      updateReadout();
      fetchMore();
    });
  }
}

// A brick's owned points (x fastest) into this thread's copy of the full level.
function writeHere(s, id, brick) {
  const [nx, ny] = s.manifest.bricks;
  const B = s.manifest.brick, size = s.type.bytes;
  const [dx, dy, dz] = s.dims;
  const bx = id % nx, by = Math.floor(id / nx) % ny, bz = Math.floor(id / (nx * ny));
  const x0 = bx * B, x1 = Math.min(dx, x0 + B);
  const y0 = by * B, y1 = Math.min(dy, y0 + B);
  const z0 = bz * B, z1 = Math.min(dz, z0 + B);
  const row = (x1 - x0) * size;
  const heap = state.module.HEAPU8;
  let from = 0;
  for (let z = z0; z < z1; ++z) {
    for (let y = y0; y < y1; ++y, from += row) {
      heap.set(brick.subarray(from, from + row), state.volumePointer + ((z * dy + y) * dx + x0) * size);
    }
  }
}

async function fetchBatch(s, ids) {
  const { body } = await request("/api/bricks/" + state.dataset.id + "?level=" + s.level +
    "&ids=" + ids.join(","), "no-cache");
  if (state.stream !== s) {
    return; // another volume since
  }
  const joined = unshuffle(new Uint8Array(body), s.type.bytes);
  const list = [];
  let offset = 0;
  for (const id of ids) {
    const brick = joined.slice(offset, offset + s.manifest.bytes[id]);
    offset += brick.length;
    writeHere(s, id, brick);
    s.resident[id] = 1;
    s.received += brick.length;
    list.push({ id, bytes: brick.buffer });
  }
  state.viewer.writeBricks(list);
  --s.inFlight;
  state.received = s.received / s.total;
  if (!s.pending.size && !s.inFlight) {
    finish(s);
    return;
  }
  // A surface whose bricks have all arrived is drawn again, at the full level.
  const key = currentValues().map((v) => ready(s, v)).join();
  if (key !== s.readyKey) {
    s.readyKey = key;
    renderNow();
  } else {
    updateReadout();
  }
  fetchMore();
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
  if (state.stream && state.stream.afterFirstFrame) {
    state.stream.afterFirstFrame = false;
    fetchMore();
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

/** For tests: the bricks asked for so far ([{ids, values}]), and the bricks values need. */
export function streamInfo(values = []) {
  const s = state.stream;
  if (!s) {
    return null;
  }
  return { level: s.level, brick: s.manifest.brick, bricks: [...s.manifest.bricks],
    requested: s.requested.map((r) => ({ ids: [...r.ids], values: [...r.values] })),
    resident: s.resident.reduce((a, b) => a + b, 0), error: s.error,
    needed: values.map((v) => [...needed(s, v)]) };
}
