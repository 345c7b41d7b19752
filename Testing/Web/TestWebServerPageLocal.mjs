// SPDX-License-Identifier: BSD-3-Clause
// Local files in the page (issue 32, point 5), in Chromium: the same volume written by this test
// as a NIfTI (.nii and .nii.gz: int16 with scl_inter -1000, so calibrated to int32, its sform
// turned 90 degrees about z) and as a MetaImage (.mha, and .mhd with its .raw: a TransformMatrix
// and an Offset), each served by Python/serve.py and then picked in the page's file box
// (setInputFiles) or dropped on the page. Checked:
// - the local volume's facts (dims, spacing, origin, direction, type, range, format) are the
//   served volume's (numbers within 1e-5 relative), and its anterior view the same;
// - the CPU path's triangles at level 3 and at the estimator's level, and the GPU path's
//   primitives, for the same isovalues, equal the served volume's;
// - opening it sent and received nothing (the page's byte counters unchanged);
// - a truncated NIfTI, a NIfTI with a bad sizeof_hdr, a file of another kind and a NIfTI over a
//   memory budget of 0.1 MB are refused with
//   one visible message (#local-note) and the volume shown stays (its facts and triangles);
// - a server operation on the local MetaImage uploads it once (one POST /api/upload, the page saying
//   how many bytes before and after) and gives the triangles the same operation gives on the
//   served volume; a second operation uploads nothing.
// - a DICOM folder written by this test (the same values as int16 slices with Rescale Intercept
//   -1000, on a plane turned 90 degrees about z, file names in reverse position order), served
//   (vtkMedicalDICOMSeriesReader), picked in the page's folder box (setInputFiles on the
//   webkitdirectory input) and dropped (Chromium's drag of the folder's path through CDP's
//   Input.dispatchDragEvent): the same facts, view, triangles and primitives, nothing sent; a copy
//   of it with one file in the RLE transfer syntax refused by name, the volume shown kept.
import { mkdirSync, mkdtempSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import path from "node:path";
import { gzipSync } from "node:zlib";
import { Checks, launchBrowser, niftiBytes, openPage, startServer } from "./webserver-harness.mjs";

const checks = new Checks();
const folder = mkdtempSync(path.join(tmpdir(), "mediso-local-"));
const [NX, NY, NZ] = [40, 36, 30];

// int16 values: a gradient and an ellipsoid of 1500 off the centre, so that a surface is not
// symmetric in any axis.
function values() {
  const data = Buffer.alloc(2 * NX * NY * NZ);
  for (let k = 0; k < NZ; ++k) {
    for (let j = 0; j < NY; ++j) {
      for (let i = 0; i < NX; ++i) {
        const e = ((i - 24) / 10) ** 2 + ((j - 15) / 8) ** 2 + ((k - 13) / 9) ** 2;
        data.writeInt16LE((e <= 1 ? 1500 : 0) + 7 * i + 3 * j - 5 * k, 2 * (i + NX * (j + NY * k)));
      }
    }
  }
  return data;
}

// The volume as a NIfTI, scl_inter -1000 (int16 - 1000 needs int32); `sizeOfHeader` other than
// 348 for the refused file.
function nifti({ sizeOfHeader = 348 } = {}) {
  return niftiBytes([NX, NY, NZ], [0.8, 0.9, 1.25], [[0, -0.9, 0, 12], [0.8, 0, 0, -30], [0, 0, 1.25, 5]],
    values(), { intercept: -1000, sizeOfHeader });
}

function metaHeader(dataFile) {
  return ["ObjectType = Image", "NDims = 3", "BinaryData = True", "BinaryDataByteOrderMSB = False",
    "CompressedData = False", "TransformMatrix = 0 -1 0 1 0 0 0 0 1", "Offset = 10 -20 30",
    "ElementSpacing = 0.8 0.9 1.25", "DimSize = " + [NX, NY, NZ].join(" "), "ElementType = MET_SHORT",
    "ElementDataFile = " + dataFile, ""].join("\n");
}

const files = {
  nii: path.join(folder, "volume.nii"),
  niigz: path.join(folder, "volume-gz.nii.gz"),
  mha: path.join(folder, "volume.mha"),
  mhd: path.join(folder, "volume-pair.mhd"),
  raw: path.join(folder, "volume-pair.raw"),
  truncated: path.join(folder, "truncated.nii"),
  badHeader: path.join(folder, "bad-header.nii"),
  other: path.join(folder, "notes.txt"),
};
writeFileSync(files.nii, nifti());
writeFileSync(files.niigz, gzipSync(nifti()));
writeFileSync(files.mha, Buffer.concat([Buffer.from(metaHeader("LOCAL")), values()]));
writeFileSync(files.mhd, metaHeader("volume-pair.raw"));
writeFileSync(files.raw, values());
writeFileSync(files.truncated, nifti().subarray(0, 352 + 1000));
writeFileSync(files.badHeader, nifti({ sizeOfHeader: 123 }));
writeFileSync(files.other, "not a volume\n");

// A DICOM Part 10 file, explicit VR little endian: slice k of values(), signed 16-bit, Rescale
// Intercept -1000, rows along y, columns along -x (a plane turned 90 degrees about z).
function dicomSlice(k, syntax = "1.2.840.10008.1.2.1") {
  const element = (group, number, vr, value) => {
    let bytes = Buffer.isBuffer(value) ? value : Buffer.from(value, "latin1");
    if (bytes.length % 2) {
      bytes = Buffer.concat([bytes, Buffer.from(vr === "UI" ? "\0" : " ", "latin1")]);
    }
    const long = ["OB", "OW", "SQ", "UN", "UT"].includes(vr);
    const head = Buffer.alloc(long ? 12 : 8);
    head.writeUInt16LE(group, 0);
    head.writeUInt16LE(number, 2);
    head.write(vr, 4, "latin1");
    if (long) {
      head.writeUInt32LE(bytes.length, 8);
    } else {
      head.writeUInt16LE(bytes.length, 6);
    }
    return Buffer.concat([head, bytes]);
  };
  const us = (v) => { const b = Buffer.alloc(2); b.writeUInt16LE(v, 0); return b; };
  const instance = "2.25.4242" + String(k + 1).padStart(3, "0");
  const meta = Buffer.concat([element(2, 1, "OB", Buffer.from([0, 1])),
    element(2, 2, "UI", "1.2.840.10008.5.1.4.1.1.2"), element(2, 3, "UI", instance),
    element(2, 0x10, "UI", syntax), element(2, 0x12, "UI", "2.25.4242")]);
  const length = Buffer.alloc(4);
  length.writeUInt32LE(meta.length, 0);
  const all = values();
  const slice = all.subarray(2 * NX * NY * k, 2 * NX * NY * (k + 1));
  const data = Buffer.concat([element(8, 0x16, "UI", "1.2.840.10008.5.1.4.1.1.2"),
    element(8, 0x18, "UI", instance), element(8, 0x60, "CS", "CT"),
    element(0x10, 0x10, "PN", "Local^Test"), element(0x18, 0x50, "DS", "1.25"),
    element(0x20, 0x0d, "UI", "2.25.4241"), element(0x20, 0x0e, "UI", "2.25.4240"),
    element(0x20, 0x13, "IS", String(k + 1)), element(0x20, 0x32, "DS", [10, -20, 30 + 1.25 * k].join("\\")),
    element(0x20, 0x37, "DS", "0\\1\\0\\-1\\0\\0"), element(0x28, 2, "US", us(1)),
    element(0x28, 4, "CS", "MONOCHROME2"), element(0x28, 0x10, "US", us(NY)),
    element(0x28, 0x11, "US", us(NX)), element(0x28, 0x30, "DS", "0.9\\0.8"),
    element(0x28, 0x100, "US", us(16)), element(0x28, 0x101, "US", us(16)),
    element(0x28, 0x102, "US", us(15)), element(0x28, 0x103, "US", us(1)),
    element(0x28, 0x1052, "DS", "-1000"), element(0x28, 0x1053, "DS", "1"),
    element(0x7fe0, 0x10, "OW", Buffer.from(slice))]);
  return Buffer.concat([Buffer.alloc(128), Buffer.from("DICM", "latin1"),
    element(2, 0, "UL", length), meta, data]);
}

const dicom = path.join(folder, "dicom-series");
const dicomRLE = path.join(folder, "dicom-rle");
mkdirSync(dicom);
mkdirSync(dicomRLE);
for (let k = 0; k < NZ; ++k) {
  const name = "img_" + String(NZ - 1 - k).padStart(3, "0") + ".dcm"; // reverse position order
  writeFileSync(path.join(dicom, name), dicomSlice(k));
  writeFileSync(path.join(dicomRLE, name), dicomSlice(k, k === 3 ? "1.2.840.10008.1.2.5" : undefined));
}

const near = (a, b) => Math.abs(a - b) <= 1e-5 * Math.max(1, Math.abs(b));
const same = (a, b) => Array.isArray(a) ? a.length === b.length && a.every((x, i) => near(x, b[i])) : a === b;
const ISOVALUES = { nii: [-500, 200], mha: [500, 1200] };

// What the page shows: the dataset's facts, the view, and the surfaces' counts on both paths.
async function measure(page, isovalues) {
  const d = await page.evaluate(() => window.mediso.dataset());
  const view = (await page.evaluate(() => window.mediso.getView())).world;
  await page.evaluate(() => window.mediso.setPath("cpu"));
  await page.evaluate((v) => window.mediso.setIsovalues(v), isovalues);
  const full = (await page.evaluate(() => window.mediso.setCPULevel(3))).triangles;
  const estimated = (await page.evaluate(() => window.mediso.setCPULevel(-1))).triangles;
  await page.evaluate(() => window.mediso.setPath("gpu"));
  const primitives = (await page.evaluate(() => window.mediso.drawn())).primitives;
  await page.evaluate(() => window.mediso.setPath("auto"));
  return { d, view, full, estimated, primitives };
}

function compare(label, served, local) {
  for (const key of ["dims", "spacing", "origin", "direction", "type", "range"]) {
    checks.check(same(local.d[key], served.d[key]), label + ": " + key + " " + JSON.stringify(local.d[key]) +
      " as served " + JSON.stringify(served.d[key]));
  }
  checks.check(local.d.format.name === served.d.format.name && local.d.format.space === served.d.format.space,
    label + ": format " + JSON.stringify(local.d.format) + " as served " + JSON.stringify(served.d.format));
  checks.check(local.d.local && !served.d.local, label + ": the page says it is local");
  checks.check(["direction", "viewUp"].every((k) => same(local.view[k], served.view[k])),
    label + ": the same anterior view " + JSON.stringify(local.view.direction));
  checks.check(local.full > 100 && local.full === served.full && local.estimated === served.estimated,
    label + ": CPU triangles " + local.full + " (level 3), " + local.estimated + " (estimator) as served " +
    served.full + ", " + served.estimated);
  checks.check(local.primitives > 0 && local.primitives === served.primitives,
    label + ": GPU primitives " + local.primitives + " as served " + served.primitives);
}

// Opens `paths` through the file box (or by a drop when `drop`) and waits for the page's note.
async function openLocal(page, paths, drop = false) {
  await page.evaluate(() => { document.getElementById("local-note").textContent = ""; });
  if (drop) {
    const { readFileSync } = await import("node:fs");
    const list = paths.map((p) => ({ name: path.basename(p), bytes: [...readFileSync(p)] }));
    await page.evaluate((list) => {
      const transfer = new DataTransfer();
      for (const f of list) {
        transfer.items.add(new File([new Uint8Array(f.bytes)], f.name));
      }
      document.getElementById("panel").dispatchEvent(
        new DragEvent("drop", { dataTransfer: transfer, bubbles: true, cancelable: true }));
    }, list);
  } else {
    await page.setInputFiles("#local-file", paths);
  }
  await page.waitForFunction(() => /^(Opened|Not opened)/.test(document.getElementById("local-note").textContent),
    null, { timeout: 60000 });
  await page.evaluate(() => window.mediso.drawn());
  return page.evaluate(() => document.getElementById("local-note").textContent);
}

// The "On the server" panel: surface 0 at level 3, no steps; the result's triangles.
async function runOperation(page) {
  await page.selectOption("#op-surface", "0");
  await page.selectOption("#op-level", "3");
  for (const step of ["#op-smooth", "#op-fill", "#op-clip", "#op-decimate"]) {
    await page.setChecked(step, false);
  }
  await page.evaluate(() => { window.shownResults = performance.getEntriesByType("resource").filter((e) =>
    e.name.includes("/api/result/") && e.name.includes("format=ply")).length; });
  await page.click("#op-run");
  await page.waitForFunction(() => ["done", "error"].includes(
    document.getElementById("op-run").closest("section").dataset.state), null, { timeout: 180000 });
  // The result's PLY, which the panel fetches to show it, has arrived (its bytes are counted).
  await page.waitForFunction(() => performance.getEntriesByType("resource").filter((e) =>
    e.name.includes("/api/result/") && e.name.includes("format=ply")).length >= window.shownResults + 1,
  null, { timeout: 60000 }).catch(() => {});
  await page.waitForTimeout(300);
  const summary = await page.textContent("#op-result");
  const triangles = /([\d,]+) triangles/.exec(summary);
  return { summary, triangles: triangles ? Number(triangles[1].replace(/,/g, "")) : -1 };
}

const niftiServer = await startServer([files.nii]);
const metaServer = await startServer([files.mha]);
const browser = await launchBrowser();

for (const [server, kind, locals] of [
  [niftiServer, "nii", [[[files.nii], false], [[files.niigz], true]]],
  [metaServer, "mha", [[[files.mha], true], [[files.mhd, files.raw], false]]]]) {
  const context = await browser.newContext({ viewport: { width: 1400, height: 900 } });
  const page = await context.newPage();
  await openPage(page, server);
  const served = await measure(page, ISOVALUES[kind]);
  const servedOperation = kind === "mha" ? await runOperation(page) : null;
  if (servedOperation) {
    checks.check(servedOperation.triangles > 0, "an operation on the served volume: " + servedOperation.summary.slice(0, 120));
  }
  const uploads = [];
  page.on("request", (r) => { if (r.url().includes("/api/upload")) { uploads.push(r.url()); } });
  for (const [paths, drop] of locals) {
    const label = paths.map((p) => path.basename(p)).join(" + ") + (drop ? " (dropped)" : " (picked)");
    const before = await page.evaluate(() => window.mediso.stats());
    const note = await openLocal(page, paths, drop);
    const after = await page.evaluate(() => window.mediso.stats());
    checks.check(/^Opened/.test(note), label + ": " + note);
    checks.check(after.bytesSent === before.bytesSent && after.bytesReceived === before.bytesReceived,
      label + ": nothing sent or received (" + (after.bytesSent - before.bytesSent) + " and " +
      (after.bytesReceived - before.bytesReceived) + " bytes)");
    compare(label, served, await measure(page, ISOVALUES[kind]));
  }

  // Bad files: one message, the volume shown stays.
  if (kind === "nii") {
    const kept = await measure(page, ISOVALUES[kind]);
    for (const [paths, expected] of [[[files.truncated], /holds only 1352 bytes/],
      [[files.badHeader], /sizeof_hdr, is 123/], [[files.other], /open anything else .*through the server/],
      [[files.nii], /over the page's memory budget of 0.1 MB/]]) {
      // The last: a good file over a budget of 0.1 MB (the box's value, read at each file).
      await page.fill("#budget", expected.source.includes("budget") ? "0.1" : "1024");
      const note = await openLocal(page, paths);
      await page.fill("#budget", "1024"); // the view measured at the budget it was shown with
      const now = await measure(page, ISOVALUES[kind]);
      checks.check(/^Not opened: /.test(note) && expected.test(note) && /The volume shown stays/.test(note),
        path.basename(paths[0]) + ": refused with " + JSON.stringify(note));
      checks.check(await page.evaluate(() => document.getElementById("local-note").classList.contains("error")),
        path.basename(paths[0]) + ": the message is shown as an error");
      checks.check(JSON.stringify(now.d) === JSON.stringify(kept.d) && now.full === kept.full,
        path.basename(paths[0]) + ": the volume shown stays (" + now.d.name + ", " + now.full + " triangles)");
    }
  }

  // A server operation on the local volume (the .mhd pair): uploaded once. (A served NIfTI with
  // a turned sform is not used here: its operations are refused for its direction matrix.)
  if (kind === "mha") {
    await page.evaluate((v) => window.mediso.setIsovalues(v), ISOVALUES[kind]);
    const first = await runOperation(page);
    const note = await page.textContent("#local-note");
    const uploaded = (await page.evaluate(() => window.mediso.dataset())).uploaded;
    checks.check(first.triangles > 0 && first.triangles === servedOperation.triangles,
      "an operation on the local volume: " + first.triangles + " triangles, as on the served one (" +
      servedOperation.triangles + "): " + first.summary.slice(0, 120));
    checks.check(uploads.length === 1 && uploaded && uploaded.raw === NX * NY * NZ * 2 && uploaded.sent > 0 &&
      uploaded.sent < uploaded.raw, "uploaded once: " + uploads.length + " upload(s), " + JSON.stringify(uploaded));
    checks.check(/^Uploaded .* once/.test(note) && note.includes(String(uploaded && uploaded.raw)) &&
      note.includes(String(uploaded && uploaded.sent)), "the page says so: " + note);
    const second = await runOperation(page);
    checks.check(second.triangles === first.triangles && uploads.length === 1,
      "a second operation uploads nothing (" + uploads.length + " upload(s), " + second.triangles + " triangles)");
  }
  await context.close();
}

// A DICOM folder: served (the server's reader) and picked in the page's folder box.
async function openFolder(page, dir) {
  await page.evaluate(() => { document.getElementById("local-note").textContent = ""; });
  await page.setInputFiles("#local-folder", dir);
  await page.waitForFunction(() => /^(Opened|Not opened)/.test(document.getElementById("local-note").textContent),
    null, { timeout: 60000 });
  await page.evaluate(() => window.mediso.drawn());
  return page.evaluate(() => document.getElementById("local-note").textContent);
}
const dicomServer = await startServer([dicom]);
{
  const context = await browser.newContext({ viewport: { width: 1400, height: 900 } });
  const page = await context.newPage();
  await openPage(page, dicomServer);
  const iso = ISOVALUES.nii;
  const served = await measure(page, iso);
  checks.check(served.d.format.name === "DICOM", "the served DICOM folder: " + JSON.stringify(served.d.format));
  const before = await page.evaluate(() => window.mediso.stats());
  const note = await openFolder(page, dicom);
  const after = await page.evaluate(() => window.mediso.stats());
  checks.check(/^Opened/.test(note), "the DICOM folder (picked): " + note);
  checks.check(after.bytesSent === before.bytesSent && after.bytesReceived === before.bytesReceived,
    "the DICOM folder: nothing sent or received (" + (after.bytesSent - before.bytesSent) + " and " +
    (after.bytesReceived - before.bytesReceived) + " bytes)");
  const local = await measure(page, iso);
  compare("the DICOM folder (picked)", served, local);
  // Dropped: Chromium's own drag of the folder's path (CDP), as a drop from the desktop.
  {
    await page.evaluate(() => { document.getElementById("local-note").textContent = ""; });
    const cdp = await context.newCDPSession(page);
    const data = { items: [], files: [dicom], dragOperationsMask: 1 };
    for (const type of ["dragEnter", "dragOver", "drop"]) {
      await cdp.send("Input.dispatchDragEvent", { type, x: 1200, y: 600, data });
    }
    await page.waitForFunction(() => /^(Opened|Not opened)/.test(document.getElementById("local-note").textContent),
      null, { timeout: 60000 });
    await page.evaluate(() => window.mediso.drawn());
    const dropNote = await page.evaluate(() => document.getElementById("local-note").textContent);
    checks.check(/^Opened dicom-series/.test(dropNote), "the DICOM folder (dropped): " + dropNote);
    compare("the DICOM folder (dropped)", served, await measure(page, iso));
  }
  const refused = await openFolder(page, dicomRLE);
  const now = await measure(page, iso);
  checks.check(/^Not opened: /.test(refused) && /"RLE Lossless" \(1\.2\.840\.10008\.1\.2\.5\) is not read in the page/.test(refused) &&
    /The volume shown stays/.test(refused), "the DICOM folder with an RLE file: refused with " + JSON.stringify(refused));
  checks.check(JSON.stringify(now.d) === JSON.stringify(local.d) && now.full === local.full,
    "the DICOM folder with an RLE file: the volume shown stays (" + now.d.name + ", " + now.full + " triangles)");
  await context.close();
}

await checks.finish(browser, niftiServer, metaServer, dicomServer);
