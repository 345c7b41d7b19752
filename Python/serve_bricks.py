"""The server's bricks (docs/web.md, Streaming): a level of a volume as disjoint bricks that the
page fetches a few at a time, the ones the current isovalues need first.

The bricks are the cores' (Filters/Core/BrickGrid.h): brick b along an axis owns the points
[b B, min((b + 1) B, n) - 1] of the level's lattice (B = BRICK_POINTS, a multiple of BlockLOD's 8
so that bricks hold whole blocks); a brick's cells read its owned points grown by 1 on the + side,
and the page's gradients APRON more on each side. The manifest states B once (the page reads it
and passes it to the module) and each brick's value range over those read points, computed here
with numpy as ComputeBrickRanges computes it (TestWebServerBricks compares the two). A brick
crosses an isovalue v when min < v <= max. What travels is each brick's owned points only: every
point once.

  GET /api/bricks/<id>?level=k             the manifest (JSON)
  GET /api/bricks/<id>?level=k&ids=3,4,9    those bricks' owned points, each x fastest, one
                                            after the other in the order asked, byte-shuffled
                                            together like /api/volume and gzip'd; kept by the
                                            browser and revalidated (ETag) like /api/volume
"""
import asyncio
import gzip

from aiohttp import web

from serve_messages import LEVEL_STRIDES

BRICK_POINTS = 64  # points a side of a brick: a multiple of BlockLOD's 8 (BrickGrid)
APRON = 1          # the page's gradients read one point more on each side
MAX_IDS = 4096     # bricks in one request
ENCODING = "bricks-shuffle-gzip6"  # part of a brick request's ETag


def brick_counts(shape):
    """Bricks along x, y, z of a level of shape (z, y, x)."""
    return [(n + BRICK_POINTS - 1) // BRICK_POINTS for n in (shape[2], shape[1], shape[0])]


def owned(values, counts, brick):
    """The owned points of brick id `brick` (x fastest), as a (z, y, x) view of `values`."""
    bx = brick % counts[0]
    by = (brick // counts[0]) % counts[1]
    bz = brick // (counts[0] * counts[1])
    b = BRICK_POINTS
    return values[bz * b:(bz + 1) * b, by * b:(by + 1) * b, bx * b:(bx + 1) * b]


def brick_ranges(values):
    """Per brick (x fastest), [min, max] over its read points (owned, + 1 on the + side, APRON
    more on each side, clamped), NaN left out; None for a brick that reads no number."""
    import numpy
    counts = brick_counts(values.shape)
    floating = values.dtype.kind == "f"
    out = []
    b = BRICK_POINTS
    for bz in range(counts[2]):
        z0, z1 = max(0, bz * b - APRON), (bz + 1) * b + 1 + APRON
        for by in range(counts[1]):
            y0, y1 = max(0, by * b - APRON), (by + 1) * b + 1 + APRON
            for bx in range(counts[0]):
                x0, x1 = max(0, bx * b - APRON), (bx + 1) * b + 1 + APRON
                read = values[z0:z1, y0:y1, x0:x1]
                if floating:
                    read = read[~numpy.isnan(read)]
                    if read.size == 0:
                        out.append(None)
                        continue
                lo, hi = read.min(), read.max()
                out.append([lo.item(), hi.item()])
    return out


def manifest(dataset, k):
    """What the page needs before the bricks: the brick size (stated once, here), the bricks per
    axis, each brick's range and owned bytes."""
    values = dataset.level(k)
    counts = brick_counts(values.shape)
    size = values.dtype.itemsize
    sizes = []
    for brick in range(counts[0] * counts[1] * counts[2]):
        sizes.append(int(owned(values, counts, brick).size * size))
    return {"level": k, "dims": [values.shape[2], values.shape[1], values.shape[0]],
            "type": dataset.type, "brick": BRICK_POINTS, "apron": APRON, "bricks": counts,
            "ranges": brick_ranges(values), "bytes": sizes}


def encode(dataset, k, ids):
    """Bricks `ids` of level k: their owned points one brick after the other (each x fastest),
    byte-shuffled together as /api/volume shuffles a level (all the first bytes, then all the
    second bytes, ...: a brick's own planes would be too short for gzip), gzip'd (level 6)."""
    import numpy
    values = dataset.level(k)
    counts = brick_counts(values.shape)
    joined = numpy.concatenate([owned(values, counts, brick).ravel() for brick in ids])
    size = joined.dtype.itemsize
    planes = joined.view(numpy.uint8).reshape(-1, size).T
    return gzip.compress(numpy.ascontiguousarray(planes).tobytes(), 6)


def parse_ids(text, count):
    """The ids of a request: distinct integers in [0, count), at most MAX_IDS; else BadIds."""
    try:
        ids = [int(t) for t in text.split(",")]
    except ValueError:
        raise web.HTTPBadRequest(text="ids: a comma-separated list of brick numbers\n")
    if not ids or len(ids) > MAX_IDS:
        raise web.HTTPBadRequest(text="ids: 1 to %d bricks a request\n" % MAX_IDS)
    if len(set(ids)) != len(ids) or min(ids) < 0 or max(ids) >= count:
        raise web.HTTPBadRequest(text="ids: distinct bricks from 0 to %d\n" % (count - 1))
    return ids


def requested_level(request, d):
    """The level a GET of dataset `d` asks for ("level", 3 when left out), shared by /api/volume
    and /api/bricks: 404 where `d` is None, 400 where the level is not 0-3."""
    if d is None:
        raise web.HTTPNotFound(text="no such dataset\n")
    try:
        k = int(request.query.get("level", "3"))
    except ValueError:
        k = -1
    if not 0 <= k < len(LEVEL_STRIDES):
        raise web.HTTPBadRequest(text="level is 0, 1, 2 or 3\n")
    return k


def handler(find, not_modified, cache_control):
    """The route's handler; `find(request)` gives the request's dataset or None. Bricks are kept
    by the browser and revalidated like /api/volume (docs/web.md, Caching): `not_modified(request,
    etag, modified)` and `cache_control` are serve.py's; the ETag is the dataset's fingerprint,
    the level, the ids and the encoding, so a page that asks for one brick a request finds each
    again after a reload."""
    manifests = {}  # (dataset id, level) -> future of the manifest
    fingerprints = {}  # dataset id -> future of its fingerprint

    def prepared(d, k):
        """The future of level k's manifest of dataset d (made once, off the event loop)."""
        key = (d.ident, k)
        if key not in manifests:
            manifests[key] = asyncio.get_running_loop().run_in_executor(None, manifest, d, k)
        return manifests[key]

    async def bricks(request):
        d = find(request)
        k = requested_level(request, d)
        loop = asyncio.get_running_loop()
        m = await asyncio.shield(prepared(d, k))
        if "ids" not in request.query:
            return web.json_response(m, headers={"Cache-Control": "no-store"})
        ids = parse_ids(request.query["ids"], len(m["ranges"]))
        if d.ident not in fingerprints:
            fingerprints[d.ident] = loop.run_in_executor(None, d.fingerprint)
        digest = await asyncio.shield(fingerprints[d.ident])
        validators = {"ETag": '"%s-%d-b%s-%s"' % (digest, k, "_".join(map(str, ids)), ENCODING),
                      "Cache-Control": cache_control}
        if not_modified(request, validators["ETag"], d.modified):
            return web.Response(status=304, headers=validators)
        body = await loop.run_in_executor(None, encode, d, k, ids)
        return web.Response(body=body, headers=dict(validators, **{
            "Content-Encoding": "gzip", "Content-Type": "application/octet-stream",
            "X-Mediso-Type": d.type, "X-Mediso-Bricks": ",".join(map(str, ids))}))

    bricks.prepare = prepared  # the server's start makes the manifest a first page asks for
    return bricks
