"""pvpython test: the colour map's opacity map applies only while its opacity mapping is on.

    pvpython TestHistoPyramidRepresentationOpacityMapping.py --plugin PATH --out DIR [--expect-fallback]

ParaView's Surface representation applies a colour map's opacity map only when the map's
"Enable opacity mapping for surfaces" (EnableOpacityMapping) is checked; HistoPyramid
Isosurface now does the same. MedicalPhantom shown as HistoPyramid Isosurface at skin
(-500 HU, bone 400 HU inside it), coloured by HU with ParaView's default opacity ramp
(0 at the minimum, 1 at the maximum: about 0.13 at skin):
- opacity mapping off (ParaView's default): the representation's SurfaceLooks (what the
  panel's Opacity column shows) say 1, and the image is the image of the same scene with a
  flat opacity map of 1: the drawn surface is as opaque as the column says;
- on: SurfaceLooks say the map's value at -500, and the image differs (the bone shows
  through the skin; the background through both);
- off again: the opaque image again;
- whatever the mapping, a surface opacity of 0.5 and the display's Opacity multiply what is
  drawn (SurfaceLooks 0.5 x 0.8), and with Color Each Surface the map never applies.
Run on the GPU path and on the CPU fallback (--expect-fallback, MEDISO_DISABLE_GPU_PATH=1):
both take each surface's look from the same place. Where the GL lacks what the GPU path
needs, the GPU run is skipped (exit 125).
"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)

import HistoPyramidRepresentationChecks as hp

args = hp.parse_args(expect_fallback=True)
check = hp.Checker()
name = "TestHistoPyramidRepresentationOpacityMapping" + ("Fallback" if args.expect_fallback else "")

LoadPlugin(args.plugin, ns=globals())
phantom = MedicalPhantom(Dimensions=[64, 64, 64], Spacing=[3.0, 3.0, 3.0])
view, display = hp.show_at(phantom, isovalues=(hp.SKIN,))

ColorBy(display, ("POINTS", "HU"))
display.RescaleTransferFunctionToDataRange(False, True)
lut = GetColorTransferFunction("HU")
pwf = GetOpacityTransferFunction("HU")
ramp = list(pwf.Points)  # ParaView's default: 0 at the minimum, 1 at the maximum
expected_map = pwf.GetClientSideObject().GetValue(hp.SKIN)

if args.expect_fallback:
    _, first_output = hp.captured(lambda: Render(view))
    check(first_output.count("Warning") == 1 and "MEDISO_DISABLE_GPU_PATH" in first_output,
          "one warning naming MEDISO_DISABLE_GPU_PATH (got %r)" % first_output.strip()[:300])
else:
    Render(view)
info = hp.render_info(display)
if not args.expect_fallback and info["path"] == "fallback":
    print("SKIP: the GPU path is not available here: %s" % info["reason"])
    sys.exit(125)
check(info["path"] == ("fallback" if args.expect_fallback else "gpu"), "path %r" % info["path"])


def looks():
    display.UpdatePropertyInformation()
    return [round(v, 6) for v in display.GetProperty("HistoPyramidSurfaceLooks")]


def shot(step):
    return hp.screenshot(view, os.path.join(args.out, "%s_%s.png" % (name, step)))


check(lut.EnableOpacityMapping == 0, "a new colour map has opacity mapping off (ParaView's default)")
check(0.02 < expected_map < 0.5 and len(ramp) >= 8,
      "the default opacity ramp gives skin %.3f (%s)" % (expected_map, ramp))

# 1. Off: as opaque as the Opacity column says.
off = shot("mapping_off")
check(looks()[3] == 1.0, "off: SurfaceLooks' opacity is 1 (%s)" % looks())
pwf.Points = [ramp[0], 1.0, 0.5, 0.0, ramp[-4], 1.0, 0.5, 0.0]
flat = shot("flat_map")
pwf.Points = ramp
check(hp.foreground_fraction(off) > 0.05, "off: the skin is drawn")
check(hp.changed_fraction(off, flat) < 0.001,
      "off: the image is the opaque image (%.4f of the pixels differ from a flat map of 1)"
      % hp.changed_fraction(off, flat))

# 2. On: translucent as mapped.
lut.EnableOpacityMapping = 1
on = shot("mapping_on")
check(abs(looks()[3] - expected_map) < 1e-6,
      "on: SurfaceLooks' opacity is the map's %.4f (%s)" % (expected_map, looks()))
check(hp.changed_fraction(on, off) > 0.05,
      "on: the skin is translucent (%.3f of the pixels change)" % hp.changed_fraction(on, off))

# 3. Off again.
lut.EnableOpacityMapping = 0
again = shot("mapping_off_again")
check(hp.changed_fraction(again, off) < 0.001, "off again: the opaque image again")

# 4. The surface's own opacity and Opacity multiply; Color Each Surface ignores the map.
display.HistoPyramidSurfaceOpacities = [0.5]
display.Opacity = 0.8
Render(view)
check(abs(looks()[3] - 0.4) < 1e-6, "off: 0.5 x Opacity 0.8 = 0.4 drawn (%s)" % looks())
lut.EnableOpacityMapping = 1
Render(view)
check(abs(looks()[3] - 0.4 * expected_map) < 1e-6,
      "on: map x 0.5 x 0.8 drawn (%s)" % looks())
display.HistoPyramidColorEachSurface = 1
display.HistoPyramidSurfaceColors = [0.2, 0.4, 0.6]
Render(view)
check(looks() == [0.2, 0.4, 0.6, 0.4], "Color Each Surface: its colour, the map not applied (%s)"
      % looks())

check.finish("%s: the opacity map applies only with opacity mapping on" % name)
