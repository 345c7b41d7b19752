// SPDX-License-Identifier: BSD-3-Clause
// Local files (docs/web.md, Local files): a NIfTI (.nii, .nii.gz) or a MetaImage (.mha, or .mhd
// with its data file) dropped on the page or picked with its file box opens in the page with no
// server round trip. The file is read by the WebAssembly module (Web/wasm/LocalVolume.cxx: the
// readers' VTK-free cores, the rules the server's readers use), after the browser has
// decompressed a .gz (DecompressionStream); the page then shows it as it shows a served volume:
// the dataset the module describes stands where /api/datasets' would, and its levels (every
// 2nd, 4th, 8th point, as the server samples them) are made here from the values.
// A DICOM folder (picked with the folder box, or dropped) goes the same way: its files (those
// directly in it, as the server's reader scans a folder) are read by the module's DICOM series
// core (Readers/Core/DICOMSeries.h), which reads uncompressed series as the server's reader does
// and refuses the rest (compressed, big endian, multi-frame) by name.

import { $, state } from "./state.js";
import { countBytes, sessionToken } from "./volume.js";

const VOLUME = /\.(nii|nii\.gz|mha|mhd)$/i;
const REFUSED_HERE = "The page reads a NIfTI (.nii, .nii.gz), a MetaImage (.mha, or .mhd with " +
  "its data file) or a DICOM folder (picked with the folder box, or dropped) itself; open anything " +
  "else through the server (Scripts/serve.sh --data)";

async function bytesOf(file) {
  if (/\.gz$/i.test(file.name)) {
    const stream = file.stream().pipeThrough(new DecompressionStream("gzip"));
    try {
      return new Uint8Array(await new Response(stream).arrayBuffer());
    } catch (error) {
      throw new Error(file.name + ": its gzip stream cannot be read (" + error.message + ")");
    }
  }
  return new Uint8Array(await file.arrayBuffer());
}

// Every `stride`-th point along each axis of a volume of `size`-byte values (the server's levels).
function sample(values, dims, stride, size) {
  const out = dims.map((n) => Math.ceil(n / stride));
  const bytes = new Uint8Array(out[0] * out[1] * out[2] * size);
  let o = 0;
  for (let k = 0; k < dims[2]; k += stride) {
    for (let j = 0; j < dims[1]; j += stride) {
      const row = (k * dims[1] + j) * dims[0];
      for (let i = 0; i < dims[0]; i += stride, o += size) {
        bytes.set(values.subarray((row + i) * size, (row + i + 1) * size), o);
      }
    }
  }
  return { dims: out, bytes };
}

// The dataset the page opens, in /api/datasets' words, with its levels made here.
function localDataset(name, read, values) {
  const { count, strides } = state.facts.levels;
  const size = state.facts.scalarTypes.get(read.type).bytes;
  const levels = strides.map((s) => {
    const dims = read.dims.map((n) => Math.ceil(n / s));
    return { dims, spacing: read.spacing.map((x) => x * s), bytes: dims[0] * dims[1] * dims[2] * size };
  });
  return {
    id: "local", name, dims: read.dims, spacing: read.spacing, origin: read.origin,
    direction: read.direction, type: read.type, range: read.range, bytes: read.bytes, levels,
    format: read.format, warnings: read.warnings,
    local: {
      values,
      level(k) {
        const { dims, bytes } = k === count - 1 ? { dims: read.dims, bytes: values } :
          sample(values, read.dims, strides[k], size);
        return { dims, spacing: levels[k].spacing, origin: read.origin, bytes };
      },
    },
  };
}

/**
 * Reads the files (a FileList or an array of File) with the module; the dataset, or an Error
 * with the reason. `budgetBytes`: the page's memory budget, which the volume must fit.
 */
export async function readLocalFiles(files, budgetBytes) {
  const list = [...files];
  const main = list.find((f) => VOLUME.test(f.name));
  if (!main) {
    throw new Error((list.map((f) => f.name).join(", ") || "nothing") + ": " + REFUSED_HERE + ".");
  }
  const M = state.module;
  const folder = "/local";
  if (!M.FS.analyzePath(folder).exists) {
    M.FS.mkdir(folder);
  }
  // A .mhd names its data file: the other files dropped with it go beside it.
  const needed = /\.mhd$/i.test(main.name) ? list : [main];
  const written = [];
  let read;
  try {
    for (const file of needed) {
      const bytes = await bytesOf(file);
      if (bytes.length > budgetBytes) {
        throw new Error(file.name + ": " + (bytes.length / 1e6).toFixed(1) + " MB is over the page's " +
          "memory budget of " + budgetBytes / 1e6 + " MB (raise the budget, or open it " +
          "through the server, which sends a coarser level).");
      }
      const path = folder + "/" + file.name.replace(/\.gz$/i, "");
      M.FS.writeFile(path, bytes);
      written.push(path);
    }
    read = M.readLocalVolume(folder + "/" + main.name.replace(/\.gz$/i, ""));
  } finally {
    for (const path of written) {
      M.FS.unlink(path);
    }
  }
  if (read.error) {
    throw new Error(main.name + ": " + read.error + ".");
  }
  if (read.bytes > budgetBytes) { // calibrated values may be wider than the file's
    M._free(read.pointer);
    throw new Error(main.name + ": its " + read.type + " values take " + (read.bytes / 1e6).toFixed(1) +
      " MB, over the page's memory budget of " + budgetBytes / 1e6 + " MB (raise the " +
      "budget, or open it through the server, which sends a coarser level).");
  }
  const values = M.HEAPU8.slice(read.pointer, read.pointer + read.bytes);
  M._free(read.pointer);
  return localDataset(main.name, read, values);
}

/**
 * Reads the DICOM folder `name` (its files: File objects directly in it) with the module; the
 * dataset, or an Error with the reason. `budgetBytes` as for readLocalFiles.
 */
export async function readLocalFolder(name, files, budgetBytes) {
  const list = [...files];
  const total = list.reduce((n, f) => n + f.size, 0);
  if (total > budgetBytes) {
    throw new Error(name + ": its files take " + (total / 1e6).toFixed(1) + " MB, over the page's " +
      "memory budget of " + budgetBytes / 1e6 + " MB (raise the budget, or open it through the " +
      "server, which sends a coarser level).");
  }
  if (!list.length) {
    throw new Error(name + ": the folder holds no files.");
  }
  const M = state.module;
  const folder = "/local-dicom";
  if (!M.FS.analyzePath(folder).exists) {
    M.FS.mkdir(folder);
  }
  const written = [];
  let read;
  try {
    for (const file of list) {
      const path = folder + "/" + file.name;
      M.FS.writeFile(path, new Uint8Array(await file.arrayBuffer()));
      written.push(path);
    }
    read = M.readLocalDICOM(folder, name);
  } finally {
    for (const path of written) {
      M.FS.unlink(path);
    }
  }
  if (read.error) {
    throw new Error(read.error.startsWith(name + ":") ? read.error + "." : name + ": " + read.error + ".");
  }
  if (read.bytes > budgetBytes) {
    M._free(read.pointer);
    throw new Error(name + ": its " + read.type + " values take " + (read.bytes / 1e6).toFixed(1) +
      " MB, over the page's memory budget of " + budgetBytes / 1e6 + " MB (raise the " +
      "budget, or open it through the server, which sends a coarser level).");
  }
  const values = M.HEAPU8.slice(read.pointer, read.pointer + read.bytes);
  M._free(read.pointer);
  return localDataset(name, read, values);
}

// The files directly in a dropped folder (FileSystemDirectoryEntry), not those of its subfolders.
async function folderFiles(entry) {
  const reader = entry.createReader();
  const entries = [];
  for (;;) {
    const batch = await new Promise((resolve, reject) => reader.readEntries(resolve, reject));
    if (!batch.length) {
      break;
    }
    entries.push(...batch);
  }
  return Promise.all(entries.filter((e) => e.isFile).map((e) =>
    new Promise((resolve, reject) => e.file(resolve, reject))));
}

/**
 * The file box and dropping on the page. `open(dataset)` (app.js) shows the volume read; a file
 * that cannot be read is said in #local-note and the volume shown stays.
 */
export function setupLocalFiles(open) {
  const note = $("local-note");
  let busy = false;
  // `folder`: a DICOM folder's name (its files in `files`), else files to read by their names.
  const take = async (files, folder = null) => {
    if (busy || !files || (!files.length && !folder)) {
      return;
    }
    busy = true;
    note.textContent = "Reading " + (folder !== null ? "the DICOM folder " + folder :
      [...files].map((f) => f.name).join(", ")) + " in the page...";
    note.classList.remove("error");
    try {
      const budget = (Number($("budget").value) || 1024) * 1e6;
      const d = folder !== null ? await readLocalFolder(folder, files, budget) :
        await readLocalFiles(files, budget);
      await open(d);
      note.textContent = "Opened " + d.name + " from this computer, read in the page (nothing was " +
        "sent)." + (d.warnings.length ? " Note: " + d.warnings.join(" ") : "");
    } catch (error) {
      note.textContent = "Not opened: " + error.message + " The volume shown stays.";
      note.classList.add("error");
    } finally {
      busy = false;
    }
  };
  $("local-file").onchange = () => take($("local-file").files);
  // A picked folder: the files directly in it (webkitRelativePath "folder/name").
  $("local-folder").onchange = () => {
    const files = [...$("local-folder").files];
    if (files.length) {
      const name = files[0].webkitRelativePath.split("/")[0];
      take(files.filter((f) => f.webkitRelativePath.split("/").length === 2), name);
    }
  };
  document.addEventListener("dragover", (e) => {
    if (e.dataTransfer && [...e.dataTransfer.types].includes("Files")) {
      e.preventDefault();
    }
  });
  document.addEventListener("drop", (e) => {
    if (!e.dataTransfer || !e.dataTransfer.files.length) {
      return;
    }
    e.preventDefault();
    // The entries are only available during the event: taken before any await.
    const entries = [...e.dataTransfer.items].map((item) => item.webkitGetAsEntry && item.webkitGetAsEntry());
    const folders = entries.filter((entry) => entry && entry.isDirectory);
    if (folders.length === 1 && entries.length === 1) {
      folderFiles(folders[0]).then((files) => take(files, folders[0].name), (error) => {
        note.textContent = "Not opened: " + folders[0].name + ": its files cannot be listed (" +
          error.message + "). The volume shown stays.";
        note.classList.add("error");
      });
    } else if (folders.length) {
      note.textContent = "Not opened: drop one DICOM folder at a time, alone. The volume shown stays.";
      note.classList.add("error");
    } else {
      take(e.dataTransfer.files);
    }
  });
}

// ---------------------------------------------------------------------------- the upload
// byte b of every value together (the encoding /api/volume sends, which gzip packs better).
function shuffle(bytes, size) {
  if (size === 1) {
    return bytes;
  }
  const n = bytes.length / size;
  const out = new Uint8Array(bytes.length);
  for (let b = 0; b < size; ++b) {
    const plane = out.subarray(b * n, (b + 1) * n);
    for (let i = 0, o = b; i < n; ++i, o += size) {
      plane[i] = bytes[o];
    }
  }
  return out;
}

async function gzip(bytes) {
  const stream = new Blob([bytes]).stream().pipeThrough(new CompressionStream("gzip"));
  return new Uint8Array(await new Response(stream).arrayBuffer());
}

async function upload(d) {
  const size = state.facts.scalarTypes.get(d.type).bytes;
  const body = await gzip(shuffle(d.local.values, size));
  const headers = {
    "Content-Type": "application/octet-stream",
    "X-Mediso-Name": encodeURIComponent(d.name),
    "X-Mediso-Dims": d.dims.join(","),
    "X-Mediso-Spacing": d.spacing.join(","),
    "X-Mediso-Origin": d.origin.join(","),
    "X-Mediso-Direction": d.direction.join(","),
    "X-Mediso-Type": d.type,
    "X-Mediso-Format": d.format.name + " " + d.format.space,
  };
  const url = "/api/upload?token=" + encodeURIComponent(sessionToken());
  const response = await fetch(url, { method: "POST", headers, body, cache: "no-store" });
  const text = await response.text();
  const headerBytes = Object.entries(headers).reduce((n, [k, v]) => n + k.length + v.length + 4, 0);
  countBytes(url.length + 64 + headerBytes + body.length, text.length + 200);
  if (!response.ok) {
    throw new Error("the local volume's upload was refused: " + text.trim());
  }
  const answer = JSON.parse(text);
  d.uploaded = { id: answer.id, raw: answer.raw, sent: body.length };
  $("local-note").textContent = "Uploaded " + d.name + " once for the server's operations: " +
    answer.raw + " bytes of values, sent as " + body.length + " bytes (byte-shuffled and gzip'd). " +
    "Its later operations send only their parameters.";
  $("local-note").classList.remove("error");
  return answer;
}

/**
 * The server's id of the dataset shown (operations.js): a local file's volume is uploaded at its
 * first operation, once (POST /api/upload, Python/serve_upload.py); the page says so and how
 * many bytes.
 */
export async function serverDataset(d) {
  if (!d.local) {
    return d.id;
  }
  if (!d.local.upload) {
    d.local.upload = upload(d);
    d.local.upload.catch(() => { d.local.upload = null; }); // tried again at the next operation
  }
  return (await d.local.upload).id;
}
