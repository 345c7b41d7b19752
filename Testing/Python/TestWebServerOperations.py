"""pvpython test: the web server's operations on a surface, end to end (docs/web.md).

Python/serve.py on the phantom (128^3): the surface it extracts for an isovalue and level is
ParaView's (level 3: vtkFlyingEdges3D's triangles and points; level 1: BlockLODContour's in this
process); smooth + fill holes + decimate on a closed surface gives a result whose STL, read back
with VTK, has the summary's triangles and no boundary edge (watertight), whose PLY and VTP read
back to the same surface; a clip opens it (boundary edges, every point behind the plane).
Progress comes in order; a running and a queued operation cancel; two clients at once each get
their own answers; a client that closes mid-operation stops it; a worker killed mid-operation
gives an error and is replaced, one killed while idle is replaced unseen; after each the server
serves the next operation.
"""
import asyncio
import json
import os
import signal
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import webserver  # noqa: E402  (skips when aiohttp or the plugin is missing)
import aiohttp  # noqa: E402

N = 128
ISO = 900.0        # the phantom's skull at 128^3: a closed surface
checks = webserver.Checks()
server = webserver.Server(["phantom:%d" % N])
SMOOTH_FILL_DECIMATE = [{"smooth": {"iterations": 20, "relaxation": 0.1}},
                        {"fillHoles": {"size": 20.0}}, {"decimate": {"reduction": 0.5}}]
HEAVY = [{"smooth": {"iterations": 500}}, {"decimate": {"reduction": 0.9}},
         {"smooth": {"iterations": 500}}]
request = webserver.surface_request


def reference_counts(level):
    """The phantom's surface here: FlyingEdges at level 3, BlockLODContour at the others."""
    import paraview.simple as simple
    from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D
    ns = {"__name__": "reference"}
    simple.LoadPlugin(webserver.PLUGIN, ns=ns)
    phantom = ns["MedicalPhantom"](Dimensions=[N] * 3, Spacing=[192.0 / N] * 3)
    if level == 3:
        phantom.UpdatePipeline()
        fe = vtkFlyingEdges3D()
        fe.SetInputData(phantom.GetClientSideObject().GetOutputDataObject(0))
        fe.SetValue(0, ISO)
        fe.ComputeNormalsOff()
        fe.Update()
        return fe.GetOutput().GetNumberOfCells(), fe.GetOutput().GetNumberOfPoints()
    contour = ns["BlockLODContour"](Input=phantom, Isosurfaces=[ISO], LOD=level)
    contour.UpdatePipeline()
    info = contour.GetDataInformation()
    return info.GetNumberOfCells(), info.GetNumberOfPoints()


def edges(polydata):
    """(boundary edges, non-manifold edges) of a surface: the server's own count (vtkFeatureEdges),
    the one its mesh report gives."""
    sys.path.insert(0, os.path.join(webserver.ROOT, "Python"))
    from serve_operations import edge_counts
    return tuple(edge_counts(polydata))


def read_back(path, fmt):
    from vtkmodules.vtkIOGeometry import vtkSTLReader
    from vtkmodules.vtkIOPLY import vtkPLYReader
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    reader = {"stl": vtkSTLReader, "ply": vtkPLYReader, "vtp": vtkXMLPolyDataReader}[fmt]()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


async def download(http, rid, fmt, folder):
    async with http.get(server.url("/api/result/%s?format=%s" % (rid, fmt))) as r:
        body = await r.read()
        checks(r.status == 200 and len(body) > 0, "the %s downloads (%d, %d bytes, %s)"
               % (fmt.upper(), r.status, len(body), r.headers.get("Content-Disposition")))
    path = os.path.join(folder, "%s.%s" % (rid, fmt))
    with open(path, "wb") as f:
        f.write(body)
    return path, body


async def status(http):
    async with http.get(server.url("/api/status")) as r:
        return await r.json()


async def wait_idle(http, seconds):
    start = time.monotonic()
    while time.monotonic() - start < seconds:
        s = await status(http)
        if not s["running"] and not s["queued"]:
            return time.monotonic() - start
        await asyncio.sleep(0.1)
    return None


async def same_surface(http, ws):
    for level in (3, 1):
        # Not cleaned: the surface as extracted (the default export cleans it, below).
        raw = dict(request(1, "d0", ISO, level), export={"clean": False})
        progress, answer = await webserver.operation(ws, raw)
        triangles, points = reference_counts(level)
        checks(answer.get("done") and answer["triangles"] == triangles and
               answer["points"] == points,
               "level %d, no steps, not cleaned: %s triangles, %s points; %s here %d, %d"
               % (level, answer.get("triangles"), answer.get("points"),
                  "vtkFlyingEdges3D" if level == 3 else "BlockLODContour", triangles, points))
        report = answer.get("report", {})
        _, cleaned = await webserver.operation(ws, request(1, "d0", ISO, level))
        checks(cleaned.get("done") and cleaned["triangles"] == triangles -
               report.get("degenerateTriangles", -1) - report.get("duplicateTriangles", -1)
               and cleaned["points"] == report.get("points"),
               "... cleaned (the default): %s triangles, the %d less the %s degenerate and %s "
               "duplicate ones the report found; its %s points" % (
                   cleaned.get("triangles"), triangles, report.get("degenerateTriangles"),
                   report.get("duplicateTriangles"), report.get("points")))


async def watertight(http, ws, folder):
    progress, answer = await webserver.operation(ws, request(2, "d0", ISO, 3, SMOOTH_FILL_DECIMATE))
    if not checks(answer.get("done") is True, "smooth + fill holes + decimate: %s"
                  % {k: answer.get(k) for k in ("triangles", "seconds", "error")}):
        return
    fractions = [p["progress"] for p in progress]
    stages = [p["stage"] for p in progress]
    checks(fractions == sorted(fractions) and all(0 <= f <= 1 for f in fractions),
           "progress rises from 0 to 1 (%d messages)" % len(fractions))
    checks(stages.index("surface") < stages.index("smooth") < stages.index("fillHoles")
           < stages.index("decimate") < stages.index("write"),
           "progress names the stages in order: %s" % sorted(set(stages), key=stages.index))
    surface = answer["stages"][0]["triangles"]
    checks(0.45 * surface <= answer["triangles"] <= 0.55 * surface,
           "decimate 0.5 halves the surface: %d -> %d triangles" % (surface, answer["triangles"]))
    checks(answer["boundaryEdges"] == 0, "the summary says closed (%d boundary edges)"
           % answer["boundaryEdges"])
    stl_path, stl = await download(http, answer["result"], "stl", folder)
    stl_surface = read_back(stl_path, "stl")
    boundary, non_manifold = edges(stl_surface)
    checks(stl_surface.GetNumberOfCells() == answer["triangles"] and
           int.from_bytes(stl[80:84], "little") == answer["triangles"] and
           len(stl) == 84 + 50 * answer["triangles"],
           "the binary STL holds the %d triangles (read back: %d)"
           % (answer["triangles"], stl_surface.GetNumberOfCells()))
    checks(boundary == 0, "the STL read back is watertight: %d boundary edges "
           "(%d non-manifold edges)" % (boundary, non_manifold))
    ply_path, ply = await download(http, answer["result"], "ply", folder)
    ply_surface = read_back(ply_path, "ply")
    checks(b"format binary_little_endian 1.0" in ply[:200] and
           ply_surface.GetNumberOfCells() == answer["triangles"] and
           ply_surface.GetNumberOfPoints() == answer["points"],
           "the PLY is binary little-endian with the same %d points and triangles"
           % ply_surface.GetNumberOfPoints())
    vtp_path, vtp = await download(http, answer["result"], "vtp", folder)
    vtp_surface = read_back(vtp_path, "vtp")
    checks(b'format="appended"' in vtp and b'encoding="raw"' in vtp and
           vtp_surface.GetNumberOfCells() == answer["triangles"] and
           edges(vtp_surface)[0] == 0,
           "the VTP is appended raw binary, the same closed surface")
    for key in ("stl", "ply", "vtp"):
        checks(answer["bytes"][key] == os.path.getsize(os.path.join(folder, "%s.%s" % (
            answer["result"], key))), "the summary gives the %s's size" % key.upper())


async def clipped(http, ws, folder):
    centre = 192.0 / N * (N - 1) / 2
    steps = SMOOTH_FILL_DECIMATE[:1] + [{"clip": {"origin": [centre] * 3, "normal": [0, 1, 0]}}]
    _, answer = await webserver.operation(ws, request(3, "d0", ISO, 2, steps))
    if not checks(answer.get("done") is True, "smooth + clip at level 2: %s triangles"
                  % answer.get("triangles")):
        return
    path, _ = await download(http, answer["result"], "stl", folder)
    surface = read_back(path, "stl")
    boundary, _ = edges(surface)
    ymax = surface.GetBounds()[3]
    checks(boundary > 0 and answer["boundaryEdges"] > 0,
           "the clip opens the surface: %d boundary edges read back" % boundary)
    checks(ymax <= centre + 1e-3, "the clip keeps the side behind the normal (y max %.3f, "
           "plane y = %.3f)" % (ymax, centre))


async def cancels(http):
    async with http.ws_connect(server.ws_url()) as ws:
        await ws.send_json(request(10, "d0", ISO, 3, HEAVY))
        await ws.send_json(request(11, "d0", ISO, 3, HEAVY))
        seen = {}
        while not ("smooth" == seen.get(10) and "queued" == seen.get(11)):
            m = json.loads((await ws.receive(timeout=120)).data)
            if "stage" in m:
                seen[m["id"]] = m["stage"]
        await ws.send_json({"op": "cancel", "id": 11})
        m = json.loads((await ws.receive(timeout=30)).data)
        while m.get("id") != 11:
            m = json.loads((await ws.receive(timeout=30)).data)
        checks(m == {"id": 11, "cancelled": True}, "a queued operation cancels: %s" % m)
        t = time.monotonic()
        await ws.send_json({"op": "cancel", "id": 10})
        while True:
            m = json.loads((await ws.receive(timeout=60)).data)
            if m.get("id") == 10 and "progress" not in m:
                break
        checks(m == {"id": 10, "cancelled": True}, "a running operation cancels in %.1f s: %s"
               % (time.monotonic() - t, m))
        s = await status(http)
        checks(s["worker"]["restarts"] == 0 and not s["running"],
               "the worker stopped it itself (restarts %d)" % s["worker"]["restarts"])
        _, answer = await webserver.operation(ws, request(12, "d0", ISO, 1))
        checks(answer.get("done") is True, "the next operation runs")


async def two_clients(http):
    async with http.ws_connect(server.ws_url()) as a, http.ws_connect(server.ws_url()) as b:
        results = await asyncio.gather(
            webserver.operation(a, request(1, "d0", ISO, 2, SMOOTH_FILL_DECIMATE)),
            webserver.operation(b, request(1, "d0", -500.0, 2, SMOOTH_FILL_DECIMATE)))
        (pa, ra), (pb, rb) = results
        checks(ra.get("done") and rb.get("done") and ra["isovalue"] == ISO and
               rb["isovalue"] == -500.0 and ra["result"] != rb["result"],
               "two clients with the same ids each get their own result (%s, %s)"
               % (ra.get("isovalue"), rb.get("isovalue")))
        checks(any(p["stage"] == "queued" for p in pa + pb),
               "the second one waited in the queue, and was told so")


async def close_mid_operation(http):
    a = await http.ws_connect(server.ws_url())
    await a.send_json(request(1, "d0", ISO, 3, HEAVY))
    while json.loads((await a.receive(timeout=120)).data).get("stage") != "smooth":
        pass
    await a.close()
    idle = await wait_idle(http, 30)
    checks(idle is not None and idle < 8, "a client that closes mid-operation stops it "
           "(the server idle %.1f s after)" % (idle if idle is not None else -1))
    s = await status(http)
    checks(s["worker"]["restarts"] == 0, "by abort, not by ending the worker")
    async with http.ws_connect(server.ws_url()) as b:
        _, answer = await webserver.operation(b, request(2, "d0", ISO, 1))
        checks(answer.get("done") is True, "another client's operation then runs")
        rid = answer.get("result")
    async with http.get(server.url("/api/result/%s?format=ply" % rid)) as r:
        checks(r.status == 200, "a closed page's result is still downloadable for a while")


async def worker_killed(http):
    pid = (await status(http))["worker"]["pid"]
    async with http.ws_connect(server.ws_url()) as ws:
        await ws.send_json(request(1, "d0", ISO, 3, HEAVY))
        while json.loads((await ws.receive(timeout=120)).data).get("stage") != "smooth":
            pass
        os.kill(pid, signal.SIGKILL)
        m = json.loads((await ws.receive(timeout=60)).data)
        while "progress" in m:
            m = json.loads((await ws.receive(timeout=60)).data)
        checks("ended unexpectedly" in m.get("error", ""),
               "a worker killed mid-operation: %s" % m.get("error"))
        _, answer = await webserver.operation(ws, request(2, "d0", ISO, 1))
        checks(answer.get("done") is True, "a new worker runs the next operation")
    s = await status(http)
    checks(s["worker"]["restarts"] == 1 and s["worker"]["pid"] != pid,
           "the worker was replaced once (restarts %d)" % s["worker"]["restarts"])
    os.kill(s["worker"]["pid"], signal.SIGKILL)  # now while it waits for work
    await asyncio.sleep(0.5)
    async with http.ws_connect(server.ws_url()) as ws:
        _, answer = await webserver.operation(ws, request(3, "d0", ISO, 1))
        checks(answer.get("done") is True, "a worker killed while idle: the next operation "
               "runs on a new one (%s)" % answer.get("error", "done"))


async def main(folder):
    async with aiohttp.ClientSession() as http:
        async with http.ws_connect(server.ws_url()) as ws:
            await same_surface(http, ws)
            await watertight(http, ws, folder)
            await clipped(http, ws, folder)
        await cancels(http)
        await two_clients(http)
        await close_mid_operation(http)
        await worker_killed(http)
        async with http.get(server.url("/api/result/r0123456789abcdef?format=stl")) as r:
            checks(r.status == 404, "an unknown result: %d" % r.status)
        checks(server.alive(), "the server is still running")


if __name__ == "__main__":
    import tempfile
    with tempfile.TemporaryDirectory() as folder:
        asyncio.run(main(folder))
    checks.finish(server)
