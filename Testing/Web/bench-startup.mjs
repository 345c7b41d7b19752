// SPDX-License-Identifier: BSD-3-Clause
// The page's start-up, request by request (issue 31's first image; Python/benchmark_web.py
// --startup runs it): in one Chromium, the page opened N times, each in a fresh context (nothing
// cached) under each network (CDP Network.emulateNetworkConditions; "loopback": none). For each
// request of the page, from navigation: when it was sent, when its response began and ended,
// and its bytes on the wire (CDP; the worker's own requests are not the page's session's); and
// the page's own marks (performance.mark "mediso:*": this thread's module loaded, the worker
// ready, the first image) up to the first image (window.mediso.ready).
//   node bench-startup.mjs CONFIG.json OUT.json
// CONFIG: {url, size: [w, h], networks: [{name, mbps, latencyMs} | {name: "loopback"}], repeats,
//          pages: {label: url} (optional: several pages, e.g. before and after a change, taken in
//          turn for each repeat and network; url's page alone otherwise)}
import { launch } from "./page.mjs";
import { readFileSync, writeFileSync } from "node:fs";

const [configFile, outFile] = process.argv.slice(2);
const config = JSON.parse(readFileSync(configFile, "utf8"));
const browser = await launch();
const runs = [];

// Network events of one CDP session into `requests` (keyed by the session's request id).
async function watch(cdp, network, requests) {
  cdp.on("Network.requestWillBeSent", (e) => {
    requests.set(e.requestId, { url: e.request.url, sent: e.timestamp, type: e.type });
  });
  cdp.on("Network.responseReceived", (e) => {
    const r = requests.get(e.requestId);
    if (r) {
      r.response = e.timestamp;
      r.status = e.response.status;
      r.encoding = (e.response.headers["Content-Encoding"] || e.response.headers["content-encoding"] || "");
      r.fromCache = e.response.fromDiskCache || e.response.fromServiceWorker || false;
    }
  });
  cdp.on("Network.loadingFinished", (e) => {
    const r = requests.get(e.requestId);
    if (r) {
      r.end = e.timestamp;
      r.bytes = e.encodedDataLength;
    }
  });
  await cdp.send("Network.enable");
  if (network.mbps) {
    await cdp.send("Network.emulateNetworkConditions", { offline: false, latency: network.latencyMs,
      downloadThroughput: (network.mbps * 1e6) / 8, uploadThroughput: (network.mbps * 1e6) / 8 });
  }
}

const pages = config.pages || { page: config.url };
for (let repeat = 0; repeat < (config.repeats || 1); ++repeat) {
  for (const network of config.networks) {
    for (const [label, url] of Object.entries(pages)) {
      const context = await browser.newContext({ viewport: { width: config.size[0] + 420, height: config.size[1] + 100 } });
      const page = await context.newPage();
      page.on("pageerror", (e) => console.log("pageerror: " + e.message));
      // The main thread's long tasks (over 50 ms) from the start: what may hold its animation frames.
      await page.addInitScript(() => {
        window.medisoLongTasks = [];
        new PerformanceObserver((list) => {
          for (const e of list.getEntries()) {
            window.medisoLongTasks.push({ at: Math.round(e.startTime), ms: Math.round(e.duration) });
          }
        }).observe({ type: "longtask" });
      });
      const requests = new Map();
      const cdp = await context.newCDPSession(page);
      await watch(cdp, network, requests);
      let navigationTs = null;
      cdp.on("Network.requestWillBeSent", (e) => {
        if (navigationTs === null) {
          navigationTs = e.timestamp;
        }
      });
      const start = Date.now();
      await page.goto(url + "&path=cpu&size=" + config.size.join("x") + (config.query || ""), { waitUntil: "commit" });
      await page.waitForFunction(() => window.mediso, null, { timeout: 600000 });
      await page.evaluate(() => window.mediso.ready);
      const firstMs = Date.now() - start;
      const marks = await page.evaluate(() => performance.getEntriesByType("mark")
        .filter((m) => m.name.startsWith("mediso:")).map((m) => ({ name: m.name, at: m.startTime })));
      const resources = await page.evaluate(() => performance.getEntriesByType("resource").map((r) => ({
        url: r.name, start: r.startTime, responseStart: r.responseStart, end: r.responseEnd,
        transfer: r.transferSize, body: r.encodedBodySize, decoded: r.decodedBodySize })));
      const nav = await page.evaluate(() => {
        const n = performance.getEntriesByType("navigation")[0];
        return { start: n.startTime, responseStart: n.responseStart, responseEnd: n.responseEnd,
          domInteractive: n.domInteractive, transfer: n.transferSize };
      });
      const list = [...requests.values()].map((r) => ({ url: r.url.replace(/^https?:\/\/[^/]+/, "").replace(/[?&]token=[^&]*/, ""),
        type: r.type, status: r.status, encoding: r.encoding,
        sentMs: Math.round((r.sent - navigationTs) * 1000), responseMs: r.response ? Math.round((r.response - navigationTs) * 1000) : null,
        endMs: r.end ? Math.round((r.end - navigationTs) * 1000) : null, bytes: r.bytes || 0 }));
      // The stream's marks and the worker's set-up and first frame (stats().streamTimes).
      const stream = await page.evaluate(() => window.mediso.stats().streamTimes);
      const longTasks = await page.evaluate(() => window.medisoLongTasks);
      runs.push({ page: label, network: network.name, firstMs, marks, resources, nav, requests: list, stream,
        longTasks });
      console.log(JSON.stringify({ page: label, network: network.name, firstMs }));
      await context.close();
    }
  }
}
await browser.close();
writeFileSync(outFile, JSON.stringify({ runs }, null, 1));
