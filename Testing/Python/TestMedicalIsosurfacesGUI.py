"""GUI test: the real ParaView GUI shows the plugin's panels (run under Xvfb, by pvpython).

    pvpython TestMedicalIsosurfacesGUI.py --paraview PATH --plugin-dir DIR --settings INI
                                          --baseline PNG --out DIR [--qch FILE]

Starts the `paraview` executable six times, each with a fresh home holding
Testing/Data/GUI/ParaView5.11.0.ini (no welcome dialog, a left dock wide enough
to read), the plugin on PV_PLUGIN_PATH, and Testing/Python/MedicalIsosurfacesGUIScene.py
as its --script:
1. "representation": the phantom as HistoPyramid Isosurface, skin (opacity 0.4)
   over bone, a colour each; a recorded event (--test-script) scrolls the
   Properties panel down to the representation's isovalue list;
2. "blocklod": Block LOD Contour with Auto LOD and a 1 MB budget applied: its
   panel shows the estimator's table with the level used marked;
1b. "start": the phantom as HistoPyramid Isosurface, nothing else set: the
   display starts at -500 and 400 and the list gives skin its colour (warm
   pixels in the view);
2b. "apply": the phantom as HistoPyramid Isosurface (pure red skin); recorded
   events add Block LOD Contour from the Filters menu and click Apply: the
   phantom's display must be hidden (no red left on the screen);
2c. "mesh": the phantom as HistoPyramid Isosurface at -500, 400 and 5000
   (outside the range); recorded events check that the panel shows the range
   warning and click Make Mesh; the scene reports the mesh: the triangles of a
   Block LOD Contour of the drawn values at Auto LOD's level, each surface's
   name, colour and opacity, the phantom hidden (the representation's one
   warning about 5000 is expected in the log);
3. "help": as 2, then recorded events: with Auto LOD the level control is
   disabled and shows the level used, the budget enabled; Auto LOD unchecked,
   the level is enabled and shows its setting, the budget disabled (QtTesting
   checks); then a click on the panel's "?" button, which must open ParaView's
   help window; the plugin's help collection (--qch) must hold the filter's and
   the source's pages.
For 1 and 2, once the scene script has written its status (what the proxies
say, checked here), the screen is captured (xwd) until two captures a second
apart agree; the window's area above the status bar (which shows the memory in
use) is cropped, and the two crops side by side are compared with the baseline
image: at most 0.5% of the pixels may differ by more than 40 in a channel. The
image is written to --out whatever the result (to make or update the baseline:
look at it, then copy it to Testing/Data/Baseline/). Anything paraview prints
that looks like a VTK error or warning fails the test.
Skipped (exit 125) without xwd and xwininfo (Debian: x11-apps, x11-utils).
"""
import argparse
import json
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import time

import numpy
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkIOImage import vtkPNGWriter

import HistoPyramidRepresentationChecks as hp

parser = argparse.ArgumentParser()
parser.add_argument("--paraview", required=True)
parser.add_argument("--plugin-dir", required=True)
parser.add_argument("--settings", required=True)
parser.add_argument("--baseline", required=True)
parser.add_argument("--out", required=True)
parser.add_argument("--qch", help="the plugin's built help collection")
args = parser.parse_args()

for tool in ("xwd", "xwininfo"):
    if not shutil.which(tool):
        print("SKIP: %s is not installed (apt-get install x11-apps x11-utils)" % tool)
        sys.exit(125)

here = os.path.dirname(os.path.abspath(__file__))
scene = os.path.join(here, "MedicalIsosurfacesGUIScene.py")
NAME = "TestMedicalIsosurfacesGUI"
# The main window's area on the 1920x1080 screen, less the status bar.
CROP = (0, 0, 1400, 1020)  # x, y, width, height
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)

check = Checks()


def capture():
    """The Xvfb screen as an (h, w, 3) uint8 array (xwd of the root window,
    TrueColor, 24 or 32 bits per pixel)."""
    raw = subprocess.run(["xwd", "-root", "-silent"], capture_output=True, check=True).stdout
    header = numpy.frombuffer(raw[:100], dtype=">u4")
    header_size, width, height = int(header[0]), int(header[4]), int(header[5])
    byte_order, bits_per_pixel, bytes_per_line = int(header[7]), int(header[11]), int(header[12])
    colormap_entries = int(header[19])
    step = bits_per_pixel // 8
    start = header_size + 12 * colormap_entries
    rows = numpy.frombuffer(raw[start:start + height * bytes_per_line], dtype=numpy.uint8)
    pixels = rows.reshape(height, bytes_per_line)[:, :step * width].reshape(height, width, step)
    # Masks 0xff0000, 0xff00, 0xff: least significant byte first is B, G, R.
    return pixels[:, :, [2, 1, 0]] if byte_order == 0 else pixels[:, :, step - 3:step]


def write_png(path, pixels):
    h, w, _ = pixels.shape
    image = vtkImageData()
    image.SetDimensions(w, h, 1)
    array = numpy_to_vtk(numpy.ascontiguousarray(pixels[::-1]).reshape(-1, 3), deep=True)
    image.GetPointData().SetScalars(array)
    writer = vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.Write()


def start_paraview(panel, xml_events=None):
    home = os.path.join(args.out, "%s-home-%s" % (NAME, panel))
    shutil.rmtree(home, ignore_errors=True)
    os.makedirs(os.path.join(home, ".config", "ParaView"))
    shutil.copy(args.settings, os.path.join(home, ".config", "ParaView", "ParaView5.11.0.ini"))
    runtime = os.path.join(home, "runtime")
    os.makedirs(runtime, mode=0o700)
    status = os.path.join(home, "status.json")
    env = dict(os.environ, HOME=home, XDG_CONFIG_HOME=os.path.join(home, ".config"),
               XDG_RUNTIME_DIR=runtime, PV_PLUGIN_PATH=args.plugin_dir,
               MEDISO_GUI_PANEL="blocklod" if panel == "help" else panel,
               MEDISO_GUI_STATUS=status)
    command = [args.paraview, "-geometry", "1400x1050+0+0", "--script=" + scene]
    if xml_events:
        events = os.path.join(home, "events.xml")
        with open(events, "w") as f:
            f.write('<?xml version="1.0" ?>\n<pqevents>\n%s\n</pqevents>\n' % xml_events)
        command.append("--test-script=" + events)
    log = open(os.path.join(home, "paraview.log"), "w")
    process = subprocess.Popen(command, env=env, stdout=log, stderr=subprocess.STDOUT)
    return process, status, log


def wait_for(path, process, seconds):
    deadline = time.time() + seconds
    while time.time() < deadline and process.poll() is None:
        if os.path.exists(path):
            with open(path) as f:
                return json.load(f)
        time.sleep(0.5)
    return None


def stop_paraview(panel, process, log, expected=None):
    """Kill paraview (SIGKILL: nothing more to print) and check what it printed: no error or
    warning, except one warning containing `expected` (and its VTK header line) when given."""
    if process.poll() is None:
        process.send_signal(signal.SIGKILL)
    process.wait()
    log.close()
    with open(log.name) as f:
        lines = f.read().splitlines()
    bad = [line for line in lines
           if "ERROR" in line or "Warning: In" in line or " ERR|" in line or " WARN|" in line
           or "critical:" in line or "Traceback" in line]
    if expected is not None:
        said = [i for i, line in enumerate(lines) if expected in line]
        check(len(said) == 1, "%s: one warning saying %r (%d)" % (panel, expected, len(said)))
        # The warning and the "Warning: In file, line N" header VTK prints above it.
        allowed = set(lines[i] for i in said) | set(lines[i - 1] for i in said if i > 0)
        bad = [line for line in bad if line not in allowed]
    check(not bad, "%s: paraview printed no error or warning (got %r)" % (panel, bad[:5]))


def stable_screen(seconds=60):
    """Captures a second apart until two agree; the last one."""
    x, y, w, h = CROP
    previous = None
    deadline = time.time() + seconds
    while time.time() < deadline:
        time.sleep(1.0)
        screen = capture()[y:y + h, x:x + w]
        if previous is not None and numpy.array_equal(screen, previous):
            return screen
        previous = screen
    print("note: the screen never settled for two captures in %d s; using the last" % seconds)
    return previous


# --- 1. the representation's isovalue list ------------------------------------
scroll = ('<pqevent object="pqClientMainWindow/propertiesDock/propertiesPanel/scrollArea/'
          'qt_scrollarea_vcontainer/1QScrollBar0" command="set_int" arguments="285" />')
process, status_path, log = start_paraview("representation", scroll)
status = wait_for(status_path, process, 120)
# As for 1b and 2b: the window may not be painted yet when the status is
# written (a black screen was captured twice a second apart under load).
time.sleep(3.0)
representation_screen = stable_screen() if status else None
stop_paraview("representation", process, log)
if check(status is not None, "representation: the scene script ran (status written)"):
    check(status["representation"] == "HistoPyramid Isosurface" and status["color_array"] == ""
          and status["isovalues"] == [-500.0, 400.0],
          "representation: HistoPyramid Isosurface, Solid Color, isovalues -500 and 400 (%s)" % status)
    check(status["render_path"] in ("gpu", "fallback")
          and (status["primitives"] > 1000 or status["triangles"] > 1000),
          "representation: drawn (path %s, %d primitives, %d triangles)"
          % (status["render_path"], status["primitives"], status["triangles"]))

# --- 2. Block LOD Contour's estimator table -----------------------------------
process, status_path, log = start_paraview("blocklod")
status = wait_for(status_path, process, 120)
blocklod_screen = stable_screen() if status else None
stop_paraview("blocklod", process, log)
if check(status is not None, "blocklod: the scene script ran (status written)"):
    triangles = status["estimated_triangles"]
    megabytes = status["estimated_mb"]
    check(status["auto_lod"] == 1 and len(triangles) == 4 and len(megabytes) == 4
          and all(0 < triangles[i] < triangles[i + 1] for i in range(3)),
          "blocklod: Auto LOD on, four growing estimates (%s)" % triangles)
    check(status["chosen_level"] == 2 and megabytes[2] <= 1.0 < megabytes[3],
          "blocklod: the budget of 1 MB chose level 2, the highest that fits (%s, %s MB)"
          % (status["chosen_level"], megabytes))

# --- 1b. the start: skin over bone without a number typed -----------------------
# The phantom shown as HistoPyramid Isosurface, nothing else set: the display
# starts at -500 and 400 (pvpython sees that too), and the isosurface list, once
# the panel shows it, gives skin its colour and translucency over bone: warm
# (skin-coloured) pixels in the view, where the values alone draw grey-white.
process, status_path, log = start_paraview("start")
status = wait_for(status_path, process, 120)
time.sleep(3.0)
start_screen = stable_screen() if status else None
stop_paraview("start", process, log)
if check(status is not None and start_screen is not None, "start: the scene script ran (status written)"):
    check(status["isovalues"] == [-500.0, 400.0],
          "start: the phantom's display starts at skin and bone (%s)" % status["isovalues"])
    pixels = start_screen[210:1010, 570:1390].astype(int)
    warm = (pixels[:, :, 0] - pixels[:, :, 2] > 40) & (pixels[:, :, 0] > 100)
    write_png(os.path.join(args.out, NAME + "-start.png"), start_screen)
    check(int(warm.sum()) > 5000,
          "start: skin is drawn in skin colour (%d warm pixels in the view)" % int(warm.sum()))

# --- 2b. Apply on Block LOD Contour hides its input ---------------------------
# The phantom is drawn as HistoPyramid Isosurface with pure red skin; the
# events add a Block LOD Contour from the Filters menu (it starts at bone, 400)
# and click Apply, which (pqApplyBehavior, the filter's Visibility hint) shows
# the contour and must hide the phantom: no red left on the screen.
accept = ('<pqevent object="pqClientMainWindow/menubar/menuFilters/Alphabetical" '
          'command="activate" arguments="BlockLODContour" />\n'
          '<pqevent object="pqClientMainWindow/propertiesDock/propertiesPanel/Accept" '
          'command="activate" arguments="" />')
process, status_path, log = start_paraview("apply", accept)
status = wait_for(status_path, process, 120)
time.sleep(3.0)
apply_screen = stable_screen() if status else None
stop_paraview("apply", process, log)
if check(status is not None and apply_screen is not None, "apply: the scene script ran (status written)"):
    check(status["head_visible"] == 1, "apply: the phantom was shown before Apply")
    # The render view's area (the panels have red icons: Delete, clear).
    pixels = apply_screen[210:1010, 570:1390].astype(int)
    red = (pixels[:, :, 0] > 120) & (pixels[:, :, 1] < 60) & (pixels[:, :, 2] < 60)
    write_png(os.path.join(args.out, NAME + "-apply.png"), apply_screen)
    check(int(red.sum()) < 50,
          "apply: after Apply the phantom's red skin is hidden (%d red pixels in the view)" % int(red.sum()))

# --- 2c. Make Mesh, and the out-of-range warning ------------------------------
# The phantom as HistoPyramid Isosurface at -500, 400 and 5000 (outside its
# range): the recorded events check that the panel shows the warning, then
# click Make Mesh. The scene script reports the mesh once it is drawn: the
# triangles of a Block LOD Contour of the two drawn values at the level Auto LOD
# chooses, the colours and names carried, the phantom hidden and the mesh shown.
# The representation's one warning about 5000 is expected in the log.
panel_list = ("pqClientMainWindow/propertiesDock/propertiesPanel/scrollArea/qt_scrollarea_viewport/"
              "scrollAreaWidgetContents/DisplayFrame/ProxyPanel/medical_isosurface_list")
mesh_events = ('<pqcheck object="%s/RangeWarning" property="visible" arguments="true" />\n'
               '<pqevent object="%s/MakeMesh" command="activate" arguments="" />'
               % (panel_list, panel_list))
process, status_path, log = start_paraview("mesh", mesh_events)
status = wait_for(status_path, process, 120)
mesh_status = wait_for(status_path + "-mesh", process, 90) if status else None
stop_paraview("mesh", process, log,
              expected="isovalue 5000 is outside the range")
if check(status is not None and mesh_status is not None,
         "mesh: the scene ran and Make Mesh made a mesh (%s)" % mesh_status):
    check(status["head_visible"] == 1 and mesh_status["head_visible"] == 0
          and mesh_status["mesh_visible"] == 1,
          "mesh: the phantom's display hidden, the mesh shown")
    check(mesh_status["contour_values"] == [-500.0, 400.0] and mesh_status["auto_lod"] == 1
          and mesh_status["chosen_level"] == 3
          and mesh_status["triangles"] == status["reference_triangles"] > 1000,
          "mesh: the drawn values (5000 left out) at Auto LOD's level 3, the Block LOD "
          "Contour's %d triangles (%d)" % (status["reference_triangles"], mesh_status["triangles"]))
    check(mesh_status["surface_names"] == ["HU -500", "HU 400"]
          and [round(c, 4) for c in mesh_status["surface_colors"]]
          == [0.93, 0.75, 0.62, 0.4, 0.96, 0.94, 0.86, 1.0],
          "mesh: each surface's name, colour and opacity carried (%s)" % mesh_status)

# --- 3. the "?" button opens the plugin's documentation ----------------------
# Before the click, the level-of-detail controls: with Auto LOD the level is
# disabled and shows the level used (2), the budget enabled; unchecked, the
# level is enabled and shows its setting (1), the budget disabled. A failed
# check makes QtTesting print a "critical:" line, which fails the test.
levels = ("pqClientMainWindow/propertiesDock/propertiesPanel/scrollArea/qt_scrollarea_viewport/"
          "scrollAreaWidgetContents/PropertiesFrame/ProxyPanel/medical_blocklod_levels")
checks = [("LOD", "enabled", "false"), ("MemoryBudget", "enabled", "true"), ("LOD", "value", "2"),
          None,
          ("LOD", "enabled", "true"), ("MemoryBudget", "enabled", "false"), ("LOD", "value", "1")]
events = []
for entry in checks:
    if entry is None:
        events.append('<pqevent object="%s/AutoLOD" command="set_boolean" arguments="false" />' % levels)
    else:
        events.append('<pqcheck object="%s/%s" property="%s" arguments="%s" />' % ((levels,) + entry))
events.append('<pqevent object="pqClientMainWindow/propertiesDock/propertiesPanel/Help" '
              'command="activate" arguments="" />')
process, status_path, log = start_paraview("help", "\n".join(events))
status = wait_for(status_path, process, 120)
opened = False
deadline = time.time() + 60
while status and not opened and time.time() < deadline:
    time.sleep(1.0)
    info = subprocess.run(["xwininfo", "-name", "ParaView Online Help"],
                          capture_output=True, text=True)
    opened = info.returncode == 0 and "IsViewable" in info.stdout
stop_paraview("help", process, log)
check(opened, "help: the '?' button of Block LOD Contour opens ParaView's help window")
if args.qch:
    try:
        pages = {row[0] for row in sqlite3.connect(args.qch).execute("SELECT Name FROM FileNameTable")}
    except sqlite3.Error as error:
        pages = set()
        print("note: %s: %s" % (args.qch, error))
    check({"filters.BlockLODContour.html", "sources.MedicalPhantom.html"} <= pages,
          "help: the plugin's help collection holds its pages (%s)" % sorted(pages))

# --- the image ---------------------------------------------------------------
if representation_screen is not None and blocklod_screen is not None:
    image = numpy.concatenate([representation_screen, blocklod_screen], axis=1)
    written = os.path.join(args.out, NAME + ".png")
    write_png(written, image)
    print("wrote %s" % written)
    if not os.path.exists(args.baseline):
        check(False, "no baseline %s: look at %s and copy it there" % (args.baseline, written))
    else:
        baseline = hp.read_png(args.baseline)[::-1]  # bottom row first, as VTK reads it
        if check(baseline.shape == image.shape,
                 "image size %s matches the baseline's %s" % (image.shape, baseline.shape)):
            differs = (numpy.abs(baseline.astype(int) - image.astype(int)) > 40).any(axis=2)
            fraction = float(differs.mean())
            check(fraction <= 0.005, "%.3f%% of the pixels differ from the baseline (at most 0.5%%)"
                  % (100 * fraction))
            if fraction > 0:
                diff = numpy.where(differs[:, :, None], [255, 0, 255], image // 3).astype(numpy.uint8)
                write_png(os.path.join(args.out, NAME + "-diff.png"), diff)
            print("%.3f%% of the pixels differ from the baseline" % (100 * fraction))

check.finish("GUI: all checks passed")
