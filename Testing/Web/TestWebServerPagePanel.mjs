// SPDX-License-Identifier: BSD-3-Clause
// The page's "On the server" panel end to end, in Chromium, on the phantom (96^3): the bone
// surface smoothed, hole-filled and decimated on the server with a progress bar on the way; the
// STL downloaded through the panel's link is binary, holds the summary's triangles and is
// watertight (every edge shared by two triangles); the PLY goes to window.mediso.showMesh; the
// WebSocket opens only at the first request and its frames (counted by CDP) are in the page's
// readout; the mesh report shows before the download, the source surface is hidden while its
// result is shown (a toggle for each) and the surface choice follows the isovalue box; a server
// refusal (a hole size of 0) and a cancel show in the panel; with a second
// browser running a long operation the first one's waits, and runs when the second closes
// mid-operation; the page then still changes isovalues without a byte.
import { readFileSync } from "node:fs";
import { tmpdir } from "node:os";
import path from "node:path";
import { Checks, countWire, launchBrowser, openPage, startServer } from "./webserver-harness.mjs";

const ISO = 900; // the phantom's skull: a closed surface
const checks = new Checks();
const server = await startServer(["phantom:96"]);
const browser = await launchBrowser();
const context = await browser.newContext({ viewport: { width: 1280, height: 1000 },
  acceptDownloads: true });
const page = await context.newPage();
const wire = await countWire(context, page);
await openPage(page, server);

// The PLY the panel hands to the page's mesh display, recorded (the page's own, when it has one,
// still runs).
await page.evaluate((iso) => {
  const own = window.mediso.showMesh;
  window.mediso.showMesh = (buffer) => {
    window.shownMesh = new TextDecoder().decode(new Uint8Array(buffer, 0, 300));
    window.shownBytes = buffer.byteLength;
    window.shownCount = (window.shownCount || 0) + 1;
    return own ? own(buffer) : undefined;
  };
  const progress = document.getElementById("op-progress");
  window.progressSeen = [];
  new MutationObserver(() => {
    if (!progress.hidden) {
      window.progressSeen.push(progress.value);
    }
  }).observe(progress, { attributes: true });
  return window.mediso.setSurfaces([{ value: iso, color: [1, 1, 1], opacity: 1 }]);
}, ISO);

const state = () => page.evaluate(() => document.getElementById("op-run").closest("section").dataset.state);
const waitState = (states, timeout = 180000) => page.waitForFunction(
  (s) => s.includes(document.getElementById("op-run").closest("section").dataset.state),
  states, { timeout });

checks.check(wire.framesSent === 0 && !wire.requests.some((r) => r.url.includes("/api/ws")),
  "no WebSocket before the first request");
await page.selectOption("#op-surface", "0");
await page.selectOption("#op-level", "3");
await page.setChecked("#op-smooth", true);
await page.fill("#op-iterations", "20");
await page.setChecked("#op-fill", true);
await page.fill("#op-hole", "20");
await page.setChecked("#op-clip", false);
await page.setChecked("#op-decimate", true);
await page.fill("#op-reduction", "0.5");
// A change is answered coarse first and refined: the surface's own count is its full level's.
await page.evaluate(() => window.mediso.whenFull());
const stats0 = await page.evaluate(() => window.mediso.stats());
const sent0 = wire.frameBytesSent, received0 = wire.frameBytesReceived;
await page.click("#op-run");
await waitState(["done", "error"]);
const summary = await page.textContent("#op-result");
checks.check(await state() === "done", "the operation ran: " + summary.slice(0, 160));
const progress = await page.evaluate(() => window.progressSeen);
checks.check(progress.length > 0 && Math.max(...progress) > 0,
  "the progress bar showed the server's progress (" + progress.length + " updates)");
checks.check(wire.framesSent >= 1 && wire.framesReceived >= 2,
  "one request up, progress and the summary down (" + wire.framesSent + " frames sent, " +
  wire.framesReceived + " received)");
const triangles = Number(/([\d,]+) triangles/.exec(summary)[1].replace(/,/g, ""));
checks.check(/closed \(no boundary edges\)/.test(summary), "the summary says the surface is closed");

// The mesh report, shown before any download; the source surface hidden while the result is
// shown, and its toggle; the surface choice follows the isovalue box.
const report = await page.evaluate(() => ({
  watertight: document.getElementById("op-run").closest("section").dataset.watertight,
  fields: [...document.querySelectorAll("#op-result .report li[data-field]")].map((li) => li.textContent),
  head: document.querySelector("#op-result .report li")?.textContent }));
checks.check(report.watertight === "true" && report.fields.length === 7 &&
  /Watertight: yes/.test(report.head) && report.fields.includes("boundary edges: 0") &&
  report.fields.includes("pieces: 1"),
  "the mesh report is shown: " + report.head + "; " + report.fields.join(", "));
const drawn = (s) => (s.path === "gpu" ? s.primitives : s.triangles);
// (mediso.drawn(): the stats once the frame of the last change is drawn; the viewer may draw in
// a worker, whose frames come after the click.)
const hidden = await page.evaluate(() => window.mediso.drawn());
const sourceBox = await page.isChecked("#op-show-source");
await page.click("#op-show-source");
const shownAgain = await page.evaluate(() => window.mediso.drawn());
await page.click("#op-show-source");
const hiddenAgain = await page.evaluate(() => window.mediso.drawn());
checks.check(!sourceBox && drawn(hidden) < drawn(stats0) && drawn(shownAgain) === drawn(stats0) &&
  drawn(hiddenAgain) === drawn(hidden),
  "the source is hidden while the result is shown (" + drawn(stats0) + " -> " + drawn(hidden) +
  " drawn on the " + hidden.path + " path), its toggle shows it (" + drawn(shownAgain) +
  ") and hides it again (" + drawn(hiddenAgain) + ")");
checks.check(await page.isChecked("#op-show-result"), "the result's toggle is on");
await page.fill("#surfaces .isovalue", "850");
const choice = await page.evaluate(() => document.getElementById("op-surface").selectedOptions[0].textContent);
checks.check(choice === "850", "the surface choice shows the isovalue as changed: " + choice);
await page.fill("#surfaces .isovalue", String(ISO));

// The STL through the panel's link, read here.
const [download] = await Promise.all([page.waitForEvent("download"),
  page.click("#op-result a[data-format=stl]")]);
const file = path.join(tmpdir(), "mediso-panel-" + process.pid + ".stl");
await download.saveAs(file);
const stl = readFileSync(file);
const count = stl.readUInt32LE(80);
checks.check(download.suggestedFilename().endsWith(".stl") && count === triangles &&
  stl.length === 84 + 50 * count,
  "the STL download (" + download.suggestedFilename() + ") is binary with the summary's " +
  triangles + " triangles");
const edges = new Map();
const key = (o) => stl.readFloatLE(o) + "," + stl.readFloatLE(o + 4) + "," + stl.readFloatLE(o + 8);
for (let t = 0; t < count; ++t) {
  const base = 84 + 50 * t + 12;
  const v = [key(base), key(base + 12), key(base + 24)];
  for (let e = 0; e < 3; ++e) {
    const [a, b] = [v[e], v[(e + 1) % 3]].sort();
    edges.set(a + "|" + b, (edges.get(a + "|" + b) || 0) + 1);
  }
}
const open = [...edges.values()].filter((n) => n === 1).length;
const nonManifold = [...edges.values()].filter((n) => n > 2).length;
checks.check(open === 0 && edges.size > 0, "the STL is watertight: " + edges.size +
  " edges, " + open + " used by one triangle only (" + nonManifold + " by more than two)");

await page.waitForFunction(() => window.shownBytes !== undefined, null, { timeout: 60000 });
const shown = await page.evaluate(() => [window.shownMesh, window.shownBytes]);
checks.check(shown[0].startsWith("ply\nformat binary_little_endian 1.0") &&
  shown[0].includes("element face " + triangles),
  "window.mediso.showMesh got the binary little-endian PLY (" + shown[1] + " bytes)");

const stats1 = await page.evaluate(() => window.mediso.stats());
const frames = { sent: wire.frameBytesSent - sent0, received: wire.frameBytesReceived - received0 };
checks.check(stats1.bytesSent - stats0.bytesSent >= frames.sent &&
  stats1.bytesReceived - stats0.bytesReceived >= frames.received + stl.length,
  "the readout counts the WebSocket frames (" + frames.sent + " B up, " + frames.received +
  " B down) and the downloads: +" + (stats1.bytesSent - stats0.bytesSent) + " B sent, +" +
  (stats1.bytesReceived - stats0.bytesReceived) + " B received");

// A value the server refuses: its message shows in the panel.
await page.fill("#op-hole", "0");
await page.click("#op-run");
await waitState(["error", "done"], 60000);
const refusal = await page.textContent("#op-result");
checks.check(await state() === "error" && refusal.includes("fillHoles.size"),
  "a hole size of 0: " + refusal);

// Cancel from the panel, mid-operation.
await page.fill("#op-hole", "20");
await page.fill("#op-iterations", "500");
await page.click("#op-run");
await page.waitForFunction(() => /smoothing/.test(document.getElementById("op-result").textContent),
  null, { timeout: 120000 });
await page.click("#op-run");
await waitState(["cancelled", "done", "error"], 60000);
checks.check(await state() === "cancelled", "Cancel stops it: " + await page.textContent("#op-result"));
const status = await (await fetch(server.api("/api/status"))).json();
checks.check(!status.running && status.worker.restarts === 0, "the server is idle again");

// Two browsers: a second one starts a long operation, the first queues a short one behind it
// (and says it waits), then the second closes mid-operation: its operation stops and the first's
// runs.
const context2 = await browser.newContext({ viewport: { width: 1280, height: 1000 } });
const page2 = await context2.newPage();
await openPage(page2, server);
await page2.fill("#op-iterations", "500");
await page2.click("#op-run");
await page2.waitForFunction(() => /smoothing/.test(document.getElementById("op-result").textContent),
  null, { timeout: 120000 });
await page.fill("#op-iterations", "5");
await page.click("#op-run");
await page.waitForFunction(
  () => /waiting for the server/.test(document.getElementById("op-result").textContent),
  null, { timeout: 60000 });
await context2.close();
await waitState(["done", "error", "cancelled"], 120000);
checks.check(await state() === "done",
  "two browsers: the first's operation waited, then ran once the second closed mid-operation");
const after = await (await fetch(server.api("/api/status"))).json();
checks.check(!after.running && after.worker.restarts === 0 && after.sessions === 1,
  "the closed browser's operation was stopped by abort and its socket is gone (" +
  JSON.stringify(after) + ")");

// (Its result then goes to the page's mesh display: that fetch ends before the count below.)
await page.waitForFunction(() => window.shownCount === 2, null, { timeout: 60000 });

// The page still changes isovalues without a byte.
const events = wire.events;
await page.evaluate(() => window.mediso.setIsovalues([300]));
await page.evaluate(() => window.mediso.setIsovalues([600]));
await page.waitForTimeout(500);
checks.check(wire.events === events, "isovalue changes after it all: " + (wire.events - events) +
  " network events");
await checks.finish(browser, server);
