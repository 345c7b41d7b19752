"""pvpython test: the web server's levels follow the C++ BlockLOD core's level rule.

The server states the levels' strides in one constant (serve_messages.LEVEL_STRIDES, the C++'s
mediso::LevelStride). On a phantom of 65^3 points (64 cells: every stride divides it, so the C++'s
coarse copy has no extra last point, the one difference the server names) each level k that
/api/volume sends, contoured here with vtkFlyingEdges3D at its spacing, must give exactly the
triangles and points of the plugin's BlockLODContour at LOD k on the full phantom, and
/api/datasets must describe it (dims, spacing, bytes). A server whose rule drifted from the C++'s
fails here.
"""
import asyncio
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import webserver  # noqa: E402  (skips when aiohttp or the plugin is missing)
import aiohttp  # noqa: E402
import numpy  # noqa: E402

N = 65
EXTENT_MM = 192.0   # the server's phantom:N spans this (serve_operations.PHANTOM_EXTENT_MM)
ISO = 400.0         # the phantom's bone
checks = webserver.Checks()
server = webserver.Server(["phantom:%d" % N])


def blocklod_counts():
    """(triangles, points) of BlockLODContour at each level on the same phantom, in this process."""
    import paraview.simple as simple
    ns = {"__name__": "reference"}
    simple.LoadPlugin(webserver.PLUGIN, ns=ns)
    phantom = ns["MedicalPhantom"](Dimensions=[N] * 3, Spacing=[EXTENT_MM / N] * 3)
    counts = []
    for level in range(4):
        contour = ns["BlockLODContour"](Input=phantom, Isosurfaces=[ISO], LOD=level, AutoLOD=0,
                                        ComputeNormals=0)
        contour.UpdatePipeline()
        info = contour.GetDataInformation()
        counts.append((info.GetNumberOfCells(), info.GetNumberOfPoints()))
    return counts


def flying_edges(values, spacing, origin):
    """(triangles, points) of vtkFlyingEdges3D at ISO on a (z, y, x) array."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D
    image = vtkImageData()
    image.SetDimensions(values.shape[2], values.shape[1], values.shape[0])
    image.SetSpacing(spacing)
    image.SetOrigin(origin)
    image.GetPointData().SetScalars(numpy_to_vtk(values.ravel(), deep=True))
    fe = vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.SetValue(0, ISO)
    fe.ComputeNormalsOff()
    fe.Update()
    return fe.GetOutput().GetNumberOfCells(), fe.GetOutput().GetNumberOfPoints()


async def main():
    expected = blocklod_counts()
    async with aiohttp.ClientSession(auto_decompress=False) as http:
        async with http.get(server.url("/api/datasets")) as r:
            d = (await r.json())["datasets"][0]
        checks(len(d["levels"]) == 4, "four levels described (%d)" % len(d["levels"]))
        dtype = numpy.dtype(d["type"])
        for k, level in enumerate(d["levels"]):
            stride = 8 >> k  # mediso::LevelStride
            points = (N - 1) // stride + 1
            checks(level["dims"] == [points] * 3 and
                   numpy.allclose(level["spacing"], [s * stride for s in d["spacing"]]) and
                   level["bytes"] == points ** 3 * dtype.itemsize,
                   "level %d: described as %s points, spacing %s, %d bytes (the C++'s stride %d)"
                   % (k, level["dims"], level["spacing"], level["bytes"], stride))
            async with http.get(server.url("/api/volume/%s?level=%d" % (d["id"], k))) as r:
                body = await r.read()
                dims = [int(n) for n in r.headers["X-Mediso-Dims"].split(",")]
            values = webserver.decode(body, dtype, dims[0] * dims[1] * dims[2])
            got = flying_edges(values.reshape(dims[2], dims[1], dims[0]), level["spacing"],
                               d["origin"])
            checks(got == expected[k] and got[0] > 0,
                   "level %d: the served volume's surface (%d triangles, %d points) is "
                   "BlockLODContour's at LOD %d (%d, %d)" % (k, got[0], got[1], k, *expected[k]))


asyncio.run(main())
checks.finish(server)
