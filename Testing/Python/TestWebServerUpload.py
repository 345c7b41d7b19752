"""pvpython test: a local volume uploaded once for the server's operations (POST /api/upload).

Python/serve.py on the phantom (docs/web.md, Local files): the phantom's own values, fetched from
/api/volume and sent back byte-shuffled and gzip'd with its geometry, are accepted as "u1"; an
operation on "u1" gives the triangles and points the same operation gives on the served "d0";
"u1" is not listed by /api/datasets. Refused with the reason, the server staying up: no token
(403), an unknown type, dims that are not a 3D volume, a non-positive spacing, a direction of 8
numbers, a body that is not gzip, a body with fewer bytes than the dims and type need, a gzip
stream that inflates far past them (only what is needed is inflated), and dims past the limit
(413). After all of it the server still runs an operation on "d0".
"""
import asyncio
import gzip
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import webserver  # noqa: E402  (skips when aiohttp or the plugin is missing)

checks = webserver.Checks()
server = webserver.Server(["phantom:40"])
ISO = 400.0


def shuffled(values):
    import numpy
    size = values.dtype.itemsize
    return numpy.ascontiguousarray(values.view(numpy.uint8).reshape(-1, size).T).tobytes()


async def post(http, headers, body, token=True):
    async with http.post(server.url("/api/upload", token), headers=headers, data=body) as r:
        return r.status, await r.text()


async def surface(http, dataset, ident):
    async with http.ws_connect(server.ws_url()) as ws:
        _, answer = await webserver.operation(ws, webserver.surface_request(ident, dataset, ISO, 3))
    return answer


async def main():
    import aiohttp
    async with aiohttp.ClientSession(auto_decompress=False) as http:  # the gzip body as sent
        async with http.get(server.url("/api/datasets")) as r:
            d = (await r.json())["datasets"][0]
        async with http.get(server.url("/api/volume/d0?level=3")) as r:
            body = await r.read()
        count = d["dims"][0] * d["dims"][1] * d["dims"][2]
        values = webserver.decode(body, d["type"], count)
        headers = {"X-Mediso-Name": "phantom%20upload.nii", "X-Mediso-Dims": ",".join(map(str, d["dims"])),
                   "X-Mediso-Spacing": ",".join(map(repr, d["spacing"])),
                   "X-Mediso-Origin": ",".join(map(repr, d["origin"])),
                   "X-Mediso-Direction": ",".join(map(repr, d["direction"])),
                   "X-Mediso-Type": d["type"], "X-Mediso-Format": "NIfTI RAS"}
        good = gzip.compress(shuffled(values), 6)

        # Refusals, each with its reason.
        code, text = await post(http, headers, good, token=None)
        checks(code == 403, "without the token: %d" % code)
        for change, expected in [({"X-Mediso-Type": "int64"}, "X-Mediso-Type"),
                                 ({"X-Mediso-Dims": "40,40"}, "X-Mediso-Dims"),
                                 ({"X-Mediso-Dims": "40,40,1"}, "not a 3D volume"),
                                 ({"X-Mediso-Spacing": "1,0,1"}, "positive"),
                                 ({"X-Mediso-Direction": "1,0,0,0,1,0,0,0"}, "X-Mediso-Direction")]:
            code, text = await post(http, dict(headers, **change), good)
            checks(code == 400 and expected in text, "%s: %d %s" % (change, code, text.strip()))
        code, text = await post(http, headers, shuffled(values))
        checks(code == 400 and "not a gzip stream" in text, "a body that is not gzip: %d %s"
               % (code, text.strip()))
        code, text = await post(http, headers, gzip.compress(shuffled(values)[:1000]))
        checks(code == 400 and "holds 1000 bytes" in text, "too few bytes: %d %s" % (code, text.strip()))
        bomb = gzip.compress(bytes(200 * 1024 * 1024), 9)
        started = time.monotonic()
        code, text = await post(http, headers, bomb)
        seconds = time.monotonic() - started
        checks(code == 400 and "inflates past the %d bytes" % (count * values.dtype.itemsize) in text,
               "a gzip stream of 200 MB (%d bytes sent) inflated only past what is needed: %d %s "
               "(%.2f s)" % (len(bomb), code, text.strip(), seconds))
        code, text = await post(http, dict(headers, **{"X-Mediso-Dims": "65536,65536,2"}), good)
        checks(code == 413, "dims past the limit: %d" % code)

        # The good one: accepted once, used by the operations, not listed.
        code, text = await post(http, headers, good)
        answer = json.loads(text) if code == 200 else {}
        checks(code == 200 and answer.get("id") == "u1" and answer.get("raw") == values.nbytes
               and answer.get("received") == len(good), "the upload is accepted: %d %s" % (code, text))
        async with http.get(server.url("/api/datasets")) as r:
            listed = [x["id"] for x in (await r.json())["datasets"]]
        checks(listed == ["d0"], "the upload is not listed: %s" % listed)
        served = await surface(http, "d0", 1)
        uploaded = await surface(http, "u1", 2)
        checks(served.get("done") and uploaded.get("done") and
               served["triangles"] == uploaded["triangles"] and served["points"] == uploaded["points"],
               "an operation on u1 gives d0's surface: %s triangles, %s points (d0: %s, %s)"
               % (uploaded.get("triangles"), uploaded.get("points"), served.get("triangles"),
                  served.get("points")))
        again = await surface(http, "d0", 3)
        checks(again.get("done") and server.alive(), "the server still runs operations on d0")


asyncio.run(main())
checks.finish(server)
