// SPDX-License-Identifier: BSD-3-Clause
// The abort of a running refinement, measured (docs/web.md, The worker; issue 30 point 3): in one
// Chromium (SwiftShader), the page with the worker, CPU path, frame budget 100 ms, on each volume
// given, with the abort (the generation word) and without it (?abort=0), in the same run:
// - changes awaited one by one: the first visible answer (the change to its first frame) and the
//   full level (to the refined frame);
// - superseded changes: a change, then 150 ms after its first frame (its refinement running) a
//   newer one; the newer one's first visible answer and full level, and the refinements aborted.
//   MEDISO_PLUGIN=build/lib/.../MedicalIsosurfaces.so node Testing/Web/bench-abort.mjs phantom:256 PATH.mha
// (arguments: serve.py --data values; prints a Markdown table).
import { installIsovalueTyping, launchBrowser, openPage, startServer } from "./webserver-harness.mjs";

const inputs = process.argv.slice(2);
const median = (a) => {
  const s = [...a].sort((x, y) => x - y);
  return s.length ? (s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2) : NaN;
};
const rows = [];
for (const input of inputs) {
  const server = await startServer([input]);
  const browser = await launchBrowser();
  for (const abort of [true, false]) {
    const context = await browser.newContext({ viewport: { width: 1220, height: 700 } });
    const page = await context.newPage();
    await openPage(page, { url: server.url + "&path=cpu&size=800x600" + (abort ? "" : "&abort=0") });
    await page.evaluate(() => window.mediso.setCPULevel(-1));
    // Bone-like isovalues of the phantom and the CT, none twice (no cache hits).
    const value = (i) => 300 + 10 * i;
    await page.evaluate((v) => window.mediso.setIsovalues([v]), value(0));
    const awaited = [];
    for (let i = 1; i <= 4; ++i) {
      const s = await page.evaluate((v) => window.mediso.setIsovalues([v]), value(i));
      awaited.push({ first: s.lastChangeMs, full: s.lastRefinedMs || s.lastChangeMs, level: s.cpuLevel });
    }
    const superseded = [];
    const aborted0 = (await page.evaluate(() => window.mediso.stats())).refinementsAborted;
    for (let i = 0; i < 4; ++i) {
      const [a, b] = [value(5 + 2 * i), value(6 + 2 * i)];
      await installIsovalueTyping(page);
      superseded.push(await page.evaluate(async ([a, b]) => {
        const { type, waitFor } = window.medisoTyping;
        type(a);
        await waitFor((f) => f.values[0] === a);
        await new Promise((resolve) => setTimeout(resolve, 150));
        const typed = performance.now();
        type(b);
        const first = await waitFor((f) => f.values[0] === b);
        const full = await waitFor((f) => f.values[0] === b && f.settled);
        return { first: first - typed, full: full - typed };
      }, [a, b]));
      await page.waitForTimeout(500);
    }
    const s = await page.evaluate(() => window.mediso.stats());
    rows.push({ input, abort, awaitedFirst: median(awaited.map((c) => c.first)),
      awaitedFull: median(awaited.map((c) => c.full)), level: awaited[awaited.length - 1].level,
      supersededFirst: median(superseded.map((c) => c.first)),
      supersededFirstMax: Math.max(...superseded.map((c) => c.first)),
      supersededFull: median(superseded.map((c) => c.full)),
      aborted: s.refinementsAborted - aborted0 });
    await context.close();
  }
  await browser.close();
  await server.stop();
}
console.log("| input | abort | change: first answer ms | change: full level ms (level) | " +
  "superseded: newer's first answer ms, median (max) | superseded: newer's full level ms | aborted of 4 |");
console.log("|---|---|---:|---:|---:|---:|---:|");
for (const r of rows) {
  const f = (x) => Math.round(x);
  console.log(`| ${r.input} | ${r.abort ? "on" : "off (?abort=0)"} | ${f(r.awaitedFirst)} | ${f(r.awaitedFull)} (${r.level}) | ` +
    `${f(r.supersededFirst)} (${f(r.supersededFirstMax)}) | ${f(r.supersededFull)} | ${r.aborted} |`);
}
process.exit(0);
