"""pvpython test: the real head CT and MRI, as Python/fetch_data.py caches them,
load in ParaView with the right dimensions, spacing, type and value range.

Skipped (exit 125) when the data is not cached: run python3 Python/fetch_data.py
(Scripts/test.sh does when the network allows).
"""
import importlib.util
import os
import pathlib
import sys

here = pathlib.Path(__file__).resolve().parent
spec = importlib.util.spec_from_file_location(
    "fetch_data", here.parent.parent / "Python" / "fetch_data.py")
fetch_data = importlib.util.module_from_spec(spec)
spec.loader.exec_module(fetch_data)

cache = fetch_data.resolve_cache_dir(None)
expected = [
    # file, dims, spacing, VTK type (4 short, 3 unsigned char), min, max
    ("ct_head.mha", (256, 256, 108), (0.9570312, 0.9570312, 1.5), 4, -1024.0, 2986.0),
    ("mri_head.mha", (181, 217, 181), (1.0, 1.0, 1.0), 3, 0.0, 254.0),
]
missing = [name for name, *_ in expected if not (cache / name).is_file()]
if missing:
    print("SKIP: real data not cached in %s (%s); run python3 Python/fetch_data.py"
          % (cache, ", ".join(missing)))
    sys.exit(125)

from paraview.simple import OpenDataFile  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)

check = Checks()


for name, dims, spacing, vtk_type, vmin, vmax in expected:
    reader = OpenDataFile(str(cache / name))
    check(reader is not None, "%s opens" % name)
    reader.UpdatePipeline()
    info = reader.GetDataInformation()
    ext = info.GetExtent()
    got_dims = tuple(ext[2 * i + 1] - ext[2 * i] + 1 for i in range(3))
    bounds = info.GetBounds()
    got_spacing = tuple((bounds[2 * i + 1] - bounds[2 * i]) / (got_dims[i] - 1) for i in range(3))
    array = reader.PointData[reader.PointData.keys()[0]]
    check(got_dims == dims, "%s dims %s" % (name, got_dims))
    check(all(abs(a - b) < 1e-5 for a, b in zip(got_spacing, spacing)),
          "%s spacing %s" % (name, got_spacing))
    check(array.GetDataType() == vtk_type, "%s VTK type %d" % (name, array.GetDataType()))
    check(tuple(array.GetRange()) == (vmin, vmax), "%s range %s" % (name, array.GetRange()))
    print("%s: dims %s, spacing %s, range %s" % (name, got_dims,
                                                 tuple(round(s, 7) for s in got_spacing),
                                                 array.GetRange()))

check.finish("real data: all checks passed")
