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
from vtkmodules.vtkCommonCore import vtkLogger, vtkOutputWindow, vtkStringOutputWindow

failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAILED: " + what)


plugin = sys.argv[1] if len(sys.argv) > 1 else os.environ["MEDISO_PLUGIN"]
LoadPlugin(plugin, ns=globals())
check("MedicalPhantom" in globals(), "LoadPlugin(ns=globals()) defines MedicalPhantom")

# --- proxies and their documentation -----------------------------------------
pxm = servermanager.ProxyManager()
definitions = pxm.SMProxyManager.GetProxyDefinitionManager()
expected = [("sources", "MedicalPhantom")]
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

# --- bad parameters -----------------------------------------------------------
# Errors are captured (so a passing run prints none) and checked for content.
cases = [
    ("zero dimension", dict(Dimensions=[0, 32, 32]), "at least 2 points"),
    ("negative dimension", dict(Dimensions=[32, -5, 32]), "at least 2 points"),
    ("2D request", dict(Dimensions=[32, 32, 1]), "3D volume"),
    ("absurd size", dict(Dimensions=[100000, 100000, 100000]), "MiB"),
]
for label, props, needle in cases:
    capture = vtkStringOutputWindow()
    previous = vtkOutputWindow.GetInstance()
    verbosity = vtkLogger.GetCurrentVerbosityCutoff()
    # Errors reach both the output window and the logger's stderr sink.
    vtkOutputWindow.SetInstance(capture)
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
    try:
        bad = MedicalPhantom(**props)
        bad.UpdatePipeline()
        points = bad.GetDataInformation().GetNumberOfPoints()
        Delete(bad)
    finally:
        vtkOutputWindow.SetInstance(previous)
        vtkLogger.SetStderrVerbosity(verbosity)
    text = capture.GetOutput()
    check("Cannot generate the phantom" in text and needle in text,
          "%s: clear error (got %r)" % (label, text.strip()[:200]))
    check(points == 0, "%s: empty output" % label)
    print("%s: error reported: %s" % (label, text.strip().splitlines()[-1][:160] if text.strip() else "none"))

if failures:
    print("%d check(s) failed" % len(failures))
    sys.exit(1)
print("plugin proxies: all checks passed")
