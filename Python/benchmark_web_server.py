"""Bytes on the wire: the page (volume once, then nothing) against server-side rendering.

    Testing/Scripts/with-xvfb.sh pvpython --no-mpi --force-offscreen-rendering \\
        Python/benchmark_web_server.py --plugin build/.../MedicalIsosurfaces.so \\
        [--data FILE | --data phantom:N] [--sizes 960x720 1920x1080] [--changes 20] [--frames 360]

The trame/ParaViewWeb way of showing a surface in a browser is to render on the server and send
one compressed image per isovalue change and per rotation frame (ParaViewWeb's image delivery:
JPEG through vtkDataEncoder, quality 100 by default; a lower interactive quality while the user
drags; PNG when exact pixels matter); the other way is to send the new surface per change and
let the browser rotate it (vtk.js local rendering). Here the server side is measured as it
would run: our mapper (the 'HistoPyramid Isosurface' representation) in pvpython renders each
change and each frame, the image is read back and encoded, and its bytes are counted; the
surface a geometry-sending server would ship is extracted (vtkFlyingEdges3D, the triangles
BlockLODContour gives at level 3) and its bytes counted raw and as zlib'd VTP. The page's side
is the volume once (Python/serve.py's own encoding: byte-shuffled, gzip) and then 0 bytes per
change and per frame (counted on the wire in Chromium by TestWebServerPageBytes).

The isovalue changes are those of TestWebServerPageBytes (one surface, --changes values from 15%
to 75% of the data range); the rotation is the paper's (1 degree per frame about the vertical,
the page's default scene: skin and bone). Prints a Markdown table; the figures in docs/web.md
come from it.
"""
import argparse
import os
import platform
import shutil
import statistics
import sys
import tempfile
import time

SKIN = (0.93, 0.75, 0.62)
BONE = (0.97, 0.95, 0.88)
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from benchmark_common import cpu_model, load_average  # noqa: E402
import serve_operations  # noqa: E402


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--plugin", required=True)
    p.add_argument("--data", help="volume (default: the fetched head CT, else phantom:192)")
    p.add_argument("--sizes", nargs="+", default=["960x720", "1920x1080"],
                   help="image sizes (960x720 is the page's canvas; 1920x1080 the paper's)")
    p.add_argument("--changes", type=int, default=20)
    p.add_argument("--frames", type=int, default=360)
    p.add_argument("--jpeg", type=int, nargs="+", default=[100, 50],
                   help="JPEG qualities (ParaViewWeb's default is 100)")
    return p.parse_args(argv)


class Encoder:
    """Reads the view's image back and encodes it as ParaViewWeb's vtkDataEncoder does."""

    def __init__(self, view, qualities):
        from vtkmodules.vtkIOImage import vtkJPEGWriter, vtkPNGWriter
        from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter
        self.grab = vtkWindowToImageFilter()
        self.grab.SetInput(view.GetRenderWindow())
        self.grab.ReadFrontBufferOff()
        self.grab.ShouldRerenderOff()
        self.writers = {}
        for q in qualities:
            w = vtkJPEGWriter()
            w.SetQuality(q)
            w.WriteToMemoryOn()
            w.SetInputConnection(self.grab.GetOutputPort())
            self.writers["JPEG q%d" % q] = w
        png = vtkPNGWriter()
        png.WriteToMemoryOn()
        png.SetInputConnection(self.grab.GetOutputPort())
        self.writers["PNG"] = png

    def __call__(self):
        """{encoding: bytes} of the image now in the view."""
        self.grab.Modified()
        sizes = {}
        for name, w in self.writers.items():
            w.Write()
            sizes[name] = w.GetResult().GetNumberOfTuples()
        return sizes


def images(view, encoder, changes):
    """Each change made, rendered and encoded: ({encoding: [bytes]}, [seconds])."""
    import paraview.simple as simple
    sizes, seconds = {}, []
    for change in changes:
        change()
        start = time.perf_counter()
        simple.Render(view)
        for k, n in encoder().items():
            sizes.setdefault(k, []).append(n)
        seconds.append(time.perf_counter() - start)
    return sizes, seconds


def surface_bytes(image, array, isovalue):
    """(raw, VTP zlib) bytes of the surface a geometry-sending server ships for an isovalue."""
    from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
    fe = vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.SetInputArrayToProcess(0, 0, 0, 0, array)
    fe.SetValue(0, isovalue)
    fe.ComputeNormalsOff()
    fe.ComputeScalarsOff()
    fe.Update()
    surface = fe.GetOutput()
    raw = 12 * surface.GetNumberOfPoints() + 12 * surface.GetNumberOfCells()
    w = vtkXMLPolyDataWriter()
    w.SetInputData(surface)
    w.SetDataModeToAppended()
    w.EncodeAppendedDataOff()
    w.WriteToOutputStringOn()
    w.Write()
    return raw, len(w.GetOutputString()), surface.GetNumberOfCells()


def stats(values):
    return min(values), statistics.median(values), max(values)


def main(argv):
    args = parse_args(argv)
    import paraview.simple as simple
    import serve  # the page's volume encoding, as the server sends it
    ns = {"__name__": "benchmark"}
    simple.LoadPlugin(args.plugin, ns=ns)
    spec = args.data or serve_operations.default_sources()[0]
    source, name, image, array = serve_operations.open_sources([spec], ns, lambda m: None)[0]
    export = tempfile.mkdtemp(prefix="mediso-bench-")  # the values as the worker hands them over
    dataset = serve.Dataset.load("d0", serve_operations.export(0, spec, name, image, array, export))
    volume_bytes = len(dataset.encode(3))
    raw_bytes = dataset.values.nbytes
    shutil.rmtree(export)
    lo, hi = dataset.range
    isovalues = [lo + (hi - lo) * (0.15 + 0.6 * i / max(1, args.changes - 1))
                 for i in range(args.changes)]
    # The page's default surfaces (Web/static/app.js): translucent skin over bone on a CT.
    if lo <= -900 and hi >= 400:
        scene = [(-500.0, SKIN, 0.35), (400.0, BONE, 1.0)]
    else:
        scene = [(float("%.4g" % (lo + 0.3 * (hi - lo))), SKIN, 1.0)]
    load_before = load_average()
    started = time.strftime("%Y-%m-%d %H:%M:%S")

    # Geometry per change (a server that ships the surface; the browser rotates it itself).
    geometry = [surface_bytes(image, array.GetName(), v) for v in isovalues]

    view = simple.CreateView("RenderView")
    view.OrientationAxesVisibility = 0
    view.Background = [0.1, 0.12, 0.16]
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    display = simple.Show(source, view)
    display.SetRepresentationType("HistoPyramid Isosurface")
    simple.ColorBy(display, None)
    display.HistoPyramidColorEachSurface = 1

    def show(surfaces):
        """The surfaces [(value, colour, opacity)] in the view, as the page draws them."""
        display.HistoPyramidSurfaceColors = [c for _, colour, _ in surfaces for c in colour]
        display.HistoPyramidSurfaceOpacities = [o for _, _, o in surfaces]
        display.IsosurfaceValues = [v for v, _, _ in surfaces]

    results = []
    renderer = "?"
    for size in args.sizes:
        w, h = (int(n) for n in size.split("x"))
        view.ViewSize = [w, h]
        encoder = Encoder(view, args.jpeg)
        simple.ResetCamera(view)
        show([(isovalues[0],) + scene[0][1:]])
        simple.Render(view)
        caps = view.GetRenderWindow().ReportCapabilities()
        renderer = next((line.split(":", 1)[1].strip() for line in caps.splitlines()
                         if "renderer string" in line), renderer)

        # As the page's setIsovalues([v]): the first surface's looks at each new value.
        per_change, change_s = images(view, encoder, (lambda v=v: show([(v,) + scene[0][1:]])
                                                      for v in isovalues))
        show(scene)
        simple.ResetCamera(view)
        camera = view.GetActiveCamera()
        per_frame, frame_s = images(view, encoder,
                                    (lambda: camera.Azimuth(1.0) for _ in range(args.frames)))
        results.append((size, per_change, change_s, per_frame, frame_s))
        if os.environ.get("MEDISO_BENCHMARK_IMAGE"):  # to look at what was measured
            simple.SaveScreenshot(os.environ["MEDISO_BENCHMARK_IMAGE"] % size, view)
        del encoder
    load_after = load_average()
    simple.Delete(display)
    simple.Delete(view)  # the GL context goes before the X display does

    out = print
    out("# Bytes per isovalue change and per rotation frame: the page against server-side "
        "rendering")
    out("")
    out("- Command: `%s`" % " ".join(["pvpython", "Python/benchmark_web_server.py"] + argv))
    out("- Started %s; load average %s before, %s after (shared machine)"
        % (started, load_before, load_after))
    out("- Machine: %s, nproc %d (%s); OpenGL renderer: %s"
        % (platform.platform(), os.cpu_count() or 0, cpu_model(), renderer))
    out("- Volume: %s, %s %s, %.1f MB raw; the page receives it once in %d bytes (%.3fx raw)"
        % (name, "x".join(map(str, dataset.dims)), dataset.type, raw_bytes / 1e6,
           volume_bytes, volume_bytes / raw_bytes))
    out("- %d isovalue changes (one surface, %g to %g); rotation: %d frames of 1 degree, "
        "scene %s" % (len(isovalues), isovalues[0], isovalues[-1], args.frames,
                      " and ".join("%g (opacity %g)" % (v, o) for v, _, o in scene)))
    out("")
    out("| method | image | per isovalue change: min / median / max bytes | per rotation frame: "
        "min / median / max bytes | server s per image (render + read back + encode), median "
        "change / frame | changes until the page's one-off volume is repaid |")
    out("|---|---|---:|---:|---:|---:|")
    out("| the page (this project): parameters only, the browser's GPU renders | - | 0 / 0 / 0 "
        "| 0 / 0 / 0 | - | volume once: %d bytes |" % volume_bytes)
    for size, per_change, change_s, per_frame, frame_s in results:
        for k in per_change:
            c, f = stats(per_change[k]), stats(per_frame[k])
            out("| server renders, sends an image (%s) | %s | %d / %d / %d | %d / %d / %d | "
                "%.3f / %.3f | %.1f changes (or %.1f frames) |"
                % (k, size, c[0], c[1], c[2], f[0], f[1], f[2], statistics.median(change_s),
                   statistics.median(frame_s), volume_bytes / c[1], volume_bytes / f[1]))
    raw, vtp = [g[0] for g in geometry], [g[1] for g in geometry]
    r, z = stats(raw), stats(vtp)
    out("| server ships the surface (float32 points + int32 triangles, no normals) | - | "
        "%d / %d / %d | 0 | - | %.1f changes |" % (r[0], r[1], r[2], volume_bytes / r[1]))
    out("| server ships the surface (VTP, zlib) | - | %d / %d / %d | 0 | - | %.1f changes |"
        % (z[0], z[1], z[2], volume_bytes / z[1]))
    triangles = stats([g[2] for g in geometry])
    out("")
    out("Surfaces of the changes: %d / %d / %d triangles (min / median / max). Frame times are "
        "this machine's software OpenGL (%s), not a GPU's; the bytes do not depend on it."
        % (triangles[0], triangles[1], triangles[2], renderer))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
