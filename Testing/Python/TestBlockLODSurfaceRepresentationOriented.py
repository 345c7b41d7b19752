"""Block LOD Contour's display on an image with a direction matrix (builtin session).

The phantom (96^3, an origin) turned 30 degrees about an oblique axis, held by a TrivialProducer:
- the filter's output is placed by the direction: its bounds are vtkFlyingEdges3D's on the same
  image (and not the unturned surface's);
- an interactive render with a triangle budget between levels 1 and 2 draws level 1 with the
  exact triangles of level 1 on the unturned phantom (GenerateLevel on the oriented input, the
  display's path), and a still render draws level 3 again.
"""
import argparse
import os

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkCommonTransforms import vtkTransform
from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D

import blocklod_display
import checks

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", default=os.environ.get("MEDISO_PLUGIN"))
args, _ = parser.parse_known_args()
check = checks.Checks()
LoadPlugin(args.plugin, ns=globals())

ISOS = [-500.0, 400.0]
phantom = MedicalPhantom(Dimensions=[96, 96, 96], Origin=[-30.0, 20.0, 10.0])
phantom.UpdatePipeline()
turn = vtkTransform()
turn.RotateWXYZ(30, 1, 2, 3)
image = vtkImageData()
image.ShallowCopy(phantom.GetClientSideObject().GetOutputDataObject(0))
image.SetDirectionMatrix([turn.GetMatrix().GetElement(r, c) for r in range(3) for c in range(3)])
producer = TrivialProducer(registrationName="turned phantom")
producer.GetClientSideObject().SetOutput(image)

contour = BlockLODContour(Input=producer, Isosurfaces=ISOS, LOD=3)
contour.UpdatePipeline()
fe = vtkFlyingEdges3D()
fe.SetInputData(image)
for i, value in enumerate(ISOS):
    fe.SetValue(i, value)
fe.Update()
bounds = contour.GetDataInformation().GetBounds()
plain = BlockLODContour(Input=phantom, Isosurfaces=ISOS, LOD=3)
plain.UpdatePipeline()
unturned = plain.GetDataInformation().GetBounds()
check(all(abs(a - b) < 1e-3 for a, b in zip(bounds, fe.GetOutput().GetBounds())),
      "the output lies where vtkFlyingEdges3D's does: %s" % (["%.2f" % b for b in bounds],))
check(any(abs(a - b) > 1.0 for a, b in zip(bounds, unturned)),
      "... not where the unturned surface does: %s" % (["%.2f" % b for b in unturned],))
exact = []
for level in range(4):
    plain.LOD = level
    plain.UpdatePipeline()
    exact.append(int(plain.GetDataInformation().GetNumberOfCells()))
check(int(contour.GetDataInformation().GetNumberOfCells()) == exact[3],
      "level 3 has the unturned phantom's %d triangles" % exact[3])

view = CreateView("RenderView")
view.ViewSize = [320, 240]
view.OrientationAxesVisibility = 0
view.LODThreshold = 0.0  # MB: interactive renders always draw the LOD geometry
display = Show(contour, view)
display.BlockLODInteractiveFrameBudget = 0.0  # the triangle budget alone decides
display.BlockLODInteractiveTriangleBudget = exact[1] + (exact[2] - exact[1]) // 2
view.ResetCamera()


def frame_info():
    return blocklod_display.frame_info(display)


Render(view)
camera = GetActiveCamera()
camera.Azimuth(1.0)
view.SMProxy.InteractiveRender()
info = frame_info()
check(info["lod"] == 1 and info["level"] == 1 and info["triangles"] == exact[1],
      "an interactive frame of the turned phantom draws level 1 with its %d triangles (got %s)"
      % (exact[1], info))
camera.Azimuth(-1.0)
Render(view)
check(frame_info()["lod"] == 0, "the still render draws the full level again")
check.finish("Block LOD display on a turned image")
