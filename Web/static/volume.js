// SPDX-License-Identifier: BSD-3-Clause
// Volume loading: the page's requests to its server, every byte counted into the readout, and
// the volume fetched once per level (byte-shuffled and gzip'd on the wire, docs/web.md's
// /api/volume), put into the WebAssembly module's memory and handed to the viewer.

import { params, state } from "./state.js";

const token = params.get("token") || "";

/** The session's token (the server panel's WebSocket sends it too). */
export function sessionToken() {
  return token;
}

function withToken(url) {
  return url + (url.includes("?") ? "&" : "?") + "token=" + encodeURIComponent(token);
}

// The bytes that crossed for a request, from its resource timing entry when the browser has one
// (transferSize: headers and body on the wire; only the headers of a 304 that the browser
// answered from its cache, docs/web.md "Caching"). Null without an entry.
function transferred(url) {
  const entries = performance.getEntriesByName(new URL(url, location.href).href, "resource");
  const last = entries[entries.length - 1];
  return last && last.transferSize > 0 ? last.transferSize : null;
}

// Requests sent before the page needs their answers (prefetch), by cache mode and URL: the
// request() that needs one takes its answer from here instead of asking again.
const early = new Map();

/**
 * Sends a request of the page's now, for a request() of the same URL and `cache` later (the
 * page's start-up: level 0 and the bricks' manifest while the modules load, docs/web.md).
 */
export function prefetch(url, cache = "no-store") {
  const key = cache + " " + url;
  if (!early.has(key)) {
    const answer = fetch(withToken(url), { cache });
    answer.catch(() => {}); // said by the request() that takes it
    early.set(key, answer);
  }
}

/**
 * Every request of the page's own goes through here, so that the bytes are counted. `cache`:
 * "no-store" (the default: never kept) or "no-cache" (the volume: kept by the browser and
 * revalidated with the server at each use, which answers 304 when it has not changed).
 */
export async function request(url, cache = "no-store") {
  const full = withToken(url);
  state.bytesSent += full.length + 64; // the request line and the few headers a browser adds
  const key = cache + " " + url;
  const sent = early.get(key);
  early.delete(key);
  const response = await (sent || fetch(full, { cache }));
  if (!response.ok) {
    throw new Error(url + ": " + response.status + " " + (await response.text()));
  }
  const wire = Number(response.headers.get("Content-Length") || 0);
  const body = await response.arrayBuffer();
  if (cache !== "no-store") {
    await new Promise((resolve) => setTimeout(resolve)); // the timing entry is queued as a task
  }
  const crossed = cache === "no-store" ? null : transferred(full);
  state.bytesReceived += crossed !== null ? crossed : (wire || body.byteLength) + 200;
  return { response, body };
}

export async function requestJSON(url) {
  const { body } = await request(url);
  return JSON.parse(new TextDecoder().decode(body));
}

/** Counts bytes the page moved outside request() (the server panel's WebSocket). */
export function countBytes(sent, received) {
  state.bytesSent += sent;
  state.bytesReceived += received;
}

// The server sends byte b of every value together: values of `size` bytes back in order.
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

// The values as JavaScript reads them (little-endian, as the server sends them and every browser
// stores them): the page's own view of the fetched level, for the slices and the histogram.
const TYPED_ARRAYS = { int8: Int8Array, uint8: Uint8Array, int16: Int16Array, uint16: Uint16Array,
  int32: Int32Array, uint32: Uint32Array, float32: Float32Array, float64: Float64Array };
function typedValues(bytes, typeName) {
  const Typed = TYPED_ARRAYS[typeName];
  const copy = bytes.byteOffset % Typed.BYTES_PER_ELEMENT === 0 ? bytes : bytes.slice();
  return new Typed(copy.buffer, copy.byteOffset, copy.length / Typed.BYTES_PER_ELEMENT);
}

/**
 * Fetches level `level` of the dataset: {type (the module's {name, value, bytes}), dims, spacing,
 * origin, bytes (un-shuffled), values (a typed array over them)}.
 */
export async function fetchLevel(level) {
  const { response, body } = await request(levelURL(state.dataset, level), "no-cache");
  const typeName = response.headers.get("X-Mediso-Type");
  const type = state.facts.scalarTypes.get(typeName);
  if (!type) {
    throw new Error("the server sent " + typeName + " values, a type this page's module does not take");
  }
  const dims = response.headers.get("X-Mediso-Dims").split(",").map(Number);
  const spacing = response.headers.get("X-Mediso-Spacing").split(",").map(Number);
  const origin = response.headers.get("X-Mediso-Origin").split(",").map(Number);
  const bytes = unshuffle(new Uint8Array(body), type.bytes);
  return { type, dims, spacing, origin, bytes, values: typedValues(bytes, typeName) };
}

/**
 * Whether the viewer has been given a volume: a fetched level, or a stream's level 0 (whose full
 * level reaches this thread's module only at its end: state.volumePointer is 0 until then).
 */
export function hasVolume() {
  return state.grid !== null;
}

/** The URL of level `level` of dataset `d` (kept by the browser: request it with "no-cache"). */
export function levelURL(d, level) {
  return "/api/volume/" + d.id + "?level=" + level;
}

/** Byte-shuffled values of `size` bytes back in order, and their typed view (stream.js). */
export { unshuffle, typedValues };

/**
 * Fetches level `level` of the dataset and gives it to the viewer (the module's memory). A local
 * file's dataset (local.js) has its levels in the page already: `d.local.level(k)`.
 */
export async function loadVolume(level) {
  const d = state.dataset;
  if (d.local) {
    const { dims, spacing, origin, bytes } = d.local.level(level);
    return putVolume(state.facts.scalarTypes.get(d.type), d.type, dims, spacing, origin, bytes, level);
  }
  const { type, dims, spacing, origin, bytes } = await fetchLevel(level);
  return putVolume(type, type.name, dims, spacing, origin, bytes, level);
}

// The level's values (little-endian bytes) into the page's copy and the module's memory.
async function putVolume(type, typeName, dims, spacing, origin, bytes, level) {
  // The module resets its camera with a new volume; another level of the same volume keeps the
  // view the user has.
  const kept = hasVolume() ? state.viewer.getView() : null;
  state.values = typedValues(bytes, typeName);
  state.grid = { dims, spacing, origin };
  const M = state.module;
  if (state.volumePointer) {
    M._free(state.volumePointer);
  }
  state.volumePointer = M._malloc(bytes.length);
  M.HEAPU8.set(bytes, state.volumePointer);
  state.level = level;
  if (!state.viewer.setVolume(type.value, state.volumePointer, dims, spacing, origin)) {
    throw new Error("the volume cannot be uploaded: " + state.viewer.stats().error);
  }
  const refused = state.remote ? await state.viewer.uploaded : ""; // the worker's upload
  if (refused) {
    throw new Error("the volume cannot be uploaded: " + refused);
  }
  if (kept) {
    state.viewer.setView(kept);
  }
}
