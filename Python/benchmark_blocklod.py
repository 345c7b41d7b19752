"""BlockLODContour benchmark (pvpython): the plugin's CPU isosurface filter against its peers.

    pvpython Python/benchmark_blocklod.py [--inputs ct,ct512,phantom256,phantom512,mri,ctnoise,...]
        [--repeats N] [--quick] [--sweep N] [--isovalues=-500,400] [--backend STDThread|Sequential]
        [--threads 2] [--out FILE.md] [--json FILE.json] [--plugin PATH] [--marching-cubes]
        [--frames [--frame-size 1024x768] [--frame-steps 9]]
    pvpython Python/benchmark_blocklod.py --interaction [--inputs ct] [--frame-size 1024x768]
        [--rotation-frames 20] [--isovalues=-500,400] [--plugin PATH] [--out FILE.md]

Inputs (each in its own child process): the real head CT (256x256x108 int16), the CT resampled
(linear) to 512x512x216, the plugin's MedicalPhantom at 256^3 and 512^3, and noisy stand-ins for
scans the project does not ship: the fetched MRI (181x217x181 uint8, noisy background), the CT with
40 HU of Gaussian noise (a low-dose scan), the phantom with 40 HU of noise, and (when asked for:
mri05) the MRI resampled to 0.5 mm with noise (a 0.5 mm MRI, 361x433x361). With a fixed SMP
backend and thread count:

1. Cold extraction (a fresh filter and a new isovalue: includes the block min/max pass and the
   estimates) at levels 0..3, warm isovalue changes (a filter that already ran on the input: block
   ranges kept, the (isovalue, level) pair not cached), warm level-3 changes once the filter's
   cache is full (as while an isovalue is dragged: each change drops the oldest surface, whose
   memory the new one reuses) and cache hits, against vtkFlyingEdges3D
   (normals on, scalars off) and ParaView's Contour (normals on), with the ratio of every time to
   vtkFlyingEdges3D's in the same run.
2. The paper's isovalue sweep: equidistant isovalues across the data range (ends excluded) at
   each level, one update per isovalue change; vtkFlyingEdges3D runs each isovalue just before
   BlockLOD's level 3 (per-step ratios under the same load).
3. The estimator: EstimatedTriangles/EstimatedMB of a pair, made before that pair is extracted
   (by a second filter updated at another level of the isovalue), against the actual output, and
   the paper's constant (2 triangles per cube of every active 8x8x8 block); the error distribution
   per input, with a sparse high isovalue per real scan estimated after a fresh filter extracted
   level 0 (issue 24's protocol); EstimatedSeconds of the extracting update against its time.
   With --frames (under X: Testing/Scripts/with-xvfb.sh), an isovalue change to a rendered frame
   in a ParaView view, split into filter, representation update and frame, for BlockLODContour,
   Contour and the Volume representation's isosurface mode, taking turns.
4. Peak memory: the peak RSS (VmHWM, reset through /proc/self/clear_refs before every timed call)
   is recorded per call, so each method's peak and its growth over the RSS before the call are
   isolated.

With --interaction (under X, in this process, no children): ParaView rotation frames of Block LOD
Contour's displays, skin (first isovalue) over bone (second) each from its own filter at level 3,
skin opaque and then at opacity 0.3: still frames (Render) against interactive frames
(InteractiveRender, as during a mouse drag), with the coarser Block LOD levels while interacting
(the default; a translucent skin blended in one pass while interacting, its default, and with the
view's depth peeling) and with ParaView's own decimated LOD (BlockLODInteractiveLevels off, depth
peeling as ParaView draws it), at the view's
default LODThreshold and the displays' default budgets; per frame median, the first interactive
frame (which makes the LOD geometry) apart, the level and triangles each display drew, and the
frame time its model predicted for that level when it was chosen.

Ends with the issue's targets: cold level 3 <= 0.6x vtkFlyingEdges3D, warm isovalue change at
level 3 <= 0.3x vtkFlyingEdges3D, level 0 under 10 ms on the 512-wide inputs, estimator within
+-10% for at least 95% of (isovalue, level) pairs with 1000 or more triangles and never under by
more, EstimatedSeconds within 25% for pairs over 10 ms.

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
from benchmark_common import (cpu_model, data_dir, fmt_s, load_average,  # noqa: E402
                              mem_total_gb, table as markdown_table)

ALL_INPUTS = ("ct", "ct512", "phantom256", "phantom512", "mri", "ctnoise", "phantomnoise", "mri05")
DEFAULT_INPUTS = ("ct", "ct512", "phantom256", "phantom512", "mri", "ctnoise", "phantomnoise")
LARGE_INPUTS = ("ct512", "phantom512", "mri05")
# Noisy stand-ins for scans the project does not ship (issue 23): the fetched MRI (noisy background),
# the CT with Gaussian noise (a low-dose scan), the phantom with noise, the MRI resampled to 0.5 mm
# with noise (a 0.5 mm MRI).
NOISY_INPUTS = ("mri", "ctnoise", "phantomnoise", "mri05")
CT_NOISE_HU = 40.0
PHANTOM_NOISE_HU = 40.0
MRI05_NOISE = 3.0
NOISE_SEED = 1
# Isovalues of the cold/warm tables: skin and bone (HU) for the CT and the phantom, skin and the
# grey/white matter boundary for the MRI.
INPUT_ISOVALUES = {"mri": (30.0, 100.0), "mri05": (30.0, 100.0)}
DEFAULT_ISOVALUES = (-500.0, 400.0)
# A sparse, high isovalue per real input for the estimator (issue 24): dense bone in the CT, bright
# spots in the MRI.
SPARSE_ISOVALUES = {"ct": 1500.0, "ct512": 1500.0, "ctnoise": 1500.0, "mri": 200.0, "mri05": 200.0}
PAPER_SWEEP = 95
QUICK_SWEEP = 19
TARGET_COLD = 0.6
TARGET_WARM = 0.3
TARGET_LEVEL0_S = 0.010
TARGET_EST_TOL = 0.10
TARGET_EST_FRACTION = 0.95
TARGET_EST_MIN_TRIANGLES = 1000
TARGET_SECONDS_TOL = 0.25
TARGET_SECONDS_MIN = 0.010
RESULT_TAG = "bench-result: "


def progress(message):
    print("bench: " + message, flush=True)


def ct_path():
    return os.path.join(data_dir(), "ct_head.mha")


def mri_path():
    return os.path.join(data_dir(), "mri_head.mha")


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
                        help="comma list of %s (default: %s)" % (", ".join(ALL_INPUTS),
                                                                  ", ".join(DEFAULT_INPUTS)))
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
    parser.add_argument("--frames", action="store_true",
                        help="also time an isovalue change to a rendered frame in ParaView "
                             "(filter, representation update, frame) for BlockLODContour, Contour "
                             "and the Volume representation's isosurface mode (needs X: run under "
                             "Testing/Scripts/with-xvfb.sh)")
    parser.add_argument("--frame-size", default="1024x768",
                        help="view size for --frames and --interaction")
    parser.add_argument("--interaction", action="store_true",
                        help="still vs interactive rotation frames of the displays (see above)")
    parser.add_argument("--rotation-frames", type=int, default=20,
                        help="frames per --interaction series (1 degree each)")
    parser.add_argument("--frame-steps", type=int, default=9,
                        help="isovalue changes per method for --frames (default 9)")
    parser.add_argument("--plugin", default=default_plugin(), help="path of MedicalIsosurfaces.so")
    parser.add_argument("--out", default="", help="write the tables (markdown) to this file")
    parser.add_argument("--json", default="", help="write the raw measurements to this file")
    parser.add_argument("--pvpython", default="",
                        help="interpreter for the child processes (default: pvpython on PATH)")
    parser.add_argument("--report-from", default="",
                        help="print the tables of a run saved with --json, measuring nothing")
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


def isovalues_for(args, name):
    if args.isovalues:
        return [float(v) for v in args.isovalues.split(",") if v.strip()]
    return list(INPUT_ISOVALUES.get(name, DEFAULT_ISOVALUES))


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


def with_noise(image, sigma, seed):
    """A copy of `image` with seeded Gaussian noise added to its scalars (rounded and clamped to
    the array's type), as a new vtkImageData."""
    import numpy as np
    from vtkmodules.util import numpy_support
    from vtkmodules.vtkCommonDataModel import vtkImageData

    scalars = image.GetPointData().GetScalars()
    values = numpy_support.vtk_to_numpy(scalars)
    info = np.iinfo(values.dtype) if np.issubdtype(values.dtype, np.integer) else None
    noisy = values.astype(np.float64) + np.random.default_rng(seed).normal(0.0, sigma, values.shape)
    if info is not None:
        noisy = np.clip(np.rint(noisy), info.min, info.max)
    array = numpy_support.numpy_to_vtk(noisy.astype(values.dtype), deep=1)
    array.SetName(scalars.GetName())
    out = vtkImageData()
    out.CopyStructure(image)
    out.GetPointData().SetScalars(array)
    return out


def resampled(image, spacing=None, dims=None):
    """`image` resampled (linear) over the same bounds to the given spacing or dimensions."""
    from vtkmodules.vtkImagingCore import vtkImageReslice

    dims_in = image.GetDimensions()
    spacing_in = image.GetSpacing()
    if dims is None:
        dims = [int(round((dims_in[i] - 1) * spacing_in[i] / spacing[i])) + 1 for i in range(3)]
    reslice = vtkImageReslice()
    reslice.SetInputData(image)
    reslice.SetInterpolationModeToLinear()
    reslice.SetOutputOrigin(image.GetOrigin())
    reslice.SetOutputSpacing([spacing_in[i] * (dims_in[i] - 1) / (dims[i] - 1) for i in range(3)])
    reslice.SetOutputExtent(0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1)
    reslice.Update()
    return reslice.GetOutput()


def make_input(name, pvs, MedicalPhantom):
    """(source proxy, vtkImageData, label, objects to keep alive) of a benchmark input."""
    from paraview import servermanager

    keep = []
    if name.startswith("phantom"):
        noise = PHANTOM_NOISE_HU if name == "phantomnoise" else 0.0
        n = 256 if name == "phantomnoise" else int(name[len("phantom"):])
        source = MedicalPhantom(Dimensions=[n, n, n], Spacing=[240.0 / (n - 1)] * 3,
                                NoiseStandardDeviation=noise, Seed=NOISE_SEED)
        source.UpdatePipeline()
        label = "MedicalPhantom %d^3 (int16 HU, seed %d, %s)" % (
            n, NOISE_SEED, "noise %g HU" % noise if noise else "no noise")
        algorithm = source.GetClientSideObject()
        image = algorithm.GetOutputDataObject(0) if algorithm is not None else None
        if image is None:
            image = servermanager.Fetch(source)
        keep.append(image)
        return source, image, label, keep
    path = mri_path() if name.startswith("mri") else ct_path()
    reader = pvs.OpenDataFile(path)
    reader.UpdatePipeline()
    original = reader.GetClientSideObject().GetOutputDataObject(0)
    keep.append(original)
    if name in ("ct", "mri"):
        label = "head %s (%s)" % ("MRI" if name == "mri" else "CT", os.path.basename(path))
        return reader, original, label, keep
    if name == "ct512":
        # vtkImageReslice gives exactly 512x512x216 over the same bounds (vtkImageResample with
        # magnification 2 would give 511x511x215).
        image = resampled(original, dims=(512, 512, 216))
        label = "head CT resampled (linear) to 512x512x216"
    elif name == "ctnoise":
        image = with_noise(original, CT_NOISE_HU, NOISE_SEED)
        label = "head CT + Gaussian noise %g HU (seed %d): a low-dose scan" % (CT_NOISE_HU, NOISE_SEED)
    else:  # mri05
        image = with_noise(resampled(original, spacing=(0.5, 0.5, 0.5)), MRI05_NOISE, NOISE_SEED)
        label = ("head MRI resampled (linear) to 0.5 mm + Gaussian noise %g (seed %d): a 0.5 mm MRI"
                 % (MRI05_NOISE, NOISE_SEED))
    keep.append(image)
    source = pvs.PVTrivialProducer()
    source.GetClientSideObject().SetOutput(image)
    source.UpdatePipeline()
    return source, image, label, keep


def measure_frames(args, name, source, image, array_name, pvs, BlockLODContour):
    """An isovalue change to a rendered frame in ParaView (builtin session), split into the
    filter's update, the representation's update (view.Update(): geometry filter, delivery) and
    the frame (Render(): the mapper's upload and the drawing), for BlockLODContour (level 3,
    Surface), ParaView's Contour (Surface) and the Volume representation's isosurface mode. The
    methods take turns at every step (their order rotating), each with only its own
    representation visible; step 0 (first uploads, shader compiles) is not counted."""
    if not os.environ.get("DISPLAY"):
        progress("[%s] no X display: ParaView frames not measured" % name)
        return dict(skipped="no X display (run under Testing/Scripts/with-xvfb.sh)")
    width, height = [int(v) for v in args.frame_size.lower().split("x")]
    lo, hi = image.GetPointData().GetScalars().GetRange()
    iso0 = isovalues_for(args, name)[0]
    delta = (hi - lo) * 0.002
    view = pvs.CreateView("RenderView")
    view.ViewSize = [width, height]
    view.OrientationAxesVisibility = 0
    lod = BlockLODContour(Input=source, ContourBy=["POINTS", array_name], Isosurfaces=[iso0])
    lod.LOD = 3
    lod.AutoLOD = 0
    lod.CacheMemoryLimit = args.cache_mb
    contour = pvs.Contour(Input=source, ContourBy=["POINTS", array_name], Isosurfaces=[iso0],
                          ComputeNormals=1, ComputeScalars=0)
    shown = {}
    for key, proxy in (("BlockLOD L3", lod), ("ParaView Contour", contour)):
        display = pvs.Show(proxy, view)
        display.ColorArrayName = [None, ""]
        shown[key] = (proxy, display)
    volume = pvs.Show(source, view)
    volume.SetRepresentationType("Volume")
    volume.BlendMode = "Isosurface"
    volume.IsosurfaceValues = [iso0]
    shown["Volume isosurface"] = (source, volume)
    pvs.ResetCamera(view)
    methods = list(shown)
    times = {m: [] for m in methods}
    triangles = {m: [] for m in methods}
    for k in range(args.frame_steps + 1):
        iso = iso0 + (k + 1) * delta
        for m in methods[k % len(methods):] + methods[:k % len(methods)]:
            for other, (_, display) in shown.items():
                display.Visibility = 1 if other == m else 0
            pvs.Render(view)  # the method's previous surface, outside the timing
            proxy, display = shown[m]
            t0 = time.perf_counter()
            if m == "Volume isosurface":
                display.IsosurfaceValues = [iso]
            else:
                proxy.Isosurfaces = [iso]
                proxy.UpdatePipeline()
            t1 = time.perf_counter()
            view.Update()
            t2 = time.perf_counter()
            pvs.Render(view)
            t3 = time.perf_counter()
            if k > 0:
                times[m].append((t1 - t0, t2 - t1, t3 - t2))
                triangles[m].append(proxy.GetDataInformation().GetNumberOfCells()
                                    if m != "Volume isosurface" else 0)
        progress("[%s] ParaView frames: step %d/%d" % (name, k, args.frame_steps))
    for key in ("BlockLOD L3", "ParaView Contour"):
        pvs.Delete(shown[key][1])
    pvs.Hide(source, view)
    pvs.Delete(lod)
    pvs.Delete(contour)
    pvs.Delete(view)
    return dict(size="%dx%d" % (width, height), steps=args.frame_steps, iso=iso0, delta=delta,
                times=times, triangles=triangles)


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
    start = time.perf_counter()
    source, image, label, keep = make_input(name, pvs, MedicalPhantom)
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
    for iso in isovalues_for(args, name):
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
                rows["warm%d" % level].setdefault("est_s", []).append(i["est_s"][level])
        # Warm level-3 changes with the cache full, as while an isovalue is dragged: a filter
        # with the same CacheMemoryLimit is filled with new isovalues until every change makes
        # the cache drop its oldest surface; the next `repeats` changes are timed, each just
        # after vtkFlyingEdges3D on the same isovalue (the row's ratios are to those).
        drag = new_lod(prime, 3)
        drag.UpdatePipeline()
        surface_mb = max(lod_info(drag)["out_mb"], 1e-3)
        fill = int(args.cache_mb / surface_mb) + 1
        for k in range(fill + repeats):
            v = iso + 0.25 + k * 1e-3
            drag.Isosurfaces = [v]
            if k < fill:
                drag.UpdatePipeline()
                continue
            progress("[%s] warm change with the cache full, iso %g, run %d/%d"
                     % (name, iso, k - fill + 1, repeats))
            fe.SetValue(0, v)
            s, p, g = timed(fe.Update)
            out = fe.GetOutput()
            record("fedrag", "vtkFlyingEdges3D (the cache-full isovalues)", "-", s, p, g,
                   out.GetNumberOfCells(), out.GetActualMemorySize() * 1024 / 1e6)
            s, p, g = timed(drag.UpdatePipeline)
            i = lod_info(drag)
            record("drag3", "BlockLOD warm change, cache full", 3, s, p, g, i["triangles"],
                   i["out_mb"], note="after %d changes filled the cache" % fill)
        pvs.Delete(drag)
        del drag
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
                ["warm%d" % l for l in range(4)] + ["fedrag", "drag3", "hit0", "hit3"]
        result["cold"].append(dict(iso=iso, rows=[dict(rows[k], key=k) for k in order if k in rows]))

    # --- (2, 3) the sweep, and the estimator on its pairs -------------------------------------
    result["sweep"] = dict(n=sweep_n, note=sweep_note, isovalues=sweep_values, levels={})
    # vtkFlyingEdges3D runs in the level-3 sweep, each isovalue just before BlockLOD's, so that
    # the two see the same machine load (per-step ratios).
    fe = vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.ComputeNormalsOn()
    fe.ComputeScalarsOff()
    fe.ComputeGradientsOff()
    fe_times, fe_tris, fe_peak, fe_growth = [], [], 0.0, 0.0
    for level in range(4):
        progress("[%s] sweep of %d isovalues with BlockLODContour at level %d%s"
                 % (name, sweep_n, level, " and vtkFlyingEdges3D" if level == 3 else ""))
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
            if level == 3:
                fe.SetValue(0, v)
                s, p, g = timed(fe.Update)
                fe_times.append(s)
                fe_tris.append(fe.GetOutput().GetNumberOfCells())
                fe_peak, fe_growth = max(fe_peak, p), max(fe_growth, g)
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
    del fe
    result["sweep"]["fe"] = dict(times=fe_times, triangles=fe_tris, peak_mb=fe_peak,
                                 growth_mb=fe_growth)
    # --- (3b) the estimator at a sparse, high isovalue (issue 24) -------------------------------
    sparse = SPARSE_ISOVALUES.get(name)
    if sparse is not None and lo < sparse <= hi:
        progress("[%s] estimator at the sparse isovalue %g" % (name, sparse))
        # A fresh filter extracts level 0; its estimates of levels 1-3 are read before those
        # levels are extracted.
        probe = new_lod(sparse, 0)
        probe.UpdatePipeline()
        estimates = lod_info(probe)["est_tris"]
        actual = []
        for level in range(4):
            probe.LOD = level
            probe.UpdatePipeline()
            actual.append(lod_info(probe)["triangles"])
        result["sparse"] = dict(iso=sparse, est_tris=estimates, triangles=actual)
        pvs.Delete(probe)
        del probe

    if args.frames:
        result["frames"] = measure_frames(args, name, source, image, array_name, pvs,
                                          BlockLODContour)
    result["peak_mb"] = memory.overall_mb()
    progress("[%s] done, peak RSS %.0f MB" % (name, result["peak_mb"]))
    with open(args.child_result, "w") as f:
        json.dump(result, f)
    return 0


# ----------------------------------------------------------------------------------------------
# Parent: runs one child per input, prints the tables
# ----------------------------------------------------------------------------------------------

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
    return [""] + markdown_table(headers, rows)


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


def distribution(errs, tolerance):
    """(fraction within tolerance, median, 95th percentile, worst) of the errors' magnitudes."""
    absolute = sorted(abs(e) for e in errs)
    p95 = absolute[min(len(absolute) - 1, int(math.ceil(0.95 * len(absolute))) - 1)]
    within = sum(1 for e in absolute if e <= tolerance) / len(absolute)
    return within, statistics.median(absolute), p95, absolute[-1]


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
        "= new isovalue on a filter that already ran on the input (\"cache full\": one whose "
        "cache, CacheMemoryLimit = --cache-mb, is full, so each change drops its oldest surface, "
        "as during a drag); cache hit = an (isovalue, level) "
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
            fedrag = next((row for row in block["rows"] if row["key"] == "fedrag"), fe)
            rows = []
            for row in block["rows"]:
                med, mn = statistics.median(row["times"]), min(row["times"])
                # The cache-full rows against FlyingEdges on their own isovalues.
                base = fedrag if row["key"] in ("fedrag", "drag3") else fe
                rows.append([row["method"], row["level"], fmt_s(mn), fmt_s(med),
                             fmt_ratio(med / statistics.median(base["times"])),
                             fmt_ratio(mn / min(base["times"])),
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
        "isovalue, i.e. made before the pair was ever extracted (exact when the filter can count "
        "every active block within its budget, else a sample scaled by an exact coarser level). "
        "paper = 2 triangles per "
        "cube x (8/stride)^3 cubes per block x active blocks (min < iso <= max, counted with numpy "
        "on 8x8x8-cell blocks sharing faces). Error = (estimate - actual) / actual; 'within' = "
        "|error| <= 10%. MB: EstimatedMB vs the output's GetMemorySize (KiB * 1024 / 10^6). "
        "Seconds: the filter's predicted extraction time vs the measured update.")
    pooled_ours, pooled_paper = [], []
    est_summary, est_under, seconds_summary, seconds_median_summary = {}, {}, {}, {}
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

    # Error distribution per input: the sweep's pairs and the sparse isovalue's.
    out("")
    out("### Error distribution per input (issue 24)")
    out("")
    out("Pairs with >= %d actual triangles: the sweep's (levels 0-3) and, where the input has one, "
        "a sparse high isovalue's (levels 1-3, estimated after a fresh filter extracted level 0). "
        "|err| = |estimate - actual| / actual; over/under: the largest error above/below the actual "
        "count." % TARGET_EST_MIN_TRIANGLES)
    rows = []
    for r in results:
        sw = r["sweep"]
        errs = []
        for level in range(4):
            rec = sw["levels"][str(level)]
            errs += errors(rec["est_tris"], rec["triangles"], TARGET_EST_MIN_TRIANGLES)
        sparse_note = "-"
        if "sparse" in r:
            sp = r["sparse"]
            sparse_errs = errors(sp["est_tris"][1:], sp["triangles"][1:], TARGET_EST_MIN_TRIANGLES)
            errs += sparse_errs
            sparse_note = "iso %g: %s" % (sp["iso"], ", ".join(
                "L%d %+.1f%%" % (l + 1, 100 * ((e - a) / a)) for l, (e, a) in
                enumerate(zip(sp["est_tris"][1:], sp["triangles"][1:])) if a >= TARGET_EST_MIN_TRIANGLES)
                or "no level with enough triangles")
        if not errs:
            continue
        within, median, p95, worst = distribution(errs, TARGET_EST_TOL)
        rows.append([r["input"], len(errs), fmt_pct(within), fmt_pct(median), fmt_pct(p95),
                     fmt_pct(worst), fmt_pct(max(0.0, max(errs))), fmt_pct(min(0.0, min(errs))),
                     sum(1 for e in errs if e < -TARGET_EST_TOL), sparse_note])
        est_summary[r["input"]] = (within, len(errs))
        est_under[r["input"]] = sum(1 for e in errs if e < -TARGET_EST_TOL)
    lines.extend(table(["input", "pairs", "within 10%", "median |err|", "95th pct |err|",
                        "worst |err|", "largest over", "largest under", "under by > 10%",
                        "sparse isovalue (issue 24 protocol)"], rows))

    # Seconds: the EstimatedSeconds of the extracting update against the update's time.
    out("")
    out("### EstimatedSeconds against the measured update (issue 23)")
    out("")
    out("EstimatedSeconds[level] as the extracting update reports it (predicted by the cost model "
        "from the pair's exact counts, before its surface is generated) against the time of that "
        "update (UpdatePipeline through the proxy), for the sweep's pairs over %.0f ms. "
        "err = predicted / measured - 1." % (1e3 * TARGET_SECONDS_MIN))
    rows = []
    for r in results:
        sw = r["sweep"]
        errs = []
        for level in range(4):
            rec = sw["levels"][str(level)]
            errs += [e / m - 1.0 for e, m in zip(rec["est_s"], rec["times"])
                     if m > TARGET_SECONDS_MIN and e > 0]
        if not errs:
            rows.append([r["input"], 0, "-", "-", "-", "-", "-"])
            continue
        within, median, p95, worst = distribution(errs, TARGET_SECONDS_TOL)
        rows.append([r["input"], len(errs), fmt_pct(within), fmt_pct(median), fmt_pct(p95),
                     fmt_pct(worst), "%+.1f%%" % (100 * statistics.median(errs))])
        seconds_summary[r["input"]] = (within, len(errs))
    lines.extend(table(["input", "pairs over 10 ms", "within 25%", "median |err|",
                        "95th pct |err|", "worst |err|", "median err"], rows))
    out("")
    out("A sweep's pair is one update, so a stall (another process holding a core for a time "
        "slice, ~20 ms here) lands on it whole. The warm changes of table 1 repeat each pair "
        "%s times: their median measured time against their median prediction, for the "
        "(isovalue, level) pairs over 10 ms:" % "/".join(sorted({str(r["repeats"]) for r in results})))
    rows = []
    for r in results:
        errs = []
        for block in r["cold"]:
            for row in block.get("rows", []):
                if row["key"].startswith("warm") and row.get("est_s"):
                    measured = statistics.median(row["times"])
                    predicted = statistics.median(row["est_s"])
                    if measured > TARGET_SECONDS_MIN and predicted > 0:
                        errs.append(predicted / measured - 1.0)
        if not errs:
            continue
        within, median, p95, worst = distribution(errs, TARGET_SECONDS_TOL)
        rows.append([r["input"], len(errs), fmt_pct(within), fmt_pct(median), fmt_pct(worst),
                     ", ".join("%+.0f%%" % (100 * e) for e in errs)])
        seconds_median_summary[r["input"]] = (within, len(errs))
    lines.extend(table(["input", "pairs over 10 ms (medians)", "within 25%", "median |err|",
                        "worst |err|", "errors"], rows))

    # (3c) ParaView: isovalue change to a rendered frame
    if any("frames" in r for r in results):
        lines.extend(frames_report(results))

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
            if "drag3" in by_key:
                drag = statistics.median(by_key["drag3"]["times"]) / \
                    statistics.median(by_key.get("fedrag", by_key["fe"])["times"])
                rows.append(["warm change level 3 <= 0.3x vtkFlyingEdges3D",
                             "%s, iso %g, cache full (a drag)" % (r["input"], block["iso"]),
                             fmt_ratio(drag), "yes" if drag <= TARGET_WARM else "no",
                             margin_text(drag, TARGET_WARM)])
        sw = r["sweep"]
        ratio = statistics.median(a / b for a, b in zip(sw["levels"]["3"]["times"],
                                                        sw["fe"]["times"]) if b > 0)
        rows.append(["warm change level 3 <= 0.3x vtkFlyingEdges3D",
                     "%s, sweep of %d (median of per-step ratios)" % (r["input"], sw["n"]),
                     fmt_ratio(ratio), "yes" if ratio <= TARGET_WARM else "no",
                     margin_text(ratio, TARGET_WARM)])
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
        if key in est_under:
            rows.append(["estimator never under the actual count by more than 10%",
                         "%s, %d pairs" % (key, pairs), "%d pairs under" % est_under[key],
                         "yes" if est_under[key] == 0 else "no", "-"])
    for label, summary in (("sweep pairs, one update each", seconds_summary),
                           ("warm changes, median of the runs", seconds_median_summary)):
        for key, (fraction, pairs) in summary.items():
            rows.append(["EstimatedSeconds within 25%% for pairs over 10 ms (%s)" % label,
                         "%s, %d pairs" % (key, pairs), fmt_pct(fraction),
                         "yes" if fraction >= 1.0 else "no",
                         "%d of %d outside" % (round((1.0 - fraction) * pairs), pairs)])
    for r in results:
        for row in r.get("frames", {}).get("ratios", []):
            rows.append(["(info) change+frame in ParaView, BlockLOD L3 / %s" % row["peer"],
                         "%s, %s" % (r["input"], r["frames"]["size"]), fmt_ratio(row["ratio"]),
                         "-", "-"])
    lines.extend(table(["target", "where", "measured", "met", "by how much"], rows))
    return lines


def frames_report(results):
    """Tables of the ParaView change+frame measurements (--frames)."""
    lines = [""]
    out = lines.append
    out("## 3c. ParaView: isovalue change to a rendered frame (issue 23)")
    out("")
    out("Builtin session, offscreen, llvmpipe. filter = the change's UpdatePipeline (for the Volume "
        "representation: setting IsosurfaceValues); representation = view.Update() (geometry "
        "filter, delivery); frame = Render() (the mapper's upload and the drawing). Medians over "
        "the steps, the methods taking turns at every step; ratio = median of the per-step ratios "
        "of change+frame to the peer's at the same step.")
    for r in results:
        fr = r.get("frames")
        if not fr:
            continue
        out("")
        if "skipped" in fr:
            out("### %s: skipped (%s)" % (input_title(r), fr["skipped"]))
            continue
        out("### %s; %s; isovalue %g + k * %g, %d steps; %s" % (
            input_title(r), fr["size"], fr["iso"], fr["delta"], fr["steps"], smp_text(r)))
        rows = []
        totals = {m: [sum(t) for t in steps] for m, steps in fr["times"].items()}
        ours = totals["BlockLOD L3"]
        fr["ratios"] = []
        for m, steps in fr["times"].items():
            med = [statistics.median(t[i] for t in steps) for i in range(3)]
            paired = [a / b for a, b in zip(ours, totals[m]) if b > 0]
            ratio = statistics.median(paired) if paired else float("nan")
            if m != "BlockLOD L3":
                fr["ratios"].append(dict(peer=m, ratio=ratio))
            rows.append([m, fmt_s(med[0]), fmt_s(med[1]), fmt_s(med[2]),
                         fmt_s(statistics.median(totals[m])), fmt_s(min(totals[m])),
                         fmt_ratio(ratio) if m != "BlockLOD L3" else "-",
                         (statistics.median(fr["triangles"][m]) if fr["triangles"][m] and
                          fr["triangles"][m][0] else "-")])
        lines.extend(table(["method", "filter s", "representation s", "frame s",
                            "change+frame s (median)", "min", "BlockLOD / this (paired)",
                            "triangles"], rows))
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


def run_parent(args, argv):
    command = "pvpython " + " ".join(shlex.quote(a) for a in [sys.argv[0]] + argv)
    if not args.plugin or not os.path.exists(args.plugin):
        progress("plugin not found: %r (pass --plugin)" % args.plugin)
        return 2
    requested = [s.strip() for s in args.inputs.split(",") if s.strip()] or list(DEFAULT_INPUTS)
    for name in requested:
        if name not in ALL_INPUTS:
            progress("unknown input %r (choose from %s)" % (name, ", ".join(ALL_INPUTS)))
            return 2
    skipped, inputs = [], []
    for name in requested:
        if name.startswith("ct") and not os.path.exists(ct_path()):
            skipped.append((name, "no CT at %s (run Python/fetch_data.py; set MEDISO_DATA_DIR)"
                            % ct_path()))
        elif name.startswith("mri") and not os.path.exists(mri_path()):
            skipped.append((name, "no MRI at %s (run Python/fetch_data.py; set MEDISO_DATA_DIR)"
                            % mri_path()))
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
        if args.frames and mpi:
            mpi.append("--force-offscreen-rendering")
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
    load_after = load_average()
    if args.json:  # first, so that the measurements survive a failing report
        with open(args.json, "w") as f:
            json.dump(dict(command=command, results=results, skipped=skipped, started=started,
                           wall=wall, load_before=load_before, load_after=load_after), f)
        progress("wrote " + args.json)
    lines = report(args, results, skipped, command, started, wall, load_before, load_after)
    text = "\n".join(lines) + "\n"
    sys.stdout.write("\n" + text)
    sys.stdout.flush()
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)
        progress("wrote " + args.out)
    return 0 if results else 1


def run_interaction(args):
    """--interaction: still and interactive rotation frames of Block LOD Contour's displays."""
    import paraview.simple as pvs

    if not os.environ.get("DISPLAY"):
        print("--interaction renders: run it under X (Testing/Scripts/with-xvfb.sh)")
        return 1
    pvs.LoadPlugin(args.plugin)
    width, height = [int(v) for v in args.frame_size.lower().split("x")]
    lines = ["# Block LOD Contour: still vs interactive frames in ParaView", "",
             "Command: `%s`" % " ".join(shlex.quote(a) for a in sys.argv),
             "Machine: %s, %.0f GB; load average before: %s" % (cpu_model(), mem_total_gb(),
                                                                 load_average()), ""]
    frame_log = []
    for name in (args.inputs.split(",") if args.inputs else ["ct"]):
        source, image, label, keep = make_input(name, pvs, pvs.MedicalPhantom)
        array_name = image.GetPointData().GetScalars().GetName()
        skin, bone = (isovalues_for(args, name) + [400.0])[:2]
        view = pvs.CreateView("RenderView")
        view.ViewSize = [width, height]
        view.OrientationAxesVisibility = 0
        filters, displays = [], []
        for iso in (skin, bone):
            f = pvs.BlockLODContour(Input=source, ContourBy=["POINTS", array_name], Isosurfaces=[iso])
            f.LOD = 3
            f.AutoLOD = 0
            d = pvs.Show(f, view)
            d.ColorArrayName = [None, ""]
            filters.append(f)
            displays.append(d)
        pvs.ResetCamera(view)
        camera = view.GetActiveCamera()
        still_triangles = [int(f.GetDataInformation().GetNumberOfCells()) for f in filters]
        rows = []
        # The main renderer's own time of each frame (its StartEvent to its EndEvent) and the
        # render window's (every renderer, the blit and the swap): the displays' frame-time model
        # observes and predicts the window's (a frame's wall time adds little around it).
        renderer = view.GetRenderer()
        clock = {"start": 0.0, "last": 0.0}

        def on_start(*_):
            clock["start"] = time.perf_counter()

        def on_end(*_):
            clock["last"] = time.perf_counter() - clock["start"]

        renderer.AddObserver("StartEvent", on_start)
        renderer.AddObserver("EndEvent", on_end)
        # And the render window's (every renderer of the view, and the buffer swap).
        window = view.GetRenderWindow()
        window_clock = {"start": 0.0, "last": 0.0}

        def on_window_start(*_):
            window_clock["start"] = time.perf_counter()

        def on_window_end(*_):
            window_clock["last"] = time.perf_counter() - window_clock["start"]

        window.AddObserver("StartEvent", on_window_start)
        window.AddObserver("EndEvent", on_window_end)

        def drawn(d):
            sub = d.SMProxy.GetProperty("BlockLODInteractiveLevel").GetParent()
            sub.UpdatePropertyInformation()
            return (int(d.GetProperty("BlockLODInteractiveLevel")[0]),
                    int(d.GetProperty("BlockLODInteractiveTriangles")[0]),
                    float(d.GetProperty("BlockLODPredictedInteractiveSeconds")[0]),
                    int(d.GetProperty("BlockLODLastRenderTranslucency")[0]))

        how = {0: "", 1: ", peeled", 2: ", blended"}  # BlockLODLastRenderTranslucency

        for opacity in (1.0, 0.3):
            displays[0].Opacity = opacity
            modes = [("Block LOD levels", 1, "One Blended Pass")]
            if opacity < 1.0:
                modes.append(("Block LOD levels, depth peeling", 1, "Depth Peeling"))
            modes.append(("ParaView decimation", 0, "Depth Peeling"))
            for mode, levels, translucency in modes:
                for d in displays:
                    d.BlockLODInteractiveLevels = levels
                    d.BlockLODInteractiveTranslucency = translucency
                pvs.Render(view)
                pvs.Render(view)
                still, moving, rendered, still_rendered, windowed = [], [], [], [], []
                for _ in range(args.rotation_frames):
                    camera.Azimuth(1.0)
                    t0 = time.perf_counter()
                    pvs.Render(view)
                    still.append(time.perf_counter() - t0)
                    still_rendered.append(clock["last"])
                camera.Azimuth(1.0)
                t0 = time.perf_counter()
                view.SMProxy.InteractiveRender()  # makes and delivers the LOD geometry
                first = time.perf_counter() - t0
                for _ in range(args.rotation_frames):
                    camera.Azimuth(1.0)
                    t0 = time.perf_counter()
                    view.SMProxy.InteractiveRender()
                    moving.append(time.perf_counter() - t0)
                    rendered.append(clock["last"])
                    windowed.append(window_clock["last"])
                what = [drawn(d) for d in displays]
                # The prediction of the frame drawn: each display predicts its level with the
                # others' triangles added, so the last display to choose predicts the frame.
                predicted = what[-1][2] if levels and what[-1][0] >= 0 else 0.0
                # The display predicts the window's frame (its model, fitted to the renderer's
                # time, plus the window's fixed cost: FrameOverhead), what a user waits for: the
                # window's time is the measure; the renderer's, beside it, tells a miss of the
                # model's triangles from one of the window's fixed cost.
                def share_within(measured):
                    within = [abs(predicted / m - 1.0) <= 0.25 for m in measured if m > 0] \
                        if predicted > 0 else []
                    return ("%d%%" % round(100.0 * sum(within) / len(within))) if within else "-"
                frame_log.append({"scene": "%s, %s" % (opacity, mode), "still_wall": still,
                                  "interactive_wall": moving, "interactive_renderer": rendered,
                                  "still_renderer": still_rendered, "interactive_window": windowed,
                                  "drawn": what})
                rows.append(["%s (%s)" % ("translucent skin %.1f" % opacity if opacity < 1 else "opaque",
                                          mode),
                             fmt_s(statistics.median(still)), fmt_s(statistics.median(moving)),
                             "%.2f" % (statistics.median(moving) / statistics.median(still)),
                             fmt_s(first),
                             " / ".join(("L%d %d" % w[:2] if w[0] >= 0 else "decimated %d" % w[1])
                                        + how.get(w[3], "") for w in what),
                             " / ".join(fmt_s(w[2]) if w[0] >= 0 else "-" for w in what),
                             "%s / %s" % (fmt_s(statistics.median(rendered)),
                                          fmt_s(statistics.median(windowed))),
                             "%s (%s)" % (share_within(windowed), share_within(rendered))])
                progress("[%s] %s" % (name, rows[-1]))
        lines += ["## %s, %dx%d, LODThreshold %g MB, skin %g + bone %g (level 3: %s triangles)"
                  % (label, width, height, view.LODThreshold, skin, bone,
                     " + ".join(str(t) for t in still_triangles)), ""]
        lines += markdown_table(["scene (interactive LOD)", "still median", "interactive median",
                                 "ratio", "first interactive", "drawn while moving (skin / bone)",
                                 "predicted (skin / bone)", "interactive median: renderer / window",
                                 "frames within 25% of the prediction: window's time (renderer's)"],
                                rows)
        lines += [""]
        for d in displays:
            pvs.Delete(d)
        for f in filters:
            pvs.Delete(f)
        pvs.Delete(view)
        del keep
    lines += ["Load average after: %s" % load_average()]
    text = "\n".join(lines) + "\n"
    sys.stdout.write(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(frame_log, f, indent=1)
    return 0


def main():
    argv = sys.argv[1:]
    args = parse_args(argv)
    if args.interaction:
        return run_interaction(args)
    if args.child:
        return run_child(args)
    if args.report_from:
        with open(args.report_from) as f:
            saved = json.load(f)
        lines = report(args, saved["results"], saved["skipped"], saved["command"],
                       saved["started"], saved["wall"], saved["load_before"], saved["load_after"])
        sys.stdout.write("\n".join(lines) + "\n")
        return 0
    return run_parent(args, argv)


if __name__ == "__main__":
    sys.exit(main())
