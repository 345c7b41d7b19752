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
  GET /api/bricks/<id>?level=k&ids=3,4,9    those bricks' owned points, each x fastest and
                                            encoded on its own (below), one after the other in
                                            the order asked, gzip'd (one gzip stream: the page
                                            finds each brick by its owned bytes, the manifest's);
                                            kept by the browser and revalidated (ETag) like
                                            /api/volume
  GET /api/bricks/<id>?level=k&need=v,w     the bricks each isovalue needs (JSON), exactly:
                                            those holding the points that the cells and
                                            gradients of the core's blocks crossing it read

A brick is encoded before gzip as a scan's values compress best: integer values go through the
level's predictor (named by a brick answer's X-Mediso-Predictor: "xyz", the 3D Lorenzo
predictor, i.e. the first difference along x, then y, then z; "x", the first difference along x;
"none"), in the type's own width with wrap-around, each residual zigzag'd (0, -1, 1, -2, ...
become 0, 1, 2, 3, ...: small magnitudes in small unsigned numbers); then the brick's values are
byte-shuffled (all first bytes, then all second bytes, ...) and gzip'd. The page undoes it with
running sums (stream.js, decodeBrick). The 512-wide CT's bricks came to 0.56x its whole level's
bytes this way, where shuffling alone gave 0.94x; on white noise a difference only spreads the
noise, and a smooth volume's values repeat patterns that gzip's level 6 finds, so each level
chooses its encoding (ENCODINGS) on a sample of its bricks. Encoded bricks are kept (a brick is
encoded once per server), encoded in the background from the manifest on, the bricks a page's
isovalues need (its need query) first.

A request names several bricks (the page asks for 10-30 batches, not one request a brick: each
request costs the page a round of fetch, answer and hand-over). Its answer is made of the kept
encodings without compressing anything again: each brick is kept as raw deflate blocks ended by a
full flush (byte-aligned, no reference to earlier bytes), so the blocks of several bricks one
after the other are one valid deflate stream; the answer puts gzip's header before them and an
empty final block, the CRC-32 of the whole (each brick's kept CRC combined: crc32_combine) and
its length after them.
"""
import asyncio
import gzip
import math
import struct
import zlib

from aiohttp import web

from serve_messages import LEVEL_STRIDES
from serve_work import VOLUME_WORK

BRICK_POINTS = 64  # points a side of a brick: a multiple of BlockLOD's 8 (BrickGrid)
APRON = 1          # the page's gradients read one point more on each side
MAX_IDS = 4096     # bricks in one request
MAX_NEED = 16      # isovalues in one need query
BLOCK = 8          # BlockLOD's block: 8 cells a side (BlockCells)
ENCODING = "bricks-predict-zigzag-shuffle"  # part of a brick request's ETag, with the level's choice
# A level's encodings to choose from (predictor, gzip level, zlib strategy). Residuals are mostly
# runs of a few small numbers, which run-length matching (Z_RLE) codes as well as level 6's
# search does, in the time of level 1 (on the 512-wide CT's bricks: 0.89x level 6's bytes in 0.11x
# its time); unpredicted values of a smooth volume repeat long patterns, which need level 6.
ENCODINGS = {"xyz-rle": ("xyz", 1, zlib.Z_RLE), "x-rle": ("x", 1, zlib.Z_RLE),
             "none-6": ("none", 6, zlib.Z_DEFAULT_STRATEGY)}
PREDICTORS = ("xyz", "x", "none")
SAMPLE_BRICKS = 4  # bricks the level's encoding is chosen on


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


def residuals(brick, predictor):
    """The brick's (z, y, x) integer values as zigzag'd residuals of `predictor`, unsigned, in the
    type's width (wrap-around: the page's running sums undo it exactly)."""
    import numpy
    unsigned = numpy.dtype("u%d" % brick.dtype.itemsize)
    signed = numpy.dtype("i%d" % brick.dtype.itemsize)
    d = numpy.ascontiguousarray(brick).view(unsigned)
    for axis in {"xyz": (2, 1, 0), "x": (2,)}[predictor]:
        d = numpy.diff(d, axis=axis, prepend=numpy.zeros_like(d.take([0], axis=axis)))
    d = d.view(signed)
    bits = 8 * brick.dtype.itemsize
    return ((d << 1) ^ (d >> (bits - 1))).view(unsigned)


def encode_raw(brick, predictor):
    """One brick's owned points (a (z, y, x) array) as the page receives them before gzip: the
    predictor's zigzag'd residuals (integers; floats as they are), byte-shuffled."""
    import numpy
    values = brick if predictor == "none" or brick.dtype.kind == "f" else residuals(brick, predictor)
    size = values.dtype.itemsize
    planes = numpy.ascontiguousarray(values).reshape(-1).view(numpy.uint8).reshape(-1, size).T
    return numpy.ascontiguousarray(planes).tobytes()


def gzipped(raw, encoding):
    """`raw` gzip'd as ENCODINGS[encoding] says."""
    _, level, strategy = ENCODINGS[encoding]
    z = zlib.compressobj(level, zlib.DEFLATED, 16 + zlib.MAX_WBITS, 9, strategy)
    return z.compress(raw) + z.flush()


class Segment:
    """One brick's encoding as kept: `blocks`, raw deflate blocks ended by a full flush (so that
    segments put one after the other are one deflate stream), the CRC-32 and length of what they
    inflate to."""
    __slots__ = ("blocks", "crc", "length")

    def __init__(self, raw, encoding):
        _, level, strategy = ENCODINGS[encoding]
        z = zlib.compressobj(level, zlib.DEFLATED, -zlib.MAX_WBITS, 9, strategy)
        self.blocks = z.compress(raw) + z.flush(zlib.Z_FULL_FLUSH)
        self.crc = zlib.crc32(raw)
        self.length = len(raw)


def _gf2_times(matrix, vector):
    """A 32x32 matrix over GF(2) (its columns as ints) times a 32-bit vector."""
    out, column = 0, 0
    while vector:
        if vector & 1:
            out ^= matrix[column]
        vector >>= 1
        column += 1
    return out


_ZEROS = {}  # byte count -> the operator that appends that many zero bytes to a CRC register


def _zeros_operator(count):
    """The CRC-32 register's change by `count` zero bytes, as a matrix (kept: bricks have few
    lengths). zlib's crc32_combine, which Python's zlib does not expose, computes the same."""
    if count not in _ZEROS:
        step = [0xEDB88320] + [1 << n for n in range(31)]  # one zero bit
        for _ in range(3):  # one zero byte
            step = [_gf2_times(step, c) for c in step]
        result, n = None, count
        while n:
            if n & 1:
                result = step if result is None else [_gf2_times(step, c) for c in result]
            n >>= 1
            if n:
                step = [_gf2_times(step, c) for c in step]
        _ZEROS[count] = result
    return _ZEROS[count]


def crc32_combine(crc1, crc2, length2):
    """The CRC-32 of A + B from A's (`crc1`), B's (`crc2`) and B's length."""
    return _gf2_times(_zeros_operator(length2), crc1) ^ crc2 if length2 else crc1


_FINAL_BLOCK = zlib.compressobj(0, zlib.DEFLATED, -zlib.MAX_WBITS).flush()  # an empty last block


def joined(segments):
    """Segments (in the order asked) as one gzip stream: the header, their blocks, an empty final
    block, the CRC-32 and length of the whole (RFC 1952). Nothing is compressed again."""
    crc, length = 0, 0
    for segment in segments:
        crc = crc32_combine(crc, segment.crc, segment.length)
        length += segment.length
    return b"".join([b"\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\xff"] + [s.blocks for s in segments] +
                    [_FINAL_BLOCK, struct.pack("<II", crc, length & 0xFFFFFFFF)])


def choose_encoding(values, counts):
    """The encoding (an ENCODINGS key) whose bricks are smallest on up to SAMPLE_BRICKS bricks
    spread over the level (floating-point values are not predicted)."""
    names = ["none-6"] if values.dtype.kind == "f" else list(ENCODINGS)
    n = counts[0] * counts[1] * counts[2]
    step = max(1, n // SAMPLE_BRICKS)
    sample = [owned(values, counts, b) for b in range(step // 2, n, step)][:SAMPLE_BRICKS]
    sizes = {e: sum(len(gzipped(encode_raw(b, ENCODINGS[e][0]), e)) for b in sample) for e in names}
    return min(names, key=lambda e: sizes[e])


def encode(dataset, k, brick, encoding):
    """Brick `brick` of level k encoded (encode_raw) with the predictor of `encoding` (an
    ENCODINGS key) and deflated as a Segment."""
    values = dataset.level(k)
    counts = brick_counts(values.shape)
    return Segment(encode_raw(owned(values, counts, brick), ENCODINGS[encoding][0]), encoding)


def block_ranges(values):
    """The core's block ranges (ComputeBlockRanges): per block of 8 cells a side, (z, y, x)
    arrays of the least and greatest value over its points [8b, min(8b + 8, n - 1)] per axis,
    missing values (NaN, infinities) left out (NaN where a block has no other)."""
    import numpy
    lo = hi = values
    if values.dtype.kind == "f":
        lo = hi = numpy.where(numpy.isfinite(values), values, numpy.nan)
    for axis in (0, 1, 2):  # z first: the reductions over whole rows are the fast ones
        n = values.shape[axis]
        blocks = max(1, (n - 1 + BLOCK - 1) // BLOCK)
        # Points 8b .. 8b + 7 of each block as a chunk (the last point repeated where the axis
        # ends first: a clamped read), then each block's point 8b + 8, its next block's first.
        chunk = numpy.minimum(numpy.arange(BLOCK * blocks), n - 1)
        far = numpy.minimum(numpy.arange(1, blocks + 1) * BLOCK, n - 1)
        reduced = []
        for a, f in ((lo, numpy.fmin), (hi, numpy.fmax)):
            if BLOCK * blocks <= n:
                index = [slice(None)] * 3
                index[axis] = slice(0, BLOCK * blocks)
                part = a[tuple(index)]
            else:
                part = a.take(chunk, axis=axis)
            shape = list(part.shape)
            shape[axis:axis + 1] = [blocks, BLOCK]
            whole = f.reduce(part.reshape(shape), axis=axis + 1)
            reduced.append(f(whole, a.take(far, axis=axis)))
        lo, hi = reduced
    return lo, hi


def needed_bricks(blocks, shape, counts, v):
    """The bricks (ids, sorted) isovalue v needs at the full level: for every block whose range
    holds v (min < v <= max, the core's test), the bricks holding the points its cells and
    gradients read, 8b - 1 .. 8b + 9 along each axis (BlockLODVolume::RegionArrived's rule for
    a block's residency)."""
    import numpy
    lo, hi = blocks
    with numpy.errstate(invalid="ignore"):
        active = numpy.nonzero((lo < v) & (v <= hi))
    if not active[0].size:
        return []
    ends = []  # per axis x, y, z: the bricks of the first and last point read
    for axis, b in ((2, active[2]), (1, active[1]), (0, active[0])):
        n = shape[axis]
        ends.append((numpy.maximum(0, BLOCK * b - 1) // BRICK_POINTS,
                     numpy.minimum(n - 1, BLOCK * b + BLOCK + 1) // BRICK_POINTS))
    ids = [x + counts[0] * (y + counts[1] * z) for x in ends[0] for y in ends[1] for z in ends[2]]
    return numpy.unique(numpy.concatenate(ids)).tolist()


def parse_need(text):
    """The isovalues of a need query: 1 to MAX_NEED finite numbers; else 400."""
    try:
        values = [float(t) for t in text.split(",")]
    except ValueError:
        values = []
    if not 1 <= len(values) <= MAX_NEED or not all(math.isfinite(v) for v in values):
        raise web.HTTPBadRequest(text="need: 1 to %d finite isovalues, comma-separated\n" % MAX_NEED)
    return values


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


class Encoder:
    """A level's bricks encoded once each (Segments, joined into any request's answer), kept for
    the server's life; ENCODE_AHEAD tasks encode them in the background, the bricks a need query
    named first, then the rest in id order, so that a page's next request finds its brick ready.
    The level's encoding is chosen first, off the event loop, once."""
    ENCODE_AHEAD = 2

    def __init__(self, dataset, k, counts):
        loop = asyncio.get_running_loop()
        self.dataset, self.k = dataset, k
        self.encoding = loop.run_in_executor(
            VOLUME_WORK, lambda: choose_encoding(dataset.level(k), counts))
        self.bodies = {}  # id -> task of its Segment
        self.queue = list(range(counts[0] * counts[1] * counts[2]))[::-1]  # popped from the end
        self.tasks = [asyncio.ensure_future(self.ahead()) for _ in range(self.ENCODE_AHEAD)]

    async def encode(self, brick):
        encoding = await asyncio.shield(self.encoding)
        return await asyncio.get_running_loop().run_in_executor(
            VOLUME_WORK, encode, self.dataset, self.k, brick, encoding)

    def body(self, brick):
        if brick not in self.bodies:
            self.bodies[brick] = asyncio.ensure_future(self.encode(brick))
        return self.bodies[brick]

    def first(self, ids):
        """Bricks `ids` go to the front of the background's queue."""
        front = set(ids)
        self.queue = ([b for b in self.queue if b not in front] +
                      [b for b in ids[::-1] if b not in self.bodies])

    async def ahead(self):
        while self.queue:
            brick = self.queue.pop()
            if brick not in self.bodies:
                try:
                    await self.body(brick)
                except Exception:  # said to the request that asks for it
                    pass


def handler(find, not_modified, cache_control):
    """The route's handler; `find(request)` gives the request's dataset or None. Bricks are kept
    by the browser and revalidated like /api/volume (docs/web.md, Caching): `not_modified(request,
    etag, modified)` and `cache_control` are serve.py's; the ETag is the dataset's fingerprint,
    the level, the ids and the encoding, so a page that asks for one brick a request finds each
    again after a reload."""
    manifests = {}  # (dataset id, level) -> future of the manifest
    fingerprints = {}  # dataset id -> future of its fingerprint
    blocks = {}  # (dataset id, level) -> future of the core's block ranges
    encoders = {}  # (dataset id, level) -> Encoder

    def prepared(d, k):
        """The future of level k's manifest of dataset d (made once, off the event loop)."""
        key = (d.ident, k)
        if key not in manifests:
            manifests[key] = asyncio.get_running_loop().run_in_executor(
                VOLUME_WORK, manifest, d, k)
        return manifests[key]

    async def bricks(request):
        d = find(request)
        k = requested_level(request, d)
        loop = asyncio.get_running_loop()
        key = (d.ident, k)
        m = await asyncio.shield(prepared(d, k))
        if key not in encoders:  # for the requests that follow the manifest, while level 0 goes
            blocks[key] = loop.run_in_executor(VOLUME_WORK, lambda: block_ranges(d.level(k)))
            encoders[key] = Encoder(d, k, m["bricks"])
        if "ids" not in request.query and "need" not in request.query:
            return web.json_response(m, headers={"Cache-Control": "no-store"})
        if "need" in request.query:
            values = parse_need(request.query["need"])
            ranges = await asyncio.shield(blocks[key])
            shape = d.level(k).shape
            need = [needed_bricks(ranges, shape, m["bricks"], v) for v in values]
            encoders[key].first([b for ids in need for b in ids])
            return web.json_response({"level": k, "need": need}, headers={"Cache-Control": "no-store"})
        ids = parse_ids(request.query["ids"], len(m["ranges"]))
        if d.ident not in fingerprints:
            fingerprints[d.ident] = loop.run_in_executor(VOLUME_WORK, d.fingerprint)
        digest = await asyncio.shield(fingerprints[d.ident])
        encoding = await asyncio.shield(encoders[key].encoding)
        validators = {"ETag": '"%s-%d-b%s-%s-%s"' % (digest, k, "_".join(map(str, ids)), ENCODING,
                                                    encoding),
                      "Cache-Control": cache_control}
        if not_modified(request, validators["ETag"], d.modified):
            return web.Response(status=304, headers=validators)
        encoder = encoders[key]
        body = joined(await asyncio.gather(*(asyncio.shield(encoder.body(b)) for b in ids)))
        return web.Response(body=body, headers=dict(validators, **{
            "Content-Encoding": "gzip", "Content-Type": "application/octet-stream",
            "X-Mediso-Type": d.type, "X-Mediso-Predictor": ENCODINGS[encoding][0],
            "X-Mediso-Bricks": ",".join(map(str, ids))}))

    bricks.prepare = prepared  # the server's start makes the manifest a first page asks for
    return bricks
