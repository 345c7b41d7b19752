"""pvpython test: the web server's operations on volumes with a direction (docs/web.md, "Operations").

The test writes three NIfTI files of one int16 ball (origin and anisotropic spacing): an
axis-aligned sform, one turned 30 degrees about an oblique axis, and its mirror image (determinant
-1). The server reads them with the plugin's MedicalNIfTIReader, which puts the sform's direction
on the image (a left-handed sform as VTK's reader does: the slices reversed, a right-handed
direction), and states that direction to the page. An operation on each succeeds, and its result
is in the page's scene frame (origin + index x spacing, the direction left out): level 3 has the
triangles and points of vtkFlyingEdges3D on the volume /api/volume sends, placed as
/api/datasets states (the page's CPU count), and its VTP and STL lie where that surface does;
level 1 lies there within a level-1 cell, with the axis-aligned file's counts for the turned file
(the same values); a capped export (the padded volume) lies there too. Before, each operation on
a file with a direction failed with BlockLODContour's error; with the direction applied and not
left out, they lie in patient space, mm to tens of mm away here (the same bounds fail).
"""
import asyncio
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import webserver  # noqa: E402  (skips when aiohttp or the plugin is missing)
from nifti import nifti1_header  # noqa: E402  (Testing/Python/nifti.py)
import aiohttp  # noqa: E402
import numpy  # noqa: E402

DIMS = (41, 37, 33)  # x, y, z
SPACING = (0.9, 0.8, 1.2)
ORIGIN = (-20.0, 10.0, 5.0)
ISO = 400.5
checks = webserver.Checks()
request = webserver.surface_request


def ball():
    """A ball of 1000 at its centre falling by 60 a voxel, with a gradient: int16, (z, y, x)."""
    z, y, x = numpy.meshgrid(*(numpy.arange(n, dtype=float) for n in DIMS[::-1]), indexing="ij")
    c = [(n - 1) / 2.0 for n in DIMS]
    r = numpy.sqrt((x - c[0]) ** 2 + ((y - c[1]) * 1.1) ** 2 + ((z - c[2]) * 0.9) ** 2)
    return numpy.round(1000.0 - 60.0 * r + 3.0 * x).astype(numpy.int16)


def rotation(degrees, axis):
    a = numpy.asarray(axis, float) / numpy.linalg.norm(axis)
    t = numpy.radians(degrees)
    k = numpy.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return numpy.eye(3) + numpy.sin(t) * k + (1 - numpy.cos(t)) * k @ k


def write_nifti(path, values, direction):
    """A NIfTI-1 file (.nii) whose sform (code 2) places voxel (i, j, k) at
    ORIGIN + direction (SPACING * (i, j, k)); no qform."""
    srow = numpy.asarray(direction) @ numpy.diag(SPACING)
    header = nifti1_header(DIMS, SPACING, sform=[[*srow[r], ORIGIN[r]] for r in range(3)],
                           sform_code=2)  # aligned
    with open(path, "wb") as f:
        f.write(header + values.astype("<i2").tobytes())


async def page_surface(http, server, dataset):
    """What the page draws at level 3: vtkFlyingEdges3D on the volume /api/volume sends, in the
    scene frame /api/datasets states (origin + index x spacing): (triangles, points), bounds."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D
    dims = dataset["dims"]
    async with http.get(server.url("/api/volume/%s?level=3" % dataset["id"])) as r:
        values = webserver.decode(await r.read(), dataset["type"], dims[0] * dims[1] * dims[2])
    image = vtkImageData()
    image.SetDimensions(dims)
    image.SetSpacing(dataset["spacing"])
    image.SetOrigin(dataset["origin"])
    image.GetPointData().SetScalars(numpy_to_vtk(values, deep=True))
    fe = vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.SetValue(0, ISO)
    fe.ComputeNormalsOff()
    fe.Update()
    out = fe.GetOutput()
    return (out.GetNumberOfCells(), out.GetNumberOfPoints()), out.GetBounds()


def read_back(path, fmt):
    from vtkmodules.vtkIOGeometry import vtkSTLReader
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    reader = {"stl": vtkSTLReader, "vtp": vtkXMLPolyDataReader}[fmt]()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


async def download(http, server, rid, fmt, folder):
    async with http.get(server.url("/api/result/%s?format=%s" % (rid, fmt))) as r:
        body = await r.read()
        checks(r.status == 200 and len(body) > 0, "the %s downloads (%d)" % (fmt.upper(), r.status))
    path = os.path.join(folder, "%s.%s" % (rid, fmt))
    with open(path, "wb") as f:
        f.write(body)
    return read_back(path, fmt)


def near(a, b, tolerance=1e-3):
    return len(a) == len(b) and all(abs(x - y) <= tolerance for x, y in zip(a, b))


async def main(server, folder, directions):
    # As the page reads /api/volume: the gzip'd body itself (decode() inflates it).
    async with aiohttp.ClientSession(auto_decompress=False) as http:
        async with http.get(server.url("/api/datasets")) as r:
            datasets = (await r.json())["datasets"]
        async with http.ws_connect(server.ws_url()) as ws:
            aligned = {}
            for i, (name, direction) in enumerate(directions):
                dataset = datasets[i]
                stated = numpy.reshape(dataset["direction"], (3, 3))
                checks(not numpy.allclose(stated, numpy.eye(3)) or i == 0,
                       "%s: the server states a direction (%s; %s)"
                       % (name, numpy.round(stated, 4).tolist(), dataset["origin"]))
                page_counts, page_bounds = await page_surface(http, server, dataset)
                for level in (3, 1):
                    raw = dict(request(10 * i + level, dataset["id"], ISO, level),
                               export={"clean": False})
                    _, answer = await webserver.operation(ws, raw)
                    if not checks(answer.get("done") is True, "%s level %d: the operation "
                                  "succeeds (%s)" % (name, level, answer.get("error"))):
                        continue
                    counts = (answer["triangles"], answer["points"])
                    vtp = await download(http, server, answer["result"], "vtp", folder)
                    stl = await download(http, server, answer["result"], "stl", folder)
                    bounds = (vtp.GetBounds(), stl.GetBounds())
                    if level == 3:
                        checks(counts == page_counts, "%s level 3: %s triangles and points; the "
                               "page's vtkFlyingEdges3D %s" % (name, counts, page_counts))
                        where = near(bounds[0], page_bounds) and near(bounds[1], page_bounds)
                    else:
                        # A coarser surface: within a cell of level 1 (4 voxels) of the page's.
                        where = near(bounds[0], page_bounds, 4 * max(SPACING)) and \
                            near(bounds[1], page_bounds, 4 * max(SPACING))
                        if i == 0:
                            aligned[level] = counts
                        elif name == "turned":  # the same values as the axis-aligned file
                            checks(counts == aligned.get(level), "%s level %d: %s triangles and "
                                   "points, the axis-aligned file's %s"
                                   % (name, level, counts, aligned.get(level)))
                    checks(where, "%s level %d: the VTP and STL in the page's scene frame (%s; "
                           "the page's %s)" % (name, level, ["%.3f" % b for b in bounds[0]],
                                               ["%.3f" % b for b in page_bounds]))
                capped = dict(request(10 * i + 5, dataset["id"], ISO, 3), export={"cap": True})
                _, answer = await webserver.operation(ws, capped)
                if checks(answer.get("done") is True and answer.get("boundaryEdges") == 0,
                          "%s capped: succeeds, closed (%s, %s boundary edges)"
                          % (name, answer.get("error"), answer.get("boundaryEdges"))):
                    box = (await download(http, server, answer["result"], "vtp", folder)).GetBounds()
                    checks(near(box, page_bounds), "%s capped: in the page's scene frame (%s)"
                           % (name, ["%.3f" % b for b in box]))
        checks(server.alive(), "the server is still running")


if __name__ == "__main__":
    import tempfile
    turned = rotation(30, (1, 2, 3))
    mirrored = turned @ numpy.diag([-1.0, 1.0, 1.0])
    directions = [("axis-aligned", numpy.eye(3)), ("turned", turned), ("mirrored", mirrored)]
    with tempfile.TemporaryDirectory() as folder:
        files = []
        for name, direction in directions:
            path = os.path.join(folder, "%s.nii" % name)
            write_nifti(path, ball(), direction)
            files.append(path)
        server = webserver.Server(files)
        asyncio.run(main(server, folder, directions))
        checks.finish(server)
