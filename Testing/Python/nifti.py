"""The NIfTI-1 header the Python tests write (plain python3 or pvpython, no imports but struct).

    with open(path, "wb") as f:
        f.write(nifti1_header((8, 6, 5), (0.5, 0.5, 2.0), slope=1.0, intercept=-1024.0) + voxels)

nifti1_header() gives the 348-byte header and its 4 extension bytes (none), as a single file
(.nii) begins: its voxels follow at once (vox_offset 352). Only the fields the tests vary are
set; every other field is zero. The C++ tests have the same writer in
Testing/Cxx/NIfTITestFiles.h, the page's tests in Testing/Web/webserver-harness.mjs.
"""
import struct

NIFTI_TYPE_UINT8 = 2
NIFTI_TYPE_INT16 = 4


def nifti1_header(dims, spacing=(1.0, 1.0, 1.0), datatype=NIFTI_TYPE_INT16, bitpix=16,
                  endian="<", slope=0.0, intercept=0.0, time_step=0.0, toffset=0.0,
                  sform=None, sform_code=0):
    """The header of a volume of `dims` (3 values, or 4 with time steps of `time_step`, pixdim[4])
    and `spacing` (pixdim[1..3], qfac 1) in byte order `endian` ("<" or ">"); `slope` and
    `intercept` calibrate the values (a slope of 0: none); `sform`, three rows of four numbers,
    places the voxels with `sform_code`; no qform."""
    header = bytearray(352)
    struct.pack_into(endian + "i", header, 0, 348)
    struct.pack_into(endian + "8h", header, 40, len(dims), *dims, *[1] * (7 - len(dims)))
    struct.pack_into(endian + "hh", header, 70, datatype, bitpix)
    struct.pack_into(endian + "8f", header, 76, 1.0, *spacing, time_step, 0, 0, 0)
    struct.pack_into(endian + "fff", header, 108, 352.0, slope, intercept)
    struct.pack_into(endian + "f", header, 136, toffset)
    if sform is not None:
        struct.pack_into(endian + "hh", header, 252, 0, sform_code)
        for r in range(3):
            struct.pack_into(endian + "4f", header, 280 + 16 * r, *sform[r])
    header[344:348] = b"n+1\0"
    return bytes(header)
