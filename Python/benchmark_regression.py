#!/usr/bin/env python3
"""Paired no-regression benchmark of vtkHistoPyramidIsoMapper: this build against an earlier commit.

    python3 Python/benchmark_regression.py [--baseline-commit ffba109] [--rounds 3]
        [--inputs ct,ct512,phantom256] [--windows 1920x1080,1024x768] [--frames 90] [--sweep 30]
        [--methods hp] [--out FILE.md]

Both builds' BenchmarkHistoPyramidIsoMapper run the same protocol (Python/benchmark_isomapper.py's:
rotation frames of 1 degree per isovalue, the isovalue sweep with change + frame), one process per
(build, input, round), the builds alternating and the order flipping every round, so a load that
drifts on a shared machine falls on both alike. The baseline is built once, from a git worktree of
--baseline-commit in build-baseline/ (or give --baseline-binary). For every (input, window,
measure) the table gives both medians and the median, min and max over the rounds of the per-round
ratio this / baseline: below 1 is faster. Not a test: timings go to tables, never to ctest.
"""
import argparse
import os
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchmark_common import (ROOT, cpu_model, data_file, load_average, progress_printer,  # noqa: E402
                              result_records, write_report)

progress = progress_printer("regression")


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--baseline-commit", default="ffba109",
                   help="the commit to compare with (default ffba109: before the portable GPU core)")
    p.add_argument("--baseline-binary", default="",
                   help="its BenchmarkHistoPyramidIsoMapper (default: build it in build-baseline/)")
    p.add_argument("--binary", default=os.path.join(ROOT, "build", "bin",
                                                    "BenchmarkHistoPyramidIsoMapper"))
    p.add_argument("--inputs", default="ct,ct512,phantom256")
    p.add_argument("--windows", default="1920x1080,1024x768")
    p.add_argument("--frames", type=int, default=90, help="rotation frames per isovalue")
    p.add_argument("--sweep", type=int, default=30, help="isovalues in the sweep")
    p.add_argument("--isovalues", default="-500,400", help="rotation isovalues")
    p.add_argument("--methods", default="hp", help="hp, and optionally hpbox (quads/boxes only)")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--zoom", type=float, default=1.0,
                   help="camera zoom (e.g. 30: cells wider than the largest point, quads)")
    p.add_argument("--out", default="", help="also write the table (markdown) here")
    return p.parse_args(argv)


def build_baseline(commit):
    """A worktree of `commit` in build-baseline/src, built there; returns its benchmark binary."""
    where = os.path.join(ROOT, "build-baseline")
    src = os.path.join(where, "src")
    binary = os.path.join(where, "build", "bin", "BenchmarkHistoPyramidIsoMapper")
    if not os.path.isdir(src):
        progress("adding a worktree of %s in %s" % (commit, src))
        subprocess.run(["git", "-C", ROOT, "worktree", "add", "--detach", src, commit], check=True)
    build = os.path.join(where, "build")
    if not os.path.isfile(os.path.join(build, "CMakeCache.txt")):
        subprocess.run(["cmake", "-S", src, "-B", build, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release"],
                       check=True, stdout=subprocess.DEVNULL)
    progress("building the baseline's benchmark (%s)" % commit)
    subprocess.run(["cmake", "--build", build, "-j2", "--target", "BenchmarkHistoPyramidIsoMapper"],
                   check=True, stdout=subprocess.DEVNULL)
    return binary


def ct_path():
    return data_file("ct_head.mha")


def run(binary, name, args):
    command = [os.path.join(ROOT, "Testing", "Scripts", "with-xvfb.sh"), binary, "--input", name,
               "--ct", ct_path(), "--frames", str(args.frames), "--sweep", str(args.sweep),
               "--windows", args.windows, "--isovalues=" + args.isovalues,
               "--methods", args.methods, "--zoom", str(args.zoom)]
    env = dict(os.environ, VTK_SMP_BACKEND_IN_USE="STDThread")
    out = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    records = result_records(out.stdout)
    if out.returncode != 0:
        progress("%s %s exited %d:\n%s" % (binary, name, out.returncode, out.stdout[-2000:]))
    return records


def measures(records):
    """{(window, measure, method): seconds} of one run."""
    got = {}
    for r in records:
        if r["kind"] == "rotation" and r["method"] != "fe":
            got[(r["window"], "rotation iso %g" % r["iso"], r["method"])] = r["median_s"]
        elif r["kind"] == "sweep" and r["method"] != "fe":
            got[(r["window"], "change+frame", r["method"])] = r["median_s"]
            got[(r["window"], "build", r["method"])] = r.get("build_median_s", float("nan"))
    return got


def main(argv):
    args = parse_args(argv)
    baseline = args.baseline_binary or build_baseline(args.baseline_commit)
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    load_before = load_average()
    t0 = time.perf_counter()
    results = {}  # (input, window, measure, method) -> {"new": [...], "old": [...]}
    for name in args.inputs.split(","):
        for k in range(args.rounds):
            order = [("new", args.binary), ("old", baseline)]
            if k % 2:
                order.reverse()
            for label, binary in order:
                progress("%s round %d/%d: %s" % (name, k + 1, args.rounds, label))
                for key, seconds in measures(run(binary, name, args)).items():
                    entry = results.setdefault((name,) + key, {"new": [], "old": []})
                    entry[label].append(seconds)
    wall = time.perf_counter() - t0
    lines = ["# No-regression run: this build against %s" % args.baseline_commit, "",
             "- Command: `python3 Python/benchmark_regression.py %s`" % " ".join(argv),
             "- Started %s, %.0f s; load average %s before, %s after (shared machine)"
             % (started, wall, load_before, load_average()),
             "- Machine: nproc %d (%s); llvmpipe under Xvfb; STDThread" % (os.cpu_count() or 0,
                                                                          cpu_model()),
             "- %d rounds, builds alternating (order flipped every round); rotation %d frames per "
             "isovalue, sweep %d isovalues; camera zoom %g" % (args.rounds, args.frames, args.sweep,
                                                              args.zoom), "",
             "| input | window | measure | method | this (median s) | baseline (median s) | "
             "ratio, median of rounds | min | max |",
             "|---|---|---|---|---:|---:|---:|---:|---:|"]
    worst = 0.0
    for key in sorted(results):
        entry = results[key]
        pairs = list(zip(entry["new"], entry["old"]))
        if not pairs:
            continue
        ratios = [a / b for a, b in pairs if b > 0]
        med = statistics.median(ratios)
        if key[2] != "build":
            worst = max(worst, med)
        lines.append("| %s | %s | %s | %s | %.4f | %.4f | %.3f | %.3f | %.3f |" % (
            key[0], key[1], key[2], key[3], statistics.median(entry["new"]),
            statistics.median(entry["old"]), med, min(ratios), max(ratios)))
    lines += ["", "Largest median ratio (rotation and change+frame): %.3f (target: at most 1.05)"
              % worst]
    write_report(lines, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
