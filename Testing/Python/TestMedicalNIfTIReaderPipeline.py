"""pvpython test: the plugin's NIfTI reader in ParaView, on files this test writes.

- A CT as NIfTI stores it (int16, scl_slope 1, scl_inter -1024, gzipped) opened with
  OpenDataFile: the plugin's Medical NIfTI Reader is chosen and the values reach the
  pipeline in Hounsfield units, exactly (int32).
- A slope of 0.5: float values v * 0.5 - 10.
- A 4D image: ParaView's time steps (TimestepValues) and the volume of each time.
- A truncated file: one error from the reader, captured here, and no volume downstream
  (no points, no triangles from Block LOD Contour).

The plugin path comes from $MEDISO_PLUGIN (set by ctest) or the first argument.
"""
import gzip
import os
import struct
import sys
import tempfile

from paraview.simple import *  # noqa: F401,F403 (pvpython idiom)
from paraview import servermanager
from vtkmodules.util.numpy_support import vtk_to_numpy
from checks import Checks, captured  # Testing/Python/checks.py
from nifti import nifti1_header  # Testing/Python/nifti.py

check = Checks()


def nifti1(dims, slope=0.0, intercept=0.0, pixdim4=1.0, toffset=0.0):
    """A single-file NIfTI-1 int16 header (348 bytes and 4 extension bytes), spacing 0.5 x 0.5 x 2."""
    return nifti1_header(dims, (0.5, 0.5, 2.0), slope=slope, intercept=intercept, time_step=pixdim4,
                         toffset=toffset)


def voxels(count, first=0):
    values = [(first + 37 * i) % 3000 for i in range(count)]
    return values, struct.pack("<%dh" % count, *values)


def fetch_values(source, time=None):
    if time is None:
        source.UpdatePipeline()
    else:
        source.UpdatePipeline(time)
    image = servermanager.Fetch(source)
    scalars = image.GetPointData().GetScalars()
    return image, scalars


plugin = sys.argv[1] if len(sys.argv) > 1 else os.environ["MEDISO_PLUGIN"]
LoadPlugin(plugin, ns=globals())
folder = tempfile.mkdtemp(prefix="mediso-nifti-")
dims = (8, 6, 5)
count = 8 * 6 * 5

# --- a CT in Hounsfield units ---------------------------------------------------
stored, data = voxels(count)
path = os.path.join(folder, "ct.nii.gz")
with gzip.open(path, "wb") as out:
    out.write(nifti1(dims, slope=1.0, intercept=-1024.0) + data)
ct = OpenDataFile(path)
check(ct is not None and ct.GetXMLName() == "MedicalNIfTIReader",
      "OpenDataFile picks the plugin's NIfTI reader (got %s)" % (ct.GetXMLName() if ct else None))
image, scalars = fetch_values(ct)
check(image.GetDimensions() == dims, "dimensions %s" % (image.GetDimensions(),))
check(scalars.GetDataTypeAsString() == "int", "int32 scalars (got %s)" % scalars.GetDataTypeAsString())
hu = list(vtk_to_numpy(scalars))
check(hu == [v - 1024 for v in stored], "the values are v - 1024, in HU (first %s)" % hu[:4])
check(ct.PointData["NIFTI"].GetRange() == (-1024.0, max(stored) - 1024.0),
      "the data information's range is in HU: %s" % (ct.PointData["NIFTI"].GetRange(),))
print("CT: %s %s, range %s" % (scalars.GetDataTypeAsString(), image.GetDimensions(),
                               ct.PointData["NIFTI"].GetRange()))
Delete(ct)

# --- slope 0.5 -------------------------------------------------------------------
path = os.path.join(folder, "half.nii")
with open(path, "wb") as out:
    out.write(nifti1(dims, slope=0.5, intercept=-10.0) + data)
half = MedicalNIfTIReader(FileName=path)
image, scalars = fetch_values(half)
check(scalars.GetDataTypeAsString() == "float", "float scalars (got %s)" % scalars.GetDataTypeAsString())
check(list(vtk_to_numpy(scalars)) == [v * 0.5 - 10.0 for v in stored], "the values are v * 0.5 - 10")
Delete(half)

# --- 4D: time steps -------------------------------------------------------------
path = os.path.join(folder, "4d.nii")
with open(path, "wb") as out:
    out.write(nifti1(dims + (3,), pixdim4=2.5, toffset=1.0))
    for t in range(3):
        out.write(voxels(count, 1000 * t)[1])
series = MedicalNIfTIReader(FileName=path)
check(list(series.TimestepValues) == [1.0, 3.5, 6.0], "time steps %s" % (list(series.TimestepValues),))
for t, time in ((1, 3.5), (2, 6.0), (0, 1.0)):
    image, scalars = fetch_values(series, time)
    check(list(vtk_to_numpy(scalars)) == voxels(count, 1000 * t)[0],
          "time %g reads volume %d" % (time, t))
Delete(series)

# --- truncated: an error and nothing downstream ----------------------------------
path = os.path.join(folder, "truncated.nii")
with open(path, "wb") as out:
    out.write(nifti1(dims, slope=1.0, intercept=-1024.0) + data[: len(data) // 2])


def read_truncated():
    bad = MedicalNIfTIReader(FileName=path)
    contour = BlockLODContour(Input=bad, Isosurfaces=[0.0], LOD=0)
    contour.UpdatePipeline()
    counts = (bad.GetDataInformation().GetNumberOfPoints(),
              contour.GetDataInformation().GetNumberOfCells())
    Delete(contour)
    Delete(bad)
    return counts


(points, triangles), text = captured(read_truncated)
expected = ("Cannot read %s: the header describes 8 x 6 x 5 INT16 voxels (480 bytes from byte 352), "
            "but the file holds only 592 bytes. The output is empty." % path)
# Block LOD Contour may say of its own that its input is empty; the reader says one thing.
check(text.count("vtkMedicalNIfTIReader (") == 1 and expected in text,
      "one error from the reader: %r (got %r)" % (expected, text.strip()[-600:]))
check(points == 0 and triangles == 0, "nothing downstream (%d points, %d cells)" % (points, triangles))
print("truncated: %s" % expected)

check.finish("NIfTI reader in ParaView: all checks passed")
