// SPDX-License-Identifier: BSD-3-Clause
// The page's "On the server" panel (docs/web.md, Operations): a surface of the page, extracted
// again by the server from the same isovalue and level, then smoothed, hole-filled, clipped and
// decimated there with ParaView/VTK filters. Only the parameters go up, on a WebSocket opened at
// the first request (an idle page keeps no connection); progress and the result's summary come
// back, and the result itself only when asked for: downloads (STL, PLY, VTP), and the PLY for
// window.mediso.showMesh when the page can draw a mesh. Every byte is counted into the readout.
// The export options (clean, largest piece, cap) go with the request; the result's mesh report,
// computed by VTK on the server (serve_messages.REPORT), is shown before any download. While the
// result is shown its source surface is hidden (a toggle for each).

import { $ } from "./state.js";

const STAGES = {
  queued: "waiting for the server",
  surface: "extracting the surface",
  smooth: "smoothing",
  fillHoles: "filling holes",
  clip: "clipping",
  decimate: "decimating",
  export: "cleaning and choosing the piece",
  report: "checking the mesh",
  write: "writing the files",
};
// The report's fields as the panel names them (docs/web.md, "Export"; serve_messages.REPORT).
const REPORT = [
  ["components", "pieces"],
  ["boundaryEdges", "boundary edges"],
  ["nonManifoldEdges", "non-manifold edges"],
  ["degenerateTriangles", "degenerate triangles"],
  ["duplicateTriangles", "duplicate triangles"],
  ["triangles", "triangles"],
  ["points", "points"],
];
const AXES = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] };

// Bytes of one WebSocket frame on the wire: header, the client's mask, the payload.
function frameBytes(payload, masked) {
  const extended = payload > 65535 ? 8 : payload > 125 ? 2 : 0;
  return 2 + extended + (masked ? 4 : 0) + payload;
}

function megabytes(n) {
  return n >= 1e6 ? (n / 1e6).toFixed(1) + " MB" : Math.max(1, Math.round(n / 1e3)) + " kB";
}

/**
 * Drives the panel. `page` gives what it needs of the rest of the page (app.js hands it over):
 *   dataset                  the dataset the page shows (docs/web.md's D)
 *   serverDataset()          a promise of its id on the server (a local file's: uploaded once)
 *   token                    the session's token
 *   surfaces()               the page's surfaces [{value, ...}]
 *   levels                   the number of levels of detail (the module's; the last is the full volume)
 *   level()                  the level of the whole volume its surfaces are drawn at
 *   request(url)             the page's counted fetch (volume.js): {response, body}
 *   count(sent, received)    adds bytes the panel moved itself (WebSocket) to the readout
 *   showSurface(s, shown)    shows or hides one of the page's surfaces (its source), redrawn
 */
export function setupOperations(page) {
  const section = $("op-run").closest("section");
  const button = $("op-run");
  const bar = $("op-progress");
  const out = $("op-result");
  const encoder = new TextEncoder();
  let socket = null;
  let opening = null;
  let nextId = 1;
  let current = null; // {id, isovalue, level, surface} of the operation in flight
  let source = null; // the page's surface whose result is shown

  // The levels to choose from, finest first, after "as on the page".
  $("op-level").append(...Array.from({ length: page.levels }, (_, i) => {
    const k = page.levels - 1 - i;
    return Object.assign(document.createElement("option"),
      { value: String(k), textContent: k === page.levels - 1 ? k + " (full)" : String(k) });
  }));

  function setState(state, text) {
    section.dataset.state = state;
    out.classList.toggle("error", state === "error");
    if (text !== undefined) {
      out.textContent = text;
    }
    const busy = state === "running";
    button.textContent = busy ? "Cancel" : "Run on the server";
    bar.hidden = !busy;
  }

  function send(message) {
    const text = JSON.stringify(message);
    page.count(frameBytes(encoder.encode(text).length, true), 0);
    socket.send(text);
  }

  function connect() {
    if (socket && socket.readyState === WebSocket.OPEN) {
      return Promise.resolve();
    }
    if (opening) {
      return opening;
    }
    const url = new URL("api/ws", location.href);
    url.protocol = location.protocol === "https:" ? "wss:" : "ws:";
    url.search = "?token=" + encodeURIComponent(page.token);
    opening = new Promise((resolve, reject) => {
      const ws = new WebSocket(url);
      // The handshake: the request line and headers a browser sends, the 101 answer.
      page.count(url.href.length + 420, 160);
      ws.onopen = () => { socket = ws; opening = null; resolve(); };
      ws.onerror = () => { opening = null; reject(new Error("the server's WebSocket is not reachable")); };
      ws.onmessage = (event) => {
        page.count(0, frameBytes(encoder.encode(event.data).length, false));
        receive(JSON.parse(event.data));
      };
      ws.onclose = (event) => {
        socket = null;
        if (current) {
          current = null;
          setState("error", "The connection to the server closed (" + event.code +
            (event.reason ? ": " + event.reason : "") + ").");
        }
      };
    });
    return opening;
  }

  function steps() {
    const d = page.dataset;
    const list = [];
    if ($("op-smooth").checked) {
      list.push({ smooth: { iterations: Math.round(Number($("op-iterations").value)), relaxation: 0.1 } });
    }
    if ($("op-fill").checked) {
      list.push({ fillHoles: { size: Number($("op-hole").value) } });
    }
    if ($("op-clip").checked) {
      const centre = d.origin.map((o, a) => o + d.spacing[a] * (d.dims[a] - 1) / 2);
      list.push({ clip: { origin: centre, normal: AXES[$("op-normal").value] } });
    }
    if ($("op-decimate").checked) {
      list.push({ decimate: { reduction: Number($("op-reduction").value) } });
    }
    return list;
  }

  function exportOptions() {
    return { clean: $("op-clean").checked, largestComponent: $("op-largest").checked,
             cap: $("op-cap").checked };
  }

  async function run() {
    const surface = page.surfaces()[Number($("op-surface").value)];
    if (!surface) {
      setState("error", "Choose a surface first.");
      return;
    }
    const choice = $("op-level").value;
    const level = choice === "page" ? page.level() : Number(choice);
    current = { id: nextId++, isovalue: surface.value, level, surface };
    bar.value = 0;
    setState("running", "Sending the parameters...");
    try {
      await connect();
      // A local file's volume is uploaded first, once (local.js).
      const dataset = await page.serverDataset();
      send({ op: "surface", id: current.id, dataset, isovalue: surface.value,
             level, steps: steps(), export: exportOptions() });
    } catch (error) {
      current = null;
      setState("error", error.message);
    }
  }

  function receive(message) {
    if (!current || message.id !== current.id) {
      if (message.error && message.id === null) {
        setState("error", "The server refused a message: " + message.error);
      }
      return;
    }
    if (message.progress !== undefined) {
      bar.value = message.progress;
      out.textContent = (STAGES[message.stage] || message.stage) + "... " +
        Math.round(100 * message.progress) + "%";
    } else if (message.done) {
      const surface = current.surface;
      current = null;
      showResult(message, surface);
    } else if (message.cancelled) {
      current = null;
      setState("cancelled", "Cancelled.");
    } else if (message.error) {
      current = null;
      setState("error", "The server says: " + message.error);
    }
  }

  async function download(result, format) {
    const { body } = await page.request("/api/result/" + result.result + "?format=" + format);
    const name = page.dataset.name.replace(/\.[^.]*$/, "").replace(/[^\w.-]+/g, "_") + "-" +
      result.isovalue + "-level" + result.level + "." + format;
    const link = Object.assign(document.createElement("a"), {
      href: URL.createObjectURL(new Blob([body])), download: name });
    document.body.append(link);
    link.click();
    link.remove();
    setTimeout(() => URL.revokeObjectURL(link.href), 10000);
  }

  // The mesh report, as a list; the section's data-watertight says it for automation.
  function reportList(report) {
    const list = document.createElement("ul");
    list.className = "report";
    const head = document.createElement("li");
    head.textContent = "Watertight: " + (report.watertight ? "yes" : "no") +
      " (checked by VTK on the server)";
    list.append(head);
    for (const [key, label] of REPORT) {
      const item = document.createElement("li");
      item.textContent = label + ": " + report[key].toLocaleString();
      item.dataset.field = key;
      list.append(item);
    }
    section.dataset.watertight = String(report.watertight);
    return list;
  }

  // A checkbox and its label; `toggle(checked)` runs on each change.
  function toggle(text, id, checked, change) {
    const box = Object.assign(document.createElement("input"), { type: "checkbox", id, checked });
    box.onchange = () => change(box.checked);
    const label = document.createElement("label");
    label.append(box, " " + text);
    return label;
  }

  // The toggles of the result and its source, the source hidden at first.
  function toggles(surface, mesh) {
    if (source && source !== surface) {
      page.showSurface(source, true); // an earlier result's source comes back
    }
    source = surface;
    page.showSurface(surface, false);
    const box = document.createElement("div");
    box.className = "toggles";
    box.append(
      toggle("Show the source surface (isovalue " + surface.value + ")", "op-show-source", false,
        (shown) => page.showSurface(surface, shown)),
      toggle("Show the result", "op-show-result", true, (shown) => {
        if (!shown) {
          window.mediso.clearMesh();
        } else if (mesh.body) {
          window.mediso.showMesh(mesh.body);
        }
      }));
    return box;
  }

  function showResult(result, surface) {
    setState("done", "");
    section.dataset.result = result.result;
    const closed = result.boundaryEdges === 0 ? "closed (no boundary edges)"
      : result.boundaryEdges.toLocaleString() + " boundary edges";
    const chain = result.stages.map((s) => s.stage + " " + s.triangles.toLocaleString()).join(" → ");
    const summary = document.createElement("div");
    summary.textContent = "Isovalue " + result.isovalue + " at level " + result.level + ": " +
      result.triangles.toLocaleString() + " triangles, " + result.points.toLocaleString() +
      " points, " + closed + ", " + result.seconds.toFixed(2) + " s on the server (" + chain + ").";
    const links = document.createElement("div");
    links.className = "downloads";
    for (const format of ["stl", "ply", "vtp"]) {
      const a = Object.assign(document.createElement("a"), {
        href: "#", textContent: format.toUpperCase() + " (" + megabytes(result.bytes[format]) + ")" });
      a.dataset.format = format;
      a.onclick = (event) => {
        event.preventDefault();
        download(result, format).catch((error) => setState("error", error.message));
      };
      links.append(a, " ");
    }
    out.replaceChildren(summary, reportList(result.report), "Download: ", links);
    if (window.mediso && typeof window.mediso.showMesh === "function") {
      const mesh = { body: null };
      out.append(toggles(surface, mesh));
      page.request("/api/result/" + result.result + "?format=ply")
        .then(({ body }) => {
          mesh.body = body;
          if ($("op-show-result").checked) {
            window.mediso.showMesh(body);
          }
        })
        .catch((error) => setState("error", "The result could not be shown: " + error.message));
    }
  }

  button.onclick = () => {
    if (current && socket) {
      send({ op: "cancel", id: current.id });
      out.textContent = "Cancelling...";
    } else if (!current) {
      run();
    }
  };
  setState("idle", "");
}
