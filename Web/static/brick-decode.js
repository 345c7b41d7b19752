// SPDX-License-Identifier: BSD-3-Clause
// The streamed level's bricks as the server encodes them (Python/serve_bricks.py; docs/web.md,
// Streaming), decoded where they are written: in the render worker (render-worker.js loads this
// classic script with importScripts when the first bricks come), straight into the module's
// memory, so that the page's main thread only fetches a batch and hands its bytes over.
//
// A brick is its owned points, x fastest, byte-shuffled (all first bytes, then all second
// bytes, ...); integer values are the zigzag'd residuals (0, -1, 1, -2 ... as 0, 1, 2, 3 ...) of
// the level's predictor in the type's own width: "xyz" (differences along x, then y, then z: the
// 3D Lorenzo predictor), "x" (along x) or "none". Running sums undo the differences (in any
// order: they commute), and a typed array's store wraps as the server's differences did, so the
// values come back exactly for every integer type.
"use strict";

(function () {
  const UNSIGNED = { 1: Uint8Array, 2: Uint16Array, 4: Uint32Array };
  const SIGNED = { 1: Int8Array, 2: Int16Array, 4: Int32Array };

  // Byte planes of `size`-byte values back in order, from `shuffled` into `out`.
  function unshuffleInto(shuffled, size, out) {
    const n = shuffled.length / size;
    for (let b = 0; b < size; ++b) {
      const plane = shuffled.subarray(b * n, (b + 1) * n);
      for (let i = 0, o = b; i < n; ++i, o += size) {
        out[o] = plane[i];
      }
    }
  }

  /**
   * Decodes one brick: `encoded` (its bytes as the answer holds them, after the HTTP gzip) into
   * `out`, a Uint8Array of the same length whose byteOffset is a multiple of `size` (the module's
   * memory: malloc aligns). `box` is its owned points [x0, x1, y0, y1, z0, z1).
   */
  function decodeBrickInto(encoded, size, predictor, box, out) {
    const n = encoded.length / size;
    let d;
    if (size === 2) {
      // The common case (int16, uint16) in one pass: the two byte planes joined and unzigzag'd.
      d = new Int16Array(out.buffer, out.byteOffset, n);
      const lo = encoded.subarray(0, n), hi = encoded.subarray(n);
      if (predictor === "none") {
        for (let i = 0; i < n; ++i) {
          d[i] = lo[i] | (hi[i] << 8);
        }
        return;
      }
      for (let i = 0; i < n; ++i) {
        const z = lo[i] | (hi[i] << 8);
        d[i] = (z >>> 1) ^ -(z & 1);
      }
    } else {
      if (size === 1) {
        out.set(encoded);
      } else {
        unshuffleInto(encoded, size, out);
      }
      if (predictor === "none" || !UNSIGNED[size]) {
        return; // floating-point values travel unpredicted
      }
      const u = new UNSIGNED[size](out.buffer, out.byteOffset, n);
      d = new SIGNED[size](out.buffer, out.byteOffset, n);
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
  }

  /**
   * The points brick `id` owns, [x0, x1, y0, y1, z0, z1), in a level of `dims` points cut into
   * bricks of `brick` points a side (the cores' BrickGrid; ids x fastest).
   */
  function ownedBox(dims, brick, id) {
    const [dx, dy, dz] = dims;
    const nx = Math.ceil(dx / brick), ny = Math.ceil(dy / brick);
    const bx = id % nx, by = Math.floor(id / nx) % ny, bz = Math.floor(id / (nx * ny));
    return [bx * brick, Math.min(dx, bx * brick + brick), by * brick, Math.min(dy, by * brick + brick),
      bz * brick, Math.min(dz, bz * brick + brick)];
  }

  self.medisoBricks = { decodeBrickInto, ownedBox };
})();
