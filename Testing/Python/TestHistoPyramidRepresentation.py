"""pvpython test: the 'HistoPyramid Isosurface' representation in builtin mode.

    pvpython TestHistoPyramidRepresentation.py --plugin PATH --out DIR [--expect-fallback]

GPU run (default):
- the type is offered for image data, and MedicalPhantom shows with it;
- skin (-500, translucent) and bone (400, opaque) through the HU colour and
  opacity maps render on the GPU path: RenderPath "gpu", no fallback reason,
  active cells drawn, one pyramid build; the image differs from the background;
- a camera move re-renders without rebuilding the pyramid;
- a new isovalue rebuilds it, draws other cells and changes the image;
- HistoPyramidForceCPUFallback switches to the fallback (one warning, checked)
  and back;
- the whole-head view draws point footprints (HistoPyramidFootprint "points"),
  HistoPyramidAllowPointFootprint off draws boxes and gives the same image;
- bone alone (opaque, one isovalue) reports the first-hit pass's buffers
  (HistoPyramidFrameBufferBytes, 10 bytes per pixel, at most the view's), and
  HistoPyramidFirstHitPass off gives the same image.
A machine whose GL lacks what the GPU path needs skips (exit 125) with the reason.

Fallback run (--expect-fallback, under MEDISO_DISABLE_GPU_PATH=1): the first
render emits exactly one warning naming MEDISO_DISABLE_GPU_PATH (captured and
checked, so it cannot pass without it); RenderPath "fallback" with that reason;
triangles drawn; the image is not empty; an isovalue change re-renders with no
further warning.
"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)

import HistoPyramidRepresentationChecks as hp

args = hp.parse_args(expect_fallback=True)
check = hp.Checker()

LoadPlugin(args.plugin, ns=globals())
phantom = MedicalPhantom(Dimensions=[64, 64, 64], Spacing=[3.0, 3.0, 3.0])
phantom.UpdatePipeline()

probe = Show(phantom)
check(hp.REPRESENTATION in probe.GetProperty("Representation").Available,
      "'%s' is a representation type of image data" % hp.REPRESENTATION)
Delete(probe)

view, display = hp.make_scene(phantom)
check(display.Representation == hp.REPRESENTATION, "display uses %s" % hp.REPRESENTATION)

_, first_output = hp.captured(lambda: Render(view))
info = hp.render_info(display)
print("first frame: %s" % info)
warnings = first_output.count("Warning")
errors = first_output.count("ERROR") + first_output.count("Error")

if args.expect_fallback:
    check(os.environ.get("MEDISO_DISABLE_GPU_PATH") == "1", "run under MEDISO_DISABLE_GPU_PATH=1")
    check(errors == 0, "no error on the fallback path (got %r)" % first_output.strip()[:300])
    check(warnings == 1 and "MEDISO_DISABLE_GPU_PATH" in first_output,
          "exactly one warning naming MEDISO_DISABLE_GPU_PATH (got %r)" % first_output.strip()[:300])
    check(info["path"] == "fallback", "RenderPath is 'fallback' (got %r)" % info["path"])
    check("MEDISO_DISABLE_GPU_PATH" in info["reason"], "FallbackReason %r" % info["reason"])
    check(info["triangles"] > 1000 and info["primitives"] == 0,
          "fallback draws triangles (%d), no GPU primitives" % info["triangles"])
    first = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentationFallback.png"))
    fraction = hp.foreground_fraction(first)
    check(0.05 < fraction < 0.9, "surface covers %.1f%% of the image" % (100 * fraction))
    display.IsosurfaceValues = [hp.BONE]
    Render(view)  # not captured: a second warning would fail the test
    after = hp.render_info(display)
    check(after["path"] == "fallback" and 0 < after["triangles"] < info["triangles"],
          "bone alone re-renders with fewer triangles (%d < %d)"
          % (after["triangles"], info["triangles"]))
    second = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentationFallbackBone.png"))
    check(hp.changed_fraction(first, second) > 0.02, "the image changes with the isovalues")
else:
    if info["path"] == "fallback" and "MEDISO_DISABLE_GPU_PATH" not in info["reason"]:
        print("SKIP: the GPU path is not available here: %s" % info["reason"])
        sys.exit(125)
    check(first_output.strip() == "", "no warning or error (got %r)" % first_output.strip()[:300])
    check(info["path"] == "gpu", "RenderPath is 'gpu' (got %r)" % info["path"])
    check(info["reason"] == "", "no FallbackReason (got %r)" % info["reason"])
    check(info["primitives"] > 1000, "active cell-isovalue pairs drawn: %d" % info["primitives"])
    check(info["builds"] == 1, "one pyramid build (got %d)" % info["builds"])
    check(info["gpu_bytes"] >= 64 ** 3 * 2, "GPU memory holds the volume: %d bytes" % info["gpu_bytes"])
    first = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentation.png"))
    fraction = hp.foreground_fraction(first)
    check(0.05 < fraction < 0.9, "surface covers %.1f%% of the image" % (100 * fraction))

    # A camera move reuses the pyramid.
    camera = view.GetActiveCamera()
    camera.Azimuth(30.0)
    Render(view)
    moved = hp.render_info(display)
    check(moved["path"] == "gpu" and moved["builds"] == 1,
          "camera move: no rebuild (builds %d)" % moved["builds"])
    rotated = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentationRotated.png"))
    check(hp.changed_fraction(first, rotated) > 0.02, "the image follows the camera")
    camera.Azimuth(-30.0)

    # A new isovalue rebuilds and re-renders.
    display.IsosurfaceValues = [hp.BONE]
    Render(view)
    bone = hp.render_info(display)
    check(bone["path"] == "gpu" and bone["builds"] == 2,
          "isovalue change: one more build (builds %d)" % bone["builds"])
    check(0 < bone["primitives"] < info["primitives"],
          "bone alone draws fewer primitives (%d < %d)" % (bone["primitives"], info["primitives"]))
    second = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentationBone.png"))
    check(hp.changed_fraction(first, second) > 0.02,
          "the image changes with the isovalues (%.1f%%)" % (100 * hp.changed_fraction(first, second)))

    # The fallback on request, and back.
    display.HistoPyramidForceCPUFallback = 1
    _, forced_output = hp.captured(lambda: Render(view))
    forced = hp.render_info(display)
    check(forced["path"] == "fallback" and forced["triangles"] > 0,
          "ForceCPUFallback: fallback path with triangles (%s)" % forced)
    check(forced_output.count("Warning") <= 1 and "ERROR" not in forced_output,
          "ForceCPUFallback: at most the fallback warning (got %r)" % forced_output.strip()[:300])
    display.HistoPyramidForceCPUFallback = 0
    Render(view)
    back = hp.render_info(display)
    check(back["path"] == "gpu" and back["reason"] == "", "back on the GPU path (%s)" % back)
    check(info["footprint"] == "points" and forced["footprint"] == "none",
          "footprint: points on the GPU (got %r), none on the fallback (got %r)"
          % (info["footprint"], forced["footprint"]))

    # Boxes on request: the same picture.
    points = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentationPoints.png"))
    display.HistoPyramidAllowPointFootprint = 0
    Render(view)
    boxed = hp.render_info(display)
    check(boxed["path"] == "gpu" and boxed["footprint"] == "boxes",
          "AllowPointFootprint off: boxes on the GPU (%s)" % boxed)
    boxes = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentationBoxes.png"))
    differing = hp.changed_fraction(points, boxes)
    check(differing < 0.002, "points and boxes give the same image (%.3f%% of pixels differ)"
          % (100 * differing))
    display.HistoPyramidAllowPointFootprint = 1

    # Bone alone is opaque with one isovalue: drawn through the first-hit
    # pass, whose buffers are reported; one pass on request gives the same image.
    Render(view)
    hit = hp.render_info(display)
    size = view.ViewSize
    # 10 bytes per pixel of the volume's projection, rounded up to 64
    # pixels and at most the view (TestHistoPyramidIsoMapperChecks_FirstHit
    # checks the rectangle itself).
    check(hit["path"] == "gpu" and 0 < hit["framebuffer_bytes"] <= 10 * size[0] * size[1]
          and hit["framebuffer_bytes"] % 10 == 0,
          "first-hit buffers of 10 bytes per pixel, within the view (%d for %dx%d)"
          % (hit["framebuffer_bytes"], size[0], size[1]))
    display.HistoPyramidFirstHitPass = 0
    Render(view)
    single = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentationOnePass.png"))
    onepass = hp.changed_fraction(points, single)
    check(onepass == 0.0, "the first-hit pass and one pass give the same image (%.3f%% of pixels "
          "differ)" % (100 * onepass))
    display.HistoPyramidFirstHitPass = 1

    # The GPU memory budget (issue 31): 0.45 MB, below the 64^3 phantom's one texture (0.57 MB),
    # keeps it as bricks where the bricks the isovalue crosses fit (dense bone at 1000 HU: a few;
    # bone at 400 HU crosses most bricks, which with their aprons exceed the one texture), drawn
    # with the primitives and the image of one texture; 0.001 MB falls back with that reason;
    # 0 (the default) gives one texture again.
    display.IsosurfaceValues = [1000.0]
    Render(view)
    dense = hp.render_info(display)
    dense_shot = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentationDense.png"))
    display.HistoPyramidGPUMemoryBudget = 0.45
    _, bricked_output = hp.captured(lambda: Render(view))
    bricked = hp.render_info(display)
    check(bricked_output.strip() == "" and bricked["path"] == "gpu" and bricked["bricks"][0] > 1
          and 0 < bricked["bricks"][1] <= bricked["bricks"][2],
          "a 0.45 MB budget: the GPU path over bricks, no message (%s, bricks %s)"
          % (bricked["path"], bricked["bricks"]))
    check(dense["path"] == "gpu" and dense["bricks"][0] == 0 and
          bricked["primitives"] == dense["primitives"] > 0,
          "as bricks, the primitives of one texture (%d, %d)" % (bricked["primitives"], dense["primitives"]))
    as_bricks = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentationBricks.png"))
    check(hp.changed_fraction(dense_shot, as_bricks) < 0.002, "as bricks, the image of one texture "
          "(%.3f%% of pixels differ)" % (100 * hp.changed_fraction(dense_shot, as_bricks)))
    display.HistoPyramidGPUMemoryBudget = 0.001
    _, over_output = hp.captured(lambda: Render(view))
    over = hp.render_info(display)
    check(over["path"] == "fallback" and over["triangles"] > 0 and "over the budget" in over["reason"]
          and over_output.count("Warning") <= 1 and "ERROR" not in over_output,
          "a 0.001 MB budget: the fallback, with the reason (%s, %r)" % (over["path"], over["reason"]))
    display.HistoPyramidGPUMemoryBudget = 0
    Render(view)
    whole = hp.render_info(display)
    check(whole["path"] == "gpu" and whole["bricks"][0] == 0,
          "the default budget: one texture again (%s, bricks %s)" % (whole["path"], whole["bricks"]))
    print("gpu: %d primitives (skin+bone), %d (bone); fallback %d triangles; %.1f%% covered; "
          "points vs boxes: %.3f%% of pixels differ; first-hit buffers %d bytes"
          % (info["primitives"], bone["primitives"], forced["triangles"], 100 * fraction,
             100 * differing, hit["framebuffer_bytes"]))

if check.failures:
    print("%d check(s) failed" % len(check.failures))
    sys.exit(1)
print("HistoPyramid representation (%s): all checks passed"
      % ("fallback" if args.expect_fallback else "gpu"))
