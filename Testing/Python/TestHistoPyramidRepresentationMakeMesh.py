"""pvpython test: the surfaces of a 'HistoPyramid Isosurface' display as a mesh to save.

    pvpython TestHistoPyramidRepresentationMakeMesh.py --plugin PATH --out DIR

medical_isosurfaces.MakeMeshFromView() (the plugin's Python module; the panel's Make Mesh
button runs it) on MedicalPhantom shown as HistoPyramid Isosurface, skin -500 (0.4) over
bone 400, a colour each:
- the mesh has exactly the triangles of a Block LOD Contour of the input at the same
  isovalues and level (point coordinates and connectivity equal), by default the level Auto
  LOD chooses (the finest the estimator fits in the budget: 3 here; 2 with a 0.2 MB budget
  set on the mesh's contour), and at a level asked for (1);
- each triangle's SurfaceIndex is the surface of its isovalue, its SurfaceColor the colour
  and opacity the view draws that surface with (the representation's SurfaceLooks); field
  data names each surface, counts its triangles (those of a one-isovalue Block LOD Contour);
- coloured by the HU colour map instead, the mesh takes the map's colours at the values,
  opaque while the map's opacity mapping is off; surfaces the view does not draw
  (opacity 0, a value outside the data range) are left out;
- the display is hidden and the mesh shown in its colours;
- saved as STL, PLY (with its colours) and VTP and read back: the same triangles,
  colours and names;
- bad calls (a display not shown as HistoPyramid Isosurface, level 5) raise ValueError.
"""
import math
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)
from paraview import servermanager
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOGeometry import vtkSTLReader
from vtkmodules.vtkIOPLY import vtkPLYReader
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

import HistoPyramidRepresentationChecks as hp

args = hp.parse_args()
check = hp.Checker()
os.makedirs(args.out, exist_ok=True)

LoadPlugin(args.plugin, ns=globals())
import medical_isosurfaces  # noqa: E402  (embedded in the plugin: importable once it is loaded)

phantom = MedicalPhantom(Dimensions=[64, 64, 64], Spacing=[3.0, 3.0, 3.0])
phantom.UpdatePipeline()
view = hp.make_view()
display = Show(phantom, view)
display.SetRepresentationType(hp.REPRESENTATION)
display.IsosurfaceValues = [hp.SKIN, hp.BONE]
display.HistoPyramidColorEachSurface = 1
SKIN_RGB, BONE_RGB = [0.93, 0.75, 0.62], [0.96, 0.94, 0.86]
display.HistoPyramidSurfaceColors = SKIN_RGB + BONE_RGB
display.HistoPyramidSurfaceOpacities = [0.4, 1.0]
view.ResetCamera()
Render(view)


def fetch(proxy):
    proxy.UpdatePipeline()
    data = servermanager.Fetch(proxy)
    return data


def arrays_equal(a, b):
    return a.shape == b.shape and bool((a == b).all())


def same_triangles(mesh, reference, what):
    """Counts, point coordinates and connectivity equal."""
    ok = check(mesh.GetNumberOfCells() == reference.GetNumberOfCells() > 0
               and mesh.GetNumberOfPoints() == reference.GetNumberOfPoints(),
               "%s: %d triangles, %d points as the Block LOD Contour's (%d, %d)"
               % (what, mesh.GetNumberOfCells(), mesh.GetNumberOfPoints(),
                  reference.GetNumberOfCells(), reference.GetNumberOfPoints()))
    if ok:
        points = arrays_equal(vtk_to_numpy(mesh.GetPoints().GetData()),
                              vtk_to_numpy(reference.GetPoints().GetData()))
        cells = arrays_equal(vtk_to_numpy(mesh.GetPolys().GetConnectivityArray()),
                             vtk_to_numpy(reference.GetPolys().GetConnectivityArray()))
        check(points and cells, "%s: the same point coordinates (%s) and connectivity (%s)"
              % (what, points, cells))


def reference_contour(values, level=None, budget=None):
    contour = BlockLODContour(Input=phantom)
    contour.SetPropertyWithName("SelectInputScalars", ["POINTS", "HU"])
    contour.SetPropertyWithName("ContourValues", values)
    contour.SetPropertyWithName("AutoLOD", 0)
    contour.SetPropertyWithName("LOD", level)
    data = fetch(contour)
    Delete(contour)
    return data


def looks_of(display):
    display.UpdatePropertyInformation()
    return list(display.GetProperty("HistoPyramidSurfaceLooks"))


def contour_of(mesh):
    return mesh.GetProperty("Input").GetProxy(0)


# --- 1. the default level: what Auto LOD chooses -------------------------------
looks = looks_of(display)
check(len(looks) == 8 and [round(v, 6) for v in looks] == SKIN_RGB + [0.4] + BONE_RGB + [1.0],
      "the view's looks: skin and bone colours, skin 0.4 (%s)" % looks)
mesh_proxy = medical_isosurfaces.MakeMeshFromView(display, view)
contour = servermanager._getPyProxy(contour_of(mesh_proxy))
contour.UpdatePropertyInformation()
chosen = contour.GetProperty("ChosenLevel")[0]
check(contour.GetPropertyValue("AutoLOD") == 1 and chosen == 3,
      "default: Auto LOD, level 3 chosen on a 64^3 phantom in 256 MB (%s)" % chosen)
check(list(contour.GetPropertyValue("ContourValues")) == [hp.SKIN, hp.BONE]
      and list(contour.GetPropertyValue("SelectInputScalars"))[-1] == "HU",
      "the contour: the display's isovalues and array")
mesh = fetch(mesh_proxy)
same_triangles(mesh, reference_contour([hp.SKIN, hp.BONE], level=3), "default (Auto LOD)")

# Each triangle's surface and colour.
index = vtk_to_numpy(mesh.GetCellData().GetArray("SurfaceIndex"))
colors = vtk_to_numpy(mesh.GetCellData().GetArray("SurfaceColor"))
isovalue = vtk_to_numpy(mesh.GetPointData().GetArray("Isovalue"))
first_point = vtk_to_numpy(mesh.GetPolys().GetConnectivityArray())[0::3]
expected_index = (isovalue[first_point] > 0).astype(int)  # -500 -> 0, 400 -> 1
check(arrays_equal(index, expected_index), "SurfaceIndex is each triangle's surface")
rgba = [[int(round(255 * c)) for c in looks[4 * s:4 * s + 4]] for s in range(2)]
check(all((colors[index == s] == rgba[s]).all() for s in range(2)),
      "SurfaceColor is the colour and opacity the view draws each surface with (%s)" % rgba)
field = mesh.GetFieldData()
names = [field.GetAbstractArray("SurfaceNames").GetValue(i) for i in range(2)]
check(names == ["HU -500", "HU 400"], "the surfaces' names (%s)" % names)
counts = list(vtk_to_numpy(field.GetArray("SurfaceTriangles")))
singles = [reference_contour([v], level=3).GetNumberOfCells() for v in (hp.SKIN, hp.BONE)]
check(counts == singles and sum(counts) == mesh.GetNumberOfCells(),
      "SurfaceTriangles per surface %s as one-isovalue contours %s" % (counts, singles))

# Shown in place of the display, in its colours.
mesh_display = GetDisplayProperties(mesh_proxy, view)
mesh_lut = mesh_display.LookupTable
check(display.Visibility == 0 and mesh_display.Visibility == 1
      and mesh_display.ColorArrayName[1] == "SurfaceIndex" and mesh_display.UseSeparateColorMap == 1
      and mesh_lut.InterpretValuesAsCategories == 1
      and list(mesh_lut.Annotations) == ["0", "HU -500", "1", "HU 400"]
      and [round(c, 6) for c in mesh_lut.IndexedColors] == SKIN_RGB + BONE_RGB
      and mesh_lut.EnableOpacityMapping == 1,
      "the display hidden, the mesh shown by surface: a colour map of its own naming each "
      "surface, in its colour, with its opacity")
pixels = hp.screenshot(view, os.path.join(args.out, "TestHistoPyramidRepresentationMakeMesh.png"))
check(hp.foreground_fraction(pixels) > 0.05, "the mesh is drawn")

# A smaller budget on the mesh's contour: Auto LOD drops to the level that fits.
contour.SetPropertyWithName("MemoryBudget", 0.2)
contour.UpdatePipeline()
contour.UpdatePropertyInformation()
lower = contour.GetProperty("ChosenLevel")[0]
check(lower < 3, "a 0.2 MB budget makes Auto LOD choose a coarser level (%s)" % lower)
same_triangles(fetch(mesh_proxy), reference_contour([hp.SKIN, hp.BONE], level=lower),
               "Auto LOD with 0.2 MB (level %s)" % lower)

# --- 2. files ---------------------------------------------------------------------
stl = os.path.join(args.out, "mesh.stl")
ply = os.path.join(args.out, "mesh.ply")
vtp = os.path.join(args.out, "mesh.vtp")
contour.SetPropertyWithName("MemoryBudget", 256.0)
mesh = fetch(mesh_proxy)
SaveData(stl, proxy=mesh_proxy, FileType="Binary")
# As the GUI's Save Data does (vtkSMPLYWriterProxyInitializationHelper): the colour
# map of the display's colouring.
SaveData(ply, proxy=mesh_proxy, EnableColoring=1, EnableAlpha=1,
         ColorArrayName=["CELLS", "SurfaceIndex"], LookupTable=mesh_lut)
SaveData(vtp, proxy=mesh_proxy)
reader = vtkSTLReader()
reader.SetMerging(0)  # merged, a triangle whose corners meet at a grid point would be dropped
reader.SetFileName(stl)
reader.Update()
read = reader.GetOutput()
corners = vtk_to_numpy(mesh.GetPoints().GetData())[
    vtk_to_numpy(mesh.GetPolys().GetConnectivityArray())].astype("float32")
check(read.GetNumberOfCells() == mesh.GetNumberOfCells()
      and arrays_equal(vtk_to_numpy(read.GetPoints().GetData()), corners),
      "STL: %d triangles read back (%d), every corner where it was"
      % (read.GetNumberOfCells(), mesh.GetNumberOfCells()))
reader = vtkPLYReader()
reader.SetFileName(ply)
reader.Update()
read = reader.GetOutput()
same_triangles(read, mesh, "PLY read back")
ply_colors = read.GetCellData().GetArray("RGBA") or read.GetCellData().GetArray("RGB")
if check(ply_colors is not None, "PLY: face colours written (cell arrays %s)"
         % [read.GetCellData().GetArrayName(i) for i in range(read.GetCellData().GetNumberOfArrays())]):
    c = vtk_to_numpy(ply_colors)
    check(c.shape == (colors.shape[0], 4) and int(abs(c.astype(int) - colors).max()) <= 1,
          "PLY: each face in its surface's colour and opacity (RGBA)")
reader = vtkXMLPolyDataReader()
reader.SetFileName(vtp)
reader.Update()
read = reader.GetOutput()
same_triangles(read, mesh, "VTP read back")
read_names = read.GetFieldData().GetAbstractArray("SurfaceNames")
check(read_names is not None and [read_names.GetValue(i) for i in range(2)] == names
      and arrays_equal(vtk_to_numpy(read.GetCellData().GetArray("SurfaceColor")), colors),
      "VTP: the names and colours read back")

# --- 3. a level asked for; the colour map's colours; a surface not drawn ---------
Delete(mesh_proxy)
Delete(contour)
Show(phantom, view)
ColorBy(display, ("POINTS", "HU"))
display.HistoPyramidColorEachSurface = 0
display.HistoPyramidSurfaceOpacities = [1.0, 1.0]
lut = GetColorTransferFunction("HU")
lut.RGBPoints = [-1000.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0, 3000.0, 0.0, 0.0, 1.0]
lut.EnableOpacityMapping = 0
mesh_proxy = medical_isosurfaces.MakeMeshFromView(display, view, level=1)
contour = servermanager._getPyProxy(contour_of(mesh_proxy))
check(contour.GetPropertyValue("AutoLOD") == 0 and contour.GetPropertyValue("LOD") == 1,
      "level=1: Auto LOD off, LOD 1")
mesh = fetch(mesh_proxy)
same_triangles(mesh, reference_contour([hp.SKIN, hp.BONE], level=1), "level 1")
surface_colors = vtk_to_numpy(mesh.GetFieldData().GetArray("SurfaceColors"))
check(surface_colors.round(6).tolist() == [[0.0, 1.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]],
      "coloured by the map: green skin and blue bone, opaque with opacity mapping off (%s)"
      % surface_colors.tolist())
Delete(mesh_proxy)
Delete(contour)
Show(phantom, view)
display.HistoPyramidSurfaceOpacities = [0.0, 1.0, 1.0]
display.IsosurfaceValues = [hp.SKIN, hp.BONE, 1.0e6]
_, warned = hp.captured(lambda: Render(view))
check("outside the range" in warned, "1e6: the representation's warning (%r)" % warned.strip()[:200])
mesh_proxy = medical_isosurfaces.MakeMeshFromView(display, view, level=1, show=False)
mesh = fetch(mesh_proxy)
check(list(servermanager._getPyProxy(contour_of(mesh_proxy)).GetPropertyValue("ContourValues"))
      == [hp.BONE], "surfaces the view does not draw (opacity 0, outside the range) are left out")
same_triangles(mesh, reference_contour([hp.BONE], level=1), "bone only")

# --- 4. bad calls -------------------------------------------------------------------
for what, call in (
        ("a display shown as Surface",
         lambda: medical_isosurfaces.MakeMeshFromView(Show(Sphere(), view), view)),
        ("level 5", lambda: medical_isosurfaces.MakeMeshFromView(display, view, level=5))):
    try:
        call()
        raised = ""
    except ValueError as error:
        raised = str(error)
    check("MakeMeshFromView" in raised, "%s raises ValueError (%r)" % (what, raised))

check.finish("MakeMeshFromView: the Block LOD Contour's triangles, labelled, saved and read back")
