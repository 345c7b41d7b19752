"""pvpython test: the Medical DICOM Series Reader on a generated corpus, case by case.

    pvpython TestMedicalDICOMSeriesReader.py --plugin PATH --out DIR

The corpus (Testing/Python/dicom_corpus.py, run with Debian's /usr/bin/python3 and pydicom;
DCMTK's tools compress its copies) holds small series that each test one thing: plain CT
with a rescale intercept, the same compressed as RLE, JPEG lossless and JPEG-LS, two series
in a folder, a missing slice, uneven steps, a slope per slice, files that are not images, a
transfer syntax that is not decoded, an enhanced multi-frame file, shuffled file order, an
oblique plane, 8-bit implicit VR and big endian files, a duplicate position, a slice of
another size, a gantry tilt, a slice on another plane, a colour image, and damaged files (one cut short, pixel data shorter than the header says, a
header claiming 34 TB). Every case asserts the exact values (interpolated ones to 1e-3) and geometry,
or the exact message: the reader's errors and warnings are captured here, and any not
expected fails the test. Skipped (exit 125) when /usr/bin/python3 lacks pydicom or DCMTK's
tools are missing (Scripts/bootstrap.sh installs both).
"""
import argparse
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys

here = pathlib.Path(__file__).resolve().parent
parser = argparse.ArgumentParser()
parser.add_argument("--plugin", default=os.environ.get("MEDISO_PLUGIN"))
parser.add_argument("--out", required=True)
args = parser.parse_args()

python = "/usr/bin/python3"
if not os.path.exists(python):
    print("SKIP: %s not found (the corpus is written with Debian's python3-pydicom)" % python)
    sys.exit(125)
corpus = pathlib.Path(args.out) / "dicom_corpus"
written = subprocess.run([python, str(here / "dicom_corpus.py"), str(corpus)],
                         capture_output=True, text=True)
if written.returncode in (3, 4):
    print("SKIP: " + written.stdout.strip())
    sys.exit(125)
if written.returncode != 0:
    print("FAILED: the corpus could not be written: " + (written.stdout + written.stderr)[-2000:])
    sys.exit(1)
manifest = json.loads((corpus / "manifest.json").read_text())

import numpy  # noqa: E402
from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: E402,F401,F403 (pvpython idiom)
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

import HistoPyramidRepresentationChecks as hp  # noqa: E402

check = hp.Checker()
LoadPlugin(args.plugin, ns=globals())

DTYPES = {"int16": numpy.int16, "float32": numpy.float32, "uint8": numpy.uint8}


def read(path, **properties):
    """Read with the plugin's reader: (image, values or None, captured messages)."""
    def run():
        # The file last: the reader reads when its information is first asked for.
        reader = MedicalDICOMSeriesReader(**properties, FileName=str(path))
        reader.UpdatePipeline()
        image = servermanager.Fetch(reader)
        Delete(reader)
        return image
    image, text = hp.captured(run)
    scalars = image.GetPointData().GetScalars() if image else None
    values = vtk_to_numpy(scalars) if scalars is not None else None
    return image, values, text


def messages(text):
    """The messages in captured VTK output, without the file/line prefix VTK adds."""
    found = []
    for block in re.split(r"\n(?=(?:ERROR|Warning): In )", text.strip()):
        if not block:
            continue
        kind = "error" if block.startswith("ERROR") else "warning"
        body = block.split("): ", 1)[-1].strip() if "): " in block else block
        found.append((kind, " ".join(body.split())))
    return found


def expect_volume(name, path=None, expected=None, tolerance=0.0, text_expected=(), **properties):
    """A case that must read: geometry, type and values from the manifest."""
    info = manifest[name]
    path = path or corpus / info["open"]
    image, values, text = read(path, **properties)
    got = messages(text)
    check([m for m in got if m[0] == "error"] == [],
          "%s: read without an error (got %s)" % (name, got))
    check([m[1] for m in got if m[0] == "warning"] == list(text_expected),
          "%s: warnings %s (expected %s)" % (name, [m[1] for m in got], list(text_expected)))
    truth = numpy.load(corpus / "expected" / (name + ".npy")) if expected is None else expected
    n, rows, columns = truth.shape
    if not check(values is not None and image.GetDimensions() == (columns, rows, n),
                 "%s: dimensions %s (expected %s)"
                 % (name, image.GetDimensions() if image else None, (columns, rows, n))):
        return None
    direction = [image.GetDirectionMatrix().GetElement(i, j) for i in range(3) for j in range(3)]
    check(numpy.allclose(image.GetSpacing(), info["spacing"], atol=1e-5),
          "%s: spacing %s (expected %s)" % (name, image.GetSpacing(), info["spacing"]))
    check(numpy.allclose(image.GetOrigin(), info["origin"], atol=1e-5),
          "%s: origin %s (expected %s)" % (name, image.GetOrigin(), info["origin"]))
    check(numpy.allclose(direction, info["direction"], atol=1e-6),
          "%s: direction %s (expected %s)" % (name, direction, info["direction"]))
    dtype = DTYPES[info["dtype"]]
    check(values.dtype == dtype, "%s: %s values (expected %s)" % (name, values.dtype, dtype))
    volume = values.reshape(n, rows, columns).astype(float)
    error = float(numpy.abs(volume - truth).max())
    check(error <= tolerance, "%s: values differ from the truth by up to %g (allowed %g)"
          % (name, error, tolerance))
    print("%s: %dx%dx%d %s, spacing %s, values %s" % (name, columns, rows, n, values.dtype,
          tuple(round(s, 4) for s in image.GetSpacing()),
          "exact" if tolerance == 0 else "within %g" % tolerance))
    return values


def expect_error(name, path, message, **properties):
    """A case that must be refused with exactly this message and an empty image."""
    image, values, text = read(path, **properties)
    got = messages(text)
    check(("error", message) in got, "%s: the message\n    %s\n  (got %s)" % (name, message, got))
    check(values is None or len(values) == 0, "%s: an empty image" % name)
    print("%s: refused: %s" % (name, message))


plain = expect_volume("plain")
check(plain is not None and plain.min() == -1024, "plain: Hounsfield units from -1024")

# Compressed copies read the same values (the files are compressed: their syntax is in them).
for name in ("rle", "jpeg_lossless", "jpegls"):
    syntax = manifest[name]["syntax"].encode()
    head = (corpus / manifest[name]["open"]).read_bytes()[:512]
    check(syntax in head, "%s: the file's transfer syntax is %s" % (name, syntax.decode()))
    values = expect_volume(name)
    check(values is not None and plain is not None and numpy.array_equal(values, plain),
          "%s: the same values as the uncompressed series" % name)

# Two series in one folder: the opened file's series, the other listed.
plain_uid, other_uid = manifest["two_series"]["series"], manifest["two_series"]["other_series"]
folder = corpus / "two_series"
plain_line = '%s ("Corpus series", 6 slices)' % plain_uid
other_line = '%s ("Other series", 3 slices)' % other_uid
listing = "%s: the folder holds 2 series; read %s, %s; not read: %s. SeriesInstanceUID chooses " \
    "another."
expect_volume("two_series", text_expected=[
    listing % (folder, plain_line, "the series of the file opened", other_line)])
expect_volume("two_series_other", text_expected=[
    listing % (folder, other_line, "the series of the file opened", plain_line)])
expect_volume("two_series", path=folder, text_expected=[
    listing % (folder, plain_line, "the series with the most slices", other_line)])
expect_volume("two_series_other", path=folder, SeriesInstanceUID=other_uid, text_expected=[
    listing % (folder, other_line, "the one SeriesInstanceUID names", plain_line)])
# The read-back property lists the folder's series, the one read first.
reader, text = hp.captured(lambda: MedicalDICOMSeriesReader(FileName=str(folder / "other_000.dcm")))
reader.UpdatePropertyInformation()
listed = list(reader.GetProperty("SeriesInFolder"))
check(listed == ["%s | Other series | 3 slices" % other_uid,
                 "%s | Corpus series | 6 slices" % plain_uid],
      "two_series: SeriesInFolder lists both, the one read first (got %s)" % listed)
Delete(reader)
expect_error("two_series: an unknown UID", folder,
             "%s: no series with Series Instance UID 1.2.3.4; the folder holds %s; %s"
             % (folder, plain_line, other_line), SeriesInstanceUID="1.2.3.4")

# A missing slice: refused with the gap named; resampled on request.
gap = "a gap of 5 mm between 15 mm (slice_002.dcm) and 20 mm (slice_004.dcm) (1 slice missing)"
expect_error("gap", corpus / "gap" / "slice_000.dcm",
             "the slices are not evenly spaced (median step 2.5 mm): %s. Turn "
             "ResampleUnevenSlices on to resample them onto an even grid." % gap)
expect_volume("gap", ResampleUnevenSlices=1, text_expected=[
    "resampled 5 unevenly spaced slices (median step 2.5 mm: %s) onto 6 slices 2.5 mm apart "
    "by linear interpolation (ResampleUnevenSlices)" % gap])

# Uneven steps: refused with the step named; resampled on request.
step = "a step of 3 mm between 4 mm (slice_002.dcm) and 7 mm (slice_003.dcm)"
expect_error("uneven", corpus / "uneven" / "slice_000.dcm",
             "the slices are not evenly spaced (median step 2 mm): %s. Turn "
             "ResampleUnevenSlices on to resample them onto an even grid." % step)
expect_volume("uneven", ResampleUnevenSlices=1, tolerance=1e-3, text_expected=[
    "resampled 6 unevenly spaced slices (median step 2 mm: %s) onto 7 slices 1.83333 mm apart "
    "by linear interpolation (ResampleUnevenSlices)" % step])

# A slope and an intercept per slice: float values, exact.
expect_volume("slopes")

# A text file, random bytes, a named pipe and a DICOM file without pixel data: ignored, quietly.
junk = expect_volume("junk")
check(junk is not None and plain is not None and numpy.array_equal(junk, plain),
      "junk: the same values as the plain series")
expect_error("junk: a text file opened", corpus / "junk" / "notes.txt",
             "%s: not a DICOM image (no Part 10 preamble \"DICM\", or no Rows, Columns and "
             "Pixel Data)" % (corpus / "junk" / "notes.txt"))
expect_error("junk: no such file", corpus / "junk" / "missing.dcm",
             "%s: no such file or folder" % (corpus / "junk" / "missing.dcm"))

# A transfer syntax the reader does not decode: refused by name.
expect_error("jpeg2000", corpus / manifest["jpeg2000"]["open"],
             'slice_002.dcm: transfer syntax "JPEG 2000 (Lossless only)" '
             "(1.2.840.10008.1.2.4.90) is not read (this reader decodes uncompressed, deflated, "
             "JPEG baseline, extended and lossless, JPEG-LS and RLE pixel data)")

# One enhanced CT file: frames placed by their per-frame positions, shared rescale.
expect_volume("multiframe")

# File names and instance numbers shuffled; an oblique plane with signed pixels.
expect_volume("shuffled")
expect_volume("oblique")
# Placed right: voxel (i, j, k) lies where DICOM puts column i, row j of the k-th slice,
# IPP_k + i * column spacing * row direction + j * row spacing * column direction.
oblique = manifest["oblique"]
image, _, _ = read(corpus / oblique["open"])
row_dir, column_dir = numpy.array(oblique["row"]), numpy.array(oblique["column"])
ipp_2 = numpy.array(oblique["positions"][2])  # as written in the third slice's file
dicom_point = ipp_2 + 3 * 0.6 * row_dir + 5 * 0.8 * column_dir
vtk_point = [0.0, 0.0, 0.0]
image.TransformIndexToPhysicalPoint(3, 5, 2, vtk_point)
check(numpy.allclose(vtk_point, dicom_point, atol=1e-4),
      "oblique: voxel (3, 5, 2) at %s, DICOM's column 3, row 5 of slice 2 at %s"
      % (vtk_point, dicom_point.tolist()))

# 8-bit implicit VR (uint8 as stored), signed big endian; a duplicate position, a mixed size.
expect_volume("mr8")
expect_volume("bigendian")
expect_error("duplicate", corpus / manifest["duplicate"]["open"],
             "two slices at the same position along the normal, 12.5 mm (slice_001.dcm) and "
             "12.5 mm (slice_001_copy.dcm): duplicate slices are not read")
expect_error("mixed_size", corpus / manifest["mixed_size"]["open"],
             "slice_006.dcm: 8 x 8 pixels, but slice_000.dcm has 16 x 12: slices of different "
             "sizes are not read")

expect_error("tilted", corpus / manifest["tilted"]["open"],
             "slice_001.dcm: its Image Position (Patient) is 0.5 mm off the line through "
             "slice_000.dcm along the slice normal (a gantry tilt or a sheared stack): not read")
expect_error("mixed_orientation", corpus / manifest["mixed_orientation"]["open"],
             "slice_006.dcm: Image Orientation (Patient) 1\\0\\0\\0\\0\\-1, but "
             "slice_000.dcm has 1\\0\\0\\0\\1\\0: slices of different orientations "
             "are not read")
expect_error("rgb", corpus / manifest["rgb"]["open"],
             'colour.dcm: 3 sample(s) per pixel, Photometric Interpretation "RGB": only '
             "greyscale (MONOCHROME1/2) images are read")

# Damaged files: each refused with its reason, nothing allocated for a header's claims.
image, values, text = read(corpus / manifest["truncated"]["open"])
check(messages(text) == [
    ("warning", "%s: skipped 1 DICOM file(s) DCMTK cannot read: slice_002.dcm (Invalid stream)"
     % (corpus / "truncated")),
    ("error", "the slices are not evenly spaced (median step 2.5 mm): a gap of 5 mm between "
     "12.5 mm (slice_001.dcm) and 17.5 mm (slice_003.dcm) (1 slice missing). Turn "
     "ResampleUnevenSlices on to resample them onto an even grid.")],
    "truncated: the cut file named, then the gap it leaves (got %s)" % messages(text))
check(values is None or len(values) == 0, "truncated: an empty image")
expect_error("short_pixels", corpus / manifest["short_pixels"]["open"],
             "short.dcm: Pixel Data holds 100 bytes, 384 expected (16 x 12 x 1 frame(s) x 2 "
             "byte(s))")
expect_error("huge", corpus / manifest["huge"]["open"],
             "huge.dcm: Pixel Data holds 64 bytes, 34358689800000 expected (65535 x 65535 x "
             "4000 frame(s) x 2 byte(s))")
image, values, text = read(corpus / manifest["huge_rle"]["open"])
got = messages(text)
check(len(got) == 1 and got[0][0] == "error" and got[0][1].startswith(
    "the decoded series and a compressed file's decoding (68717379.6 MB) does not fit in "
    "the "),
    "huge_rle: refused before allocating or decoding (got %s)" % got)
check(values is None or len(values) == 0, "huge_rle: an empty image")

expect_error("frames_claimed", corpus / manifest["frames_claimed"]["open"],
             "frames.dcm: 2000000000 frames without per-frame positions (Per-frame Functional "
             "Groups, Plane Position Sequence): their placement is unknown")
expect_error("far_slice", corpus / manifest["far_slice"]["open"],
             "the slices are not evenly spaced (median step 1 mm) and an even grid over their "
             "100000 mm would take 100001 slices: not resampled", ResampleUnevenSlices=1)

if check.failures:
    print("%d check(s) failed" % len(check.failures))
    sys.exit(1)
print("medical DICOM series reader: all checks passed")
