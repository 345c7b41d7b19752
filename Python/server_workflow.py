"""The paper's server-side workflow against a pvserver (only parameters travel).

    pvpython Python/server_workflow.py --port 11111 --plugin /server/path/MedicalIsosurfaces.so \\
        --out-dir /server/path/results [--file /server/path/ct_head.mha] [--isovalue 400]

1. Find an isovalue at a coarse level: BlockLODContour at LOD 0, its small
   geometry delivered to the client (local rendering), several candidate
   isovalues tried (--candidates), triangles printed for each.
2. The chosen isovalue (--isovalue, else the first candidate) at full
   resolution (LOD 3) on the server, then ParaView's own filters, all on the
   server: Smooth (Laplacian), holes filled (vtkFillHolesFilter in a
   Programmable Filter: only its script text is sent), Clip by a plane (the
   plane widget's Origin and Normal: --clip-origin, --clip-normal), Extract
   Surface + Triangulate, Decimate (--reduction).
3. The result is shown (remote rendering: an image comes back, not the
   surface) and saved by the server's writers as VTP, STL and PLY in --out-dir
   (a folder on the server's file system).

The client sends property values and proxy creations only; the surface never
crosses the connection client->server. With --relay-control (the tests' byte
relay) the script prints bytes per step and checks that. The plugin must be
on the server: loaded from here (default, --plugin is the server's path) or
found by pvserver on PV_PLUGIN_PATH (--plugin-on-server-path).
"""
import argparse
import os
import socket
import sys
import time

import paraview.simple as simple
from paraview import servermanager

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--host", default="localhost")
parser.add_argument("--port", type=int, default=11111)
parser.add_argument("--plugin", default="", help="plugin library path on the server")
parser.add_argument("--plugin-on-server-path", action="store_true",
                    help="pvserver was started with PV_PLUGIN_PATH")
parser.add_argument("--file", help="volume file on the server (default: the phantom)")
parser.add_argument("--phantom-size", type=int, default=128)
parser.add_argument("--array", default=None, help="point array to contour (default: the first)")
parser.add_argument("--candidates", type=float, nargs="+", default=[400.0, -500.0, 1000.0])
parser.add_argument("--isovalue", type=float, help="final isovalue (default: first candidate)")
parser.add_argument("--smooth-iterations", type=int, default=20)
parser.add_argument("--hole-size", type=float, default=20.0, help="largest hole to fill (world units)")
parser.add_argument("--clip-origin", type=float, nargs=3, help="plane origin (default: centre)")
parser.add_argument("--clip-normal", type=float, nargs=3, default=[0.0, 1.0, 0.0])
parser.add_argument("--reduction", type=float, default=0.5, help="Decimate TargetReduction")
parser.add_argument("--out-dir", required=True, help="folder on the server for VTP/STL/PLY")
parser.add_argument("--representation", default="Surface",
                    help="representation of the final surface in the view")
parser.add_argument("--relay-control", help="byte relay control socket (tests)")
parser.add_argument("--max-upload", type=int, default=128 * 1024,
                    help="with --relay-control: most bytes client->server for any workflow step")
args, _ = parser.parse_known_args()


class Steps:
    """Per-step timing, and bytes through the tests' relay when there is one."""

    def __init__(self, control):
        self.control = control
        self.rows = []
        self.t = time.time()
        self.last = self.totals()

    def totals(self):
        if not self.control:
            return (0, 0)
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
            s.settimeout(10)
            s.connect(self.control)
            s.sendall(b"totals\n")
            data = s.recv(256)
        c2s, s2c, _ = (int(x) for x in data.split())
        return (c2s, s2c)

    def __call__(self, name, workflow=True):
        if self.control:
            time.sleep(0.2)
        now, t = self.totals(), time.time()
        self.rows.append((name, now[0] - self.last[0], now[1] - self.last[1], t - self.t, workflow))
        print("  %-60s %6.2f s" % (name, t - self.t))
        sys.stdout.flush()
        self.last, self.t = now, time.time()


steps = Steps(args.relay_control)
simple.Connect(args.host, args.port, timeout=30)
if not servermanager.ActiveConnection.IsRemote():
    sys.exit("error: could not connect to %s:%d" % (args.host, args.port))
ns = {"__name__": "medical_isosurfaces_proxies"}
if args.plugin_on_server_path:
    simple._add_functions(ns)
else:
    simple.LoadPlugin(args.plugin, remote=True, ns=ns)
if "BlockLODContour" not in ns:
    sys.exit("error: the MedicalIsosurfaces plugin is not loaded on the server")
steps("connect, plugin", workflow=False)

if args.file:
    volume = simple.OpenDataFile(args.file)
else:
    n = args.phantom_size
    volume = ns["MedicalPhantom"](Dimensions=[n, n, n], Spacing=[200.0 / n] * 3)
volume.UpdatePipeline()
array = args.array or volume.PointData.keys()[0]
bounds = volume.GetDataInformation().GetBounds()
centre = [(bounds[2 * a] + bounds[2 * a + 1]) / 2 for a in range(3)]
contour = ns["BlockLODContour"](Input=volume, ContourBy=["POINTS", array],
                                Isosurfaces=[args.candidates[0]], LOD=0)
view = simple.CreateView("RenderView")
view.ViewSize = [800, 600]
view.OrientationAxesVisibility = 0
view.RemoteRenderThreshold = 1.0e6  # the coarse preview is rendered by the client
preview = simple.Show(contour, view)
preview.ColorArrayName = ["POINTS", ""]
simple.ResetCamera(view)
simple.Render(view)
steps("volume on the server, coarse preview shown", workflow=False)

# 1. Interactive search at level 0 (the client rotates the small geometry itself).
print("coarse preview (LOD 0), client-side rendering:")
for iso in args.candidates:
    contour.Isosurfaces = [iso]
    simple.Render(view)
    print("  isovalue %8g: %7d triangles at level 0"
          % (iso, contour.GetDataInformation().GetNumberOfCells()))
    steps("preview at level 0, isovalue %g" % iso)
isovalue = args.isovalue if args.isovalue is not None else args.candidates[0]

# 2. Full resolution and the heavier operations, all on the server.
simple.Hide(contour, view)
contour.Isosurfaces = [isovalue]
contour.LOD = 3
smooth = simple.Smooth(Input=contour, NumberofIterations=args.smooth_iterations)
fill = simple.ProgrammableFilter(Input=smooth, OutputDataSetType="vtkPolyData")
fill.Script = (
    "from vtkmodules.vtkFiltersModeling import vtkFillHolesFilter\n"
    "f = vtkFillHolesFilter()\n"
    "f.SetInputData(self.GetPolyDataInput())\n"
    "f.SetHoleSize(%r)\n"
    "f.Update()\n"
    "self.GetPolyDataOutput().ShallowCopy(f.GetOutput())\n" % args.hole_size)
clip = simple.Clip(Input=fill, ClipType="Plane")
clip.ClipType.Origin = args.clip_origin or centre
clip.ClipType.Normal = args.clip_normal
surface = simple.ExtractSurface(Input=clip)
triangles = simple.Triangulate(Input=surface)
decimate = simple.Decimate(Input=triangles, TargetReduction=args.reduction,
                           PreserveTopology=0)
decimate.UpdatePipeline()
steps("full resolution, smooth, fill holes, clip, decimate (server)")
for name, proxy in (("level 3", contour), ("smoothed", smooth), ("holes filled", fill),
                    ("clipped", triangles), ("decimated", decimate)):
    info = proxy.GetDataInformation()
    print("  %-13s %8d cells %8.2f MB on the server"
          % (name, info.GetNumberOfCells(), info.GetMemorySize() / 1024.0))
final_info = decimate.GetDataInformation()
steps("data information", workflow=False)

# 3. Show the result (the server renders; an image comes back) and save it there.
view.RemoteRenderThreshold = 0
result = simple.Show(decimate, view)
result.Representation = args.representation
result.ColorArrayName = ["POINTS", ""]
simple.ResetCamera(view)
simple.Render(view)
steps("result shown (remote rendering)")
saved = []
for ext in ("vtp", "stl", "ply"):
    path = os.path.join(args.out_dir, "surface_%g.%s" % (isovalue, ext))
    simple.SaveData(path, proxy=decimate)
    saved.append(path)
steps("saved by the server's writers: VTP, STL, PLY")

print("isovalue %g: %d triangles after decimation (%.2f MB on the server); files on the server:"
      % (isovalue, final_info.GetNumberOfCells(), final_info.GetMemorySize() / 1024.0))
for path in saved:
    print("  " + path)

failures = []
if args.relay_control:
    print("| step | client->server B | server->client B | s |")
    print("|---|---:|---:|---:|")
    for name, c2s, s2c, secs, _ in steps.rows:
        print("| %s | %d | %d | %.2f |" % (name, c2s, s2c, secs))
    geometry = contour.GetDataInformation().GetMemorySize() * 1024
    upload = sum(r[1] for r in steps.rows if r[4])
    print("workflow steps sent %d B client->server in all; the level-3 surface is %d B" %
          (upload, geometry))
    for name, c2s, _, _, workflow in steps.rows:
        if workflow and c2s > args.max_upload:
            failures.append("step '%s' sent %d B client->server" % (name, c2s))
    final_bytes = final_info.GetMemorySize() * 1024
    if not upload < min(geometry / 20, final_bytes / 10):
        failures.append("the workflow sent %d B client->server, not far below the surfaces "
                        "(%d B at level 3, %d B decimated)" % (upload, geometry, final_bytes))
    # The tests run client and server on one machine: the files are visible here.
    for path in saved:
        if not (os.path.exists(path) and os.path.getsize(path) > 1000):
            failures.append("the server did not write %s" % path)
    if final_info.GetNumberOfCells() < 1000:
        failures.append("the decimated surface has %d cells" % final_info.GetNumberOfCells())
simple.Disconnect()
for f in failures:
    print("FAILED: " + f)
sys.exit(1 if failures else 0)
