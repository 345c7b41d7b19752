// SPDX-License-Identifier: BSD-3-Clause
// What the web server's browser tests share: Python/serve.py started on a free port, Debian's
// chromium (headless, SwiftShader's WebGL2) driven by playwright-core, the page opened and
// ready, the bytes on the wire counted by Chrome's own network events (CDP), checks that print
// ok/FAILED and end the test. Run through Testing/Scripts/web-test.sh (npm ci first).
import { spawn } from "node:child_process";
import { existsSync, writeFileSync } from "node:fs";
import net from "node:net";
import path from "node:path";
import { fileURLToPath } from "node:url";

export const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "..", "..");

export function skip(reason) {
  console.log("SKIP: " + reason);
  process.exit(125);
}

function freePort() {
  return new Promise((resolve, reject) => {
    const s = net.createServer();
    s.on("error", reject);
    s.listen(0, "127.0.0.1", () => {
      const { port } = s.address();
      s.close(() => resolve(port));
    });
  });
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

/** Python/serve.py in pvpython; `data`: its --data values (none: the server's default). */
export async function startServer(data = []) {
  const plugin = process.env.MEDISO_PLUGIN || "";
  if (!existsSync(plugin)) {
    skip("MEDISO_PLUGIN does not name the built plugin (" + plugin + ")");
  }
  const wasm = process.env.MEDISO_WEB_BINARY_DIR || path.join(ROOT, "build-web", "bin");
  if (!existsSync(path.join(wasm, "mediso.wasm"))) {
    skip("the page's WebAssembly module is not built in " + wasm + " (Scripts/build-web.sh)");
  }
  const port = await freePort();
  const token = "t" + Math.random().toString(36).slice(2, 12);
  const args = ["--no-mpi", path.join(ROOT, "Python", "serve.py"), "--plugin", plugin,
    "--wasm", wasm, `--token=${token}`, "--port", String(port),
    ...data.flatMap((d) => ["--data", d])];
  const child = spawn(process.env.MEDISO_PVPYTHON || "pvpython", args,
    { stdio: ["ignore", "pipe", "pipe"] });
  const lines = [];
  const collect = (chunk) => lines.push(chunk.toString());
  child.stdout.on("data", collect);
  child.stderr.on("data", collect);
  let exitCode = null;
  process.on("exit", () => { // whatever ends the test, the server goes with it
    if (exitCode === null) {
      child.kill("SIGTERM");
    }
  });
  const exited = new Promise((resolve) => child.on("exit", (code, signal) => {
    exitCode = code ?? signal;
    resolve();
  }));
  const base = "http://127.0.0.1:" + port;
  const server = {
    base, token, lines, url: base + "/?token=" + token,
    api: (p) => base + p + (p.includes("?") ? "&" : "?") + "token=" + token,
    alive: () => exitCode === null,
    get exitCode() { return exitCode; },
    async stop() {
      if (exitCode === null) {
        child.kill("SIGTERM");
        await Promise.race([exited, sleep(30000)]);
        if (exitCode === null) {
          child.kill("SIGKILL");
          await exited;
        }
      }
    },
  };
  const deadline = Date.now() + 180000;
  while (Date.now() < deadline && exitCode === null) {
    try {
      const status = await (await fetch(server.api("/api/status"))).json();
      if (status.worker.pid) {
        return server;
      }
    } catch { /* not listening yet */ }
    await sleep(200);
  }
  console.log(lines.join(""));
  await server.stop();
  throw new Error("FAILED: the server did not start (exit " + exitCode + ")");
}

/** Debian's chromium as the page's own tests launch it (page.mjs). */
export async function launchBrowser() {
  let page;
  try {
    page = await import("./page.mjs");
  } catch (error) {
    skip("playwright-core is not installed in Testing/Web (npm ci): " + error.message);
  }
  return page.launch();
}

/**
 * Everything the page sends and receives, from Chrome's network events: HTTP requests (their
 * encoded bytes as loaded, headers included) and WebSocket handshakes and frames.
 */
export async function countWire(context, page) {
  const cdp = await context.newCDPSession(page);
  const wire = { events: 0, requests: [], received: 0, framesSent: 0, framesReceived: 0,
    frameBytesSent: 0, frameBytesReceived: 0, responses: new Map() };
  cdp.on("Network.requestWillBeSent", (e) => {
    wire.events++;
    wire.requests.push({ id: e.requestId, url: e.request.url });
  });
  cdp.on("Network.responseReceived", (e) => {
    wire.events++;
    wire.responses.set(e.requestId, { url: e.response.url, headers: e.response.headers,
      status: e.response.status });
  });
  cdp.on("Network.dataReceived", () => { wire.events++; });
  cdp.on("Network.loadingFinished", (e) => {
    wire.events++;
    wire.received += e.encodedDataLength;
    const r = wire.responses.get(e.requestId);
    if (r) {
      r.encodedDataLength = e.encodedDataLength;
    }
  });
  cdp.on("Network.webSocketCreated", () => { wire.events++; });
  cdp.on("Network.webSocketFrameSent", (e) => {
    wire.events++;
    wire.framesSent++;
    wire.frameBytesSent += Buffer.byteLength(e.response.payloadData);
  });
  cdp.on("Network.webSocketFrameReceived", (e) => {
    wire.events++;
    wire.framesReceived++;
    wire.frameBytesReceived += Buffer.byteLength(e.response.payloadData);
  });
  await cdp.send("Network.enable");
  return wire;
}

/** Opens the page and waits for its first frame (window.mediso.ready). */
export async function openPage(page, server, scriptsMs = 120000) {
  page.on("console", (m) => console.log("console." + m.type() + ": " + m.text()));
  page.on("pageerror", (e) => console.log("pageerror: " + e.message));
  await page.goto(server.url, { waitUntil: "commit" });
  await page.waitForFunction(() => window.mediso !== undefined, null, { timeout: scriptsMs });
  await page.evaluate(() => window.mediso.ready);
}

/**
 * Opens `url` in a new context of `viewport`, the link emulated at `mbit` Mbit/s and `latencyMs`
 * (CDP Network.emulateNetworkConditions; none where `mbit` is 0), and waits for the first image.
 * `watch(context, page, cdp)` installs the caller's own network records on the context before the
 * page is asked for; its result is returned with `context` and `page`.
 *
 * Under that emulation Chromium now and then never hands the page the answers to a wave of its
 * module requests, although the server wrote them (docs/web.md, "Page loads whose module requests
 * never complete"): the page's scripts never start. Such a page (no window.mediso after 60 s) is
 * opened again once, in a fresh context with fresh records, and the test's log says so; a page
 * whose scripts did start is never retried, so nothing the tests check is given a second chance.
 */
export async function openEmulated(browser, url, { viewport, mbit = 0, latencyMs = 40, watch = async () => ({}) }) {
  for (let attempt = 1; ; ++attempt) {
    const context = await browser.newContext({ viewport });
    const page = await context.newPage();
    const cdp = await context.newCDPSession(page);
    const watched = await watch(context, page, cdp);
    if (mbit) {
      await cdp.send("Network.enable");
      await cdp.send("Network.emulateNetworkConditions", { offline: false, latency: latencyMs,
        downloadThroughput: (mbit * 1e6) / 8, uploadThroughput: (mbit * 1e6) / 8 });
    }
    try {
      await openPage(page, { url }, mbit && attempt === 1 ? 60000 : 120000);
      return { context, page, ...watched };
    } catch (e) {
      const started = await page.evaluate(() => window.mediso !== undefined).catch(() => true);
      if (attempt > 1 || !mbit || started) {
        throw e;
      }
      console.log("the page's scripts did not start in 60 s under the emulated link (Chromium held its " +
        "module requests' answers: docs/web.md): opened again in a fresh context");
      await context.close();
    }
  }
}

/** A new browser context of `viewport` (CSS pixels) with the page at `url` opened and ready. */
export async function openInContext(browser, url, viewport = { width: 1000, height: 700 }) {
  const context = await browser.newContext({ viewport });
  const page = await context.newPage();
  await openPage(page, { url });
  return page;
}

/** The page's window.mediso.stats() and frames(). */
export const pageStats = (page) => page.evaluate(() => window.mediso.stats());
/** The `seq` of the page's newest frame (0 before any): framesAfter's mark. */
export const lastFrameSeq = (page) => page.evaluate(() => {
  const f = window.mediso.frames();
  return f.length ? f[f.length - 1].seq : 0;
});

/** The page's frames drawn after the one numbered `seq` (by number: the log keeps only the last 200). */
export const framesAfter = (page, seq) =>
  page.evaluate((n) => window.mediso.frames().filter((f) => f.seq > n), seq);

/**
 * Gives the page window.medisoTyping, for steps timed inside it: type(v) puts v in the first
 * surface's isovalue box as a person typing would (an "input" event); waitFor(test) resolves, with
 * performance.now(), once the newest of window.mediso.frames() passes `test` (polled every ms).
 */
export const installIsovalueTyping = (page) => page.evaluate(() => {
  const box = document.querySelector("#surfaces .isovalue");
  window.medisoTyping = {
    type: (v) => {
      box.value = String(v);
      box.dispatchEvent(new Event("input"));
    },
    waitFor: (test) => new Promise((resolve) => {
      const poll = setInterval(() => {
        const f = window.mediso.frames();
        if (f.length && test(f[f.length - 1])) {
          clearInterval(poll);
          resolve(performance.now());
        }
      }, 1);
    }),
  };
});

/**
 * The centroid of the pixels the surfaces cover (more than 30 off the corner's background, summed
 * over R, G and B), from the canvas's centre in its pixels (x right, y up), and how many.
 */
export const drawnCentroid = (page) => page.evaluate(() => {
  const view = document.getElementById("view");
  const copy = Object.assign(document.createElement("canvas"), { width: view.width, height: view.height });
  const g = copy.getContext("2d");
  g.drawImage(view, 0, 0);
  const pixels = g.getImageData(0, 0, view.width, view.height).data;
  const bg = [pixels[0], pixels[1], pixels[2]];
  let n = 0, sx = 0, sy = 0;
  for (let y = 0; y < view.height; ++y) {
    for (let x = 0; x < view.width; ++x) {
      const o = 4 * (x + view.width * y);
      if (Math.abs(pixels[o] - bg[0]) + Math.abs(pixels[o + 1] - bg[1]) + Math.abs(pixels[o + 2] - bg[2]) > 30) {
        ++n;
        sx += x;
        sy += y;
      }
    }
  }
  return { n, x: n ? sx / n - view.width / 2 : 0, y: n ? view.height / 2 - sy / n : 0 };
});

/**
 * The streaming tests' volume: n^3 int16 points of two blobs, a large one in the middle (1000 at
 * its centre, falling 10 a point) and a small one near the far corner (2000 at `corner` along each
 * axis, falling 20 a point), over 0, plus deterministic noise of `noise` levels (xorshift32); as a
 * NIfTI file at `file` (1 mm, identity axes). Returns the values written, i fastest.
 */
export function writeTwoBlobs(file, n, corner, noise) {
  const values = new Int16Array(n * n * n);
  const middle = n / 2;
  let seed = 2463534242;
  for (let k = 0, id = 0; k < n; ++k) {
    for (let j = 0; j < n; ++j) {
      for (let i = 0; i < n; ++i, ++id) {
        seed ^= seed << 13; seed ^= seed >>> 17; seed ^= seed << 5;
        const big = 1000 - 10 * Math.hypot(i - middle, j - middle, k - middle);
        const small = 2000 - 20 * Math.hypot(i - corner, j - corner, k - corner);
        values[id] = Math.round(Math.max(0, big, small)) + ((seed >>> 0) % noise);
      }
    }
  }
  writeFileSync(file, niftiBytes([n, n, n], [1, 1, 1], [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]], values));
  return values;
}

/**
 * The bytes of a NIfTI-1 file (.nii), in mm, with an sform of code 1 (scanner) and no qform:
 * `dims` [i, j, k], `spacing` its pixdim, `sform` the three rows (4 numbers each) of the
 * index-to-RAS matrix, `values` the i-fastest values: a Float32Array (float32), else int16 (an
 * Int16Array or their bytes); scl_slope 1 and `intercept`; `sizeOfHeader` other than 348 for a
 * file the page must refuse.
 */
export function niftiBytes(dims, spacing, sform, values, { intercept = 0, sizeOfHeader = 348 } = {}) {
  const header = Buffer.alloc(352);
  header.writeInt32LE(sizeOfHeader, 0);
  [3, ...dims, 1, 1, 1, 1].forEach((v, i) => header.writeInt16LE(v, 40 + 2 * i));
  const float = values instanceof Float32Array;
  header.writeInt16LE(float ? 16 : 4, 70); // DT_FLOAT32 or DT_INT16
  header.writeInt16LE(float ? 32 : 16, 72);
  [1, ...spacing, 1, 1, 1, 1].forEach((v, i) => header.writeFloatLE(v, 76 + 4 * i));
  header.writeFloatLE(352, 108); // vox_offset
  header.writeFloatLE(1, 112); // scl_slope
  header.writeFloatLE(intercept, 116); // scl_inter
  header.writeUInt8(10, 123); // xyzt_units: mm, s
  header.writeInt16LE(0, 252); // qform_code
  header.writeInt16LE(1, 254); // sform_code: scanner
  sform.forEach((row, r) => row.forEach((v, c) => header.writeFloatLE(v, 280 + 16 * r + 4 * c)));
  header.write("n+1\0", 344, "latin1");
  const data = Buffer.isBuffer(values) ? values : Buffer.from(values.buffer, values.byteOffset, values.byteLength);
  return Buffer.concat([header, data]);
}

export class Checks {
  constructor() {
    this.failures = 0;
  }

  check(ok, what) {
    console.log((ok ? "ok: " : "FAILED: ") + what);
    if (!ok) {
      this.failures++;
    }
    return ok;
  }

  async finish(browser, ...servers) {
    if (browser) {
      await browser.close();
    }
    for (const server of servers) {
      await server.stop();
      console.log("---- server output\n" + server.lines.join("").trimEnd());
      this.check(server.exitCode === 0, "the server ended cleanly (exit " + server.exitCode + ")");
    }
    console.log(this.failures + " failure(s)");
    process.exit(this.failures ? 1 : 0);
  }
}
