"""What the Block LOD Surface display's tests share (pvpython).

    info = frame_info(display)   # {"level": ..., "triangles": ..., "lod": ..., "translucency": ...}
    pixels = window_pixels(view) # the image the last render left in the window
"""
from paraview.modules.vtkRemotingCore import vtkPVSession
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter


def frame_info(display):
    """What the rendering process's representation drew in the last render (builtin: this
    process; client/server with local rendering: the client): the interactive level, its
    triangles, whether the render used the LOD geometry (1) or the full level (0), and how it
    drew the surface (0 opaque, 1 translucent with depth peeling, 2 in one blended pass)."""
    sub = display.SMProxy.GetProperty("BlockLODInteractiveLevel").GetParent()
    previous = sub.GetLocation()
    sub.SetLocation(vtkPVSession.CLIENT)
    try:
        sub.UpdatePropertyInformation()
    finally:
        sub.SetLocation(previous)
    value = lambda name: display.GetProperty(name)[0]  # noqa: E731
    return {"level": int(value("BlockLODInteractiveLevel")),
            "triangles": int(value("BlockLODInteractiveTriangles")),
            "lod": int(value("BlockLODLastRenderUsedLOD")),
            "translucency": int(value("BlockLODLastRenderTranslucency"))}


def window_pixels(view):
    """The RGB image the last render left in `view`'s window (no new render), rows bottom first."""
    grab = vtkWindowToImageFilter()
    grab.SetInput(view.GetRenderWindow())
    grab.ShouldRerenderOff()
    grab.ReadFrontBufferOff()
    grab.Update()
    image = grab.GetOutput()
    w, h, _ = image.GetDimensions()
    return vtk_to_numpy(image.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3].astype(int)
