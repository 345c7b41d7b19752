"""Only parameters travel: bytes per step through the relay, for two volume sizes.

Run by Testing/Scripts/client-server.sh (pvserver and the byte relay in a
loopback-only namespace). For a 64^3 and a 256^3 phantom (64 times the voxels)
in remote rendering mode, after set-up:
- changing the isovalue sends under 2 KB client->server (the property, 71 B,
  and ParaView marking the shown representation modified on the server), and
  so does the render that follows (progress, update and data-information
  requests, the render request with the camera); both together stay under
  2.5 KB, the same for both sizes. (The first property push after set-up
  carries about 0.7 KB more pending proxy state, once: it is shown as a
  set-up step, and the next two changes are the ones checked;)
- a remote frame brings back about one image (JPEG-free LZ4 of 800x600),
  whatever the volume size: the two sizes' frames are within 25% of each
  other, while their surfaces differ about 16 times;
- no step of the session sends geometry or volume data client->server.
Prints the per-step table (docs/clientserver.md's table comes from this output).
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import clientserver as cs  # noqa: E402
from paraview.simple import CreateView, Delete, GetActiveCamera, Hide, Render, ResetCamera  # noqa

args = cs.parse_args(__doc__.splitlines()[0], lambda p: p.add_argument(
    "--sizes", type=int, nargs="+", default=[64, 256]))
check = cs.Checks()
relay = cs.RelayCounter(args.relay_control)
cs.connect(args)
ns = cs.load_plugin(args)
view = CreateView("RenderView")
view.ViewSize = [800, 600]
view.OrientationAxesVisibility = 0
view.RemoteRenderThreshold = 0
relay.step("connect, plugin, view")

results = {}
for n in args.sizes:
    tag = "%d^3" % n
    phantom = ns["MedicalPhantom"](Dimensions=[n, n, n])
    contour = ns["BlockLODContour"](Input=phantom, ContourBy=["POINTS", "HU"],
                                    Isosurfaces=[400.0], LOD=3)
    display = cs.surface_representation(view, contour, phantom, args.representation, 400.0)
    ResetCamera(view)
    Render(view)
    GetActiveCamera().Azimuth(10)
    Render(view)
    relay.step("%s: set-up and two renders" % tag)
    cs.set_isovalue(display, contour, args.representation, 350.0)
    relay.step("%s: set-up, first isovalue change 400 -> 350 (property)" % tag)
    Render(view)
    relay.step("%s: set-up, render after the first change" % tag)
    changes = []
    for old, new in ((350.0, 250.0), (250.0, 300.0)):
        cs.set_isovalue(display, contour, args.representation, new)
        c2s_property, _ = relay.step("%s: isovalue %g -> %g (property)" % (tag, old, new))
        Render(view)
        c2s_render, _ = relay.step("%s: render after the change" % tag)
        changes.append(c2s_property + c2s_render)
        check(c2s_property < 2048, "%s: an isovalue change sends %d B client->server (limit 2048)"
              % (tag, c2s_property))
        check(c2s_render < 2048, "%s: the render after it sends %d B client->server (limit 2048)"
              % (tag, c2s_render))
    if args.representation == cs.SURFACE:
        info = contour.GetDataInformation()
        geometry = info.GetMemorySize() * 1024
        triangles = info.GetNumberOfCells()
    else:
        # The GPU representation: its active cells and GPU bytes on the server.
        import HistoPyramidRepresentationChecks as hp
        drawn = hp.render_info(display)
        check(drawn["path"] == "gpu", "%s: the server drew on the GPU path (%s)" % (tag, drawn))
        geometry = drawn["gpu_bytes"]
        triangles = drawn["primitives"]
        for c in changes:
            check(c < 2048, "%s: changing the isovalue and rendering sends %d B client->server "
                  "(limit 2048)" % (tag, c))
    frames = []
    for i in range(3):
        GetActiveCamera().Azimuth(10)
        Render(view)
        frames.append(relay.step("%s: remote frame %d" % (tag, i)))
    change = max(changes)
    for c in changes:
        check(c < 2560, "%s: changing the isovalue and rendering sends %d B client->server "
              "(limit 2560)" % (tag, c))
    check(triangles > 1000, "%s: the new isovalue has a surface (%d triangles or cells)"
          % (tag, triangles))
    frame_s2c = sorted(f[1] for f in frames)[1]
    check(frame_s2c < 800 * 600 * 4, "%s: a frame is at most one raw image (%d B)"
          % (tag, frame_s2c))
    results[n] = (change, frame_s2c, triangles, geometry)
    for f in frames:
        check(f[0] < 2048, "%s: a frame sends %d B client->server" % (tag, f[0]))
    Hide(contour if args.representation == cs.SURFACE else phantom, view)
    Delete(contour)
    Delete(phantom)
    relay.step("%s: delete" % tag)

print(relay.table("Bytes through the relay, remote rendering 800x600, %s:" % args.representation))
print()
print("| phantom | voxels | triangles (iso 300, L3) | surface in server memory | "
      "isovalue change + render, client->server | remote frame, server->client |")
print("|---|---:|---:|---:|---:|---:|")
for n, (change, frame, triangles, geometry) in sorted(results.items()):
    print("| %d^3 | %d | %d | %.1f MB | %d B | %.1f KB |"
          % (n, n ** 3, triangles, geometry / 1e6, change, frame / 1e3))
small, large = min(results), max(results)
check(large ** 3 >= 8 * small ** 3, "the sizes are at least 8x apart in voxels")
ratio = results[large][1] / float(results[small][1])
check(len(set(r[0] for r in results.values())) == 1,
      "an isovalue change with its render sends the same bytes for every volume size")
check(0.75 < ratio < 1.33, "a frame's bytes do not follow the volume size (%d^3: %d B, %d^3: %d B)"
      % (small, results[small][1], large, results[large][1]))
check(results[large][3] > 4 * results[small][3], "the surfaces do grow with the volume")
check(relay.rows and max(r[1] for r in relay.rows) < 64 * 1024,
      "no step sends more than 64 KB client->server (no geometry or volume goes up)")
check.finish("only parameters travel: all checks passed")
