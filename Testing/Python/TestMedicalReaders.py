"""pvpython test: a NIfTI .nii.gz MRI and a DICOM CT series open in ParaView as
the same volumes as their .mha exports, and give the same surfaces.

    pvpython TestMedicalReaders.py --plugin PATH --out DIR

- The fetched MRI, ch2.nii.gz (gzipped: ParaView 5.11's NIfTI reader takes only
  .nii), opened with OpenDataFile: the plugin's Medical NIfTI Reader is the one
  chosen; 181x217x181, 1 mm, origin and direction from the header's sform
  (identity axes, origin (-90, -125, -71)), the voxels of mri_head.mha.
- The head CT written as a DICOM series by DCMTK (Python/write_dicom_series.py:
  unsigned pixels, Rescale Intercept -1024), read by the Medical DICOM Series
  Reader: the dimensions, spacing, origin and direction of ct_head.mha, and its
  voxels in HU. ParaView's own DICOM reader is read too, to show what the
  plugin's reader corrects (its slices and rows come out reversed).
- Block LOD Contour (level 3) of each at the dataset's skin isovalue gives the
  .mha's triangles, with the points moved by the difference of the origins;
  the HistoPyramid Isosurface representation draws the same active cells.
Skipped (exit 125) when the data is not cached or DCMTK is not installed.
"""
import argparse
import importlib.util
import os
import pathlib
import shutil
import subprocess
import sys

here = pathlib.Path(__file__).resolve().parent
root = here.parent.parent
spec = importlib.util.spec_from_file_location("fetch_data", root / "Python" / "fetch_data.py")
fetch_data = importlib.util.module_from_spec(spec)
spec.loader.exec_module(fetch_data)

parser = argparse.ArgumentParser()
parser.add_argument("--plugin", default=os.environ.get("MEDISO_PLUGIN"))
parser.add_argument("--out", required=True)
args = parser.parse_args()

cache = fetch_data.resolve_cache_dir(None)
missing = [n for n in ("ct_head.mha", "mri_head.mha", "ch2.nii.gz") if not (cache / n).is_file()]
if missing:
    print("SKIP: real data not cached in %s (%s); run python3 Python/fetch_data.py"
          % (cache, ", ".join(missing)))
    sys.exit(125)
if not shutil.which("dump2dcm"):
    print("SKIP: DCMTK's dump2dcm is not installed (apt-get install dcmtk)")
    sys.exit(125)

import numpy  # noqa: E402
from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: E402,F401,F403 (pvpython idiom)
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

import HistoPyramidRepresentationChecks as hp  # noqa: E402

check = hp.Checker()
LoadPlugin(args.plugin, ns=globals())

series = pathlib.Path(args.out) / "ct_head_dicom"
if series.exists():
    shutil.rmtree(series)
written = subprocess.run([shutil.which("python3") or "python3", str(root / "Python" / "write_dicom_series.py"),
                          "--mha", str(cache / "ct_head.mha"), "--out", str(series)],
                         capture_output=True, text=True)
check(written.returncode == 0 and len(list(series.glob("*.dcm"))) == 108,
      "the DICOM series is written (%s)" % (written.stdout + written.stderr).strip()[-300:])


def fetch(source):
    source.UpdatePipeline()
    image = servermanager.Fetch(source)
    values = vtk_to_numpy(image.GetPointData().GetScalars())
    direction = [image.GetDirectionMatrix().GetElement(i, j) for i in range(3) for j in range(3)]
    return image, values, direction


def close(a, b, tolerance):
    return all(abs(x - y) <= tolerance for x, y in zip(a, b))


def surface(source, isovalue):
    """Triangles and points of Block LOD Contour level 3 at the isovalue."""
    name = source.PointData.keys()[0]
    contour = BlockLODContour(Input=source, ContourBy=["POINTS", name], Isosurfaces=[isovalue],
                              LOD=3, ComputeNormals=0)
    contour.UpdatePipeline()
    mesh = servermanager.Fetch(contour)
    points = vtk_to_numpy(mesh.GetPoints().GetData()).astype(float)
    Delete(contour)
    return mesh.GetNumberOfPolys(), points


def active_cells(source, isovalue):
    """What the HistoPyramid Isosurface representation draws (path, primitives, triangles)."""
    view = CreateView("RenderView")
    view.ViewSize = [200, 200]
    display = Show(source, view)
    display.SetRepresentationType(hp.REPRESENTATION)
    display.IsosurfaceValues = [isovalue]
    view.ResetCamera()
    Render(view)
    info = hp.render_info(display)
    Delete(display)
    Delete(view)
    return info["path"], info["primitives"], info["triangles"]


def compare(label, reference, candidate, isovalue):
    """Same surface as the reference, the points moved by the origins' difference."""
    ref_image, _, _ = fetch(reference)
    image, _, _ = fetch(candidate)
    shift = numpy.array(image.GetOrigin()) - numpy.array(ref_image.GetOrigin())
    ref_triangles, ref_points = surface(reference, isovalue)
    triangles, points = surface(candidate, isovalue)
    check(triangles == ref_triangles and triangles > 1000,
          "%s: Block LOD Contour at %g gives the .mha's %d triangles (got %d)"
          % (label, isovalue, ref_triangles, triangles))
    if points.shape == ref_points.shape:
        error = float(numpy.abs(points - shift - ref_points).max())
        check(error < 1e-3, "%s: the same points, moved by %s (largest difference %.2g mm)"
              % (label, shift.tolist(), error))
    drawn, ref_drawn = active_cells(candidate, isovalue), active_cells(reference, isovalue)
    check(drawn == ref_drawn and drawn[0] in ("gpu", "fallback"),
          "%s: HistoPyramid Isosurface draws what it draws for the .mha (%s against %s)"
          % (label, drawn, ref_drawn))
    print("%s: %d triangles at %g, same as the .mha; representation %s"
          % (label, triangles, isovalue, drawn))


# --- the MRI, gzipped NIfTI --------------------------------------------------
mri_mha = OpenDataFile(str(cache / "mri_head.mha"))
nifti = OpenDataFile(str(cache / "ch2.nii.gz"))
check(nifti is not None and nifti.GetXMLName() == "MedicalNIfTIReader",
      "OpenDataFile picks the plugin's NIfTI reader for .nii.gz (got %s)"
      % (nifti.GetXMLName() if nifti else None))
image, values, direction = fetch(nifti)
mha_image, mha_values, _ = fetch(mri_mha)
check(image.GetDimensions() == (181, 217, 181), "NIfTI dims %s" % (image.GetDimensions(),))
check(close(image.GetSpacing(), (1.0, 1.0, 1.0), 1e-6), "NIfTI spacing %s" % (image.GetSpacing(),))
check(close(image.GetOrigin(), (-90.0, -125.0, -71.0), 1e-4),
      "NIfTI origin from the sform %s" % (image.GetOrigin(),))
check(close(direction, (1, 0, 0, 0, 1, 0, 0, 0, 1), 1e-9), "NIfTI direction %s" % direction)
check(numpy.array_equal(values, mha_values), "NIfTI voxels equal mri_head.mha's")
compare("MRI ch2.nii.gz", mri_mha, nifti, 30.0)

# --- the CT, DICOM series ----------------------------------------------------
ct_mha = OpenDataFile(str(cache / "ct_head.mha"))
dicom = MedicalDICOMSeriesReader(FileName=str(series / "slice_000.dcm"))
image, values, direction = fetch(dicom)
mha_image, mha_values, _ = fetch(ct_mha)
check(image.GetDimensions() == mha_image.GetDimensions(), "DICOM dims %s" % (image.GetDimensions(),))
check(close(image.GetSpacing(), mha_image.GetSpacing(), 1e-6), "DICOM spacing %s" % (image.GetSpacing(),))
check(close(image.GetOrigin(), mha_image.GetOrigin(), 1e-6), "DICOM origin %s" % (image.GetOrigin(),))
check(close(direction, (1, 0, 0, 0, 1, 0, 0, 0, 1), 1e-9), "DICOM direction %s" % direction)
check(values.dtype == numpy.int16 and values.min() == -1024 and values.max() == 2986,
      "DICOM values in HU (%s, %d..%d)" % (values.dtype, values.min(), values.max()))
check(numpy.array_equal(values, mha_values), "DICOM voxels equal ct_head.mha's")
compare("CT DICOM series", ct_mha, dicom, -500.0)

# ParaView's own reader of the same series: same voxels, slices and rows reversed.
builtin = DICOMReaderdirectory(FileName=str(series))
_, builtin_values, _ = fetch(builtin)
nx, ny, nz = mha_image.GetDimensions()
check(numpy.array_equal(builtin_values.reshape(nz, ny, nx)[::-1, ::-1, :],
                        mha_values.reshape(nz, ny, nx)),
      "ParaView's DICOM reader gives the slices and rows reversed (what this reader corrects)")

if check.failures:
    print("%d check(s) failed" % len(check.failures))
    sys.exit(1)
print("medical readers: all checks passed")
