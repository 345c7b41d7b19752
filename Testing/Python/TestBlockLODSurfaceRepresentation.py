"""Block LOD Contour's display draws a coarser Block LOD level while the camera moves.

Builtin session (ctest TestBlockLODSurfaceRepresentation), or a client of a pvserver
(TestBlockLODSurfaceRepresentationClientServer, run by Testing/Scripts/client-server.sh with
--port; local rendering, so the interactive geometry is delivered to the client and drawn there,
as ParaView delivers its own LOD). On the phantom's skin (-500) and bone (400) at level 3, with
the view's LODThreshold at 0 (the view always uses LOD geometry while interacting):
- the filter's display is the "Surface" representation type of its own display proxy;
- for budgets between the levels' exact triangle counts (each level made by a filter at that
  LOD), an interactive render draws the finest level within the budget, and says which level
  and how many triangles (equal to that level's, exactly), on the process that rendered;
- the still render after interaction is the same image as before it (pixel for pixel), and an
  interactive frame at level 1 differs from it (it really drew the coarser surface);
- with InteractiveLevels off, the LOD is ParaView's decimated copy (no level; other triangles);
- a level made once is served from the filter's cache afterwards (its NumberOfExtractions does
  not grow when the budget returns to that level), and the output's own level costs none.
(GenerateLevel itself, level by level, is TestBlockLODContourGenerateLevel.)
"""
import argparse
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)
from paraview import servermanager

import blocklod_display
import checks

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", default=os.environ.get("MEDISO_PLUGIN"))
parser.add_argument("--out", default=os.environ.get("MEDISO_TEST_OUTPUT", os.getcwd()))
parser.add_argument("--host", default="localhost")
parser.add_argument("--port", type=int, default=0, help="a pvserver to connect to")
args, _ = parser.parse_known_args()  # client-server.sh passes more options

check = checks.Checks()
remote = args.port > 0
if remote:
    if Connect(args.host, args.port, timeout=30) is None:
        print("FAILED: could not connect to %s:%d" % (args.host, args.port))
        sys.exit(1)
    LoadPlugin(args.plugin, remote=False, ns=globals())
    LoadPlugin(args.plugin, remote=True, ns=globals())
else:
    LoadPlugin(args.plugin, ns=globals())

SIZE = [400, 300]
phantom = MedicalPhantom(Dimensions=[128, 128, 128])
contour = BlockLODContour(Input=phantom)
contour.Isosurfaces = [-500.0, 400.0]
contour.LOD = 3

# Exact triangles of every level, each made by a filter of its own.
exact = []
for level in range(4):
    reference = BlockLODContour(Input=phantom)
    reference.Isosurfaces = [-500.0, 400.0]
    reference.LOD = level
    reference.UpdatePipeline()
    exact.append(int(reference.GetDataInformation().GetNumberOfCells()))
    Delete(reference)
print("exact triangles per level: %s" % exact)
check(exact[0] < exact[1] < exact[2] < exact[3], "each level has more triangles than the one below")

view = CreateView("RenderView")
view.ViewSize = SIZE
view.OrientationAxesVisibility = 0
view.UseColorPaletteForBackground = 0
view.Background = [0.1, 0.1, 0.15]
view.LODThreshold = 0.0  # MB: interactive renders always draw the LOD geometry
if remote:
    view.RemoteRenderThreshold = 1e6  # MB: render on the client
display = Show(contour, view)
check(display.GetXMLName() == "BlockLODContourRepresentation",
      "the filter's display is its own proxy (got %s)" % display.GetXMLName())
check(display.Representation == "Surface", "shown as 'Surface' (got %s)" % display.Representation)
check(display.BlockLODInteractiveLevels == 1, "interactive levels are on by default")
check(abs(display.BlockLODInteractiveFrameBudget - 0.1) < 1e-12, "a frame budget of 0.1 s by default")
display.BlockLODInteractiveFrameBudget = 0.0  # the triangle budget alone decides, exactly
view.CameraPosition = [400.0, -300.0, 200.0]
view.CameraFocalPoint = [0.0, 0.0, 0.0]
view.CameraViewUp = [0.0, 0.0, 1.0]
view.ResetCamera()


def frame_info():
    return blocklod_display.frame_info(display)


def window_pixels():
    return blocklod_display.window_pixels(view)


def still_pixels():
    Render(view)
    return window_pixels()


def interact():
    """An interactive render, as during a mouse drag (the camera moved a little first)."""
    camera = GetActiveCamera()
    camera.Azimuth(1.0)
    view.SMProxy.InteractiveRender()
    camera.Azimuth(-1.0)


before = still_pixels()
info = frame_info()
check(info["lod"] == 0, "a still render draws the full level, not the LOD (%s)" % info)
check((abs(before - [25, 25, 38]) > 8).any(axis=2).mean() > 0.05, "the still image shows the surface")



def extractions():
    contour.UpdatePropertyInformation()
    return int(contour.GetProperty("NumberOfExtractions")[0])


for level in (2, 1, 0, 3, 1):
    # A budget between this level's count and the next finer one's.
    budget = exact[level] + (exact[level + 1] - exact[level]) // 2 if level < 3 else 10 * exact[3]
    extracted = extractions()
    display.BlockLODInteractiveTriangleBudget = budget
    Render(view)
    interact()
    info = frame_info()
    check(info["lod"] == 1, "budget %d: the interactive render drew the LOD geometry" % budget)
    check(info["level"] == level and info["triangles"] == exact[level],
          "budget %d: interactive frames draw level %d with its %d triangles (got %s)"
          % (budget, level, exact[level], info))
    if level == 1:
        moving = window_pixels()
    if level == 3:
        check(extractions() == extracted, "level 3 is the output itself: no extraction")
# At the boundaries: a budget of exactly a level's triangles takes it, one less the level below.
for level in (2, 1):
    for budget, expected in ((exact[level], level), (exact[level] - 1, level - 1)):
        display.BlockLODInteractiveTriangleBudget = budget
        Render(view)
        interact()
        info = frame_info()
        check(info["level"] == expected and info["triangles"] == exact[expected],
              "budget %d: level %d (got %s)" % (budget, expected, info))
print("interactive level per budget: checked levels 2, 1, 0, 3, 1 and the boundaries")
extracted = extractions()
display.BlockLODInteractiveTriangleBudget = exact[2] + (exact[3] - exact[2]) // 2
Render(view)
interact()
check(frame_info()["level"] == 2 and extractions() == extracted,
      "returning to level 2 is served from the filter's cache (%d extractions, were %d)"
      % (extractions(), extracted))

# The frame budget, through the frame-time model: nothing fits a nanosecond (level 0), a
# thousand seconds fit the output's own level; the prediction is reported.
display.BlockLODInteractiveTriangleBudget = 0.0
for seconds, expected in ((1e-9, 0), (1e3, 3)):
    display.BlockLODInteractiveFrameBudget = seconds
    Render(view)
    interact()
    info = frame_info()
    predicted = display.GetProperty("BlockLODPredictedInteractiveSeconds")[0]
    check(info["level"] == expected and info["triangles"] == exact[expected],
          "frame budget %g s: level %d (got %s)" % (seconds, expected, info))
    if not remote:  # chosen on the data server: this process only in builtin mode
        check(0 < predicted, "frame budget %g s: a prediction is reported (%g s)" % (seconds, predicted))
display.BlockLODInteractiveFrameBudget = 0.0

after = still_pixels()
info = frame_info()
check(info["lod"] == 0, "the still render after interaction draws the full level (%s)" % info)
differ = int((before != after).any(axis=2).sum())
check(differ == 0, "the still image after interaction equals the one before (%d pixels differ)" % differ)
moved = float((abs(moving - before) > 8).any(axis=2).mean())
check(moved > 0.002, "an interactive frame at level 1 differs from the still image (%.2f%%)" % (100 * moved))

display.BlockLODInteractiveLevels = 0
Render(view)
interact()
info = frame_info()
check(info["lod"] == 1 and info["level"] == -1 and 0 < info["triangles"] and info["triangles"] not in exact,
      "interactive levels off: ParaView's decimated copy (%s)" % info)
display.BlockLODInteractiveLevels = 1

# Two displays in one view, skin (translucent) and bone each from a filter of its own as a user
# shows them: at the default frame budget they choose one level together and predict the same
# frame, a translucent one (issue 30: the first display to choose used to add the other's still
# triangles, and the opaque one predicted an opaque frame). Predictions are made on the data
# server: builtin only.
if not remote:
    Hide(contour, view)
    pair = []
    for iso in (-500.0, 400.0):
        surface = BlockLODContour(Input=phantom)
        surface.Isosurfaces = [iso]
        surface.LOD = 3
        pair.append((surface, Show(surface, view)))
    pair[0][1].Opacity = 0.3
    Render(view)
    Render(view)  # a display counts its levels at its first frame of new data; this one is learnt
    interact()
    chosen, predicted = [], []
    for _, shown in pair:
        shown.SMProxy.GetProperty("BlockLODInteractiveLevel").GetParent().UpdatePropertyInformation()
        chosen.append(int(shown.GetProperty("BlockLODInteractiveLevel")[0]))
        predicted.append(float(shown.GetProperty("BlockLODPredictedInteractiveSeconds")[0]))
    check(chosen[0] == chosen[1] and 0 <= chosen[0] <= 3,
          "two displays choose one level together (skin, bone: %s)" % chosen)
    check(predicted[0] > 0 and abs(predicted[0] - predicted[1]) <= 1e-12 * predicted[0],
          "two displays predict the same frame (skin, bone: %s s)" % predicted)
    for surface, shown in pair:
        Delete(shown)
        Delete(surface)

check.finish("TestBlockLODSurfaceRepresentation%s: interactive levels %s, still image unchanged"
             % (" (client/server)" if remote else "", exact))
if remote:
    Disconnect()
