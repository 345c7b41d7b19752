"""MedicalIsosurfaces demo (pvpython): skin and bone of a head, through the plugin.

    pvpython Python/demo.py --plugin PATH --out DIR [--ct FILE.mha | --phantom]

Renders the skin (-500 HU) and bone (400 HU) isosurfaces of the real head CT
(or of the plugin's MedicalPhantom when no CT is available), writes one PNG per
surface plus a combined view (translucent skin over bone), and a text report:
input, isovalues, triangle counts, extraction times and frame times over a
rotation. Scripts/demo.sh runs it after bootstrap and data fetch.

Surfaces are extracted with the plugin's BlockLODContour filter at full
resolution (LOD 3); the report also gives its triangle estimates for every
level, the time of a cached repeat, and ParaView's own Contour on the same
isovalue for comparison. The same two surfaces are then drawn straight from the
volume by the plugin's 'HistoPyramid Isosurface' representation (GPU cell
rasterisation, translucent skin over opaque bone in one pass):
histopyramid_skin_and_bone.png, its frame times over the same rotation, the
time of an isovalue change plus a frame, and the path that rendered.
"""
import argparse
import os
import platform
import statistics
import sys
import time

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)
from paraview import servermanager

SURFACES = [
    # name, isovalue (HU), colour, opacity in the combined view
    ("skin", -500.0, (0.93, 0.75, 0.62), 0.35),
    ("bone", 400.0, (0.96, 0.94, 0.86), 1.0),
]


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plugin", required=True, help="path of MedicalIsosurfaces.so")
    parser.add_argument("--out", required=True, help="output folder")
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--ct", help="head CT as .mha (from Python/fetch_data.py)")
    source.add_argument("--phantom", action="store_true", help="use MedicalPhantom")
    parser.add_argument("--phantom-size", type=int, default=256)
    parser.add_argument("--fallback-reason", default="",
                        help="why the phantom is used (written to the report)")
    parser.add_argument("--size", default="1024x768", help="image size WxH")
    parser.add_argument("--frames", type=int, default=36,
                        help="frames in the timed rotation (360/frames degrees each)")
    return parser.parse_args()


def progress(message):
    print("demo: " + message, flush=True)


def timed(function, repeat=1):
    times = []
    result = None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return result, times


def gl_renderer(view):
    """The OpenGL renderer string of the view's context (for the report)."""
    try:
        text = view.GetRenderWindow().ReportCapabilities()
    except Exception:  # the report is informative only
        return "unknown"
    for line in text.splitlines():
        if "renderer string" in line.lower():
            return line.split(":", 1)[1].strip()
    return "unknown"


def frame_camera(view, bounds):
    """Front view of the face (anterior is +y in both inputs), head up (+z)."""
    centre = [(bounds[2 * i] + bounds[2 * i + 1]) / 2.0 for i in range(3)]
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[0] - 0.35, centre[1] + 1.0, centre[2] + 0.15]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera(False)
    view.CameraParallelProjection = 0
    GetActiveCamera().Dolly(1.25)


def time_rotation(view, frames):
    """Render `frames` frames rotating the camera about the view-up axis."""
    camera = GetActiveCamera()
    step = 360.0 / frames
    times = []
    for _ in range(frames):
        camera.Azimuth(step)
        start = time.perf_counter()
        Render(view)
        times.append(time.perf_counter() - start)
    return times


def histopyramid_view(volume, view, array_name, bounds, frames, width, height, path):
    """Skin and bone through the 'HistoPyramid Isosurface' representation: times and info."""
    display = Show(volume, view)
    display.SetRepresentationType("HistoPyramid Isosurface")
    ColorBy(display, ("POINTS", array_name))
    (_, skin, skin_colour, skin_opacity), (_, bone, bone_colour, bone_opacity) = SURFACES
    middle = (skin + bone) / 2.0
    lut = GetColorTransferFunction(array_name)
    lut.RGBPoints = [skin - 1000.0] + list(skin_colour) + [middle - 1.0] + list(skin_colour) + \
        [middle + 1.0] + list(bone_colour) + [bone + 4000.0] + list(bone_colour)
    lut.EnableOpacityMapping = 1  # the opacity map applies only with it, as for surfaces
    pwf = GetOpacityTransferFunction(array_name)
    pwf.Points = [skin - 1000.0, skin_opacity, 0.5, 0.0, middle - 1.0, skin_opacity, 0.5, 0.0,
                  middle + 1.0, bone_opacity, 0.5, 0.0, bone + 4000.0, bone_opacity, 0.5, 0.0]
    display.Specular = 0.25
    display.IsosurfaceValues = [skin, bone]
    frame_camera(view, bounds)
    _, first = timed(lambda: Render(view))
    frame_times = time_rotation(view, frames)
    # Isovalue changes (each rebuilds the pyramid), one frame each; as many as
    # rotation frames, at most 5 (llvmpipe frames at full size are slow).
    changes = []
    for step in range(1, max(1, min(5, frames)) + 1):
        display.IsosurfaceValues = [skin + 20.0 * step, bone]
        changes.append(timed(lambda: Render(view))[1][0])
    display.IsosurfaceValues = [skin, bone]
    frame_camera(view, bounds)
    SaveScreenshot(path, view, ImageResolution=[width, height])
    display.UpdatePropertyInformation()  # builtin: this process rendered
    info = dict(
        path=display.GetProperty("HistoPyramidRenderPath")[0],
        reason=display.GetProperty("HistoPyramidFallbackReason")[0],
        primitives=int(display.GetProperty("HistoPyramidPrimitives")[0]),
        gpu_bytes=display.GetProperty("HistoPyramidGPUMemoryBytes")[0],
        volume_bytes=volume.GetDataInformation().GetMemorySize() * 1024.0,
        first_frame=first[0], frame_median=statistics.median(frame_times),
        change_median=statistics.median(changes), changes=len(changes), image=path)
    Hide(volume, view)
    return info


def main():
    args = parse_args()
    os.makedirs(args.out, exist_ok=True)
    width, height = (int(v) for v in args.size.lower().split("x"))

    LoadPlugin(args.plugin, ns=globals())

    if args.ct:
        progress("reading " + args.ct)
        volume = OpenDataFile(args.ct)
        label = "head CT (Debian invesalius-examples, Cranium.inv3), " + os.path.basename(args.ct)
    else:
        n = args.phantom_size
        progress("generating MedicalPhantom %d^3" % n)
        volume = MedicalPhantom(Dimensions=[n, n, n], Spacing=[240.0 / (n - 1)] * 3)
        label = "MedicalPhantom %d^3 (synthetic; %s)" % (n, args.fallback_reason or "requested")
    _, load_times = timed(lambda: volume.UpdatePipeline())
    info = volume.GetDataInformation()
    array_name = volume.PointData.keys()[0]
    value_range = volume.PointData[array_name].GetRange()
    extent = info.GetExtent()
    dims = [extent[2 * i + 1] - extent[2 * i] + 1 for i in range(3)]
    bounds = info.GetBounds()

    view = CreateView("RenderView")
    view.ViewSize = [width, height]
    view.OrientationAxesVisibility = 0
    view.Background = [0.08, 0.09, 0.12]
    try:  # ParaView 5.11 uses a palette background unless told otherwise
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    SetActiveView(view)

    rows = []
    displays = {}
    for name, isovalue, colour, _ in SURFACES:
        progress("extracting %s at %g" % (name, isovalue))
        contour = BlockLODContour(Input=volume, ContourBy=["POINTS", array_name],
                                  Isosurfaces=[isovalue], LOD=3, ComputeNormals=1)
        _, extract_times = timed(lambda: contour.UpdatePipeline())
        triangles = contour.GetDataInformation().DataInformation.GetNumberOfCells()
        contour.UpdatePropertyInformation()
        estimates = list(contour.GetProperty("EstimatedTriangles"))
        # The same request again is served from the filter's cache.
        contour.Isosurfaces = [isovalue + 1.0]
        contour.UpdatePipeline()
        contour.Isosurfaces = [isovalue]
        _, cached_times = timed(lambda: contour.UpdatePipeline())
        reference = Contour(Input=volume, ContourBy=["POINTS", array_name],
                            Isosurfaces=[isovalue], ComputeScalars=0, ComputeNormals=1)
        _, reference_times = timed(lambda: reference.UpdatePipeline())
        reference_triangles = reference.GetDataInformation().DataInformation.GetNumberOfCells()
        Delete(reference)
        display = Show(contour, view)
        display.ColorArrayName = ['POINTS', '']
        display.DiffuseColor = list(colour)
        display.AmbientColor = list(colour)
        display.Specular = 0.25
        displays[name] = display
        rows.append(dict(name=name, isovalue=isovalue, triangles=triangles,
                         extract=extract_times[0], cached=cached_times[0], estimates=estimates,
                         reference=reference_times[0], reference_triangles=reference_triangles,
                         method="BlockLODContour L3"))

    # One surface at a time, then both (skin translucent over bone).
    for row in rows:
        for name, display in displays.items():
            display.Visibility = 1 if name == row["name"] else 0
            display.Opacity = 1.0
        frame_camera(view, bounds)
        _, first = timed(lambda: Render(view))
        frame_times = time_rotation(view, args.frames)
        frame_camera(view, bounds)
        path = os.path.join(args.out, "%s.png" % row["name"])
        SaveScreenshot(path, view, ImageResolution=[width, height])
        row.update(first_frame=first[0], frame_median=statistics.median(frame_times),
                   frame_min=min(frame_times), image=path)
        progress("wrote %s (%d triangles)" % (path, row["triangles"]))
    renderer = gl_renderer(view)  # needs a context: after the first render
    for name, _, _, opacity in SURFACES:
        displays[name].Visibility = 1
        displays[name].Opacity = opacity
    view.EnableRenderOnInteraction = 0
    frame_camera(view, bounds)
    combined = os.path.join(args.out, "skin_and_bone.png")
    SaveScreenshot(combined, view, ImageResolution=[width, height])
    progress("wrote " + combined)

    # The same two surfaces drawn straight from the volume by the plugin's
    # 'HistoPyramid Isosurface' representation (GPU cell rasterisation): no
    # triangles, colour and opacity from the colour and opacity maps.
    for display in displays.values():
        display.Visibility = 0
    progress("rendering the HistoPyramid Isosurface representation")
    iso = histopyramid_view(volume, view, array_name, bounds, args.frames, width, height,
                            os.path.join(args.out, "histopyramid_skin_and_bone.png"))
    progress("wrote %s (path %s)" % (iso["image"], iso["path"]))

    report = os.path.join(args.out, "report.txt")
    with open(report, "w") as out:
        out.write("MedicalIsosurfaces demo report\n")
        out.write("machine: %s, %d cores, GL renderer: %s\n"
                  % (platform.node(), os.cpu_count(), renderer))
        out.write("ParaView %s.%s.%s\n" % (servermanager.vtkSMProxyManager.GetVersionMajor(),
                                           servermanager.vtkSMProxyManager.GetVersionMinor(),
                                           servermanager.vtkSMProxyManager.GetVersionPatch()))
        out.write("input: %s\n" % label)
        spacing = [(bounds[2 * i + 1] - bounds[2 * i]) / max(1, dims[i] - 1) for i in range(3)]
        out.write("  dimensions %d x %d x %d, spacing %s mm, array '%s', range %g .. %g, load %.3f s\n"
                  % (dims[0], dims[1], dims[2], " x ".join("%.4g" % s for s in spacing),
                     array_name, value_range[0], value_range[1], load_times[0]))
        out.write("image %dx%d, rotation of %d frames (%.0f degrees each)\n"
                  % (width, height, args.frames, 360.0 / args.frames))
        header = "%-6s %9s %-18s %10s %11s %9s %12s %12s %8s\n" % (
            "surface", "iso (HU)", "method", "triangles", "extract s", "cached s", "1st frame s",
            "median frame", "fps")
        out.write(header)
        for row in rows:
            out.write("%-6s %9g %-18s %10d %11.3f %9.4f %12.3f %12.4f %8.1f\n" % (
                row["name"], row["isovalue"], row["method"], row["triangles"], row["extract"],
                row["cached"], row["first_frame"], row["frame_median"], 1.0 / row["frame_median"]))
        out.write("%-6s %9s %-18s %10s %11s %9s %12.3f %12.4f %8.1f\n" % (
            "both", "-500,400", "HistoPyramid " + iso["path"], "-", "-", "-",
            iso["first_frame"], iso["frame_median"], 1.0 / iso["frame_median"]))
        out.write("HistoPyramid Isosurface representation (skin translucent + bone opaque in one "
                  "pass, from the volume): path %s%s, %d active cell-isovalue pairs, GPU memory "
                  "%.1f MB for a %.1f MB volume; 1st frame includes the volume upload and the "
                  "pyramid build; isovalue change + frame %.4f s (median of %d)\n" % (
                      iso["path"], " (%s)" % iso["reason"] if iso["reason"] else "",
                      iso["primitives"], iso["gpu_bytes"] / 1e6, iso["volume_bytes"] / 1e6,
                      iso["change_median"], iso["changes"]))
        out.write("for comparison, ParaView's Contour on the same input: %s\n" % ", ".join(
            "%s %d triangles in %.3f s" % (r["name"], r["reference_triangles"], r["reference"])
            for r in rows))
        out.write("BlockLODContour estimated triangles per level 0..3: %s\n" % "; ".join(
            "%s %s" % (r["name"], " / ".join("%d" % e for e in r["estimates"])) for r in rows))
        out.write("(extract s is a first, uncached extraction including the block min/max pass; "
                  "cached s is the same isovalue asked again; times through pvpython's proxies)\n")
        out.write("images: %s\n" % ", ".join([r["image"] for r in rows] + [combined, iso["image"]]))
    with open(report) as text:
        sys.stdout.write(text.read())
    # Release the view while its GL context and the X display still exist:
    # left to interpreter exit, the context is torn down too late (GLXBadContext).
    Delete(view)
    return 0


if __name__ == "__main__":
    sys.exit(main())
