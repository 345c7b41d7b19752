"""Where a ParaView interactive frame's time goes on a software renderer (issue 30).

    Testing/Scripts/with-xvfb.sh pvpython --no-mpi Python/benchmark_render_window.py \
        [--plugin PATH] [--input ct|phantomN] [--frames 7] [--size 1024x768] [--out FILE.md]

Block LOD Contour's displays of skin (-500) and bone (400) in a render view of --size, the
orientation axes off, interactive renders (a mouse drag's: the displays draw their coarse levels)
of 1 degree each. Per series the medians of: the frame's wall time, the render window's (its
StartEvent to EndEvent: every renderer of the view, the blit and the buffer swap), the main
renderer's (what the displays' frame-time model is fed), and the main renderer's with a glFinish
at its end (vtkOpenGLRenderWindow::WaitForCompletion). llvmpipe rasterises a frame's draw calls
when they are flushed, at the swap, so without the glFinish the renderer's own drawing is counted
in the window's time; with it, what is left of the window is the cost that does not depend on the
data shown (the view's other renderers, the blit, the swap). The series: opaque and skin at 0.3,
with the view's defaults (FXAA as ParaView sets it, depth peeling with 4 peels), with FXAA off,
translucent with 1 peel, translucent with depth peeling off (VTK's one blended pass), and the
empty view. Not a test: it prints a table.
"""
import argparse
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchmark_common import ROOT, cpu_model, load_average, write_report  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plugin", default=os.path.join(ROOT, "build", "lib", "paraview-5.11", "plugins",
                                                         "MedicalIsosurfaces", "MedicalIsosurfaces.so"))
    parser.add_argument("--input", default="ct", help="ct or phantomN (benchmark_blocklod.py's inputs)")
    parser.add_argument("--frames", type=int, default=7, help="interactive frames per series")
    parser.add_argument("--size", default="1024x768")
    parser.add_argument("--out", default="")
    args = parser.parse_args()
    if not os.environ.get("DISPLAY"):
        print("benchmark_render_window.py renders: run it under X (Testing/Scripts/with-xvfb.sh)")
        return 1
    import paraview.simple as pvs
    from benchmark_blocklod import make_input

    pvs.LoadPlugin(args.plugin)
    load_before = load_average()
    source, image, label, keep = make_input(args.input, pvs, pvs.MedicalPhantom)
    array_name = image.GetPointData().GetScalars().GetName()
    view = pvs.CreateView("RenderView")
    view.ViewSize = [int(v) for v in args.size.split("x")]
    view.OrientationAxesVisibility = 0
    displays, filters = [], []
    for iso in (-500.0, 400.0):
        f = pvs.BlockLODContour(Input=source, ContourBy=["POINTS", array_name], Isosurfaces=[iso])
        f.LOD = 3
        f.AutoLOD = 0
        d = pvs.Show(f, view)
        d.ColorArrayName = [None, ""]
        displays.append(d)
        filters.append(f)
    pvs.ResetCamera(view)
    camera = view.GetActiveCamera()
    window, renderer = view.GetRenderWindow(), view.GetRenderer()
    clock, finish = {}, {"on": False}

    def mark(key):
        def observer(*_):
            clock[key] = time.perf_counter()
        return observer

    def finished(*_):
        if finish["on"]:
            window.WaitForCompletion()
            clock["renderer finished"] = time.perf_counter()

    renderer.AddObserver("StartEvent", mark("renderer start"))
    renderer.AddObserver("EndEvent", mark("renderer end"))
    renderer.AddObserver("EndEvent", finished, -1.0)  # after the mark above
    window.AddObserver("StartEvent", mark("window start"))
    window.AddObserver("EndEvent", mark("window end"))

    def series():
        """Medians of (wall, window, renderer, renderer + glFinish) over --frames frames."""
        pvs.Render(view)
        for _ in range(2):
            view.SMProxy.InteractiveRender()  # the coarse levels made and delivered
        times = []
        for _ in range(args.frames):
            camera.Azimuth(1.0)
            for on in (False, True):
                finish["on"] = on
                t0 = time.perf_counter()
                view.SMProxy.InteractiveRender()
                wall = time.perf_counter() - t0
                window_s = clock["window end"] - clock["window start"]
                if not on:
                    row = [wall, window_s, clock["renderer end"] - clock["renderer start"]]
                else:
                    row.append(clock["renderer finished"] - clock["renderer start"])
                    row.append(window_s)
            times.append(row)
        finish["on"] = False
        return [statistics.median(t[k] for t in times) for k in range(5)]

    rows = []
    peels, fxaa, peeling = view.MaximumNumberOfPeels, view.UseFXAA, view.DepthPeeling
    for opacity in (1.0, 0.3):
        displays[0].Opacity = opacity
        scene = "opaque" if opacity == 1.0 else "skin 0.3 over bone"
        settings = [("view's defaults (FXAA %d, %d peels)" % (fxaa, peels), fxaa, peels, peeling),
                    ("FXAA off", 0, peels, peeling)]
        if opacity < 1.0:
            settings.append(("FXAA off, 1 peel", 0, 1, peeling))
            # VTK's renderer blends translucent props in one pass (weighted, order-independent
            # blending) when depth peeling is off.
            settings.append(("depth peeling off (one blended pass)", fxaa, peels, 0))
            settings.append(("FXAA off, depth peeling off", 0, peels, 0))
        for name, use_fxaa, use_peels, use_peeling in settings:
            view.UseFXAA, view.MaximumNumberOfPeels, view.DepthPeeling = use_fxaa, use_peels, use_peeling
            rows.append((scene, name, series()))
            print(rows[-1], flush=True)
        view.UseFXAA, view.MaximumNumberOfPeels, view.DepthPeeling = fxaa, peels, peeling
    for d in displays:
        d.Visibility = 0
    rows.append(("empty view", "view's defaults", series()))
    lines = ["# ParaView's interactive frame on a software renderer, split", "",
             "- Command: `%s`" % " ".join(sys.argv),
             "- Input: %s; %s, interactive renders of 1 degree, %d per series" % (label, args.size, args.frames),
             "- Machine: %s; load average %s before, %s after" % (cpu_model(), load_before, load_average()), "",
             "| scene | settings | wall s | window s | renderer s (calls) | renderer s (with glFinish) | "
             "window s (with glFinish) | window - renderer with glFinish |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for scene, name, (wall, window_s, submitted, drawn, window_f) in rows:
        lines.append("| %s | %s | %.4f | %.4f | %.4f | %.4f | %.4f | %.4f |" % (
            scene, name, wall, window_s, submitted, drawn, window_f, window_f - drawn))
    write_report(lines, args.out)
    for proxy in displays + filters + [view]:
        pvs.Delete(proxy)
    del keep
    return 0


if __name__ == "__main__":
    sys.exit(main())
