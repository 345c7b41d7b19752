"""pvpython test: the 'HistoPyramid Isosurface' representation on bad and unusual input.

    pvpython TestHistoPyramidRepresentationBadInput.py --plugin PATH --out DIR

Each case is shown as the representation and rendered twice; what it prints is
captured and checked (so a passing run prints no VTK error or warning):
- image data whose spacing has a zero or a NaN component: one error naming the
  spacing, nothing drawn (path "none", the image is the background);
- IsosurfaceValues [nan]: one warning saying the value is not a number (not
  "no isovalues"), nothing drawn; [nan, 400]: the warning, and bone drawn as
  with [400] alone;
- a vtkRectilinearGrid (which ParaView's image-data display also takes):
  evenly spaced, drawn with no message and the same active cells as the image
  data it describes; unevenly spaced, drawn after one warning saying that it
  was resampled.
Runs on the GPU path, or on the fallback where the GL lacks it (its one
warning is then allowed on the first render of each display).
"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)

import HistoPyramidRepresentationChecks as hp

args = hp.parse_args()
check = hp.Checker()
LoadPlugin(args.plugin, ns=globals())

# A distance field (a sphere of radius 6 at the centre), as image data with
# the given spacing or as a rectilinear grid with the given coordinates.
FIELD = """
import math
from vtkmodules.vtkCommonCore import vtkDoubleArray
out = self.GetOutput()
n = 24
axes = {axes!r}
if {rectilinear!r}:
    out.SetDimensions(n, n, n)
    setters = [out.SetXCoordinates, out.SetYCoordinates, out.SetZCoordinates]
    for axis in range(3):
        c = vtkDoubleArray()
        for i in range(n):
            c.InsertNextValue(axes[axis][i])
        setters[axis](c)
else:
    out.SetDimensions(n, n, n)
    out.SetSpacing({spacing!r})
values = vtkDoubleArray()
values.SetName("distance")
for k in range(n):
    for j in range(n):
        for i in range(n):
            x, y, z = axes[0][i], axes[1][j], axes[2][k]
            values.InsertNextValue(math.sqrt((x - 11.5) ** 2 + (y - 11.5) ** 2 + (z - 11.5) ** 2))
out.GetPointData().SetScalars(values)
"""


def field(spacing=(1.0, 1.0, 1.0), axes=None):
    rectilinear = axes is not None
    if axes is None:
        axes = [[float(i) for i in range(24)]] * 3
    source = ProgrammableSource()
    source.OutputDataSetType = "vtkRectilinearGrid" if rectilinear else "vtkImageData"
    source.Script = FIELD.format(axes=axes, rectilinear=rectilinear, spacing=list(spacing))
    if not rectilinear:
        # Whole extent and spacing for the pipeline (the script sets the data's).
        source.ScriptRequestInformation = (
            "from paraview import util\n"
            "util.SetOutputWholeExtent(self, [0, 23, 0, 23, 0, 23])\n")
    return source


def show(source, isovalues, step):
    """Show as the representation, render twice; return (info, captured text,
    fraction of the image covered)."""
    view = hp.make_view([300, 300])
    display = Show(source, view)
    display.SetRepresentationType(hp.REPRESENTATION)
    display.IsosurfaceValues = isovalues
    view.CameraPosition = [11.5, -60.0, 11.5]
    view.CameraFocalPoint = [11.5, 11.5, 11.5]
    view.CameraViewUp = [0.0, 0.0, 1.0]

    def twice():
        Render(view)
        Render(view)

    _, text = hp.captured(twice)
    info = hp.render_info(display)
    pixels = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentationBadInput_%s.png" % step))
    Delete(display)
    Delete(view)
    return info, text, hp.foreground_fraction(pixels)


def without_fallback_warning(text, info):
    """The text less the fallback's one warning (allowed where there is no GPU path)."""
    if info["path"] == "fallback" or "GPU isosurface path unavailable" in text:
        lines = [line for line in text.splitlines() if "GPU isosurface path unavailable" not in line]
        return "\n".join(lines)
    return text


# --- zero and non-finite spacing ---------------------------------------------
for label, spacing in (("zero", (1.0, 0.0, 1.0)), ("nan", (1.0, float("nan"), 1.0))):
    source = field(spacing=spacing)
    info, text, covered = show(source, [6.0], "spacing_%s" % label)
    check("spacing" in text and "has a zero or non-finite component" in text
          and ("ERROR" in text or "ERR|" in text),
          "%s spacing: an error naming the spacing (got %r)" % (label, text.strip()[:300]))
    check(text.count("has a zero or non-finite component") == 1,
          "%s spacing: said once for two renders (got %d)"
          % (label, text.count("has a zero or non-finite component")))
    check(info["path"] == "none" and covered == 0.0,
          "%s spacing: nothing drawn (path %r, %.2f%% covered)" % (label, info["path"], 100 * covered))

# --- NaN isovalues -----------------------------------------------------------
phantom = MedicalPhantom(Dimensions=[48, 48, 48], Spacing=[3.0, 3.0, 3.0])
info, text, covered = show(phantom, [float("nan")], "isovalue_nan")
rest = without_fallback_warning(text, info)
check("not a number" in rest and "no isovalues" not in rest,
      "IsosurfaceValues [nan]: says the value is not a number (got %r)" % rest.strip()[:300])
check(rest.count("not a number") == 1, "[nan]: one warning for two renders")
check(info["path"] == "none" and covered == 0.0, "[nan]: nothing drawn (path %r)" % info["path"])

bone_info, bone_text, bone_covered = show(phantom, [hp.BONE], "isovalue_bone")
check(without_fallback_warning(bone_text, bone_info).strip() == "",
      "[400]: no message (got %r)" % bone_text.strip()[:300])
info, text, covered = show(phantom, [float("nan"), hp.BONE], "isovalue_nan_bone")
rest = without_fallback_warning(text, info)
check("1 of the 2 isovalues is not a number" in rest,
      "[nan, 400]: says which part is not a number (got %r)" % rest.strip()[:300])
check(info["path"] == bone_info["path"] and info["path"] in ("gpu", "fallback")
      and abs(covered - bone_covered) < 1e-9
      and info["primitives"] == bone_info["primitives"] and info["triangles"] == bone_info["triangles"],
      "[nan, 400] draws what [400] draws (%s against %s)" % (info, bone_info))

# --- rectilinear grids -------------------------------------------------------
image = field()
image_info, image_text, image_covered = show(image, [6.0], "image")
even = field(axes=[[float(i) for i in range(24)]] * 3)
info, text, covered = show(even, [6.0], "rectilinear_even")
check(without_fallback_warning(text, info).strip() == "",
      "evenly spaced rectilinear grid: no message (got %r)" % text.strip()[:300])
check(info["path"] == image_info["path"] and info["path"] in ("gpu", "fallback")
      and info["primitives"] == image_info["primitives"]
      and info["triangles"] == image_info["triangles"] and abs(covered - image_covered) < 1e-9,
      "evenly spaced rectilinear grid: drawn as its image data (%s against %s)" % (info, image_info))

uneven_axis = [float(i) if i < 12 else 12.0 + 1.5 * (i - 12) for i in range(24)]
uneven = field(axes=[uneven_axis, [float(i) for i in range(24)], [float(i) for i in range(24)]])
info, text, covered = show(uneven, [6.0], "rectilinear_uneven")
rest = without_fallback_warning(text, info)
check(rest.count("not evenly spaced") == 1 and "resampled" in rest,
      "unevenly spaced rectilinear grid: one warning saying it was resampled (got %r)"
      % rest.strip()[:300])
check("ERROR" not in rest and "Input port 0 of algorithm" not in rest,
      "no type error from the mapper (got %r)" % rest.strip()[:300])
check(info["path"] in ("gpu", "fallback") and covered > 0.01,
      "unevenly spaced rectilinear grid: drawn (path %r, %.1f%% covered)" % (info["path"], 100 * covered))

if check.failures:
    print("%d check(s) failed" % len(check.failures))
    sys.exit(1)
print("HistoPyramid representation bad input: all checks passed")
