"""GUI test: the real ParaView GUI shows the plugin's panels (run under Xvfb, by pvpython).

    pvpython TestMedicalIsosurfacesGUI.py --paraview PATH --plugin-dir DIR --settings INI
                                          --baseline PNG --out DIR [--qch FILE]
                                          [--panels NAME ...] [--data MHA]

Starts the `paraview` executable once per session --panels names (by default
the phantom's seven below; TestMedicalIsosurfacesGUI_CT names the head CT's
ct-start, ct-preset and ct-drag), each with a fresh home holding
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
2d. "clip": the phantom as HistoPyramid Isosurface, skin opaque over bone, the
   representation's clipping plane through the centre but off; recorded events
   check Clip Plane in the panel: bone-coloured pixels where the unclipped view
   (captured first) showed skin, and the window against the baseline
   TestMedicalIsosurfacesGUI-clip.png beside --baseline;
3. "help": as 2, then recorded events: with Auto LOD the level control is
   disabled and shows the level used, the budget enabled; Auto LOD unchecked,
   the level is enabled and shows its setting, the budget disabled (QtTesting
   checks); then a click on the panel's "?" button, which must open ParaView's
   help window; the plugin's help collection (--qch) must hold the filter's and
   the source's pages, and the HistoPyramid Isosurface representation's page
   with the paper, the fallback paragraph and every property (qthelp.py, as
   TestPluginHelpCollection checks without the GUI).
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
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import time

import numpy
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkIOImage import vtkPNGWriter

import HistoPyramidRepresentationChecks as hp

# The sessions: the plugin's panels on the phantom (TestMedicalIsosurfacesGUI)
# and the head CT's start, a preset and a histogram drag (..._CT).
DEFAULT_PANELS = ["representation", "blocklod", "start", "apply", "mesh", "clip", "help"]
# How long the clip session's events wait before turning the plane on (the
# driver captures the unclipped view meanwhile).
CLIP_PAUSE_MS = 15000
CLIP_SCROLL_Y = 400
CT_PANELS = ["ct-start", "ct-preset", "ct-drag"]
parser = argparse.ArgumentParser()
parser.add_argument("--paraview", required=True)
parser.add_argument("--plugin-dir", required=True)
parser.add_argument("--settings", required=True)
parser.add_argument("--baseline", required=True)
parser.add_argument("--out", required=True)
parser.add_argument("--qch", help="the plugin's built help collection")
parser.add_argument("--panels", nargs="+", default=DEFAULT_PANELS,
                    help="the sessions to run (default: the phantom's seven; the CT's: " + " ".join(CT_PANELS) + ")")
parser.add_argument("--data", help="the head CT (.mha) for the ct- panels (default: the data cache's)")
args = parser.parse_args()


def wanted(panel):
    return panel in args.panels

for tool in ("xwd", "xwininfo"):
    if not shutil.which(tool):
        print("SKIP: %s is not installed (apt-get install x11-apps x11-utils)" % tool)
        sys.exit(125)

here = os.path.dirname(os.path.abspath(__file__))
scene = os.path.join(here, "MedicalIsosurfacesGUIScene.py")
NAME = "TestMedicalIsosurfacesGUI"
if any(wanted(panel) for panel in CT_PANELS):
    if not args.data:
        spec = importlib.util.spec_from_file_location(
            "fetch_data", os.path.join(here, "..", "..", "Python", "fetch_data.py"))
        fetch_data = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(fetch_data)
        args.data = str(fetch_data.resolve_cache_dir(None) / "ct_head.mha")
    if not os.path.isfile(args.data):
        print("SKIP: the head CT is not cached (%s); run python3 Python/fetch_data.py" % args.data)
        sys.exit(125)
    NAME = "TestMedicalIsosurfacesGUI_CT"
# The main window's area on the 1920x1080 screen, less the status bar.
CROP = (0, 0, 1400, 1020)  # x, y, width, height
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)
import qthelp  # noqa: E402  (Testing/Python/qthelp.py: the help collection's checks)

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
               MEDISO_GUI_STATUS=status, MEDISO_GUI_DATA=args.data or "")
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


def read_log(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        # Each entry ends with the time it was written (for reading by eye).
        return [json.loads(line)[:-1] for line in f if line.strip()]


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


def wait_for_playback(log, seconds):
    """Waits until QtTesting says the events have been played (its debug line
    in what paraview prints)."""
    deadline = time.time() + seconds
    while time.time() < deadline:
        log.flush()
        with open(log.name) as f:
            if "is finished." in f.read():
                return True
        time.sleep(0.5)
    return False


def stable_screen(seconds=60):
    """Captures a second apart until two agree; the last one. A screen of one
    colour does not count: the main window is not shown yet (paraview runs the
    scene script first, and a CT's first frames can take seconds)."""
    x, y, w, h = CROP
    previous = None
    deadline = time.time() + seconds
    while time.time() < deadline:
        time.sleep(1.0)
        screen = capture()[y:y + h, x:x + w]
        if (screen == screen[0, 0]).all():
            continue
        if previous is not None and numpy.array_equal(screen, previous):
            return screen
        previous = screen
    print("note: the screen never settled for two captures in %d s; using the last" % seconds)
    return previous


representation_screen = blocklod_screen = None

# --- 1. the representation's isovalue list ------------------------------------
if wanted("representation"):
    # Scrolled once the panel has its final height (the list's histogram is
    # counted after the panel is first laid out; earlier, the value is clamped).
    scroll = ('<pqevent object="pqClientMainWindow" command="pause" arguments="3000" />\n'
              '<pqevent object="pqClientMainWindow/propertiesDock/propertiesPanel/scrollArea/'
              'qt_scrollarea_vcontainer/1QScrollBar0" command="set_int" arguments="375" />')
    process, status_path, log = start_paraview("representation", scroll)
    status = wait_for(status_path, process, 120)
    if status:
        wait_for_playback(log, 60)
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
if wanted("blocklod"):
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
if wanted("start"):
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
if wanted("apply"):
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
if wanted("mesh"):
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

# --- 2d. the clip plane, turned on in the panel --------------------------------
# The phantom as HistoPyramid Isosurface, skin opaque over bone, seen from the
# front; the representation's Clip Plane set through the centre facing the
# camera (Invert: the front half goes) but off. The screen is captured (skin
# only: no bone-coloured pixels), then the recorded events check the plane's
# checkbox in the Properties panel (its display section applies at once) and
# hide the plane widget (its translucent plane would tint the view); the cut
# then shows bone inside the skin, where the unclipped view showed skin. The
# clipped window is compared with the baseline TestMedicalIsosurfacesGUI-clip.png
# next to --baseline (at most 0.5% of the pixels off by more than 40).
DISPLAY_PANEL = ("pqClientMainWindow/propertiesDock/propertiesPanel/scrollArea/qt_scrollarea_viewport/"
                 "scrollAreaWidgetContents/DisplayFrame/ProxyPanel")


def bone_and_skin(screen):
    """The view's pixels in bone's colour (0.96, 0.94, 0.86 shaded: grey-white,
    red and blue close) and in skin's (0.93, 0.75, 0.62: red well above blue),
    as two masks."""
    pixels = screen[210:1010, 570:1390].astype(int)
    redness = pixels[:, :, 0] - pixels[:, :, 2]
    return (pixels[:, :, 0] > 90) & (redness < 25), (pixels[:, :, 0] > 100) & (redness > 40)


clip_screen = None
if wanted("clip"):
    # The pause leaves the driver time to capture the unclipped view first.
    clip_events = "\n".join([
        '<pqevent object="pqClientMainWindow" command="pause" arguments="%d" />' % CLIP_PAUSE_MS,
        '<pqevent object="%s/HistoPyramidClipPlane/CheckBox" command="set_boolean" arguments="true" />'
        % DISPLAY_PANEL,
        '<pqcheck object="%s/HistoPyramidClipPlane/CheckBox" property="checked" arguments="true" />'
        % DISPLAY_PANEL,
        '<pqevent object="%s/InteractivePlane/show3DWidget" command="set_boolean" arguments="false" />'
        % DISPLAY_PANEL,
        # The panel scrolled to the plane's group and its checkbox.
        '<pqevent object="pqClientMainWindow/propertiesDock/propertiesPanel/scrollArea/'
        'qt_scrollarea_vcontainer/1QScrollBar0" command="set_int" arguments="%d" />' % CLIP_SCROLL_Y])
    process, status_path, log = start_paraview("clip", clip_events)
    status = wait_for(status_path, process, 120)
    time.sleep(3.0)
    unclipped_screen = stable_screen() if status else None
    unclipped_at = time.time()
    clip_status = wait_for(status_path + "-clip", process, 90) if status else None
    if clip_status:
        wait_for_playback(log, 60)
        time.sleep(2.0)
        clip_screen = stable_screen()
    stop_paraview("clip", process, log)
    if check(status is not None and unclipped_screen is not None and clip_status is not None,
             "clip: the scene ran and the panel's checkbox turned the clip plane on (%s)" % clip_status):
        check(status["clip_plane"] == 0 and unclipped_at < clip_status["time"],
              "clip: the unclipped view was captured before the plane was turned on (%.1f s before; "
              "raise CLIP_PAUSE_MS if not)" % (clip_status["time"] - unclipped_at))
        check(clip_status["clip_plane"] == 1 and clip_status["origin"] == [94.5, 94.5, 94.5]
              and clip_status["normal"] == [0.0, -1.0, 0.0] and clip_status["invert"] == 1,
              "clip: the plane on, through the centre, facing the camera (%s)" % clip_status)
        write_png(os.path.join(args.out, NAME + "-unclipped.png"), unclipped_screen)
        bone_before, skin_before = bone_and_skin(unclipped_screen)
        bone_after, _ = bone_and_skin(clip_screen)
        uncovered = int((bone_after & skin_before).sum())
        print("clip: %d pixels of bone colour where the unclipped view showed skin" % uncovered)
        check(int(bone_before.sum()) < 200 and uncovered > 5000,
              "clip: bone shows inside the cut skin (%d pixels of bone colour where the unclipped view "
              "showed skin; %d of bone colour before the cut)" % (uncovered, int(bone_before.sum())))

# --- 3. the "?" button opens the plugin's documentation ----------------------
# Before the click, the level-of-detail controls: with Auto LOD the level is
# disabled and shows the level used (2), the budget enabled; unchecked, the
# level is enabled and shows its setting (1), the budget disabled. A failed
# check makes QtTesting print a "critical:" line, which fails the test.
if wanted("help"):
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
    # The histogram above the levels (the phantom: -1000 to 1075 HU, the plot
    # 507 pixels wide at this dock width): bone's marker at 400 (x 348) dragged to
    # x 250, about 0 HU, edits the isovalue (1: rounded to whole HU) on release,
    # and the panel then has a change to apply (played first: the Auto LOD
    # events above leave one too).
    events[:0] = ['<pqevent object="%s/Histogram" command="mousePress" arguments="1,1,0,348,30" />' % levels,
               '<pqevent object="%s/Histogram" command="mouseMove" arguments="1,0,0,300,30" />' % levels,
               '<pqevent object="%s/Histogram" command="mouseMove" arguments="1,0,0,250,30" />' % levels,
               '<pqevent object="pqClientMainWindow" command="pause" arguments="1000" />',
               '<pqcheck object="%s" property="previewing" arguments="true" />' % levels,
               '<pqcheck object="pqClientMainWindow/propertiesDock/propertiesPanel/Accept" '
               'property="enabled" arguments="false" />',
               '<pqevent object="%s/Histogram" command="mouseRelease" arguments="1,0,0,250,30" />' % levels,
               '<pqcheck object="%s" property="previewing" arguments="false" />' % levels,
               '<pqcheck object="%s/Histogram" property="markerValues" arguments="1" />' % levels,
               '<pqcheck object="pqClientMainWindow/propertiesDock/propertiesPanel/Accept" '
               'property="enabled" arguments="true" />']
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
    # The drag's preview, from the renders the scene logged: during the drag a
    # Block LOD Contour that is not the filter (unregistered), at the preview's
    # level, with bone's value dragged below 400, drew triangles in place of the
    # filter's display; after the release the filter's display alone again.
    logged = [entry[1:] for entry in read_log(status_path + ".log") if entry[0] == "render"]
    renders = [drawn for drawn, _ in logged]
    undo_sets = sorted(set(sets for _, sets in logged))
    previews = [drawn for drawn in renders
                if any(not registered for registered, _, _, _ in drawn)]
    check(any(len(drawn) == 1 and drawn[0][2] == 1 and len(drawn[0][1]) == 1
              and 0.0 < drawn[0][1][0] < 400.0 and drawn[0][3] > 100 for drawn in previews),
          "help: dragging the histogram's marker rendered a preview (LOD 1, the dragged value, "
          "triangles) in place of the filter's display (%s)" % previews[-3:])
    check(bool(renders) and renders[-1] == [[True, [400.0], 1, status["triangles"]]] if status else False,
          "help: after the release the filter's display is back alone, unchanged until Apply (%s)"
          % renders[-1:])
    # The drag (an unapplied edit) and its preview add no undo step.
    check(len(undo_sets) == 1, "help: the undo stack kept its size through the drag (%s)" % undo_sets)
    check(opened, "help: the '?' button of Block LOD Contour opens ParaView's help window")
    if args.qch:
        # The filter's and the source's pages, and the representation's page with
        # its paper, fallback paragraph and every property (Testing/Python/qthelp.py).
        pages = qthelp.check_collection(
            check, args.qch, os.path.join(here, "..", "..", "Plugin", "MedicalIsosurfaces.xml"))
        print("help: the plugin's help collection holds %s" % sorted(pages))

# --- 4. the head CT: its start, a preset, a histogram drag (..._CT) ------------
# The CT shown as HistoPyramid Isosurface with nothing set; the Properties panel
# scrolled to the isovalue list and its histogram. The list's widgets, by path:
LIST = ("pqClientMainWindow/propertiesDock/propertiesPanel/scrollArea/qt_scrollarea_viewport/"
        "scrollAreaWidgetContents/DisplayFrame/ProxyPanel/medical_isosurface_list")
CT_RANGE = (-1024.0, 2986.0)
CT_SCROLL_Y = 330
HISTOGRAM_WIDTH = 519
# Scrolled once the panel has its final height (earlier, the scroll bar's
# range is still short and clamps the value).
CT_SCROLL = ('<pqevent object="pqClientMainWindow" command="pause" arguments="3000" />\n'
             '<pqevent object="pqClientMainWindow/propertiesDock/propertiesPanel/scrollArea/'
             'qt_scrollarea_vcontainer/1QScrollBar0" command="set_int" arguments="%d" />' % CT_SCROLL_Y)


def histogram_x(value):
    """Where the histogram draws a value (its widget's pixels): the plot spans
    the widget less half a marker handle and a pixel each side
    (pqMedicalHistogramWidget::plotRect); the widget's width is fixed by the
    dock's width in Testing/Data/GUI/ParaView5.11.0.ini."""
    side = 5.5
    return side + (value - CT_RANGE[0]) / (CT_RANGE[1] - CT_RANGE[0]) * (HISTOGRAM_WIDTH - 2 * side)


def wait_for_log(path, done, seconds):
    """Waits until done(values) holds for the values logged so far (None: no
    values needed) and the view has rendered since the last of them (a frame can
    take seconds here)."""
    deadline = time.time() + seconds
    while time.time() < deadline:
        entries = read_log(path)
        values = [entry[1] for entry in entries if entry[0] == "values"]
        if entries and entries[-1][0] == "render" and (done is None or values and done(values)):
            return True
        time.sleep(0.5)
    return False


def warm_pixels(screen):
    pixels = screen[210:1010, 570:1390].astype(int)
    return int(((pixels[:, :, 0] - pixels[:, :, 2] > 40) & (pixels[:, :, 0] > 100)).sum())


ct_screens = {}
if wanted("ct-start"):
    # The start: skin over bone, nothing typed; the histogram marks both.
    events = CT_SCROLL
    process, status_path, log = start_paraview("ct-start", events)
    status = wait_for(status_path, process, 120)
    if status:
        # The list gives skin and bone their look: one more render; then the
        # events' pause and scroll.
        wait_for_log(status_path + ".log", None, 120)
        wait_for_playback(log, 60)
    time.sleep(2.0)
    ct_screens["ct-start"] = stable_screen() if status else None
    if ct_screens["ct-start"] is not None:
        write_png(os.path.join(args.out, "%s-ct-start.png" % NAME), ct_screens["ct-start"])
    stop_paraview("ct-start", process, log)
    if check(status is not None and ct_screens["ct-start"] is not None,
             "ct-start: the scene script ran (status written)"):
        check(status["isovalues"] == [-500.0, 400.0],
              "ct-start: the CT's display starts at skin and bone (%s)" % status["isovalues"])
        warm = warm_pixels(ct_screens["ct-start"])
        check(warm > 5000, "ct-start: skin is drawn in skin colour (%d warm pixels in the view)" % warm)

if wanted("ct-preset"):
    # Add > Soft tissue (40 HU, its colour, opacity 0.5): a third row, marked
    # in the histogram, drawn (Color Each Surface stays on).
    events = "\n".join([
        CT_SCROLL,
        '<pqevent object="%s/Add/Presets" command="activate" arguments="Preset1" />' % LIST])
    process, status_path, log = start_paraview("ct-preset", events)
    status = wait_for(status_path, process, 120)
    if status:
        wait_for_log(status_path + ".log", lambda values: values[-1] == [-500.0, 400.0, 40.0], 120)
        wait_for_playback(log, 60)
    ct_screens["ct-preset"] = stable_screen() if status else None
    if ct_screens["ct-preset"] is not None:
        write_png(os.path.join(args.out, "%s-ct-preset.png" % NAME), ct_screens["ct-preset"])
    stop_paraview("ct-preset", process, log)
    values = [entry[1] for entry in read_log(status_path + ".log") if entry[0] == "values"]
    check(values[-1:] == [[-500.0, 400.0, 40.0]],
          "ct-preset: Add > Soft tissue makes the isovalues -500, 400, 40 (changes seen: %s)" % values)

if wanted("ct-drag"):
    # Bone's marker (400) dragged to about 1000 (cortical bone only) in three
    # moves, released; then Edit > Undo (one step: back to 400) and Redo. Each
    # preview renders the CT's surfaces on llvmpipe: seconds on a busy machine.
    y = 30
    target = 1000.0
    path = [histogram_x(400.0) + (histogram_x(target) - histogram_x(400.0)) * k / 3.0
            for k in range(4)]
    events = [CT_SCROLL,
              '<pqevent object="%s/Histogram" command="mousePress" arguments="1,1,0,%d,%d" />'
              % (LIST, round(path[0]), y)]
    for x in path[1:]:
        events.append('<pqevent object="%s/Histogram" command="mouseMove" arguments="1,0,0,%d,%d" />'
                      % (LIST, round(x), y))
        events.append('<pqevent object="pqClientMainWindow" command="pause" arguments="150" />')
    events += [
        '<pqevent object="%s/Histogram" command="mouseRelease" arguments="1,0,0,%d,%d" />'
        % (LIST, round(path[-1]), y),
        '<pqevent object="pqClientMainWindow" command="pause" arguments="1000" />',
        '<pqevent object="pqClientMainWindow/menubar/menu_Edit" command="activate" arguments="actionEditUndo" />',
        '<pqevent object="pqClientMainWindow" command="pause" arguments="1000" />',
        '<pqevent object="pqClientMainWindow/menubar/menu_Edit" command="activate" arguments="actionEditRedo" />']
    process, status_path, log = start_paraview("ct-drag", "\n".join(events))
    status = wait_for(status_path, process, 120)
    # Done when the log shows the commit, the undo and the redo.
    def redone(values):
        restores = [i for i, v in enumerate(values) if v == [-500.0, 400.0]]
        return (len(restores) >= 2 and restores[-1] == len(values) - 2
                and values[-1] == values[restores[0] + 1])

    if status:
        wait_for_playback(log, 300)
        wait_for_log(status_path + ".log", redone, 120)
    ct_screens["ct-drag"] = stable_screen() if status else None
    if ct_screens["ct-drag"] is not None:
        write_png(os.path.join(args.out, "%s-ct-drag.png" % NAME), ct_screens["ct-drag"])
    stop_paraview("ct-drag", process, log)
    entries = read_log(status_path + ".log")
    values = [entry[1] for entry in entries if entry[0] == "values"]
    if check(len(values) >= 5, "ct-drag: previews, the commit, Undo and Redo changed the isovalues (%s)" % values):
        dragged = values[-1]
        # One pixel of the plot is (range / plot width) HU: allow two.
        tolerance = 2.0 * (CT_RANGE[1] - CT_RANGE[0]) / (HISTOGRAM_WIDTH - 11.0)
        check(dragged[0] == -500.0 and abs(dragged[1] - target) <= tolerance
              and dragged[1] == round(dragged[1]),
              "ct-drag: bone dragged to an integer within %.0f HU of %g (%s)" % (tolerance, target, dragged))
        # values: previews..., the value before the drag put back, the commit, Undo, Redo.
        previews = values[:-4]
        check(len(previews) >= 2 and all(v[0] == -500.0 and 400.0 < v[1] <= dragged[1] + tolerance
                                         for v in previews),
              "ct-drag: the drag previewed values between 400 and the release (%s)" % previews)
        check(values[-4] == [-500.0, 400.0] and values[-3] == dragged,
              "ct-drag: on release the old value is put back and the dragged one set once (%s)" % values[-4:])
        check(values[-2] == [-500.0, 400.0],
              "ct-drag: one Edit > Undo goes back to the value before the drag (%s)" % values[-2])
        # Renders during the drag, before the release: the preview.
        first = next(i for i, entry in enumerate(entries) if entry[0] == "values")
        release = next(i for i in range(first, len(entries)) if entries[i] == ["values", [-500.0, 400.0]])
        renders = sum(1 for entry in entries[first:release] if entry[0] == "render")
        check(renders >= 2, "ct-drag: the view rendered %d times during the drag (at least 2)" % renders)


# --- the images ----------------------------------------------------------------
def compare_with_baseline(image, baseline_path, name):
    written = os.path.join(args.out, name + ".png")
    write_png(written, image)
    print("wrote %s" % written)
    if not os.path.exists(baseline_path):
        check(False, "no baseline %s: look at %s and copy it there" % (baseline_path, written))
        return
    baseline = hp.read_png(baseline_path)[::-1]  # bottom row first, as VTK reads it
    if check(baseline.shape == image.shape,
             "image size %s matches the baseline's %s" % (image.shape, baseline.shape)):
        differs = (numpy.abs(baseline.astype(int) - image.astype(int)) > 40).any(axis=2)
        fraction = float(differs.mean())
        check(fraction <= 0.005, "%s: %.3f%% of the pixels differ from the baseline (at most 0.5%%)"
              % (name, 100 * fraction))
        if fraction > 0:
            diff = numpy.where(differs[:, :, None], [255, 0, 255], image // 3).astype(numpy.uint8)
            write_png(os.path.join(args.out, name + "-diff.png"), diff)
        print("%s: %.3f%% of the pixels differ from the baseline" % (name, 100 * fraction))


if representation_screen is not None and blocklod_screen is not None:
    compare_with_baseline(numpy.concatenate([representation_screen, blocklod_screen], axis=1),
                          args.baseline, NAME)
if clip_screen is not None:
    compare_with_baseline(clip_screen, os.path.splitext(args.baseline)[0] + "-clip.png", NAME + "-clip")
if all(ct_screens.get(panel) is not None for panel in CT_PANELS):
    compare_with_baseline(numpy.concatenate([ct_screens[panel] for panel in CT_PANELS], axis=1),
                          args.baseline, NAME)

check.finish("GUI: all checks passed")
