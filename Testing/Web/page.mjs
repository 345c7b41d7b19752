// SPDX-License-Identifier: BSD-3-Clause
// Drives the web client in Debian's Chromium (headless, software WebGL2) for the tests and the
// benchmark: opens URL, waits for window.mediso.ready (or the page's "unsupported" message),
// runs a list of window.mediso calls, and writes what happened as JSON.
//   node page.mjs URL OUT.json [--actions FILE.json] [--shot CANVAS.png] [--no-webgl]
// Actions: [{"call": "setSurfaces", "args": [[...]]}, {"call": "shot", "args": ["x.png"]}, ...];
// each call's result goes to "results". Chromium is /usr/bin/chromium (MEDISO_CHROMIUM
// overrides); playwright-core downloads no browser.
import { chromium } from "playwright-core";
import { readFileSync, writeFileSync } from "node:fs";

export const chromiumArgs = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
  "--disable-background-networking", "--disable-component-update", "--disable-sync",
  "--no-first-run", "--disable-features=Translate,MediaRouter"];

export async function launch({ webgl = true } = {}) {
  return chromium.launch({
    executablePath: process.env.MEDISO_CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: webgl ? chromiumArgs : [...chromiumArgs, "--disable-3d-apis"],
  });
}

// A mark of the page's frame log (window.mediso.frames()), for framesSince.
export const frameMark = (page) => page.evaluate(() => {
  const f = window.mediso.frames ? window.mediso.frames() : [];
  return { length: f.length, seq: f.length ? f[f.length - 1].seq : 0 };
});

// The frames drawn since `mark`: by `seq` where the page numbers them (its log keeps the last 200),
// else by position (a page from before that); null where the page has no frame log.
export const framesSince = (page, mark) => page.evaluate((n) => (window.mediso.frames
  ? window.mediso.frames().filter((f, i) => (f.seq === undefined ? i >= n.length : f.seq > n.seq))
  : null), mark);

// Still frames of the page's scene: the camera turned about its view-up by 2 degrees `count` times,
// each frame awaited at its full level; returns the still frames drawn (settled, not interactive).
export async function turnStills(page, count) {
  const mark = await frameMark(page);
  await page.evaluate(async (n) => {
    for (let i = 0; i < n; ++i) {
      const v = window.mediso.getView();
      const a = 2 * Math.PI / 180, f = v.focalPoint, u = v.viewUp;
      const d = [0, 1, 2].map((k) => v.position[k] - f[k]);
      const dot = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
      const cross = [u[1] * d[2] - u[2] * d[1], u[2] * d[0] - u[0] * d[2], u[0] * d[1] - u[1] * d[0]];
      const r = [0, 1, 2].map((k) => d[k] * Math.cos(a) + cross[k] * Math.sin(a) + u[k] * dot * (1 - Math.cos(a)));
      await window.mediso.setView({ position: [0, 1, 2].map((k) => f[k] + r[k]), focalPoint: f, viewUp: u,
        viewAngle: v.viewAngle, parallelScale: v.parallelScale });
    }
  }, count);
  return ((await framesSince(page, mark)) || []).filter((f) => !f.interactive && f.settled);
}

// Opens the page and waits until it has drawn its first frame or said why it cannot.
export async function open(browser, url, log = () => {}) {
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  page.on("console", (m) => log("console: " + m.text()));
  page.on("pageerror", (e) => log("pageerror: " + e.message));
  await page.goto(url, { waitUntil: "commit" });
  // At "commit" the document may not be parsed yet: a box not there yet is not a box shown (taken
  // as shown, the wait ended before app.js had set window.mediso, now and then on a loaded machine).
  await page.waitForFunction(() => {
    const box = document.getElementById("unsupported");
    return window.mediso || (box && !box.hidden);
  }, null, { timeout: 120000 });
  const state = await page.evaluate(() => window.mediso.ready.then(() => "ready", (e) => "failed: " + e.message));
  const unsupported = await page.evaluate(() => {
    const box = document.getElementById("unsupported");
    return box && !box.hidden ? box.textContent : "";
  });
  return { page, state, unsupported };
}

async function main() {
  const [url, out, ...rest] = process.argv.slice(2);
  const option = (name) => {
    const i = rest.indexOf(name);
    return i >= 0 ? rest[i + 1] : undefined;
  };
  const actions = option("--actions") ? JSON.parse(readFileSync(option("--actions"), "utf8")) : [];
  const browser = await launch({ webgl: !rest.includes("--no-webgl") });
  const logs = [];
  const started = Date.now();
  const { page, state, unsupported } = await open(browser, url, (line) => logs.push(line));
  const result = { state, unsupported, readyMs: Date.now() - started, results: [], logs };
  if (state === "ready") {
    for (const action of actions) {
      if (action.call === "shot") {
        await page.locator("#view").screenshot({ path: action.args[0] });
        result.results.push(action.args[0]);
        continue;
      }
      result.results.push(await page.evaluate(
        ([call, args]) => Promise.resolve(window.mediso[call](...args)), [action.call, action.args || []]));
    }
    result.stats = await page.evaluate(() => window.mediso.stats());
    if (option("--shot")) {
      await page.locator("#view").screenshot({ path: option("--shot") });
    }
  }
  writeFileSync(out, JSON.stringify(result, null, 1));
  await browser.close();
}

if (import.meta.url === "file://" + process.argv[1]) {
  main().catch((e) => {
    console.error(e);
    process.exit(1);
  });
}
