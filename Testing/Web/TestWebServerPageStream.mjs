// SPDX-License-Identifier: BSD-3-Clause
// Streaming (issue 31; docs/web.md, Streaming), in Chromium (SwiftShader), CPU path in the worker,
// the network throttled through CDP (Network.emulateNetworkConditions) so that there is a "while",
// on a volume the test writes (two blobs, one in the middle, one in a corner):
// - the first image comes from level 0 (every surface at level 0, said in the readout), and at
//   every frame each surface's triangles are the dense ones at its level: level 0's from a page
//   that fetched level 0 whole, level 3's from a page that fetched level 3 whole (?stream=0);
// - the bricks the surface at FIRST needs, as the server answers the need query, are those its
//   blocks read (a brute force here over the values written: 14, the 8 middle ones among them),
//   where the manifest's ranges alone gave all 64 (the bricks that hold the value, and every
//   neighbour);
// - an isovalue changed mid-stream (to the corner's blob) is drawn at once, and the next bricks
//   asked for are the ones it needs, while others are still to come;
// - the stream's first requests carry 1, 2, 4, ... bricks, up to the batch (the first answer sooner);
// - whenFull() resolves with every surface at level 3 (before the whole level has come, where
//   the surface needs fewer bricks), its surface made ahead as the bricks arrived (stats()'s
//   takenAhead), then received reaches 1; the bytes of level 0 and the bricks on the wire are at
//   most 1.05x the whole level's;
// - after the end, the manifest's brick ranges are the cores' ComputeBrickRanges over the level
//   received, and a change sends nothing.
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import path from "node:path";
import { Checks, countWire, launchBrowser, openEmulated, startServer, writeTwoBlobs } from "./webserver-harness.mjs";

const checks = new Checks();
// Two blobs in a 256^3 int16 NIfTI (bricks of 64: 4 per axis): a large one in the middle, whose
// surface at FIRST (radius 50, points 78-178 along each axis) lies in the middle 8 bricks, and a
// small one in a corner, whose surface at SMALL needs the far corner's bricks (the last in the
// volume's order); a little deterministic noise.
const N = 256, FIRST = 500, SMALL = 1500;
const writeVolume = (file) => writeTwoBlobs(file, N, 226, 4);

// The bricks (64 points a side) isovalue v needs, by brute force: for every block of 8 cells whose
// points [8b, 8b + 8] hold v (min < v <= max), the bricks of the points 8b - 1 .. 8b + 9 its
// cells and gradients read.
function exactNeed(values, v) {
  const blocks = Math.ceil((N - 1) / 8), out = new Set();
  for (let bz = 0; bz < blocks; ++bz) {
    for (let by = 0; by < blocks; ++by) {
      for (let bx = 0; bx < blocks; ++bx) {
        let lo = Infinity, hi = -Infinity;
        for (let k = 8 * bz; k <= Math.min(N - 1, 8 * bz + 8); ++k) {
          for (let j = 8 * by; j <= Math.min(N - 1, 8 * by + 8); ++j) {
            for (let i = 8 * bx; i <= Math.min(N - 1, 8 * bx + 8); ++i) {
              const x = values[(k * N + j) * N + i];
              lo = Math.min(lo, x);
              hi = Math.max(hi, x);
            }
          }
        }
        if (!(lo < v && v <= hi)) {
          continue;
        }
        const ends = [bx, by, bz].map((b) =>
          [...new Set([Math.max(0, 8 * b - 1) >> 6, Math.min(N - 1, 8 * b + 9) >> 6])]);
        for (const z of ends[2]) {
          for (const y of ends[1]) {
            for (const x of ends[0]) {
              out.add((z * 4 + y) * 4 + x);
            }
          }
        }
      }
    }
  }
  return [...out].sort((a, b) => a - b);
}
const folder = mkdtempSync(path.join(tmpdir(), "mediso-stream-"));
const nifti = path.join(folder, "blobs.nii");
const written = writeVolume(nifti);
const server = await startServer([nifti]);
const browser = await launchBrowser();
const surface = (value) => ({ value, color: [1, 1, 1], opacity: 1 });

async function open(query, throttle) {
  return openEmulated(browser, server.url + query, { viewport: { width: 900, height: 600 }, mbit: throttle || 0,
    watch: async (context, page) => ({ wire: await countWire(context, page) }) });
}

// The streaming page, at 5 Mbit/s and 40 ms (the predicted bricks are 0.76x the level: slower than the
// 8 Mbit/s of before, so that the change below still comes mid-stream), one surface.
const { page, wire } = await open("&path=cpu#iso=" + FIRST + ",ffffff,1", 5);
const first = await page.evaluate(() => window.mediso.stats());
checks.check(first.levels.length === 1 && first.levels[0] === 0 && first.received < 1,
  "the first image: the surface at level 0 (" + first.levels + "), " + (100 * first.received).toFixed(0) + "% received");
checks.check(/level 0 is the coarse one/.test(await page.locator("#readout").textContent()),
  "the readout says the coarse level and the fraction received");

// The server's need for FIRST: exactly the bricks its blocks read (the middle 8, and the corner
// blob's: 500 is inside it too), far fewer than the superset's 64.
await page.waitForFunction((v) => { const i = window.mediso.streamInfo([v]); return !i || i.exact[0]; },
  FIRST, { timeout: 60000, polling: 20 });
{
  const i = await page.evaluate((v) => window.mediso.streamInfo([v]), FIRST);
  const expected = exactNeed(written, FIRST);
  if (checks.check(i !== null, "the stream was under way when the server's need came")) {
    checks.check(i.needed[0].slice().sort((a, b) => a - b).join() === expected.join() &&
      [21, 22, 25, 26, 37, 38, 41, 42].every((id) => expected.includes(id)) && i.superset[0] === 64,
      "the surface at " + FIRST + " needs the " + expected.length + " bricks its blocks read, the middle 8 " +
      "among them (" + i.needed[0] + "), where the manifest's ranges alone gave " + i.superset[0]);
  }
}

// Mid-stream: a change to the small blob is drawn at once, its bricks first.
const pick = SMALL;
const VALUES = [FIRST, pick];
const changed = await page.evaluate((s) => window.mediso.setSurfaces(s), [surface(pick)]);
checks.check(changed.received < 1 && changed.levels.length === 1,
  "a change mid-stream (to " + pick + ") is drawn at once (" + (100 * changed.received).toFixed(0) +
  "% received, level " + changed.levels + ")");
const info = await page.evaluate((v) => window.mediso.streamInfo(v), [pick]);
if (checks.check(info !== null, "the stream was still under way after the change")) {
  const need = new Set(info.needed[0]);
  const total = info.bricks[0] * info.bricks[1] * info.bricks[2];
  const after = info.requested.filter((r) => r.values.join() === String(pick));
  const before = new Set(info.requested.filter((r) => !after.includes(r)).flatMap((r) => r.ids));
  const owed = [...need].filter((id) => !before.has(id));
  const asked = after.flatMap((r) => r.ids);
  console.log("bricks: " + total + ", asked before the change " + before.size + ", " + pick + " needs " +
    need.size + " (" + owed.length + " not yet asked); asked after: " + JSON.stringify(after.map((r) => r.ids)));
  checks.check(need.size < total && owed.length > 0, "the new isovalue needs some bricks not asked for yet, " +
    "and not all of them (" + owed.length + " of " + need.size + " of " + total + ")");
  checks.check(asked.slice(0, owed.length).every((id) => need.has(id)),
    "after the change the next bricks asked for are those the new isovalue needs");
  // The first requests ramp up to the batch (stream.js, FIRST_BATCH): request i carries at most 2^i bricks.
  const sizes = info.requested.map((r) => r.ids.length);
  checks.check(sizes.length >= 2 && sizes[0] === 1 && sizes[1] === 2 && sizes.every((n, i) => n <= 2 ** i),
    "the first requests carry 1, 2, 4, ... bricks (" + sizes + ")");
}

const full = await page.evaluate(() => window.mediso.whenFull());
checks.check(full.levels.join() === "3" && full.surfaceTriangles[0] > 0,
  "whenFull(): the surface at level 3 (" + full.levels + ") with " + (100 * full.received).toFixed(0) +
  "% of the level received");
checks.check(full.takenAhead >= 1, "the surface at the full level was extracted ahead, as its bricks " +
  "arrived, not at its frame (" + full.takenAhead + " taken)");
await page.waitForFunction(() => window.mediso.stats().received === 1, null, { timeout: 300000 });
checks.check((await page.evaluate(() => window.mediso.stats())).levels.join() === "3",
  "the whole level received, the surface still at level 3");
const log = await page.evaluate(() => window.mediso.frames());
{
  const ranges = await page.evaluate(() => window.mediso.brickRanges());
  const same = ranges && ranges.server.length === ranges.core.length && ranges.server.every((r, i) =>
    (r === null && ranges.core[i] === null) || (r && ranges.core[i] && r[0] === ranges.core[i][0] && r[1] === ranges.core[i][1]));
  checks.check(same && ranges.server.length === 64, "the manifest's " + (ranges ? ranges.server.length : 0) +
    " brick ranges (the server's numpy) are the cores' ComputeBrickRanges over the level received");
}

// The dense triangles of each value at level 3 and at level 0 (each a page of today's whole fetch).
const dense = { 0: {}, 3: {} };
let wholeBytes = 0;
{
  const { page: p, wire: w } = await open("&path=cpu&stream=0");
  for (const v of VALUES) {
    const s = await p.evaluate((x) => window.mediso.setSurfaces([x]), surface(v));
    dense[3][v] = s.surfaceTriangles[0];
  }
  const volume = [...w.responses.values()].find((r) => /\/api\/volume\/.*level=3/.test(r.url));
  wholeBytes = volume ? volume.encodedDataLength : 0;
  await p.close();
}
{
  const { page: p } = await open("&path=cpu&stream=0&budget=0.2");
  const s0 = await p.evaluate(() => window.mediso.stats());
  checks.check(s0.level === 0, "the reference page for level 0 fetched level 0 (" + s0.level + ")");
  await p.evaluate(() => window.mediso.setCPULevel(3));
  for (const v of VALUES) {
    const s = await p.evaluate((x) => window.mediso.setSurfaces([x]), surface(v));
    dense[0][v] = s.surfaceTriangles[0];
  }
  await p.close();
}
console.log("dense triangles: " + JSON.stringify(dense) + "; the whole level " + wholeBytes + " bytes");
checks.check(VALUES.every((v) => dense[0][v] > 0 && dense[3][v] > 0), "every value has a surface at levels 0 and 3");

let exact = 0;
const wrong = [];
for (const f of log) {
  (f.surfaceValues || []).forEach((v, i) => {
    const level = f.coarse[i] ? 0 : 3;
    if (f.surfaceTriangles[i] === dense[level][v]) {
      ++exact;
    } else {
      wrong.push([v, level, f.surfaceTriangles[i], dense[level][v]]);
    }
  });
}
checks.check(exact > 0 && wrong.length === 0, "at every frame each surface's triangles are the dense ones at its level (" +
  exact + " exact; wrong: " + JSON.stringify(wrong.slice(0, 5)) + ")");
checks.check(log.some((f) => f.coarse.some(Boolean)) && log.some((f) => f.coarse.length && !f.coarse.some(Boolean)),
  "frames at level 0 and at level 3 were drawn");
const streamed = [...wire.responses.values()].filter((r) => /\/api\/bricks\/.*ids=|\/api\/volume\/.*level=0/.test(r.url));
const streamedBytes = streamed.reduce((a, r) => a + (r.encodedDataLength || 0), 0);
checks.check(wholeBytes > 0 && streamedBytes <= 1.05 * wholeBytes,
  "level 0 and the bricks: " + streamedBytes + " bytes on the wire, " + (streamedBytes / wholeBytes).toFixed(3) +
  "x the whole level's " + wholeBytes + " (at most 1.05x)");

// After the end: a change sends nothing.
const requestsBefore = wire.requests.length, bytesBefore = wire.received;
await page.evaluate((s) => window.mediso.setSurfaces(s), [surface(VALUES[0])]);
await page.evaluate(() => window.mediso.whenFull());
checks.check(wire.requests.length === requestsBefore && wire.received === bytesBefore,
  "after the end, a change sends nothing (" + (wire.requests.length - requestsBefore) + " requests)");

rmSync(folder, { recursive: true, force: true });
await checks.finish(browser, server);
