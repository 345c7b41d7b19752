#!/usr/bin/env python3
"""mediso-render --hit-cull: hidden points dropped in the first-hit pass, the same image.

    python3 TestMedisoRenderHitCull.py MEDISO_RENDER TEMP_DIR

Plain python3 (no ParaView). On OpenGL ES 3.0 (the WebGL2 subset) and OpenGL 3.2 core, opaque
scenes of the phantom (one surface; two surfaces, drawn one primitive per cell; a cut by a
cropping plane; a zoom that makes every point tens of pixels wide; a parallel camera; a reduced
frame at sample distance 2) are drawn with --hit-cull on and off: both go through the first-hit
pass with point footprints, the stats say whether the cull ran, and the PNGs are byte-identical
with equal primitive counts. By default (auto) the cull is off on a software renderer (llvmpipe,
softpipe, SwiftShader). A bad mode is refused (exit 2). A context that cannot be made skips (125).

The phantom's scenes hardly ever put an earlier hit over part of a later point: the points behind
its skin are hidden whole. Three scenes of volumes this test writes do (write_volume(): balls, and
a plate with two slits, in front of a wall): on a coarse grid seen close, points some 15-20 pixels
wide, the edges of the nearer surface, drawn mostly in the first range, cross the points of the
wall, drawn in the later ones. A cull that tests less than a point's whole square (its centre's
block, one of its four blocks, a square half as wide) drops wall points that still show at some
of their pixels, and the images differ (checked by hand: see docs/histopyramid.md).

A fourth ("bars") shows the wall only through gaps narrower than a block of the coverage pyramid,
each at the middle of a wall point, with everything around them covered. Its points are some 28
pixels wide: the level the cull reads has 32-pixel blocks, the level below 16-pixel ones, so a
point spans three columns of those and the middle column lies inside it, away from its edges. A
cull that read the level below (its four corner blocks) finds the two outer columns covered and
drops the wall points that show through a gap lying in a middle column.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)
from medisorender import run_stats, write_short_volume  # noqa: E402

check = Checks()
SOFTWARE = ("llvmpipe", "softpipe", "swiftshader")

# name: the volume (phantom:N, or "balls" or "slits": write_volume()) and mediso-render's options
SCENES = {
    "bone": ("phantom:64", ["--iso", "400", "--elevation", "-60"]),
    "skin_bone": ("phantom:64", ["--iso", "-500:0.93,0.75,0.62", "--iso", "400:0.97,0.95,0.88",
                                 "--azimuth", "30"]),
    "cropped": ("phantom:64", ["--iso", "-500:0.93,0.75,0.62", "--iso", "400", "--crop",
                               "0,63,0,63,0,36", "--elevation", "-90"]),
    "zoomed": ("phantom:24", ["--iso", "-500", "--zoom", "2.5", "--azimuth", "20"]),
    "parallel": ("phantom:64", ["--iso", "-500", "--iso", "400", "--parallel", "--azimuth", "-40"]),
    "reduced": ("phantom:64", ["--iso", "400", "--sample-distance", "2"]),
    "balls": ("balls", ["--iso", "0", "--zoom", "2.5"]),
    "balls_parallel": ("balls", ["--iso", "0", "--zoom", "3.5", "--parallel", "--azimuth", "-25",
                                 "--elevation", "15"]),
    "slits": ("slits", ["--iso", "0", "--zoom", "2.5"]),
    "bars": ("bars", ["--iso", "0", "--zoom", "4.5", "--parallel"]),
}
# Volumes whose surface faces the camera (VTK's, looking down -z) with a wall behind: the
# half-space z < WALL. The walk draws the nearer surface's points mostly in the first range and
# the wall's after them. "balls": three overlapping balls (centre x, y, z and radius, in points);
# "slits": a plate (mid-plane z = PLATE[0], PLATE[1] thick on either side) cut by slits 2 SLITS[2]
# wide along x = SLITS[0] and y = SLITS[1], the wall seen through them (centred on planes of points:
# between them, trilinear interpolation would close a slit narrower than a cell).
WALL = 5.25
BALLS = ((9.45, 12.15, 15.3, 5.4), (15.6, 9.3, 18.75, 3.45), (13.65, 16.5, 12.6, 3.15))
PLATE = (16, 0.3)
SLITS = (12, 9, 0.3)
# "bars": bars along y, BARS[2] thick on either side of their mid-planes, alternately at z =
# BARS[0] and BARS[1], whose edges leave, seen head on, gaps 2 GAP wide at x = GAPS: the middles of
# the wall's cells (the edges of a bar are where its field crosses 0 between two planes of points,
# so a gap needs no plane of points inside, as a slit does). Both depths lie in the pyramid's near
# half (cells z >= 16 of 32), the wall in its far half, so the walk draws every bar before any wall
# point, and the bars are under three quarters of the primitives: the last range draws only wall
# points, tested against all of the bars. The gaps are 2, 3 and 2 cells apart, so that they do not all fall at the
# same place in the blocks of the coverage pyramid (cells 27 pixels wide).
BARS = (20, 17, 0.6)
GAPS = (7.5, 9.5, 12.5, 14.5)
GAP = 0.1


def balls(x, y, z):
    return max(r - math.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2)
               for cx, cy, cz, r in BALLS)


def slits(x, y, z):
    return min(PLATE[1] - abs(z - PLATE[0]), abs(x - SLITS[0]) - SLITS[2],
               abs(y - SLITS[1]) - SLITS[2])


def bars(x, y, z):
    edges = (-math.inf,) + tuple(e for g in GAPS for e in (g - GAP, g + GAP)) + (math.inf,)
    return max(min(BARS[2] - abs(z - BARS[k % 2]), x - edges[2 * k], edges[2 * k + 1] - x)
               for k in range(len(GAPS) + 1))


def write_volume(path, front, n=24):
    """`front` and the wall as one int16 field on n^3 points, 100 per point inside (iso 0)."""
    return write_short_volume(
        path, n, lambda x, y, z: int(round(100 * max(WALL - z, front(x, y, z)))))


def render(binary, api, volume, options, mode, path):
    args = [volume, "--size", "320x240", "--api", api, "--stats", "--output", path] + options
    if mode is not None:
        args += ["--hit-cull", mode]
    return run_stats(binary, args)


def main():
    binary, temp = sys.argv[1], sys.argv[2]
    os.makedirs(temp, exist_ok=True)
    volumes = {name: write_volume(os.path.join(temp, name + ".mha"), front)
               for name, front in (("balls", balls), ("slits", slits), ("bars", bars))}
    ran = False
    for api in ("es", "gl"):
        for name, (volume, options) in SCENES.items():
            volume = volumes.get(volume, volume)
            results = {}
            for mode in ("on", "off"):
                path = os.path.join(temp, "%s_%s_%s.png" % (api, name, mode))
                code, stats, text = render(binary, api, volume, options, mode, path)
                if code == 4:
                    print("SKIP: no %s context: %s" % (api, text.strip().splitlines()[-1:]))
                    break
                ran = True
                if not check(code == 0 and stats is not None,
                             "%s %s --hit-cull %s: drawn (exit %d: %s)" % (api, name, mode, code,
                                                                           text.strip()[-300:])):
                    continue
                check(stats["footprint"] == "points" and stats["first_hit"],
                      "%s %s --hit-cull %s: points through the first-hit pass (got %s, %s)"
                      % (api, name, mode, stats["footprint"], stats["first_hit"]))
                check(stats["hit_cull"] == (mode == "on"),
                      "%s %s --hit-cull %s: the stats say hit_cull %s" % (api, name, mode,
                                                                          stats["hit_cull"]))
                with open(path, "rb") as png:
                    results[mode] = (stats["primitives"], png.read())
            if len(results) == 2:
                print("%s %s: %d primitives" % (api, name, results["on"][0]))
                check(results["on"][0] == results["off"][0] and results["on"][0] > 1000,
                      "%s %s: equal primitive counts (%d, %d)" % (api, name, results["on"][0],
                                                                  results["off"][0]))
                check(results["on"][1] == results["off"][1],
                      "%s %s: the culled image is byte-identical to the unculled one"
                      % (api, name))
        # The default: off on a software renderer, on elsewhere.
        code, stats, text = render(binary, api, "phantom:32", ["--iso", "400"], None,
                                   os.path.join(temp, "%s_auto.png" % api))
        if code == 0 and stats is not None:
            software = any(s in stats["renderer"].lower() for s in SOFTWARE)
            check(stats["hit_cull"] == (not software),
                  "%s: by default the cull is %s on %s (got %s)"
                  % (api, "off" if software else "on", stats["renderer"], stats["hit_cull"]))
    code, _, text = render(binary, "es", "phantom:32", ["--iso", "400"], "sometimes",
                           os.path.join(temp, "bad.png"))
    check(code == 2 and "--hit-cull" in text,
          "a bad --hit-cull is refused with exit 2 and a message (got %d: %s)" % (code, text[-200:]))
    if not ran:
        sys.exit(125)
    check.finish("TestMedisoRenderHitCull: all checks passed")


main()
