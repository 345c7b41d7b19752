#!/usr/bin/env python3
"""mediso-render --sample-distance: the core's reduced frames on both contexts (issue 30).

    python3 TestMedisoRenderSampleDistance.py MEDISO_RENDER TEMP_DIR

Plain python3 (no ParaView). On OpenGL ES 3.0 (the WebGL2 subset) and OpenGL 3.2 core, the phantom's
skin (translucent) over bone and bone alone (opaque: the first-hit pass inside the reduced target)
are drawn at sample distance 1 and 3: the stats say the distance drawn at, the reduced images
cover the full ones' pixels within 10% and differ from them. A distance below 1 is refused
(exit 2). A context that cannot be made skips (125).
"""
import os
import struct
import sys
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)
from medisorender import run_stats  # noqa: E402

check = Checks()
BACKGROUND = (26, 31, 41)  # mediso-render's default 0.1, 0.12, 0.16


def read_png(path):
    """(width, height, rows of RGB bytes) of mediso-render's PNGs (8-bit RGB, filter 0)."""
    data = open(path, "rb").read()
    offset, width, height, idat = 8, 0, 0, b""
    while offset < len(data):
        length = struct.unpack(">I", data[offset:offset + 4])[0]
        kind = data[offset + 4:offset + 8]
        chunk = data[offset + 8:offset + 8 + length]
        if kind == b"IHDR":
            width, height = struct.unpack(">II", chunk[:8])
        elif kind == b"IDAT":
            idat += chunk
        offset += 12 + length
    raw = zlib.decompress(idat)
    stride = 1 + 3 * width
    return width, height, [raw[r * stride + 1:(r + 1) * stride] for r in range(height)]


def covered(rows):
    count = 0
    for row in rows:
        for p in range(0, len(row), 3):
            if max(abs(row[p + c] - BACKGROUND[c]) for c in range(3)) > 8:
                count += 1
    return count


def render(binary, api, distance, isos, path):
    args = ["phantom:48", "--size", "160x120", "--api", api, "--stats", "--output", path,
            "--sample-distance", str(distance)]
    for iso in isos:
        args += ["--iso", iso]
    return run_stats(binary, args)


def main():
    binary, temp = sys.argv[1], sys.argv[2]
    os.makedirs(temp, exist_ok=True)
    scenes = {"translucent": ["-500:0.93,0.75,0.62,0.3", "400"], "opaque": ["400"]}
    ran = False
    for api in ("es", "gl"):
        for name, isos in scenes.items():
            images = {}
            for distance in (1, 3):
                path = os.path.join(temp, "%s_%s_%d.png" % (api, name, distance))
                code, stats, text = render(binary, api, distance, isos, path)
                if code == 4:
                    print("SKIP: no %s context: %s" % (api, text.strip().splitlines()[-1:]))
                    break
                ran = True
                if not check(code == 0 and stats is not None,
                             "%s %s distance %d: drawn (exit %d: %s)" % (api, name, distance, code,
                                                                          text.strip()[-300:])):
                    continue
                check(stats["sample_distance"] == distance,
                      "%s %s: the stats say distance %d (got %r)" % (api, name, distance,
                                                                     stats["sample_distance"]))
                images[distance] = read_png(path)[2]
            if len(images) == 2:
                full, reduced = covered(images[1]), covered(images[3])
                print("%s %s: covered pixels %d at distance 1, %d at 3" % (api, name, full, reduced))
                check(full > 1000 and abs(full - reduced) < full / 10,
                      "%s %s: distance 3 covers the pixels of distance 1 within 10%%" % (api, name))
                check(images[1] != images[3],
                      "%s %s: the reduced image differs from the full one" % (api, name))
    code, _, text = render(binary, "es", 0.5, ["400"], os.path.join(temp, "bad.png"))
    check(code == 2 and "--sample-distance" in text,
          "a distance below 1 is refused with exit 2 and a message (got %d: %s)" % (code, text[-200:]))
    if not ran:
        sys.exit(125)
    check.finish("TestMedisoRenderSampleDistance: all checks passed")


main()
