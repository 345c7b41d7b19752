#!/usr/bin/python3
"""Write the DICOM reader's test corpus: small series, each with one thing to get right.

    /usr/bin/python3 dicom_corpus.py OUT

Debian's python3-pydicom and numpy write the files; DCMTK's dcmcrle, dcmcjpeg and dcmcjpls
compress copies of the plain series. Every case is a folder OUT/<case>/; OUT/manifest.json
holds what each case must read as (geometry, UIDs, the file to open) and OUT/expected/<case>.npy
its true values (float64, k, j, i order: slice, row, column). Exit status 3 when pydicom or
numpy is missing, 4 when a DCMTK tool is, with the reason on stdout.

Cases (16 columns x 12 rows per slice, small on purpose):
- plain: 6 axial slices, 12 of 16 bits stored unsigned, Rescale Intercept -1024 (HU, int16).
- rle, jpeg_lossless, jpegls: the plain series compressed by DCMTK (same values).
- two_series: the plain series and a 3-slice series in one folder.
- gap: the plain series without its 4th slice.
- uneven: steps of 2, 2, 3, 2, 2 mm.
- slopes: a slope and an intercept per slice (non-integral: float output).
- junk: the plain series with a text file, a binary file, a named pipe and a DICOM file without
  pixel data.
- jpeg2000: the plain series with one file's transfer syntax UID set to JPEG 2000.
- multiframe: one Enhanced CT file of 5 frames in reverse position order, functional groups.
- shuffled: the plain series with file names and instance numbers in a shuffled order.
- oblique: signed 16-bit slices on a rotated plane, stacked along its normal, files shuffled.
- mr8: 8-bit slices, implicit VR, no rescale (uint8 as stored).
- bigendian: signed 16-bit slices in explicit VR big endian.
- duplicate: the plain series with one slice copied under another UID.
- mixed_size: the plain series with a 7th slice of 8 x 8 pixels.
- tilted: slices shifted along y as they go along z (a gantry tilt).
- mixed_orientation: the plain series with a 7th slice on a coronal plane.
- rgb: a colour image.
- truncated: the plain series with one slice's file cut short.
- short_pixels: a slice whose Pixel Data is shorter than Rows x Columns.
- huge: a multi-frame header claiming 34 TB of pixels over 64 bytes; huge_rle: the same, RLE.
- frames_claimed: a header claiming two billion frames without per-frame groups.
- far_slice: slices at 0, 1, 2 and 100000 mm (an even grid too large to resample onto).
"""
import json
import os
import shutil
import subprocess
import sys

try:
    import numpy
    import pydicom
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.encaps import encapsulate
    from pydicom.uid import ExplicitVRLittleEndian
except ImportError as error:  # pragma: no cover - the skip path
    print("pydicom or numpy is missing for %s (%s): apt-get install python3-pydicom"
          % (sys.executable, error))
    sys.exit(3)

COLUMNS, ROWS = 16, 12
CT_IMAGE = "1.2.840.10008.5.1.4.1.1.2"
ENHANCED_CT_IMAGE = "1.2.840.10008.5.1.4.1.1.2.1"
BASIC_TEXT_SR = "1.2.840.10008.5.1.4.1.1.88.11"
JPEG2000_LOSSLESS = "1.2.840.10008.1.2.4.90"
PLAIN_Z = [10.0 + 2.5 * k for k in range(6)]


def uid(*parts):
    """A deterministic 2.25 UID."""
    import hashlib
    digest = hashlib.sha1("/".join(str(p) for p in parts).encode()).digest()[:16]
    return "2.25.%d" % int.from_bytes(digest, "big")


def stored_slice(k, seed=0):
    """Stored values of slice k: 0..4095, different in every pixel and slice."""
    j, i = numpy.mgrid[0:ROWS, 0:COLUMNS]
    return ((i * 37 + j * 101 + k * 211 + seed * 17) % 4096).astype(numpy.uint16)


def base_dataset(sop_class, series, instance, number):
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = sop_class
    meta.MediaStorageSOPInstanceUID = instance
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.is_little_endian = True
    ds.is_implicit_VR = False
    ds.SOPClassUID = sop_class
    ds.SOPInstanceUID = instance
    ds.Modality = "CT"
    ds.PatientName = "Corpus^Test"
    ds.PatientID = "MEDISO-DICOM-CORPUS"
    ds.StudyInstanceUID = uid("study")
    ds.SeriesInstanceUID = series
    ds.InstanceNumber = number
    return ds


def image_slice(path, series, k, pixels, position, orientation=(1, 0, 0, 0, 1, 0),
                slope=1.0, intercept=-1024.0, signed=False, bits_stored=12, number=None,
                description="Corpus series"):
    ds = base_dataset(CT_IMAGE, series, uid(series, path, k), number if number else k + 1)
    ds.SeriesDescription = description
    ds.ImagePositionPatient = [float(v) for v in position]
    ds.ImageOrientationPatient = [float(v) for v in orientation]
    ds.PixelSpacing = [0.8, 0.6]  # between rows, between columns
    ds.SliceThickness = 2.5
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.Rows, ds.Columns = ROWS, COLUMNS
    ds.BitsAllocated = 16
    ds.BitsStored = bits_stored
    ds.HighBit = bits_stored - 1
    ds.PixelRepresentation = 1 if signed else 0
    ds.RescaleSlope = "%.10g" % slope
    ds.RescaleIntercept = "%.10g" % intercept
    ds.PixelData = pixels.astype(numpy.int16 if signed else numpy.uint16).tobytes()
    ds.save_as(path, write_like_original=False)


def plain_series(folder, series, z=PLAIN_Z, names=None, numbers=None, seed=0):
    """The plain series (or the slices at z); returns the true HU (k, j, i)."""
    os.makedirs(folder, exist_ok=True)
    values = []
    for k, position in enumerate(z):
        pixels = stored_slice(k, seed)
        name = names[k] if names else "slice_%03d.dcm" % k
        image_slice(os.path.join(folder, name), series, k, pixels, (-20.0, -15.0, position),
                    number=numbers[k] if numbers else None)
        values.append(pixels.astype(float) - 1024.0)
    return numpy.array(values)


def compress(tool, source, target):
    os.makedirs(target, exist_ok=True)
    for name in sorted(os.listdir(source)):
        result = subprocess.run([tool, os.path.join(source, name), os.path.join(target, name)],
                                capture_output=True, text=True)
        if result.returncode != 0:
            raise SystemExit("%s failed on %s: %s" % (tool, name, result.stdout + result.stderr))


def main(out):
    tools = {name: shutil.which(name) for name in ("dcmcrle", "dcmcjpeg", "dcmcjpls")}
    missing = [name for name, path in tools.items() if not path]
    if missing:
        print("DCMTK's %s not installed: apt-get install dcmtk" % ", ".join(missing))
        return 4
    if os.path.exists(out):
        shutil.rmtree(out)
    os.makedirs(os.path.join(out, "expected"))
    manifest = {}

    def case(name, values, **info):
        numpy.save(os.path.join(out, "expected", name + ".npy"), numpy.asarray(values, float))
        manifest[name] = info

    axial = {"origin": [-20.0, -15.0, 10.0], "spacing": [0.6, 0.8, 2.5],
             "direction": [1, 0, 0, 0, 1, 0, 0, 0, 1]}
    plain_uid = uid("plain")
    plain = plain_series(os.path.join(out, "plain"), plain_uid)
    case("plain", plain, open="plain/slice_000.dcm", series=plain_uid, dtype="int16", **axial)

    for name, tool, syntax in (("rle", "dcmcrle", "1.2.840.10008.1.2.5"),
                               ("jpeg_lossless", "dcmcjpeg", "1.2.840.10008.1.2.4.70"),
                               ("jpegls", "dcmcjpls", "1.2.840.10008.1.2.4.80")):
        compress(tools[tool], os.path.join(out, "plain"), os.path.join(out, name))
        case(name, plain, open=name + "/slice_000.dcm", series=plain_uid, dtype="int16",
             syntax=syntax, **axial)

    # Two series: the plain one (6 slices) and a smaller one at other positions.
    other_uid = uid("other")
    folder = os.path.join(out, "two_series")
    plain_series(folder, plain_uid)
    other = []
    for k in range(3):
        pixels = stored_slice(k, seed=5)
        image_slice(os.path.join(folder, "other_%03d.dcm" % k), other_uid, k, pixels,
                    (-20.0, -15.0, 50.0 + 3.0 * k), description="Other series")
        other.append(pixels.astype(float) - 1024.0)
    case("two_series", plain, open="two_series/slice_000.dcm", series=plain_uid, dtype="int16",
         other_series=other_uid, **axial)
    case("two_series_other", other, open="two_series/other_001.dcm", series=other_uid,
         dtype="int16", origin=[-20.0, -15.0, 50.0], spacing=[0.6, 0.8, 3.0],
         direction=axial["direction"])

    # A gap: the 4th slice (z = 17.5) missing; resampled, it is the mean of its neighbours.
    folder = os.path.join(out, "gap")
    plain_series(folder, uid("gap"))
    os.remove(os.path.join(folder, "slice_003.dcm"))
    resampled = plain.copy()
    resampled[3] = (plain[2] + plain[4]) / 2.0
    case("gap", resampled, open="gap/slice_000.dcm", series=uid("gap"), dtype="float32",
         **axial)

    # Uneven steps: 2, 2, 3, 2, 2 mm.
    uneven_z = [0.0, 2.0, 4.0, 7.0, 9.0, 11.0]
    uneven = plain_series(os.path.join(out, "uneven"), uid("uneven"), z=uneven_z)
    # Resampled onto 7 slices 11/6 mm apart (span 11 mm, median step 2 mm: 5.5 steps,
    # rounded half away from zero to 6).
    grid = [11.0 / 6.0 * k for k in range(7)]
    grid[-1] = 11.0
    values = []
    for at in grid:
        b = max(i for i in range(5) if uneven_z[i] <= at + 1e-9)
        w = (at - uneven_z[b]) / (uneven_z[b + 1] - uneven_z[b])
        values.append((1 - w) * uneven[b] + w * uneven[b + 1])
    case("uneven", numpy.array(values), open="uneven/slice_000.dcm", series=uid("uneven"),
         dtype="float32", origin=[-20.0, -15.0, 0.0], spacing=[0.6, 0.8, 11.0 / 6.0],
         direction=axial["direction"])

    # A slope and an intercept per slice, values exact in float32.
    folder = os.path.join(out, "slopes")
    os.makedirs(folder)
    values = []
    for k, z in enumerate(PLAIN_Z):
        slope, intercept = 0.5 * (k + 1), -1000.25 + 10 * k
        pixels = stored_slice(k)
        image_slice(os.path.join(folder, "slice_%03d.dcm" % k), uid("slopes"), k, pixels,
                    (-20.0, -15.0, z), slope=slope, intercept=intercept)
        values.append(pixels.astype(float) * slope + intercept)
    case("slopes", values, open="slopes/slice_000.dcm", series=uid("slopes"), dtype="float32",
         **axial)

    # Not images: a text file, random bytes, and a DICOM file without pixel data in the series.
    folder = os.path.join(out, "junk")
    plain_series(folder, plain_uid)
    with open(os.path.join(folder, "notes.txt"), "w") as f:
        f.write("Not DICOM: a note left in the series folder.\n" * 20)
    with open(os.path.join(folder, "random.bin"), "wb") as f:
        f.write(bytes((i * 73 + 11) % 256 for i in range(4096)))
    os.mkfifo(os.path.join(folder, "pipe"))  # opening it to read would block
    report = base_dataset(BASIC_TEXT_SR, plain_uid, uid("report"), 99)
    report.Modality = "SR"
    report.ValueType = "CONTAINER"
    report.save_as(os.path.join(folder, "report.dcm"), write_like_original=False)
    case("junk", plain, open="junk/slice_000.dcm", series=plain_uid, dtype="int16", **axial)

    # A transfer syntax the reader does not decode, named in its message.
    folder = os.path.join(out, "jpeg2000")
    plain_series(folder, plain_uid)
    ds = pydicom.dcmread(os.path.join(folder, "slice_002.dcm"))
    ds.file_meta.TransferSyntaxUID = JPEG2000_LOSSLESS
    # Encapsulated as a compressed syntax requires (the fragment is not a real
    # JPEG 2000 codestream: the reader must refuse the syntax before decoding).
    ds.PixelData = encapsulate([ds.PixelData])
    ds["PixelData"].is_undefined_length = True
    ds["PixelData"].VR = "OB"
    ds.save_as(os.path.join(folder, "slice_002.dcm"), write_like_original=False)
    case("jpeg2000", plain, open="jpeg2000/slice_000.dcm", series=plain_uid,
         syntax=JPEG2000_LOSSLESS)

    # Enhanced CT, one file: frames stored in decreasing position, the rescale and
    # orientation in the shared functional groups, the positions per frame.
    folder = os.path.join(out, "multiframe")
    os.makedirs(folder)
    series = uid("multiframe")
    ds = base_dataset(ENHANCED_CT_IMAGE, series, uid(series, "file"), 1)
    ds.SeriesDescription = "Enhanced CT"
    frames = 5
    ds.NumberOfFrames = frames
    ds.Rows, ds.Columns = ROWS, COLUMNS
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 12, 11, 0
    measures = Dataset()
    measures.PixelSpacing = [0.7, 0.9]
    measures.SliceThickness = 3.0
    orientation = Dataset()
    orientation.ImageOrientationPatient = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    transform = Dataset()
    transform.RescaleIntercept = "-1000"
    transform.RescaleSlope = "1"
    transform.RescaleType = "HU"
    shared = Dataset()
    shared.PixelMeasuresSequence = [measures]
    shared.PlaneOrientationSequence = [orientation]
    shared.PixelValueTransformationSequence = [transform]
    ds.SharedFunctionalGroupsSequence = [shared]
    per_frame, pixels, values = [], [], []
    for f in range(frames):
        k = frames - 1 - f  # frame f is the k-th slice in increasing position
        position = Dataset()
        position.ImagePositionPatient = [5.0, 6.0, -30.0 + 3.0 * k]
        group = Dataset()
        group.PlanePositionSequence = [position]
        per_frame.append(group)
        pixels.append(stored_slice(k, seed=9))
    ds.PerFrameFunctionalGroupsSequence = per_frame
    ds.PixelData = numpy.array(pixels, numpy.uint16).tobytes()
    ds.save_as(os.path.join(folder, "enhanced.dcm"), write_like_original=False)
    values = [stored_slice(k, seed=9).astype(float) - 1000.0 for k in range(frames)]
    case("multiframe", values, open="multiframe/enhanced.dcm", series=series, dtype="int16",
         origin=[5.0, 6.0, -30.0], spacing=[0.9, 0.7, 3.0], direction=axial["direction"])

    # File names and instance numbers in a shuffled order.
    order = [3, 0, 5, 1, 4, 2]  # slice k goes to file name order[k]
    shuffled = plain_series(os.path.join(out, "shuffled"), uid("shuffled"),
                            names=["img_%03d.dcm" % order[k] for k in range(6)],
                            numbers=[order[k] + 1 for k in range(6)])
    case("shuffled", shuffled, open="shuffled/img_000.dcm", series=uid("shuffled"),
         dtype="int16", **axial)

    # An oblique plane: rows along (cos a, sin a, 0), columns tilted by b, signed pixels.
    a, b = numpy.radians(30.0), numpy.radians(20.0)
    row = numpy.array([numpy.cos(a), numpy.sin(a), 0.0])
    col = numpy.array([-numpy.sin(a) * numpy.cos(b), numpy.cos(a) * numpy.cos(b), numpy.sin(b)])
    # Decimal strings hold at most 16 characters: round the cosines, then use
    # the rounded values for the expected geometry.
    row = numpy.array([float("%.8f" % v) for v in row])
    col = numpy.array([float("%.8f" % v) for v in col])
    normal = numpy.cross(row, col)
    origin = numpy.array([12.5, -40.0, 7.25])
    folder = os.path.join(out, "oblique")
    os.makedirs(folder)
    series = uid("oblique")
    values, positions = [], []
    for k in range(4):
        pixels = stored_slice(k, seed=3).astype(numpy.int32) - 2048  # -2048..2047
        position = origin + 1.75 * k * normal
        position = [float("%.6f" % v) for v in position]
        positions.append(position)
        if k == 0:
            origin = numpy.array(position)
        image_slice(os.path.join(folder, "o_%d.dcm" % ((k * 3) % 4)), series, k, pixels,
                    position, orientation=list(row) + list(col), slope=1.0, intercept=0.0,
                    signed=True, bits_stored=16, number=4 - k)
        values.append(pixels.astype(float))
    case("oblique", values, open="oblique/o_0.dcm", series=series, dtype="int16",
         positions=positions, row=list(row), column=list(col),
         origin=list(origin), spacing=[0.6, 0.8, 1.75],
         direction=[row[0], col[0], normal[0], row[1], col[1], normal[1],
                    row[2], col[2], normal[2]])

    # 8-bit MR-like slices in implicit VR little endian, no rescale: uint8 as stored.
    folder = os.path.join(out, "mr8")
    os.makedirs(folder)
    values = []
    for k in range(3):
        pixels = (stored_slice(k) % 256).astype(numpy.uint8)
        path = os.path.join(folder, "mr_%d.dcm" % k)
        image_slice(path, uid("mr8"), k, pixels, (0.0, 0.0, 4.0 * k), slope=1.0, intercept=0.0)
        ds = pydicom.dcmread(path)
        ds.file_meta.TransferSyntaxUID = pydicom.uid.ImplicitVRLittleEndian
        ds.is_implicit_VR, ds.is_little_endian = True, True
        ds.Modality = "MR"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit = 8, 8, 7
        del ds.RescaleSlope, ds.RescaleIntercept
        ds.PixelData = pixels.tobytes()
        ds.save_as(path, write_like_original=False)
        values.append(pixels.astype(float))
    case("mr8", values, open="mr8/mr_0.dcm", series=uid("mr8"), dtype="uint8",
         origin=[0.0, 0.0, 0.0], spacing=[0.6, 0.8, 4.0], direction=axial["direction"])

    # Signed 16-bit in explicit VR big endian (retired, still met), intercept 0.
    folder = os.path.join(out, "bigendian")
    os.makedirs(folder)
    values = []
    for k in range(3):
        pixels = stored_slice(k, seed=2).astype(numpy.int16) - 2000
        path = os.path.join(folder, "be_%d.dcm" % k)
        image_slice(path, uid("bigendian"), k, pixels, (0.0, 0.0, 4.0 * k), slope=1.0,
                    intercept=0.0, signed=True, bits_stored=16)
        ds = pydicom.dcmread(path)
        ds.file_meta.TransferSyntaxUID = pydicom.uid.ExplicitVRBigEndian
        ds.is_implicit_VR, ds.is_little_endian = False, False
        ds.PixelData = pixels.astype(">i2").tobytes()
        ds.save_as(path, write_like_original=False)
        values.append(pixels.astype(float))
    case("bigendian", values, open="bigendian/be_0.dcm", series=uid("bigendian"),
         dtype="int16", origin=[0.0, 0.0, 0.0], spacing=[0.6, 0.8, 4.0],
         direction=axial["direction"])

    # The same position twice: a copy of a slice under another SOP Instance UID.
    folder = os.path.join(out, "duplicate")
    plain_series(folder, uid("duplicate"))
    ds = pydicom.dcmread(os.path.join(folder, "slice_001.dcm"))
    ds.SOPInstanceUID = ds.file_meta.MediaStorageSOPInstanceUID = uid("duplicate", "copy")
    ds.save_as(os.path.join(folder, "slice_001_copy.dcm"), write_like_original=False)
    case("duplicate", plain, open="duplicate/slice_000.dcm", series=uid("duplicate"))

    # One slice of another size in the series.
    folder = os.path.join(out, "mixed_size")
    plain_series(folder, uid("mixed"))
    image_slice(os.path.join(folder, "slice_006.dcm"), uid("mixed"), 6,
                stored_slice(6)[:8, :8].copy(), (-20.0, -15.0, 25.0))
    ds = pydicom.dcmread(os.path.join(folder, "slice_006.dcm"))
    ds.Rows, ds.Columns = 8, 8
    ds.save_as(os.path.join(folder, "slice_006.dcm"), write_like_original=False)
    case("mixed_size", plain, open="mixed_size/slice_000.dcm", series=uid("mixed"))

    # A gantry tilt: each slice shifted 0.5 mm along y, so the stack leaves the normal.
    folder = os.path.join(out, "tilted")
    os.makedirs(folder)
    for k, z in enumerate(PLAIN_Z):
        image_slice(os.path.join(folder, "slice_%03d.dcm" % k), uid("tilted"), k, stored_slice(k),
                    (-20.0, -15.0 + 0.5 * k, z))
    case("tilted", plain, open="tilted/slice_000.dcm", series=uid("tilted"))

    # One slice of the series on another plane.
    folder = os.path.join(out, "mixed_orientation")
    plain_series(folder, uid("orientation"))
    image_slice(os.path.join(folder, "slice_006.dcm"), uid("orientation"), 6, stored_slice(6),
                (-20.0, -15.0, 25.0), orientation=(1, 0, 0, 0, 0, -1))
    case("mixed_orientation", plain, open="mixed_orientation/slice_000.dcm",
         series=uid("orientation"))

    # Colour: three samples per pixel.
    folder = os.path.join(out, "rgb")
    os.makedirs(folder)
    path = os.path.join(folder, "colour.dcm")
    image_slice(path, uid("rgb"), 0, stored_slice(0), (0.0, 0.0, 0.0))
    ds = pydicom.dcmread(path)
    ds.SamplesPerPixel, ds.PhotometricInterpretation, ds.PlanarConfiguration = 3, "RGB", 0
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 8, 8, 7, 0
    ds.PixelData = bytes(ROWS * COLUMNS * 3)
    ds.save_as(path, write_like_original=False)
    case("rgb", plain[:1], open="rgb/colour.dcm", series=uid("rgb"))

    # Damaged files. A slice cut short in its pixel data, in the middle of the series.
    folder = os.path.join(out, "truncated")
    plain_series(folder, uid("truncated"))
    cut = os.path.join(folder, "slice_002.dcm")
    with open(cut, "rb") as f:
        data = f.read()
    with open(cut, "wb") as f:
        f.write(data[:len(data) - 100])
    case("truncated", plain, open="truncated/slice_000.dcm", series=uid("truncated"))

    # One slice whose pixel data is shorter than Rows x Columns says (its length
    # consistent with the file, so that only the reader can tell).
    folder = os.path.join(out, "short_pixels")
    os.makedirs(folder)
    image_slice(os.path.join(folder, "short.dcm"), uid("short"), 0, stored_slice(0),
                (0.0, 0.0, 0.0))
    ds = pydicom.dcmread(os.path.join(folder, "short.dcm"))
    ds.PixelData = ds.PixelData[:100]
    ds.save_as(os.path.join(folder, "short.dcm"), write_like_original=False)
    case("short_pixels", plain[:1], open="short_pixels/short.dcm", series=uid("short"))

    # A multi-frame header that claims 4000 frames of 65535 x 65535 (34 TB) over
    # a few bytes of pixel data: refused before any allocation.
    folder = os.path.join(out, "huge")
    os.makedirs(folder)
    series = uid("huge")
    ds = base_dataset(ENHANCED_CT_IMAGE, series, uid(series, "file"), 1)
    frames = 4000
    ds.NumberOfFrames = frames
    ds.Rows, ds.Columns = 65535, 65535
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 0
    ds.SharedFunctionalGroupsSequence = [shared]
    per_frame = []
    for f in range(frames):
        position = Dataset()
        position.ImagePositionPatient = [0.0, 0.0, float(f)]
        group = Dataset()
        group.PlanePositionSequence = [position]
        per_frame.append(group)
    ds.PerFrameFunctionalGroupsSequence = per_frame
    ds.PixelData = bytes(64)
    ds.save_as(os.path.join(folder, "huge.dcm"), write_like_original=False)
    case("huge", plain[:1], open="huge/huge.dcm", series=series)
    # The same header over an RLE fragment: compressed, its size is unknown
    # until decoded, so the memory check is what refuses it.
    folder = os.path.join(out, "huge_rle")
    os.makedirs(folder)
    ds.file_meta.TransferSyntaxUID = "1.2.840.10008.1.2.5"
    ds.PixelData = encapsulate([bytes(64)])
    ds["PixelData"].VR = "OB"
    ds["PixelData"].is_undefined_length = True
    ds.save_as(os.path.join(folder, "huge.dcm"), write_like_original=False)
    case("huge_rle", plain[:1], open="huge_rle/huge.dcm", series=series)

    # A multi-frame header claiming two billion frames and no per-frame groups.
    folder = os.path.join(out, "frames_claimed")
    os.makedirs(folder)
    image_slice(os.path.join(folder, "frames.dcm"), uid("frames"), 0, stored_slice(0),
                (0.0, 0.0, 0.0))
    ds = pydicom.dcmread(os.path.join(folder, "frames.dcm"))
    ds.NumberOfFrames = 2000000000
    ds.save_as(os.path.join(folder, "frames.dcm"), write_like_original=False)
    case("frames_claimed", plain[:1], open="frames_claimed/frames.dcm", series=uid("frames"))

    # Slices at 0, 1, 2 and 100000 mm: an even grid would take 100001 slices.
    far = plain_series(os.path.join(out, "far_slice"), uid("far"), z=[0.0, 1.0, 2.0, 1.0e5])
    case("far_slice", far, open="far_slice/slice_000.dcm", series=uid("far"))

    with open(os.path.join(out, "manifest.json"), "w") as f:
        json.dump(manifest, f, indent=1)
    print("dicom_corpus: %d cases in %s" % (len(manifest), out))
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print(__doc__)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
