#!/usr/bin/env python3
"""The web client against vtk.js in the same browser: isovalue change + frame, first image, bytes.

    python3 Python/benchmark_web.py [--inputs ct,ct512] [--sweep 10] [--size 800x600] [--out FILE.md]
    python3 Python/benchmark_web.py --interactive [--inputs phantom:256,ct] [--paths cpu,gpu] [--before main]
    python3 Python/benchmark_web.py --stream [--inputs ct512,phantom:512:noise=40] [--networks 30/40,loopback] [--warm]
    python3 Python/benchmark_web.py --startup [--inputs ct] [--networks 30/40,loopback]
    python3 Python/benchmark_web.py --bricks [--inputs ct] [--limits 200,200/24] [--sweep 6] [--stills 6]
    python3 Python/benchmark_web.py --fullframe [--inputs ct512,phantom:512:noise=40] [--sizes 800x600,200x150]
        [--base-wasm [LABEL=]DIR,...]

In one headless Chromium (Debian's, software WebGL2: SwiftShader), on the same volume and canvas
size: the page's GPU path (the core on WebGL2), its CPU path (the BlockLOD core in WebAssembly at
level 3, full resolution) and vtk.js 37 (`vtkImageMarchingCubes` + its WebGL renderer, the way
Glance and the vtk.js examples draw isosurfaces) take the same isovalues in turn, the order turning
every step; a change is timed from the call to the finished frame (a pixel read back). Also the
time from opening each page to its first image, and the bytes the page received for the volume
against its raw bytes. The page is served by Python/serve.py (pvpython), vtk.js's page by a static
server; vtk.js reads the same raw values. ct512 is the CT resampled to 512x512x216
(BenchmarkHistoPyramidIsoMapper --write-input). Not a test: it prints a table.

--interactive (issue 30): the page before (the page of git ref --before, which draws on the main
thread, served from an export of that ref with the same WebAssembly module) and this page (the
viewer in a worker), in one Chromium, on each path: the time from an isovalue change to its first
visible frame and to the full level, the median frame of a mouse drag with its level or image
sample distance, and the longest main-thread task (PerformanceObserver longtask) over the changes
and the drag. Inputs: phantom:N (the plugin's phantom) or ct. --scene skin-bone drags issue 30's
scene (skin -500 at opacity 0.3 over bone 400) instead of the last change's surface; --stills N
adds N still frames after the drag (the camera turned 2 degrees each) and their median, the drag
frame's ratio to it, and the steady drag frame (without the first frame at each level and sample
distance, which may build that level or compile its program); --move-ms the wait after each of the
drag's --moves (a longer drag for slow frames); --before none runs this page only.

--stream (issue 31): the page on the CPU path fetching its level whole (?stream=0) and streaming
it (level 0, then the bricks the surfaces need first), each in a fresh browser context, in one
Chromium, under each network (MBIT/LATENCY_MS through CDP's Network.emulateNetworkConditions, or
loopback): the time to the first image, to the current surfaces at the full level, to the whole
level, and the bytes on the wire. Inputs: ct, ct512, or any server spec phantom:N[:noise=HU]
(the issue's: the 512-wide CT and phantom:512:noise=40, the default). Below it, where each
streamed page's time went (its stats().streamTimes) beside the whole page's frames. With
--before REF, the streaming page of git REF (its Python/ and Web/static, served by a server of
its own with this tree's WebAssembly module) is timed too, between the whole page and this one.

--startup (issue 31's first image): the streaming page's start-up request by request, in a fresh
context under each network (Testing/Web/bench-startup.mjs): when each of the page's requests was
sent and finished and its bytes on the wire, and the page's marks (its module loaded, the worker
ready, the first image).

--bricks (issue 31's brick pool): the page's GPU path on each input as one texture and, under each
forced texture limit (and GPU budget: LIMIT/MB), as bricks drawn from the pool and each as its own
pyramid (`?brickPool=0`), each in a fresh context in one Chromium (Testing/Web/bench-bricks.mjs): an
isovalue change to its full-level frame and the part of it that built the pyramids (medians over the
sweep's isovalues, the first left out), a still frame (median, the camera turned 2 degrees each),
and the primitives, bricks and pool slots. Inputs: ct, ct512 or phantom:N[:noise=HU].

--fullframe (issue 31's full-level frame): the CPU path's frame of every surface at the full level,
part by part, on the page with its level whole (Testing/Web/bench-fullframe.mjs), at each canvas
size of --sizes: still frames (nothing uploaded), the surfaces uploaded again (the upload's own
time, stats().uploadMs, and the frame), and each surface alone (a translucent one also opaque).
--base-wasm LABEL=DIR,... times other WebAssembly modules against --wasm, pages alternated in one
Chromium (an A/B of a change to the drawing: --before cannot, its page takes this tree's module).
"""
import argparse
import contextlib
import json
import os
import shutil
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchmark_common import (ROOT, cpu_model, data_dir, free_port, load_average,  # noqa: E402
                              progress_printer, write_report)

progress = progress_printer("web-bench")
WEB = os.path.join(ROOT, "Testing", "Web")
TYPES = {"MET_CHAR": "int8", "MET_UCHAR": "uint8", "MET_SHORT": "int16", "MET_USHORT": "uint16",
         "MET_INT": "int32", "MET_UINT": "uint32", "MET_FLOAT": "float32", "MET_DOUBLE": "float64"}


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--inputs", default="ct,ct512")
    p.add_argument("--sweep", type=int, default=10, help="isovalues, equidistant inside the range")
    p.add_argument("--size", default="800x600")
    p.add_argument("--plugin", default=os.path.join(ROOT, "build", "lib", "paraview-5.11", "plugins",
                                                    "MedicalIsosurfaces", "MedicalIsosurfaces.so"))
    p.add_argument("--wasm", default=os.path.join(ROOT, "build-web", "bin"))
    p.add_argument("--work", default=os.path.join(ROOT, "build", "bench-web"))
    p.add_argument("--out", default="")
    p.add_argument("--interactive", action="store_true",
                   help="the page before (--before) against this one: first answer, drag, long tasks")
    p.add_argument("--before", default="",
                   help="--interactive, --startup: the git ref of the page before (--interactive's "
                        "default: where this branch left main; --startup's: none), whose page takes "
                        "this tree's WebAssembly module; --stream: that ref's streaming page too "
                        "(default: none)")
    p.add_argument("--moves", type=int, default=30, help="--interactive: mouse moves of the drag")
    p.add_argument("--paths", default="cpu,gpu", help="--interactive: the page's paths to run")
    p.add_argument("--scene", default="", choices=["", "skin-bone"],
                   help="--interactive: skin-bone drags skin -500 (opacity 0.3) over bone 400")
    p.add_argument("--move-ms", type=int, default=30,
                   help="--interactive: the wait after each mouse move of the drag (ms)")
    p.add_argument("--changes", type=int, default=6,
                   help="--interactive: isovalue changes timed before the drag (at most 6)")
    p.add_argument("--prepare-drag", default="",
                   help="--interactive: this page with ?prepareDrag= each of these (e.g. 0,1: an A/B of "
                        "the drag's frame made ready ahead, render-worker.js), one page each")
    p.add_argument("--frame-budget", type=int, default=0,
                   help="--interactive: the pages' frame budget in ms (?frameBudget=, the page "
                        "before's too; 0: the page's, 100 ms): on a loaded machine, a budget as many "
                        "times the page's as its frames are slower keeps the levels a quiet machine "
                        "would choose")
    p.add_argument("--drag-after-ms", default="0",
                   help="--interactive with --scene: idle waits between the scene's settled frame and "
                        "a drag (the first: the drag of the tables; each further one: the scene "
                        "changed again, then a drag of its own: the first-drag table)")
    p.add_argument("--stills", type=int, default=0,
                   help="--interactive: still frames after the drag (their median beside the drag's)")
    p.add_argument("--trace", action="store_true",
                   help="--interactive: Chromium's trace over the measured window names what ran in "
                        "each main-thread task over 50 ms (Testing/Web/longtasks.mjs)")
    p.add_argument("--stream", action="store_true",
                   help="streaming against the whole level (issue 31): first image, full level, bytes")
    p.add_argument("--networks", default="30/40,loopback",
                   help="--stream: MBIT/LATENCY_MS or loopback, comma-separated")
    p.add_argument("--repeats", type=int, default=1, help="--stream: runs of each page")
    p.add_argument("--startup", action="store_true",
                   help="the streaming page's start-up, request by request (issue 31's first image)")
    p.add_argument("--warm", action="store_true",
                   help="--stream: before the pages, have the server encode the whole level and "
                        "every brick once (both are kept), so that neither page waits for it")
    p.add_argument("--bricks", action="store_true",
                   help="the GPU path as one texture, from the brick pool and per brick (issue 31)")
    p.add_argument("--limits", default="200,200/24",
                   help="--bricks: forced texture limits, each optionally /GPU budget in MB")
    p.add_argument("--fullframe", action="store_true",
                   help="the CPU path's full-level frame, part by part (issue 31): still frames, the "
                        "upload, each surface alone, at each of --sizes")
    p.add_argument("--sizes", default="800x600,200x150", help="--fullframe: canvas sizes")
    p.add_argument("--base-wasm", default="",
                   help="--fullframe: other WebAssembly modules' folders, [LABEL=]DIR comma-separated "
                        "(e.g. main's build-web/bin), timed against --wasm page by page in the same "
                        "Chromium (all the surfaces only, not each alone)")
    return p.parse_args(argv)


def read_mha(path):
    """Header fields and the raw values (little-endian) of an uncompressed MetaImage."""
    with open(path, "rb") as f:
        data = f.read()
    fields = {}
    at = 0
    while True:
        end = data.index(b"\n", at)
        line = data[at:end].decode()
        at = end + 1
        key, _, value = line.partition("=")
        fields[key.strip()] = value.strip()
        if key.strip() == "ElementDataFile":
            break
    dims = [int(v) for v in fields["DimSize"].split()]
    kind = TYPES[fields["ElementType"]]
    size = {"int8": 1, "uint8": 1, "int16": 2, "uint16": 2, "int32": 4, "uint32": 4, "float32": 4,
            "float64": 8}[kind]
    if fields["ElementDataFile"] == "LOCAL":
        raw = data[at:at + dims[0] * dims[1] * dims[2] * size]
    else:
        with open(os.path.join(os.path.dirname(path), fields["ElementDataFile"]), "rb") as f:
            raw = f.read()
    spacing = [float(v) for v in fields.get("ElementSpacing", "1 1 1").split()]
    origin = [float(v) for v in fields.get("Offset", "0 0 0").split()]
    return {"dims": dims, "type": kind, "spacing": spacing, "origin": origin}, raw


def volume_path(name):
    data = data_dir()
    if name == "ct":
        return os.path.join(data, "ct_head.mha")
    path = os.path.join(ROOT, "build", "bench-volumes", name + ".mha")
    if not os.path.isfile(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        subprocess.run([os.path.join(ROOT, "build", "bin", "BenchmarkHistoPyramidIsoMapper"), "--input",
                        name, "--ct", volume_path("ct"), "--write-input", path], check=True,
                       stdout=subprocess.DEVNULL)
    return path


def run_input(args, name):
    path = volume_path(name)
    header, raw = read_mha(path)
    work = work_folder(args, "", name)
    with open(os.path.join(work, "volume.raw"), "wb") as f:
        f.write(raw)
    subprocess.run([os.path.join(WEB, "node_modules", ".bin", "esbuild"),
                    os.path.join(WEB, "bench", "vtkjs-bench.mjs"), "--bundle", "--format=iife",
                    "--minify", "--log-level=warning", "--outfile=" + os.path.join(work, "vtkjs-bench.js")],
                   check=True)
    shutil.copy(os.path.join(WEB, "bench", "vtkjs.html"), work)
    server, page_url = start_server(ROOT, args, path)
    static_port = free_port()
    static = subprocess.Popen([sys.executable, "-m", "http.server", str(static_port), "--bind",
                               "127.0.0.1", "--directory", work],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        lo_hi = None
        # the isovalues: equidistant inside the data range (its ends left out)
        import array
        values = array.array({"int8": "b", "uint8": "B", "int16": "h", "uint16": "H", "int32": "i",
                              "uint32": "I", "float32": "f", "float64": "d"}[header["type"]])
        values.frombytes(raw)
        lo_hi = (min(values), max(values))
        isovalues = [lo_hi[0] + (lo_hi[1] - lo_hi[0]) * (i + 1) / (args.sweep + 1)
                     for i in range(args.sweep)]
        size = [int(v) for v in args.size.split("x")]
        config = {"pageUrl": page_url,
                  "vtkjsUrl": "http://127.0.0.1:%d/vtkjs.html" % static_port,
                  "volume": {"url": "volume.raw", **header}, "size": size, "isovalues": isovalues}
        progress("%s: %d isovalues, %s" % (name, args.sweep, args.size))
        result = run_script(work, "bench.mjs", config)
    finally:
        server.kill()
        static.kill()
    result["raw_bytes"] = len(raw)
    result["header"] = header
    return result


def start_server(root, args, data):
    """serve.py of the tree `root` on a free port with --data `data`; (process, page URL)."""
    port = free_port()
    token = "bench-%d" % port
    server = subprocess.Popen([shutil.which("pvpython"), "--no-mpi", os.path.join(root, "Python", "serve.py"),
                               "--plugin", args.plugin, "--wasm", args.wasm, "--data", data,
                               "--port", str(port), "--token=" + token],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              env=dict(os.environ, PYTHONDONTWRITEBYTECODE="1"))
    for line in server.stdout:
        if "open http" in line:
            break
    return server, "http://127.0.0.1:%d/?token=%s" % (port, token)


@contextlib.contextmanager
def serving(args, name, trees):
    """Input `name` (ct, ct512, or a server spec phantom:N[:noise=HU] as serve.py takes it) served
    by serve.py of each tree in `trees` (label -> tree, started in that order); yields label -> page
    URL and stops the servers however the block ends."""
    data = volume_path(name) if not name.startswith("phantom:") else name
    servers = []
    try:
        urls = {}
        for label, root in trees.items():
            server, urls[label] = start_server(root, args, data)
            servers.append(server)
        yield urls
    finally:
        for server in servers:
            server.kill()


def work_folder(args, prefix, name):
    """The input's folder under --work for a mode's files (its config, its result), made."""
    work = os.path.join(args.work, prefix + name.replace(":", "-"))
    os.makedirs(work, exist_ok=True)
    return work


def run_script(work, script, config):
    """Testing/Web/`script` run by node with `config`, both in the folder `work`; its result."""
    config_file = os.path.join(work, "config.json")
    out_file = os.path.join(work, "result.json")
    with open(config_file, "w") as f:
        json.dump(config, f)
    subprocess.run(["node", os.path.join(WEB, script), config_file, out_file], check=True, cwd=WEB,
                   timeout=3600)
    with open(out_file) as f:
        return json.load(f)


def run_interactive(args, name, before_root):
    trees = {"before": before_root, "after": ROOT} if before_root else {"after": ROOT}
    with serving(args, name, trees) as pages:
        lo, hi = (-1000, 1100) if name.startswith("phantom:") else (-1000, 2000)
        isovalues = [400, -500, 300, 500, -300, 200, 600]
        isovalues = [v for v in isovalues if lo < v < hi][:max(1, args.changes) + 1]
        if args.frame_budget:
            # every page's (the page before reads ?frameBudget= too), so that an A/B compares pages
            # choosing within the same budget
            pages = {k: url + "&frameBudget=%d" % args.frame_budget for k, url in pages.items()}
        if args.prepare_drag:
            # this tree's page once per ?prepareDrag= value, named after it (a value given again:
            # the page again, numbered, in the order given, so that A/B runs can alternate)
            after = pages.pop("after")
            values = args.prepare_drag.split(",")
            for i, v in enumerate(values):
                again = values[:i].count(v)
                pages["after, prepareDrag=%s%s" % (v, " (%d)" % (again + 1) if again else "")] = \
                    after + "&prepareDrag=" + v
        config = {"pages": pages, "paths": args.paths.split(","),
                  "dragAfterMs": [int(v) for v in args.drag_after_ms.split(",")],
                  "size": [int(v) for v in args.size.split("x")], "isovalues": isovalues,
                  "moves": args.moves, "stills": args.stills, "moveMs": args.move_ms, "trace": args.trace}
        if args.scene == "skin-bone":
            config["surfaces"] = [{"value": -500, "opacity": 0.3, "color": [0.93, 0.75, 0.62]},
                                  {"value": 400}]
        progress("%s: the page before and after, %d changes and a drag of %d moves per path"
                 % (name, len(isovalues) - 1, args.moves))
        return run_script(work_folder(args, "interactive-", name), "bench-interactive.mjs", config)


def first_drag_lines(results):
    """The first drag frame after the scene's change, apart from the steady ones (issue 30): the
    first frame on its level for the new isovalues, which built that level's pyramid and first used
    its programs unless the worker made them ready after the change (render-worker.js); one row for
    the drag of the tables and one for each later drag (--drag-after-ms), with the idle wait
    between the settled frame and the drag, and what was made ready ahead by the first move (its
    steps together, and the longest step: the most a drag waits for it)."""
    lines = ["", "The drag's first frame (after the scene's change), apart from the steady frames:", "",
             "| input | path | page | drag begun ms after settled | first drag frame ms | predicted ms | "
             "built a pyramid | level / sample distance | wait from the first move ms | steady drag frame ms, "
             "median | made ready ahead ms (longest step) |",
             "|---|---|---|---:|---:|---:|---|---|---:|---:|---:|"]
    for name, r in results.items():
        for run in r["runs"]:
            drags = [dict(run["drag"], dragPrepared=run.get("dragPrepared"))] + run.get("laterDrags", [])
            for d in drags:
                f = d.get("first")
                if not f:
                    continue
                made = d.get("dragPrepared") or {}
                lines.append("| %s | %s | %s | %s | %.0f | %.0f | %s | %s / %s | %s | %s | %s |" % (
                    name, run["path"], run["page"], d.get("afterMs", 0), f["ms"], f.get("predictedMs") or 0,
                    {True: "yes", False: "no"}.get(f.get("pyramidBuilt"), "-"), f.get("level"),
                    f.get("sampleDistance"),
                    "%.0f" % f["waitMs"] if f.get("waitMs") is not None else "-",
                    "%.0f" % d["steadyMs"] if d.get("steadyMs") else "-",
                    "%.0f (%s, level %s)" % (made["ms"], "%.0f" % made["longestStepMs"]
                                             if made.get("longestStepMs") is not None else "-",
                                             made.get("level")) if made.get("ms") else "-"))
    return lines


def before_tree(args):
    """The page of git ref args.before (its Python/ and Web/static) in a folder under --work, or ""
    for --before none."""
    if args.before == "none":
        return ""
    before_root = os.path.join(args.work, "before-" + args.before.replace("/", "-"))
    shutil.rmtree(before_root, ignore_errors=True)
    os.makedirs(before_root)
    archive = subprocess.run(["git", "-C", ROOT, "archive", args.before, "Python", "Web/static"],
                             check=True, stdout=subprocess.PIPE).stdout
    subprocess.run(["tar", "-x", "-C", before_root], input=archive, check=True)
    return before_root


def long_task_lines(results):
    """Each main-thread task over 50 ms in the measured window (issue 30's budget), with the phase it
    began in and, with --trace, what ran in it (Chromium's trace: the largest self times)."""
    def phase(run, start):
        p = run.get("phases") or {}
        for key, text in (("release", "after the drag (its refinement)"), ("drag", "the drag"),
                          ("scene", "the drag's scene set and refined"), ("window", "the timed changes")):
            if key in p and start >= p[key]:
                return text
        return "-"
    lines = ["", "Main-thread tasks over 50 ms (PerformanceObserver `longtask`) in the measured window: from "
             "after the load and a first change (1 s later) through the timed changes, the drag's scene and "
             "its refinement, the drag, and its refinement (until settled, and 500 ms):", ""]
    rows = []
    for name, r in results.items():
        for run in r["runs"]:
            traced = run.get("traced") or []
            for task in run.get("longTasks") or []:
                if not isinstance(task, dict):
                    continue
                near = min(traced, key=lambda t: abs(t["ms"] - task["ms"]) + abs(t["start"] - task["start"]),
                           default=None) if traced else None
                what = "; ".join("%s %.0f ms" % (k, v) for k, v in near["self"][:4]) if near else "-"
                cpu = "%.0f" % near["cpuMs"] if near and near.get("cpuMs") is not None else "-"
                rows.append("| %s | %s | %s | %.0f | %s | %.0f | %s | %s |" % (
                    name, run["path"], run["page"], task["ms"], cpu, task["start"] - run["phases"]["window"],
                    phase(run, task["start"]), what))
    if not rows:
        return lines[:-1] + ["none."]
    return lines + ["| input | path | page | task ms | its CPU time ms (with --trace; far less: it waited for a "
                    "core) | at ms (from the window's start) | phase | where its time went (self time, with "
                    "--trace) |", "|---|---|---|---:|---:|---:|---|---|"] + rows


def main_interactive(args, argv):
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    load_before = load_average()
    t0 = time.perf_counter()
    if not args.before:
        args.before = subprocess.run(["git", "-C", ROOT, "merge-base", "HEAD", "main"], check=True,
                                     stdout=subprocess.PIPE, text=True).stdout.strip()[:12]
    before_root = before_tree(args)
    results = {name: run_interactive(args, name, before_root) for name in args.inputs.split(",")}
    budget = args.frame_budget or 100
    lines = ["# The page before and after the worker (issue 30)", "",
             "- Command: `python3 Python/benchmark_web.py %s`" % " ".join(argv),
             "- Started %s, %.0f s; load average %s before, %s after" % (
                 started, time.perf_counter() - t0, load_before, load_average()),
             "- Machine: nproc %d (%s); Chromium headless, SwiftShader; canvas %s" % (
                 os.cpu_count() or 0, cpu_model(), args.size),
             ("- before: `%s`'s page (the viewer on the main thread, where that page has no worker); after: "
              "this tree's (the viewer in a worker, frame budget %d ms); the same WebAssembly module"
              % (args.before, budget)) if before_root else
             "- after: this tree's page (the viewer in a worker, frame budget %d ms) only (`--before none`)"
             % budget, "",
             "| input | path | page | first visible answer ms, median (max) | full level ms, median | "
             "drag frame ms, median | drag frames/s | drag level / sample distance | longest main-thread task ms |"
             + (" still frame ms, median | drag / still | steady drag frame ms, median (frames) | steady drag / still |"
                if args.stills else ""),
             "|---|---|---|---:|---:|---:|---:|---|---:|" + ("---:|---:|---:|---:|" if args.stills else "")]
    if args.scene:
        lines[5:5] = ["- Drag and still frames: skin -500 at opacity 0.3 over bone 400 (`--scene skin-bone`)"]
    for name, r in results.items():
        for run in r["runs"]:
            firsts = [c["firstMs"] for c in run["changes"]]
            fulls = [c["fullMs"] for c in run["changes"]]
            d = run["drag"]
            how = "-"
            if d.get("levels") is not None:
                how = ("levels %s" % d["levels"]) if run["path"] == "cpu" else \
                    ("distance %s" % ", ".join("%.2g" % s for s in d["sampleDistances"]) +
                     ("; volume level %s" % ", ".join(str(k) for k in d["gpuLevels"])
                      if d.get("gpuLevels") else ""))
            row = "| %s | %s | %s | %.0f (%.0f) | %.0f | %.0f | %s | %s | %.0f |" % (
                name, run["path"], run["page"], statistics.median(firsts), max(firsts),
                statistics.median(fulls), d["frameMs"] or 0,
                "%.1f" % d["rate"] if d.get("rate") is not None else "-", how, run["longestTaskMs"])
            if args.stills:
                still = (run.get("still") or {}).get("frameMs")
                steady = d.get("steadyMs")
                row += " %s | %s | %s | %s |" % (
                    "%.0f" % still if still else "-",
                    "%.2f" % (d["frameMs"] / still) if still and d["frameMs"] else "-",
                    "%.0f (%d)" % (steady, d["steadyFrames"]) if steady else "-",
                    "%.2f" % (steady / still) if still and steady else "-")
            lines.append(row)
    errors = ["%s %s: %.0f%%" % (name, run["path"], 100 * run["drag"]["predictionError"])
              for name, r in results.items() for run in r["runs"]
              if run["page"].startswith("after") and run["drag"].get("predictionError") is not None
              and run["drag"]["predictionError"] == run["drag"]["predictionError"]]
    lines += ["", "The frame-time model's median error on the drag frames it chose (after): " +
              (", ".join(errors) or "none recorded") + "."]
    lines += first_drag_lines(results)
    lines += long_task_lines(results)
    write_report(lines, args.out)
    return 0


def warm(url):
    """The server's encodings made before the pages: level 3 of /api/volume and each brick of
    /api/bricks (serve.py keeps both), as a server that has served the volume once has them."""
    import urllib.request
    base, _, query = url.partition("/?")
    get = lambda path: urllib.request.urlopen(base + path + ("&" if "?" in path else "?") + query,  # noqa: E731
                                              timeout=3600).read()
    ident = json.loads(get("/api/datasets"))["datasets"][0]["id"]
    get("/api/volume/%s?level=3" % ident)
    count = len(json.loads(get("/api/bricks/%s?level=3" % ident))["ranges"])
    for brick in range(count):
        get("/api/bricks/%s?level=3&ids=%d" % (ident, brick))
    progress("warm: level 3 and its %d bricks encoded" % count)


def main_stream(args, argv):
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    load_before = load_average()
    t0 = time.perf_counter()
    networks = parse_networks(args.networks)
    before_root = before_tree(args) if args.before else ""
    trees = {"page": ROOT, "before": before_root} if before_root else {"page": ROOT}
    modes = ("whole", "before", "stream") if before_root else ("whole", "stream")
    labels = {"whole": "whole level (`?stream=0`)", "before": "streaming, before (`%s`)" % args.before,
              "stream": "**streaming**"}
    lines = ["# The page streaming against the whole level (issue 31)", "",
             "- Command: `python3 Python/benchmark_web.py %s`" % " ".join(argv), "",
             "| input | network | page | first image ms | surfaces at full level ms | whole level ms | bytes "
             "| bytes at full level (level received) |",
             "|---|---|---|---:|---:|---:|---:|---:|"]
    results = []
    for name in args.inputs.split(","):
        with serving(args, name, trees) as urls:
            if args.warm:
                for url in urls.values():
                    warm(url)
            progress("%s: whole and streamed, %s" % (name, args.networks))
            runs = run_script(work_folder(args, "stream-", name), "bench-stream.mjs",
                              {"url": urls["page"], "beforeUrl": urls.get("before"),
                               "size": [int(v) for v in args.size.split("x")],
                               "networks": networks, "repeats": args.repeats})["runs"]
        results.append((name, runs))
        for network in networks:
            whole = {}
            for mode in modes:
                rs = [r for r in runs if r["network"] == network["name"] and r["mode"] == mode]
                med = lambda key: statistics.median(r[key] for r in rs)  # noqa: E731
                if mode == "whole":
                    whole = {key: med(key) for key in ("wholeMs", "bytes")}
                    ratios = ("", "", "")
                else:  # against the whole level's page of the same run
                    ratios = (" (%.2fx)" % (med("fullMs") / whole["wholeMs"]),
                              " (%.2fx)" % (med("wholeMs") / whole["wholeMs"]),
                              " (%.2fx)" % (med("bytes") / whole["bytes"]))
                lines.append("| %s | %s | %s | %.0f | %.0f%s | %.0f%s | %d%s | %d (%.0f%%) |" % (
                    name, network["name"], labels[mode],
                    med("firstMs"), med("fullMs"), ratios[0], med("wholeMs"), ratios[1], med("bytes"),
                    ratios[2], med("bytesAtFull"), 100 * med("receivedAtFull")))
    lines += stream_parts(results)
    lines[3:3] = ["- Started %s, %.0f s; load average %s before, %s after; medians of %d; %s" % (
        started, time.perf_counter() - t0, load_before, load_average(), args.repeats,
        "warm server (--warm: the level and the bricks encoded before the pages)" if args.warm
        else "cold server (each page's first request of the level or a brick has it encoded)"),
        "- Machine: nproc %d (%s); Chromium headless, SwiftShader; CPU path in the worker; canvas %s" % (
        os.cpu_count() or 0, cpu_model(), args.size)]
    write_report(lines, args.out)
    return 0


def stream_parts(results):
    """Where each streamed page's time went (its stats().streamTimes; bench-stream.mjs), run by run."""
    lines = ["", "Where the streamed pages' time went (ms from navigation; the worker's decoding and "
             "writing summed over the bricks; frames: each frame's ms, the part that made and "
             "uploaded the surfaces, its triangles, L0 where some came from level 0; the whole "
             "page's frames for comparison):", "",
             "| input | network | page | level 0 in | first frame | bricks asked | last answer "
             "| last handed over | last written | full level | decode ms | write ms | frames "
             "| whole page's frames |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|"]
    frame = lambda f: "%d (%d, %dk%s)" % (f["ms"], f["buildMs"], f["triangles"] / 1000,  # noqa: E731
                                          " L0" if f["coarse"] else "")
    for name, runs in results:
        for r in runs:
            t = r.get("times")
            if r["mode"] == "whole" or not t:
                continue
            w = t.get("worker") or {}
            whole = [x for x in runs if x["mode"] == "whole" and x["network"] == r["network"]]
            whole_frames = ", ".join("%d (%dk)" % (f["ms"], f["triangles"] / 1000)
                                     for f in (whole[0].get("frames") or [])) if whole else ""
            lines.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                name, r["network"], "before" if r["mode"] == "before" else "this", t.get("level0"),
                t.get("framed"), t.get("requested"), t.get("lastAnswer"), t.get("lastHanded"),
                w.get("lastBricks"), t.get("full"), w.get("decodeMs"), w.get("writeMs"),
                ", ".join(frame(f) for f in w.get("frames", [])), whole_frames))
    return lines


def main_startup(args, argv, networks):
    """The streaming page's requests and marks up to its first image (bench-startup.mjs)."""
    lines = ["# The page's start-up (issue 31's first image)", "",
             "- Command: `python3 Python/benchmark_web.py %s`" % " ".join(argv),
             "- Started %s; load average %s; Chromium headless, SwiftShader; CPU path in the worker; "
             "canvas %s; each run in a fresh context; ms from navigation" % (
                 time.strftime("%Y-%m-%d %H:%M:%S"), load_average(), args.size)]
    trees = {"before": before_tree(args), "after": ROOT} if args.before else {"page": ROOT}
    if args.before:
        lines.append("- before: `%s`'s page, after: this tree's; the same WebAssembly module (this tree's); "
                     "the pages taken in turn for each repeat and network" % args.before)
    lines += ["", "| input | network | page | first image ms (each run) | median | worker ready | level 0 in "
              "| stream set up | first frame answered | (medians, ms from navigation) |",
              "|---|---|---|---|---:|---:|---:|---:|---:|---|"]
    summary = len(lines)
    for name in args.inputs.split(","):
        with serving(args, name, trees) as urls:
            progress("%s: start-up, %s" % (name, args.networks))
            runs = run_script(work_folder(args, "startup-", name), "bench-startup.mjs",
                              {"pages": urls, "size": [int(v) for v in args.size.split("x")],
                               "networks": networks, "repeats": args.repeats})["runs"]
        for network in networks:
            for label in trees:
                rs = [r for r in runs if r["network"] == network["name"] and r["page"] == label]
                mark = lambda r, n: next((m["at"] for m in r["marks"] if m["name"] == n), None)  # noqa: E731
                step = lambda r, k: (r.get("stream") or {}).get(k)  # noqa: E731
                med = lambda values: ("%.0f" % statistics.median(values)  # noqa: E731
                                      if values and None not in values else "-")
                lines.insert(summary, "| %s | %s | %s | %s | %s | %s | %s | %s | %s | |" % (
                    name, network["name"], label, ", ".join(str(r["firstMs"]) for r in rs),
                    med([r["firstMs"] for r in rs]), med([mark(r, "mediso:worker") for r in rs]),
                    med([step(r, "level0") for r in rs]), med([step(r, "begun") for r in rs]),
                    med([step(r, "framed") for r in rs])))
                summary += 1
        for run in runs:
            # the page's marks in time order (the worker's on its own clock: worker-*)
            marks = ", ".join("%s %.0f" % (m["name"][len("mediso:"):], m["at"])
                              for m in sorted(run["marks"], key=lambda m: m["at"]))
            lines += ["", "## %s, %s, %s: first image %d ms (%s)" % (name, run["network"], run["page"],
                                                                     run["firstMs"], marks)]
            w = (run.get("stream") or {}).get("worker")
            if w:
                first = w["frames"][0] if w.get("frames") else {}
                lines += ["", "The worker's stream set-up ms (buffers, setStreamingVolume, "
                          "setCoarseVolume): %s; its first frame began at %s ms and took %s ms (%s making "
                          "and uploading the surfaces)" % (", ".join(str(v) for v in w.get("setupMs", [])),
                                                           first.get("at"), first.get("ms"), first.get("buildMs"))]
            tasks = [t for t in run.get("longTasks") or [] if t["at"] < run["firstMs"]]
            lines += ["", "The main thread's long tasks before the first image (at ms, for ms): %s" % (
                ", ".join("%d for %d" % (t["at"], t["ms"]) for t in tasks) or "none")]
            lines += ["", "| request | sent | response | end | bytes | encoding |", "|---|---:|---:|---:|---:|---|"]
            for r in sorted(run["requests"], key=lambda r: r["sentMs"]):
                if "ids=" in r["url"] or r["sentMs"] > run["firstMs"]:
                    continue  # the bricks, and what came after the first image
                lines.append("| %s | %s | %s | %s | %d | %s |" % (
                    r["url"].split("&token")[0], r["sentMs"], r["responseMs"], r["endMs"], r["bytes"],
                    r.get("encoding") or ""))
    write_report(lines, args.out)
    return 0


def parse_networks(text):
    """MBIT/LATENCY_MS or loopback, comma-separated, as bench-stream.mjs and bench-startup.mjs take them."""
    networks = []
    for n in text.split(","):
        if n == "loopback":
            networks.append({"name": "loopback"})
        else:
            mbps, latency = n.split("/")
            networks.append({"name": "%s Mbit/s, %s ms" % (mbps, latency), "mbps": float(mbps),
                             "latencyMs": float(latency)})
    return networks


def main_bricks(args, argv):
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    load_before = load_average()
    t0 = time.perf_counter()
    stills = args.stills or 6  # --stills, 6 by default here
    configs = [{"name": "one texture", "query": ""}]
    for spec in args.limits.split(","):
        limit, _, budget = spec.partition("/")
        query = "&maxTextureSize=" + limit + ("&gpuBudgetMB=" + budget if budget else "")
        what = "limit " + limit + (", " + budget + " MB" if budget else "")
        configs += [{"name": what + ": pool", "query": query},
                    {"name": what + ": per brick", "query": query + "&brickPool=0"}]
    results = {}
    for name in args.inputs.split(","):
        with serving(args, name, {"page": ROOT}) as urls:
            lo, hi = (-1000, 1100) if name.startswith("phantom:") else (-1000, 2000)
            isovalues = [lo + (hi - lo) * (i + 1) / (args.sweep + 1) for i in range(args.sweep)]
            # bone first (the warm-up change), then the sweep in a turning order
            isovalues = [400] + isovalues[::2] + isovalues[1::2]
            config = {"url": urls["page"], "size": [int(v) for v in args.size.split("x")], "configs": configs,
                      "isovalues": isovalues, "stills": stills}
            progress("%s: %d configurations, %d changes and %d still frames each"
                     % (name, len(configs), len(isovalues) - 1, stills))
            results[name] = run_script(work_folder(args, "bricks-", name), "bench-bricks.mjs", config)
    lines = ["# The page's GPU path: one texture, the brick pool, per-brick pyramids (issue 31)", "",
             "- Command: `python3 Python/benchmark_web.py %s`" % " ".join(argv),
             "- Started %s, %.0f s; load average %s before, %s after" % (
                 started, time.perf_counter() - t0, load_before, load_average()),
             "- Machine: nproc %d (%s); Chromium headless, SwiftShader; canvas %s; the viewer in its worker" % (
                 os.cpu_count() or 0, cpu_model(), args.size), "",
             "| input | kept as | bricks (active, pool slots, pyramids built) | change to full level ms, "
             "median | / one texture | its build ms | still frame ms, median | / one texture | primitives (last) |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|"]
    for name, r in results.items():
        dense = r["runs"][0]
        for run in r["runs"]:
            s = run["stats"]
            kept = "%d (%d, %d, %d)" % (s["bricks"], s["activeBricks"], s["poolSlots"],
                                        s["brickPyramidBuilds"]) if s["bricks"] else "-"
            if s["path"] != "gpu":
                kept += " (fell back to the %s path)" % s["path"]
            lines.append("| %s | %s | %s | %.0f | %.2fx | %.0f | %.0f | %.2fx | %d |" % (
                name, run["name"], kept, run["changeMs"], run["changeMs"] / dense["changeMs"],
                run["buildMs"], run["still"]["frameMs"], run["still"]["frameMs"] / dense["still"]["frameMs"],
                s["primitives"]))
    write_report(lines, args.out)
    return 0


def main_fullframe(args, argv):
    """The CPU path's full-level frame, part by part (Testing/Web/bench-fullframe.mjs), for the
    module of --wasm and, with --base-wasm, another one, pages alternated in one Chromium."""
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    load_before = load_average()
    t0 = time.perf_counter()
    modules = {}
    for i, spec in enumerate(filter(None, args.base_wasm.split(","))):
        label, _, folder = spec.rpartition("=")
        modules[label or ("base" if i == 0 else "base%d" % i)] = folder
    modules["this"] = args.wasm
    lines = ["# The full-level frame on SwiftShader, part by part (issue 31)", "",
             "- Command: `python3 Python/benchmark_web.py %s`" % " ".join(argv)]
    table = ["", "Still frames: all the surfaces, nothing uploaded (median of --stills). Upload: the surfaces "
             "set again after none (taken from the cache and uploaded: its buildMs, of which the upload's calls "
             "uploadMs; the frame; the still frame after it), twice. Each surface alone: still frames (median).", "",
             "| input | canvas | module | triangles | still frame ms | upload: buildMs (uploadMs) / frame ms / "
             "next still ms | each surface alone: value (opacity) triangles still ms |",
             "|---|---|---|---:|---:|---|---|"]
    for name in args.inputs.split(","):
        urls = {}
        with contextlib.ExitStack() as stack:
            for label, wasm in modules.items():
                server_args = argparse.Namespace(**vars(args))
                server_args.wasm = wasm
                urls[label] = stack.enter_context(serving(server_args, name, {"page": ROOT}))["page"]
            progress("%s: full frames, %s" % (name, args.sizes))
            runs = run_script(work_folder(args, "fullframe-", name), "bench-fullframe.mjs",
                              {"urls": urls, "sizes": [[int(v) for v in s.split("x")] for s in args.sizes.split(",")],
                               "stills": args.stills or 4, "repeats": args.repeats,
                               "each": not args.base_wasm})["runs"]
        for run in runs:
            table.append("| %s | %s | %s | %d | %.0f (%s) | %s | %s |" % (
                name, "x".join(map(str, run["size"])), run["label"], run["draw"]["triangles"], run["draw"]["ms"],
                ", ".join(map(str, run["draw"]["all"])),
                "; ".join("%d (%d) / %d / %d" % (u["buildMs"], u.get("uploadMs", 0), u["ms"], u["next"])
                          for u in run["upload"]),
                "; ".join("%g (%g) %dk %.0f" % (e["value"], e["opacity"], e["draw"]["triangles"] / 1000,
                                                e["draw"]["ms"]) for e in run["each"])))
    lines += ["- Started %s, %.0f s; load average %s before, %s after; %d run(s) of each page" % (
        started, time.perf_counter() - t0, load_before, load_average(), args.repeats),
        "- Machine: nproc %d (%s); Chromium headless, SwiftShader; CPU path in the worker, the level whole "
        "(`?stream=0`); modules: %s" % (os.cpu_count() or 0, cpu_model(),
                                        ", ".join("%s `%s`" % kv for kv in modules.items()))]
    write_report(lines + table, args.out)
    return 0


def main(argv):
    args = parse_args(argv)
    if args.fullframe:
        if args.inputs == "ct,ct512":
            args.inputs = "ct512,phantom:512:noise=40"
        return main_fullframe(args, argv)
    if args.bricks:
        if args.inputs == "ct,ct512":
            args.inputs = "ct"
        return main_bricks(args, argv)
    if args.startup:
        if args.inputs == "ct,ct512":
            args.inputs = "ct"
        return main_startup(args, argv, parse_networks(args.networks))
    if args.stream:
        if args.inputs == "ct,ct512":
            args.inputs = "ct512,phantom:512:noise=40"
        return main_stream(args, argv)
    if args.interactive:
        if args.inputs == "ct,ct512":
            args.inputs = "phantom:256,ct"
        return main_interactive(args, argv)
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    load_before = load_average()
    t0 = time.perf_counter()
    results = {name: run_input(args, name) for name in args.inputs.split(",")}
    chromium = subprocess.run(["/usr/bin/chromium", "--version"], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, text=True).stdout.strip()
    lines = ["# The web client against vtk.js", "",
             "- Command: `python3 Python/benchmark_web.py %s`" % " ".join(argv),
             "- Started %s, %.0f s; load average %s before, %s after" % (
                 started, time.perf_counter() - t0, load_before, load_average()),
             "- Machine: nproc %d (%s); %s headless, software WebGL2 (SwiftShader)" % (
                 os.cpu_count() or 0, cpu_model(), chromium),
             "- Canvas %s; %d isovalues per input, the three methods in turn" % (args.size, args.sweep), "",
             "| input | method | median change + frame ms | min | max | / vtk.js | first image ms | "
             "elements (median) |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for name, r in results.items():
        medians = {m: statistics.median(c["ms"] for c in r["methods"][m]["changes"]) for m in r["methods"]}
        labels = {"gpu": "ours, GPU path (WebGL2 core)",
                  "cpu": "ours, CPU path (BlockLOD wasm, level 3, %s thread(s))"
                         % r["methods"]["cpu"].get("threads", "?"),
                  "vtkjs": "vtk.js vtkImageMarchingCubes + renderer (1 thread)"}
        for m in ("gpu", "cpu", "vtkjs"):
            changes = r["methods"][m]["changes"]
            key = "primitives" if m == "gpu" else "triangles"
            elements = statistics.median(c.get(key, 0) for c in changes)
            lines.append("| %s %s | %s | %.1f | %.1f | %.1f | %.2fx | %.0f | %d %s |" % (
                name, "x".join(map(str, r["header"]["dims"])), labels[m], medians[m],
                min(c["ms"] for c in changes), max(c["ms"] for c in changes),
                medians[m] / medians["vtkjs"], r["methods"][m]["firstImageMs"], elements,
                "cells" if m == "gpu" else "triangles"))
    lines += ["", "Where the time goes (medians over the sweep). GPU path: the pyramid's build within a "
              "change (its passes and the read-back of its total, which waits for them). CPU path: the "
              "extraction and the upload of its triangles. vtk.js: `vtkImageMarchingCubes` alone. "
              "Draw-only: a frame of the same surface with nothing rebuilt.", "",
              "| input | method | change + frame ms | build / extract ms | draw-only frame ms | elements |",
              "|---|---|---:|---:|---:|---:|"]
    for name, r in results.items():
        for m in ("gpu", "cpu", "vtkjs"):
            changes = r["methods"][m]["changes"]
            med = lambda key: statistics.median(c.get(key, 0) for c in changes)  # noqa: E731
            build = med("extractMs") if m == "vtkjs" else med("buildMs")
            draw = "%.1f" % med("drawMs")
            elements = med("primitives") if m == "gpu" else med("triangles")
            lines.append("| %s | %s | %.1f | %.1f | %s | %d %s |" % (
                name, m, med("ms"), build, draw, elements, "cells" if m == "gpu" else "triangles"))
    lines += ["", "| input | volume's raw bytes | bytes the page received before its first image "
              "(the volume, once) | / raw | bytes sent + received during the sweep (page's count) |",
              "|---|---:|---:|---:|---:|"]
    for name, r in results.items():
        gpu = r["methods"]["gpu"]
        during = (gpu["bytesSentAfter"] - gpu["bytesSent"]) + (gpu["bytesReceivedAfter"] - gpu["bytesReceived"])
        lines.append("| %s | %d | %d | %.2fx | %d |" % (
            name, r["raw_bytes"], gpu["bytesReceived"], gpu["bytesReceived"] / r["raw_bytes"], during))
    write_report(lines, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
