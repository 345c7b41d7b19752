"""What the Block LOD Surface display's tests share (pvpython).

    info = frame_info(display)   # {"level": ..., "triangles": ..., "lod": ...}
"""
from paraview.modules.vtkRemotingCore import vtkPVSession


def frame_info(display):
    """What the rendering process's representation drew in the last render (builtin: this
    process; client/server with local rendering: the client): the interactive level, its
    triangles, and whether the render used the LOD geometry (1) or the full level (0)."""
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
            "lod": int(value("BlockLODLastRenderUsedLOD"))}
