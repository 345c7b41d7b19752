"""The web client in Chromium against ParaView, on the same volume and scene.

    with-xvfb.sh pvpython --no-mpi TestWebPage.py gpu|cpu|nowebgl --plugin P --wasm DIR --out DIR

- gpu: the page's GPU path (the core on Chromium's software WebGL2) against the plugin's
  HistoPyramid Isosurface representation in pvpython: the same primitives as the representation
  and as the CPU model's count, and images that differ by more than 32 levels (of 255, any
  channel) in at most 2% of the pixels (two different software rasterisers: SwiftShader in
  Chromium, llvmpipe here).
- cpu: the page's CPU path (the BlockLOD core in WebAssembly) against the plugin's
  BlockLODContour: exactly its triangles at levels 3 and 1, and images within the same threshold.
- nowebgl: Chromium without WebGL: the page says so in words instead of staying blank.
- budget: a client memory budget the full volume exceeds: the page fetches a coarser level of it
  (each path its own), says so, and its bytes are that level's. The facts the page takes from
  its WebAssembly module (scalar types, levels and their strides) describe the server's levels.

The volume is the plugin's phantom at 72^3 written as a MetaImage; the page is served by
Python/serve.py on a free local port. Exits 125 (skip) where Chromium, node or the module are
missing.
"""
import argparse
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

parser = argparse.ArgumentParser()
parser.add_argument("case", choices=["gpu", "cpu", "nowebgl", "budget"])
parser.add_argument("--plugin", required=True)
parser.add_argument("--wasm", required=True)
parser.add_argument("--out", required=True)
args = parser.parse_args()

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "Python"))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)

check = Checks(verbose=True)


def skip(why):
    print("SKIP: " + why)
    sys.exit(125)


for need, why in [("/usr/bin/chromium", "Debian's chromium is not installed"),
                  (os.path.join(args.wasm, "mediso.wasm"), "the WebAssembly module is not built"),
                  (os.path.join(HERE, "node_modules", "playwright-core"),
                   "playwright-core is not installed (npm ci in Testing/Web)")]:
    if not os.path.exists(need):
        skip(why)
if not shutil.which("node"):
    skip("node is not installed")

os.makedirs(args.out, exist_ok=True)
from paraview.simple import *  # noqa: E402,F401,F403
from paraview import servermanager  # noqa: E402

LoadPlugin(args.plugin, ns=globals())

# --- the volume -------------------------------------------------------------------------------
volume = os.path.join(args.out, "phantom72.vti")
phantom = MedicalPhantom(Dimensions=[72, 72, 72], Spacing=[2.5, 2.5, 2.5])
SaveData(volume, proxy=phantom)
reader = OpenDataFile(volume)
reader.UpdatePipeline()
bounds = reader.GetDataInformation().GetBounds()
center = [0.5 * (bounds[2 * a] + bounds[2 * a + 1]) for a in range(3)]
direction = [0.45, -1.0, 0.55]
norm = sum(d * d for d in direction) ** 0.5
distance = 2.2 * max(bounds[2 * a + 1] - bounds[2 * a] for a in range(3))
camera = {"position": [center[a] + distance * direction[a] / norm for a in range(3)],
          "focalPoint": center, "viewUp": [0.0, 0.0, 1.0], "viewAngle": 30.0}
SIZE = [400, 300]
MATERIAL = {"ambient": 0.15, "diffuse": 0.8, "specular": 0.25, "specularPower": 30.0,
            "background": [0.1, 0.12, 0.16]}
BONE = {"value": 400.0, "color": [0.9, 0.82, 0.65], "opacity": 1.0}


# --- the page ---------------------------------------------------------------------------------
def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_server():
    port = free_port()
    token = "test-token-%d" % port
    command = [sys.executable if os.path.basename(sys.executable).startswith("pvpython")
               else shutil.which("pvpython"), "--no-mpi", os.path.join(ROOT, "Python", "serve.py"),
               "--plugin", args.plugin, "--wasm", args.wasm, "--data", volume,
               "--port", str(port), "--token=" + token]
    server = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    deadline = time.time() + 120
    while time.time() < deadline:
        line = server.stdout.readline()
        if not line:
            break
        print("server: " + line.rstrip(), flush=True)
        if "open http" in line:
            # the server's later output, read so that a full pipe never blocks it
            threading.Thread(target=lambda: [print("server: " + l.rstrip(), flush=True)
                                             for l in server.stdout], daemon=True).start()
            return server, "http://127.0.0.1:%d/?token=%s&size=%dx%d" % (port, token, SIZE[0], SIZE[1])
    stop_server(server)
    raise SystemExit("FAILED: the server did not start")


def stop_server(server):
    """Stops the server as Ctrl-C would (it stops its operations worker), killing it only if it
    does not stop in 20 s."""
    server.send_signal(signal.SIGINT)
    try:
        server.wait(timeout=20)
    except subprocess.TimeoutExpired:
        server.kill()
        server.wait()


def run_page(url, actions, name, extra=()):
    actions_file = os.path.join(args.out, name + "-actions.json")
    out_file = os.path.join(args.out, name + ".json")
    with open(actions_file, "w") as f:
        json.dump(actions, f)
    subprocess.run(["node", os.path.join(HERE, "page.mjs"), url, out_file, "--actions", actions_file]
                   + list(extra), check=True, cwd=HERE, timeout=600)
    with open(out_file) as f:
        result = json.load(f)
    for line in result.get("logs", []):
        print("page: " + line)
    return result


# --- ParaView's images --------------------------------------------------------------------------
def paraview_view():
    view = CreateView("RenderView")
    view.ViewSize = SIZE
    view.OrientationAxesVisibility = 0
    view.UseColorPaletteForBackground = 0
    view.Background = MATERIAL["background"]
    view.UseLight = 0  # no light kit: one headlight, as the page (VTK's default light)
    light = AddLight(view=view)
    light.Coords = "Headlight"
    light.Type = "Directional"
    light.Intensity = 1.0
    return view


def place_camera(view):
    # After the first render, which resets ParaView's camera to the data.
    Render(view)
    view.CameraPosition = camera["position"]
    view.CameraFocalPoint = camera["focalPoint"]
    view.CameraViewUp = camera["viewUp"]
    view.CameraViewAngle = camera["viewAngle"]
    Render(view)


def style(display):
    display.ColorArrayName = [None, ""]  # Solid Color
    display.AmbientColor = BONE["color"]
    display.DiffuseColor = BONE["color"]
    display.Ambient = MATERIAL["ambient"]
    display.Diffuse = MATERIAL["diffuse"]
    display.Specular = MATERIAL["specular"]
    display.SpecularPower = MATERIAL["specularPower"]


def differing(a_path, b_path, levels=32):
    from vtkmodules.vtkIOImage import vtkPNGReader
    from vtkmodules.util.numpy_support import vtk_to_numpy
    images = []
    for path in (a_path, b_path):
        r = vtkPNGReader()
        r.SetFileName(path)
        r.Update()
        image = r.GetOutput()
        images.append((image.GetDimensions(), vtk_to_numpy(image.GetPointData().GetScalars())[:, :3]))
    if images[0][0] != images[1][0]:
        return 1.0, "sizes %s and %s" % (images[0][0], images[1][0])
    difference = abs(images[0][1].astype(int) - images[1][1].astype(int)).max(axis=1)
    return float((difference > levels).mean()), "largest difference %d" % difference.max()


def compare(page_png, reference_png, what):
    fraction, note = differing(page_png, reference_png)
    check(fraction <= 0.02, "%s: %.2f%% of pixels differ by more than 32 levels (at most 2%%; %s)"
          % (what, 100 * fraction, note))


common = [{"call": "setLook", "args": [MATERIAL]}, {"call": "setView", "args": [camera]}]
if args.case == "budget":
    # The 72^3 int16 phantom is 0.75 MB: a 0.5 MB budget takes level 2 (36^3, 0.09 MB) for the GPU
    # path (the volume texture and the pyramid, as the module estimates them) and for the CPU path
    # (half the budget for the volume).
    server, url = start_server()
    try:
        results = {path: run_page(url + "&budget=0.5&path=" + path,
                                  [{"call": "facts"}, {"call": "estimates"}], "budget-" + path)
                   for path in ("gpu", "cpu")}
        with urllib.request.urlopen(url.replace("/?", "/api/datasets?")) as answer:
            described = json.load(answer)["datasets"][0]
    finally:
        stop_server(server)
    facts = results["gpu"]["results"][0]
    print("the module's facts: " + json.dumps(facts))
    strides = facts["levels"]["strides"]
    check(len(strides) == facts["levels"]["count"] == len(described["levels"])
          and len(results["gpu"]["results"][1]) == len(strides),
          "the module's levels (%d), the server's (%d) and the estimator's table (%d) agree in number"
          % (facts["levels"]["count"], len(described["levels"]), len(results["gpu"]["results"][1])))
    types = {t["name"]: t for t in facts["scalarTypes"]}
    check(described["type"] in types, "the server's type %s is one of the module's %s"
          % (described["type"], sorted(types)))
    # The server states two of the cores' facts itself (it cannot load the module): they must be
    # the ones the module hands the page.
    sys.path.insert(0, os.path.join(ROOT, "Python"))
    from serve_messages import LEVEL_STRIDES  # noqa: E402
    from serve_operations import SCALAR_TYPES  # noqa: E402
    check(list(LEVEL_STRIDES) == strides, "the server's LEVEL_STRIDES %s are the module's strides %s"
          % (list(LEVEL_STRIDES), strides))
    check(sorted(SCALAR_TYPES) == sorted(types), "the server's SCALAR_TYPES %s are the module's %s"
          % (sorted(SCALAR_TYPES), sorted(types)))
    size = types.get(described["type"], {}).get("bytes", 0)
    for k, (stride, level) in enumerate(zip(strides, described["levels"])):
        d = level["dims"]
        check(all(abs(level["spacing"][a] - stride * described["spacing"][a]) < 1e-9 for a in range(3))
              and level["bytes"] == size * d[0] * d[1] * d[2],
              "level %d: the server's spacing %s is the module's stride %d times %s, and its %d bytes "
              "are %s values of %d bytes" % (k, level["spacing"], stride, described["spacing"],
                                             level["bytes"], d, size))
    for path, result in results.items():
        stats = result["stats"]
        print("%s: level %d, %s" % (path, stats["level"], stats["levelNote"]))
        check(result["state"] == "ready", "%s: the page is ready" % path)
        check(stats["level"] == 2, "%s: the volume is fetched at level 2 (got %d)" % (path, stats["level"]))
        check("level 2" in stats["levelNote"] and "budget" in stats["levelNote"],
              "%s: the page says why it took level 2" % path)
        stride = strides[2]
        ordinal = "%d%s" % (stride, "th" if 11 <= stride % 100 <= 13 else
                            {1: "st", 2: "nd", 3: "rd"}.get(stride % 10, "th"))
        check("every %s point" % ordinal in stats["levelNote"],
              "%s: the note says every %s point" % (path, ordinal))
        check(stats["bytesReceived"] < 0.2 * 72 ** 3 * 2,
              "%s: the bytes received (%d) are those of the coarse level" % (path, stats["bytesReceived"]))
elif args.case == "nowebgl":
    server, url = start_server()
    try:
        result = run_page(url, [], "nowebgl", ["--no-webgl"])
    finally:
        stop_server(server)
    print("page says: " + result["unsupported"])
    check(result["state"] != "ready", "the page does not claim to be ready without WebGL")
    check("WebGL2" in result["unsupported"], "the page says that WebGL2 is missing")
elif args.case == "gpu":
    server, url = start_server()
    try:
        shot = os.path.join(args.out, "page-gpu.png")
        result = run_page(url + "&path=gpu", common + [
            {"call": "setSurfaces", "args": [[BONE]]},
            {"call": "cpuCount", "args": [[BONE["value"]]]},
            {"call": "shot", "args": [shot]}], "gpu")
        # The same page with a forced texture limit of 32 (the 72^3 phantom as 27 bricks of 24)
        # and a 3 MB GPU budget, and with a budget that the bricks bone crosses cannot fit.
        bricked_shot = os.path.join(args.out, "page-gpu-bricks.png")
        bricked = run_page(url + "&path=gpu&maxTextureSize=32&gpuBudgetMB=3", common + [
            {"call": "setSurfaces", "args": [[BONE]]},
            {"call": "shot", "args": [bricked_shot]}], "gpu-bricks")
        # (the refused frame's answer starts the fallback; the second call waits for its frame)
        refused = run_page(url + "&path=gpu&maxTextureSize=32&gpuBudgetMB=0.01", common + [
            {"call": "setSurfaces", "args": [[BONE]]},
            {"call": "setSurfaces", "args": [[BONE]]}], "gpu-over-budget")
    finally:
        stop_server(server)
    check(result["state"] == "ready", "the page is ready (%s)" % result["state"])
    stats = result["stats"]
    print("page stats: " + json.dumps({k: stats[k] for k in ("path", "reason", "primitives", "lastChangeMs")}))
    view = paraview_view()
    display = Show(reader, view)
    display.SetRepresentationType("HistoPyramid Isosurface")
    style(display)
    display.IsosurfaceValues = [BONE["value"]]
    place_camera(view)
    reference = os.path.join(args.out, "paraview-gpu.png")
    SaveScreenshot(reference, view, ImageResolution=SIZE)
    display.UpdatePropertyInformation()
    ours = int(display.GetPropertyValue("HistoPyramidPrimitives"))
    check(stats["path"] == "gpu", "the page drew with the GPU path")
    check(stats["primitives"] == result["results"][3] > 0,
          "the page's primitives (%d) equal the CPU model's count (%d)" % (stats["primitives"], result["results"][3]))
    check(stats["primitives"] == ours,
          "the page's primitives (%d) equal the ParaView mapper's (%d)" % (stats["primitives"], ours))
    compare(shot, reference, "the GPU path against ParaView's HistoPyramid Isosurface")
    b = bricked["stats"]
    print("bricked page stats: " + json.dumps({k: b[k] for k in ("path", "primitives", "bricks", "activeBricks",
                                                                "residentBricks")}))
    check(bricked["state"] == "ready" and b["path"] == "gpu" and b["bricks"] == 27 and
          0 < b["activeBricks"] <= b["residentBricks"] <= 27,
          "under a texture limit of 32 the page draws the phantom on the GPU path as 27 bricks "
          "(%d, %d active, %d resident)" % (b["bricks"], b["activeBricks"], b["residentBricks"]))
    check(b["primitives"] == stats["primitives"],
          "as bricks, the page's primitives (%d) are those of one texture (%d)" % (b["primitives"], stats["primitives"]))
    compare(bricked_shot, reference, "the GPU path as bricks against ParaView's HistoPyramid Isosurface")
    r = refused["stats"]
    print("over-budget page stats: " + json.dumps({k: r[k] for k in ("path", "reason", "triangles")}))
    check(refused["state"] == "ready" and r["path"] == "cpu" and r["triangles"] > 0 and
          "over the budget" in r["reason"],
          "with the bricks bone crosses over a 0.01 MB GPU budget the page falls back to the CPU "
          "path and says why (%s, %s)" % (r["path"], r["reason"]))
else:
    server, url = start_server()
    try:
        shots = [os.path.join(args.out, "page-cpu-level%d.png" % k) for k in (3, 1)]
        result = run_page(url + "&path=cpu", common + [
            {"call": "setSurfaces", "args": [[BONE]]},
            {"call": "setCPULevel", "args": [3]},
            {"call": "shot", "args": [shots[0]]},
            {"call": "setCPULevel", "args": [1]},
            {"call": "shot", "args": [shots[1]]}], "cpu")
    finally:
        stop_server(server)
    check(result["state"] == "ready", "the page is ready (%s)" % result["state"])
    levels = {3: result["results"][3], 1: result["results"][5]}
    view = paraview_view()
    for (k, page_stats), shot in zip(sorted(levels.items(), reverse=True), shots):
        contour = BlockLODContour(Input=reader, Isosurfaces=[BONE["value"]], LOD=k)
        contour.UpdatePipeline()
        triangles = contour.GetDataInformation().GetNumberOfCells()
        check(page_stats["path"] == "cpu" and page_stats["cpuLevel"] == k,
              "level %d: the page drew with the CPU path at that level" % k)
        check(page_stats["triangles"] == triangles,
              "level %d: the page's triangles (%d) equal BlockLODContour's (%d)"
              % (k, page_stats["triangles"], triangles))
        display = Show(contour, view)
        style(display)
        place_camera(view)
        reference = os.path.join(args.out, "paraview-cpu-level%d.png" % k)
        SaveScreenshot(reference, view, ImageResolution=SIZE)
        Hide(contour, view)
        compare(shot, reference, "level %d: the CPU path against ParaView's BlockLODContour" % k)

check.finish("TestWebPage %s passed" % args.case)
