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

/** Every request of the page's own goes through here, so that the bytes are counted. */
export async function request(url) {
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

export async function requestJSON(url) {
  const { body } = await request(url);
  return JSON.parse(new TextDecoder().decode(body));
}

/** Counts bytes the page moved outside request() (the server panel's WebSocket). */
export function countBytes(sent, received) {
  state.bytesSent += sent;
  state.bytesReceived += received;
}

// The server sends byte b of every value together: values of `size` bytes back in order, into
// `out` (the module's memory: no second copy for the collector to reclaim during the first
// changes).
function unshuffle(shuffled, size, out) {
  if (size === 1) {
    out.set(shuffled);
    return;
  }
  const n = shuffled.length / size;
  for (let b = 0; b < size; ++b) {
    const plane = shuffled.subarray(b * n, (b + 1) * n);
    for (let i = 0, o = b; i < n; ++i, o += size) {
      out[o] = plane[i];
    }
  }
}

/** Fetches level `level` of the dataset and gives it to the viewer (the module's memory). */
export async function loadVolume(level) {
  const d = state.dataset;
  const { response, body } = await request("/api/volume/" + d.id + "?level=" + level);
  const typeName = response.headers.get("X-Mediso-Type");
  const type = state.facts.scalarTypes.get(typeName);
  if (!type) {
    throw new Error("the server sent " + typeName + " values, a type this page's module does not take");
  }
  const dims = response.headers.get("X-Mediso-Dims").split(",").map(Number);
  const spacing = response.headers.get("X-Mediso-Spacing").split(",").map(Number);
  const origin = response.headers.get("X-Mediso-Origin").split(",").map(Number);
  const shuffled = new Uint8Array(body);
  const M = state.module;
  const pointerBefore = state.volumePointer;
  if (state.volumePointer) {
    M._free(state.volumePointer);
  }
  state.volumePointer = M._malloc(shuffled.length);
  unshuffle(shuffled, type.bytes, M.HEAPU8.subarray(state.volumePointer, state.volumePointer + shuffled.length));
  state.level = level;
  // The module resets its camera with a new volume; another level of the same volume keeps the
  // view the user has.
  const kept = pointerBefore ? state.viewer.getView() : null;
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
