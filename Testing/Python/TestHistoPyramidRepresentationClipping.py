"""pvpython test: the 'HistoPyramid Isosurface' representation's cropping and clipping plane.

    pvpython TestHistoPyramidRepresentationClipping.py --plugin PATH --out DIR [--expect-fallback]

ParaView 5.11's image volume displays crop with UseCropping, CroppingOrigin and
CroppingScale (vtkImageVolumeRepresentation: region planes = origin + data
bounds x scale, per axis); the representation takes them from the display.
MedicalPhantom (skin -500 HU over bone 400 HU, opaque, solid white):
- the display's cropping groups are shown for this type (the panel rule names
  'HistoPyramid Isosurface', the box widget's group included);
- UseCropping with a box on voxel faces gives the image of Block LOD Contour
  (level 3) of ExtractSubset of the same box shown as a Surface: covered pixels
  agree on >= 98.5% of those covered by either, mean colour difference <= 12
  (of 255) where both cover; and differs from the uncropped image;
- UseCropping off again gives the uncropped image back;
- the clipping plane (HistoPyramidClipPlane, ...Origin, ...Normal, ...Invert;
  its widget group shown for this type) gives the image of Block LOD Contour
  + Clip with the same plane, with Invert on and off (same thresholds), and
  differs from the unclipped image; off again, the unclipped image.
Run twice: on the GPU path, and on the CPU fallback (--expect-fallback, under
MEDISO_DISABLE_GPU_PATH=1; its one warning is captured and checked). A machine
whose GL lacks what the GPU path needs skips the GPU run (exit 125).
"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)

import HistoPyramidRepresentationChecks as hp

args = hp.parse_args(expect_fallback=True)
check = hp.Checker()
expected_path = "fallback" if args.expect_fallback else "gpu"
name = "TestHistoPyramidRepresentationClipping" + ("Fallback" if args.expect_fallback else "")

LoadPlugin(args.plugin, ns=globals())
phantom = MedicalPhantom(Dimensions=[64, 64, 64], Spacing=[3.0, 3.0, 3.0])
view, display = hp.show_at(phantom, eye=(-0.4, 1.0, 0.3))
bounds = phantom.GetDataInformation().GetBounds()
centre = list(view.CameraFocalPoint)


def shot(step):
    return hp.screenshot(view, os.path.join(args.out, "%s_%s.png" % (name, step)))


# 1. The panel shows the cropping groups for this type.
def decorator_values(element):
    """The 'value' attributes of every PropertyWidgetDecorator under a hints element."""
    values = []
    if element is None:
        return values
    if element.GetName() == "PropertyWidgetDecorator" and element.GetAttribute("value"):
        values.append(element.GetAttribute("value"))
    for i in range(element.GetNumberOfNestedElements()):
        values += decorator_values(element.GetNestedElement(i))
    return values


proxy = display.SMProxy
groups = {}
for g in range(proxy.GetNumberOfPropertyGroups()):
    group = proxy.GetPropertyGroup(g)
    for p in range(group.GetNumberOfProperties()):
        groups.setdefault(proxy.GetPropertyName(group.GetProperty(p)), []).append(group)
for prop in ("UseCropping", "CroppingOrigin", "CroppingScale"):
    check(display.GetProperty(prop) is not None, "the display has %s" % prop)
    owner = groups.get(prop, [None])[-1]  # a property belongs to the last group naming it
    values = decorator_values(owner.GetHints()) if owner is not None else []
    check(hp.REPRESENTATION in values,
          "%s's panel group is shown for %s (its rule names %s)" % (prop, hp.REPRESENTATION, values))
box_group = groups.get("CroppingOrigin", [None])[-1]
check(box_group is not None and box_group.GetPanelWidget() == "InteractiveBox",
      "CroppingOrigin and CroppingScale are edited with the box widget")

# 2. The uncropped image.
hp.first_render(view, display, check, args.expect_fallback)
whole = shot("uncropped")
check(hp.render_info(display)["path"] == expected_path, "uncropped: path %r" % expected_path)

# 3. Cropped to a box on voxel faces: the face (+y, towards the camera) and the
#    neck cut away (points 0..63, 0..36, 16..63 of 64), the skull seen through the cut.
voi = [0, 63, 0, 36, 16, 63]
spacing = 3.0
data_origin = [bounds[0], bounds[2], bounds[4]]
box = [data_origin[i // 2] + voi[i] * spacing for i in range(6)]
scale = [(box[2 * a + 1] - box[2 * a]) / (bounds[2 * a + 1] - bounds[2 * a]) for a in range(3)]
display.UseCropping = 1
display.CroppingScale = scale
display.CroppingOrigin = [box[2 * a] - bounds[2 * a] * scale[a] for a in range(3)]
_, crop_output = hp.captured(lambda: Render(view))
check(crop_output.strip() == "", "cropping: no warning or error (got %r)" % crop_output.strip()[:300])
cropped = shot("cropped")
check(hp.render_info(display)["path"] == expected_path, "cropped: path %r" % expected_path)
check(hp.changed_fraction(whole, cropped) > 0.05,
      "cropping changes the image (%.1f%% of the pixels)" % (100 * hp.changed_fraction(whole, cropped)))

# The reference: Block LOD Contour (level 3) of the same box, shown as a Surface.
subset = ExtractSubset(Input=phantom, VOI=voi)
contour = BlockLODContour(Input=subset, Isosurfaces=[hp.SKIN, hp.BONE], LOD=3, AutoLOD=0,
                          ComputeNormals=1)
camera = [list(view.CameraPosition), list(view.CameraFocalPoint), list(view.CameraViewUp)]
Hide(phantom, view)
surface = Show(contour, view)
# The same camera (showing into a view with nothing visible resets it).
view.CameraPosition, view.CameraFocalPoint, view.CameraViewUp = camera
surface.ColorArrayName = ["POINTS", ""]
for prop in ("Ambient", "Diffuse", "Specular", "SpecularPower"):
    surface.SetPropertyWithName(prop, display.GetPropertyValue(prop))
reference = shot("reference")
agreement, difference, either = hp.compare_images(cropped, reference)
print("cropped vs Block LOD Contour of the box: %d pixels covered by either, masks agree on "
      "%.2f%%, mean colour difference %.2f" % (either, 100 * agreement, difference))
check(either > 5000, "the cropped surfaces cover a good part of the image")
check(agreement >= 0.985, "cropped: covered pixels agree with the contour of the box")
check(difference <= 12.0, "cropped: colours agree with the contour of the box")

# 4. UseCropping off again: the uncropped image.
Hide(contour, view)
display = Show(phantom, view)
display.UseCropping = 0
again = shot("uncropped_again")
check(hp.changed_fraction(whole, again) < 0.001,
      "UseCropping off: the uncropped image again (%.2f%% differ)"
      % (100 * hp.changed_fraction(whole, again)))

# 5. The clipping plane, against Block LOD Contour + Clip with the same plane.
clip_group = groups.get("HistoPyramidClipPlaneOrigin", [None])[-1]
check(clip_group is not None and clip_group.GetPanelWidget() == "InteractivePlane"
      and hp.REPRESENTATION in decorator_values(clip_group.GetHints()),
      "the clipping plane is edited with the plane widget, shown for this type")
full = BlockLODContour(Input=phantom, Isosurfaces=[hp.SKIN, hp.BONE], LOD=3, AutoLOD=0,
                       ComputeNormals=1)
plane_origin = [centre[0] + 6.0, centre[1], centre[2]]
plane_normal = [1.0, 0.25, 0.2]
for invert in (1, 0):
    display.HistoPyramidClipPlane = 1
    display.HistoPyramidClipPlaneOrigin = plane_origin
    display.HistoPyramidClipPlaneNormal = plane_normal
    display.HistoPyramidClipPlaneInvert = invert
    _, clip_output = hp.captured(lambda: Render(view))
    check(clip_output.strip() == "", "clip plane: no warning or error (got %r)" % clip_output.strip()[:300])
    clipped = shot("clip_plane_invert%d" % invert)
    check(hp.render_info(display)["path"] == expected_path, "clip plane: path %r" % expected_path)
    check(hp.changed_fraction(whole, clipped) > 0.05,
          "Invert %d: the plane changes the image (%.1f%% of the pixels)"
          % (invert, 100 * hp.changed_fraction(whole, clipped)))
    cut = Clip(Input=full, ClipType="Plane", Invert=invert)
    cut.ClipType.Origin = plane_origin
    cut.ClipType.Normal = plane_normal
    camera = [list(view.CameraPosition), list(view.CameraFocalPoint), list(view.CameraViewUp)]
    Hide(phantom, view)
    surface = Show(cut, view)
    surface.SetRepresentationType("Surface")
    surface.ColorArrayName = ["POINTS", ""]
    for prop in ("Ambient", "Diffuse", "Specular", "SpecularPower"):
        surface.SetPropertyWithName(prop, display.GetPropertyValue(prop))
    view.CameraPosition, view.CameraFocalPoint, view.CameraViewUp = camera
    reference = shot("clip_reference_invert%d" % invert)
    agreement, difference, either = hp.compare_images(clipped, reference)
    print("clip plane (Invert %d) vs Block LOD Contour + Clip: %d pixels covered by either, masks "
          "agree on %.2f%%, mean colour difference %.2f" % (invert, either, 100 * agreement, difference))
    check(either > 5000, "Invert %d: the clipped surfaces cover a good part of the image" % invert)
    check(agreement >= 0.985, "Invert %d: covered pixels agree with Block LOD Contour + Clip" % invert)
    check(difference <= 12.0, "Invert %d: colours agree with Block LOD Contour + Clip" % invert)
    Hide(cut, view)
    display = Show(phantom, view)
display.HistoPyramidClipPlane = 0
again = shot("unclipped_again")
check(hp.changed_fraction(whole, again) < 0.001,
      "clip plane off: the unclipped image again (%.2f%% differ)"
      % (100 * hp.changed_fraction(whole, again)))

if check.failures:
    print("%d check(s) failed" % len(check.failures))
    sys.exit(1)
print("HistoPyramid representation cropping and clipping (%s): all checks passed" % expected_path)
