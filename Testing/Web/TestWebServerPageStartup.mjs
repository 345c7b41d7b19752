// SPDX-License-Identifier: BSD-3-Clause
// The page's start-up (issue 31's first image; docs/web.md, "The page's start-up"):
// - the server sends the page's files gzip'd to a client that takes gzip (the scripts, the style
//   sheet, the page, the WebAssembly modules), with Vary, an ETag of that representation and
//   Last-Modified; the bytes inflate to the file on disk exactly; If-None-Match with the tag
//   gets 304 and no body; a client that does not take gzip gets the file as it is;
// - index.html preloads (modulepreload) exactly the modules app.js imports, directly or not;
// - in Chromium, a fresh context, the network throttled (30 Mbit/s, 40 ms through CDP): every
//   module is asked for before app.js has arrived (one wave, not one per import level), the
//   render worker's script before app.js has arrived (index.html starts the worker) and once,
//   and so before this thread's module has arrived (the two modules load side by side), and level 0 and the bricks' manifest before the worker is ready (the
//   mediso:worker mark); the first image is level 0's; the scripts and the module cross gzip'd;
// - with ?stream=0 nothing is asked for ahead: the level comes once, and level 0 never;
// - with ?worker=0 (the viewer on the main thread) index.html starts no worker.
import { readFileSync } from "node:fs";
import http from "node:http";
import path from "node:path";
import zlib from "node:zlib";
import { Checks, ROOT, launchBrowser, openEmulated, startServer } from "./webserver-harness.mjs";

const checks = new Checks();
const server = await startServer(["phantom:128"]);
const wasm = process.env.MEDISO_WEB_BINARY_DIR || path.join(ROOT, "build-web", "bin");
const STATIC = path.join(ROOT, "Web", "static");

// A GET with exactly these headers (node's http: nothing added, nothing inflated).
function get(url, headers) {
  return new Promise((resolve, reject) => {
    http.get(url, { headers }, (response) => {
      const chunks = [];
      response.on("data", (c) => chunks.push(c));
      response.on("end", () => resolve({ status: response.statusCode, headers: response.headers,
        body: Buffer.concat(chunks) }));
    }).on("error", reject);
  });
}

// ---------------------------------------------------------------- the files, gzip'd
for (const [name, file, kind] of [["/", path.join(STATIC, "index.html"), "text/html"],
  ["/static/app.js", path.join(STATIC, "app.js"), "text/javascript"],
  ["/static/style.css", path.join(STATIC, "style.css"), "text/css"],
  ["/static/mediso.js", path.join(wasm, "mediso.js"), "text/javascript"],
  ["/static/mediso.wasm", path.join(wasm, "mediso.wasm"), "application/wasm"]]) {
  const disk = readFileSync(file);
  const r = await get(server.api(name), { "Accept-Encoding": "gzip, deflate" });
  let inflated = null;
  try {
    inflated = zlib.gunzipSync(r.body);
  } catch { /* not gzip: said below */ }
  checks.check(r.status === 200 && r.headers["content-encoding"] === "gzip" &&
    (r.headers["content-type"] || "").startsWith(kind) && /accept-encoding/i.test(r.headers.vary || "") &&
    r.headers.etag && r.headers["last-modified"] && inflated && inflated.equals(disk),
  name + ": " + r.status + " " + r.headers["content-type"] + ", " + r.body.length + " bytes gzip'd (" +
    (r.body.length / disk.length).toFixed(2) + "x the file's " + disk.length + "), Content-Encoding " +
    r.headers["content-encoding"] + ", Vary " + r.headers.vary + ", ETag " + r.headers.etag +
    ", inflated " + (inflated && inflated.equals(disk) ? "equal to the file" : "NOT the file"));
  const again = await get(server.api(name), { "Accept-Encoding": "gzip", "If-None-Match": r.headers.etag || "x" });
  checks.check(again.status === 304 && again.body.length === 0,
    "... If-None-Match with its tag: " + again.status + ", " + again.body.length + " bytes");
  const plain = await get(server.api(name), {});
  checks.check(plain.status === 200 && !plain.headers["content-encoding"] && plain.body.equals(disk),
    "... without Accept-Encoding: " + plain.status + ", the file as it is (" + plain.body.length + " bytes)");
}
{
  const r = await get(server.api("/static/..%2fPython%2fserve.py"), { "Accept-Encoding": "gzip" });
  const s = await get(server.api("/static/render-worker.js"), { "Accept-Encoding": "gzip" });
  checks.check(r.status === 404 && s.status === 200 && s.headers["content-encoding"] === "gzip",
    "a path outside the folder: " + r.status + "; the worker's script: " + s.status + " gzip'd");
}

// ---------------------------------------------------------------- the preloads
const imported = new Set();
(function visit(name) {
  const text = readFileSync(path.join(STATIC, name), "utf8");
  for (const m of text.matchAll(/^\s*(?:import|export)\b[^;]*?\bfrom\s+"\.\/([^"]+)"/gms)) {
    if (!imported.has(m[1])) {
      imported.add(m[1]);
      visit(m[1]);
    }
  }
})("app.js");
const html = readFileSync(path.join(STATIC, "index.html"), "utf8");
const preloaded = new Set([...html.matchAll(/<link rel="modulepreload" href="static\/([^"]+)">/g)].map((m) => m[1]));
const missing = [...imported].filter((m) => !preloaded.has(m));
const extra = [...preloaded].filter((m) => !imported.has(m));
checks.check(imported.size > 10 && !missing.length && !extra.length,
  "index.html preloads the " + imported.size + " modules app.js imports" +
  (missing.length ? "; not: " + missing.join(", ") : "") + (extra.length ? "; not imported: " + extra.join(", ") : ""));

// ---------------------------------------------------------------- the page, throttled
const browser = await launchBrowser();
async function open(query) {
  const { page, requests } = await openEmulated(browser, server.url + "&path=cpu&size=400x300" + query, {
    viewport: { width: 900, height: 600 }, mbit: 30,
    watch: async (context, page, cdp) => {
      const requests = new Map();
      cdp.on("Network.requestWillBeSent", (e) => requests.set(e.requestId,
        { url: e.request.url.replace(/[?&]token=[^&]*/, ""), sent: e.timestamp }));
      cdp.on("Network.responseReceived", (e) => Object.assign(requests.get(e.requestId) || {},
        { encoding: e.response.headers["Content-Encoding"] || e.response.headers["content-encoding"] || "" }));
      cdp.on("Network.loadingFinished", (e) => Object.assign(requests.get(e.requestId) || {},
        { end: e.timestamp, bytes: e.encodedDataLength }));
      return { requests };
    } });
  const list = [...requests.values()];
  const find = (pattern) => list.filter((r) => pattern.test(r.url));
  return { page, list, find };
}

{
  const { page, list, find } = await open("");
  const stats = await page.evaluate(() => window.mediso.stats());
  const [app] = find(/\/static\/app\.js/);
  const modules = find(/\/static\/(?!app\.js|render-worker\.js|mediso)[^/?]+\.js/);
  const late = modules.filter((r) => !(r.sent < app.end));
  checks.check(app && modules.length === imported.size && late.length === 0,
    modules.length + " modules asked for before app.js had arrived" +
    (late.length ? "; not: " + late.map((r) => r.url.replace(/.*\//, "")).join(", ") : ""));
  const [worker] = find(/\/static\/render-worker\.js/);
  const [wasmFile] = find(/\/static\/mediso\.wasm/);
  checks.check(worker && wasmFile && worker.sent < wasmFile.end,
    "the render worker's script asked for " + (worker && wasmFile ? Math.round(1000 * (wasmFile.end - worker.sent)) : "?") +
    " ms before this thread's module had arrived");
  // index.html starts the worker (its inline script runs before any module script can), and the
  // page takes it over: one request for its script. When that request goes out against app.js's
  // arrival is a race of the loopback and the load (it lost by 230-240 ms in two runs of four), so the
  // order is checked on the page's own marks, which are sequential.
  const workers = find(/\/static\/render-worker\.js/);
  const marks = await page.evaluate(() => ({
    created: performance.getEntriesByName("mediso:worker-created")[0]?.startTime,
    module: performance.getEntriesByName("mediso:module")[0]?.startTime,
    wasm: performance.getEntriesByName("mediso:worker-wasm")[0]?.startTime,
    imported: performance.getEntriesByName("mediso:worker-imported")[0]?.startTime }));
  checks.check(worker && marks.created !== undefined && marks.module !== undefined &&
    marks.created < marks.module && workers.length === 1,
    "the render worker started by index.html (at " + Math.round(marks.created) + " ms), before this thread's module ran (" +
    Math.round(marks.module) + " ms), and its script asked for once (" + workers.length + ")");
  // The worker's wasm asked for beside its module's script, not after it (the worker's clock).
  checks.check(marks.wasm !== undefined && marks.imported !== undefined && marks.wasm < marks.imported,
    "the worker's wasm asked for at " + Math.round(marks.wasm) + " ms, before its module's script had loaded (" +
    Math.round(marks.imported) + " ms)");
  // Level 0 and the manifest against the worker's readiness (the page's own clock).
  const timing = await page.evaluate(() => ({
    worker: performance.getEntriesByName("mediso:worker")[0]?.startTime,
    level0: performance.getEntriesByType("resource").find((e) => /\/api\/volume\/[^?]*\?level=0/.test(e.name))?.startTime,
    manifest: performance.getEntriesByType("resource").find((e) => /\/api\/bricks\/[^?]*\?level=\d&token/.test(e.name))?.startTime,
  }));
  checks.check(timing.worker > 0 && timing.level0 < timing.worker && timing.manifest < timing.worker,
    "level 0 and the bricks' manifest asked for at " + Math.round(timing.level0) + " and " +
    Math.round(timing.manifest) + " ms, before the worker was ready (" + Math.round(timing.worker) + " ms)");
  const [first] = await page.evaluate(() => window.mediso.frames());
  checks.check(stats.levels.length > 0 && first && first.coarse.length === stats.levels.length &&
    first.coarse.every(Boolean) && first.triangles > 0,
    "the first image is level 0's (" + (first ? first.triangles + " triangles, from level 0: " +
    JSON.stringify(first.coarse) : "no frame") + ")");
  const scripts = find(/\/static\/[^/?]+\.(js|wasm)$/).filter((r) => r.bytes > 0);
  const plain = scripts.filter((r) => r.encoding !== "gzip");
  checks.check(scripts.length >= imported.size + 3 && !plain.length,
    scripts.length + " scripts and modules crossed gzip'd, " + scripts.reduce((a, r) => a + r.bytes, 0) +
    " bytes" + (plain.length ? "; not: " + plain.map((r) => r.url).join(", ") : ""));
  const full = await page.evaluate(() => window.mediso.whenFull());
  checks.check(full.levels.every((l) => l === 3),
    "then every surface at the full level (" + JSON.stringify(full.levels) + ")");
  const volumes = list.filter((r) => /\/api\/volume\//.test(r.url));
  checks.check(volumes.length === 1, "the volume's level 0 asked for once (" + volumes.length + ")");
  await page.context().close();
}
{
  const { page, list } = await open("&stream=0");
  const stats = await page.evaluate(() => window.mediso.stats());
  const volumes = list.filter((r) => /\/api\/volume\//.test(r.url)).map((r) => r.url.replace(/.*\?/, ""));
  const manifests = list.filter((r) => /\/api\/bricks\//.test(r.url));
  checks.check(volumes.length === 1 && volumes[0] === "level=3" && !manifests.length && stats.received === 1,
    "?stream=0: the volume asked for once (" + volumes.join(", ") + "), no manifest (" + manifests.length +
    "), nothing ahead");
  await page.context().close();
}
{
  // The viewer on this thread: index.html starts no worker.
  const { page, find } = await open("&worker=0&threads=0");
  const stats = await page.evaluate(() => window.mediso.stats());
  const workers = find(/\/static\/render-worker\.js/);
  checks.check(stats.renderer === "main" && workers.length === 0,
    "?worker=0: drawn on the main thread (" + stats.renderer + "), no render worker asked for (" +
    workers.length + ")");
  await page.context().close();
}
await checks.finish(browser, server);
