"""pvpython test: the web server opens each format it promises, and sends each volume exactly.

Writes one small volume per format with VTK (MetaImage int16, VTK XML image float32, NIfTI .nii
uint8 and .nii.gz int16, and a DICOM series when this tree has Python/write_dicom_series.py and
the plugin its DICOM series reader), serves them all with Python/serve.py, and checks for each:
/api/datasets gives its dimensions, spacing, type and range; /api/volume at levels 3 and 1,
un-gzipped and un-shuffled, is exactly the values written (every 2nd point at level 1); an
operation on it runs. On the head CT (when fetched) the volume travels in at most 0.6x its raw
bytes. Bad --data (no such file, a folder without DICOM files, a surface, a 2D image, a phantom
of size 1) and a port in use each stop the server with a message saying why.
"""
import asyncio
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import webserver  # noqa: E402  (skips when aiohttp or the plugin is missing)
import aiohttp  # noqa: E402
import numpy  # noqa: E402

checks = webserver.Checks()
DIMS = (45, 38, 31)
SPACING = (0.8, 0.9, 1.2)
ORIGIN = (10.0, -5.0, 3.0)
NUMPY = {"int16": numpy.int16, "uint8": numpy.uint8, "float32": numpy.float32,
         "int8": numpy.int8, "uint16": numpy.uint16, "int32": numpy.int32,
         "uint32": numpy.uint32, "float64": numpy.float64}


def volume(dtype):
    """A ball with a ramp, z-major (k, j, i), in dtype."""
    k, j, i = numpy.meshgrid(*(numpy.arange(n) for n in DIMS[::-1]), indexing="ij")
    r = numpy.sqrt(((i - 22) * SPACING[0]) ** 2 + ((j - 19) * SPACING[1]) ** 2 +
                   ((k - 15) * SPACING[2]) ** 2)
    v = 200.0 - 12.0 * r + 0.5 * i
    if dtype == numpy.uint8:
        v = numpy.clip(v, 0, 255)
    return v.astype(dtype)


def image(values):
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    im = vtkImageData()
    im.SetDimensions(values.shape[2], values.shape[1], values.shape[0])
    im.SetSpacing(SPACING)
    im.SetOrigin(ORIGIN)
    array = numpy_to_vtk(values.ravel(), deep=True)
    array.SetName("values")
    im.GetPointData().SetScalars(array)
    return im


def write(folder):
    """[(path, values, exact geometry?)] of the volumes written."""
    from vtkmodules.vtkIOImage import vtkMetaImageWriter, vtkNIFTIImageWriter
    from vtkmodules.vtkIOXML import vtkXMLImageDataWriter
    written = []
    for name, dtype, writer, exact in (("ball.mha", numpy.int16, vtkMetaImageWriter, True),
                                       ("ball.vti", numpy.float32, vtkXMLImageDataWriter, True),
                                       ("ball.nii", numpy.uint8, vtkNIFTIImageWriter, False),
                                       ("ball.nii.gz", numpy.int16, vtkNIFTIImageWriter, False)):
        values = volume(dtype)
        path = os.path.join(folder, name)
        w = writer()
        w.SetFileName(path)
        w.SetInputData(image(values))
        w.Write()
        written.append((path, values, exact))
    plain = os.path.join(folder, "plain.mha")  # the DICOM writer reads uncompressed MetaImage
    w = vtkMetaImageWriter()
    w.SetFileName(plain)
    w.SetCompression(False)
    w.SetInputData(image(written[0][1]))
    w.Write()
    dicom = dicom_series(folder, plain)
    if dicom:
        written.append((dicom, written[0][1], False))
    return written


def dicom_series(folder, mha):
    """A DICOM series of the MetaImage, when this tree can write and read one; else None."""
    script = os.path.join(webserver.ROOT, "Python", "write_dicom_series.py")
    import paraview.simple as simple
    ns = {"__name__": "probe"}
    simple.LoadPlugin(webserver.PLUGIN, ns=ns)
    if not os.path.isfile(script) or "MedicalDICOMSeriesReader" not in ns:
        print("note: no DICOM series here (needs Python/write_dicom_series.py and the plugin's "
              "MedicalDICOMSeriesReader, from the gui branch): the folder case is not run")
        return None
    out = os.path.join(folder, "dicom")
    run = subprocess.run(["python3", script, "--mha", mha, "--out", out], capture_output=True,
                         text=True)
    if run.returncode != 0:
        print("note: write_dicom_series.py could not write the series (%s): the folder case "
              "is not run" % (run.stdout + run.stderr).strip()[-200:])
        return None
    return out


async def served(server, written):
    async with aiohttp.ClientSession(auto_decompress=False) as http:
        async with http.get(server.url("/api/datasets")) as r:
            datasets = (await r.json())["datasets"]
        checks(len(datasets) == len(written), "%d datasets served" % len(datasets))
        for d, (path, values, exact) in zip(datasets, written):
            name = os.path.basename(path)
            checks(d["dims"] == list(DIMS), "%s: dims %s" % (name, d["dims"]))
            checks(numpy.allclose(d["spacing"], SPACING, rtol=1e-5), "%s: spacing %s"
                   % (name, d["spacing"]))
            if exact:
                checks(numpy.allclose(d["origin"], ORIGIN), "%s: origin %s" % (name, d["origin"]))
                checks(NUMPY[d["type"]] == values.dtype, "%s: type %s" % (name, d["type"]))
            checks(d["range"] == [float(values.min()), float(values.max())],
                   "%s: range %s" % (name, d["range"]))
            for level in (3, 1):
                async with http.get(server.url("/api/volume/%s?level=%d" % (d["id"], level))) as r:
                    body = await r.read()
                    dims = [int(n) for n in r.headers["X-Mediso-Dims"].split(",")]
                step = 1 << (3 - level)
                expected = values[::step, ::step, ::step]
                got = webserver.decode(body, NUMPY[d["type"]], expected.size)
                checks(dims == list(expected.shape[::-1]) and
                       numpy.array_equal(got.astype(numpy.float64),
                                         expected.ravel().astype(numpy.float64)),
                       "%s: level %d is the %s values written (%d bytes for %d raw)"
                       % (name, level, "x".join(map(str, dims)), len(body), expected.nbytes))
        async with http.ws_connect(server.ws_url()) as ws:
            for i, d in enumerate(datasets):
                mid = (d["range"][0] + d["range"][1]) / 2
                _, answer = await webserver.operation(ws, webserver.surface_request(
                    i, d["id"], mid, 3, [{"smooth": {"iterations": 5}}]))
                checks(answer.get("done") is True and answer["triangles"] > 0,
                       "%s: an operation at its mid-range isovalue: %s triangles"
                       % (d["name"], answer.get("triangles", answer.get("error"))))


async def compression(server):
    async with aiohttp.ClientSession(auto_decompress=False) as http:
        async with http.get(server.url("/api/volume/d0?level=3")) as r:
            body = await r.read()
            raw = int(r.headers["X-Mediso-Raw-Bytes"])
    checks(len(body) <= 0.6 * raw, "the head CT travels in %d bytes, %.3fx its %d raw bytes "
           "(at most 0.6x)" % (len(body), len(body) / raw, raw))


def refused(data, words, extra=()):
    command = [webserver.PVPYTHON, "--no-mpi", webserver.SERVE, "--plugin", webserver.PLUGIN,
               "--port", str(webserver.free_port())] + list(extra)
    for d in data:
        command += ["--data", d]
    run = subprocess.run(command, capture_output=True, text=True, timeout=120,
                         stdin=subprocess.DEVNULL)
    text = (run.stdout + run.stderr).strip()
    checks(run.returncode != 0 and words in text and "Traceback" not in text,
           "--data %s: exit %d, %r" % (" ".join(data), run.returncode, text.splitlines()[-1:]))


def bad_input(folder, written):
    from vtkmodules.vtkFiltersSources import vtkSphereSource
    from vtkmodules.vtkIOXML import vtkXMLImageDataWriter, vtkXMLPolyDataWriter
    refused([os.path.join(folder, "missing.mha")], "no such file or folder")
    empty = os.path.join(folder, "empty")
    os.mkdir(empty)
    with open(os.path.join(empty, "notes.txt"), "w") as f:
        f.write("not DICOM")
    refused([empty], "holds no DICOM files")
    sphere = vtkSphereSource()
    sphere.Update()
    surface = os.path.join(folder, "sphere.vtp")
    w = vtkXMLPolyDataWriter()
    w.SetFileName(surface)
    w.SetInputData(sphere.GetOutput())
    w.Write()
    refused([surface], "not a 3D image")
    flat = os.path.join(folder, "flat.vti")
    w = vtkXMLImageDataWriter()
    w.SetFileName(flat)
    w.SetInputData(image(volume(numpy.int16)[:1]))
    w.Write()
    refused([flat], "is not a 3D volume")
    refused(["phantom:1"], "the phantom's size is an integer 2-1024")
    server = webserver.Server([written[0][0]])
    refused([written[0][0]], "cannot listen on 127.0.0.1:%d: Address already in use" % server.port,
            ["--port", str(server.port)])
    return server


def main():
    with tempfile.TemporaryDirectory() as folder:
        written = write(folder)
        server = webserver.Server([path for path, _, _ in written])
        asyncio.run(served(server, written))
        servers = [server, bad_input(folder, written)]
        ct = webserver.data_cache() / "ct_head.mha"
        if ct.is_file():
            servers.append(webserver.Server([str(ct)]))
            asyncio.run(compression(servers[-1]))
        else:
            print("note: the head CT is not fetched (python3 Python/fetch_data.py): its "
                  "compression is not measured")
        checks.finish(*servers)


main()
