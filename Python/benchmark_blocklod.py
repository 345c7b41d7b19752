"""BlockLODContour benchmark (pvpython): the plugin's CPU isosurface filter against its peers.

    pvpython Python/benchmark_blocklod.py [--inputs ct,ct512,phantom256,phantom512]
        [--repeats N] [--quick] [--sweep N] [--isovalues=-500,400] [--backend STDThread|Sequential]
        [--threads 2] [--out FILE.md] [--json FILE.json] [--plugin PATH] [--marching-cubes]

Measures, on the real head CT (256x256x108 int16), the CT resampled (linear) to 512x512x216, and
the plugin's MedicalPhantom at 256^3 and 512^3, with a fixed SMP backend and thread count:

1. Cold extraction (a fresh filter and a new isovalue: includes the block min/max pass and the
   estimates) at levels 0..3, warm isovalue changes (a filter that already ran on the input: block
   ranges kept, the (isovalue, level) pair not cached) and cache hits, against vtkFlyingEdges3D
   (normals on, scalars off) and ParaView's Contour (normals on), with the ratio of every time to
   vtkFlyingEdges3D's in the same run.
2. The paper's isovalue sweep: 95 equidistant isovalues across the data range (ends excluded) at
   each level, one update per isovalue change, and the same sweep with vtkFlyingEdges3D.
3. The estimator: EstimatedTriangles/EstimatedMB of a pair, made before that pair is extracted
   (by a second filter updated at another level of the isovalue: with one level known it cannot
   scale, so these are sampled estimates), against the actual output; EstimatedSeconds of the
   extracting update (predicted from exact counts and the cost model); and the paper's constant
   (2 triangles per cube of every active 8x8x8 block, active blocks counted here with numpy).
4. Peak memory: every input runs in its own child process (this script with --child INPUT); the
   peak RSS (VmHWM, reset through /proc/self/clear_refs before every timed call) is recorded per
   call, so each method's peak and its growth over the RSS before the call are isolated.

Ends with the issue's targets: cold level 3 <= 0.6x vtkFlyingEdges3D, warm isovalue change at
level 3 <= 0.3x vtkFlyingEdges3D, level 0 under 10 ms on the 512-wide inputs, estimator within
+-10% for at least 95% of (isovalue, level) pairs with 1000 or more triangles.

Times are wall-clock seconds of one UpdatePipeline() (proxies) or Update() (VTK filters); the
BlockLODContour times include ParaView's proxy overhead, which the cache-hit row bounds.
"""
import argparse
import json
import math
import os
import platform
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from machine_info import cpu_model, load_average  # noqa: E402

ALL_INPUTS = ("ct", "ct512", "phantom256", "phantom512")
LARGE_INPUTS = ("ct512", "phantom512")
DEFAULT_ISOVALUES = (-500.0, 400.0)  # skin and bone, HU, for the CT and the phantom alike
PAPER_SWEEP = 95
QUICK_SWEEP = 19
TARGET_COLD = 0.6
TARGET_WARM = 0.3
TARGET_LEVEL0_S = 0.010
TARGET_EST_TOL = 0.10
TARGET_EST_FRACTION = 0.95
TARGET_EST_MIN_TRIANGLES = 1000
RESULT_TAG = "bench-result: "


def progress(message):
    print("bench: " + message, flush=True)


def data_dir():
    return os.environ.get("MEDISO_DATA_DIR") or os.path.expanduser("~/.cache/medical-isosurfaces")


def ct_path():
    return os.path.join(data_dir(), "ct_head.mha")


def default_plugin():
    here = os.path.dirname(os.path.abspath(__file__))
    try:
        with open(os.path.join(here, "..", "build", "plugin-path.txt")) as f:
            return f.read().strip()
    except OSError:
        return ""


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--inputs", default="",
                        help="comma list of %s (default: all available)" % ", ".join(ALL_INPUTS))
    parser.add_argument("--repeats", type=int, default=0,
                        help="timed runs per measurement (default 5, 3 for the 512-wide inputs)")
    parser.add_argument("--quick", action="store_true",
                        help="sweep %d isovalues instead of %d on every input" % (QUICK_SWEEP, PAPER_SWEEP))
    parser.add_argument("--sweep", type=int, default=0,
                        help="isovalues in the sweep on every input (default %d, and %d on the "
                             "512-wide inputs to keep the run short)" % (PAPER_SWEEP, QUICK_SWEEP))
    parser.add_argument("--isovalues", default="",
                        help="comma list of isovalues for the cold/warm tables "
                             "(default -500,400: skin and bone; write --isovalues=-500,400 "
                             "when the list starts with a minus sign)")
    parser.add_argument("--backend", default="STDThread", help="vtkSMPTools backend")
    parser.add_argument("--threads", type=int, default=2,
                        help="SMP threads (default 2; 1 with the Sequential backend)")
    parser.add_argument("--cache-mb", type=float, default=512.0,
                        help="BlockLODContour CacheMemoryLimit and MemoryBudget, MB (default 512)")
    parser.add_argument("--marching-cubes", action="store_true",
                        help="also time vtkMarchingCubes (single-threaded, slow) in the cold table")
    parser.add_argument("--plugin", default=default_plugin(), help="path of MedicalIsosurfaces.so")
    parser.add_argument("--out", default="", help="write the tables (markdown) to this file")
    parser.add_argument("--json", default="", help="write the raw measurements to this file")
    parser.add_argument("--pvpython", default="",
                        help="interpreter for the child processes (default: pvpython on PATH)")
    parser.add_argument("--child", default="", help=argparse.SUPPRESS)
    parser.add_argument("--child-result", default="", help=argparse.SUPPRESS)
    return parser.parse_args(argv)


def repeats_for(args, name):
    if args.repeats > 0:
        return args.repeats
    return 3 if name in LARGE_INPUTS else 5


def sweep_for(args, name):
    if args.sweep > 0:
        return args.sweep, "--sweep %d" % args.sweep
    if args.quick:
        return QUICK_SWEEP, "--quick"
    if name in LARGE_INPUTS:
        return QUICK_SWEEP, "default for 512-wide inputs (the paper's 95 would take too long here)"
    return PAPER_SWEEP, "the paper's 95"


def isovalues_for(args):
    if args.isovalues:
        return [float(v) for v in args.isovalues.split(",") if v.strip()]
    return list(DEFAULT_ISOVALUES)


# ----------------------------------------------------------------------------------------------
# Memory: peak RSS per call (VmHWM reset through /proc/self/clear_refs, Linux 4.0+)
# ----------------------------------------------------------------------------------------------
class Memory:
    def __init__(self):
        self.peak_kb = 0
        self.can_reset = False
        try:
            with open("/proc/self/clear_refs", "w") as f:
                f.write("5")
            self.can_reset = True
        except OSError:
            pass

    @staticmethod
    def status_kb():
        values = {}
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith(("VmRSS:", "VmHWM:")):
                    values[line.split(":")[0]] = int(line.split()[1])
        return values.get("VmRSS", 0), values.get("VmHWM", 0)

    def begin(self):
        """Before a call: returns the RSS (kB) and resets the high-water mark."""
        rss, hwm = self.status_kb()
        self.peak_kb = max(self.peak_kb, hwm)
        if self.can_reset:
            with open("/proc/self/clear_refs", "w") as f:
                f.write("5")
        return rss

    def end(self, rss_before):
        """After a call: (peak RSS MB during it, peak growth over the RSS before it, MB)."""
        _, hwm = self.status_kb()
        self.peak_kb = max(self.peak_kb, hwm)
        if not self.can_reset:
            return hwm / 1024.0, float("nan")
        return hwm / 1024.0, (hwm - rss_before) / 1024.0

    def overall_mb(self):
        _, hwm = self.status_kb()
        self.peak_kb = max(self.peak_kb, hwm)
        return self.peak_kb / 1024.0


# ----------------------------------------------------------------------------------------------
# Child: all measurements of one input, in its own process
# ----------------------------------------------------------------------------------------------
def block_ranges_numpy(image, array_name):
    """Per-block min and max of the filter's 8x8x8-cell blocks (neighbours share a face of points:
    block b of an axis with n points covers points [8b, min(8b + 8, n - 1)])."""
    import numpy as np
    from vtkmodules.util import numpy_support

    nx, ny, nz = image.GetDimensions()
    a = numpy_support.vtk_to_numpy(image.GetPointData().GetArray(array_name)).reshape(nz, ny, nx)

    def reduce_axis(values, axis, n, func):
        nb = (n - 1 + 7) // 8
        starts = np.arange(nb) * 8
        segments = func.reduceat(values, starts, axis=axis)  # [8b, 8b + 8) and the last to the end
        shared = np.take(values, np.minimum(starts + 8, n - 1), axis=axis)  # the shared face
        return func(segments, shared)

    mins, maxs = a, a
    for axis, n in ((2, nx), (1, ny), (0, nz)):
        mins = reduce_axis(mins, axis, n, np.minimum)
        maxs = reduce_axis(maxs, axis, n, np.maximum)
    return np.sort(mins.ravel().astype(np.float64)), np.sort(maxs.ravel().astype(np.float64))


def active_block_counts(sorted_mins, sorted_maxs, isovalues):
    """Blocks with min < iso <= max (the filter's IsActive)."""
    import numpy as np

    iso = np.asarray(isovalues, dtype=np.float64)
    below_min = np.searchsorted(sorted_mins, iso, side="left")  # blocks with min < iso
    below_max = np.searchsorted(sorted_maxs, iso, side="left")  # blocks with max < iso
    return [int(v) for v in (below_min - below_max)]


def run_child(args):
    from vtkmodules.vtkCommonCore import vtkSMPTools

    name = args.child
    memory = Memory()
    vtkSMPTools.SetBackend(args.backend)
    threads = 1 if args.backend.lower() == "sequential" else max(1, args.threads)
    vtkSMPTools.Initialize(threads)
    backend = vtkSMPTools.GetBackend()
    threads_in_use = vtkSMPTools.GetEstimatedNumberOfThreads()

    import paraview.simple as pvs
    from paraview import servermanager
    from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D

    pvs.LoadPlugin(args.plugin)  # adds the plugin's proxies to paraview.simple
    BlockLODContour = pvs.BlockLODContour
    MedicalPhantom = pvs.MedicalPhantom

    result = dict(input=name, backend=backend, threads=threads_in_use,
                  paraview="%d.%d.%d" % (servermanager.vtkSMProxyManager.GetVersionMajor(),
                                         servermanager.vtkSMProxyManager.GetVersionMinor(),
                                         servermanager.vtkSMProxyManager.GetVersionPatch()),
                  mem_reset=memory.can_reset)
    progress("[%s] SMP backend %s, %d threads; ParaView %s" % (name, backend, threads_in_use,
                                                              result["paraview"]))

    # --- input ------------------------------------------------------------------------------
    keep = []  # keeps VTK objects of the input alive
    start = time.perf_counter()
    if name.startswith("phantom"):
        n = int(name[len("phantom"):])
        source = MedicalPhantom(Dimensions=[n, n, n], Spacing=[240.0 / (n - 1)] * 3)
        source.UpdatePipeline()
        label = "MedicalPhantom %d^3 (int16 HU, seed 1, no noise)" % n
        algorithm = source.GetClientSideObject()
        image = algorithm.GetOutputDataObject(0) if algorithm is not None else None
        if image is None:
            image = servermanager.Fetch(source)
    else:
        reader = pvs.OpenDataFile(ct_path())
        reader.UpdatePipeline()
        ct_image = reader.GetClientSideObject().GetOutputDataObject(0)
        if name == "ct":
            source, image = reader, ct_image
            label = "head CT (%s)" % os.path.basename(ct_path())
        else:
            # vtkImageResample with magnification 2 gives 511x511x215 (the same bounds at half
            # the spacing); vtkImageReslice gives exactly 512x512x216 over the same bounds.
            from vtkmodules.vtkImagingCore import vtkImageReslice

            dims_in = ct_image.GetDimensions()
            spacing_in = ct_image.GetSpacing()
            dims_out = (512, 512, 216)
            reslice = vtkImageReslice()
            reslice.SetInputData(ct_image)
            reslice.SetInterpolationModeToLinear()
            reslice.SetOutputOrigin(ct_image.GetOrigin())
            reslice.SetOutputSpacing([spacing_in[i] * (dims_in[i] - 1) / (dims_out[i] - 1)
                                      for i in range(3)])
            reslice.SetOutputExtent(0, dims_out[0] - 1, 0, dims_out[1] - 1, 0, dims_out[2] - 1)
            reslice.Update()
            image = reslice.GetOutput()
            keep.append(reslice)
            source = pvs.PVTrivialProducer()
            source.GetClientSideObject().SetOutput(image)
            source.UpdatePipeline()
            label = "head CT resampled (linear) to 512x512x216"
    keep.append(image)
    load_s = time.perf_counter() - start
    scalars = image.GetPointData().GetScalars()
    array_name = scalars.GetName()
    value_range = scalars.GetRange()
    dims = list(image.GetDimensions())
    result.update(label=label, dims=dims, dtype=scalars.GetDataTypeAsString(), array=array_name,
                  range=list(value_range), spacing=list(image.GetSpacing()), load_s=load_s)
    progress("[%s] %s: %s, %s '%s', range %g..%g, loaded in %.2f s"
             % (name, label, "x".join(map(str, dims)), result["dtype"], array_name,
                value_range[0], value_range[1], load_s))

    # Active blocks for the paper's constant (numpy, before the timed part).
    sweep_n, sweep_note = sweep_for(args, name)
    lo, hi = value_range
    sweep_values = [lo + (hi - lo) * (i + 1) / (sweep_n + 1) for i in range(sweep_n)]
    sorted_mins, sorted_maxs = block_ranges_numpy(image, array_name)
    result["blocks"] = int(len(sorted_mins))
    result["sweep_active_blocks"] = active_block_counts(sorted_mins, sorted_maxs, sweep_values)
    del sorted_mins, sorted_maxs
    rss_after_load = memory.begin()  # also resets the high-water mark
    result["input_rss_mb"] = rss_after_load / 1024.0
    result["input_mb"] = image.GetActualMemorySize() / 1024.0

    def new_lod(isovalue, level):
        lod = BlockLODContour(Input=source, ContourBy=["POINTS", array_name],
                              Isosurfaces=[isovalue])
        lod.LOD = level
        lod.AutoLOD = 0
        lod.MemoryBudget = args.cache_mb
        lod.CacheMemoryLimit = args.cache_mb
        return lod

    def lod_info(lod):
        info = lod.GetDataInformation().DataInformation
        lod.UpdatePropertyInformation()
        smproxy = lod.SMProxy

        def vector(prop):
            p = smproxy.GetProperty(prop)
            return [p.GetElement(i) for i in range(p.GetNumberOfElements())]
        return dict(triangles=info.GetNumberOfCells(), out_mb=info.GetMemorySize() * 1024 / 1e6,
                    est_tris=vector("EstimatedTriangles"), est_mb=vector("EstimatedMB"),
                    est_s=vector("EstimatedSeconds"),
                    chosen=smproxy.GetProperty("ChosenLevel").GetElement(0))

    def timed(function):
        rss = memory.begin()
        t0 = time.perf_counter()
        function()
        seconds = time.perf_counter() - t0
        peak, growth = memory.end(rss)
        return seconds, peak, growth

    # --- (1) cold, warm and cached extraction ---------------------------------------------------
    repeats = repeats_for(args, name)
    result["repeats"] = repeats
    result["cold"] = []
    for iso in isovalues_for(args):
        if not (lo < iso <= hi):
            progress("[%s] isovalue %g is outside the data range: skipped" % (name, iso))
            result["cold"].append(dict(iso=iso, skipped="outside the data range %g..%g" % (lo, hi)))
            continue
        rows = {}

        def record(key, method, level, seconds, peak, growth, triangles, out_mb, note=""):
            row = rows.setdefault(key, dict(method=method, level=level, times=[], peak_mb=0.0,
                                            growth_mb=0.0, triangles=[], out_mb=0.0, note=note))
            row["times"].append(seconds)
            row["peak_mb"] = max(row["peak_mb"], peak)
            row["growth_mb"] = max(row["growth_mb"], growth)
            row["triangles"].append(int(triangles))
            row["out_mb"] = max(row["out_mb"], out_mb)

        fe = vtkFlyingEdges3D()
        fe.SetInputData(image)
        fe.ComputeNormalsOn()
        fe.ComputeScalarsOff()
        fe.ComputeGradientsOff()
        contour = pvs.Contour(Input=source, ContourBy=["POINTS", array_name], Isosurfaces=[iso],
                              ComputeNormals=1, ComputeScalars=0)
        marching = None
        if args.marching_cubes:
            from vtkmodules.vtkFiltersCore import vtkMarchingCubes
            marching = vtkMarchingCubes()
            marching.SetInputData(image)
            marching.ComputeNormalsOn()
            marching.ComputeScalarsOff()
        # Warm filters: one per level, primed on another isovalue (block ranges computed).
        prime = iso + 0.5
        warm = {}
        for level in range(4):
            warm[level] = new_lod(prime, level)
            warm[level].UpdatePipeline()
        values = [iso + k * 1e-3 for k in range(repeats)]  # every run a new isovalue
        for k, v in enumerate(values):
            progress("[%s] cold/warm iso %g, run %d/%d" % (name, iso, k + 1, repeats))
            fe.SetValue(0, v)
            s, p, g = timed(fe.Update)
            out = fe.GetOutput()
            record("fe", "vtkFlyingEdges3D", "-", s, p, g, out.GetNumberOfCells(),
                   out.GetActualMemorySize() * 1024 / 1e6)
            contour.Isosurfaces = [v]
            s, p, g = timed(contour.UpdatePipeline)
            info = contour.GetDataInformation().DataInformation
            record("contour", "ParaView Contour", "-", s, p, g, info.GetNumberOfCells(),
                   info.GetMemorySize() * 1024 / 1e6)
            if marching is not None:
                marching.SetValue(0, v)
                s, p, g = timed(marching.Update)
                out = marching.GetOutput()
                record("mc", "vtkMarchingCubes (serial)", "-", s, p, g, out.GetNumberOfCells(),
                       out.GetActualMemorySize() * 1024 / 1e6)
            for level in range(4):
                lod = new_lod(v, level)
                s, p, g = timed(lod.UpdatePipeline)
                i = lod_info(lod)
                record("cold%d" % level, "BlockLOD cold", level, s, p, g, i["triangles"], i["out_mb"])
                pvs.Delete(lod)
                del lod
            for level in range(4):
                warm[level].Isosurfaces = [v]
                s, p, g = timed(warm[level].UpdatePipeline)
                i = lod_info(warm[level])
                record("warm%d" % level, "BlockLOD warm change", level, s, p, g, i["triangles"],
                       i["out_mb"])
        # Cache hits: alternate between two isovalues already extracted at the level.
        for level in (0, 3):
            missed = 0
            # Start on values[0] unless the filter already shows it (a same-value set is no update).
            pair = [values[0], prime] if values[-1] != values[0] else [prime, values[0]]
            for k in range(repeats):
                v = pair[k % 2]
                warm[level].Isosurfaces = [v]
                s, p, g = timed(warm[level].UpdatePipeline)
                i = lod_info(warm[level])
                missed += 1 if i["est_s"][level] != 0 else 0  # EstimatedSeconds is 0 when cached
                record("hit%d" % level, "BlockLOD cache hit", level, s, p, g, i["triangles"],
                       i["out_mb"])
            if missed:
                rows["hit%d" % level]["note"] = "%d of %d runs were not cache hits" % (missed, repeats)
        for level in range(4):
            pvs.Delete(warm[level])
        warm.clear()
        pvs.Delete(contour)
        del contour, fe, marching
        order = ["fe", "contour", "mc"] + ["cold%d" % l for l in range(4)] + \
                ["warm%d" % l for l in range(4)] + ["hit0", "hit3"]
        result["cold"].append(dict(iso=iso, rows=[dict(rows[k], key=k) for k in order if k in rows]))

    # --- (2, 3) the sweep, and the estimator on its pairs -------------------------------------
    result["sweep"] = dict(n=sweep_n, note=sweep_note, isovalues=sweep_values, levels={})
    progress("[%s] sweep of %d isovalues with vtkFlyingEdges3D" % (name, sweep_n))
    fe = vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.ComputeNormalsOn()
    fe.ComputeScalarsOff()
    fe.ComputeGradientsOff()
    fe_times, fe_tris, fe_peak, fe_growth = [], [], 0.0, 0.0
    for v in sweep_values:
        fe.SetValue(0, v)
        s, p, g = timed(fe.Update)
        fe_times.append(s)
        fe_tris.append(fe.GetOutput().GetNumberOfCells())
        fe_peak, fe_growth = max(fe_peak, p), max(fe_growth, g)
    del fe
    result["sweep"]["fe"] = dict(times=fe_times, triangles=fe_tris, peak_mb=fe_peak,
                                 growth_mb=fe_growth)
    for level in range(4):
        progress("[%s] sweep of %d isovalues with BlockLODContour at level %d"
                 % (name, sweep_n, level))
        # Primed on the data's midpoint shifted off the sweep's grid: every sweep update is then
        # a warm change (block ranges known, the pair new).
        prime = lo + (hi - lo) * 0.5 + (hi - lo) / (sweep_n + 1) * 0.37
        lod = new_lod(prime, level)
        prime_s, _, _ = timed(lod.UpdatePipeline)
        # The estimate of (v, level) must be made before that pair is extracted (the filter
        # reports exact counts for pairs it has planned): a second filter, updated at another
        # level of v, supplies it. With only one level of v known it cannot scale, so these are
        # its sampled estimates.
        probe = new_lod(prime, 1 if level == 0 else 0)
        probe.UpdatePipeline()
        rec = dict(prime_s=prime_s, times=[], triangles=[], out_mb=[], est_tris=[], est_mb=[],
                   est_s=[], chosen=[], peak_mb=0.0, growth_mb=0.0)
        for v in sweep_values:
            probe.Isosurfaces = [v]
            probe.UpdatePipeline()
            estimate = lod_info(probe)
            lod.Isosurfaces = [v]
            s, p, g = timed(lod.UpdatePipeline)
            i = lod_info(lod)
            rec["times"].append(s)
            rec["triangles"].append(i["triangles"])
            rec["out_mb"].append(i["out_mb"])
            rec["est_tris"].append(estimate["est_tris"][level])
            rec["est_mb"].append(estimate["est_mb"][level])
            rec["est_s"].append(i["est_s"][level])
            rec["chosen"].append(i["chosen"])
            rec["peak_mb"], rec["growth_mb"] = max(rec["peak_mb"], p), max(rec["growth_mb"], g)
        pvs.Delete(lod)
        pvs.Delete(probe)
        del lod, probe
        result["sweep"]["levels"][str(level)] = rec
    result["peak_mb"] = memory.overall_mb()
    progress("[%s] done, peak RSS %.0f MB" % (name, result["peak_mb"]))
    with open(args.child_result, "w") as f:
        json.dump(result, f)
    return 0


# ----------------------------------------------------------------------------------------------
# Parent: runs one child per input, prints the tables
# ----------------------------------------------------------------------------------------------
def fmt_s(seconds):
    if seconds is None or (isinstance(seconds, float) and math.isnan(seconds)):
        return "-"
    if seconds < 0.1:
        return "%.4f" % seconds
    return "%.3f" % seconds


def fmt_ratio(value):
    if value is None or math.isnan(value):
        return "-"
    return "%.2fx" % value


def fmt_pct(value):
    if value is None or math.isnan(value):
        return "-"
    return "%.1f%%" % (100.0 * value)


def fmt_mb(value):
    if value is None or math.isnan(value):
        return "-"
    return "%.1f" % value


def table(headers, rows):
    lines = ["", "| " + " | ".join(headers) + " |",
             "|" + "|".join("---" if i == 0 else "---:" for i in range(len(headers))) + "|"]
    for row in rows:
        lines.append("| " + " | ".join(str(c) for c in row) + " |")
    return lines


def input_title(r):
    return "%s: %s, %s %s" % (r["input"], r["label"], "x".join(map(str, r["dims"])), r["dtype"])


def smp_text(r):
    return "backend %s, %d thread(s)" % (r["backend"], r["threads"])


def errors(estimates, actuals, min_triangles):
    out = []
    for e, a in zip(estimates, actuals):
        if a >= min_triangles:
            out.append((e - a) / a)
    return out


def error_stats(errs):
    if not errs:
        return float("nan"), float("nan"), float("nan")
    absolute = [abs(e) for e in errs]
    within = sum(1 for e in absolute if e <= TARGET_EST_TOL) / len(absolute)
    return within, statistics.median(absolute), max(absolute)


def margin_text(measured, limit, lower_is_better=True):
    if measured is None or math.isnan(measured):
        return "not measured"
    if lower_is_better:
        if measured <= limit:
            return "%.0f%% under the limit" % (100.0 * (1.0 - measured / limit))
        return "%.2fx the limit" % (measured / limit)
    if measured >= limit:
        return "%.1f points above" % (100.0 * (measured - limit))
    return "%.1f points short" % (100.0 * (limit - measured))


def report(args, results, skipped, command, started, wall, load_before, load_after):
    lines = []
    out = lines.append
    out("# BlockLODContour benchmark")
    out("")
    out("- command: `%s`" % command)
    out("- machine: %s, %s, %d logical CPUs (%d usable), %s, %.1f GB RAM"
        % (platform.node(), platform.platform(), os.cpu_count() or 0,
           len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 0,
           cpu_model(), mem_total_gb()))
    out("- started %s, wall time %.0f s; load average before %s, after %s"
        % (started, wall, load_before, load_after))
    if results:
        r0 = results[0]
        out("- ParaView %s, Python %s; SMP %s (every table); BlockLODContour CacheMemoryLimit "
            "= MemoryBudget = %g MB, AutoLOD off, normals on" % (r0["paraview"],
                                                                 platform.python_version(),
                                                                 smp_text(r0), args.cache_mb))
    out("- plugin: %s" % build_text(args.plugin))
    for name, why in skipped:
        out("- skipped %s: %s" % (name, why))
    out("- times: seconds of one update; min and median of the runs; ratio = median / median "
        "(and min / min) of vtkFlyingEdges3D in the same run, same isovalue. Every run uses a new "
        "isovalue (iso + k*0.001) so nothing is reused unless the row says so. vtkFlyingEdges3D: "
        "normals on, scalars off; ParaView Contour: ComputeNormals 1, ComputeScalars 0.")
    out("- cold = fresh BlockLODContour (block min/max pass + estimates + extraction); warm change "
        "= new isovalue on a filter that already ran on the input; cache hit = an (isovalue, level) "
        "already extracted. BlockLOD times go through the proxy (UpdatePipeline); the cache-hit row "
        "bounds that overhead.")
    out("")

    # (1) cold/warm
    out("## 1. Cold extraction, warm isovalue change, cache hit")
    for r in results:
        for block in r["cold"]:
            out("")
            out("### %s; isovalue %g; %s; %d runs" % (input_title(r), block["iso"], smp_text(r),
                                                     r["repeats"]))
            if "skipped" in block:
                out("skipped: " + block["skipped"])
                continue
            fe = next(row for row in block["rows"] if row["key"] == "fe")
            fe_med, fe_min = statistics.median(fe["times"]), min(fe["times"])
            rows = []
            for row in block["rows"]:
                med, mn = statistics.median(row["times"]), min(row["times"])
                rows.append([row["method"], row["level"], fmt_s(mn), fmt_s(med),
                             fmt_ratio(med / fe_med), fmt_ratio(mn / fe_min),
                             row["triangles"][0], fmt_mb(row["out_mb"]), fmt_mb(row["peak_mb"]),
                             fmt_mb(row["growth_mb"]), row["note"]])
            lines.extend(table(["method", "LOD", "min s", "median s", "ratio (median)",
                                "ratio (min)", "triangles", "output MB", "peak RSS MB",
                                "RSS growth MB", "note"], rows))
    out("")
    out("Triangles are those of the first run (isovalue exactly as given); output MB is the "
        "output's GetActualMemorySize (KiB * 1024 / 10^6). Peak RSS: VmHWM during the call; growth: "
        "that peak minus the RSS before the call (max over the runs).")

    # (2) sweep
    out("")
    out("## 2. Isovalue sweep (equidistant isovalues across the data range, ends excluded)")
    for r in results:
        sw = r["sweep"]
        out("")
        out("### %s; %d isovalues (%s); %s" % (input_title(r), sw["n"], sw["note"], smp_text(r)))
        fe_t = sw["fe"]["times"]
        fe_total = sum(fe_t)
        rows = [["vtkFlyingEdges3D", "-", "-", fmt_s(fe_total), fmt_s(fe_total / len(fe_t)),
                 fmt_s(statistics.median(fe_t)), fmt_s(max(fe_t)), "1.00x",
                 sum(sw["fe"]["triangles"]), "-"]]
        for level in range(4):
            rec = sw["levels"][str(level)]
            t = rec["times"]
            total = sum(t)
            note = ""
            if level == 3:
                mismatch = sum(1 for a, b in zip(rec["triangles"], sw["fe"]["triangles"]) if a != b)
                note = "triangles equal vtkFlyingEdges3D's at %d of %d isovalues" % (
                    len(t) - mismatch, len(t))
            bad_level = sum(1 for c in rec["chosen"] if c != level)
            if bad_level:
                note += "; ChosenLevel != %d at %d isovalues" % (level, bad_level)
            rows.append(["BlockLOD warm changes", level, fmt_s(rec["prime_s"]), fmt_s(total),
                         fmt_s(total / len(t)), fmt_s(statistics.median(t)), fmt_s(max(t)),
                         fmt_ratio(total / fe_total), sum(rec["triangles"]), note])
        lines.extend(table(["method", "LOD", "first update s (cold, not in total)", "total s",
                            "mean s/change", "median s/change", "max s/change",
                            "ratio (total)", "triangles (sum)", "note"], rows))
    out("")
    out("Paper (512^3 heart, GeForce 8800GTX): 0.0693 s per isovalue change stand-alone, "
        "extraction and rendering; here extraction only.")

    # (3) estimator
    out("")
    out("## 3. Estimator (pairs of the sweep with >= %d actual triangles)" % TARGET_EST_MIN_TRIANGLES)
    out("")
    out("ours = EstimatedTriangles[level] of a second filter updated at another level of the same "
        "isovalue, i.e. made before the pair was ever extracted (sampled on about 256 active blocks, "
        "exact when there are fewer). paper = 2 triangles per "
        "cube x (8/stride)^3 cubes per block x active blocks (min < iso <= max, counted with numpy "
        "on 8x8x8-cell blocks sharing faces). Error = (estimate - actual) / actual; 'within' = "
        "|error| <= 10%. MB: EstimatedMB vs the output's GetMemorySize (KiB * 1024 / 10^6). "
        "Seconds: the filter's predicted extraction time vs the measured update.")
    pooled_ours, pooled_paper = [], []
    est_summary = {}
    for r in results:
        sw = r["sweep"]
        out("")
        out("### %s; %d isovalues; %s" % (input_title(r), sw["n"], smp_text(r)))
        rows = []
        all_ours, all_paper = [], []
        for level in range(4):
            rec = sw["levels"][str(level)]
            actual = rec["triangles"]
            ours = errors(rec["est_tris"], actual, TARGET_EST_MIN_TRIANGLES)
            paper_est = [2.0 * 8 ** level * a for a in r["sweep_active_blocks"]]
            paper = errors(paper_est, actual, TARGET_EST_MIN_TRIANGLES)
            mb_err = [abs(e - a) / a for e, a, t in zip(rec["est_mb"], rec["out_mb"], actual)
                      if t >= TARGET_EST_MIN_TRIANGLES and a > 0]
            s_ratio = [m / e for e, m, t in zip(rec["est_s"], rec["times"], actual)
                       if t >= TARGET_EST_MIN_TRIANGLES and e > 0]
            all_ours += ours
            all_paper += paper
            o = error_stats(ours)
            p = error_stats(paper)
            rows.append([level, len(ours), len(actual) - len(ours), fmt_pct(o[0]), fmt_pct(o[1]),
                         fmt_pct(o[2]), fmt_pct(p[0]), fmt_pct(p[1]), fmt_pct(p[2]),
                         fmt_pct(statistics.median(mb_err)) if mb_err else "-",
                         ("%.2f" % statistics.median(s_ratio)) if s_ratio else "-"])
        o = error_stats(all_ours)
        p = error_stats(all_paper)
        rows.append(["all", len(all_ours), "", fmt_pct(o[0]), fmt_pct(o[1]), fmt_pct(o[2]),
                     fmt_pct(p[0]), fmt_pct(p[1]), fmt_pct(p[2]), "", ""])
        est_summary[r["input"]] = (o[0], len(all_ours))
        pooled_ours += all_ours
        pooled_paper += all_paper
        lines.extend(table(["LOD", "pairs", "pairs < 1000 tris (excluded)", "ours within 10%",
                            "ours median abs err", "ours max abs err", "paper within 10%",
                            "paper median abs err", "paper max abs err", "MB median abs err",
                            "s measured/predicted (median)"], rows))
    if len(results) > 1:
        o = error_stats(pooled_ours)
        p = error_stats(pooled_paper)
        out("")
        out("All inputs together: %d pairs; ours within 10%%: %s (median |err| %s, max %s); "
            "paper's constant within 10%%: %s (median |err| %s, max %s)."
            % (len(pooled_ours), fmt_pct(o[0]), fmt_pct(o[1]), fmt_pct(o[2]), fmt_pct(p[0]),
               fmt_pct(p[1]), fmt_pct(p[2])))
        est_summary["all inputs"] = (o[0], len(pooled_ours))

    # (4) memory
    out("")
    out("## 4. Peak memory (RSS, MB; one child process per input)")
    out("")
    rows = []
    for r in results:
        block = next((b for b in r["cold"] if "rows" in b), None)
        by_key = {row["key"]: row for row in block["rows"]} if block else {}

        def cell(key):
            row = by_key.get(key)
            return "%s / %s" % (fmt_mb(row["peak_mb"]), fmt_mb(row["growth_mb"])) if row else "-"
        sw = r["sweep"]
        l3 = sw["levels"]["3"]
        rows.append([r["input"], "x".join(map(str, r["dims"])), fmt_mb(r["input_mb"]),
                     fmt_mb(r["input_rss_mb"]), cell("fe"), cell("contour"), cell("cold3"),
                     cell("warm3"), "%s / %s" % (fmt_mb(sw["fe"]["peak_mb"]),
                                                 fmt_mb(sw["fe"]["growth_mb"])),
                     "%s / %s" % (fmt_mb(l3["peak_mb"]), fmt_mb(l3["growth_mb"])),
                     fmt_mb(r["peak_mb"])])
    lines.extend(table(["input", "size", "image MB", "RSS after load", "FE cold peak / growth",
                        "Contour peak / growth", "BlockLOD L3 cold peak / growth",
                        "BlockLOD L3 warm peak / growth", "FE sweep peak / growth",
                        "BlockLOD L3 sweep peak / growth", "child peak RSS"], rows))
    out("")
    out("Cold/warm columns: first isovalue of table 1. Growth = peak during a call minus the RSS "
        "before it (outputs and caches of earlier calls are in the RSS before). The BlockLOD sweep "
        "keeps up to CacheMemoryLimit of surfaces. Child peak includes the input, numpy block "
        "ranges excluded (computed before the high-water mark was reset)."
        + ("" if all(r["mem_reset"] for r in results) else
           " /proc/self/clear_refs was not writable: per-call peaks are not isolated."))

    # Targets
    out("")
    out("## Targets")
    out("")
    rows = []
    for r in results:
        for block in r["cold"]:
            if "rows" not in block:
                continue
            by_key = {row["key"]: row for row in block["rows"]}
            fe_med = statistics.median(by_key["fe"]["times"])
            cold = statistics.median(by_key["cold3"]["times"]) / fe_med
            rows.append(["cold level 3 <= 0.6x vtkFlyingEdges3D", "%s, iso %g" % (r["input"], block["iso"]),
                         fmt_ratio(cold), "yes" if cold <= TARGET_COLD else "no",
                         margin_text(cold, TARGET_COLD)])
    for r in results:
        for block in r["cold"]:
            if "rows" not in block:
                continue
            by_key = {row["key"]: row for row in block["rows"]}
            fe_med = statistics.median(by_key["fe"]["times"])
            warm = statistics.median(by_key["warm3"]["times"]) / fe_med
            rows.append(["warm change level 3 <= 0.3x vtkFlyingEdges3D",
                         "%s, iso %g" % (r["input"], block["iso"]), fmt_ratio(warm),
                         "yes" if warm <= TARGET_WARM else "no", margin_text(warm, TARGET_WARM)])
        sw = r["sweep"]
        ratio = sum(sw["levels"]["3"]["times"]) / sum(sw["fe"]["times"])
        rows.append(["warm change level 3 <= 0.3x vtkFlyingEdges3D",
                     "%s, sweep of %d (total)" % (r["input"], sw["n"]), fmt_ratio(ratio),
                     "yes" if ratio <= TARGET_WARM else "no", margin_text(ratio, TARGET_WARM)])
    for r in results:
        if r["input"] not in LARGE_INPUTS:
            continue
        for block in r["cold"]:
            if "rows" not in block:
                continue
            by_key = {row["key"]: row for row in block["rows"]}
            t = statistics.median(by_key["warm0"]["times"])
            rows.append(["level 0 < 10 ms on 512-wide inputs (warm change, median)",
                         "%s, iso %g" % (r["input"], block["iso"]), "%.1f ms" % (1e3 * t),
                         "yes" if t < TARGET_LEVEL0_S else "no", margin_text(t, TARGET_LEVEL0_S)])
            t = statistics.median(by_key["cold0"]["times"])
            rows.append(["(info) level 0 cold, median", "%s, iso %g" % (r["input"], block["iso"]),
                         "%.1f ms" % (1e3 * t), "yes" if t < TARGET_LEVEL0_S else "no",
                         margin_text(t, TARGET_LEVEL0_S)])
        t0 = r["sweep"]["levels"]["0"]["times"]
        for what, t in (("median", statistics.median(t0)), ("max", max(t0))):
            rows.append(["level 0 < 10 ms on 512-wide inputs (sweep, %s per change)" % what,
                         "%s, %d isovalues" % (r["input"], len(t0)), "%.1f ms" % (1e3 * t),
                         "yes" if t < TARGET_LEVEL0_S else "no", margin_text(t, TARGET_LEVEL0_S)])
    for key, (fraction, pairs) in est_summary.items():
        rows.append(["estimator within 10% for >= 95% of pairs (>= 1000 tris)",
                     "%s, %d pairs" % (key, pairs), fmt_pct(fraction),
                     "yes" if fraction >= TARGET_EST_FRACTION else "no",
                     margin_text(fraction, TARGET_EST_FRACTION, lower_is_better=False)])
    lines.extend(table(["target", "where", "measured", "met", "by how much"], rows))
    return lines


def build_text(plugin):
    """The plugin's path, the newest build time of its libraries and the source revision."""
    folder = os.path.dirname(plugin)
    try:
        newest = max(os.path.getmtime(os.path.join(folder, f)) for f in os.listdir(folder)
                     if f.endswith(".so"))
        built = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(newest))
    except (OSError, ValueError):
        built = "unknown"
    here = os.path.dirname(os.path.abspath(__file__))
    try:
        rev = subprocess.run(["git", "-C", here, "rev-parse", "--short", "HEAD"],
                             capture_output=True, text=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "-C", here, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10).stdout.strip()
        rev = (rev or "unknown") + (" + uncommitted changes" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        rev = "unknown"
    return "%s (libraries built %s; source %s)" % (plugin, built, rev)


def mem_total_gb():
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemTotal:"):
                    return int(line.split()[1]) / 1024.0 / 1024.0
    except OSError:
        pass
    return 0.0


def run_parent(args, argv):
    command = "pvpython " + " ".join(shlex.quote(a) for a in [sys.argv[0]] + argv)
    if not args.plugin or not os.path.exists(args.plugin):
        progress("plugin not found: %r (pass --plugin)" % args.plugin)
        return 2
    requested = [s.strip() for s in args.inputs.split(",") if s.strip()] or list(ALL_INPUTS)
    for name in requested:
        if name not in ALL_INPUTS:
            progress("unknown input %r (choose from %s)" % (name, ", ".join(ALL_INPUTS)))
            return 2
    skipped, inputs = [], []
    for name in requested:
        if name.startswith("ct") and not os.path.exists(ct_path()):
            skipped.append((name, "no CT at %s (run Python/fetch_data.py; set MEDISO_DATA_DIR)"
                            % ct_path()))
        else:
            inputs.append(name)
    interpreter = args.pvpython or shutil.which("pvpython") or sys.executable
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    load_before = load_average()
    progress("command: " + command)
    progress("machine: %s, %d CPUs, load average %s" % (platform.platform(), os.cpu_count() or 0,
                                                        load_before))
    for name, why in skipped:
        progress("skipping %s: %s" % (name, why))
    t0 = time.perf_counter()
    results = []
    passthrough = list(argv)
    for name in inputs:
        progress("=== %s (child process) ===" % name)
        handle, result_path = tempfile.mkstemp(prefix="bench_blocklod_", suffix=".json")
        os.close(handle)
        # --no-mpi: OpenMPI start-up fails on machines with no network interface.
        mpi = ["--no-mpi"] if os.path.basename(interpreter).startswith("pvpython") else []
        child_cmd = [interpreter] + mpi + [os.path.abspath(__file__)] + passthrough + [
            "--child", name, "--child-result", result_path, "--plugin", args.plugin]
        child_start = time.perf_counter()
        rc = subprocess.call(child_cmd)
        try:
            with open(result_path) as f:
                text = f.read()
            result = json.loads(text) if text.strip() else None
        except (OSError, ValueError):
            result = None
        finally:
            try:
                os.remove(result_path)
            except OSError:
                pass
        if rc != 0 or result is None:
            progress("%s failed (exit status %d): left out of the tables" % (name, rc))
            skipped.append((name, "child process failed with exit status %d" % rc))
            continue
        result["child_wall_s"] = time.perf_counter() - child_start
        progress("%s finished in %.0f s" % (name, result["child_wall_s"]))
        results.append(result)
    wall = time.perf_counter() - t0
    lines = report(args, results, skipped, command, started, wall, load_before, load_average())
    text = "\n".join(lines) + "\n"
    sys.stdout.write("\n" + text)
    sys.stdout.flush()
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)
        progress("wrote " + args.out)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(dict(command=command, results=results, skipped=skipped), f)
        progress("wrote " + args.json)
    return 0 if results else 1


def main():
    argv = sys.argv[1:]
    args = parse_args(argv)
    if args.child:
        return run_child(args)
    return run_parent(args, argv)


if __name__ == "__main__":
    sys.exit(main())
