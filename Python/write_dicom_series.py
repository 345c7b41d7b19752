#!/usr/bin/env python3
"""Write an int16 MetaImage volume (the head CT) as a DICOM CT series, with DCMTK.

    python3 Python/write_dicom_series.py --mha ct_head.mha --out DIR [--intercept -1024]

One file per slice, DIR/slice_NNN.dcm, made by DCMTK's ``dump2dcm`` (Debian
package ``dcmtk``) from a text dump of the slice's attributes and a raw file
of its pixels. The series is an ordinary axial CT as a scanner would store
it: unsigned 16-bit pixels, stored value = HU - intercept, with Rescale
Intercept and Rescale Slope (1) so that a reader that applies them gets
Hounsfield units back; Image Orientation (Patient) 1\\0\\0\\0\\1\\0, Image
Position (Patient) of each slice = the volume's origin + k x slice spacing
along z, Pixel Spacing (row spacing, then column spacing) and Slice
Thickness from the MetaImage header. The MetaImage's axes are taken as
DICOM patient axes (both are LPS), so a reader that honours the DICOM
geometry gives back the same image as the .mha.

UIDs are derived from the input's name and size (2.25.<integer> form), so
that writing the same volume twice gives the same files. Exit status 2 when
dump2dcm is not installed.
"""
import argparse
import hashlib
import os
import shutil
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fetch_data  # noqa: E402 (the project's MetaImage parser)

CT_IMAGE_STORAGE = "1.2.840.10008.5.1.4.1.1.2"


def uid(*parts):
    """A DICOM UID of the 2.25 form (a UUID-sized integer) derived from parts."""
    digest = hashlib.sha1("/".join(str(p) for p in parts).encode()).digest()[:16]
    return "2.25.%d" % int.from_bytes(digest, "big")


def ds(value):
    """A DICOM decimal string (at most 16 characters)."""
    text = "%.10g" % value
    return text if len(text) <= 16 else "%.6g" % value


def slice_dump(header, k, pixel_file, study, series, intercept):
    dims, spacing, origin = header["dims"], header["spacing"], header["origin"]
    position = [origin[0], origin[1], origin[2] + k * spacing[2]]
    lines = [
        "(0008,0016) UI =CTImageStorage",
        "(0008,0018) UI [%s]" % uid(series, "instance", k),
        "(0008,0060) CS [CT]",
        "(0008,103e) LO [Head CT (MedicalIsosurfaces test series)]",
        "(0010,0010) PN [Anonymous]",
        "(0010,0020) LO [MEDISO-CT-HEAD]",
        "(0018,0050) DS [%s]" % ds(spacing[2]),
        "(0020,000d) UI [%s]" % study,
        "(0020,000e) UI [%s]" % series,
        "(0020,0013) IS [%d]" % (k + 1),
        "(0020,0032) DS [%s]" % "\\".join(ds(v) for v in position),
        "(0020,0037) DS [1\\0\\0\\0\\1\\0]",
        "(0020,1041) DS [%s]" % ds(position[2]),
        "(0028,0002) US 1",
        "(0028,0004) CS [MONOCHROME2]",
        "(0028,0010) US %d" % dims[1],
        "(0028,0011) US %d" % dims[0],
        "(0028,0030) DS [%s\\%s]" % (ds(spacing[1]), ds(spacing[0])),
        "(0028,0100) US 16",
        "(0028,0101) US 16",
        "(0028,0102) US 15",
        "(0028,0103) US 0",
        "(0028,1052) DS [%s]" % ds(intercept),
        "(0028,1053) DS [1]",
        "(0028,1054) LO [HU]",
        "(7fe0,0010) OW =%s" % pixel_file,
    ]
    return "\n".join(lines) + "\n"


def read_mha(path):
    header = fetch_data.parse_mha(path)
    if header["scalar_type"] != "int16":
        raise ValueError("%s: int16 expected, got %s" % (path, header["scalar_type"]))
    origin = [0.0, 0.0, 0.0]
    with open(path, "rb") as f:
        data = f.read()
    for line in data[:header["file_bytes"] - header["data_bytes"]].decode("ascii").splitlines():
        key, _, value = line.partition("=")
        if key.strip() == "Offset":
            origin = [float(v) for v in value.split()]
    header["origin"] = origin
    return header, data[header["file_bytes"] - header["data_bytes"]:]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mha", required=True, help="int16 MetaImage volume (HU)")
    parser.add_argument("--out", required=True, help="directory for slice_NNN.dcm")
    parser.add_argument("--intercept", type=float, default=-1024.0,
                        help="Rescale Intercept: stored value = HU - intercept (default -1024)")
    args = parser.parse_args(argv)

    dump2dcm = shutil.which("dump2dcm")
    if not dump2dcm:
        print("write_dicom_series: dump2dcm not found (apt-get install dcmtk)")
        return 2
    header, voxels = read_mha(args.mha)
    dims = header["dims"]
    count = dims[0] * dims[1]
    values = struct.unpack("<%dh" % (count * dims[2]), voxels)
    lowest = min(values)
    if lowest - args.intercept < 0 or max(values) - args.intercept > 65535:
        raise SystemExit("write_dicom_series: values %d..%d do not fit unsigned 16 bits with "
                         "intercept %g" % (lowest, max(values), args.intercept))
    os.makedirs(args.out, exist_ok=True)
    name = os.path.basename(args.mha)
    study = uid(name, dims, "study")
    series = uid(name, dims, "series")
    with tempfile.TemporaryDirectory() as work:
        for k in range(dims[2]):
            stored = [v - int(args.intercept) for v in values[k * count:(k + 1) * count]]
            pixels = os.path.join(work, "slice_%03d.raw" % k)
            with open(pixels, "wb") as f:
                f.write(struct.pack("<%dH" % count, *stored))
            dump = os.path.join(work, "slice_%03d.txt" % k)
            with open(dump, "w") as f:
                f.write(slice_dump(header, k, pixels, study, series, args.intercept))
            out = os.path.join(args.out, "slice_%03d.dcm" % k)
            result = subprocess.run([dump2dcm, "--write-xfer-little", dump, out],
                                    capture_output=True, text=True)
            if result.returncode != 0:
                raise SystemExit("write_dicom_series: dump2dcm failed on slice %d: %s"
                                 % (k, (result.stdout + result.stderr).strip()))
    print("write_dicom_series: %d slices of %dx%d, spacing %s, intercept %g -> %s"
          % (dims[2], dims[0], dims[1], header["spacing"], args.intercept, args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
