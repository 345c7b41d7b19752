"""Offline test of Python/fetch_data.py's format code (plain python3, no network).

The real data cannot be fetched everywhere, so the converters are checked on
small synthetic inputs: MetaImage write/parse round trips (int16 with negative
values, uint8), byte order of the written voxels, rejection of truncated files,
NIfTI-1 header parsing in both byte orders, and the InVesalius plist geometry
(numpy z, y, x order to x, y, z); and the data folder's one rule (MEDISO_DATA_DIR, else
${XDG_CACHE_HOME:-$HOME/.cache}/medical-isosurfaces).
"""
import array
import importlib.util
import os
import pathlib
import struct
import sys
import tempfile

here = pathlib.Path(__file__).resolve().parent
spec = importlib.util.spec_from_file_location(
    "fetch_data", here.parent.parent / "Python" / "fetch_data.py")
fetch_data = importlib.util.module_from_spec(spec)
spec.loader.exec_module(fetch_data)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)
from nifti import nifti1_header  # noqa: E402  (Testing/Python/nifti.py)

check = Checks()


def nifti_header(endian, dims, spacing, datatype, bitpix):
    return nifti1_header(dims, spacing, datatype, bitpix, endian=endian, slope=1.0)


with tempfile.TemporaryDirectory() as tmp:
    tmp = pathlib.Path(tmp)
    # int16 round trip, little-endian on disk whatever the host.
    dims = (5, 4, 3)
    values = array.array("h", [(-1024 + 97 * i) for i in range(fetch_data.product(dims))])
    path = tmp / "ct.mha"
    fetch_data.write_mha(path, dims, (0.9570312, 0.9570312, 1.5), "int16",
                         fetch_data.little_endian_bytes(values))
    info = fetch_data.parse_mha(path)
    check(info["dims"] == list(dims), "int16 dims round trip: %s" % info["dims"])
    check(abs(info["spacing"][0] - 0.9570312) < 1e-9 and info["spacing"][2] == 1.5,
          "spacing round trip: %s" % info["spacing"])
    check(info["scalar_type"] == "int16", "scalar type round trip")
    raw = path.read_bytes()[-info["data_bytes"]:]
    check(struct.unpack_from("<h", raw, 0)[0] == -1024 and
          struct.unpack_from("<h", raw, 2)[0] == -1024 + 97, "voxels stored little-endian")
    back = fetch_data.voxels_to_array(raw, "int16", True)
    check(back == values, "voxels round trip")
    check(fetch_data.value_range(back) == (min(values), max(values)), "value range")

    # A truncated file is rejected, not trusted.
    truncated = tmp / "short.mha"
    truncated.write_bytes(path.read_bytes()[:-2])
    try:
        fetch_data.parse_mha(truncated)
        check(False, "truncated .mha rejected")
    except ValueError:
        pass

    # uint8 round trip.
    u8 = array.array("B", [i % 256 for i in range(7 * 6 * 5)])
    path8 = tmp / "mri.mha"
    fetch_data.write_mha(path8, (7, 6, 5), (1, 1, 1), "uint8", u8.tobytes())
    info8 = fetch_data.parse_mha(path8)
    check(info8["scalar_type"] == "uint8" and info8["dims"] == [7, 6, 5], "uint8 round trip")

# NIfTI-1 headers in both byte orders.
for endian in "<>":
    header = fetch_data.parse_nifti1_header(nifti_header(endian, (181, 217, 181), (1, 1, 1), 2, 8))
    check(header["dims"] == (181, 217, 181) and header["scalar_type"] == "uint8"
          and header["little_endian"] == (endian == "<") and header["vox_offset"] == 352,
          "NIfTI header %s parsed: %s" % (endian, header["dims"]))
try:
    fetch_data.parse_nifti1_header(nifti_header("<", (4, 4, 4), (1, 1, 1), 2, 16))
    check(False, "bitpix/datatype mismatch rejected")
except fetch_data.CheckFailed:
    pass
try:
    fetch_data.parse_nifti1_header(b"\0" * 400)
    check(False, "non-NIfTI data rejected")
except fetch_data.CheckFailed:
    pass

# InVesalius stores numpy shapes (z, y, x).
dims, spacing, dtype, matrix, _ = fetch_data.ct_geometry_from_plist(
    {"matrix": {"shape": [108, 256, 256], "dtype": "int16", "filename": "matrix.dat"},
     "spacing": [0.9570312, 0.9570312, 1.5]})
check(dims == (256, 256, 108) and spacing[2] == 1.5 and dtype == "int16"
      and matrix == "matrix.dat", "plist geometry: %s %s" % (dims, spacing))

# The data folder's rule (resolve_cache_dir; MedicalTestUtilities.h's DataDirectory states it
# for C++).
saved = {k: os.environ.get(k) for k in ("MEDISO_DATA_DIR", "XDG_CACHE_HOME", "HOME")}
try:
    for environment, expected in (
            ({"MEDISO_DATA_DIR": "/data/m", "XDG_CACHE_HOME": "/x", "HOME": "/h"}, "/data/m"),
            ({"MEDISO_DATA_DIR": "", "XDG_CACHE_HOME": "/x", "HOME": "/h"},
             "/x/medical-isosurfaces"),
            ({"MEDISO_DATA_DIR": "", "XDG_CACHE_HOME": "", "HOME": "/h"},
             "/h/.cache/medical-isosurfaces")):
        os.environ.update(environment)
        folder = str(fetch_data.resolve_cache_dir(None))
        check(folder == expected, "data folder with %s: %s (expected %s)"
              % (environment, folder, expected))
finally:
    for key, value in saved.items():
        if value is None:
            os.environ.pop(key, None)
        else:
            os.environ[key] = value

check.finish("fetch_data formats: all checks passed")
