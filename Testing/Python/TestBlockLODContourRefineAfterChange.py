"""pvpython test: an isovalue change of Block LOD Contour answered coarse first, then refined
(medical_isosurfaces.RefineAfterChange; issue 30 point 3; docs/blocklod.md).

    pvpython TestBlockLODContourRefineAfterChange.py --plugin PATH

On the phantom (128^3), a Block LOD Contour with Auto LOD (the memory budget allows level 3)
shown in a render view:
- with a frame budget no extraction fits (1 ns), a change is drawn first at level 0 (the filter's
  ChosenLevel after the first render, its output's triangles those of a filter at LOD 0) and
  says so; the refinement reaches level 3 with the triangles of a filter at LOD 3;
- a newer change waiting (``newer`` true at the refinement's first progress event) aborts the
  refinement: counted, the filter's output after it is the coarse answer again (not the empty
  output of the aborted update), and the next change refines to level 3;
- a budget the full level's extraction fits but not its extraction and its frame (the display's
  predicted still frame, BlockLODPredictedStillSeconds) is answered at a coarser level first;
- with a budget every level fits (the surfaces cached), the first answer is the full level and
  there is no refinement;
- the filter's settings (Auto LOD) are as the user set them after each refinement.
"""
import argparse
import os

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)
from paraview import servermanager

import checks

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", default=os.environ.get("MEDISO_PLUGIN"))
args, _ = parser.parse_known_args()
check = checks.Checks()

LoadPlugin(args.plugin, ns=globals())
import medical_isosurfaces  # noqa: E402  (embedded in the plugin: importable once it is loaded)

phantom = MedicalPhantom(Dimensions=[128, 128, 128])
contour = BlockLODContour(Input=phantom)
contour.Isosurfaces = [400.0]
contour.AutoLOD = 1
contour.MemoryBudget = 256.0
view = CreateRenderView()
view.ViewSize = [300, 200]
Show(contour, view)
view.ResetCamera()
Render(view)


def triangles(proxy):
    proxy.UpdatePipeline()
    return servermanager.Fetch(proxy).GetNumberOfCells()


def exact(value, level):
    reference = BlockLODContour(Input=phantom)
    reference.Isosurfaces = [value]
    reference.LOD = level
    count = triangles(reference)
    Delete(reference)
    return count


def chosen():
    """The filter's ChosenLevel (its last update's level)."""
    contour.UpdatePropertyInformation()
    return int(contour.GetProperty("ChosenLevel")[0])


def shown():
    """The triangles of the filter's output as it is now (no update)."""
    return contour.GetClientSideObject().GetOutputDataObject(0).GetNumberOfCells()


refine = medical_isosurfaces.RefineAfterChange(contour, view, frame_budget=1e-9)

# A change: level 0 first, then level 3.
found = contour.GetClientSideObject()
result = refine.change([300.0])
print("change to 300: %r" % result)
check(result["first_level"] == 0 and not result["aborted"] and result["level"] == 3,
      "a change is drawn first at level 0 and refined to level 3 (%r)" % result)
check(result["first_note"].startswith("First answer: level 0") and result["note"] == "",
      "the first answer said it is coarse, the refined one says nothing (%r, %r)"
      % (result["first_note"], result["note"]))
check(shown() == exact(300.0, 3) and chosen() == 3,
      "the refinement's output has level 3's triangles (%d, %d at LOD 3)"
      % (shown(), exact(300.0, 3)))
check(int(contour.AutoLOD) == 1, "Auto LOD is as the user set it after the refinement")
check(refine.refinements == 1 and refine.refinements_aborted == 0,
      "one refinement, none aborted (%d, %d)" % (refine.refinements, refine.refinements_aborted))

# The first answer's own image: a change observed at its first render.
first = {}


def first_render(caller, event):
    if not first:
        first["level"] = chosen()
        first["triangles"] = shown()


tag = view.GetRenderer().AddObserver("EndEvent", first_render)
result = refine.change([350.0])
view.GetRenderer().RemoveObserver(tag)
check(first.get("level") == 0 and first.get("triangles") == exact(350.0, 0),
      "the first render after a change draws level 0's triangles (%r; %d at LOD 0)"
      % (first, exact(350.0, 0)))

# A newer change waiting: the refinement is aborted, the coarse answer stays.
def extractions():
    contour.UpdatePropertyInformation()
    return int(contour.GetProperty("NumberOfExtractions")[0])


polls = []
extracted = extractions()
result = refine.change([250.0], newer=lambda: polls.append(1) or True)
check(extractions() == extracted + 1,
      "the aborted refinement extracted nothing (extractions %d -> %d: the first answer's only)"
      % (extracted, extractions()))
print("change to 250 with a newer one waiting: %r" % result)
check(result["aborted"] and result["level"] == 0 and refine.refinements_aborted == 1,
      "a newer change aborts the refinement, counted (%r, aborted %d)"
      % (result, refine.refinements_aborted))
check(len(polls) == 1, "the newer change was polled once, at the refinement's first progress "
      "event (%d polls)" % len(polls))
Render(view)
check(chosen() == 0 and shown() == exact(250.0, 0),
      "after the aborted refinement the view draws the coarse answer (%d triangles, level %d; "
      "%d at LOD 0)" % (shown(), chosen(), exact(250.0, 0)))
result = refine.change([260.0])
check(result["level"] == 3 and shown() == exact(260.0, 3) and not result["aborted"],
      "the next change refines to level 3 (%r)" % result)

# The first answer's frame counts: a budget that the full level's extraction fits but not its
# extraction and its frame (the display's frame-time model, BlockLODPredictedStillSeconds, for
# the level's estimated triangles) is answered at a coarser level first.
contour.Isosurfaces = [320.0]
contour.UpdatePropertyInformation()
extraction = [float(x) for x in contour.GetProperty("CurrentEstimatedSeconds")]
display = GetDisplayProperties(contour, view)
display.SMProxy.GetProperty("BlockLODPredictedStillSeconds").GetParent().UpdatePropertyInformation()
drawing = [float(x) for x in display.GetProperty("BlockLODPredictedStillSeconds")]
print("change to 320: extraction %s s, frame %s s" % (extraction, drawing))
check(min(drawing) > 0 and drawing[3] > drawing[0],
      "the display predicts a still frame of each level of the isovalues set now, level 3's the "
      "longest (%s)" % drawing)
refine.frame_budget = extraction[3] + 0.5 * drawing[3]
memory, first, predicted = refine.levels()
check(memory == 3 and first < 3 and abs(predicted - extraction[first] - drawing[first]) < 1e-9,
      "a budget level 3's extraction fits (%g s) but not with its frame (%g s) chooses a coarser "
      "first answer (level %d, predicted %g s)" % (extraction[3], drawing[3], first, predicted))
result = refine.change([320.0])
check(result["first_level"] == first and result["level"] == 3 and not result["aborted"],
      "that change is drawn first at level %d, then refined to level 3 (%r)" % (first, result))

# A budget every level fits: the full level at once, no refinement.
refine.frame_budget = 1e9
before = refine.refinements
result = refine.change([300.0])
check(result["first_level"] == 3 and result["level"] == 3 and refine.refinements == before,
      "within the budget the first answer is the full level, with no refinement (%r)" % result)

check.finish("TestBlockLODContourRefineAfterChange: all checks passed")
