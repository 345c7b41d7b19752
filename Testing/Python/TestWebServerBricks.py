"""pvpython test: the server's bricks (docs/web.md, Streaming; Python/serve_bricks.py).

On the phantom at 77^3 points (bricks of 64: 2 per axis, the last ones partial) and at level 2
(39^3): the manifest states the brick size, the bricks per axis, each brick's owned bytes and its
range over its read points (owned, + 1 on the + side, the apron on each side) equal to a brute
force here; the bricks, fetched in batches in an order that is not the volume's and decoded here
(each brick byte-shuffled on its own, its integer values the zigzag'd residuals of the predictor
the answer names, undone by running sums), put back together, are the level's values exactly,
every point sent once; their bytes on the wire, with level 0's, are at most 1.05x the whole
level's from /api/volume (1.10x at level 3, where 13 of the 77 points per axis are a partial
brick); a need query answers, for each isovalue, exactly the bricks holding the points that the
core's blocks crossing it read (a brute force over the blocks here), a subset of the page's
superset (the bricks whose range holds it and their neighbours); a batch of bricks is their
single answers joined (values, order, bytes no more); bad requests (a batch that repeats a brick,
ids out of range or not integers) get 400, a wrong token 403. The same server opens
phantom:77:noise=40 (serve_operations.phantom_spec): its values are the noiseless phantom's plus
noise of about 40 HU, and its bricks decode to them. On
the head CT (when Python/fetch_data.py has fetched it), the bricks and level 0 are at most 1.05x
its whole level on the wire. The ranges against the C++ core's ComputeBrickRanges, and the
surfaces drawn from the needed bricks against the dense ones, are checked in Chromium
(TestWebServerPageStream), where the module is.
"""
import asyncio
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import webserver  # noqa: E402  (skips when aiohttp or the plugin is missing)
import aiohttp  # noqa: E402
import numpy  # noqa: E402

N = 77
checks = webserver.Checks()
NOISE = 40
server = webserver.Server(["phantom:%d" % N, "phantom:%d:noise=%d" % (N, NOISE)])
PREDICTORS = ("xyz", "x", "none")


def decode_bricks(body, dtype, boxes, predictor):
    """The owned points of each brick of a /api/bricks answer ((z, y, x) shapes `boxes`, in the
    order asked): gunzip, then per brick unshuffle, unzigzag and running sums in the type's width."""
    import gzip
    raw = gzip.decompress(body)
    size = dtype.itemsize
    unsigned = numpy.dtype("u%d" % size)
    out, offset = [], 0
    for shape in boxes:
        count = shape[0] * shape[1] * shape[2]
        planes = numpy.frombuffer(raw, numpy.uint8, count * size, offset).reshape(size, count)
        offset += count * size
        values = numpy.ascontiguousarray(planes.T).view(unsigned).reshape(shape)
        if predictor != "none" and dtype.kind != "f":
            values = (values >> 1) ^ (-(values & 1).astype(dtype)).view(unsigned)
            for axis in {"xyz": (0, 1, 2), "x": (2,)}[predictor]:
                values = numpy.cumsum(values, axis=axis, dtype=unsigned)
        out.append(values.view(dtype))
    return out, offset == len(raw)


def brute_need(values, brick, v):
    """The bricks isovalue v needs: for every block of 8 cells whose points [8b, 8b + 8] hold it
    (min < v <= max), the bricks of the points 8b - 1 .. 8b + 9 its cells and gradients read."""
    n = values.shape
    blocks = [max(1, (m - 1 + 7) // 8) for m in n]
    counts = [(m + brick - 1) // brick for m in n[::-1]]
    out = set()
    for bz in range(blocks[0]):
        for by in range(blocks[1]):
            for bx in range(blocks[2]):
                box = values[8 * bz:8 * bz + 9, 8 * by:8 * by + 9, 8 * bx:8 * bx + 9]
                if not box.min() < v <= box.max():
                    continue
                ends = [sorted({max(0, 8 * b - 1) // brick, min(m - 1, 8 * b + 9) // brick})
                        for b, m in ((bx, n[2]), (by, n[1]), (bz, n[0]))]
                for z in ends[2]:
                    for y in ends[1]:
                        for x in ends[0]:
                            out.add(x + counts[0] * (y + counts[1] * z))
    return sorted(out)


def superset(ranges, counts, v):
    """The page's superset before the server answers: the bricks whose range holds v and their
    neighbours."""
    out = set()
    for i, (lo, hi) in enumerate(ranges):
        if lo < v <= hi:
            b = (i % counts[0], (i // counts[0]) % counts[1], i // (counts[0] * counts[1]))
            for z in range(max(0, b[2] - 1), min(counts[2], b[2] + 2)):
                for y in range(max(0, b[1] - 1), min(counts[1], b[1] + 2)):
                    for x in range(max(0, b[0] - 1), min(counts[0], b[0] + 2)):
                        out.add(x + counts[0] * (y + counts[1] * z))
    return out


def brute_ranges(values, brick, apron):
    """[min, max] per brick (x fastest) over its read points, one point at a time."""
    nz, ny, nx = values.shape
    counts = [(n + brick - 1) // brick for n in (nx, ny, nz)]
    out = []
    for bz in range(counts[2]):
        for by in range(counts[1]):
            for bx in range(counts[0]):
                box = []
                for b, n in ((bz, nz), (by, ny), (bx, nx)):
                    box.append(slice(max(0, b * brick - apron), min(n, (b + 1) * brick + 1 + apron)))
                read = values[tuple(box)].ravel()
                out.append([float(read.min()), float(read.max())])
    return counts, out


async def main():
    async with aiohttp.ClientSession(auto_decompress=False) as http:
        async with http.get(server.url("/api/datasets")) as r:
            d = (await r.json())["datasets"][0]
        dtype = numpy.dtype(d["type"])
        for k in (3, 2):
            level = d["levels"][k]
            async with http.get(server.url("/api/volume/%s?level=%d" % (d["id"], k))) as r:
                whole = await r.read()
            count = level["dims"][0] * level["dims"][1] * level["dims"][2]
            values = webserver.decode(whole, dtype, count).reshape(level["dims"][::-1])
            async with http.get(server.url("/api/bricks/%s?level=%d" % (d["id"], k))) as r:
                m = await r.json()
            counts, ranges = brute_ranges(values, m["brick"], m["apron"])
            checks(m["brick"] % 8 == 0 and m["apron"] == 1 and m["bricks"] == counts and
                   m["dims"] == level["dims"],
                   "level %d: bricks of %d points (a multiple of 8), %s per axis, apron %d"
                   % (k, m["brick"], m["bricks"], m["apron"]))
            checks([[float(a), float(b)] for a, b in m["ranges"]] == ranges,
                   "level %d: each brick's range over its read points is the brute force's" % k)
            checks(sum(m["bytes"]) == level["bytes"],
                   "level %d: the bricks own every point once (%d bytes)" % (k, sum(m["bytes"])))
            ids = list(range(len(ranges)))[::-1]
            batches = [ids[i:i + 9] for i in range(0, len(ids), 9)]
            wire = 0
            rebuilt = numpy.full(values.shape, -32768, dtype)
            b = m["brick"]
            for batch in batches:
                url = "/api/bricks/%s?level=%d&ids=%s" % (d["id"], k, ",".join(map(str, batch)))
                async with http.get(server.url(url)) as r:
                    body = await r.read()
                    predictor = r.headers.get("X-Mediso-Predictor")
                    checks(r.status == 200 and r.headers["X-Mediso-Bricks"] == ",".join(map(str, batch))
                           and predictor in PREDICTORS,
                           "level %d: bricks %s answered (predictor %s)" % (k, batch, predictor))
                wire += len(body)
                boxes = []
                for brick in batch:
                    bx = brick % counts[0]
                    by = (brick // counts[0]) % counts[1]
                    bz = brick // (counts[0] * counts[1])
                    boxes.append((slice(bz * b, (bz + 1) * b), slice(by * b, (by + 1) * b),
                                  slice(bx * b, (bx + 1) * b)))
                decoded, whole_body = decode_bricks(body, dtype, [rebuilt[box].shape for box in boxes],
                                                    predictor)
                for box, brick_values in zip(boxes, decoded):
                    rebuilt[box] = brick_values
                checks(whole_body, "level %d: a batch holds its bricks and nothing else" % k)
            checks(numpy.array_equal(rebuilt, values),
                   "level %d: the bricks put together are the level's values" % k)
            async with http.get(server.url("/api/volume/%s?level=0" % d["id"])) as r:
                level0 = len(await r.read())
            # 1.05x (the bound) at level 2; at level 3 this small phantom's partial bricks
            # (13 points of 77) cost more: 1.09x was measured, 1.10x allowed.
            bound = 1.05 if k == 2 else 1.10
            checks(wire + level0 <= bound * len(whole),
                   "level %d: the bricks (%d bytes) and level 0 (%d) are at most %.2fx the whole "
                   "level (%d: %.3fx)" % (k, wire, level0, bound, len(whole),
                                          (wire + level0) / len(whole)))
            for v in (-500.0, 0.0, 400.0, float(values.max())):
                url = "/api/bricks/%s?level=%d&need=%r" % (d["id"], k, v)
                async with http.get(server.url(url)) as r:
                    need = (await r.json())["need"][0]
                exact = brute_need(values, b, v)
                checks(need == exact and set(need) <= superset(m["ranges"], counts, v),
                       "level %d, isovalue %g: the server's need (%d bricks) is the blocks' brute "
                       "force (%d) and within the superset (%d)" % (
                           k, v, len(need), len(exact), len(superset(m["ranges"], counts, v))))
        url = "/api/bricks/%s?level=3&need=-500,400" % d["id"]
        async with http.get(server.url(url)) as r:
            both = (await r.json())["need"]
        checks(len(both) == 2, "a need query answers each isovalue in order")
        await noisy_phantom(http)
        await batch_answers(http, d)
        for query, status in (("level=4", 400), ("level=x", 400), ("level=3&ids=", 400),
                              ("level=3&need=", 400), ("level=3&need=a", 400),
                              ("level=3&need=nan", 400), ("level=3&need=" + ",".join(["1"] * 17), 400),
                              ("level=3&ids=1,1", 400), ("level=3&ids=-1", 400),
                              ("level=3&ids=27", 400), ("level=3&ids=a", 400)):
            async with http.get(server.url("/api/bricks/%s?%s" % (d["id"], query))) as r:
                checks(r.status == status, "%s: %d (%d)" % (query, status, r.status))
        # A batch: a brick repeated anywhere in it, an id past the last, a negative, empty or not
        # whole one; refused whole, with a line saying what ids must be.
        for ids in ("0,5,3,5", "3,0,3", "0,1,8", "2,-1", "1,,2", "0,1.5"):
            async with http.get(server.url("/api/bricks/%s?level=3&ids=%s" % (d["id"], ids))) as r:
                text = await r.text()
                checks(r.status == 400 and text.startswith("ids:"),
                       "ids=%s: 400 (%d, %s)" % (ids if len(ids) < 20 else ids[:17] + "...", r.status,
                                                text.strip()))
        async with http.get(server.url("/api/bricks/nope?level=3")) as r:
            checks(r.status == 404, "an unknown dataset: 404 (%d)" % r.status)
        async with http.get(server.url("/api/bricks/%s?level=3&ids=0" % d["id"], token="wrong")) as r:
            checks(r.status == 403, "without the token: 403 (%d)" % r.status)


async def batch_answers(http, d):
    """A batch is its bricks' single answers put together: the same values in the order asked (one
    gzip stream, its CRC checked by gzip.decompress), in no more bytes than the single answers
    (the server joins its kept encodings; each single answer has a gzip header and trailer more),
    the same bytes at every request (the browser's copy stays valid), and a batch of every brick
    in any order decodes too."""
    import gzip
    base = "/api/bricks/%s?level=3&ids=" % d["id"]
    singles = {}
    for brick in range(8):
        async with http.get(server.url(base + str(brick))) as r:
            singles[brick] = await r.read()
    order = [6, 1, 7, 0, 3]
    bodies = []
    for _ in range(2):
        async with http.get(server.url(base + ",".join(map(str, order)))) as r:
            bodies.append(await r.read())
            checks(r.status == 200 and r.headers["X-Mediso-Bricks"] == ",".join(map(str, order)) and
                   r.headers["Content-Encoding"] == "gzip", "a batch of 5 bricks answered")
    joined = b"".join(gzip.decompress(singles[b]) for b in order)
    checks(gzip.decompress(bodies[0]) == joined,
           "a batch inflates to its bricks' single answers, one after the other in the order asked")
    checks(len(bodies[0]) <= sum(len(singles[b]) for b in order) and bodies[0] == bodies[1],
           "... in %d bytes (the single answers: %d), the same at every request"
           % (len(bodies[0]), sum(len(singles[b]) for b in order)))
    every = list(range(8))[::-1]
    async with http.get(server.url(base + ",".join(map(str, every)))) as r:
        body = await r.read()
    checks(gzip.decompress(body) == b"".join(gzip.decompress(singles[b]) for b in every),
           "a batch of every brick, last first, inflates to them all")


async def noisy_phantom(http):
    """phantom:N:noise=40: the noiseless phantom's values plus seeded noise of about 40 HU (the
    two as the server sends them), and its bricks decode to its values."""
    async with http.get(server.url("/api/datasets")) as r:
        clean, noisy = (await r.json())["datasets"][:2]
    levels = []
    for d in (clean, noisy):
        async with http.get(server.url("/api/volume/%s?level=3" % d["id"])) as r:
            body = await r.read()
        levels.append(webserver.decode(body, numpy.dtype(d["type"]), N * N * N).reshape(N, N, N))
    difference = levels[1].astype(numpy.float64) - levels[0]
    checks("noise 40 HU" in noisy["name"] and 35 < difference.std() < 45 and abs(difference.mean()) < 2,
           "phantom:%d:noise=%d (%s): the noiseless values plus noise of std %.1f HU, mean %.2f"
           % (N, NOISE, noisy["name"], difference.std(), difference.mean()))
    url = "/api/bricks/%s?level=3&ids=0,7" % noisy["id"]
    async with http.get(server.url(url)) as r:
        body = await r.read()
        predictor = r.headers.get("X-Mediso-Predictor")
    (first, last), _ = decode_bricks(body, levels[1].dtype, [(64, 64, 64), (13, 13, 13)], predictor)
    checks(numpy.array_equal(first, levels[1][:64, :64, :64]) and
           numpy.array_equal(last, levels[1][64:, 64:, 64:]),
           "the noisy phantom's bricks 0 and 7 decode to its values (predictor %s)" % predictor)


async def ct_bytes(ct):
    """The head CT's bricks, 8 to a request, with level 0, against its whole level: at most 1.05x."""
    async with aiohttp.ClientSession(auto_decompress=False) as http:
        async with http.get(ct.url("/api/datasets")) as r:
            d = (await r.json())["datasets"][0]
        sizes = {}
        for k in (3, 0):
            async with http.get(ct.url("/api/volume/%s?level=%d" % (d["id"], k))) as r:
                sizes[k] = len(await r.read())
        async with http.get(ct.url("/api/bricks/%s?level=3" % d["id"])) as r:
            n = len((await r.json())["ranges"])
        wire = 0
        for i in range(0, n, 8):
            ids = ",".join(map(str, range(i, min(n, i + 8))))
            async with http.get(ct.url("/api/bricks/%s?level=3&ids=%s" % (d["id"], ids))) as r:
                wire += len(await r.read())
        checks(wire + sizes[0] <= 1.05 * sizes[3],
               "the head CT: %d bricks (%d bytes) and level 0 (%d) are %.3fx its whole level (%d), "
               "at most 1.05x" % (n, wire, sizes[0], (wire + sizes[0]) / sizes[3], sizes[3]))


asyncio.run(main())
servers = [server]
ct_file = webserver.data_cache() / "ct_head.mha"
if ct_file.is_file():
    servers.append(webserver.Server([str(ct_file)]))
    asyncio.run(ct_bytes(servers[-1]))
else:
    print("note: the head CT is not fetched (python3 Python/fetch_data.py): its bricks' bytes are "
          "not measured")
checks.finish(*servers)
