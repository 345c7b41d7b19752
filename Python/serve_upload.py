# SPDX-License-Identifier: BSD-3-Clause
"""A local volume uploaded once for the server's operations (docs/web.md, Local files).

The page reads a dropped file itself (Web/static/local.js); the server's operations (smoothing,
hole filling, clipping, decimation, export) need the volume here. The page sends it once:

    POST /api/upload?token=T
    X-Mediso-Name (URI-encoded), X-Mediso-Dims (nx,ny,nz), X-Mediso-Spacing, X-Mediso-Origin,
    X-Mediso-Direction (9, row-major, columns = axes), X-Mediso-Type (SCALAR_TYPES),
    X-Mediso-Format ("NIfTI RAS", "MetaImage LPS")
    body: the values byte-shuffled and gzip'd, as /api/volume sends them

and gets {"id": "u1", "raw": raw bytes, "received": bytes on the wire}. The values are checked
(type, dims, the exact number of bytes, at most MAX_UPLOAD_BYTES either way, the gzip stream
decompressed no further than the bytes expected), written as a MetaImage into the worker's
folder and added to the worker's volumes (the worker starts again at the next operation, as
after a crash); the dataset is then known to the WebSocket's operations by its id. It is not
listed by /api/datasets: the page that sent it names it.
"""
import os
import zlib
from urllib.parse import unquote

from aiohttp import web

MAX_UPLOAD_BYTES = 1 << 30
TYPE_NAMES = {"int8": "MET_CHAR", "uint8": "MET_UCHAR", "int16": "MET_SHORT", "uint16": "MET_USHORT",
              "int32": "MET_INT", "uint32": "MET_UINT", "float32": "MET_FLOAT", "float64": "MET_DOUBLE"}


def _numbers(request, name, count):
    text = request.headers.get(name, "")
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != count or not all(v == v and abs(v) < 1e300 for v in values):
        raise web.HTTPBadRequest(text="%s: %d numbers are needed (got %r)\n" % (name, count, text))
    return values


def handler(state_key, dataset_class):
    """The /api/upload handler of serve.py's app (its state key and Dataset class)."""
    import numpy

    async def upload(request):
        state = request.app[state_key]
        type_name = request.headers.get("X-Mediso-Type", "")
        if type_name not in TYPE_NAMES:
            raise web.HTTPBadRequest(text="X-Mediso-Type: %r is not one of %s\n"
                                     % (type_name, ", ".join(TYPE_NAMES)))
        dims = _numbers(request, "X-Mediso-Dims", 3)
        if not all(d == int(d) and 1 <= d <= 65536 for d in dims) or min(dims) < 2:
            raise web.HTTPBadRequest(text="X-Mediso-Dims: %r is not a 3D volume\n" % dims)
        dims = [int(d) for d in dims]
        spacing = _numbers(request, "X-Mediso-Spacing", 3)
        if not all(s > 0 for s in spacing):
            raise web.HTTPBadRequest(text="X-Mediso-Spacing: must be positive\n")
        origin = _numbers(request, "X-Mediso-Origin", 3)
        direction = _numbers(request, "X-Mediso-Direction", 9)
        name, _, space = request.headers.get("X-Mediso-Format", "upload LPS").rpartition(" ")
        size = numpy.dtype(type_name).itemsize
        raw = dims[0] * dims[1] * dims[2] * size
        if raw > MAX_UPLOAD_BYTES or (request.content_length or 0) > MAX_UPLOAD_BYTES:
            raise web.HTTPRequestEntityTooLarge(max_size=MAX_UPLOAD_BYTES,
                                                actual_size=max(raw, request.content_length or 0))
        # The body read in chunks, decompressed no further than the bytes the header promises.
        inflate = zlib.decompressobj(16 + zlib.MAX_WBITS)
        out = bytearray()
        received = 0
        try:
            async for chunk in request.content.iter_chunked(1 << 20):
                received += len(chunk)
                if received > MAX_UPLOAD_BYTES:
                    raise web.HTTPRequestEntityTooLarge(max_size=MAX_UPLOAD_BYTES, actual_size=received)
                out += inflate.decompress(chunk, raw + 1 - len(out))
                if len(out) > raw:
                    break  # more than promised: what is left is never inflated
            else:
                out += inflate.flush(raw + 1 - len(out))
        except zlib.error as e:
            raise web.HTTPBadRequest(text="the body is not a gzip stream (%s)\n" % e)
        if len(out) > raw:
            raise web.HTTPBadRequest(text="the body inflates past the %d bytes of values of %s %s\n"
                                     % (raw, "x".join(map(str, dims)), type_name))
        if len(out) != raw:
            raise web.HTTPBadRequest(text="the body holds %d bytes of values, %d are needed for %s %s\n"
                                     % (len(out), raw, "x".join(map(str, dims)), type_name))
        planes = numpy.frombuffer(bytes(out), numpy.uint8).reshape(size, -1)
        values = numpy.ascontiguousarray(planes.T).view(type_name).reshape(dims[2], dims[1], dims[0])
        lo, hi = float(numpy.nanmin(values)), float(numpy.nanmax(values))
        if not lo < hi:
            raise web.HTTPBadRequest(text="its values span no range\n")

        operations = state.operations
        if operations.running is not None:
            # The worker is busy with a job on the volumes it has: it takes a new one when idle.
            raise web.HTTPServiceUnavailable(text="an operation is running; upload again when it ends\n")
        ident = "u%d" % (sum(1 for k in state.by_id if k.startswith("u")) + 1)
        path = os.path.join(operations.folder, "%s.mha" % ident)
        m = direction
        header = ("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
                  "CompressedData = False\nTransformMatrix = %s\nOffset = %s\nElementSpacing = %s\n"
                  "DimSize = %s\nElementType = %s\nElementDataFile = LOCAL\n"
                  % (" ".join(repr(v) for v in m), " ".join(repr(v) for v in origin),
                     " ".join(repr(v) for v in spacing), " ".join(map(str, dims)), TYPE_NAMES[type_name]))
        with open(path, "wb") as f:
            f.write(header.encode())
            f.write(values.astype(values.dtype.newbyteorder("<"), copy=False).tobytes())
        operations.specs.append(path)
        operations.index[ident] = len(operations.specs) - 1
        await operations.stop_worker()  # started again, with this volume, by the next job
        state.by_id[ident] = dataset_class(
            ident, unquote(request.headers.get("X-Mediso-Name", ident))[:200], dims, spacing, origin, direction,
            type_name, [lo, hi], values, {"name": name or "upload", "space": space or "LPS"})
        return web.json_response({"id": ident, "raw": raw, "received": received})

    return upload
