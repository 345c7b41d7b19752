// SPDX-License-Identifier: BSD-3-Clause
// The viewer in a worker (docs/web.md, The worker): RemoteViewer has the WebViewer's methods,
// so the rest of the page calls it as it calls the module's viewer, but the drawing happens in
// render-worker.js on the canvas handed over as an OffscreenCanvas. The camera stays here (the
// module's ViewCamera, the same C++ camera), so that getView answers at once between frames;
// the surfaces and the camera go to the worker with each frame; the worker answers every frame
// with the viewer's stats, which stats() gives until the next one. What WebViewer answered
// synchronously from the drawing (render, finish, estimates) is a promise or the last frame's.

/** True when this browser can draw WebGL2 into an OffscreenCanvas (which a worker may hold). */
export function offscreenWebGL2() {
  try {
    return typeof OffscreenCanvas === "function" && typeof Worker === "function" &&
      !!HTMLCanvasElement.prototype.transferControlToOffscreen &&
      !!new OffscreenCanvas(1, 1).getContext("webgl2");
  } catch {
    return false;
  }
}

export class RemoteViewer {
  /**
   * Starts the worker on `canvas` (its control handed over for good: size it first); it loads
   * its module at once, while this thread loads its own (the page's start-up, docs/web.md).
   * `threads`: the worker loads the threaded module; `budgetMs`: the frame budget (0: the
   * worker's); `abort`: false to let a running refinement run to its end; `slowExtractionMs`,
   * `slowPass`, `refineDelayMs`, `slowFirstDragFrameMs`: test hooks (render-worker.js);
   * `prepareDrag`: the page's ?prepareDrag= (when a drag's level is made ready, render-worker.js:
   * "0" never, "1" after a settled frame, else before a change's refinement). Returns
   * {worker, ready}, ready a promise of the worker's "ready" message, for start().
   */
  static launch(canvas, { threads, budgetMs, abort, slowExtractionMs, slowPass, refineDelayMs,
    slowFirstDragFrameMs, prepareDrag }) {
    const worker = RemoteViewer.takeEarlyWorker(threads) || new Worker("static/render-worker.js");
    const offscreen = canvas.transferControlToOffscreen();
    const base = new URL("static/", location.href).href;
    const ready = new Promise((resolve, reject) => {
      worker.onmessage = (e) => e.data.op === "ready" && resolve(e.data);
      worker.onerror = (e) => reject(new Error("the render worker failed: " + (e.message || "no reason given")));
    });
    ready.catch(() => {}); // start() awaits it
    worker.postMessage({ op: "init", canvas: offscreen, base, threads, budgetMs, abort, slowExtractionMs,
      slowPass, refineDelayMs, slowFirstDragFrameMs, prepareDrag },
      [offscreen]);
    return { worker, ready };
  }

  /**
   * The worker index.html started before the page's modules (loading its module with `threads`
   * or not), where its choice of threads is `threads`; else null, and that worker is ended.
   * Called once: where the page draws on its own thread, with no `threads`, to end it.
   */
  static takeEarlyWorker(threads) {
    const early = window.medisoEarlyWorker;
    window.medisoEarlyWorker = null;
    if (early && early.threads === threads) {
      return early.worker;
    }
    if (early) {
      early.worker.terminate();
    }
    return null;
  }

  /**
   * The viewer of a launched worker (launch()) once it is ready, with the module `M` of this
   * thread (the camera, the CPU model's count). Resolves to the viewer, or rejects.
   */
  static async start({ worker, ready }, M, onFrame) {
    const answer = await ready;
    // The worker's start-up on the page's timeline (docs/web.md, "The page's start-up"): its
    // clock's epoch times as this thread's marks.
    for (const [step, at] of Object.entries(answer.startup || {})) {
      performance.mark("mediso:worker-" + step, { startTime: Math.max(0, at - performance.timeOrigin) });
    }
    const viewer = new RemoteViewer(worker, M, onFrame);
    viewer.readyState = answer;
    viewer.generation = answer.generation || null;
    return viewer;
  }

  constructor(worker, M, onFrame) {
    this.worker = worker;
    this.M = M;
    this.camera = new M.ViewCamera();
    this.typeBytes = new Map(M.scalarTypes().map((t) => [t.value, t.bytes]));
    this.onFrame = onFrame;
    this.surfaces = [];
    this.nextId = 1;
    this.lastStats = { error: "", primitives: 0, triangles: 0, cpuLevel: 3, buildMs: 0, frameMs: 0 };
    this.waiting = []; // [{id, settled, resolve}]
    this.answers = new Map(); // id -> resolve
    this.volume = null; // {type, pointer, dims}: the main thread's copy (this module's memory)
    this.lastDrawn = 0; // the newest frame id the worker answered
    // The worker's generation word (render-worker.js; null where the page is not cross-origin
    // isolated) and the isovalues of the last frame asked for.
    this.generation = null;
    this.sentKey = "";
    worker.onmessage = (e) => this.receive(e.data);
  }

  receive(m) {
    if (m.op === "answer") {
      const resolve = this.answers.get(m.id);
      this.answers.delete(m.id);
      if (resolve) {
        resolve(m.value);
      }
    } else if (m.op === "frame") {
      m.stats.id = m.id;
      this.lastStats = m.stats;
      this.lastDrawn = Math.max(this.lastDrawn, m.id);
      this.onFrame(m.stats, m.id);
      this.waiting = this.waiting.filter((w) => {
        const done = w.id <= m.id && (!w.settled || m.stats.settled || !m.stats.ok);
        if (done) {
          w.resolve(m.stats);
        }
        return !done;
      });
    } else if (m.op === "prepared") {
      // a drag's frame made ready in the idle time (render-worker.js): said by stats() now, not
      // only with the next frame
      this.lastStats = Object.assign({}, this.lastStats, { dragPrepared: m.value, dragPreparedCount: m.count });
    } else if (m.op === "error") {
      this.lastStats = Object.assign({}, this.lastStats, { error: m.message });
      console.error("render worker: " + m.message);
    }
  }

  call(method, ...args) {
    this.worker.postMessage({ op: "call", method, args });
  }

  ask(method, ...args) {
    const id = this.nextId++;
    return new Promise((resolve) => {
      this.answers.set(id, resolve);
      this.worker.postMessage({ op: "call", method, args, id });
    });
  }

  ready() {
    return !!this.readyState.ok;
  }
  error() {
    return this.readyState.error || "";
  }
  info() {
    return this.readyState.info || { error: this.error() };
  }

  /**
   * The volume at `pointer` in this thread's module: kept here (the CPU model's count, and
   * the page's own reading of values) and copied to the worker. The answer comes with the
   * worker's upload; the camera is reset here at once, as WebViewer.setVolume resets its own.
   */
  setVolume(type, pointer, dims, spacing, origin) {
    this.volume = { type, pointer, dims: [...dims] };
    const byteLength = this.typeBytes.get(type) * dims[0] * dims[1] * dims[2];
    const bytes = this.M.HEAPU8.slice(pointer, pointer + byteLength);
    this.camera.setVolume(dims, spacing, origin);
    const id = this.nextId++;
    this.uploaded = new Promise((resolve) => this.answers.set(id, resolve));
    this.worker.postMessage({ op: "volume", id, type, bytes: bytes.buffer, dims, spacing, origin },
      [bytes.buffer]);
    return true;
  }

  /**
   * Streaming (stream.js): a full level of `dims` (its bricks written as they come) in the
   * worker's own buffer, and level 0 as the coarse volume. This thread has no copy of the level
   * until the end (keepStreamedVolume); the CPU model's count finds none until then. Resolves to
   * "" or why the worker refused.
   */
  beginStream({ type, dims, spacing, origin, brick, coarse }) {
    this.volume = null;
    this.streamed = { type, dims: [...dims] };
    this.camera.setVolume(dims, spacing, origin);
    const id = this.nextId++;
    const uploaded = new Promise((resolve) => this.answers.set(id, resolve));
    const bytes = coarse.bytes.slice();
    this.worker.postMessage({ op: "stream", id, type, dims, spacing, origin, brick,
      coarse: { bytes: bytes.buffer, dims: coarse.dims, spacing: coarse.spacing, origin: coarse.origin } },
    [bytes.buffer]);
    return uploaded;
  }
  /**
   * A batch of bricks for the worker's buffer: `body` (an ArrayBuffer, transferred) holds bricks
   * `ids` one after the other as the server encoded them (predictor `predictor`); the worker
   * decodes and writes them (render-worker.js, writeBricks).
   */
  writeBricks({ ids, body, predictor }) {
    this.worker.postMessage({ op: "bricks", ids, body, predictor }, [body]);
  }
  /** Streaming ends; resolves to the level's bytes as the worker holds them (an ArrayBuffer). */
  endStream() {
    const id = this.nextId++;
    const bytes = new Promise((resolve) => this.answers.set(id, resolve));
    this.worker.postMessage({ op: "streamEnd", id });
    return bytes;
  }
  /**
   * The streamed level's values, copied from endStream's bytes into this thread's module at
   * `pointer` (stream.js): the CPU model's count reads them from now on.
   */
  keepStreamedVolume(pointer) {
    this.volume = { ...this.streamed, pointer };
  }
  setCoarseValues(values) { this.call("setCoarseValues", values); }

  setSurfaces(surfaces) {
    this.surfaces = surfaces.map((s) => ({ value: s.value, color: [...s.color], opacity: s.opacity }));
    return true;
  }

  resize(width, height) {
    this.camera.resize(width, height);
    this.call("resize", width, height);
  }

  // The camera, here.
  resetCamera() { this.camera.resetCamera(); }
  azimuth(d) { this.camera.azimuth(d); }
  elevation(d) { this.camera.elevation(d); }
  zoom(f) { this.camera.zoom(f); }
  dolly(f) { this.camera.dolly(f); }
  setParallel(p) {
    this.camera.setParallel(p);
    this.call("setParallel", p);
  }
  setView(view) { this.camera.setView(view); }
  /** The direction the grid is drawn with (PageCamera::SetDirection), here and in the worker. */
  setDirection(d) {
    this.call("setDirection", d);
    return this.camera.setDirection(d);
  }
  getView() { return this.camera.getView(); }

  setBackground(r, g, b) { this.call("setBackground", r, g, b); }
  setMaterial(a, d, s, p) { this.call("setMaterial", a, d, s, p); }
  setPath(path) { this.call("setPath", path); }
  setCPULevel(level) { this.call("setCPULevel", level); }
  setBudget(bytes) { this.call("setBudget", bytes); }
  setMaxTextureSize(texels) { this.call("setMaxTextureSize", texels); }
  setGPUBudget(bytes) { this.call("setGPUBudget", bytes); }
  setBrickPool(on) { this.call("setBrickPool", on); }
  /** The estimator's table, from the worker (a promise). */
  estimates() { return this.ask("estimates"); }
  clearResultMesh() { this.call("clearResultMesh"); }
  /** A surface the server made: the arrays themselves (copied to the worker). */
  setResultArrays(points, triangles, color, opacity) {
    this.worker.postMessage({ op: "mesh", points, triangles, color, opacity });
  }

  /**
   * Asks the worker for a frame of the surfaces and camera as they are now; `interactive`
   * during a drag. Resolves with the first frame answered for it (or a newer one), or, with
   * `settled`, with the frame at the full level (a refinement's).
   */
  frame(interactive = false) {
    const id = this.nextId++;
    this.worker.postMessage({ op: "frame", id, surfaces: this.surfaces, view: this.camera.getView(),
      interactive, generation: this.nextGeneration(interactive) });
    const first = new Promise((resolve) => this.waiting.push({ id, settled: false, resolve }));
    const settled = new Promise((resolve) => this.waiting.push({ id, settled: true, resolve }));
    return { id, first, settled };
  }

  /**
   * The generation of a frame asked for now: new isovalues or a drag frame make the refinement
   * the worker may be running obsolete, so the word moves on at once, before the frame's
   * message, and the worker's extraction stops without waiting for that message.
   */
  nextGeneration(interactive) {
    const key = JSON.stringify(this.surfaces.map((s) => s.value));
    const obsoletes = interactive || key !== this.sentKey;
    this.sentKey = key;
    if (!this.generation) {
      return 0;
    }
    return obsoletes ? Atomics.add(this.generation, 0, 1) + 1 : Atomics.load(this.generation, 0);
  }

  render() {
    return true;
  }
  finish() {}
  stats() {
    return this.lastStats;
  }
  countOnCPU(values, level) {
    const v = this.volume;
    return v ? this.M.countCrossings(v.type, v.pointer, v.dims, values, level) : 0;
  }
}
