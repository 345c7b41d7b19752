"""pvpython test: where a new display and a new Block LOD Contour start (issue 33).

- A CT (MedicalPhantom, in Hounsfield units): a new image display starts its
  IsosurfaceValues at skin and bone (-500, 400), marked as the HU start for
  the GUI's isosurface list (which gives skin its colour and translucency),
  its colours and opacities untouched; Block LOD Contour starts at bone (400).
- Not HU: a synthetic uint8 MRI-like volume (background 18-22, a ball at
  198-202) starts at Otsu's threshold, 22.5 (the lowest split between the two
  modes; also worked out here with numpy, independently of the plugin); the
  phantom shifted to positive values (float, 256 bins) starts at its Otsu
  threshold as numpy computes it from the fetched data.
- Values a script sets are kept: Block LOD Contour created with Isosurfaces,
  a display's IsosurfaceValues set after Show.
- An isovalue outside the data range is warned about once (the values and
  the range named), not on every render; a new out-of-range value again once.
- The hints: the display keeps UniformGridRepresentation's warning before
  Volume and names the plugin's initialization helper; Block LOD Contour's
  Visibility hint hides its input on Apply (replace_input 1: the GUI's
  pqApplyBehavior reads it; pvpython's Show applies no Visibility hint, so the
  hint itself is checked).
- One name for the DICOM reader: its label, and its file type in the open dialog.

Any VTK error or warning not captured by the test fails it (ctest's fail regex).
"""
import argparse
import os
import sys

import numpy
from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)
from paraview import servermanager
from vtkmodules.util.numpy_support import vtk_to_numpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import HistoPyramidRepresentationChecks as hp  # noqa: E402
from checks import Checks  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", default=os.environ.get("MEDISO_PLUGIN"))
parser.add_argument("--out", required=True)
args = parser.parse_args()
LoadPlugin(args.plugin, ns=globals())  # noqa: F405

check = Checks()
START = "MedicalIsosurfaceStart"


def otsu(values, integral):
    """Otsu's threshold as HistogramThreshold.h defines it, in numpy: bins of one
    integer from min - 0.5 for integers spanning at most 256 values, else 256
    equal bins over the range; the split maximising w0 w1 (m0 - m1)^2, the
    lowest on ties; the value at the boundary after it."""
    lo, hi = float(values.min()), float(values.max())
    if integral and hi - lo + 1 <= 256:
        low, width, count = lo - 0.5, 1.0, int(hi - lo + 1)
    else:
        low, width, count = lo, (hi - lo) / 256.0, 256
    bins = numpy.clip(numpy.floor((values.astype(numpy.float64) - low) / width), 0, count - 1)
    counts = numpy.bincount(bins.astype(numpy.int64), minlength=count).astype(numpy.float64)
    index = numpy.arange(count, dtype=numpy.float64)
    below = numpy.cumsum(counts)[:-1]
    moment = numpy.cumsum(index * counts)[:-1]
    total, total_moment = counts.sum(), (index * counts).sum()
    above = total - below
    valid = (below > 0) & (above > 0)
    between = numpy.where(valid, below * above * (
        moment / numpy.where(valid, below, 1) - (total_moment - moment) / numpy.where(valid, above, 1)) ** 2, -1)
    return low + (int(numpy.argmax(between)) + 1) * width


def fetched_values(source, name):
    data = servermanager.Fetch(source)
    return vtk_to_numpy(data.GetPointData().GetArray(name))


view = hp.make_view([300, 300])

# --- a CT: skin and bone ------------------------------------------------------
phantom = MedicalPhantom(Dimensions=[48, 48, 48], Spacing=[3.0, 3.0, 3.0])  # noqa: F405
display = Show(phantom, view)
check(list(display.IsosurfaceValues) == [-500.0, 400.0],
      "CT: a new display starts at skin and bone (got %s)" % list(display.IsosurfaceValues))
check(display.SMProxy.HasAnnotation(START),
      "CT: the display is marked as the HU start for the isosurface list")
check(list(display.HistoPyramidSurfaceOpacities) == [] and display.HistoPyramidColorEachSurface == 0
      and list(display.HistoPyramidSurfaceColors) == [],
      "CT: the start sets values only (opacities %s, colour each %s)"
      % (list(display.HistoPyramidSurfaceOpacities), display.HistoPyramidColorEachSurface))
hints = display.SMProxy.GetHints()
helper = hints.FindNestedElementByName("InitializationHelper") if hints else None
warn = hints.FindNestedElementByName("WarnOnRepresentationChange") if hints else None
check(helper is not None and helper.GetAttribute("class") == "vtkSMMedicalIsosurfaceInitializationHelper",
      "the display's hints name the plugin's initialization helper")
check(warn is not None and warn.GetAttribute("value") == "Volume",
      "the display keeps UniformGridRepresentation's warning before Volume")
contour = BlockLODContour(Input=phantom)  # noqa: F405
check(list(contour.Isosurfaces) == [400.0],
      "CT: a new Block LOD Contour starts at bone (got %s)" % list(contour.Isosurfaces))

# --- values a script sets are kept ---------------------------------------------
explicit = BlockLODContour(Input=phantom, Isosurfaces=[123.0])  # noqa: F405
explicit.UpdatePipeline()
check(list(explicit.Isosurfaces) == [123.0],
      "Block LOD Contour created with Isosurfaces=[123] keeps it (got %s)" % list(explicit.Isosurfaces))
display.IsosurfaceValues = [250.0]
display.SetRepresentationType(hp.REPRESENTATION)
Render(view)
check(list(display.IsosurfaceValues) == [250.0] and list(display.HistoPyramidSurfaceOpacities) == []
      and display.HistoPyramidColorEachSurface == 0,
      "IsosurfaceValues set by a script are kept, nothing else changed (got %s)"
      % list(display.IsosurfaceValues))

# --- an isovalue outside the data range: one warning ---------------------------
def renders():
    Render(view)
    Render(view)
    view.CameraPosition = [200.0, -300.0, 150.0]
    Render(view)


display.IsosurfaceValues = [5000.0, 400.0]
_, text = hp.captured(renders)
lines = [line for line in text.splitlines() if "outside the range" in line]
check(len(lines) == 1 and "5000" in lines[0] and "[-1000, " in lines[0] and '"HU"' in lines[0],
      "isovalue 5000: one warning naming it and the range, for three renders (got %r)" % lines)
display.IsosurfaceValues = [400.0]
_, text = hp.captured(renders)
check("outside the range" not in text, "back inside the range: no warning (got %r)" % text[:300])
display.IsosurfaceValues = [-5000.0, 9000.0]
_, text = hp.captured(renders)
lines = [line for line in text.splitlines() if "outside the range" in line]
check(len(lines) == 1 and "-5000, 9000 are outside" in lines[0],
      "two values outside: one warning naming both (got %r)" % lines)
display.IsosurfaceValues = [400.0]
Render(view)
Hide(phantom, view)  # noqa: F405

# --- not HU: Otsu's threshold ---------------------------------------------------
mri = ProgrammableSource()  # noqa: F405
mri.OutputDataSetType = "vtkImageData"
mri.Script = """
import numpy
from vtkmodules.util.numpy_support import numpy_to_vtk
n = 32
z, y, x = numpy.mgrid[0:n, 0:n, 0:n]
background = 18 + (x + 2 * y + 3 * z) % 5
ball = 198 + (x + y + z) % 5
inside = (x - 15.5) ** 2 + (y - 15.5) ** 2 + (z - 15.5) ** 2 < 100
values = numpy.where(inside, ball, background).astype(numpy.uint8)
out = self.GetOutput()
out.SetDimensions(n, n, n)
array = numpy_to_vtk(values.ravel(), deep=True)
array.SetName("MR")
out.GetPointData().SetScalars(array)
"""
mri.ScriptRequestInformation = ("from paraview import util\n"
                                "util.SetOutputWholeExtent(self, [0, 31, 0, 31, 0, 31])\n")
mri.UpdatePipeline()
expected = otsu(fetched_values(mri, "MR"), integral=True)
check(expected == 22.5, "numpy's Otsu threshold of the uint8 volume is 22.5 (got %r)" % expected)
mri_display = Show(mri, view)
check(list(mri_display.IsosurfaceValues) == [expected] and not mri_display.SMProxy.HasAnnotation(START),
      "uint8 MRI-like: the display starts at Otsu's threshold %r (got %s)"
      % (expected, list(mri_display.IsosurfaceValues)))
mri_contour = BlockLODContour(Input=mri)  # noqa: F405
check(list(mri_contour.Isosurfaces) == [expected],
      "uint8 MRI-like: Block LOD Contour starts at %r (got %s)" % (expected, list(mri_contour.Isosurfaces)))
Hide(mri, view)  # noqa: F405

shifted = Calculator(Input=phantom, Function="HU+1024", ResultArrayName="Shifted")  # noqa: F405
shifted.UpdatePipeline()
expected = otsu(fetched_values(shifted, "Shifted"), integral=False)
shifted_display = Show(shifted, view)
got = list(shifted_display.IsosurfaceValues)
check(len(got) == 1 and abs(got[0] - expected) <= 1e-9 * 2100,
      "the phantom shifted positive (double): starts at Otsu's threshold %r (got %s)" % (expected, got))
check(300 < expected < 1000, "...which lies between air (24) and soft tissue (1064): %r" % expected)
# TestHistoPyramidRepresentationClientServer expects the same value with the data on a server.
check(expected == 633.78125, "...633.78125, the value the client/server test expects: %r" % expected)
shifted_contour = BlockLODContour(Input=shifted)  # noqa: F405
got = list(shifted_contour.Isosurfaces)
check(len(got) == 1 and abs(got[0] - expected) <= 1e-9 * 2100,
      "the shifted phantom: Block LOD Contour starts at %r (got %s)" % (expected, got))

# --- Block LOD Contour hides its input on Apply -----------------------------------
hints = contour.SMProxy.GetHints()
visibility = hints.FindNestedElementByName("Visibility") if hints else None
check(visibility is not None and visibility.GetAttribute("replace_input") == "1",
      "Block LOD Contour's Visibility hint hides its input on Apply (replace_input %r)"
      % (visibility.GetAttribute("replace_input") if visibility is not None else None))

# --- one name for the DICOM reader -------------------------------------------------
prototype = servermanager.ProxyManager().SMProxyManager.GetPrototypeProxy(
    "sources", "MedicalDICOMSeriesReader")
factory = prototype.GetHints().FindNestedElementByName("ReaderFactory")
check(prototype.GetXMLLabel() == "Medical DICOM Series Reader"
      and "Medical DICOM Series Reader" in factory.GetAttribute("file_description"),
      "the DICOM reader's label and file type name it the same (%r, %r)"
      % (prototype.GetXMLLabel(), factory.GetAttribute("file_description")))

check.finish("TestMedicalIsosurfacesDefaults: all checks passed")
