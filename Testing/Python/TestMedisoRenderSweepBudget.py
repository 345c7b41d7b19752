#!/usr/bin/env python3
"""mediso-render --sweep under a GPU budget that some of its isovalues' bricks exceed.

    python3 TestMedisoRenderSweepBudget.py MEDISO_RENDER TEMP_DIR

Plain python3 (no ParaView). The volume is the distance from a corner (10 per point, 40^3 int16):
an isovalue crosses a shell of bricks that grows with the value, so under a budget of 0.15 MB the
sweep's higher isovalues cross more bricks than fit and the lower ones fit. The sweep must go on
past the isovalues over the budget (exit 0), say in one line how many there were (with the first
one's value and the scene's reason), and print its row over the others: their number in the
frames column and the largest of their primitives. Each isovalue is also drawn alone with
--iso, under the same budget, to find which ones are over it (exit 4, "over the budget") and
their primitives (--stats): the line's count, the row's frames and its primitives must agree.
A sweep where no isovalue fits exits 4 and says so.
"""
import json
import math
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)
from medisorender import write_short_volume  # noqa: E402

check = Checks()
SWEEP = 9
BUDGET = "0.15"


def write_radial(path, n):
    return write_short_volume(
        path, n, lambda x, y, z: int(round(10 * math.sqrt(x * x + y * y + z * z))))


def run(binary, args):
    p = subprocess.run([binary] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                       timeout=300)
    return p.returncode, p.stdout, p.stderr


def main():
    binary, temp = sys.argv[1], sys.argv[2]
    os.makedirs(temp, exist_ok=True)
    volume = os.path.join(temp, "radial.mha")
    write_radial(volume, 40)
    common = [volume, "--size", "64x64", "--gpu-budget-mb", BUDGET]

    code, out, err = run(binary, common + ["--sweep", str(SWEEP)])
    print(out + err)
    check(code == 0, "the sweep exits %d, expected 0 (it goes on past the isovalues over the "
          "budget)" % code)
    header = re.search(r"MET_SHORT \(([-0-9.e+]+)\.\.([-0-9.e+]+)\)", out)
    check(header is not None, "no data range in the header line")
    if header is None:
        return check.finish("TestMedisoRenderSweepBudget passed")
    lo, hi = float(header.group(1)), float(header.group(2))
    lines = [l for l in out.splitlines() if l.startswith("(sweep:") and "not drawn" in l]
    rows = [l.split() for l in out.splitlines() if l.startswith("sweep ")]
    check(len(lines) == 1, "one line about the isovalues over the budget, found %d" % len(lines))
    check(len(rows) == 1 and len(rows[0]) == 8, "one sweep row of 8 columns, found %s" % rows)

    # Each isovalue alone, as the sweep computes them, under the same budget.
    over, primitives = [], []
    for i in range(SWEEP):
        iso = lo + (hi - lo) * (i + 1) / (SWEEP + 1)
        code, out1, err1 = run(binary, common + ["--iso", repr(iso), "--stats"])
        if code == 4:
            check("over the budget" in err1, "iso %r: exit 4 without the budget's reason: %s"
                  % (iso, err1))
            over.append(iso)
        else:
            check(code == 0, "iso %r alone exits %d: %s" % (iso, code, err1))
            stats = [json.loads(l) for l in out1.splitlines() if l.startswith("{")]
            check(len(stats) == 1 and stats[0]["bricks"] > 0,
                  "iso %r alone: one --stats line, drawn as bricks" % iso)
            if stats:
                primitives.append(stats[0]["primitives"])
    print("alone: %d of %d over the budget (%s), primitives of the others %s"
          % (len(over), SWEEP, ", ".join("%g" % v for v in over), primitives))
    check(0 < len(over) < SWEEP, "the budget must leave some isovalues over it and some within "
          "(%d of %d over): the test's volume or budget no longer does" % (len(over), SWEEP))
    if lines:
        found = re.match(r"\(sweep: (\d+) of the (\d+) isovalues not drawn, .*; the row is over the "
                         r"other (\d+); the first, ([-0-9.e+]+): (.*)\)$", lines[0])
        check(found is not None, "the line does not read as expected: %s" % lines[0])
        if found:
            check(int(found.group(1)) == len(over) and int(found.group(2)) == SWEEP and
                  int(found.group(3)) == SWEEP - len(over),
                  "the line counts %s of %s over the budget, %s drawn; alone: %d of %d"
                  % (found.group(1), found.group(2), found.group(3), len(over), SWEEP))
            check(bool(over) and math.isclose(float(found.group(4)), over[0], rel_tol=1e-5),
                  "the line's first isovalue %s is not the first over the budget alone (%s)"
                  % (found.group(4), over[:1]))
            check("over the budget of" in found.group(5),
                  "the line does not give the scene's reason: %s" % found.group(5))
    if rows and len(rows[0]) == 8:
        check(int(rows[0][1]) == SWEEP - len(over),
              "the row's frames %s, expected the %d isovalues within the budget"
              % (rows[0][1], SWEEP - len(over)))
        check(bool(primitives) and int(rows[0][7]) == max(primitives),
              "the row's primitives %s, expected the largest of the drawn isovalues' %s"
              % (rows[0][7], primitives))

    # No isovalue fits: nothing to time, exit 4 with the line and the reason.
    code, out, err = run(binary, [volume, "--size", "64x64", "--gpu-budget-mb", "0.02",
                                  "--sweep", "3"])
    print(out + err)
    check(code == 4, "a sweep with no isovalue within the budget exits %d, expected 4" % code)
    check("(sweep: 3 of the 3 isovalues not drawn" in out, "the line is missing: %s" % out)
    check(not any(l.startswith("sweep ") for l in out.splitlines()), "a row with nothing drawn")
    check("no isovalue of the sweep fits the GPU budget" in err, "the reason is missing: %s" % err)
    return check.finish("TestMedisoRenderSweepBudget passed")


if __name__ == "__main__":
    sys.exit(main())
