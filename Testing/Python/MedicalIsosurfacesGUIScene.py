"""The scene TestMedicalIsosurfacesGUI shows in the real ParaView GUI (paraview --script).

Environment (set by the driver, Testing/Python/TestMedicalIsosurfacesGUI.py):
    MEDISO_GUI_PANEL   "representation": the phantom shown as HistoPyramid
                       Isosurface, selected, its panel showing the isovalue list
                       (skin 0.4 opaque over bone, a colour each);
                       "blocklod": Block LOD Contour with Auto LOD applied,
                       selected, its panel showing the estimator's table
                       "start": the phantom shown as HistoPyramid Isosurface
                       with nothing else set (the start: skin over bone);
                       "apply": the phantom shown as HistoPyramid Isosurface,
                       skin in pure red, selected: the driver's events add a
                       Block LOD Contour from the Filters menu and click Apply
                       "ct-start", "ct-preset", "ct-drag": the head CT
                       (MEDISO_GUI_DATA) shown as HistoPyramid Isosurface with
                       nothing set (its start: skin over bone); the driver's
                       events then add a preset, or drag a histogram marker
                       "mesh": the phantom as HistoPyramid Isosurface at -500,
                       400 and 5000 (outside the range: the panel's warning),
                       selected: the driver's events click Make Mesh; once the
                       mesh is drawn, what it is goes to MEDISO_GUI_STATUS
                       with "-mesh" appended
    "clip":            the phantom as HistoPyramid Isosurface, skin opaque over
                       bone, its Clip Plane through the centre facing the
                       camera but off, selected: the driver's events check its
                       checkbox in the panel; the first frame drawn with the
                       plane on is reported in MEDISO_GUI_STATUS + "-clip"
    MEDISO_GUI_STATUS  where to write what the proxies say, as JSON, once the
                       scene is set up (the driver waits for this file)
    MEDISO_GUI_DATA    the head CT (.mha) for the "ct-" panels

For the "ct-" panels, each change of the display's IsosurfaceValues and each
render of the view that ends is appended to MEDISO_GUI_STATUS + ".log" (one
JSON list a line: ["values", [...], time] or ["render", time]), so that the driver can tell
a drag's previews, its one committed change, and what Undo and Redo give.

The plugin is loaded by ParaView from PV_PLUGIN_PATH, as a user would.
"""
import json
import os
import time

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)

panel = os.environ["MEDISO_GUI_PANEL"]
status_path = os.environ["MEDISO_GUI_STATUS"]

view = GetActiveViewOrCreate("RenderView")
view.OrientationAxesVisibility = 0
view.UseColorPaletteForBackground = 0
view.Background = [0.1, 0.1, 0.15]

if panel.startswith("ct-"):
    head = OpenDataFile(os.environ["MEDISO_GUI_DATA"])
else:
    head = MedicalPhantom(Dimensions=[64, 64, 64], Spacing=[3.0, 3.0, 3.0])
display = Show(head, view)
status = {"panel": panel}
if panel == "representation":
    display.SetRepresentationType("HistoPyramid Isosurface")
    display.IsosurfaceValues = [-500.0, 400.0]
    display.HistoPyramidColorEachSurface = 1
    display.HistoPyramidSurfaceColors = [0.93, 0.75, 0.62, 0.96, 0.94, 0.86]
    display.HistoPyramidSurfaceOpacities = [0.4, 1.0]
    view.CameraPosition = [94.5, -300.0, 94.5]
    view.CameraFocalPoint = [94.5, 94.5, 94.5]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    Render(view)
    sub = display.SMProxy.GetProperty("HistoPyramidRenderPath").GetParent()
    sub.UpdatePropertyInformation()
    status.update({
        "representation": display.GetProperty("Representation").GetData(),
        "color_array": str(display.ColorArrayName[1]),
        "isovalues": list(display.IsosurfaceValues),
        "surface_colors": list(display.HistoPyramidSurfaceColors),
        "surface_opacities": list(display.HistoPyramidSurfaceOpacities),
        "color_each_surface": display.HistoPyramidColorEachSurface,
        "render_path": display.GetProperty("HistoPyramidRenderPath")[0],
        "primitives": display.GetProperty("HistoPyramidPrimitives")[0],
        "triangles": display.GetProperty("HistoPyramidFallbackTriangles")[0],
    })
    SetActiveSource(head)
elif panel == "start":
    display.SetRepresentationType("HistoPyramid Isosurface")
    view.CameraPosition = [94.5, -300.0, 94.5]
    view.CameraFocalPoint = [94.5, 94.5, 94.5]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    Render(view)
    status.update({"isovalues": list(display.IsosurfaceValues)})
    SetActiveSource(head)
elif panel == "apply":
    display.SetRepresentationType("HistoPyramid Isosurface")
    display.IsosurfaceValues = [-500.0]
    display.HistoPyramidColorEachSurface = 1
    display.HistoPyramidSurfaceColors = [1.0, 0.0, 0.0]
    display.HistoPyramidSurfaceOpacities = [1.0]
    view.CameraPosition = [94.5, -300.0, 94.5]
    view.CameraFocalPoint = [94.5, 94.5, 94.5]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    Render(view)
    status.update({"head_visible": display.Visibility})
    SetActiveSource(head)
elif panel.startswith("ct-"):
    # Nothing set: the display starts at skin and bone, and the list (once the
    # panel shows it) gives them their colours.
    display.SetRepresentationType("HistoPyramid Isosurface")
    # The face, from the front and a little to the side (as Python/demo.py).
    view.CameraPosition = [122.0 - 140.0, 122.0 + 400.0, 80.0 + 60.0]
    view.CameraFocalPoint = [122.0, 122.0, 80.0]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    Render(view)
    status.update({"isovalues": list(display.IsosurfaceValues)})
    log_path = status_path + ".log"

    def record(*entry):
        with open(log_path, "a") as log:
            log.write(json.dumps(list(entry) + [round(time.time(), 2)]) + "\n")

    display.SMProxy.GetProperty("IsosurfaceValues").AddObserver(
        "ModifiedEvent", lambda *_: record("values", list(display.IsosurfaceValues)))
    view.SMProxy.AddObserver("EndEvent", lambda *_: record("render"))
    SetActiveSource(head)
elif panel == "mesh":
    display.SetRepresentationType("HistoPyramid Isosurface")
    display.IsosurfaceValues = [-500.0, 400.0, 5000.0]
    display.HistoPyramidColorEachSurface = 1
    display.HistoPyramidSurfaceColors = [0.93, 0.75, 0.62, 0.96, 0.94, 0.86, 0.2, 0.2, 1.0]
    display.HistoPyramidSurfaceOpacities = [0.4, 1.0, 1.0]
    view.ResetCamera()
    Render(view)
    # What a Block LOD Contour of the drawn values makes at the level Auto LOD
    # chooses (3 here), to compare with the mesh the button makes.
    reference = BlockLODContour(Input=head, ContourBy=["POINTS", "HU"], Isosurfaces=[-500.0, 400.0],
                                LOD=3)
    reference.UpdatePipeline()
    status.update({"reference_triangles": reference.GetDataInformation().GetNumberOfCells(),
                   "head_visible": display.Visibility})
    Delete(reference)
    del reference

    def mesh_drawn(caller, event):
        mesh = FindSource("Mesh of MedicalPhantom1")
        if mesh is None or os.path.exists(status_path + "-mesh"):
            return
        contour = mesh.Input
        contour.UpdatePropertyInformation()
        mesh_status = {
            "triangles": mesh.GetDataInformation().GetNumberOfCells(),
            "contour_values": list(contour.GetPropertyValue("ContourValues")),
            "auto_lod": contour.GetPropertyValue("AutoLOD"),
            "chosen_level": contour.GetProperty("ChosenLevel")[0],
            "surface_names": list(mesh.SurfaceNames),
            "surface_colors": list(mesh.SurfaceColors),
            "head_visible": GetDisplayProperties(head, view).Visibility,
            "mesh_visible": GetDisplayProperties(mesh, view).Visibility,
        }
        with open(status_path + "-mesh.part", "w") as f:
            json.dump(mesh_status, f, indent=1)
        os.replace(status_path + "-mesh.part", status_path + "-mesh")

    # The button runs medical_isosurfaces.MakeMeshFromView, whose last step renders.
    view.SMProxy.AddObserver("EndEvent", mesh_drawn)
    SetActiveSource(head)
elif panel == "clip":
    # Skin opaque over bone, seen from the front; the clipping plane set
    # through the phantom's centre, facing the camera (Invert: the front half
    # goes), but off: the driver's events turn it on in the panel.
    display.SetRepresentationType("HistoPyramid Isosurface")
    display.IsosurfaceValues = [-500.0, 400.0]
    display.HistoPyramidColorEachSurface = 1
    display.HistoPyramidSurfaceColors = [0.93, 0.75, 0.62, 0.96, 0.94, 0.86]
    display.HistoPyramidSurfaceOpacities = [1.0, 1.0]
    display.HistoPyramidClipPlaneOrigin = [94.5, 94.5, 94.5]
    display.HistoPyramidClipPlaneNormal = [0.0, -1.0, 0.0]
    view.CameraPosition = [94.5, -300.0, 94.5]
    view.CameraFocalPoint = [94.5, 94.5, 94.5]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    Render(view)
    status.update({"clip_plane": display.HistoPyramidClipPlane,
                   "isovalues": list(display.IsosurfaceValues)})

    def clipped_drawn(caller, event):
        if display.HistoPyramidClipPlane != 1 or os.path.exists(status_path + "-clip"):
            return
        with open(status_path + "-clip.part", "w") as f:
            json.dump({"clip_plane": display.HistoPyramidClipPlane,
                       "origin": list(display.HistoPyramidClipPlaneOrigin),
                       "normal": list(display.HistoPyramidClipPlaneNormal),
                       "invert": display.HistoPyramidClipPlaneInvert,
                       "time": time.time()}, f, indent=1)
        os.replace(status_path + "-clip.part", status_path + "-clip")

    # The first frame drawn with the plane on (the checkbox applies at once,
    # as display properties do, and renders).
    view.SMProxy.AddObserver("EndEvent", clipped_drawn)
    SetActiveSource(head)
else:
    Hide(head, view)
    contour = BlockLODContour(Input=head, ContourBy=["POINTS", "HU"], Isosurfaces=[400.0], LOD=1)
    contour.AutoLOD = 1
    contour.MemoryBudget = 1.0  # MB: level 3 (about 1.2 MB here) does not fit, level 2 does
    contour_display = Show(contour, view)
    view.CameraPosition = [94.5, -300.0, 94.5]
    view.CameraFocalPoint = [94.5, 94.5, 94.5]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    Render(view)
    contour.UpdatePropertyInformation()
    status.update({
        "auto_lod": contour.AutoLOD,
        "lod": contour.LOD,
        "memory_budget": contour.MemoryBudget,
        "chosen_level": contour.GetProperty("ChosenLevel")[0],
        "estimated_triangles": list(contour.GetProperty("EstimatedTriangles")),
        "estimated_mb": list(contour.GetProperty("EstimatedMB")),
        "estimated_seconds": list(contour.GetProperty("EstimatedSeconds")),
        "triangles": contour.GetDataInformation().GetNumberOfCells(),
    })
    log_path = status_path + ".log"

    def record_render(caller, event):
        # What each render drew: every visible Block LOD Contour display, as
        # [registered (the filter) or not (a drag's preview), isovalues, LOD,
        # cells drawn], and the undo stack's size, so the driver can tell the
        # histogram drag's preview and that it left no undo step.
        drawn = []
        for representation in view.Representations:
            source = getattr(representation, "Input", None)
            if (source is None or representation.GetPropertyValue("Visibility") != 1
                    or source.SMProxy.GetXMLName() != "BlockLODContour"):
                continue
            info = representation.SMProxy.GetRepresentedDataInformation()
            drawn.append([source.SMProxy.GetSessionProxyManager().GetProxyName("sources", source.SMProxy)
                          is not None, list(source.GetPropertyValue("ContourValues")),
                          source.GetPropertyValue("LOD"),
                          info.GetNumberOfCells() if info else 0])
        undo = servermanager.vtkSMProxyManager.GetProxyManager().GetUndoStackBuilder()
        undo_sets = undo.GetUndoStack().GetNumberOfUndoSets() if undo and undo.GetUndoStack() else -1
        with open(log_path, "a") as log:
            log.write(json.dumps(["render", drawn, undo_sets, round(time.time(), 2)]) + "\n")

    view.SMProxy.AddObserver("EndEvent", record_render)
    SetActiveSource(contour)

with open(status_path + ".part", "w") as f:
    json.dump(status, f, indent=1)
os.replace(status_path + ".part", status_path)
