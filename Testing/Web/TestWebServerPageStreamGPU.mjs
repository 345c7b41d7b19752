// SPDX-License-Identifier: BSD-3-Clause
// Streaming on the GPU path (issue 31; docs/web.md, Streaming), in Chromium (SwiftShader), the
// viewer in the worker, the network throttled through CDP so that there is a "while", on a volume
// the test writes (two blobs: one whose surface needs every brick, one a corner's):
// - the first image comes from level 0 (stats().levels 0, gpuLevel 0, said in the readout) with
//   exactly level 0's primitives (the CPU model's count on a page that fetched level 0 whole);
// - at every frame the primitives are exactly the CPU model's count at the level it was drawn at
//   (0 while any current surface's bricks are missing, else 3), and every surface's level in
//   stats() is that one;
// - an isovalue changed mid-stream (to the corner's blob) is drawn at once, and the bricks it
//   needs (the server's exact need, within the ranges' superset) are asked for before any other;
// - whenFull() resolves with the surface at level 3 and the full level's exact count before the
//   whole level has come; received reaches 1; the bricks went into the texture as sub-regions
//   (one whole upload: the empty buffer); the bytes of level 0 and the bricks are at most 1.05x
//   the whole level's; after the end a change sends nothing.
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import path from "node:path";
import { Checks, countWire, launchBrowser, openEmulated, startServer, writeTwoBlobs } from "./webserver-harness.mjs";

const checks = new Checks();
// Two blobs in a 192^3 int16 NIfTI (bricks of 64: 3 per axis): a large one in the middle, whose
// surface at FIRST needs every brick, and a small one in a corner, whose surface at SMALL needs
// the far corner's 8 bricks (the last in the volume's order); deterministic noise (4 bits, so that
// the level takes a while on the wire).
const N = 192, FIRST = 500, SMALL = 1500;
const writeVolume = (file) => writeTwoBlobs(file, N, 168, 16);
const folder = mkdtempSync(path.join(tmpdir(), "mediso-stream-gpu-"));
const nifti = path.join(folder, "blobs.nii");
writeVolume(nifti);
const server = await startServer([nifti]);
const browser = await launchBrowser();
const surface = (value) => ({ value, color: [1, 1, 1], opacity: 1 });
const VALUES = [FIRST, SMALL];

async function open(query, throttle) {
  return openEmulated(browser, server.url + query, { viewport: { width: 640, height: 480 }, mbit: throttle || 0,
    watch: async (context, page) => ({ wire: await countWire(context, page) }) });
}

// The CPU model's counts of each value at level 0 (a page that fetched level 0 whole: its volume
// is the server's level 0) and at level 3 (the whole level), and the whole level's bytes.
const counts = { 0: {}, 3: {} };
let wholeBytes = 0;
{
  const { page: p, wire: w } = await open("&path=gpu&stream=0");
  for (const v of VALUES) {
    counts[3][v] = await p.evaluate((x) => window.mediso.cpuCount([x]), v);
  }
  const volume = [...w.responses.values()].find((r) => /\/api\/volume\/.*level=3/.test(r.url));
  wholeBytes = volume ? volume.encodedDataLength : 0;
  await p.close();
}
{
  const { page: p } = await open("&path=gpu&stream=0&budget=0.1");
  const s0 = await p.evaluate(() => window.mediso.stats());
  checks.check(s0.level === 0, "the reference page for level 0 fetched level 0 (" + s0.level + ")");
  for (const v of VALUES) {
    counts[0][v] = await p.evaluate((x) => window.mediso.cpuCount([x]), v);
  }
  await p.close();
}
console.log("CPU model's counts: " + JSON.stringify(counts) + "; the whole level " + wholeBytes + " bytes");
checks.check(VALUES.every((v) => counts[0][v] > 0 && counts[3][v] > counts[0][v]),
  "every value has cells at levels 0 and 3");

// The streaming page, GPU path, at 5 Mbit/s and 40 ms (the first frames on SwiftShader under load
// take a while), one surface.
const { page, wire } = await open("&path=gpu#iso=" + FIRST + ",ffffff,1", 5);
const first = await page.evaluate(() => window.mediso.stats());
console.log("first image: " + JSON.stringify({ path: first.path, levels: first.levels, gpuLevel: first.gpuLevel,
  primitives: first.primitives, received: first.received }));
checks.check(first.path === "gpu" && first.levels.join() === "0" && first.gpuLevel === 0 && first.received < 1,
  "the first image on the GPU path: the surface at level 0 (" + first.levels + ", gpuLevel " + first.gpuLevel +
  "), " + (100 * first.received).toFixed(0) + "% received");
checks.check(first.primitives === counts[0][FIRST],
  "the first image's primitives are level 0's exact count (" + first.primitives + ", " + counts[0][FIRST] + ")");
checks.check(/level 0 is the coarse one/.test(await page.locator("#readout").textContent()),
  "the readout says the coarse level and the fraction received");

// Mid-stream: a change to the small blob is drawn at once, its bricks first.
const changed = await page.evaluate((s) => window.mediso.setSurfaces(s), [surface(SMALL)]);
checks.check(changed.received < 1 && changed.levels.length === 1 &&
  changed.primitives === counts[changed.levels[0]][SMALL],
  "a change mid-stream (to " + SMALL + ") is drawn at once (" + (100 * changed.received).toFixed(0) +
  "% received, level " + changed.levels + ", " + changed.primitives + " primitives: that level's count)");
const info = await page.evaluate((v) => window.mediso.streamInfo(v), [SMALL]);
if (checks.check(info !== null, "the stream was still under way after the change")) {
  const need = new Set(info.needed[0]);
  const total = info.bricks[0] * info.bricks[1] * info.bricks[2];
  const before = new Set(info.requested.filter((r) => r.values.join() !== String(SMALL)).flatMap((r) => r.ids));
  const owed = [...need].filter((id) => !before.has(id));
  checks.check(need.size < total && owed.length > 0, "the new isovalue needs some bricks not asked for yet, " +
    "and not all of them (" + owed.length + " of " + need.size + " of " + total + ")");
  // The server's exact need (the bricks the blocks crossing SMALL read) replaces the superset when
  // it comes; the requests after the change, once those it owes have gone out (or the stream ended).
  await page.waitForFunction((v) => { const i = window.mediso.streamInfo([v]); return !i || i.exact[0]; },
    SMALL, { timeout: 60000, polling: 20 });
  const exactInfo = await page.evaluate((v) => window.mediso.streamInfo(v), [SMALL]);
  const exact = new Set(exactInfo ? exactInfo.needed[0] : []);
  const owedExact = [...exact].filter((id) => !before.has(id));
  await page.waitForFunction(([v, owedIds]) => {
    const i = window.mediso.streamInfo([v]);
    if (!i) {
      return true;
    }
    const asked = new Set(i.requested.filter((r) => r.values.join() === String(v)).flatMap((r) => r.ids));
    return owedIds.every((id) => asked.has(id));
  }, [SMALL, owedExact], { timeout: 300000 });
  const later = await page.evaluate((v) => window.mediso.streamInfo(v), [SMALL]);
  const asked = later ? later.requested.filter((r) => r.values.join() === String(SMALL)).flatMap((r) => r.ids) : [];
  console.log("bricks: " + total + ", asked before the change " + before.size + ", " + SMALL + " needs " +
    need.size + " by the ranges, " + exact.size + " by the server (" + owedExact.length +
    " not yet asked); asked after: " + JSON.stringify(asked));
  // Every brick it needs is asked for before any brick that it does not need by the ranges either.
  const lastNeeded = Math.max(...owedExact.map((id) => asked.indexOf(id)));
  const firstOther = asked.findIndex((id) => !need.has(id));
  checks.check(exact.size > 0 && [...exact].every((id) => need.has(id)) && lastNeeded >= 0 &&
    (firstOther < 0 || lastNeeded < firstOther),
    "after the change the bricks the new isovalue needs (" + owedExact.length + " owed) are asked for " +
    "before any other");
}

const full = await page.evaluate(() => window.mediso.whenFull());
checks.check(full.levels.join() === "3" && full.gpuLevel === 3 && full.primitives === counts[3][SMALL],
  "whenFull(): the surface at level 3 (" + full.levels + ") with the full level's exact count (" +
  full.primitives + ", " + counts[3][SMALL] + ")");
checks.check(full.received < 1, "... before the whole level had come (" + (100 * full.received).toFixed(0) + "% received)");
await page.waitForFunction(() => window.mediso.stats().received === 1, null, { timeout: 300000 });
const end = await page.evaluate(() => window.mediso.drawn());
checks.check(end.levels.join() === "3" && end.primitives === counts[3][SMALL],
  "the whole level received, the surface still at level 3 with its exact count");
checks.check(end.volumeUploads === 1 && end.regionUploads === 27,
  "the bricks went into the texture as sub-regions: " + end.volumeUploads + " whole upload (the empty buffer), " +
  end.regionUploads + " region uploads for 27 bricks");

// Every frame: its primitives the exact count of its values at the level it was drawn at, and
// every surface of it said to be at that level.
const log = await page.evaluate(() => window.mediso.frames());
let exact = 0;
const wrong = [];
for (const f of log) {
  const level = f.gpuLevel === 0 ? 0 : 3;
  const expected = f.values.reduce((a, v) => a + counts[level][v], 0);
  const said = f.coarse.every((c) => c === (level === 0)) && f.coarse.length === f.values.length;
  if (f.gpuLevel !== 0 && f.gpuLevel !== 3) {
    wrong.push(["level", f.gpuLevel]);
  } else if (f.primitives === expected && said) {
    ++exact;
  } else {
    wrong.push([f.values, f.gpuLevel, f.primitives, expected, f.coarse]);
  }
}
checks.check(exact > 0 && wrong.length === 0, "at every frame the primitives are the exact count at the level " +
  "drawn, each surface said to be there (" + exact + " exact; wrong: " + JSON.stringify(wrong.slice(0, 5)) + ")");
checks.check(log.some((f) => f.gpuLevel === 0) && log.some((f) => f.gpuLevel === 3),
  "frames at level 0 and at level 3 were drawn");

const streamed = [...wire.responses.values()].filter((r) => /\/api\/bricks\/.*ids=|\/api\/volume\/.*level=0/.test(r.url));
const streamedBytes = streamed.reduce((a, r) => a + (r.encodedDataLength || 0), 0);
checks.check(wholeBytes > 0 && streamedBytes > 0 && streamedBytes <= 1.05 * wholeBytes,
  "level 0 and the bricks: " + streamedBytes + " bytes on the wire, " + (streamedBytes / wholeBytes).toFixed(3) +
  "x the whole level's " + wholeBytes + " (at most 1.05x)");

// After the end: a change sends nothing, and is drawn at the full level with its exact count.
const requestsBefore = wire.requests.length, bytesBefore = wire.received;
await page.evaluate((s) => window.mediso.setSurfaces(s), [surface(FIRST)]);
const after = await page.evaluate(() => window.mediso.whenFull());
checks.check(wire.requests.length === requestsBefore && wire.received === bytesBefore,
  "after the end, a change sends nothing (" + (wire.requests.length - requestsBefore) + " requests)");
checks.check(after.levels.join() === "3" && after.primitives === counts[3][FIRST],
  "after the end, the change drawn at level 3 with its exact count (" + after.primitives + ", " +
  counts[3][FIRST] + ")");

rmSync(folder, { recursive: true, force: true });
await checks.finish(browser, server);
