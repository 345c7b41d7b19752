"""Client/server test of the 'HistoPyramid Isosurface' representation
(run by Testing/Scripts/client-server.sh: pvserver in a loopback-only namespace).

The plugin is loaded on both sides (the representation has a client-side copy,
as every ParaView representation). With remote rendering forced
(RemoteRenderThreshold 0) the server renders and the image comes back (with
local rendering asked for, ParaView keeps volume representations on the
server: checked too):
- the data is produced by the pvserver process;
- the server's representation reports RenderPath "gpu" with active cells drawn,
  while the client's copy drew nothing ("none"): the frame was the server's;
- the screenshot taken by the client is not empty;
- an isovalue change (only the value travels) rebuilds the pyramid on the
  server and changes the image that comes back;
- a new display and a new Block LOD Contour start at Otsu's threshold counted
  on the server (the phantom shifted positive), and the phantom at skin and bone.
Skips (125) when the server's GL lacks what the GPU path needs.
"""
import argparse
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)
from paraview.modules.vtkRemotingCore import vtkPVSession

import HistoPyramidRepresentationChecks as hp

parser = argparse.ArgumentParser()
parser.add_argument("--host", default="localhost")
parser.add_argument("--port", type=int, required=True)
parser.add_argument("--server-pid", type=int, required=True)
parser.add_argument("--plugin", required=True)
args, _ = parser.parse_known_args()  # client-server.sh also passes relay and log options
check = hp.Checker()
out = os.environ.get("MEDISO_TEST_OUTPUT", os.path.join(os.getcwd(), "cs-output"))

if Connect(args.host, args.port, timeout=30) is None:
    print("FAILED: could not connect to %s:%d" % (args.host, args.port))
    sys.exit(1)
check(servermanager.ActiveConnection.IsRemote(), "the connection is remote")
LoadPlugin(args.plugin, remote=False, ns=globals())
LoadPlugin(args.plugin, remote=True, ns=globals())

phantom = MedicalPhantom(Dimensions=[64, 64, 64], Spacing=[3.0, 3.0, 3.0])
phantom.UpdatePipeline()
producer = phantom.FieldData["ProducerProcessId"]
check(producer is not None and int(producer.GetRange()[0]) == args.server_pid,
      "data produced by pvserver pid %d" % args.server_pid)

view, display = hp.make_scene(phantom)
view.RemoteRenderThreshold = 0  # MB: always render on the server
Render(view)
server = hp.render_info(display)
client = hp.render_info(display, vtkPVSession.CLIENT)
print("server: %s\nclient: %s" % (server, client))
if server["path"] == "fallback" and "MEDISO_DISABLE_GPU_PATH" not in server["reason"]:
    print("SKIP: the GPU path is not available on the server: %s" % server["reason"])
    sys.exit(125)
check(server["path"] == "gpu", "server RenderPath is 'gpu' (got %r)" % server["path"])
check(server["primitives"] > 1000 and server["builds"] == 1,
      "server drew %d primitives after 1 build (%d)" % (server["primitives"], server["builds"]))
check(client["path"] == "none" and client["primitives"] == 0,
      "the client's copy drew nothing (got %r)" % client["path"])

first = hp.screenshot(view, os.path.join(out, "TestHistoPyramidRepresentationClientServer.png"))
fraction = hp.foreground_fraction(first)
check(0.05 < fraction < 0.9, "the image from the server shows the surface (%.1f%%)" % (100 * fraction))

display.IsosurfaceValues = [hp.BONE]
Render(view)
bone = hp.render_info(display)
check(bone["path"] == "gpu" and bone["builds"] == 2 and 0 < bone["primitives"] < server["primitives"],
      "isovalue change: rebuilt on the server, fewer primitives (%s)" % bone)
second = hp.screenshot(view, os.path.join(out, "TestHistoPyramidRepresentationClientServerBone.png"))
check(hp.changed_fraction(first, second) > 0.02, "the image from the server changes")
print("client/server: server pid %d drew %d then %d primitives; image %.1f%% covered"
      % (args.server_pid, server["primitives"], bone["primitives"], 100 * fraction))

# Local rendering asked for: ParaView 5.11 still renders volume
# representations where the data is (vtkImageVolumeRepresentation requires
# distributed rendering), so the volume never travels to the client; the
# server keeps drawing and the client's copy draws nothing. (The paper's
# local-rendering mode, coarse geometry rotated on the client, is
# BlockLODContour's: TestBlockLODContourRemoteSession*.)
view.RemoteRenderThreshold = 1.0e9  # MB: local rendering wherever ParaView allows it
Render(view)
builds = hp.render_info(display)["builds"]
for _ in range(3):
    view.CameraPosition = [-p for p in view.CameraPosition]
    Render(view)
after = hp.render_info(display)
client_after = hp.render_info(display, vtkPVSession.CLIENT)
check(after["path"] == "gpu" and after["builds"] == builds and client_after["path"] == "none",
      "local rendering asked for: the server still draws, camera moves reuse its pyramid, "
      "the client draws nothing (%s / %s)" % (after, client_after))
third = hp.screenshot(view, os.path.join(out, "TestHistoPyramidRepresentationClientServerLocal.png"))
check(hp.foreground_fraction(third) > 0.05, "the image still shows the surface")

# Where a new display and a new Block LOD Contour start when the histogram
# lives on the server: the phantom shifted positive (not HU) starts at Otsu's
# threshold, counted there (vtkPVMedicalHistogramInformation), the same value
# as in a builtin session (TestMedicalIsosurfacesDefaults: 633.78125 for this
# phantom); the phantom itself at skin and bone.
start_phantom = MedicalPhantom(Dimensions=[48, 48, 48], Spacing=[3.0, 3.0, 3.0])  # noqa: F405
shifted = Calculator(Input=start_phantom, Function="HU+1024", ResultArrayName="Shifted")  # noqa: F405
shifted_display = Show(shifted, view)
shifted_contour = BlockLODContour(Input=shifted)  # noqa: F405
phantom_display = Show(start_phantom, view)
check(list(shifted_display.IsosurfaceValues) == [633.78125]
      and list(shifted_contour.Isosurfaces) == [633.78125]
      and list(phantom_display.IsosurfaceValues) == [-500.0, 400.0],
      "the start with the data on the server: Otsu's threshold 633.78125 for the shifted "
      "phantom (display %s, filter %s), skin and bone for the phantom (%s)"
      % (list(shifted_display.IsosurfaceValues), list(shifted_contour.Isosurfaces),
         list(phantom_display.IsosurfaceValues)))

Disconnect()
if check.failures:
    print("%d check(s) failed" % len(check.failures))
    sys.exit(1)
print("HistoPyramid representation client/server: all checks passed")
