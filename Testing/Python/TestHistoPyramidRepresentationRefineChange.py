"""pvpython test: an isovalue change of the 'HistoPyramid Isosurface' representation answered
coarse first (medical_isosurfaces.RefineHistoPyramidChange; issue 30 point 3; docs/blocklod.md).

    pvpython TestHistoPyramidRepresentationRefineChange.py --plugin PATH --out DIR

On the phantom, skin over bone, a tiny interactive budget with the triangle levels off (so the
interactive choice is the GPU path's coarsest: volume level 0 at sample distance 8):
- a change's first render (an interactive one, right after the isovalues changed) draws volume
  level 0, not the full volume, and the helper says so; the still render after it draws level 3
  at every pixel, with as many primitives as a still render of those values by itself;
- the display's properties say the same (HistoPyramidLastLevel, LastSampleDistance).
A machine whose GL lacks the GPU path skips (exit 125).
"""
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)

import HistoPyramidRepresentationChecks as hp

args = hp.parse_args()
check = hp.Checker()

LoadPlugin(args.plugin, ns=globals())
import medical_isosurfaces  # noqa: E402  (embedded in the plugin: importable once it is loaded)

phantom = MedicalPhantom(Dimensions=[64, 64, 64], Spacing=[3.0, 3.0, 3.0])
phantom.UpdatePipeline()
view, display = hp.make_scene(phantom)
view.StillRender()
view.StillRender()
info = hp.render_info(display)
if info["path"] != "gpu":
    print("SKIP: the GPU path does not run here (%s)" % info["reason"])
    sys.exit(125)

display.HistoPyramidInteractiveFrameBudget = 1e-7
display.HistoPyramidInteractiveTriangleLevels = 0
for _ in range(3):
    view.InteractiveRender()  # the frame-time model sees the interactive frames

changed = [hp.SKIN + 50.0, hp.BONE + 50.0]
result = medical_isosurfaces.RefineHistoPyramidChange(display, changed, view)
print("RefineHistoPyramidChange:", result)
check(result["first_level"] == 0 and result["first_sample_distance"] > 1.0,
      "a change's first render draws volume level 0 at a sample distance above 1, not the full "
      "volume (got %r)" % result)
check(result["level"] == 3 and result["first_seconds"] <= result["seconds"],
      "the still render after it draws the full volume (got %r)" % result)
refined = hp.render_info(display)
check(int(display.GetProperty("HistoPyramidLastLevel")[0]) == 3 and
      float(display.GetProperty("HistoPyramidLastSampleDistance")[0]) == 1.0,
      "the display says the last frame is level 3 at every pixel")

# The same values drawn by a still render alone: the same primitives.
display.IsosurfaceValues = [hp.SKIN, hp.BONE]
view.StillRender()
display.IsosurfaceValues = changed
view.StillRender()
alone = hp.render_info(display)
check(refined["primitives"] == alone["primitives"] > 0,
      "the refined frame has the primitives of a still render of those values (%d, %d)"
      % (refined["primitives"], alone["primitives"]))

check.finish("TestHistoPyramidRepresentationRefineChange: all checks passed")
