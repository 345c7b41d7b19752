#!/usr/bin/env python3
"""vtkHistoPyramidIsoMapper benchmark (issue 4): GPU isosurface rendering against its peers.

    python3 Python/benchmark_isomapper.py [--inputs ct,ct512,phantom256] [--frames 360]
        [--sweep 95] [--windows 1920x1080,1024x768] [--isovalues=-500,400]
        [--rc-factors 0.5[,1.0]] [--methods hp,rc,fe] [--images DIR] [--out FILE.md]
        [--json FILE.json] [--binary build/bin/BenchmarkHistoPyramidIsoMapper]
        [--interactive-budget 0.1 [--opacity 0.3 --together]]

Runs the C++ program BenchmarkHistoPyramidIsoMapper (the plugin's classes are not Python-wrapped)
under its own Xvfb (Testing/Scripts/with-xvfb.sh), one process per input, with
VTK_SMP_BACKEND_IN_USE=STDThread, and turns its "bench-result:" lines into markdown tables:

1. Rotation: the surface at one isovalue, the camera turned 1 degree (azimuth) per frame, after a
   first render and one warm-up render; every frame is Render() + glFinish. Per frame min and
   median seconds, fps = 1 / median, and our median / the ray caster's.
2. Isovalue sweep: --sweep isovalues equidistant across the data range with its ends left out
   (lo + (hi - lo) * i / (N + 1), i = 1..N); time per change + frame (FlyingEdges: re-extract +
   render; the volume mappers: set the isovalue + render). The methods' scenes are open side by
   side and take each isovalue in turn (the order rotating every step), so each step gives our
   time over FlyingEdges + PolyDataMapper's taken moments apart: the target is judged on the
   median of those paired ratios (the ratio of the two medians is shown beside it).
3. GPU memory of vtkHistoPyramidIsoMapper (GetGPUMemoryBytes) against the volume's bytes, and
   whether camera moves rebuilt the pyramid.

Methods, in the same process: vtkHistoPyramidIsoMapper (GetLastRenderPath() must be the GPU path),
vtkGPUVolumeRayCastMapper in isosurface blend mode (shading on, AutoAdjustSampleDistances off,
SampleDistance = factor x the smallest spacing), vtkFlyingEdges3D (normals on) + vtkPolyDataMapper.
With --interactive-budget S (issue 30), every hp rotation is followed by as many interactive
frames (the render window's DesiredUpdateRate 1000, InteractiveFrameBudget S): their median
against the still median, the image sample distances the mapper chose, and the frame-time model's
predicted against measured seconds for the frames it chose; --opacity and --together draw skin
(the first isovalue) at that opacity over bone in one scene.
Ends with the issue's targets: rotation frame time <= 0.5x the ray caster's, isovalue change+frame
<= 0.5x FlyingEdges + PolyDataMapper's, GPU memory <= 1.5x the volume's bytes.
"""
import argparse
import json
import os
import platform
import shlex
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchmark_common import cpu_model, data_file, fmt_s, load_average, table  # noqa: E402

ALL_INPUTS = ("ct", "ct512", "phantom256")
TARGET_ROTATION = 0.5
TARGET_SWEEP = 0.5
TARGET_MEMORY = 1.5
RESULT_TAG = "bench-result: "
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def progress(message):
    print("bench: " + message, flush=True)


def ct_path():
    return data_file("ct_head.mha")


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--inputs", default=",".join(ALL_INPUTS),
                   help="comma list of ct, ct512, phantom256 (or phantomN); default all")
    p.add_argument("--frames", type=int, default=360,
                   help="rotation frames of 1 degree (default 360, the paper's)")
    p.add_argument("--sweep", type=int, default=95, help="isovalues in the sweep (default 95)")
    p.add_argument("--windows", default="1920x1080,1024x768")
    p.add_argument("--isovalues", default="-500,400",
                   help="rotation isovalues (write --isovalues=-500,400)")
    p.add_argument("--methods", default="hp,rc,fe")
    p.add_argument("--rc-factors", default="0.5",
                   help="ray caster SampleDistance as factors of the smallest spacing (default 0.5)")
    p.add_argument("--images", default="", help="save the first rotation frame of each method here")
    p.add_argument("--binary", default=os.path.join(ROOT, "build", "bin",
                                                    "BenchmarkHistoPyramidIsoMapper"))
    p.add_argument("--out", default="", help="write the tables (markdown) to this file")
    p.add_argument("--json", default="", help="write the raw records to this file")
    p.add_argument("--interactive-budget", type=float, default=0.0,
                   help="> 0: interactive rotation frames of hp with this budget (seconds)")
    p.add_argument("--interactive-levels", default="volume,triangles",
                   help="coarser levels interactive hp frames may take: volume (the GPU path on "
                        "a coarse volume level), triangles (Block LOD triangles), both (default) "
                        "or none")
    p.add_argument("--opacity", type=float, default=1.0,
                   help="opacity of the first isovalue (the others opaque)")
    p.add_argument("--together", action="store_true",
                   help="one rotation scene with all the isovalues (skin over bone)")
    return p.parse_args(argv)


def run_input(args, name):
    command = [os.path.join(ROOT, "Testing", "Scripts", "with-xvfb.sh"), args.binary,
               "--input", name, "--ct", ct_path(), "--frames", str(args.frames),
               "--sweep", str(args.sweep), "--windows", args.windows,
               "--isovalues=" + args.isovalues, "--methods", args.methods,
               "--rc-factors", args.rc_factors]
    if args.interactive_budget > 0:
        command += ["--interactive-budget", str(args.interactive_budget),
                    "--interactive-levels", args.interactive_levels]
    if args.opacity != 1.0:
        command += ["--opacity", str(args.opacity)]
    if args.together:
        command += ["--together", "1"]
    if args.images:
        os.makedirs(args.images, exist_ok=True)
        command += ["--images", args.images]
    env = dict(os.environ, VTK_SMP_BACKEND_IN_USE="STDThread")
    records = []
    start = time.perf_counter()
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          env=env) as child:
        for line in child.stdout:
            line = line.rstrip("\n")
            if line.startswith(RESULT_TAG):
                records.append(json.loads(line[len(RESULT_TAG):]))
            else:
                progress("[%s] %s" % (name, line))
    wall = time.perf_counter() - start
    progress("[%s] exit status %d after %.0f s" % (name, child.returncode, wall))
    return child.returncode, records, wall


def fmt_ratio(v):
    return "%.2fx" % v


def margin(ratio, limit):
    if ratio <= limit:
        return "%.0f%% under the limit" % (100.0 * (1.0 - ratio / limit))
    return "%.2fx the limit" % (ratio / limit)


def method_name(r):
    if r["method"] == "hp":
        return "HistoPyramid (ours)"
    if r["method"] == "hpbox":
        return "HistoPyramid, boxes only"
    if r["method"] == "hp1":
        return "HistoPyramid, one pass"
    if r["method"] == "rc":
        return "GPU ray caster, sample %gx" % r["factor"]
    return "FlyingEdges + PolyDataMapper"


def target_row(name, where, ratio, limit):
    """A row of the targets table: measured ratio, met or not, by how much."""
    return [name, where, fmt_ratio(ratio), "yes" if ratio <= limit else "no", margin(ratio, limit)]


def report(args, command, records, failed, started, wall, load_before, load_after):
    lines = []
    out = lines.append
    inputs = [r for r in records if r["kind"] == "input"]
    machine = next((r for r in records if r["kind"] == "machine"), {})
    out("# vtkHistoPyramidIsoMapper benchmark")
    out("")
    out("- Command: `%s`" % command)
    out("- Started %s, %.0f s wall; load average %s before, %s after (shared machine)"
        % (started, wall, load_before, load_after))
    out("- Machine: %s, nproc %d (%s)" % (platform.platform(), os.cpu_count() or 0, cpu_model()))
    out("- OpenGL: %s / %s / %s%s" % (machine.get("gl_vendor", "?"), machine.get("gl_renderer", "?"),
                                       machine.get("gl_version", "?"),
                                       " (software rasteriser: NOT measured on a GPU)"
                                       if "llvmpipe" in machine.get("gl_renderer", "") else ""))
    if inputs:
        i0 = inputs[0]
        out("- VTK %s; vtkSMPTools backend %s, %d threads (VTK_SMP_BACKEND_IN_USE=STDThread)"
            % (i0["vtk"], i0["smp_backend"], i0["smp_threads"]))
    out("- Rotation: %d frames of 1 degree per (input, window, method, isovalue)%s; sweep: %d "
        "isovalues" % (args.frames, "" if args.frames == 360 else
                       " (the paper's protocol is 360: reduced with --frames to fit the run time)",
                       args.sweep) + ("" if args.sweep == 95 else " (the paper's is 95: reduced with --sweep)"))
    for i in inputs:
        out("- Input %s: %s, %s %s, range %g..%g, spacing %s mm, %.1f MB"
            % (i["input"], i["label"], i["dims"], i["type"], i["range"][0], i["range"][1],
               "x".join("%.4g" % s for s in i["spacing"]), i["volume_bytes"] / 2**20))
    for name, why in failed:
        out("- %s: %s" % (name, why))
    dims = {i["input"]: i["dims"] for i in inputs}

    # 1. rotation
    out("")
    out("## Rotation (seconds per frame, Render + glFinish)")
    out("")
    rot = [r for r in records if r["kind"] == "rotation"]
    rows = []
    targets = []
    for r in rot:
        peer = [p for p in rot if p["method"] == "rc" and p["input"] == r["input"]
                and p["window"] == r["window"] and p["iso"] == r["iso"]]
        ours = r["method"] in ("hp", "hp1", "hpbox")
        ratios = " / ".join(fmt_ratio(r["median_s"] / p["median_s"]) for p in peer) \
            if ours else ""
        el = "%d %s" % (r["elements"], "triangles" if r["method"] == "fe" else "cells") \
            if r["elements"] >= 0 else "-"
        rows.append(["%s %s" % (r["input"], dims.get(r["input"], "")), r["window"], "%g" % r["iso"],
                     method_name(r) + (" [%s path]" % r["path"] if ours else ""),
                     r["frames"], fmt_s(r["min_s"]), fmt_s(r["median_s"]),
                     "%.2f" % (1.0 / r["median_s"]), "%.1f" % r["total_s"], el, ratios])
        if r["method"] == "hp":
            for p in peer:
                ratio = r["median_s"] / p["median_s"]
                targets.append(target_row(
                    "rotation <= 0.5x ray caster (sample %gx)" % p["factor"],
                    "%s, %s, iso %g" % (r["input"], r["window"], r["iso"]), ratio, TARGET_ROTATION))
    lines.extend(table(["input", "window", "iso", "method", "frames", "min s", "median s",
                        "fps (1/median)", "total s", "primitives", "ours / ray caster (median)"],
                       rows))

    # 1b. interactive frames (issue 30)
    inter = [r for r in records if r["kind"] == "interactive"]
    if inter:
        out("")
        out("## Interactive frames (seconds per frame, Render + glFinish; budget %g s)"
            % inter[0]["budget_s"])
        out("")
        rows = []
        for r in inter:
            rows.append(["%s %s" % (r["input"], dims.get(r["input"], "")), r["window"],
                         "%g (%d isovalues, first at opacity %g)" % (r["iso"], r["isovalues"],
                                                                     r["opacity"]),
                         r["frames"], fmt_s(r["still_median_s"]), fmt_s(r["median_s"]),
                         "%.2f" % (r["median_s"] / r["still_median_s"]),
                         "%g (%g..%g)" % (r["distance_median"], r["distance_min"],
                                          r["distance_max"]),
                         "%d; GPU volume level frames %d; level median %g, min %g"
                         % (r["triangle_frames"], r.get("volume_level_frames", 0),
                            r["level_median"], r["level_min"]),
                         "%s / %s" % (fmt_s(r["predicted_median_s"]),
                                      fmt_s(r["measured_median_s"])),
                         "%.0f%%" % (100.0 * r["error_median"]),
                         "%.0f%%" % (100.0 * r["within_25"]),
                         "%s at %g" % (fmt_s(r["still_after_s"]), r["still_after_distance"])])
            targets.append(target_row("interactive frame median <= 0.1 s",
                                      "%s, %s" % (r["input"], r["window"]),
                                      r["median_s"] / 0.1, 1.0))
        lines.extend(table(["input", "window", "isovalues", "frames", "still median s",
                            "interactive median s", "interactive / still",
                            "sample distance median (min..max)",
                            "frames as Block LOD triangles",
                            "predicted / measured median s", "median |error|",
                            "frames predicted within 25%", "still frame after"], rows))

    # 2. sweep
    out("")
    out("## Isovalue sweep (seconds per change + frame)")
    out("")
    sw = [r for r in records if r["kind"] == "sweep"]
    rows = []
    for r in sw:
        peer = next((p for p in sw if p["method"] == "fe" and p["input"] == r["input"]
                     and p["window"] == r["window"]), None)
        ratio = r["median_s"] / peer["median_s"] if peer and r["method"] != "fe" else None
        paired = r.get("paired_fe_median")
        rows.append(["%s %s" % (r["input"], dims.get(r["input"], "")), r["window"], method_name(r),
                     "%d (%g..%g)" % (r["n"], r["first_iso"], r["last_iso"]), fmt_s(r["min_s"]),
                     fmt_s(r["median_s"]), fmt_s(r["max_s"]), "%.1f" % r["total_s"],
                     fmt_s(r["extract_median_s"]) if r["method"] == "fe"
                     else ("build " + fmt_s(r["build_median_s"]) +
                           (" (%.0f%% of tiles)" % (100.0 * r["build_tiles_median"])
                            if "build_tiles_median" in r else ""))
                     if "build_median_s" in r else "-",
                     ("%d..%d" % (r["min_elements"], r["max_elements"]))
                     if r["min_elements"] >= 0 else "-",
                     fmt_ratio(ratio) if ratio is not None else "",
                     ("%s (%s..%s; %d of %d steps <= 0.5x)"
                      % (fmt_ratio(paired), fmt_ratio(r["paired_fe_min"]),
                         fmt_ratio(r["paired_fe_max"]), r["paired_fe_at_most_half"], r["n"]))
                     if paired is not None else ""])
        if r["method"] == "hp" and peer:
            # The C++ program pairs every method's steps with FlyingEdges' in the same run.
            targets.append(target_row(
                "change+frame <= 0.5x FlyingEdges + PolyDataMapper (median of paired steps)",
                "%s, %s, sweep of %d" % (r["input"], r["window"], r["n"]), paired, TARGET_SWEEP))
    lines.extend(table(["input", "window", "method", "isovalues", "min s", "median s", "max s",
                        "total s", "FE extract / our build, median s (level-1 tiles drawn)",
                        "primitives", "ours / FE+PDM (medians)",
                        "ours / FE+PDM per step: median (range; steps at the target)"],
                       rows))

    # 3. memory
    out("")
    out("## GPU memory of vtkHistoPyramidIsoMapper")
    out("")
    rows = []
    seen = set()
    for r in rot:
        if r["method"] != "hp" or (r["input"], r["iso"]) in seen:
            continue
        seen.add((r["input"], r["iso"]))
        ratio = r["gpu_bytes"] / r["volume_bytes"]
        s = next((x for x in sw if x["method"] == "hp" and x["input"] == r["input"]), None)
        # The first-hit pass's buffers (10 bytes per pixel of the volume's projection), per window.
        buffers = {x["window"]: x.get("framebuffer_bytes", 0) for x in rot
                   if x["method"] == "hp" and x["input"] == r["input"] and x["iso"] == r["iso"]}
        largest = max(buffers.values()) if buffers else 0
        with_buffers = (r["gpu_bytes"] + largest) / r["volume_bytes"]
        rows.append(["%s %s" % (r["input"], dims.get(r["input"], "")), "%g" % r["iso"],
                     "%.1f" % (r["volume_bytes"] / 2**20), "%.1f" % (r["gpu_bytes"] / 2**20),
                     fmt_ratio(ratio), int(r["builds_during_rotation"]),
                     ("%.1f / %.1f" % (s["gpu_bytes_before"] / 2**20, s["gpu_bytes_after"] / 2**20))
                     if s else "-",
                     ", ".join("%s %.1f" % (w, b / 2**20) for w, b in sorted(buffers.items())),
                     fmt_ratio(with_buffers)])
        targets.append(target_row("GPU memory <= 1.5x volume bytes",
                                  "%s, iso %g" % (r["input"], r["iso"]), ratio, TARGET_MEMORY))
        targets.append(target_row("the same with the first-hit buffers of the largest window",
                                  "%s, iso %g" % (r["input"], r["iso"]), with_buffers,
                                  TARGET_MEMORY))
    lines.extend(table(["input", "iso", "volume MB", "GPU MB", "GPU / volume",
                        "pyramid builds during rotation", "GPU MB before / after sweep",
                        "first-hit buffers MB per window", "with the largest / volume"], rows))
    ends = [r for r in records if r["kind"] == "end"]
    if ends:
        out("")
        out("Peak RSS per child process: " + ", ".join(
            "%s %.0f MB" % (i["input"], e["peak_rss_mb"]) for i, e in zip(inputs, ends)) + ".")

    out("")
    out("## Targets")
    out("")
    lines.extend(table(["target", "where", "measured", "met", "by how much"], targets))
    return lines


def main():
    argv = sys.argv[1:]
    args = parse_args(argv)
    command = "python3 " + " ".join(shlex.quote(a) for a in ["Python/benchmark_isomapper.py"] + argv)
    if not os.path.exists(args.binary):
        progress("no %s: build it (Scripts/bootstrap.sh or ninja -C build "
                 "BenchmarkHistoPyramidIsoMapper)" % args.binary)
        return 2
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    load_before = load_average()
    progress("command: " + command)
    progress("machine: nproc %d, %s, load average %s" % (os.cpu_count() or 0, cpu_model(),
                                                          load_before))
    t0 = time.perf_counter()
    records, failed = [], []
    for name in [s.strip() for s in args.inputs.split(",") if s.strip()]:
        if name.startswith("ct") and not os.path.exists(ct_path()):
            failed.append((name, "skipped: no CT at %s (run Python/fetch_data.py)" % ct_path()))
            continue
        rc, recs, wall = run_input(args, name)
        records += recs
        if rc != 0:
            failed.append((name, "child exit status %d (a frame not drawn by the GPU path, or a "
                                 "crash: see the log)" % rc))
    lines = report(args, command, records, failed, started, time.perf_counter() - t0, load_before,
                   load_average())
    text = "\n".join(lines) + "\n"
    sys.stdout.write("\n" + text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)
        progress("wrote " + args.out)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(dict(command=command, records=records, failed=failed), f)
        progress("wrote " + args.json)
    return 0 if records and not failed else 1


if __name__ == "__main__":
    sys.exit(main())
