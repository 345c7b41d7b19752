"""An isovalue change answered coarse first, then refined (medical_isosurfaces.RefineAfterChange),
against a plain change, in ParaView (issue 30 point 3; docs/blocklod.md).

    Testing/Scripts/with-xvfb.sh pvpython --no-mpi Python/benchmark_refine.py PLUGIN [--budget 0.1]

The head CT from the data cache (python3 Python/fetch_data.py), one bone isovalue, a Block LOD
Contour with Auto LOD shown in a 1024x768 render view, builtin session: three plain changes warm
the filter's cost model, then five plain changes (the property set, then Render: the full level at
once) and five RefineAfterChange changes (the first render at the level that fits the budget, then
the refinement and its render), each to an isovalue not seen before; printed: the seconds from the
change to its first render and to the full level, medians, and the level first drawn; last, a
change whose refinement a newer change aborts (counted).
"""
import argparse
import os
import statistics
import time

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)

parser = argparse.ArgumentParser()
parser.add_argument("plugin")
parser.add_argument("--budget", type=float, default=0.1, help="the first answer's seconds")
parser.add_argument("--size", default="1024x768")
args = parser.parse_args()

LoadPlugin(args.plugin, ns=globals())
import medical_isosurfaces  # noqa: E402  (embedded in the plugin)

path = os.path.join(os.path.expanduser("~"), ".cache", "medical-isosurfaces", "ct_head.mha")
if not os.path.isfile(path):
    raise SystemExit("benchmark_refine: %s is missing (python3 Python/fetch_data.py)" % path)
contour = BlockLODContour(Input=OpenDataFile(path))
contour.Isosurfaces = [400.0]
contour.AutoLOD = 1
view = CreateRenderView()
view.ViewSize = [int(x) for x in args.size.split("x")]
Show(contour, view)
view.ResetCamera()
Render(view)


def plain(values):
    start = time.perf_counter()
    contour.Isosurfaces = values
    Render(view)
    return time.perf_counter() - start


for v in (410.0, 420.0, 430.0):
    plain([v])
plain_seconds = [plain([500.0 + 10 * i]) for i in range(5)]
refine = medical_isosurfaces.RefineAfterChange(contour, view, frame_budget=args.budget)
changes = [refine.change([600.0 + 10 * i]) for i in range(5)]
aborted = refine.change([700.0], newer=lambda: True)


def line(name, seconds):
    return "%s s: %s, median %.3f" % (name, " ".join("%.3f" % s for s in seconds),
                                      statistics.median(seconds))


print(line("plain change (full level at once)", plain_seconds))
print(line("RefineAfterChange first answer", [c["first_seconds"] for c in changes]) +
      ", levels %s" % [c["first_level"] for c in changes])
print(line("RefineAfterChange full level", [c["seconds"] for c in changes]))
print("a refinement a newer change aborted: aborted %s, counted %d" %
      (aborted["aborted"], refine.refinements_aborted))
