"""BlockLODContour through a pvserver, with remote and with local rendering.

Run by Testing/Scripts/client-server.sh, twice: the plugin loaded from the
client (LoadPlugin(path, remote=True)) and found by pvserver on PV_PLUGIN_PATH
(--plugin-on-server-path). Checks:
- the proxies exist on both sides, the surface is made in the server process
  (the phantom's ProducerProcessId is pvserver's pid) and, with a remote
  LoadPlugin, the plugin library is not mapped into the client at all;
- remote rendering (RemoteRenderThreshold 0): the server renders, the client
  receives a non-empty image, and a frame brings back about one image, far
  less than the surface's geometry;
- local rendering (threshold 1e6) of level 0: the coarse geometry is
  delivered to the client once; then rotating the camera renders on the
  client alone: no image and no geometry cross the connection (ParaView still
  sends a few hundred bytes of view synchronisation per frame).
--representation picks what draws the isosurface (clientserver.py).
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import clientserver as cs  # noqa: E402
from paraview.simple import CreateView, GetActiveCamera, Render, ResetCamera  # noqa: E402

args = cs.parse_args(__doc__.splitlines()[0])
check = cs.Checks()
relay = cs.RelayCounter(args.relay_control)
cs.connect(args)
relay.step("connect")
ns = cs.load_plugin(args)
relay.step("plugin")
check("MedicalPhantom" in ns and "BlockLODContour" in ns, "the plugin's proxies are available")
if not args.plugin_on_server_path:
    check(not cs.plugin_mapped_here(args.plugin),
          "the plugin library is not loaded in the client process")

phantom = ns["MedicalPhantom"](Dimensions=[96, 96, 96])
contour = ns["BlockLODContour"](Input=phantom, ContourBy=["POINTS", "HU"], Isosurfaces=[400.0],
                                LOD=3)
contour.UpdatePipeline()
producer = phantom.FieldData["ProducerProcessId"]
if args.server_pid and not os.environ.get("MEDISO_SERVER_RANKS"):
    check(producer is not None and int(producer.GetRange()[0]) == args.server_pid,
          "the data is produced in the pvserver process")
triangles = contour.GetDataInformation().GetNumberOfCells()
geometry_bytes = contour.GetDataInformation().GetMemorySize() * 1024
check(triangles > 10000, "level 3 has a surface (%d triangles)" % triangles)

view = CreateView("RenderView")
view.ViewSize = [800, 600]
view.OrientationAxesVisibility = 0
view.RemoteRenderThreshold = 0  # MB: always render on the server
display = cs.surface_representation(view, contour, phantom, args.representation, 400.0)
ResetCamera(view)
Render(view)
relay.step("set-up, first remote render")
check(view.GetClientSideObject().GetUseDistributedRenderingForRender(),
      "remote rendering: the server renders")
coverage, size = cs.image_coverage(view)
check(coverage > 0.02, "remote rendering: the image shows the surface (%.1f%% of pixels)"
      % (100 * coverage))
check(size == (800, 600), "the image has the view's size (%s)" % (size,))
relay.step("capture")
frames = []
for i in range(3):
    GetActiveCamera().Azimuth(10)
    Render(view)
    frames.append(relay.step("remote frame %d" % i))
for c2s, s2c in frames:
    check(s2c > 2000, "a remote frame brings an image back (%d B)" % s2c)
    check(s2c < 800 * 600 * 4, "a remote frame is at most one raw image (%d B)" % s2c)
    check(s2c < geometry_bytes / 4, "a remote frame is far smaller than the geometry "
          "(%d B against %d B)" % (s2c, geometry_bytes))

# Local rendering of a coarse level: the paper's fast client response.
view.RemoteRenderThreshold = 1.0e6
contour.LOD = 0
Render(view)
_, delivered = relay.step("local render of level 0 (geometry delivered)")
check(not view.GetClientSideObject().GetUseDistributedRenderingForRender(),
      "local rendering: the client renders")
coarse = contour.GetDataInformation().GetNumberOfCells()
check(0 < coarse < triangles / 8, "level 0 is coarse (%d triangles)" % coarse)
check(delivered > coarse * 3 * 4, "the level-0 geometry came to the client (%d B)" % delivered)
coverage, _ = cs.image_coverage(view)
check(coverage > 0.02, "local rendering: the image shows the surface (%.1f%% of pixels)"
      % (100 * coverage))
relay.step("local capture")
for i in range(10):
    GetActiveCamera().Azimuth(10)
    Render(view)
    c2s, s2c = relay.step("local frame %d" % i)
    check(s2c < 256, "local frame %d: nothing comes back from the server (%d B)" % (i, s2c))
    check(c2s < 1024, "local frame %d: only view synchronisation goes to the server (%d B)"
          % (i, c2s))

print(relay.table("Bytes through the relay (%s, plugin %s):" % (
    args.representation,
    "on PV_PLUGIN_PATH" if args.plugin_on_server_path else "loaded remotely")))
check.finish("BlockLODContour remote session: all checks passed")
