// SPDX-License-Identifier: BSD-3-Clause
// The paper's claim on the wire, counted by Chrome itself (CDP network events, WebSocket frames
// included): the page fetches the volume once, in at most 0.6x its raw bytes, and then 20
// isovalue changes, 5 colour and opacity changes and 5 camera changes send and receive nothing
// at all: no request, no WebSocket frame, 0 bytes; the page's own readout agrees. A reload then
// revalidates the volume (304) instead of fetching it again. Where the page streams (level 0,
// then the bricks: docs/web.md, Streaming), each brick comes once, several a request, the whole
// within 0.6x, the changes come after the last brick, and the reload revalidates the bricks too.
// On the server's default dataset: the head CT when it is fetched, else the phantom (said).
import { Checks, countWire, launchBrowser, openPage, startServer } from "./webserver-harness.mjs";

const checks = new Checks();
const server = await startServer();
const browser = await launchBrowser();
const context = await browser.newContext({ viewport: { width: 1280, height: 800 } });
const page = await context.newPage();
const wire = await countWire(context, page);
await openPage(page, server);
// Where the page streams (docs/web.md, Streaming: level 0, then the level's bricks), until the
// whole level has arrived.
const received = () => page.waitForFunction(() => window.mediso.stats().received === 1, null,
  { timeout: 300000 });
await received();

const dataset = (await (await fetch(server.api("/api/datasets"))).json()).datasets[0];
console.log("dataset: " + dataset.name + " " + dataset.dims.join("x") + " " + dataset.type +
  (dataset.name.startsWith("MedicalPhantom") ? " (the head CT is not fetched: the phantom)" : ""));
const volumes = [...wire.responses.values()].filter((r) => r.url.includes("/api/volume/"));
const bricks = [...wire.responses.values()].filter((r) => /\/api\/bricks\/[^?]*\?.*ids=/.test(r.url));
checks.check(volumes.length === 1, "the volume (streamed: its level 0) is fetched once (" + volumes.length + ")");
const brickIds = bricks.flatMap((r) => new URL(r.url).searchParams.get("ids").split(","));
checks.check(new Set(brickIds).size === brickIds.length, "each brick is fetched once (" + brickIds.length +
  " bricks in " + bricks.length + " requests)");
// Several bricks a request (stream.js's BATCHES: about 24 a level), not one request a brick.
checks.check(!bricks.length || (bricks.length <= 24 && bricks.length < brickIds.length),
  "... several bricks a request, at most 24 requests (" + bricks.length + ")");
{
  const level = (await page.evaluate(() => window.mediso.stats())).level;
  const raw = dataset.levels[level].bytes;
  const crossed = [...volumes, ...bricks].reduce((a, r) => a + r.encodedDataLength, 0);
  checks.check(crossed > 0 && crossed <= 0.6 * raw,
    "the volume crossed in " + crossed + " bytes with their headers (" + (bricks.length ? "level 0 and " +
    bricks.length + " bricks" : "one request") + "), " + (crossed / raw).toFixed(3) + "x its " + raw +
    " raw bytes (at most 0.6x)");
}
// The page is ES modules (app.js imports the others): a browser runs a module script only when
// it comes with a JavaScript MIME type.
const scripts = [...wire.responses.values()].filter((r) => /\/static\/[^/?]+\.js(\?|$)/.test(r.url));
const header = (r, name) => Object.entries(r.headers).find(([k]) => k.toLowerCase() === name)?.[1] || "";
const notJS = scripts.filter((r) => !/^(text|application)\/javascript\b/.test(header(r, "content-type")));
checks.check(scripts.length > 0 && notJS.length === 0,
  scripts.length + " scripts of /static/ served as JavaScript" + (notJS.length ? " (not: " +
    notJS.map((r) => r.url.replace(/\?.*/, "") + " " + header(r, "content-type")).join(", ") + ")" : ""));
checks.check(wire.framesSent + wire.framesReceived === 0,
  "no WebSocket frame while the page loads and renders (" + wire.framesSent + " sent)");

const before = { events: wire.events, received: wire.received, requests: wire.requests.length,
  frames: wire.framesSent + wire.framesReceived };
const stats0 = await page.evaluate(() => window.mediso.stats());
const [lo, hi] = dataset.range;
const primitives = [];
for (let i = 0; i < 20; ++i) {
  const v = lo + (hi - lo) * (0.15 + 0.6 * i / 19);
  const s = await page.evaluate((value) => window.mediso.setIsovalues([value]), v);
  primitives.push(s.path === "gpu" ? s.primitives : s.triangles);
}
for (let i = 0; i < 5; ++i) {
  await page.evaluate((k) => window.mediso.setSurfaces([
    { value: -500 + 10 * k, color: [0.2 * k, 0.5, 0.9], opacity: 0.3 + 0.1 * k },
    { value: 400, color: [1, 1, 1], opacity: 1 }]), i);
}
const view = await page.evaluate(() => window.mediso.getView());
for (let i = 0; i < 5; ++i) {
  const angle = (i + 1) * 0.3;
  const d = view.position.map((p, a) => p - view.focalPoint[a]);
  const r = Math.hypot(d[0], d[2]);
  await page.evaluate((v) => window.mediso.setView(v), {
    position: [view.focalPoint[0] + r * Math.sin(angle), view.position[1],
      view.focalPoint[2] + r * Math.cos(angle)],
    focalPoint: view.focalPoint, viewUp: view.viewUp, viewAngle: view.viewAngle });
}
await page.waitForTimeout(1500); // anything late would show up here
const stats1 = await page.evaluate(() => window.mediso.stats());
checks.check(new Set(primitives).size > 10,
  "the 20 isovalue changes drew different surfaces on the " + stats1.path.toUpperCase() +
  " path (" + new Set(primitives).size + " distinct primitive or triangle counts)");
checks.check(wire.requests.length === before.requests,
  "20 isovalue, 5 colour/opacity and 5 camera changes: " +
  (wire.requests.length - before.requests) + " HTTP requests");
checks.check(wire.framesSent + wire.framesReceived === before.frames,
  "... " + (wire.framesSent + wire.framesReceived - before.frames) + " WebSocket frames");
checks.check(wire.received === before.received && wire.events === before.events,
  "... " + (wire.received - before.received) + " bytes received, " +
  (wire.events - before.events) + " network events in all");
checks.check(stats1.bytesSent === stats0.bytesSent && stats1.bytesReceived === stats0.bytesReceived,
  "... and the page's readout agrees (" + stats1.bytesSent + " B sent, " +
  stats1.bytesReceived + " B received since it loaded)");

// A reload: the browser kept the volume (ETag, Cache-Control no-cache) and revalidates it; the
// server answers 304 and the volume's bytes do not cross again (docs/web.md, "Caching").
const kept = new Set(wire.responses.keys());
await page.reload({ waitUntil: "commit" });
await page.waitForFunction(() => window.mediso !== undefined, null, { timeout: 120000 });
await page.evaluate(() => window.mediso.ready);
await received();
const again = [...wire.responses.entries()].filter(([id, r]) => !kept.has(id) &&
  r.url.includes("/api/volume/")).map(([, r]) => r);
const stats2 = await page.evaluate(() => window.mediso.stats());
// Chrome reports the cached response (status 200) after a 304; what crossed is the 304's headers:
// more than nothing (it was asked again, not taken unrevalidated) and far less than the volume.
checks.check(again.length === 1 && again[0].encodedDataLength > 0 && again[0].encodedDataLength < 2000,
  "after a reload the volume is revalidated, not sent: " + again.map((r) => "status " + r.status +
    " as Chrome reports it, " + r.encodedDataLength + " bytes on the wire").join("; "));
const bricksAgain = [...wire.responses.entries()].filter(([id, r]) => !kept.has(id) &&
  /\/api\/bricks\/[^?]*\?.*ids=/.test(r.url)).map(([, r]) => r);
checks.check(bricksAgain.every((r) => r.encodedDataLength < 2000),
  "... and so are the bricks (" + bricksAgain.length + ", at most " +
  Math.max(0, ...bricksAgain.map((r) => r.encodedDataLength)) + " bytes each on the wire)");
checks.check((stats2.primitives || stats2.triangles) > 0 && stats2.bytesReceived < 0.05 * dataset.bytes,
  "... the page draws it from the browser's copy and counts " + stats2.bytesReceived +
  " B received (the volume's raw bytes: " + dataset.bytes + ")");
await checks.finish(browser, server);
