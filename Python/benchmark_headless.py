#!/usr/bin/env python3
"""mediso-render against the ParaView mapper on the paper's protocol, in one run.

    python3 Python/benchmark_headless.py [--inputs ct,ct512,phantom256]
        [--windows 1920x1080,1024x768] [--frames 360] [--sweep 95] [--isovalues=-500,400]
        [--rounds 2] [--api es] [--out FILE.md]

The same GPU core twice: mediso-render (its own EGL context, no X, no VTK) and
vtkHistoPyramidIsoMapper in a VTK window (BenchmarkHistoPyramidIsoMapper --methods hp, under
Xvfb), on the same volumes (the benchmark program writes ct512 and phantom256 as MetaImages for
mediso-render), the same windows, isovalues, camera (VTK's ResetCamera, 1-degree azimuth steps)
and sweep (isovalues lo + (hi - lo) i / (N + 1)); the view from the front (-y), head up (+z). The two programs alternate, the order flipping
every round. Prints, per input and window, the median frame of the rotation and the median
isovalue change + frame of each, and mediso-render's over the mapper's. Runs on whatever GL the
machine has: on llvmpipe here, and unchanged on a GPU machine with only a driver (give --mapper ""
there: no ParaView).
"""
import argparse
import os
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchmark_common import (ROOT, cpu_model, data_dir, load_average, progress_printer,  # noqa: E402
                              result_records, write_report)

progress = progress_printer("headless")


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--inputs", default="ct,ct512,phantom256")
    p.add_argument("--windows", default="1920x1080,1024x768")
    p.add_argument("--frames", type=int, default=360)
    p.add_argument("--sweep", type=int, default=95)
    p.add_argument("--isovalues", default="-500,400")
    p.add_argument("--rounds", type=int, default=2)
    p.add_argument("--api", default="es", help="mediso-render's context: es or gl")
    p.add_argument("--render", default=os.path.join(ROOT, "build", "bin", "mediso-render"))
    p.add_argument("--mapper", default=os.path.join(ROOT, "build", "bin",
                                                    "BenchmarkHistoPyramidIsoMapper"),
                   help="the mapper's benchmark program; empty: mediso-render only")
    p.add_argument("--volumes", default="",
                   help="folder of ct512.mha, phantom256.mha (default: written to build/bench-volumes)")
    p.add_argument("--out", default="")
    return p.parse_args(argv)


def volume_for(args, name):
    """mediso-render's arguments for the input: a file, or on a machine with no mapper
    (a GPU machine with only a driver) the volume mediso-render makes itself."""
    if name == "ct":
        return [os.path.join(data_dir(), "ct_head.mha")]
    folder = args.volumes or os.path.join(ROOT, "build", "bench-volumes")
    path = os.path.join(folder, name + ".mha")
    if not os.path.isfile(path):
        if not args.mapper:
            if name == "ct512":
                return volume_for(args, "ct") + ["--resample", "512x512x216"]
            if name.startswith("phantom") and name[len("phantom"):].isdigit():
                return ["phantom:" + name[len("phantom"):]]
            raise SystemExit("no %s: give --volumes with %s.mha" % (path, name))
        os.makedirs(folder, exist_ok=True)
        progress("writing %s" % path)
        subprocess.run([args.mapper, "--input", name, "--ct", volume_for(args, "ct")[0],
                        "--write-input", path], check=True, stdout=subprocess.DEVNULL)
    return [path]


def run_render(args, volume, window, isovalue, rotate, sweep):
    """{protocol: (median ms, build ms, primitives)} of one mediso-render run."""
    # The mapper's benchmark views the volume from the front (-y), head up (+z): from VTK's
    # default camera (+z, up +y) that is an elevation of -90 degrees.
    command = [args.render] + volume + ["--iso", "%g" % isovalue, "--size", window,
                                        "--api", args.api, "--elevation", "-90"]
    if rotate:
        command += ["--rotate", str(rotate)]
    if sweep:
        command += ["--sweep", str(sweep)]
    out = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if out.returncode != 0:
        raise SystemExit("mediso-render failed:\n" + out.stdout)
    rows = {}
    for line in out.stdout.splitlines():
        fields = line.split()
        if fields and fields[0] in ("rotation", "sweep") and len(fields) == 8:
            rows[fields[0]] = (float(fields[4]), fields[6], int(fields[7]))
        elif line.startswith("mediso-render:"):
            rows["context"] = line
    return rows


def run_mapper(args, name, window):
    command = [os.path.join(ROOT, "Testing", "Scripts", "with-xvfb.sh"), args.mapper, "--input", name,
               "--ct", volume_for(args, "ct")[0], "--frames", str(args.frames), "--sweep",
               str(args.sweep), "--windows", window, "--isovalues=" + args.isovalues,
               "--methods", "hp"]
    env = dict(os.environ, VTK_SMP_BACKEND_IN_USE="STDThread")
    out = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    records = result_records(out.stdout)
    rows = {}
    for r in records:
        if r["kind"] == "rotation":
            rows[("rotation", r["iso"])] = 1000.0 * r["median_s"]
        elif r["kind"] == "sweep":
            rows[("sweep", None)] = 1000.0 * r["median_s"]
        elif r["kind"] == "machine":
            rows["gl"] = r.get("gl_renderer", "?") + " / " + r.get("gl_version", "?")
    if out.returncode != 0:
        progress("the mapper's benchmark exited %d" % out.returncode)
    return rows


def main(argv):
    args = parse_args(argv)
    isovalues = [float(v) for v in args.isovalues.split(",")]
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    load_before = load_average()
    t0 = time.perf_counter()
    results = {}  # (input, window, measure) -> {"render": [...], "mapper": [...]}
    context, gl = "", ""
    for name in args.inputs.split(","):
        volume = volume_for(args, name)
        for window in args.windows.split(","):
            for k in range(args.rounds):
                order = ["render", "mapper"] if args.mapper else ["render"]
                if k % 2:
                    order.reverse()
                for who in order:
                    progress("%s %s round %d/%d: %s" % (name, window, k + 1, args.rounds, who))
                    if who == "render":
                        for i, iso in enumerate(isovalues):
                            rows = run_render(args, volume, window, iso, args.frames,
                                              args.sweep if i == 0 else 0)
                            context = rows.get("context", context)
                            results.setdefault((name, window, "rotation iso %g" % iso),
                                               {"render": [], "mapper": []})["render"].append(
                                rows["rotation"][0])
                            if i == 0:
                                results.setdefault((name, window, "change+frame"),
                                                   {"render": [], "mapper": []})["render"].append(
                                    rows["sweep"][0])
                    else:
                        rows = run_mapper(args, name, window)
                        gl = rows.get("gl", gl)
                        for iso in isovalues:
                            if ("rotation", iso) in rows:
                                results.setdefault((name, window, "rotation iso %g" % iso),
                                                   {"render": [], "mapper": []})["mapper"].append(
                                    rows[("rotation", iso)])
                        if ("sweep", None) in rows:
                            results.setdefault((name, window, "change+frame"),
                                               {"render": [], "mapper": []})["mapper"].append(
                                rows[("sweep", None)])
    wall = time.perf_counter() - t0
    lines = ["# mediso-render against vtkHistoPyramidIsoMapper", "",
             "- Command: `python3 Python/benchmark_headless.py %s`" % " ".join(argv),
             "- Started %s, %.0f s; load average %s before, %s after" % (started, wall, load_before,
                                                                        load_average()),
             "- Machine: nproc %d (%s)" % (os.cpu_count() or 0, cpu_model()),
             "- mediso-render: %s" % context.replace("mediso-render: ", ""),
             "- the mapper (in a VTK window under Xvfb): %s" % (gl or "not run"),
             "- rotation: %d frames of 1 degree per isovalue; sweep: %d isovalues; %d rounds, the "
             "programs alternating" % (args.frames, args.sweep, args.rounds), "",
             "| input | window | measure | mediso-render median ms | mapper median ms | ratio |",
             "|---|---|---|---:|---:|---:|"]
    for key in sorted(results):
        r = results[key]
        a = statistics.median(r["render"]) if r["render"] else float("nan")
        b = statistics.median(r["mapper"]) if r["mapper"] else float("nan")
        lines.append("| %s | %s | %s | %.1f | %.1f | %.2f |" % (key[0], key[1], key[2], a, b,
                                                              a / b if b == b and b > 0 else
                                                              float("nan")))
    write_report(lines, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
