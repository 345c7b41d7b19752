"""The web client's server: the page, each volume once, and the operations that need the server.

    pvpython --no-mpi Python/serve.py --plugin build/.../MedicalIsosurfaces.so --wasm build-web/bin \\
        [--data FILE_OR_DICOM_DIR ...] [--port 8765] [--host 127.0.0.1] [--token TOKEN]

Run by Scripts/serve.sh, which installs and builds what is needed first. Opens the volumes with
ParaView's readers, prints the page's URL (with the session's token) and serves it with aiohttp
(docs/web.md has the API). Without --data: the fetched head CT, or the plugin's MedicalPhantom
when the CT is not there.
"""
import argparse
import asyncio
import gzip
import json
import os
import secrets
import sys

from aiohttp import web

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
STATIC = os.path.join(ROOT, "Web", "static")
TYPES = {"char": "int8", "signed char": "int8", "unsigned char": "uint8", "short": "int16",
         "unsigned short": "uint16", "int": "int32", "unsigned int": "uint32", "float": "float32",
         "double": "float64"}


def log(message):
    print("serve: " + message, flush=True)


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--data", action="append", default=[],
                   help="a volume file (MetaImage, VTK XML image, NIfTI) or a DICOM series folder")
    p.add_argument("--port", type=int, default=8765)
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (default 127.0.0.1: this machine only)")
    p.add_argument("--token", default="", help="the session's token (default: a random one)")
    p.add_argument("--plugin", required=True, help="MedicalIsosurfaces.so")
    p.add_argument("--wasm", default=os.path.join(ROOT, "build-web", "bin"),
                   help="folder of mediso.js and mediso.wasm")
    return p.parse_args(argv)


class Dataset:
    """A volume the server opened: its values and where they lie."""

    def __init__(self, ident, name, image):
        from vtkmodules.util.numpy_support import vtk_to_numpy
        scalars = image.GetPointData().GetScalars()
        if scalars is None or scalars.GetNumberOfComponents() != 1:
            raise ValueError("%s has no single-component point scalars" % name)
        self.ident = ident
        self.name = name
        self.dims = list(image.GetDimensions())
        self.spacing = list(image.GetSpacing())
        self.origin = list(image.GetOrigin())
        matrix = image.GetDirectionMatrix()
        self.direction = [matrix.GetElement(r, c) for r in range(3) for c in range(3)]
        self.type = TYPES.get(scalars.GetDataTypeAsString())
        if self.type is None:
            raise ValueError("%s: %s values are not supported" % (name, scalars.GetDataTypeAsString()))
        values = vtk_to_numpy(scalars)
        self.values = values.reshape(self.dims[2], self.dims[1], self.dims[0])
        lo, hi = scalars.GetRange()
        self.range = [float(lo), float(hi)]
        self.encoded = {}  # level -> gzip'd shuffled bytes

    def level(self, k):
        """Level k's values: every 2^(3-k)-th point along each axis."""
        step = 1 << (3 - k)
        return self.values[::step, ::step, ::step]

    def describe(self):
        levels = []
        for k in range(4):
            v = self.level(k)
            step = 1 << (3 - k)
            levels.append({"dims": [v.shape[2], v.shape[1], v.shape[0]],
                           "spacing": [s * step for s in self.spacing], "bytes": int(v.nbytes)})
        return {"id": self.ident, "name": self.name, "dims": self.dims, "spacing": self.spacing,
                "origin": self.origin, "direction": self.direction, "type": self.type,
                "range": self.range, "bytes": int(self.values.nbytes), "levels": levels}

    def encode(self, k):
        """Level k byte-shuffled and gzip'd (made once)."""
        import numpy
        if k not in self.encoded:
            v = numpy.ascontiguousarray(self.level(k))
            size = v.dtype.itemsize
            planes = v.view(numpy.uint8).reshape(-1, size).T  # byte b of every value, in a row
            self.encoded[k] = gzip.compress(numpy.ascontiguousarray(planes).tobytes(), 6)
        return self.encoded[k]


def open_datasets(paths):
    import paraview.simple as simple
    from paraview import servermanager
    datasets = []
    sources = paths or []
    if not sources:
        ct = os.path.join(os.environ.get("MEDISO_DATA_DIR") or
                          os.path.expanduser("~/.cache/medical-isosurfaces"), "ct_head.mha")
        sources = [ct] if os.path.isfile(ct) else []
    for path in sources:
        name = os.path.basename(os.path.normpath(path))
        if os.path.isdir(path):
            reader = simple.DICOMReaderdirectory(FileName=path)
        else:
            reader = simple.OpenDataFile(path)
        if reader is None:
            raise SystemExit("serve: ParaView has no reader for %s" % path)
        reader.UpdatePipeline()
        image = servermanager.Fetch(reader)
        datasets.append(Dataset("d%d" % len(datasets), name, image))
    if not datasets:
        log("the head CT is not fetched (python3 Python/fetch_data.py): serving the phantom")
        phantom = simple.MedicalPhantom(Dimensions=[192, 192, 192], Spacing=[1.0, 1.0, 1.0])
        phantom.UpdatePipeline()
        datasets.append(Dataset("d0", "MedicalPhantom 192^3", servermanager.Fetch(phantom)))
    for d in datasets:
        log("%s: %s, %s %s, range %g..%g" % (d.ident, d.name, "x".join(map(str, d.dims)), d.type,
                                             d.range[0], d.range[1]))
    return datasets


def make_app(args, datasets):
    token = args.token
    by_id = {d.ident: d for d in datasets}
    wasm_files = {"mediso.js", "mediso.wasm", "mediso-mt.js", "mediso-mt.wasm", "mediso-mt.worker.js"}

    @web.middleware
    async def authenticate(request, handler):
        given = request.query.get("token") or request.cookies.get("mediso_token")
        if not given or not secrets.compare_digest(given, token):
            return web.Response(status=403, text="403: this server needs the token of its URL\n")
        response = await handler(request)
        if request.query.get("token"):
            response.set_cookie("mediso_token", token, httponly=True, samesite="Strict")
        # Cross-origin isolation: the page may then use threads (SharedArrayBuffer).
        response.headers["Cross-Origin-Opener-Policy"] = "same-origin"
        response.headers["Cross-Origin-Embedder-Policy"] = "require-corp"
        return response

    async def index(request):
        return web.FileResponse(os.path.join(STATIC, "index.html"))

    async def static(request):
        name = request.match_info["name"]
        if name in wasm_files:
            path = os.path.join(args.wasm, name)
        elif name in os.listdir(STATIC):
            path = os.path.join(STATIC, name)
        else:
            raise web.HTTPNotFound()
        if not os.path.isfile(path):
            raise web.HTTPNotFound(text="%s is not built: run Scripts/build-web.sh\n" % name)
        return web.FileResponse(path)

    async def list_datasets(request):
        return web.json_response({"datasets": [d.describe() for d in datasets]})

    async def volume(request):
        d = by_id.get(request.match_info["ident"])
        if d is None:
            raise web.HTTPNotFound(text="no such dataset\n")
        try:
            k = int(request.query.get("level", "3"))
        except ValueError:
            k = -1
        if not 0 <= k <= 3:
            raise web.HTTPBadRequest(text="level is 0, 1, 2 or 3\n")
        body = await asyncio.get_running_loop().run_in_executor(None, d.encode, k)
        level = d.describe()["levels"][k]
        headers = {"Content-Encoding": "gzip", "Content-Type": "application/octet-stream",
                   "X-Mediso-Dims": ",".join(map(str, level["dims"])),
                   "X-Mediso-Spacing": ",".join(repr(s) for s in level["spacing"]),
                   "X-Mediso-Origin": ",".join(repr(s) for s in d.origin),
                   "X-Mediso-Type": d.type, "X-Mediso-Raw-Bytes": str(level["bytes"]),
                   "Cache-Control": "no-store"}
        return web.Response(body=body, headers=headers)

    app = web.Application(middlewares=[authenticate], client_max_size=64 * 1024)
    app.router.add_get("/", index)
    app.router.add_get("/static/{name}", static)
    app.router.add_get("/api/datasets", list_datasets)
    app.router.add_get("/api/volume/{ident}", volume)
    return app


def main(argv):
    args = parse_args(argv)
    import paraview.simple as simple
    simple.LoadPlugin(args.plugin, ns=globals())
    args.token = args.token or secrets.token_urlsafe(18)
    datasets = open_datasets(args.data)
    app = make_app(args, datasets)
    host = "[%s]" % args.host if ":" in args.host else args.host
    log("open http://%s:%d/?token=%s" % (host, args.port, args.token))
    web.run_app(app, host=args.host, port=args.port, print=None, access_log=None)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
