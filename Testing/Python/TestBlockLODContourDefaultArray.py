"""pvpython test: the README's BlockLODContour example works as written, with
ContourBy left unset (ParaView leaves it empty until the input has run).

- BlockLODContour(Input=MedicalPhantom(...), Isosurfaces=[400], LOD=3) on a
  phantom that has not run yet contours its active array "HU", with the same
  triangles as when ContourBy names it, and the README's AutoLOD lines report a
  chosen level and estimates;
- the same on OpenDataFile(ct_head.mha) when the real CT is cached (skipped
  part otherwise: run python3 Python/fetch_data.py).

Any VTK error or warning fails the test (ctest's fail regex).
The plugin path comes from $MEDISO_PLUGIN (set by ctest) or the first argument.
"""
import importlib.util
import os
import pathlib
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom, as the README)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from clientserver import Checks  # noqa: E402

check = Checks()


def readme_example(head, label, isovalue):
    """The README's lines, then the same filter with ContourBy named."""
    bone = BlockLODContour(Input=head, Isosurfaces=[isovalue], LOD=3)  # noqa: F405
    bone.UpdatePipeline()
    triangles = bone.GetDataInformation().GetNumberOfCells()
    bone.AutoLOD = 1; bone.MemoryBudget = 64       # MB: the highest level that fits
    bone.UpdatePipeline(); bone.UpdatePropertyInformation()
    chosen = bone.GetProperty("ChosenLevel")[0]
    estimated = list(bone.GetProperty("EstimatedMB"))
    print("%s: ContourBy %s; %d triangles at LOD 3; AutoLOD (64 MB) chose level %d, estimated MB %s"
          % (label, list(bone.ContourBy), triangles, chosen, estimated))
    array = head.PointData.keys()[0]
    named = BlockLODContour(Input=head, ContourBy=["POINTS", array],  # noqa: F405
                            Isosurfaces=[isovalue], LOD=3)
    named.UpdatePipeline()
    expected = named.GetDataInformation().GetNumberOfCells()
    check(triangles > 0, "%s: the example makes a surface" % label)
    check(triangles == expected, "%s: %d triangles, %d with ContourBy %s"
          % (label, triangles, expected, array))
    check(0 <= chosen <= 3 and all(mb > 0 for mb in estimated),
          "%s: AutoLOD chose a level and reported estimates" % label)
    Delete(named)  # noqa: F405
    Delete(bone)  # noqa: F405


plugin = sys.argv[1] if len(sys.argv) > 1 else os.environ["MEDISO_PLUGIN"]
LoadPlugin(plugin, ns=globals())  # noqa: F405

readme_example(MedicalPhantom(Dimensions=[64, 64, 64]), "MedicalPhantom 64^3", 400)  # noqa: F405

here = pathlib.Path(__file__).resolve().parent
spec = importlib.util.spec_from_file_location(
    "fetch_data", here.parent.parent / "Python" / "fetch_data.py")
fetch_data = importlib.util.module_from_spec(spec)
spec.loader.exec_module(fetch_data)
ct = fetch_data.resolve_cache_dir(None) / "ct_head.mha"
if ct.is_file():
    readme_example(OpenDataFile(str(ct)), "OpenDataFile(ct_head.mha)", 400)  # noqa: F405
else:
    print("real CT not cached (%s): OpenDataFile part not run" % ct)

check.finish("BlockLODContour default array: all checks passed")
