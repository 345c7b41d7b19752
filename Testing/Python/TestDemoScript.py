"""pvpython test: the demo end to end, and what it promises (docs/demo.md).

Runs Python/demo.py (its arguments after --, e.g. the phantom at 64^3 and 2 frames) in its own
pvpython, on this test's X display, and checks what docs/demo.md says it writes: the four images
(skin.png, bone.png, skin_and_bone.png, histopyramid_skin_and_bone.png) exist at the requested size
and are not blank (a surface covers part of the view: at least 1% of the pixels differ from the
background); report.txt has every row: the machine, ParaView, the input, the image, the table's
header, a skin and a bone row with triangles, times and frames per second, the HistoPyramid row
and its description, ParaView's Contour for comparison, the estimates for levels 0..3, the note
on times, and the images.

    pvpython TestDemoScript.py --out DIR -- --plugin P --phantom --phantom-size 64 --frames 2
"""
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEMO = os.path.join(ROOT, "Python", "demo.py")
PVPYTHON = os.path.realpath("/proc/self/exe")
IMAGES = ("skin.png", "bone.png", "skin_and_bone.png", "histopyramid_skin_and_bone.png")
SIZE = (1024, 768)  # demo.py's default --size

check = Checks(verbose=True)
split = sys.argv.index("--")
out = sys.argv[sys.argv.index("--out") + 1]
demo_args = sys.argv[split + 1:] + ["--out", out]
for name in IMAGES + ("report.txt",):  # what an earlier run left must not pass for this one
    if os.path.exists(os.path.join(out, name)):
        os.remove(os.path.join(out, name))

done = subprocess.run([PVPYTHON, "--no-mpi", "--force-offscreen-rendering", DEMO] + demo_args,
                      stdin=subprocess.DEVNULL, timeout=600)
check(done.returncode == 0, "demo.py exits 0 (%d)" % done.returncode)


def covered(path):
    """(width, height, fraction of the pixels that differ from the corner's background)."""
    from HistoPyramidRepresentationChecks import read_png
    pixels = read_png(path)
    differs = (abs(pixels - pixels[0, 0]) > 10).any(axis=2)
    return pixels.shape[1], pixels.shape[0], float(differs.mean())


for name in IMAGES:
    path = os.path.join(out, name)
    if check(os.path.isfile(path), "%s written" % name):
        width, height, fraction = covered(path)
        check((width, height) == SIZE and fraction >= 0.01,
              "%s: %dx%d, %.1f%% of the pixels are not the background (at least 1%%)"
              % (name, width, height, 100 * fraction))

report = os.path.join(out, "report.txt")
text = open(report).read() if os.path.isfile(report) else ""
check(bool(text), "report.txt written")
number = r"[-+0-9.e]+"
ROWS = [
    ("the title", r"^MedicalIsosurfaces demo report$"),
    ("the machine", r"^machine: .+, \d+ cores, GL renderer: .+$"),
    ("ParaView's version", r"^ParaView \d+\.\d+\.\d+$"),
    ("the input", r"^input: .+$"),
    ("the input's geometry", r"^  dimensions \d+ x \d+ x \d+, spacing .+ mm, array '.+', range .+$"),
    ("the image and rotation", r"^image \d+x\d+, rotation of \d+ frames"),
    ("the table's header", r"^surface +iso \(HU\) +method +triangles +extract s +cached s +"
                           r"1st frame s +median frame +fps$"),
    ("the skin row", r"^skin +-500 BlockLODContour L3 +[1-9]\d* +(%s +){4}%s$" % (number, number)),
    ("the bone row", r"^bone +400 BlockLODContour L3 +[1-9]\d* +(%s +){4}%s$" % (number, number)),
    ("the HistoPyramid row", r"^both +-500,400 HistoPyramid \w+ +- +- +- +(%s +){2}%s$"
                             % (number, number)),
    ("the HistoPyramid description", r"^HistoPyramid Isosurface representation .*path \w+.*"
                                     r"\d+ active cell-isovalue pairs, GPU memory"),
    ("ParaView's Contour", r"^for comparison, ParaView's Contour on the same input: skin \d+ "
                           r"triangles in .+ s, bone \d+ triangles in .+ s$"),
    ("the estimates", r"^BlockLODContour estimated triangles per level 0\.\.3: skin \d+ / \d+ / "
                      r"\d+ / \d+; bone \d+ / \d+ / \d+ / \d+$"),
    ("the note on times", r"^\(extract s is a first, uncached extraction"),
    ("the images", r"^images: .*skin\.png, .*bone\.png, .*skin_and_bone\.png, "
                   r".*histopyramid_skin_and_bone\.png$"),
]
for what, pattern in ROWS:
    check(re.search(pattern, text, re.MULTILINE) is not None, "report.txt has %s" % what)
for name, row in (("skin", "skin "), ("bone", "bone ")):
    line = next((x for x in text.splitlines() if x.startswith(row)), "")
    fps = float(line.split()[-1]) if line else 0.0
    check(fps > 0, "%s: %g frames per second" % (name, fps))

check.finish("demo script: all checks passed")
