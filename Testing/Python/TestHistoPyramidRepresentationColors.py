"""pvpython test: how the 'HistoPyramid Isosurface' representation colours its surfaces.

    pvpython TestHistoPyramidRepresentationColors.py --plugin PATH --out DIR [--expect-fallback]

MedicalPhantom (skin -500 HU in front of bone 400 HU), the colour of a patch at
the image centre (the face's skin) and of the whole image, checked step by step:
- shown with no colour array (Solid Color, as a fresh display is): an opaque,
  lit surface in the default solid colour (white), not black;
- Solid Color red: the surfaces are red;
- coloured by HU with a green colour map: green; back to Solid Color: red
  again (the colour map is dropped);
- Color Each Surface, skin blue and bone yellow: blue; skin at opacity 0.3:
  the yellow bone shows through it;
- Opacity 0.5 with one opaque surface: the background shows through; Opacity
  0: nothing drawn (path "none").
Run twice: on the GPU path, and on the CPU fallback (--expect-fallback, under
MEDISO_DISABLE_GPU_PATH=1; its one warning is captured and checked): both
paths take their colours from the same place. A machine whose GL lacks what
the GPU path needs skips the GPU run (exit 125).
"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)

import HistoPyramidRepresentationChecks as hp

args = hp.parse_args(expect_fallback=True)
check = hp.Checker()
expected_path = "fallback" if args.expect_fallback else "gpu"
name = "TestHistoPyramidRepresentationColors" + ("Fallback" if args.expect_fallback else "")

LoadPlugin(args.plugin, ns=globals())
phantom = MedicalPhantom(Dimensions=[64, 64, 64], Spacing=[3.0, 3.0, 3.0])
view, display = hp.show_at(phantom)


def look(step):
    """Render, check the path, and return (mean colour of the central patch,
    fraction of the image covered) for the step."""
    pixels = hp.screenshot(view, os.path.join(args.out, "%s_%s.png" % (name, step)))
    h, w, _ = pixels.shape
    patch = pixels[h // 2 - 6:h // 2 + 6, w // 2 - 6:w // 2 + 6].reshape(-1, 3).mean(axis=0)
    return patch, hp.foreground_fraction(pixels)


def dominant(patch, channel, what):
    others = [patch[c] for c in range(3) if c != channel]
    check(patch[channel] > 60 and all(patch[channel] > 2.0 * o + 10 for o in others),
          "%s (centre %s)" % (what, [int(round(c)) for c in patch]))


# 1. A fresh display has no colour array: Solid Color, white by default.
check(display.ColorArrayName[1] == "", "a fresh display colours nothing (Solid Color)")
hp.first_render(view, display, check, args.expect_fallback)
info = hp.render_info(display)
check(info["path"] == expected_path, "path %r (expected %r)" % (info["path"], expected_path))
patch, covered = look("solid_white")
check(0.05 < covered < 0.9, "the surfaces cover %.1f%% of the image" % (100 * covered))
check(min(patch) > 90 and max(patch) - min(patch) < 30,
      "Solid Color (white): a lit grey-white surface, not black (centre %s)"
      % [int(round(c)) for c in patch])

# 2. Solid Color red.
display.AmbientColor = [1.0, 0.0, 0.0]
display.DiffuseColor = [1.0, 0.0, 0.0]
patch, _ = look("solid_red")
dominant(patch, 0, "Solid Color red: red surfaces")

# 3. Coloured by HU through a green colour map, then back to Solid Color.
ColorBy(display, ("POINTS", "HU"))
lut = GetColorTransferFunction("HU")
lut.RGBPoints = [-1000.0, 0.0, 1.0, 0.0, 3000.0, 0.0, 1.0, 0.0]
GetOpacityTransferFunction("HU").Points = [-1000.0, 1.0, 0.5, 0.0, 3000.0, 1.0, 0.5, 0.0]
patch, _ = look("colormap_green")
dominant(patch, 1, "coloured by HU: the colour map's green")
ColorBy(display, None)
check(display.ColorArrayName[1] == "", "ColorBy None is Solid Color")
patch, _ = look("solid_again")
dominant(patch, 0, "back to Solid Color: red again, the colour map dropped")

# 4. A colour and an opacity per surface, without transfer functions.
display.HistoPyramidColorEachSurface = 1
display.HistoPyramidSurfaceColors = [0.0, 0.0, 1.0, 1.0, 1.0, 0.0]
patch, _ = look("each_blue")
dominant(patch, 2, "Color Each Surface: the skin's own blue")
opaque_blue = patch
display.HistoPyramidSurfaceOpacities = [0.3, 1.0]
patch, _ = look("each_translucent")
check(patch[0] > opaque_blue[0] + 40 and patch[1] > opaque_blue[1] + 40 and patch[2] < opaque_blue[2],
      "skin at opacity 0.3: the yellow bone shows through the blue skin (centre %s, opaque %s)"
      % ([int(round(c)) for c in patch], [int(round(c)) for c in opaque_blue]))
check(hp.render_info(display)["path"] == expected_path, "translucent surfaces: path %r" % expected_path)

# 5. Opacity multiplies every surface: half, then nothing.
display.HistoPyramidSurfaceOpacities = [1.0, 1.0]
display.IsosurfaceValues = [hp.SKIN]
patch, _ = look("opacity_full")
full = patch
display.Opacity = 0.5
patch, _ = look("opacity_half")
# The ray at the centre crosses the skin twice (face, back of the head):
# 0.5 + 0.5 x 0.5 of the surface's colour, a quarter of the background.
background = [255 * c for c in hp.BACKGROUND]
expected = [0.75 * full[c] + 0.25 * background[c] for c in range(3)]
check(all(abs(patch[c] - expected[c]) < 25 for c in range(3)),
      "Opacity 0.5: the background shows through both skin layers (%s, expected about %s)"
      % ([int(round(c)) for c in patch], [int(round(c)) for c in expected]))
display.Opacity = 0.0
patch, covered = look("opacity_zero")
check(covered == 0.0, "Opacity 0: nothing drawn (%.2f%% covered)" % (100 * covered))
check(hp.render_info(display)["path"] == "none", "Opacity 0: path 'none'")

if check.failures:
    print("%d check(s) failed" % len(check.failures))
    sys.exit(1)
print("HistoPyramid representation colours (%s): all checks passed" % expected_path)
