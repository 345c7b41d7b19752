"""Block LOD Contour's display blends a translucent surface in one pass while the camera moves.

Builtin session (ctest TestBlockLODSurfaceRepresentationTranslucent). The phantom's skin (-500,
opacity 0.3) over its bone (400), each from a filter of its own at level 3, the view's
LODThreshold at 0 (interactive renders always draw the LOD geometry) and its depth peeling on
(ParaView's default):
- Interactive Translucency is "One Blended Pass" by default; a still frame draws the skin with
  the view's depth peeling and says so, the opaque bone says it is opaque;
- an interactive frame draws the skin's coarse level in one blended pass and says so, and the
  view's renderer peels again after it (the setting is switched for that frame only);
- with "Depth Peeling" the interactive frame is peeled, as before this setting; the two
  interactive images of the same camera differ (the blended one really is another drawing) but
  cover the same pixels and stay close in colour (a correct-looking surface, not an artefact);
- the still image after all this equals the one before, pixel for pixel;
- a hidden display says it drew nothing translucent;
- a view without depth peeling: its still and interactive frames blend, and its setting stays
  off after an interactive frame;
- the frame-time model predicts a blended frame as a kind of its own, between an opaque and a
  peeled one, and learns the blended frames apart from the opaque ones.
(How much time the blended pass saves: Python/benchmark_render_window.py and
benchmark_blocklod.py --interaction, docs/blocklod.md.)
"""
import argparse
import os

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)

import blocklod_display
import checks

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", default=os.environ.get("MEDISO_PLUGIN"))
parser.add_argument("--out", default=os.environ.get("MEDISO_TEST_OUTPUT", os.getcwd()))
args, _ = parser.parse_known_args()
check = checks.Checks()
LoadPlugin(args.plugin, ns=globals())

PEELED, BLENDED = 1, 2  # BlockLODLastRenderTranslucency
BACKGROUND = [25, 25, 38]
phantom = MedicalPhantom(Dimensions=[128, 128, 128])
view = CreateView("RenderView")
view.ViewSize = [400, 300]
view.OrientationAxesVisibility = 0
view.UseColorPaletteForBackground = 0
view.Background = [c / 255.0 for c in BACKGROUND]
view.UseFXAA = 0  # the images compared below are the surfaces', not the filter's
view.LODThreshold = 0.0  # MB: interactive renders always draw the LOD geometry
check(view.DepthPeeling == 1, "the view peels translucent geometry by default")
renderer = view.GetRenderer()

shown = []
for iso in (-500.0, 400.0):
    surface = BlockLODContour(Input=phantom)
    surface.Isosurfaces = [iso]
    surface.LOD = 3
    display = Show(surface, view)
    display.BlockLODInteractiveFrameBudget = 0.0
    display.BlockLODInteractiveTriangleBudget = 1.0  # level 0, whatever the machine's speed
    shown.append((surface, display))
skin, bone = shown[0][1], shown[1][1]
skin.Opacity = 0.3
check(skin.BlockLODInteractiveTranslucency == "One Blended Pass",
      "one blended pass is the default (got %s)" % skin.BlockLODInteractiveTranslucency)
view.CameraPosition = [400.0, -300.0, 200.0]
view.CameraFocalPoint = [0.0, 0.0, 0.0]
view.CameraViewUp = [0.0, 0.0, 1.0]
view.ResetCamera()


def window_pixels():
    return blocklod_display.window_pixels(view)


def still():
    Render(view)
    return window_pixels()


def interactive():
    """An interactive render, as during a mouse drag (the camera moved a little first), and its
    image; the camera is put back after it."""
    camera = GetActiveCamera()
    camera.Azimuth(2.0)
    view.SMProxy.InteractiveRender()
    image = window_pixels()
    camera.Azimuth(-2.0)
    return image


before = still()
info, bone_info = blocklod_display.frame_info(skin), blocklod_display.frame_info(bone)
check(info["lod"] == 0 and info["translucency"] == PEELED,
      "a still frame draws the full translucent skin with depth peeling (%s)" % info)
check(bone_info["translucency"] == 0, "the opaque bone says it is opaque (%s)" % bone_info)
check(renderer.GetLastRenderingUsedDepthPeeling() == 1, "the still frame was peeled (the renderer)")
check((abs(before - BACKGROUND) > 8).any(axis=2).mean() > 0.05, "the still image shows the surfaces")



def predicted_frame(opacity, peeling):
    """The skin's prediction of a frame at level 0 (BlockLODPredictedStillSeconds, computed when
    read, with the model as it stands: no frame drawn) with the skin at `opacity` in a view that
    peels or not (a view without depth peeling blends its translucent frames in one pass)."""
    skin.Opacity, view.DepthPeeling = opacity, peeling
    try:
        skin.SMProxy.GetProperty("BlockLODPredictedStillSeconds").GetParent().UpdatePropertyInformation()
        return float(skin.GetProperty("BlockLODPredictedStillSeconds")[0])
    finally:
        skin.Opacity, view.DepthPeeling = 0.3, 1


# The frame-time model counts a blended frame as a kind of its own (issue 30: counted as an
# opaque frame, the head CT's blended level-2 frame was predicted 30 ms short and the level
# overran the budget): at the same triangles dearer than an opaque frame and cheaper than a
# peeled one, and the blended interactive frames are learnt apart from the opaque ones. Only
# peeled frames are drawn so far: the opaque and blended predictions are their priors at the
# peeled frames' scale.
opaque_s, blended_s, peeled_s = predicted_frame(1.0, 1), predicted_frame(0.3, 0), predicted_frame(0.3, 1)
print("level 0 predicted: opaque %.4f s, blended %.4f s, peeled %.4f s" % (opaque_s, blended_s, peeled_s))
check(0 < opaque_s < blended_s < peeled_s,
      "a blended frame is predicted dearer than an opaque one and cheaper than a peeled one "
      "(%.4f < %.4f < %.4f s)" % (opaque_s, blended_s, peeled_s))
for _ in range(3):
    interactive()
check(blocklod_display.frame_info(skin)["translucency"] == BLENDED, "those interactive frames blended")
# Each prediction adds the window's fixed cost, which every frame updates: the opaque
# prediction is compared with the peeled one's, which no interactive frame changes.
opaque_after, peeled_after = predicted_frame(1.0, 1), predicted_frame(0.3, 1)
check(abs((peeled_after - opaque_after) - (peeled_s - opaque_s)) <= 1e-9 * peeled_s,
      "blended frames leave the opaque prediction as it was (%.6f s below the peeled one, was %.6f s)"
      % (peeled_after - opaque_after, peeled_s - opaque_s))

Render(view)
blended = interactive()
info = blocklod_display.frame_info(skin)
check(info["lod"] == 1 and info["level"] == 0 and info["translucency"] == BLENDED,
      "an interactive frame draws the skin's level 0 in one blended pass and says so (%s)" % info)
check(renderer.GetLastRenderingUsedDepthPeeling() == 0, "the interactive frame was not peeled (the renderer)")
check(renderer.GetUseDepthPeeling() == 1 and view.DepthPeeling == 1,
      "the view peels again after the interactive frame")
interactive()
check(blocklod_display.frame_info(skin)["translucency"] == BLENDED, "so does the next interactive frame")

skin.BlockLODInteractiveTranslucency = "Depth Peeling"
Render(view)
peeled = interactive()
info = blocklod_display.frame_info(skin)
check(info["lod"] == 1 and info["level"] == 0 and info["translucency"] == PEELED,
      "'Depth Peeling': the interactive frame peels the skin's level 0 (%s)" % info)
check(renderer.GetLastRenderingUsedDepthPeeling() == 1, "that frame was peeled (the renderer)")
covered_blended = (abs(blended - BACKGROUND) > 2).any(axis=2)
covered_peeled = (abs(peeled - BACKGROUND) > 2).any(axis=2)
surface = covered_blended | covered_peeled
coverage = float((covered_blended != covered_peeled).sum()) / max(1, int(surface.sum()))
difference = abs(blended - peeled).max(axis=2)[surface]
changed = float((difference > 2).mean())
print("blended against peeled, same camera: %.2f%% of the surface's pixels differ by more than 2, "
      "mean difference %.1f, coverage differs on %.3f%%" % (100 * changed, difference.mean(), 100 * coverage))
check(changed > 0.01, "the blended frame is another drawing than the peeled one (%.2f%% differ)" % (100 * changed))
check(coverage < 0.005, "both cover the same pixels (%.3f%% differ)" % (100 * coverage))
check(difference.mean() < 8, "and are close in colour (mean difference %.1f of 255)" % difference.mean())
skin.BlockLODInteractiveTranslucency = "One Blended Pass"

after = still()
info = blocklod_display.frame_info(skin)
check(info["lod"] == 0 and info["translucency"] == PEELED, "the still frame after is peeled (%s)" % info)
differ = int((before != after).any(axis=2).sum())
check(differ == 0, "the still image after interaction equals the one before (%d pixels differ)" % differ)

# A hidden display draws nothing: it says so (it hears the renderer's frames all the same).
Hide(shown[0][0], view)
still()
interactive()
check(blocklod_display.frame_info(skin)["translucency"] == 0, "a hidden skin says it drew nothing translucent")
Show(shown[0][0], view)

# A view that does not peel: nothing to switch; its frames blend, and it stays that way.
view.DepthPeeling = 0
still()
check(blocklod_display.frame_info(skin)["translucency"] == BLENDED, "a view without peeling: the still frame blends")
interactive()
check(blocklod_display.frame_info(skin)["translucency"] == BLENDED, "and the interactive one")
check(renderer.GetUseDepthPeeling() == 0 and view.DepthPeeling == 0, "the view's setting stays off")
view.DepthPeeling = 1

for surface, display in shown:
    Delete(display)
    Delete(surface)
check.finish("TestBlockLODSurfaceRepresentationTranslucent: interactive frames blend the translucent "
             "skin in one pass and say so; still frames peeled and unchanged")
