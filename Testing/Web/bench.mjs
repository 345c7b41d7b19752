// SPDX-License-Identifier: BSD-3-Clause
// The web benchmark's browser side (Python/benchmark_web.py runs it): in one Chromium, the page's
// GPU path, its CPU path (BlockLOD level 3) and vtk.js (vtkImageMarchingCubes + its renderer) on
// the same volume and canvas size take the same isovalues in turn; each change is timed from the
// call to the finished frame.
//   node bench.mjs CONFIG.json OUT.json
// CONFIG: {pageUrl, vtkjsUrl, volume: {url, dims, spacing, origin, type}, size: [w, h], isovalues}
import { launch } from "./page.mjs";
import { readFileSync, writeFileSync } from "node:fs";

const [configFile, outFile] = process.argv.slice(2);
const config = JSON.parse(readFileSync(configFile, "utf8"));
const browser = await launch();
const result = { methods: {} };

async function openPage(name, url) {
  const page = await browser.newPage({ viewport: { width: 1600, height: 1000 } });
  page.on("pageerror", (e) => console.log(name + " pageerror: " + e.message));
  const start = Date.now();
  await page.goto(url, { waitUntil: "commit" });
  return { page, start };
}

const size = config.size.join("x");
const ours = {};
for (const path of ["gpu", "cpu"]) {
  const { page, start } = await openPage(path, config.pageUrl + "&size=" + size + "&path=" + path);
  await page.waitForFunction(() => window.mediso, null, { timeout: 300000 });
  await page.evaluate(() => window.mediso.ready);
  const firstImageMs = Date.now() - start;
  if (path === "cpu") {
    await page.evaluate(() => window.mediso.setCPULevel(3));
  }
  const stats = await page.evaluate(() => window.mediso.stats());
  ours[path] = page;
  result.methods[path] = { firstImageMs, bytesReceived: stats.bytesReceived, bytesSent: stats.bytesSent,
    changes: [], reason: stats.reason, threads: stats.threads };
}
const { page: vtkjs, start: vtkStart } = await openPage("vtkjs", config.vtkjsUrl);
await vtkjs.waitForFunction(() => window.vtkBench, null, { timeout: 120000 });
const loaded = await vtkjs.evaluate((c) => window.vtkBench.load(c), { ...config.volume, size: config.size });
const first = await vtkjs.evaluate((v) => window.vtkBench.change(v, true), config.isovalues[0]);
result.methods.vtkjs = { firstImageMs: Date.now() - vtkStart, loadMs: loaded.loadMs, changes: [] };

const runners = {
  gpu: async (v) => {
    const s = await ours.gpu.evaluate((v) => window.mediso.setIsovalues([v]), v);
    // where the time goes: the pyramid's build (its total read back) within the change, and a
    // frame of the same surface with no build (the drawing alone)
    const redraw = await ours.gpu.evaluate(async () => {
      await window.mediso.setView(window.mediso.getView());
      return window.mediso.stats();
    });
    return { ms: s.lastChangeMs, buildMs: s.buildMs, drawMs: redraw.lastFrameMs, primitives: s.primitives };
  },
  cpu: async (v) => {
    const s = await ours.cpu.evaluate((v) => window.mediso.setIsovalues([v]), v);
    // the same split: the extraction and upload of the triangles, and a frame of them alone
    const redraw = await ours.cpu.evaluate(async () => {
      await window.mediso.setView(window.mediso.getView());
      return window.mediso.stats();
    });
    return { ms: s.lastChangeMs, buildMs: s.buildMs, drawMs: redraw.lastFrameMs, triangles: s.triangles };
  },
  vtkjs: async (v) => {
    const r = await vtkjs.evaluate((v) => window.vtkBench.change(v), v);
    return { ...r, drawMs: await vtkjs.evaluate(() => window.vtkBench.redraw()) };
  },
};
const names = Object.keys(runners);
result.isovalues = config.isovalues;
for (let i = 0; i < config.isovalues.length; ++i) {
  for (let k = 0; k < names.length; ++k) {
    const name = names[(i + k) % names.length]; // the order turns every step
    const r = await runners[name](config.isovalues[i]);
    result.methods[name].changes.push({ isovalue: config.isovalues[i], ...r });
    process.stdout.write(".");
  }
}
process.stdout.write("\n");
for (const name of ["gpu", "cpu"]) {
  result.methods[name].bytesSentAfter = (await ours[name].evaluate(() => window.mediso.stats())).bytesSent;
  result.methods[name].bytesReceivedAfter = (await ours[name].evaluate(() => window.mediso.stats())).bytesReceived;
}
result.vtkjsFirst = first;
writeFileSync(outFile, JSON.stringify(result, null, 1));
await browser.close();
