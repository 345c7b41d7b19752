"""pvpython test: the HistoPyramid Isosurface representation's CPU-side copies under an
address-space limit (as `ulimit -v` sets it) the test sets on itself, after the render
window exists.

- A double volume whose rows are not a multiple of 4 points: the upload's copy (doubles as
  float, rows padded) does not fit, so the GPU path is refused with that reason, the one
  fallback warning says it, and the CPU path takes over; nothing aborts.
- An unevenly spaced rectilinear grid whose even resampling does not fit: one error, nothing
  drawn.

Usage: pvpython TestHistoPyramidRepresentationMemory.py --plugin PATH --out DIR
"""
import argparse
import resource

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)
from vtkmodules.vtkCommonCore import vtkDoubleArray
from vtkmodules.vtkCommonDataModel import vtkRectilinearGrid

from HistoPyramidRepresentationChecks import REPRESENTATION, captured, make_view, render_info
from checks import Checks  # Testing/Python/checks.py

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", required=True)
parser.add_argument("--out", required=True)
args = parser.parse_args()
LoadPlugin(args.plugin, ns=globals())

check = Checks()


def limit_address_space(headroom_mb):
    """What is mapped now plus headroom_mb MiB, for the rest of the process."""
    with open("/proc/self/status") as status:
        vm_kb = [int(line.split()[1]) for line in status if line.startswith("VmSize")][0]
    resource.setrlimit(resource.RLIMIT_AS,
                       (vm_kb * 1024 + (headroom_mb << 20), resource.RLIM_INFINITY))


# 301 x 300 x 300 doubles (217 MB): the upload copies them as float with rows padded to
# 304 points, 217.8 MB, more than the 150 MiB left.
phantom = MedicalPhantom(Dimensions=[301, 300, 300])
volume = Calculator(Input=phantom, ResultArrayName="HUd", Function="HU", ResultArrayType="Double")
volume.UpdatePipeline()

# The uneven grid: 80 points per axis packed at one end, so an even grid as fine needs
# 320 points per axis (32.8 M points of a double and a mask, 294.9 MB).
N = 80
grid = vtkRectilinearGrid()
grid.SetDimensions(N, N, N)
for setter in (grid.SetXCoordinates, grid.SetYCoordinates, grid.SetZCoordinates):
    coords = vtkDoubleArray()
    for i in range(N):
        coords.InsertNextValue(0.01 * i if i < N - 1 else 100.0)
    setter(coords)
values = vtkDoubleArray()
values.SetName("value")
for k in range(N):
    for j in range(N):
        for i in range(N):
            values.InsertNextValue(float(i + j + k))
grid.GetPointData().SetScalars(values)
uneven = TrivialProducer()
uneven.GetClientSideObject().SetOutput(grid)
uneven.UpdatePipeline()

# The render window and its context exist before the limit is set.
view = make_view()
display = Show(volume, view)
display.SetRepresentationType(REPRESENTATION)
ColorBy(display, ("POINTS", "HUd"))
# Above every value of the phantom: the CPU path then has nothing to draw, so that what
# it allocates does not depend on the surface (the copy is refused before any isovalue
# is looked at).
display.IsosurfaceValues = [1200.0]
display.Visibility = 0
Render(view)

limit_address_space(150)
display.Visibility = 1
_, text = captured(lambda: Render(view))
info = render_info(display)
reason_start = "the volume's copy for the GPU upload (217.8 MB) does not fit in the "
reason_end = " MB the process may still allocate (the process's address-space limit (ulimit -v))"
check(info["reason"].startswith(reason_start) and info["reason"].endswith(reason_end),
      "the GPU path is refused for the upload's copy (reason %r)" % info["reason"])
check(info["path"] == "fallback" and info["triangles"] == 0,
      "the CPU path draws instead (%s, %d triangles)" % (info["path"], info["triangles"]))
check(text.count("GPU isosurface path unavailable (" + reason_start) == 1 and "ERROR" not in text,
      "one fallback warning with the reason, no error (got %r)" % text.strip()[-500:])
print("upload: %s, %d triangles; %s" % (info["path"], info["triangles"], info["reason"]))
Hide(volume, view)

uneven_display = Show(uneven, view)
uneven_display.SetRepresentationType(REPRESENTATION)
uneven_display.IsosurfaceValues = [60.0]
_, text = captured(lambda: Render(view))
expected_start = ("HistoPyramid Isosurface cannot draw this rectilinear grid: the rectilinear grid "
                  "resampled onto an even grid (294.9 MB) does not fit in the ")
check(text.count("ERROR") == 1 and expected_start in text and "(ulimit -v))." in text,
      "one error: %r... (got %r)" % (expected_start, text.strip()[-500:]))
check("resampled onto an even" not in text.split(expected_start)[-1],
      "no resampling warning after the error")
print("rectilinear: %s" % (text.strip().splitlines()[-1] if text.strip() else "no message"))

check.finish("HistoPyramid representation under a memory limit: all checks passed")
