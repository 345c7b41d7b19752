"""The paper's Table 2 on our stack: stand-alone (builtin) against client/server.

    pvpython --no-mpi Python/benchmark_clientserver.py --plugin PATH [--frames 360] [--isovalues 95]

Runs the protocol of shared/BENCHMARK.md twice on the same machine: in this
process (builtin session), then through a pvserver that this script starts with
Testing/Scripts/client-server.sh (loopback-only network namespace, own Xvfb;
the client connects to pvserver directly, not through the test relay), with
remote rendering (the server renders, images come back).
- Rotation: BlockLODContour's surface at one isovalue, the camera turned by
  360 / frames degrees per frame; total seconds and frames per second.
- Isovalue sweep: equidistant isovalues across the data range (ends
  excluded), each one extracted and rendered; seconds per change.
Prints one table with the overhead of the client/server session per frame
and per isovalue change. --representation picks what draws the surface (the
GPU representation plugs in here). Each mode's figures are the median and
minimum of --repeats runs of the whole protocol.
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

import paraview.simple as simple
from paraview import servermanager

here = os.path.dirname(os.path.abspath(__file__))
parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--plugin", default=os.environ.get("MEDISO_PLUGIN", ""))
parser.add_argument("--size", type=int, default=256, help="phantom size (voxels per axis)")
parser.add_argument("--isovalue", type=float, default=400.0)
parser.add_argument("--lod", type=int, default=3)
parser.add_argument("--frames", type=int, default=360)
parser.add_argument("--isovalues", type=int, default=95)
parser.add_argument("--repeats", type=int, default=1)
parser.add_argument("--view-size", type=int, nargs=2, default=[1920, 1080])
parser.add_argument("--representation", default="Surface")
parser.add_argument("--mode", choices=["both", "builtin", "remote"], default="both")
parser.add_argument("--server-port", type=int, default=0, help="(remote mode) pvserver's port")
parser.add_argument("--plugin-on-server-path", action="store_true")
parser.add_argument("--json", help="(builtin/remote mode) write the figures here")
args, _ = parser.parse_known_args()


def run_protocol():
    ns = {"__name__": "medical_isosurfaces_proxies"}
    remote = servermanager.ActiveConnection.IsRemote()
    if remote and args.plugin_on_server_path:
        simple._add_functions(ns)
    else:
        simple.LoadPlugin(args.plugin, remote=remote, ns=ns)
    n = args.size
    phantom = ns["MedicalPhantom"](Dimensions=[n, n, n], Spacing=[256.0 / n] * 3)
    contour = ns["BlockLODContour"](Input=phantom, ContourBy=["POINTS", "HU"],
                                    Isosurfaces=[args.isovalue], LOD=args.lod)
    view = simple.CreateView("RenderView")
    view.ViewSize = args.view_size
    view.OrientationAxesVisibility = 0
    view.RemoteRenderThreshold = 0  # client/server: the server renders
    if args.representation == "Surface":
        display = simple.Show(contour, view)
        display.ColorArrayName = ["POINTS", ""]
    else:
        display = simple.Show(phantom, view)
        display.Representation = args.representation
    simple.ResetCamera(view)
    simple.Render(view)
    lo, hi = phantom.PointData["HU"].GetRange()
    sweep = [lo + (hi - lo) * (i + 1) / (args.isovalues + 1) for i in range(args.isovalues)]
    camera = simple.GetActiveCamera()
    rotations, changes = [], []
    for _ in range(args.repeats):
        contour.Isosurfaces = [args.isovalue]
        simple.Render(view)
        t = time.perf_counter()
        for _ in range(args.frames):
            camera.Azimuth(360.0 / args.frames)
            simple.Render(view)
        rotations.append(time.perf_counter() - t)
        t = time.perf_counter()
        for iso in sweep:
            if args.representation == "Surface":
                contour.Isosurfaces = [iso]
            else:
                display.Isosurfaces = [iso]
            simple.Render(view)
        changes.append((time.perf_counter() - t) / len(sweep))
    contour.Isosurfaces = [args.isovalue]
    contour.UpdatePipeline()
    return {
        "mode": "client/server (pvserver, remote rendering)" if remote else "builtin",
        "distributed": bool(view.GetClientSideObject().GetUseDistributedRenderingForRender()),
        "triangles": contour.GetDataInformation().GetNumberOfCells(),
        "rotation_s": rotations,
        "change_s": changes,
    }


def row(r):
    rot = statistics.median(r["rotation_s"])
    ch = statistics.median(r["change_s"])
    return rot, ch


if args.mode in ("builtin", "remote"):
    if args.mode == "remote":
        simple.Connect("localhost", args.server_port, timeout=60)
    result = run_protocol()
    if args.mode == "remote":
        simple.Disconnect()
    with open(args.json, "w") as f:
        json.dump(result, f)
    sys.stdout.flush()
    # Skip interpreter teardown: destroying a live offscreen GLX view there
    # raises an X error on this stack.
    os._exit(0)

# --mode both: builtin in a child pvpython, then the same through a pvserver.
tmp = tempfile.mkdtemp()
pvpython = sys.executable if "pvpython" in os.path.basename(sys.executable) else "pvpython"
common = [os.path.abspath(__file__), "--size", str(args.size), "--isovalue", str(args.isovalue),
          "--lod", str(args.lod), "--frames", str(args.frames), "--isovalues", str(args.isovalues),
          "--repeats", str(args.repeats), "--view-size"] + [str(v) for v in args.view_size] + [
          "--representation", args.representation, "--plugin", args.plugin]
env = dict(os.environ, MEDISO_PLUGIN=args.plugin,
           VTK_SMP_BACKEND_IN_USE=os.environ.get("VTK_SMP_BACKEND_IN_USE", "STDThread"))
xvfb = os.path.join(here, "..", "Testing", "Scripts", "with-xvfb.sh")
launcher = os.path.join(here, "..", "Testing", "Scripts", "client-server.sh")
print("builtin run ...", flush=True)
subprocess.check_call([xvfb, "pvpython", "--no-mpi", "--force-offscreen-rendering"] + common +
                      ["--mode", "builtin", "--json", os.path.join(tmp, "builtin.json")], env=env)
print("client/server run ...", flush=True)
subprocess.check_call([launcher, "pvserver", "pvpython"] + common +
                      ["--mode", "remote", "--json", os.path.join(tmp, "remote.json")], env=env)
builtin = json.load(open(os.path.join(tmp, "builtin.json")))
remote = json.load(open(os.path.join(tmp, "remote.json")))

renderer = "unknown"
try:
    out = subprocess.run(["glxinfo", "-B"], capture_output=True, text=True, timeout=10).stdout
    renderer = next((l.split(":", 1)[1].strip() for l in out.splitlines()
                     if "renderer string" in l), renderer)
except Exception:
    pass
print()
print("machine: %s, %d cores, %s; SMP backend %s; window %dx%d" % (
    platform.node(), os.cpu_count(), renderer, env["VTK_SMP_BACKEND_IN_USE"], *args.view_size))
print("input: phantom %d^3 int16, isovalue %g, LOD %d (%d triangles); %d-frame rotation, "
      "%d-isovalue sweep; median of %d run(s)" % (args.size, args.isovalue, args.lod,
                                                 builtin["triangles"], args.frames,
                                                 args.isovalues, args.repeats))
print()
print("| mode | rotation s | fps | s per frame | isovalue change s | ratio to builtin (frame / change) |")
print("|---|---:|---:|---:|---:|---:|")
b_rot, b_ch = row(builtin)
for r in (builtin, remote):
    rot, ch = row(r)
    print("| %s | %.2f | %.2f | %.4f | %.4f | %.2fx / %.2fx |" % (
        r["mode"], rot, args.frames / rot, rot / args.frames, ch,
        rot / b_rot, ch / b_ch))
r_rot, r_ch = row(remote)
print()
print("client/server overhead: %+.4f s per frame, %+.4f s per isovalue change"
      % ((r_rot - b_rot) / args.frames, r_ch - b_ch))
if not remote["distributed"]:
    print("warning: the client/server run did not render on the server")
