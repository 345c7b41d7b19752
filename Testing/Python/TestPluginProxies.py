"""pvpython test: the MedicalIsosurfaces plugin in builtin mode.

- LoadPlugin(path, ns=globals()) makes MedicalPhantom available;
- the plugin's proxies exist, and the proxy and every property are documented;
- MedicalPhantom produces the requested extent, spacing, origin and type;
- bad parameters give a clear error and an empty output, not a crash.

The plugin path comes from $MEDISO_PLUGIN (set by ctest) or the first argument.
"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)
from paraview import servermanager

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks, captured  # noqa: E402  (Testing/Python/checks.py)

check = Checks()


plugin = sys.argv[1] if len(sys.argv) > 1 else os.environ["MEDISO_PLUGIN"]
LoadPlugin(plugin, ns=globals())
check("MedicalPhantom" in globals(), "LoadPlugin(ns=globals()) defines MedicalPhantom")

# --- proxies and their documentation -----------------------------------------
pxm = servermanager.ProxyManager()
definitions = pxm.SMProxyManager.GetProxyDefinitionManager()
expected = [("sources", "MedicalPhantom"), ("filters", "BlockLODContour")]
for group, name in expected:
    check(definitions.HasDefinition(group, name), "proxy %s/%s is defined" % (group, name))
    proxy = servermanager._getPyProxy(pxm.SMProxyManager.NewProxy(group, name))
    doc = proxy.SMProxy.GetDocumentation()
    check(doc is not None and (doc.GetShortHelp() or "").strip() != "",
          "%s has a short help" % name)
    check(doc is not None and (doc.GetDescription() or "").strip() != "",
          "%s has a description" % name)
    for prop in proxy.ListProperties():
        sm = proxy.GetProperty(prop).SMProperty
        pdoc = sm.GetDocumentation()
        text = (pdoc.GetDescription() or "").strip() if pdoc else ""
        check(len(text) > 20, "property %s.%s is documented" % (name, prop))
    print("%s/%s: %d documented properties: %s" % (group, name, len(proxy.ListProperties()),
                                                   ", ".join(proxy.ListProperties())))

# --- the requested extent and type --------------------------------------------
phantom = MedicalPhantom(Dimensions=[33, 47, 21], Spacing=[0.5, 0.75, 2.0], Origin=[-10, 5, 100])
phantom.UpdatePipeline()
info = phantom.GetDataInformation()
check(tuple(info.GetExtent()) == (0, 32, 0, 46, 0, 20), "extent is %s" % (info.GetExtent(),))
check(tuple(info.GetBounds()) == (-10.0, 6.0, 5.0, 39.5, 100.0, 140.0),
      "bounds are %s" % (info.GetBounds(),))
check(info.GetNumberOfPoints() == 33 * 47 * 21, "point count")
hu = phantom.PointData["HU"]
check(hu is not None and hu.GetDataType() == 4, "HU array is VTK_SHORT (int16)")  # 4 == VTK_SHORT
check(hu.GetRange()[0] == -1000.0 and hu.GetRange()[1] > 400.0, "HU range %s" % (hu.GetRange(),))
print("MedicalPhantom: extent %s, HU range %s" % (info.GetExtent(), hu.GetRange()))

# --- BlockLODContour through its proxy ------------------------------------------
check("BlockLODContour" in globals(), "LoadPlugin(ns=globals()) defines BlockLODContour")
head = MedicalPhantom(Dimensions=[64, 64, 64])
lod = BlockLODContour(Input=head, ContourBy=["POINTS", "HU"], Isosurfaces=[400.0], LOD=2)
lod.UpdatePipeline()
lod.UpdatePropertyInformation()
triangles = lod.GetDataInformation().DataInformation.GetNumberOfCells()
estimates = list(lod.GetProperty("EstimatedTriangles"))
check(triangles > 0, "BlockLODContour makes a surface")
check(lod.GetProperty("ChosenLevel")[0] == 2, "ChosenLevel reports LOD 2")
check(len(estimates) == 4 and estimates[0] < estimates[1] < estimates[2] < estimates[3],
      "estimates grow with the level: %s" % estimates)
check(abs(estimates[2] - triangles) <= 0.1 * triangles,
      "level-2 estimate %g within 10%% of %d" % (estimates[2], triangles))
lod.AutoLOD = 1
lod.MemoryBudget = 0.05  # MB: too small for the finer levels of a 64^3 head
lod.UpdatePipeline()
lod.UpdatePropertyInformation()
chosen = lod.GetProperty("ChosenLevel")[0]
megabytes = list(lod.GetProperty("EstimatedMB"))
check(0 <= chosen < 3 and megabytes[chosen] <= 0.05 and megabytes[chosen + 1] > 0.05,
      "AutoLOD picks the highest level within 0.05 MB: level %d of %s" % (chosen, megabytes))
level = lod.FieldData["BlockLODLevel"]
check(level is not None and level.GetRange()[0] == chosen, "the chosen level is in field data")
print("BlockLODContour: %d triangles at LOD 2, estimates %s; AutoLOD(0.05 MB) chose level %d"
      % (triangles, [int(e) for e in estimates], chosen))
Delete(lod)
Delete(head)

# --- bad parameters -----------------------------------------------------------
# Errors are captured (so a passing run prints none) and checked for content.
cases = [
    ("zero dimension", dict(Dimensions=[0, 32, 32]), "at least 2 points"),
    ("negative dimension", dict(Dimensions=[32, -5, 32]), "at least 2 points"),
    ("2D request", dict(Dimensions=[32, 32, 1]), "3D volume"),
    ("absurd size", dict(Dimensions=[100000, 100000, 100000]), "MB"),
    ("row scratch", dict(Dimensions=[2147483647, 2, 2], MemoryLimit=20000), "a row of 2147483647 doubles"),
]
for label, props, needle in cases:
    def generate():
        bad = MedicalPhantom(**props)
        bad.UpdatePipeline()
        points = bad.GetDataInformation().GetNumberOfPoints()
        Delete(bad)
        return points

    points, text = captured(generate)
    check("Cannot generate the phantom" in text and needle in text,
          "%s: clear error (got %r)" % (label, text.strip()[:200]))
    check(points == 0, "%s: empty output" % label)
    print("%s: error reported: %s" % (label, text.strip().splitlines()[-1][:160] if text.strip() else "none"))

check.finish("plugin proxies: all checks passed")
