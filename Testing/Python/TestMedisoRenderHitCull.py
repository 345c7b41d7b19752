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
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)
from medisorender import run_stats  # noqa: E402

check = Checks()
SOFTWARE = ("llvmpipe", "softpipe", "swiftshader")

# name: the phantom's size and mediso-render's options
SCENES = {
    "bone": ("phantom:64", ["--iso", "400", "--elevation", "-60"]),
    "skin_bone": ("phantom:64", ["--iso", "-500:0.93,0.75,0.62", "--iso", "400:0.97,0.95,0.88",
                                 "--azimuth", "30"]),
    "cropped": ("phantom:64", ["--iso", "-500:0.93,0.75,0.62", "--iso", "400", "--crop",
                               "0,63,0,63,0,36", "--elevation", "-90"]),
    "zoomed": ("phantom:24", ["--iso", "-500", "--zoom", "2.5", "--azimuth", "20"]),
    "parallel": ("phantom:64", ["--iso", "-500", "--iso", "400", "--parallel", "--azimuth", "-40"]),
    "reduced": ("phantom:64", ["--iso", "400", "--sample-distance", "2"]),
}


def render(binary, api, volume, options, mode, path):
    args = [volume, "--size", "320x240", "--api", api, "--stats", "--output", path] + options
    if mode is not None:
        args += ["--hit-cull", mode]
    return run_stats(binary, args)


def main():
    binary, temp = sys.argv[1], sys.argv[2]
    os.makedirs(temp, exist_ok=True)
    ran = False
    for api in ("es", "gl"):
        for name, (volume, options) in SCENES.items():
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
