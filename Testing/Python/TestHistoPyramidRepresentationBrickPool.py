"""pvpython test: the HistoPyramid Isosurface representation says whether the brick pool drew
its bricks and why not (issue 31), as its read-only HistoPyramidBrickPoolSlots and
HistoPyramidBrickPoolReason, decided again at each isovalue change.

A 64x64x100 MedicalPhantom under a GPU Memory Budget of 0.1 MB is kept as bricks of 8 points
(832 of them). At 1060 HU its 6 crossed bricks are drawn from a pool of 6 slots, at 1050 HU
its 10 from a pool of 10, and at 1060 HU again from a pool of 6 (the pool of 10 would take over
3x the memory of the 6 bricks' own pyramids: made again, smaller); at 1000 HU the pool cannot
hold its 16 within the budget (each crossed brick its own pyramid, the reason naming the
budget); at 900 HU the crossed bricks alone exceed the budget (the fallback, with that reason);
and back. Every GPU frame draws the primitives of the one-texture volume (the default budget)
at the same isovalue, and only the over-budget frame warns. The one-texture frames report no
pool and no reason. A machine whose GL lacks what the GPU path needs skips (exit 125).

Usage: pvpython TestHistoPyramidRepresentationBrickPool.py --plugin PATH --out DIR
"""
from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)

import HistoPyramidRepresentationChecks as hp

args = hp.parse_args()
check = hp.Checker()
LoadPlugin(args.plugin, ns=globals())

FEW, POOLED, OWN, OVER = 1060.0, 1050.0, 1000.0, 900.0
phantom = MedicalPhantom(Dimensions=[64, 64, 100], Spacing=[3.0, 3.0, 3.0])
view, display = hp.show_at(phantom, isovalues=[POOLED])
hp.first_render(view, display, check, expect_fallback=False)


def render(isovalue):
    """The frame at `isovalue`, with its messages captured: (its information, the messages)."""
    display.IsosurfaceValues = [isovalue]
    _, output = hp.captured(lambda: Render(view))
    info = hp.render_info(display)
    print("%g HU, budget %g MB: %s, bricks %s, %d primitives, %d pool slots, pool reason %r%s"
          % (isovalue, display.HistoPyramidGPUMemoryBudget, info["path"], info["bricks"],
             info["primitives"], info["pool_slots"], info["pool_reason"],
             ", fallback: " + info["reason"] if info["reason"] else ""))
    return info, output


# One texture: the primitives each isovalue's bricks must draw; no pool, no reason.
dense = {}
for iso in (FEW, POOLED, OWN):
    info, output = render(iso)
    dense[iso] = info["primitives"]
    check(info["path"] == "gpu" and info["bricks"][0] == 0 and info["primitives"] > 0 and
          info["pool_slots"] == 0 and info["pool_reason"] == "" and output.strip() == "",
          "%g HU, one texture: drawn on the GPU, no pool and no reason" % iso)

display.HistoPyramidGPUMemoryBudget = 0.1
warnings = 0
slots = {}  # each pooled isovalue's slots at its first frame as bricks
for iso in (FEW, POOLED, FEW, OWN, POOLED, OVER, POOLED, OWN, FEW):
    info, output = render(iso)
    warnings += output.count("Warning")
    if iso == OVER:
        check(info["path"] == "fallback" and "over the budget" in info["reason"] and
              "ERROR" not in output,
              "%g HU: the crossed bricks over the budget, the fallback says so (%r)"
              % (iso, info["reason"]))
        continue
    check(output.strip() == "", "%g HU: no message (got %r)" % (iso, output.strip()[:300]))
    check(info["path"] == "gpu" and info["bricks"][0] > 1 and info["bricks"][1] > 1 and
          info["primitives"] == dense[iso],
          "%g HU as bricks: the GPU path, the one texture's %d primitives (%s, %d)"
          % (iso, dense[iso], info["path"], info["primitives"]))
    if iso in (FEW, POOLED):
        slots.setdefault(iso, info["pool_slots"])
        check(info["pool_slots"] >= info["bricks"][1] and info["pool_reason"] == "" and
              info["pool_slots"] == slots[iso],
              "%g HU: the crossed bricks drawn from a pool of %d slots (%d at its first frame), "
              "no reason" % (iso, info["pool_slots"], slots[iso]))
    else:
        check(info["pool_slots"] == 0 and "budget of 0.1 MB" in info["pool_reason"],
              "%g HU: each crossed brick its own pyramid, the reason the budget (%r)"
              % (iso, info["pool_reason"]))
check(warnings == 1, "one warning, the over-budget frame's (got %d)" % warnings)
check(slots.get(FEW, 0) < slots.get(POOLED, 0),
      "fewer bricks, a smaller pool (%r)" % slots)

display.HistoPyramidGPUMemoryBudget = 0
info, _ = render(POOLED)
check(info["path"] == "gpu" and info["bricks"][0] == 0 and info["pool_slots"] == 0 and
      info["pool_reason"] == "", "the default budget: one texture again, no pool and no reason")

check.finish("HistoPyramid representation brick pool: all checks passed")
