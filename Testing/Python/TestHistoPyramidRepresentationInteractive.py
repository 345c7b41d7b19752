"""pvpython test: the 'HistoPyramid Isosurface' representation's interactive frames.

    pvpython TestHistoPyramidRepresentationInteractive.py --plugin PATH --out DIR

- The advanced properties exist with their defaults: HistoPyramidInteractiveAdjust on,
  HistoPyramidInteractiveFrameBudget 0.1 s; the information properties
  (HistoPyramidLastInteractive, LastSampleDistance, LastLevel, LastPredictedSeconds,
  LastMeasuredSeconds, WindowFixedSeconds) exist.
- The view's window's cost outside the representation is measured on its frames (issue 30:
  interactive frames take it off the budget): positive after two still renders.
- Still renders (the view's StillRender) draw every pixel of the full level, timed.
- With a tiny budget, the view's InteractiveRender (a camera move) draws on the GPU path at a
  sample distance above 1 on a coarse volume level (HistoPyramidInteractiveVolumeLevels, on by
  default: level 0, the volume sampled every 8th point), or on the full volume with the volume
  levels off, and the information properties say so; the still render after it is back at 1
  and level 3, and its screenshot equals the one before the interaction.
- The CPU fallback (HistoPyramidForceCPUFallback) draws a coarser level during interaction
  and level 3 when still.
- HistoPyramidInteractiveAdjust off: interactive renders at full quality.
A machine whose GL lacks the GPU path skips (exit 125).
"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)

import HistoPyramidRepresentationChecks as hp

args = hp.parse_args()
check = hp.Checker()

LoadPlugin(args.plugin, ns=globals())
phantom = MedicalPhantom(Dimensions=[64, 64, 64], Spacing=[3.0, 3.0, 3.0])
phantom.UpdatePipeline()
view, display = hp.make_scene(phantom)

INFO = ["HistoPyramidLastInteractive", "HistoPyramidLastSampleDistance", "HistoPyramidLastLevel",
        "HistoPyramidLastPredictedSeconds", "HistoPyramidLastMeasuredSeconds",
        "HistoPyramidWindowFixedSeconds"]
for name in ["HistoPyramidInteractiveAdjust", "HistoPyramidInteractiveFrameBudget",
             "HistoPyramidInteractiveTriangleLevels", "HistoPyramidInteractiveVolumeLevels"] + INFO:
    check(display.GetProperty(name) is not None, "the display has %s" % name)
check(display.HistoPyramidInteractiveAdjust == 1, "InteractiveAdjust is on by default")
check(abs(display.HistoPyramidInteractiveFrameBudget - 0.1) < 1e-12,
      "InteractiveFrameBudget is 0.1 s by default")
check(display.HistoPyramidInteractiveTriangleLevels == 1, "InteractiveTriangleLevels is on by default")
check(display.HistoPyramidInteractiveVolumeLevels == 1, "InteractiveVolumeLevels is on by default")


def last_frame():
    """The interactive information properties, as the rendering process has them."""
    info = hp.render_info(display)
    value = lambda name: display.GetProperty(name)[0]  # noqa: E731
    info.update({
        "interactive": int(value("HistoPyramidLastInteractive")),
        "distance": float(value("HistoPyramidLastSampleDistance")),
        "level": int(value("HistoPyramidLastLevel")),
        "predicted": float(value("HistoPyramidLastPredictedSeconds")),
        "measured": float(value("HistoPyramidLastMeasuredSeconds")),
        "window_fixed": float(value("HistoPyramidWindowFixedSeconds")),
    })
    return info


view.StillRender()
view.StillRender()
still = last_frame()
print("still:", still)
if still["path"] != "gpu":
    print("SKIP: the GPU path does not run here (%s)" % still["reason"])
    sys.exit(125)
check(still["interactive"] == 0 and still["distance"] == 1.0 and still["level"] == 3,
      "a still render draws every pixel of the full level (got %r)" % still)
check(still["measured"] > 0.0 and still["predicted"] > 0.0,
      "a still frame is timed and predicted (got %r)" % still)
check(still["window_fixed"] > 0.0,
      "the view's window's cost outside the representation is measured (got %r)" % still)
before = hp.screenshot(view, os.path.join(args.out, "InteractiveStillBefore.png"))

display.HistoPyramidInteractiveFrameBudget = 1e-7
display.HistoPyramidInteractiveTriangleLevels = 0
for _ in range(3):
    view.InteractiveRender()
moving = last_frame()
print("interactive:", moving)
check(moving["interactive"] == 1 and moving["distance"] == 8.0 and moving["path"] == "gpu",
      "an interactive render with a tiny budget, triangle levels off, draws on the GPU path at "
      "the coarsest sample distance, 8 (got %r)" % moving)
check(moving["predicted"] > 0.0 and moving["measured"] > 0.0,
      "the interactive frame says what was predicted and measured (got %r)" % moving)
check(moving["level"] == 0 and 0 < moving["primitives"] < still["primitives"],
      "with the volume levels (default) it draws the GPU path on volume level 0, fewer "
      "primitives than the still frame (got %r)" % moving)
display.HistoPyramidInteractiveVolumeLevels = 0
view.InteractiveRender()
view.InteractiveRender()
full_volume = last_frame()
print("interactive, volume levels off:", full_volume)
check(full_volume["path"] == "gpu" and full_volume["level"] == 3
      and full_volume["distance"] == 8.0 and full_volume["primitives"] == still["primitives"],
      "with the volume levels off it draws the full volume at distance 8 (got %r)" % full_volume)
# The triangle levels without the volume levels (with both, a tiny budget takes the coarse frame
# predicted fastest, either kind).
display.HistoPyramidInteractiveTriangleLevels = 1
view.InteractiveRender()
view.InteractiveRender()
coarse = last_frame()
print("interactive, triangle levels:", coarse)
check(coarse["interactive"] == 1 and coarse["path"] == "fallback" and coarse["reason"] == ""
      and coarse["level"] < 3 and coarse["triangles"] > 0,
      "with the triangle levels a tiny budget draws a coarser Block LOD level, with "
      "no fallback reason (got %r)" % coarse)
display.HistoPyramidInteractiveVolumeLevels = 1

view.StillRender()
after_info = last_frame()
check(after_info["interactive"] == 0 and after_info["distance"] == 1.0
      and after_info["level"] == 3,
      "the still render after the interaction draws every pixel (got %r)" % after_info)
after = hp.screenshot(view, os.path.join(args.out, "InteractiveStillAfter.png"))
check(hp.changed_fraction(before, after) == 0.0,
      "the still image after the interaction equals the one before")

display.HistoPyramidForceCPUFallback = 1
view.StillRender()
view.StillRender()
fallback_still = last_frame()
view.InteractiveRender()
fallback_moving = last_frame()
view.StillRender()
fallback_after = last_frame()
print("fallback:", fallback_still, fallback_moving, fallback_after)
check(fallback_still["path"] == "fallback" and fallback_still["level"] == 3,
      "fallback: a still render draws level 3 (got %r)" % fallback_still)
check(fallback_moving["interactive"] == 1 and fallback_moving["level"] < 3
      and 0 < fallback_moving["triangles"] < fallback_still["triangles"],
      "fallback: an interactive render draws a coarser level, fewer triangles (got %r)"
      % fallback_moving)
check(fallback_after["level"] == 3 and fallback_after["triangles"] == fallback_still["triangles"],
      "fallback: the still render after it draws level 3 again (got %r)" % fallback_after)
display.HistoPyramidForceCPUFallback = 0

display.HistoPyramidInteractiveAdjust = 0
view.InteractiveRender()
off = last_frame()
check(off["interactive"] == 0 and off["distance"] == 1.0 and off["measured"] == 0.0,
      "InteractiveAdjust off: interactive renders at full quality, untimed (got %r)" % off)

check.finish("TestHistoPyramidRepresentationInteractive: all checks passed")
