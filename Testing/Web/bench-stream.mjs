// SPDX-License-Identifier: BSD-3-Clause
// The streaming benchmark's browser side (Python/benchmark_web.py --stream runs it): in one
// Chromium, the page on the CPU path fetching its level whole (?stream=0, the page before issue
// 31) and streaming (level 0, then the bricks), each in a fresh context (nothing cached), under
// each network condition (CDP Network.emulateNetworkConditions; "loopback": none): the time from
// navigation to the first image (window.mediso.ready), to the current surfaces at the full level
// (whenFull()), to the whole level received (stats().received === 1), and the bytes on the wire
// (CDP loadingFinished), in all and when the surfaces were at the full level, with the fraction of
// the level received then.
//   node bench-stream.mjs CONFIG.json OUT.json
// CONFIG: {url, beforeUrl?, size: [w, h], networks: [{name, mbps, latencyMs} | {name: "loopback"}], repeats}
// (beforeUrl: another tree's page, streaming, timed between the two as mode "before")
import { launch } from "./page.mjs";
import { readFileSync, writeFileSync } from "node:fs";

const [configFile, outFile] = process.argv.slice(2);
const config = JSON.parse(readFileSync(configFile, "utf8"));
const browser = await launch();
const runs = [];
for (let repeat = 0; repeat < (config.repeats || 1); ++repeat) {
  for (const network of config.networks) {
    for (const mode of config.beforeUrl ? ["whole", "before", "stream"] : ["whole", "stream"]) {
      const context = await browser.newContext({ viewport: { width: config.size[0] + 420, height: config.size[1] + 100 } });
      const page = await context.newPage();
      page.on("pageerror", (e) => console.log(mode + " pageerror: " + e.message));
      const cdp = await context.newCDPSession(page);
      let bytes = 0;
      cdp.on("Network.loadingFinished", (e) => { bytes += e.encodedDataLength; });
      await cdp.send("Network.enable");
      if (network.mbps) {
        await cdp.send("Network.emulateNetworkConditions", { offline: false, latency: network.latencyMs,
          downloadThroughput: (network.mbps * 1e6) / 8, uploadThroughput: (network.mbps * 1e6) / 8 });
      }
      const start = Date.now();
      await page.goto((mode === "before" ? config.beforeUrl : config.url) + "&path=cpu&size=" + config.size.join("x") + (mode === "whole" ? "&stream=0" : ""),
        { waitUntil: "commit" });
      await page.waitForFunction(() => window.mediso, null, { timeout: 600000 });
      await page.evaluate(() => window.mediso.ready);
      const firstMs = Date.now() - start;
      const full = await page.evaluate(() => window.mediso.whenFull());
      const fullMs = Date.now() - start;
      const bytesAtFull = bytes;
      await page.waitForFunction(() => window.mediso.stats().received === 1, null, { timeout: 600000, polling: 50 });
      const wholeMs = Date.now() - start;
      await page.waitForTimeout(200);
      // Where the time went: the stream's marks (stats().streamTimes, ms from navigation) and the
      // worker's frames (the whole page's too).
      const parts = await page.evaluate(() => ({ times: window.mediso.stats().streamTimes,
        frames: window.mediso.frames().map((f) => ({ ms: Math.round(f.ms), cpuLevel: f.cpuLevel,
          triangles: f.triangles, coarse: f.coarse.filter(Boolean).length })) }));
      runs.push({ network: network.name, mode, firstMs, fullMs, wholeMs, bytes, bytesAtFull,
        receivedAtFull: full.received, levels: full.levels, times: parts.times, frames: parts.frames,
        surfaces: (await page.evaluate(() => window.mediso.getSurfaces())).map((s) => s.value) });
      console.log(JSON.stringify(runs[runs.length - 1]));
      await context.close();
    }
  }
}
await browser.close();
writeFileSync(outFile, JSON.stringify({ runs }));
