// SPDX-License-Identifier: BSD-3-Clause
// Streaming (docs/web.md, Streaming): with the viewer in a worker (either path), the page does
// not wait for the whole level. It fetches the server's level 0 (1/512 of the points) and draws
// every surface from it at once, then fetches the full level's bricks (/api/bricks, the cores'
// BrickGrid bricks; the brick size is the server's manifest's) in batches of several bricks a
// request, a few requests at a time, the bricks the current isovalues need first; each answer's
// bytes go to the worker as they came (transferred), which decodes them (brick-decode.js: the
// server's predictor undone) straight into the full level's buffer (WebViewer.writeBrick
// completes the BlockLOD ranges of what arrived), and each surface is drawn at the full level as
// soon as every brick it needs is there. This thread does nothing per brick; it gets the level
// back from the worker at the end (its own copy: slices, histogram). What goes up is the
// isovalues (the need query) and the list of bricks; every point comes once.
//
// An isovalue needs the bricks holding the points that the cells and gradients of the core's
// blocks crossing it read: the server answers which (askExact); until it has, the page takes a
// superset from the manifest's brick ranges (the bricks whose range holds the value, min < v <=
// max, and all their neighbours).

import { drawnLevel } from "./path.js";
import { updateReadout } from "./readout.js";
import { params, state } from "./state.js";
import { afterFrame, beforeFrame, renderNow } from "./viewer.js";
import { fetchLevel, hasVolume, levelURL, loadVolume, prefetch, request, requestJSON,
  typedValues } from "./volume.js";

// Requests in flight at once (a browser opens 6 connections to a host over HTTP/1.1). Two made
// the first answer come sooner but the bricks as a whole later (docs/web.md, The critical path
// from level 0 to the full level).
const IN_FLIGHT = 6;
// Requests a level's bricks are cut into, about: each request costs this thread a fetch, an
// answer and a hand-over to the worker, and the server a round of its event loop (one brick a
// request was 256-512 requests on a 512-wide volume). The batches are the same at every load
// with the same isovalues (the first waits for the server's need: nextBatch), so their URLs are
// too, and the browser keeps each answer as it keeps a level: a reload revalidates them (304).
const BATCHES = 24;
// Bricks in a stream's first request; each next request carries twice the one before, up to the
// batch (BATCHES), then every request the batch (a slow start). Six full batches asked for
// together shared the two cores (loopback) or the link, so the first answer came with the other
// five, 0.4-0.9 s after asking, with the worker idle meanwhile (docs/web.md, The critical path
// from level 0 to the full level). The worker writes a brick in about the time the server and
// the browser deliver one (5-6 ms a brick each in the quiet trace), so an answer of
// twice the bricks before it comes about when the worker has written those. The sizes depend only
// on a request's place in the stream, so the batches stay the same at every load; the ramp costs
// about log2(batch) requests more.
const FIRST_BATCH = 1;

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
        if (s.started) {
          redrawIfReady(s);
        } else {
          begin(s); // it waited for this answer
        }
      }
    })
    .catch((error) => {
      // The supersets stay: the surfaces come later, never wrong.
      values.forEach((v) => s.asked.delete(v));
      console.error("streaming: the bricks the isovalues need: " + error.message);
      begin(s);
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
  if (missing.size && missing.size <= IN_FLIGHT * s.batch && !s.error) {
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
  const times = { started: epochNow() };
  const manifest = await requestJSON(manifestURL(d, level));
  if (manifest.ranges.length < 2) {
    await loadVolume(level); // one brick: nothing comes sooner by streaming it
    return;
  }
  const coarse = await fetchLevel(0);
  times.level0 = epochNow();
  performance.mark("mediso:level0");
  const type = coarse.type;
  const dims = manifest.dims;
  const kept = hasVolume() ? state.viewer.getView() : null;
  if (state.volumePointer) {
    state.module._free(state.volumePointer);
    state.volumePointer = 0;
  }
  // The page's own copy (slices, histogram) is level 0 until the full level has arrived; this
  // thread's module has none of it until then (finish): allocating the full level here held the
  // first image (docs/web.md, "The first image at 30 Mbit/s: the third pass").
  state.values = coarse.values;
  state.grid = { dims: coarse.dims, spacing: coarse.spacing, origin: coarse.origin };
  state.level = 0;
  const refused = await state.viewer.beginStream({ type: type.value, dims,
    spacing: d.levels[level].spacing, origin: coarse.origin, brick: manifest.brick,
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
    pending: new Set(Array.from({ length: count }, (_, i) => i)), inFlight: 0, neededInFlight: 0,
    received: 0, total: manifest.bytes.reduce((a, b) => a + b, 0), need: new Map(), exact: new Map(),
    asked: new Set(), requested: [], arrived: [], readyKey: "", error: "", started: false, framed: false,
    showing: false,
    batch: Math.max(1, Math.ceil(count / BATCHES)), times };
  times.begun = epochNow();
  performance.mark("mediso:stream");
  lastTimes = times;
  state.received = 0;
  // The bricks are asked for once the first frame (level 0's) is drawn and shown (afterEach): on
  // a fast link they would otherwise come first, and their writing and the server's encoding
  // would hold that frame (the page's start-up, docs/web.md). The bricks the first surfaces need
  // are asked of the server before that frame (beforeEach), so that the first requests are
  // theirs; a timer in case no frame comes.
  const s = state.stream;
  setTimeout(() => framed(s), 1000);
}

// The first frame is drawn and shown (or a second has passed without one): the bricks may be
// asked for.
function framed(s) {
  if (s && state.stream === s) {
    s.framed = true;
    s.times.framed = s.times.framed || epochNow();
    begin(s);
    if (s.arrived.length) {
      handOver(s);
    }
  }
}

// The bricks are asked for once the first frame is shown and the server has said which bricks
// the current isovalues need (one round trip, sent before that frame: it has mostly come by
// then): the batches are then those of the exact sets, the same at every load (BATCHES). A need
// query that fails (the supersets) or takes over 2 s more does not hold the bricks.
function begin(s, late = false) {
  if (!s || state.stream !== s || s.started || !s.framed) {
    return;
  }
  askExact(s);
  if (!late && currentValues().some((v) => s.asked.has(v) && !s.exact.has(v))) {
    if (!s.needTimer) {
      s.needTimer = setTimeout(() => begin(s, true), 2000);
    }
    return;
  }
  s.started = true;
  s.times.requested = epochNow();
  fetchMore();
}

// The next batch: up to `size` bricks the current isovalues need (those of the first value
// first), else up to `size` of the others in id order (none while a batch of needed bricks is
// still travelling: `othersToo` false); a batch does not mix the two, so that the last needed
// bricks do not wait for others. `size` is s.batch after the first requests' ramp (FIRST_BATCH).
function nextBatch(s, othersToo) {
  const size = Math.min(s.batch, FIRST_BATCH * 2 ** s.requested.length);
  const ids = [];
  for (const v of currentValues()) {
    for (const id of needed(s, v)) {
      if (s.pending.has(id)) {
        s.pending.delete(id);
        ids.push(id);
        if (ids.length === size) {
          return ids;
        }
      }
    }
  }
  if (ids.length || !othersToo) {
    return ids;
  }
  for (const id of s.pending) {
    if (ids.length === size) {
      break;
    }
    ids.push(id);
  }
  ids.forEach((id) => s.pending.delete(id));
  return ids;
}

// Up to IN_FLIGHT requests. The others' batches (no current surface needs them) wait until every
// batch of needed bricks has arrived: on loopback the server's sending and the browser's
// inflating of the others took the two cores from the needed ones (and the writing) at the end
// of the needed bricks, and on a slow link their bytes took its bandwidth; the others follow at
// most one round trip later.
function fetchMore() {
  const s = state.stream;
  while (s && state.stream === s && s.inFlight < IN_FLIGHT && s.pending.size) {
    const batch = nextBatch(s, !s.neededInFlight);
    if (!batch.length) {
      break; // others, after the needed batches in flight
    }
    const values = currentValues();
    const neededBatch = batch.some((id) => values.some((v) => needed(s, v).has(id)));
    s.requested.push({ ids: batch, values });
    ++s.inFlight;
    s.neededInFlight += neededBatch ? 1 : 0;
    fetchBatch(s, batch, neededBatch).catch((error) => {
      // Said in the readout; the surfaces that need the brick stay at level 0.
      s.error = "bricks " + batch.join(", ") + ": " + error.message;
      console.error("streaming: " + s.error);
      updateReadout();
      fetchMore();
      handOver(s); // nothing waits for a surface that cannot come
    });
  }
}

async function fetchBatch(s, ids, neededBatch) {
  let response, body;
  try {
    ({ response, body } = await request("/api/bricks/" + state.dataset.id + "?level=" + s.level +
      "&ids=" + ids.join(","), "no-cache"));
  } finally {
    --s.inFlight;
    s.neededInFlight -= neededBatch ? 1 : 0;
  }
  if (state.stream !== s) {
    return; // another volume since
  }
  // The next request goes out before this answer is handed over: the link stays busy.
  fetchMore();
  const length = ids.reduce((sum, id) => sum + s.manifest.bytes[id], 0);
  if (body.byteLength !== length) {
    throw new Error(body.byteLength + " bytes where the bricks own " + length);
  }
  s.times.lastAnswer = epochNow();
  s.times.firstAnswer = s.times.firstAnswer || s.times.lastAnswer;
  s.arrived.push({ ids, body, predictor: response.headers.get("X-Mediso-Predictor") || "none" });
  await handOver(s);
}

// Hands the batches that have arrived to the worker, which decodes and writes them before any
// frame asked for after them (messages keep their order); the bricks are resident for this
// thread's bookkeeping from then on. A batch that no current surface needs waits while a
// surface still lacks bricks: on a fast link the bricks come faster than the worker writes them
// (a first frame or an extraction holds it), and the others' batches queued before the frame
// that a surface's last brick asks for would hold that frame. They go as soon as every current
// surface has its bricks (after that frame's request), or a brick has failed.
async function handOver(s) {
  if (state.stream !== s || !s.framed) {
    return; // held until the first frame is shown (framed hands them over then)
  }
  const values = currentValues();
  const needs = (id) => values.some((v) => needed(s, v).has(id));
  const write = (batch) => {
    s.times.lastHanded = epochNow();
    state.viewer.writeBricks(batch);
    for (const id of batch.ids) {
      s.resident[id] = 1;
      s.received += s.manifest.bytes[id];
    }
  };
  const held = [];
  for (const batch of s.arrived) {
    if (batch.ids.some(needs)) {
      write(batch);
    } else {
      held.push(batch);
    }
  }
  s.arrived = held;
  const drawn = redrawIfReady(s);
  if (held.length && (s.error || values.every((v) => ready(s, v)))) {
    held.forEach(write);
    s.arrived = [];
  }
  if (!s.pending.size && !s.inFlight && !s.arrived.length) { // every brick is in the worker
    if (!s.finishing) {
      s.finishing = true;
      await finish(s); // received is 1 once the page's copy is there too
    }
    return;
  }
  state.received = s.received / s.total;
  if (!drawn) {
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

// Every brick is here: the viewer's buffer is the full level; the worker hands it back for the
// page's copy (this thread's module: the CPU count; the values: slices and histogram).
async function finish(s) {
  lastStream = s;
  s.times.ending = epochNow();
  const bytes = new Uint8Array(await state.viewer.endStream());
  s.times.ended = epochNow();
  if (state.stream !== s) {
    return; // another volume since
  }
  const M = state.module;
  const pointer = M._malloc(bytes.length);
  if (!pointer) {
    throw new Error("no memory in this page's module for the level's " + bytes.length + " bytes");
  }
  M.HEAPU8.set(bytes, pointer);
  state.volumePointer = pointer;
  state.viewer.keepStreamedVolume(pointer);
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
  const s = state.stream;
  if (s && !s.framed && !s.showing) {
    // Once the first frame is on the screen (two animation frames, as drawn() waits): the bricks'
    // answers, their hand-over and their writing in the worker, begun at its answer, held the
    // page's next frames, and so the first image's display (docs/web.md, "The page's start-up").
    s.showing = true;
    s.times.framed = epochNow();
    requestAnimationFrame(() => requestAnimationFrame(() => {
      s.times.shown = epochNow();
      framed(s);
    }));
  }
  if (state.stream && state.stream.arrived.length) {
    handOver(state.stream); // a change since may need them, or need nothing more
  }
  const stats = state.viewer.stats();
  const drawn = stats.surfaceValues || [];
  const full = state.stream ? state.stream.level : drawnLevel();
  state.surfaceLevels = currentValues().map((v) => ((stats.coarse || [])[drawn.indexOf(v)] ? 0 : full));
  if (lastTimes && !lastTimes.full && fullNow()) {
    lastTimes.full = epochNow();
  }
  if (waiting.length && fullNow()) {
    const resolve = waiting;
    waiting = [];
    resolve.forEach((r) => r());
  }
}

// The times of the last stream (streamTimes), the epoch's ms (performance.timeOrigin + now).
let lastTimes = null;
function epochNow() {
  return performance.timeOrigin + performance.now();
}

/**
 * Where the last stream's time went (the streaming benchmark's table of parts, docs/web.md), in
 * ms from the page's navigation, or null where the level came whole: on this thread, the stream
 * begun (startStream), level 0 in, the stream set up in the worker, the first frame drawn (its
 * answer) and shown (two animation frames later), the first bricks asked for, the first and last answer in, the last batch handed to the worker,
 * every current surface at the full level, and the level's end; in the worker (from its newest
 * frame's stats), the set-up's steps, the first and last batch written, the bricks' decoding and
 * writing (writeBrick: the copy, the residency and the extraction ahead) and each frame (when it began, its time,
 * the part that made and uploaded the surfaces, its surfaces from level 0).
 */
export function streamTimes() {
  if (!lastTimes) {
    return null;
  }
  const since = (t) => (t ? Math.round(t - performance.timeOrigin) : null);
  const out = Object.fromEntries(Object.entries(lastTimes).map(([k, t]) => [k, since(t)]));
  const w = (state.viewer && state.viewer.stats().streamTimes) || null;
  if (w) {
    // The worker's clock from its stream's start, which this thread saw answered at `begun`: the
    // two threads' timeOrigin + now() were seen to differ by a fifth of a second under load.
    const worker = (t) => (t ? since(lastTimes.begun + t - w.begun) : null);
    out.worker = { firstBricks: worker(w.firstBricks), lastBricks: worker(w.lastBricks),
      batches: w.batches, bricks: w.bricks, decodeMs: Math.round(w.decodeMs),
      writeMs: Math.round(w.writeMs), setupMs: (w.setupMs || []).map(Math.round),
      frames: w.frames.map((f) => ({ at: worker(f.at), ms: Math.round(f.ms),
        buildMs: Math.round(f.buildMs), triangles: f.triangles, coarse: f.coarse })) };
  }
  return out;
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
