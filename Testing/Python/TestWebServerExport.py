"""pvpython test: the web server's export options, its mesh report, the volume's validators and
the source format it states (docs/web.md, "Export" and "Caching").

A volume written here: two spheres in a 48^3 int16 grid, a large one cut by the volume's x = 0
face and a small one inside. Python/serve.py serves it with a NIfTI, a MetaImage and the phantom.
- Export: without capping, the large sphere's surface is open where the face cuts it (boundary
  edges, not watertight, two pieces); capped, both spheres are closed (watertight, no boundary
  or non-manifold edge), also at a coarse level; capped with the largest piece kept, one closed
  piece. Without cleaning, the isovalue through grid points gives degenerate triangles; cleaned,
  none. A cap at the data's minimum and a bad option are refused with a message.
- The report: every field of serve_messages.REPORT, counted again here with numpy on the
  downloaded STL's triangles (corners at the same float32 position are one point), equal.
- Caching: /api/volume answers with an ETag, Last-Modified and Cache-Control no-cache (not
  no-store); the same request with If-None-Match (or only If-Modified-Since) gets 304 and no
  body; another level or a wrong tag gets the bytes; without the token or with a wrong one, 403
  and never the bytes nor a 304; a second server on the same file gives the same ETag, on the
  file changed a new one.
- Format: each dataset states its format and the patient space of its world (NIfTI RAS,
  MetaImage LPS, the phantom RAS, VTK image LPS).
"""
import asyncio
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import webserver  # noqa: E402  (skips when aiohttp or the plugin is missing)
import aiohttp  # noqa: E402
import numpy  # noqa: E402

sys.path.insert(0, os.path.join(webserver.ROOT, "Python"))
from serve_messages import REPORT  # noqa: E402

N = 48
BIG = ((2.0, 24.0, 24.0), 20.0)      # cut by the x = 0 face
SMALL = ((37.0, 37.0, 37.0), 5.0)    # inside
checks = webserver.Checks()
request = webserver.surface_request


def spheres(bump=0):
    """int16 values 500 on the spheres' surfaces, 25 per mm inside them, clamped to 0..1000."""
    z, y, x = numpy.mgrid[0:N, 0:N, 0:N].astype(float)
    values = []
    for (cx, cy, cz), r in (BIG, SMALL):
        d = numpy.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2)
        values.append(500 + 25 * (r - d))
    v = numpy.clip(numpy.rint(numpy.maximum(*values)), 0, 1000).astype(numpy.int16)
    v[0, 0, N - 1] += bump  # a corner far from both spheres
    return v


def write_vti(path, values):
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOXML import vtkXMLImageDataWriter
    image = vtkImageData()
    image.SetDimensions(N, N, N)
    image.SetSpacing(1, 1, 1)
    array = numpy_to_vtk(values.ravel(), deep=True)
    array.SetName("values")
    image.GetPointData().SetScalars(array)
    w = vtkXMLImageDataWriter()
    w.SetFileName(path)
    w.SetInputData(image)
    w.Write()
    return image


def write_others(folder, image):
    from vtkmodules.vtkIOImage import vtkMetaImageWriter, vtkNIFTIImageWriter
    paths = []
    for writer, name in ((vtkNIFTIImageWriter(), "spheres.nii"),
                         (vtkMetaImageWriter(), "spheres.mha")):
        path = os.path.join(folder, name)
        writer.SetFileName(path)
        writer.SetInputData(image)
        writer.Write()
        paths.append(path)
    return paths


def count_stl(body):
    """REPORT's fields of a binary STL, counted with numpy alone."""
    n = int.from_bytes(body[80:84], "little")
    record = numpy.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attr", "<u2")])
    corners = numpy.frombuffer(body, record, count=n, offset=84)["corners"].reshape(-1, 3)
    corners = corners + numpy.float32(0)  # -0.0 and 0.0 are one position
    positions, ids = numpy.unique(corners, axis=0, return_inverse=True)
    tri = ids.reshape(-1, 3)
    degenerate = (tri[:, 0] == tri[:, 1]) | (tri[:, 1] == tri[:, 2]) | (tri[:, 0] == tri[:, 2])
    good = tri[~degenerate]
    duplicates = len(good) - len(numpy.unique(numpy.sort(good, axis=1), axis=0))
    edges = numpy.sort(numpy.concatenate([good[:, [0, 1]], good[:, [1, 2]], good[:, [2, 0]]]),
                       axis=1)
    _, uses = numpy.unique(edges, axis=0, return_counts=True)
    # pieces: the smallest id of each corner's piece, spread along the edges until it settles
    labels = numpy.arange(len(positions))
    a, b = edges[:, 0], edges[:, 1]
    while True:
        low = numpy.minimum(labels[a], labels[b])
        new = labels.copy()
        numpy.minimum.at(new, a, low)
        numpy.minimum.at(new, b, low)
        new = new[new]
        if numpy.array_equal(new, labels):
            break
        labels = new
    pieces = len(numpy.unique(labels[numpy.unique(good)])) if len(good) else 0
    boundary, non_manifold = int((uses == 1).sum()), int((uses >= 3).sum())
    return {"triangles": n, "points": len(positions), "components": pieces,
            "boundaryEdges": boundary, "nonManifoldEdges": non_manifold,
            "degenerateTriangles": int(degenerate.sum()), "duplicateTriangles": duplicates,
            "watertight": len(good) > 0 and boundary == 0 and non_manifold == 0 and
            duplicates == 0}


async def result(http, server, ws, ident, isovalue, level=3, export=None, steps=()):
    """(the done answer, the numpy count of its STL), or (the answer, None) when it failed."""
    message = request(ident, "d0", isovalue, level, steps)
    if export is not None:
        message["export"] = export
    _, answer = await webserver.operation(ws, message)
    if not answer.get("done"):
        return answer, None
    async with http.get(server.url("/api/result/%s?format=stl" % answer["result"])) as r:
        body = await r.read()
    return answer, count_stl(body)


def same_report(what, answer, counted):
    report = answer.get("report", {})
    checks(sorted(report) == sorted(REPORT), "%s: the report has REPORT's fields (%s)"
           % (what, ", ".join(sorted(report))))
    differ = {k: (report.get(k), counted[k]) for k in REPORT if report.get(k) != counted[k]}
    checks(not differ, "%s: the report equals numpy's count on the STL %s%s"
           % (what, {k: report.get(k) for k in REPORT},
              "; differ (report, numpy): %s" % differ if differ else ""))
    return report


async def export_options(http, server):
    async with http.ws_connect(server.ws_url()) as ws:
        answer, counted = await result(http, server, ws, 1, 500.0, export={"clean": False})
        raw = same_report("isovalue 500 (on grid points), not cleaned", answer, counted) \
            if counted else {}
        checks(raw.get("degenerateTriangles", 0) > 0, "... the isovalue through grid points "
               "gives degenerate triangles uncleaned (%s)" % raw.get("degenerateTriangles"))

        answer, counted = await result(http, server, ws, 2, 500.0)
        open_ = same_report("isovalue 500, cleaned (the default), not capped", answer, counted) \
            if counted else {}
        checks(answer.get("export") == {"clean": True, "largestComponent": False, "cap": False},
               "the answer states the export options applied: %s" % answer.get("export"))
        checks(open_.get("degenerateTriangles") == 0 and open_.get("duplicateTriangles") == 0,
               "... cleaned: no degenerate or duplicate triangle")
        checks(open_.get("boundaryEdges", 0) > 0 and open_.get("watertight") is False and
               open_.get("components") == 2,
               "... the face cuts the large sphere: %s boundary edges, not watertight, %s pieces"
               % (open_.get("boundaryEdges"), open_.get("components")))
        checks(answer.get("boundaryEdges") == open_.get("boundaryEdges"),
               "... the summary's boundaryEdges is the report's")

        closed = {}
        for level in (3, 1):
            answer, counted = await result(http, server, ws, 3 + level, 500.0, level,
                                           {"cap": True})
            capped = closed[level] = same_report("capped at level %d" % level, answer, counted) \
                if counted else {}
            checks(capped.get("watertight") is True and capped.get("boundaryEdges") == 0 and
                   capped.get("nonManifoldEdges") == 0 and capped.get("components") == 2,
                   "... closed where the face cut it: watertight, 0 boundary and non-manifold "
                   "edges, 2 pieces (%s)" % capped.get("components"))
            bounds = answer.get("bounds", [0] * 6)
            stride = 8 >> level
            checks(-stride - 1e-3 <= bounds[0] < 0,
                   "... the cap lies within one sample (%g mm) outside the x = 0 face "
                   "(x min %.3f)" % (stride, bounds[0]))

        answer, counted = await result(http, server, ws, 6, 500.0,
                                       export={"cap": True, "largestComponent": True})
        one = same_report("capped, largest piece", answer, counted) if counted else {}
        checks(one.get("components") == 1 and one.get("watertight") is True and
               one.get("triangles", 0) < closed[3].get("triangles", 0),
               "... one closed piece: %s of %s triangles" % (one.get("triangles"),
                                                             closed[3].get("triangles")))
        checks(answer.get("bounds", [0] * 6)[1] < SMALL[0][0] - SMALL[1],
               "... the large sphere's (x max %.2f)" % answer.get("bounds", [0] * 6)[1])

        answer, counted = await result(http, server, ws, 7, 500.0, steps=[
            {"decimate": {"reduction": 0.5}}], export={"cap": True})
        if counted:
            same_report("capped, decimated", answer, counted)

        _, answer = await webserver.operation(ws, dict(request(8, "d0", 0.0), export={
            "cap": True}))
        checks("cap: the isovalue is the data's minimum" in answer.get("error", ""),
               "a cap at the data's minimum is refused: %s" % answer.get("error"))
        _, answer = await webserver.operation(ws, dict(request(9, "d0", 500.0), export={
            "cap": 1}))
        checks(answer.get("error") == "export.cap: true or false (1)",
               "a bad export option is refused: %s" % answer.get("error"))
        _, answer = await webserver.operation(ws, dict(request(10, "d0", 500.0), export={
            "holes": True}))
        checks(answer.get("error") == "export: unknown field 'holes'",
               "an unknown export option is refused: %s" % answer.get("error"))


async def validators(http, server):
    """The volume's ETag round trip; returns level 3's ETag."""
    url = "/api/volume/d0?level=3"
    async with http.get(server.url(url)) as r:
        body = await r.read()
        etag, modified = r.headers.get("ETag"), r.headers.get("Last-Modified")
        cache = r.headers.get("Cache-Control", "")
        checks(r.status == 200 and len(body) > 1000 and etag and modified,
               "the volume: 200, %d bytes, ETag %s, Last-Modified %s" % (len(body), etag,
                                                                          modified))
    checks("no-cache" in cache and "no-store" not in cache and "private" in cache,
           "... Cache-Control %r: kept by the browser, revalidated at each use" % cache)
    for what, headers in (("If-None-Match", {"If-None-Match": etag}),
                          ("a weak If-None-Match in a list",
                           {"If-None-Match": '"other", W/%s' % etag}),
                          ("If-Modified-Since alone", {"If-Modified-Since": modified})):
        async with http.get(server.url(url), headers=headers) as r:
            again = await r.read()
            checks(r.status == 304 and len(again) == 0 and r.headers.get("ETag") == etag,
                   "%s: %d, %d bytes" % (what, r.status, len(again)))
    for what, headers in (("a wrong ETag", {"If-None-Match": '"0-3-x"'}),
                          ("a wrong ETag with a matching If-Modified-Since",
                           {"If-None-Match": '"0-3-x"', "If-Modified-Since": modified})):
        async with http.get(server.url(url), headers=headers) as r:
            again = await r.read()
            checks(r.status == 200 and again == body, "%s: %d and the bytes" % (what, r.status))
    async with http.get(server.url("/api/volume/d0?level=1")) as r:
        await r.read()
        checks(r.status == 200 and r.headers.get("ETag") not in (None, etag),
               "level 1 has its own ETag (%s)" % r.headers.get("ETag"))
    async with http.get(server.url("/api/volume/d3?level=1")) as r:
        await r.read()
        checks(r.status == 200 and r.headers.get("ETag") and "Last-Modified" not in r.headers,
               "the phantom: an ETag, no Last-Modified (it has no file)")
    # The token is checked first: no bytes, no 304, without it or with a wrong one.
    async with aiohttp.ClientSession() as bare:  # no cookie
        for what, token in (("no token", None), ("a wrong token", "wrong")):
            for headers in ({}, {"If-None-Match": etag}, {"If-Modified-Since": modified}):
                async with bare.get(server.url(url, token), headers=headers) as r:
                    text = await r.read()
                    checks(r.status in (401, 403) and len(text) < 100 and
                           "ETag" not in r.headers,
                           "%s, %s: %d, %d bytes, no ETag" % (
                               what, ", ".join(headers) or "unconditional", r.status,
                               len(text)))
    return etag


async def formats(http, server):
    async with http.get(server.url("/api/datasets")) as r:
        datasets = (await r.json())["datasets"]
    got = [(d["name"], d.get("format")) for d in datasets]
    expected = [{"name": "VTK image", "space": "LPS"}, {"name": "NIfTI", "space": "RAS"},
                {"name": "MetaImage", "space": "LPS"}, {"name": "phantom", "space": "RAS"}]
    checks([f for _, f in got] == expected, "each dataset states its format and space: %s" % got)


async def etag_of(server):
    async with aiohttp.ClientSession() as http:
        async with http.get(server.url("/api/volume/d0?level=3")) as r:
            await r.read()
            return r.headers.get("ETag")


async def main(folder, server):
    async with aiohttp.ClientSession() as http:
        await formats(http, server)
        etag = await validators(http, server)
        await export_options(http, server)
    return etag


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as folder:
        vti = os.path.join(folder, "spheres.vti")
        image = write_vti(vti, spheres())
        server = webserver.Server([vti] + write_others(folder, image) + ["phantom:32"])
        etag = asyncio.run(main(folder, server))
        servers = [server]
        # The same file served again keeps its ETag (a browser's copy survives a restart); the
        # file changed gets another.
        again = webserver.Server([vti])
        servers.append(again)
        checks(asyncio.run(etag_of(again)) == etag, "another server on the same file: the same "
               "ETag")
        again.stop()
        write_vti(vti, spheres(bump=1))
        changed = webserver.Server([vti])
        servers.append(changed)
        new = asyncio.run(etag_of(changed))
        checks(new not in (None, etag), "the file changed: a new ETag (%s, was %s)" % (new, etag))
        checks.finish(*servers)
