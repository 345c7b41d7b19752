"""Shared by the HistoPyramid Isosurface representation tests (builtin and client/server).

A scene (MedicalPhantom shown as 'HistoPyramid Isosurface', skin -500 HU
translucent over bone 400 HU opaque, colours and opacities from the HU colour
and opacity maps), reading the representation's read-only properties from the
process that rendered, and image checks on saved screenshots.
"""
import argparse
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)
from paraview.modules.vtkRemotingCore import vtkPVSession
from vtkmodules.vtkIOImage import vtkPNGReader
from vtkmodules.util.numpy_support import vtk_to_numpy

REPRESENTATION = "HistoPyramid Isosurface"
SIZE = [400, 400]
BACKGROUND = [0.1, 0.1, 0.15]
SKIN, BONE = -500.0, 400.0


# The checks collector of the client/server tests (records and prints failures).
from clientserver import Checks as Checker  # noqa: E402,F401
# The tests reach captured() as hp.captured (Testing/Python/checks.py has it).
from checks import captured  # noqa: E402,F401


def parse_args(expect_fallback=False):
    """The arguments ctest gives a representation test: --plugin (default $MEDISO_PLUGIN) and
    --out (the folder of its screenshots); with expect_fallback also --expect-fallback (the run
    with MEDISO_DISABLE_GPU_PATH=1, where the fallback must draw)."""
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", default=os.environ.get("MEDISO_PLUGIN"))
    parser.add_argument("--out", required=True)
    if expect_fallback:
        parser.add_argument("--expect-fallback", action="store_true")
    return parser.parse_args()


def make_view(size=SIZE):
    """A render view with the tests' fixed size and background, no orientation axes."""
    view = CreateView("RenderView")
    view.ViewSize = size
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = BACKGROUND
    view.EnableRenderOnInteraction = 0
    return view


def show_at(source, isovalues=(SKIN, BONE), eye=(0.0, 1.0, 0.0)):
    """`source` (updated here) shown as the representation at `isovalues` in a test view looking
    at its centre from `eye` (an offset from the centre; anterior is +y), head up (+z), the camera
    reset to the bounds. Returns (view, display)."""
    source.UpdatePipeline()
    view = make_view()
    display = Show(source, view)
    display.SetRepresentationType(REPRESENTATION)
    display.IsosurfaceValues = list(isovalues)
    bounds = source.GetDataInformation().GetBounds()
    centre = [(bounds[2 * i] + bounds[2 * i + 1]) / 2.0 for i in range(3)]
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[i] + eye[i] for i in range(3)]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    return view, display


def first_render(view, display, check, expect_fallback):
    """The scene's first render: with the fallback expected (MEDISO_DISABLE_GPU_PATH), exactly
    one warning naming it; else none at all, and the test skipped (exit 125) where the GPU path
    cannot run."""
    _, output = captured(lambda: Render(view))
    if expect_fallback:
        check(output.count("Warning") == 1 and "MEDISO_DISABLE_GPU_PATH" in output,
              "one warning naming MEDISO_DISABLE_GPU_PATH (got %r)" % output.strip()[:300])
        return
    info = render_info(display)
    if info["path"] == "fallback":
        print("SKIP: the GPU path is not available here: %s" % info["reason"])
        sys.exit(125)
    check(output.strip() == "", "no warning or error (got %r)" % output.strip()[:300])


def make_scene(source):
    """Render view + the source shown as the HistoPyramid Isosurface representation."""
    view = make_view()
    display = Show(source, view)
    display.SetRepresentationType(REPRESENTATION)
    ColorBy(display, ("POINTS", "HU"))
    display.IsosurfaceValues = [SKIN, BONE]
    lut = GetColorTransferFunction("HU")
    lut.RGBPoints = [-1000.0, 0.93, 0.75, 0.62, -100.0, 0.93, 0.75, 0.62,
                     100.0, 0.96, 0.94, 0.86, 3000.0, 0.96, 0.94, 0.86]
    # The opacity map applies only with the colour map's opacity mapping on,
    # as for ParaView's Surface representation.
    lut.EnableOpacityMapping = 1
    pwf = GetOpacityTransferFunction("HU")
    # skin 0.35, bone 1 (x, value, midpoint, sharpness)
    pwf.Points = [-1000.0, 0.35, 0.5, 0.0, -100.0, 0.35, 0.5, 0.0,
                  100.0, 1.0, 0.5, 0.0, 3000.0, 1.0, 0.5, 0.0]
    display.Ambient = 0.1
    display.Diffuse = 0.9
    display.Specular = 0.2
    # Front view of the face (anterior is +y), head up (+z).
    bounds = source.GetDataInformation().GetBounds()
    centre = [(bounds[2 * i] + bounds[2 * i + 1]) / 2.0 for i in range(3)]
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[0] - 0.35, centre[1] + 1.0, centre[2] + 0.15]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    return view, display


def render_info(display, location=vtkPVSession.RENDER_SERVER):
    """The representation's read-only properties, as the rendering process has them.

    ParaView pulls information properties of a proxy that also lives on the
    client from the client's copy; with remote rendering the server's copy is
    the one that drew, so the pull is pointed at the render server (the same
    process in builtin mode). location=vtkPVSession.CLIENT reads the client's.
    """
    sub = display.SMProxy.GetProperty("HistoPyramidRenderPath").GetParent()
    previous = sub.GetLocation()
    sub.SetLocation(location)
    try:
        sub.UpdatePropertyInformation()
    finally:
        sub.SetLocation(previous)
    value = lambda name: display.GetProperty(name)[0]  # noqa: E731
    return {
        "path": value("HistoPyramidRenderPath"),
        "footprint": value("HistoPyramidFootprint"),
        "reason": value("HistoPyramidFallbackReason"),
        "primitives": int(value("HistoPyramidPrimitives")),
        "triangles": int(value("HistoPyramidFallbackTriangles")),
        "builds": int(value("HistoPyramidBuilds")),
        "gpu_bytes": int(value("HistoPyramidGPUMemoryBytes")),
        "framebuffer_bytes": int(value("HistoPyramidFrameBufferBytes")),
        # the bricks the volume is kept as (0: one texture), those the isovalues cross, resident
        "bricks": [int(b) for b in display.GetProperty("HistoPyramidLastBricks")],
        # the brick pool's slots the last GPU frame drew those bricks from (0: none), and why not
        "pool_slots": int(value("HistoPyramidBrickPoolSlots")),
        "pool_reason": value("HistoPyramidBrickPoolReason"),
    }


def screenshot(view, path):
    """Save the view and read the PNG back as an (h, w, 3) array."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    SaveScreenshot(path, view, ImageResolution=SIZE, TransparentBackground=0)
    return read_png(path)


def foreground_fraction(pixels):
    """Fraction of pixels that differ from the background colour."""
    background = [round(255 * c) for c in BACKGROUND]
    differs = (abs(pixels - background) > 8).any(axis=2)
    return float(differs.mean())


def changed_fraction(a, b):
    """Fraction of pixels that differ between two images."""
    return float((abs(a - b) > 8).any(axis=2).mean())


def read_png(path):
    """A PNG as an (h, w, 3) int array."""
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    w, h, _ = image.GetDimensions()
    pixels = vtk_to_numpy(image.GetPointData().GetScalars())
    return pixels.reshape(h, w, -1)[:, :, :3].astype(int)


def compare_images(a, b):
    """(mask agreement, mean colour difference over pixels covered by both,
    pixels covered by either) of two screenshots of the same scene."""
    background = [round(255 * c) for c in BACKGROUND]
    ca = (abs(a - background) > 8).any(axis=2)
    cb = (abs(b - background) > 8).any(axis=2)
    either = int((ca | cb).sum())
    both = ca & cb
    agreement = 1.0 - float((ca != cb).sum()) / either if either else 0.0
    diff = float(abs(a - b)[both].mean()) if both.any() else 255.0
    return agreement, diff, either
