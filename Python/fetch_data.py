#!/usr/bin/env python3
"""Fetch, convert, check and cache the real test volumes of MedicalIsosurfaces.

What
    Two real head volumes are taken from Debian packages and converted to
    single-file MetaImage (``.mha``) volumes that ParaView and VTK read
    without any plugin:

    ``ct_head.mha``
        Head CT from the package ``invesalius-examples`` (InVesalius project
        ``Cranium.inv3``, a gzip'd tar whose ``matrix.dat`` member is raw
        int16 little-endian, x fastest, 256 x 256 x 108 voxels of
        0.9570312 x 0.9570312 x 1.5 mm, values in HU).  Skin is about
        -500 HU, bone about 400 HU.
    ``mri_head.mha`` (+ the original ``ch2.nii.gz``)
        T1 MRI head template "ch2" (Colin 27) from the package
        ``mricron-data``: NIfTI-1, 181 x 217 x 181 uint8, 1 mm.  Skin is
        about 25-40.

    A manifest ``data.json`` records, per dataset, the path, dimensions,
    spacing, scalar type, value range, byte sizes, source package and
    version, a licence note and suggested isovalues.

Why
    The data is NEVER committed to the source tree: it is large, binary and
    under its own licence (invesalius-examples: GPL-2; mricron-data: BSD
    style, see the package's copyright file).  Instead it is fetched on
    demand through the ordinary Debian tools and cached outside the tree, in
    ``--cache-dir``, else ``$MEDISO_DATA_DIR``, else
    ``${XDG_CACHE_HOME:-$HOME/.cache}/medical-isosurfaces``.

How the packages are obtained
    1. If the file is already installed (``/usr/share/...``) it is used.
    2. As root: ``apt-get install -y --no-install-recommends PKG`` (with an
       ``apt-get update`` only when the package is unknown).  Images that
       exclude ``/usr/share/doc`` from dpkg installs leave the file missing;
       then step 3 is used as well.
    3. Otherwise (or not root): ``apt-get download PKG`` and
       ``dpkg -x PKG_*.deb <cache>/debs/PKG``.

Exit status
    0  every requested dataset is ready (converted and checked),
    1  a check failed (unexpected dimensions, spacing, sizes or values),
    2  the data could not be fetched (no network, no apt, unknown package);
       a line starting with ``fetch_data: unavailable:`` says why.

Only the Python 3 standard library is used; ParaView is not needed.
"""

import argparse
import array
import gzip
import json
import os
import plistlib
import shutil
import struct
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

PREFIX = "fetch_data: "
MANIFEST_NAME = "data.json"
MANIFEST_FORMAT = 1

CT_PACKAGE = "invesalius-examples"
CT_PACKAGE_FILE = "usr/share/doc/invesalius-examples/examples/Cranium.inv3"
CT_EXPECTED_DIMS = (256, 256, 108)
CT_EXPECTED_SPACING = (0.9570312, 0.9570312, 1.5)

MRI_PACKAGE = "mricron-data"
MRI_PACKAGE_FILE = "usr/share/mricron/templates/ch2.nii.gz"
MRI_EXPECTED_DIMS = (181, 217, 181)
MRI_EXPECTED_SPACING = (1.0, 1.0, 1.0)

# The volumes' direction matrices in patient space (LPS, as DICOM and ITK), row-major with the
# voxel axes as columns, as the TransformMatrix is written (and Headless/MetaImage.cxx reads it;
# both matrices here are diagonal, so a reader taking the rows as the axes agrees).
# The head CT: InVesalius' reader (vtkGDCMImageReader, rows flipped to VTK's lower-left origin)
# leaves x along the series' rows, the patient's left in an axial series, y towards the face
# (anterior: -y in LPS) and z up the slices (superior). The file keeps no DICOM header, so x's
# sense is the reader's and cannot be checked from it; y and z are what the volume shows (face
# at +j, crown at +k). The MRI's comes from ch2.nii.gz's sform.
CT_DIRECTION = ((1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0))
IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

SPACING_TOLERANCE = 1e-4

# MetaImage element type, array typecode and bytes per voxel of each scalar type.
SCALAR_TYPES = {
    "uint8": ("MET_UCHAR", "B", 1),
    "int8": ("MET_CHAR", "b", 1),
    "uint16": ("MET_USHORT", "H", 2),
    "int16": ("MET_SHORT", "h", 2),
    "int32": ("MET_INT", "i", 4),
    "float32": ("MET_FLOAT", "f", 4),
}
MET_TO_SCALAR = {met: name for name, (met, _, _) in SCALAR_TYPES.items()}

# NIfTI-1 datatype codes supported here.
NIFTI_DATATYPES = {2: "uint8", 256: "int8", 512: "uint16", 4: "int16", 8: "int32", 16: "float32"}


class Unavailable(Exception):
    """The source data could not be obtained (exit status 2)."""


class CheckFailed(Exception):
    """The data was obtained but does not look as expected (exit status 1)."""


def log(message):
    print(PREFIX + message, flush=True)


def log_error(message):
    print(PREFIX + message, file=sys.stderr, flush=True)


# --------------------------------------------------------------------------
# Cache directory and manifest
# --------------------------------------------------------------------------

def resolve_cache_dir(option):
    if option:
        return Path(option).expanduser().resolve()
    env = os.environ.get("MEDISO_DATA_DIR")
    if env:
        return Path(env).expanduser().resolve()
    xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return (Path(xdg) / "medical-isosurfaces").resolve()


def load_manifest(cache_dir):
    path = cache_dir / MANIFEST_NAME
    try:
        with open(path, encoding="utf-8") as f:
            manifest = json.load(f)
        if isinstance(manifest, dict) and isinstance(manifest.get("datasets"), dict):
            return manifest
    except (OSError, ValueError):
        pass
    return {"datasets": {}}


def save_manifest(cache_dir, manifest):
    manifest["format_version"] = MANIFEST_FORMAT
    manifest["generator"] = "MedicalIsosurfaces Python/fetch_data.py"
    manifest["note"] = ("Fetched from Debian packages on demand; never commit these files. "
                        "Offsets are 0 0 0; axes are the stored voxel axes (x fastest), their "
                        "directions in patient space (LPS) in each file's TransformMatrix and "
                        "'axes'.")
    path = cache_dir / MANIFEST_NAME
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w", encoding="utf-8") as f:
        json.dump(manifest, f, indent=2, sort_keys=True)
        f.write("\n")
    os.replace(tmp, path)


# --------------------------------------------------------------------------
# Getting a file out of a Debian package
# --------------------------------------------------------------------------

def run_command(cmd, cwd=None, timeout=900):
    """Run cmd; return (returncode, combined output).  Missing tools -> Unavailable."""
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive", LC_ALL="C")
    try:
        proc = subprocess.run(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, timeout=timeout)
    except FileNotFoundError:
        raise Unavailable("%s not found (not a Debian/Ubuntu system?)" % cmd[0])
    except subprocess.TimeoutExpired:
        return 124, "%s timed out after %d s" % (" ".join(cmd), timeout)
    except OSError as exc:
        raise Unavailable("cannot run %s: %s" % (cmd[0], exc))
    return proc.returncode, proc.stdout


def apt_error_summary(output):
    """The most telling line of an apt failure (its last 'E:' line), for one-line reports."""
    lines = [line.strip() for line in output.splitlines() if line.strip()]
    errors = [line for line in lines if line.startswith("E:")]
    return " ".join((errors or lines or ["no output"])[-1].split())


def package_unknown(output):
    return ("Unable to locate package" in output or "has no installation candidate" in output
            or "No packages found" in output or "Can't select candidate" in output)


class AptSession:
    """apt-get calls with at most one 'apt-get update' per run."""

    def __init__(self):
        self.updated = False

    def update(self):
        if self.updated or os.geteuid() != 0:
            return False
        self.updated = True
        log("running apt-get update")
        rc, out = run_command(["apt-get", "update"])
        if rc != 0:
            log("apt-get update failed: " + apt_error_summary(out))
        return True

    def install(self, package):
        cmd = ["apt-get", "install", "-y", "--no-install-recommends", package]
        log("running " + " ".join(cmd))
        rc, out = run_command(cmd)
        if rc != 0 and package_unknown(out) and self.update():
            rc, out = run_command(cmd)
        if rc != 0:
            raise Unavailable("apt-get install %s failed: %s" % (package, apt_error_summary(out)))

    def download(self, package, directory):
        cmd = ["apt-get", "download", package]
        log("running %s (in %s)" % (" ".join(cmd), directory))
        rc, out = run_command(cmd, cwd=directory)
        if rc != 0 and package_unknown(out) and self.update():
            rc, out = run_command(cmd, cwd=directory)
        if rc != 0:
            raise Unavailable("apt-get download %s failed: %s" % (package, apt_error_summary(out)))
        debs = sorted(Path(directory).glob(package + "_*.deb"))
        if not debs:
            raise Unavailable("apt-get download %s produced no .deb file" % package)
        return debs[-1]


def installed_version(package):
    try:
        rc, out = run_command(["dpkg-query", "-W", "-f=${Version}", package], timeout=60)
    except Unavailable:
        return "unknown"
    return out.strip() if rc == 0 and out.strip() else "unknown"


def deb_version(deb):
    rc, out = run_command(["dpkg-deb", "-f", str(deb), "Version"], timeout=60)
    return out.strip() if rc == 0 and out.strip() else "unknown"


def extract_deb(apt, package, relpath, cache_dir):
    """apt-get download + dpkg -x; keep only relpath, under <cache>/debs/<package>/.

    Returns (path of the extracted file, package version)."""
    debs_dir = cache_dir / "debs"
    debs_dir.mkdir(parents=True, exist_ok=True)
    target = debs_dir / package / relpath
    with tempfile.TemporaryDirectory(prefix="download-", dir=str(debs_dir)) as tmp:
        deb = apt.download(package, tmp)
        version = deb_version(deb)
        root = Path(tmp) / "root"
        log("extracting %s with dpkg -x" % deb.name)
        rc, out = run_command(["dpkg", "-x", str(deb), str(root)], timeout=600)
        if rc != 0:
            raise Unavailable("dpkg -x %s failed: %s" % (deb.name, apt_error_summary(out)))
        if not (root / relpath).is_file():
            raise Unavailable("package %s %s has no file /%s" % (package, version, relpath))
        if (debs_dir / package).exists():
            shutil.rmtree(debs_dir / package)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.move(str(root / relpath), str(target))
    (debs_dir / (package + ".version")).write_text(version + "\n", encoding="utf-8")
    log("kept %s" % target)
    return target, version


def locate_package_file(apt, package, relpath, cache_dir, use_system, force):
    """Find relpath of package: system, earlier extraction, apt-get install, or download.

    use_system False skips the installed file and apt-get install (testing the
    plain-user path).  Returns (path, version, how)."""
    system_path = Path("/") / relpath
    if use_system and system_path.is_file():
        return system_path, installed_version(package), "installed system file"

    extracted = cache_dir / "debs" / package / relpath
    version_file = cache_dir / "debs" / (package + ".version")
    if not force and extracted.is_file() and version_file.is_file():
        version = version_file.read_text(encoding="utf-8").strip() or "unknown"
        return extracted, version, "earlier dpkg -x extraction"

    if use_system and os.geteuid() == 0:
        try:
            apt.install(package)
        except Unavailable as exc:
            log("%s; trying apt-get download instead" % exc)
        else:
            if system_path.is_file():
                return system_path, installed_version(package), "apt-get install"
            log("%s is installed but %s is missing (dpkg path-exclude?); "
                "trying apt-get download + dpkg -x" % (package, system_path))

    extracted, version = extract_deb(apt, package, relpath, cache_dir)
    return extracted, version, "apt-get download + dpkg -x"


# --------------------------------------------------------------------------
# Voxel data helpers
# --------------------------------------------------------------------------

def product(values):
    result = 1
    for v in values:
        result *= int(v)
    return result


def voxels_to_array(raw, scalar_type, little_endian):
    """Host-order array of the voxels stored in raw with the given byte order."""
    code = SCALAR_TYPES[scalar_type][1]
    values = array.array(code)
    if values.itemsize != SCALAR_TYPES[scalar_type][2]:
        raise CheckFailed("array typecode %r is %d bytes here, need %d"
                          % (code, values.itemsize, SCALAR_TYPES[scalar_type][2]))
    values.frombytes(raw)
    if values.itemsize > 1 and little_endian != (sys.byteorder == "little"):
        values.byteswap()
    return values


def little_endian_bytes(values):
    """Bytes of a host-order array, written little-endian whatever the host."""
    if values.itemsize > 1 and sys.byteorder != "little":
        values = array.array(values.typecode, values)
        values.byteswap()
    return values.tobytes()


def value_range(values):
    return min(values), max(values)


def format_number(value):
    value = float(value)
    return str(int(value)) if value.is_integer() else repr(value)


def write_mha(path, dims, spacing, scalar_type, data_le, axes=IDENTITY):
    """Write a single-file MetaImage: ASCII header, ElementDataFile = LOCAL, raw bytes. `axes`:
    the direction matrix in patient space (LPS), rows of 3, the voxel axes as columns, written as
    the TransformMatrix (ITK, 3D Slicer and the web server place the volume by it; VTK's and
    ParaView's readers leave it out, so their images and surfaces are the same as without)."""
    header = "\n".join([
        "ObjectType = Image",
        "NDims = 3",
        "BinaryData = True",
        "BinaryDataByteOrderMSB = False",
        "CompressedData = False",
        "TransformMatrix = " + " ".join(format_number(c) for axis in axes for c in axis),
        "Offset = 0 0 0",
        "CenterOfRotation = 0 0 0",
        "ElementSpacing = " + " ".join(format_number(s) for s in spacing),
        "DimSize = " + " ".join(str(int(d)) for d in dims),
        "ElementType = " + SCALAR_TYPES[scalar_type][0],
        "ElementDataFile = LOCAL",
    ]) + "\n"
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(data_le)
    os.replace(tmp, path)
    return path.stat().st_size


def parse_mha(path):
    """Parse a single-file .mha header; return dict with dims, spacing, scalar_type, sizes.

    Raises ValueError when the file is not a complete LOCAL MetaImage."""
    fields = {}
    header_bytes = 0
    with open(path, "rb") as f:
        for _ in range(64):
            line = f.readline()
            if not line:
                break
            header_bytes += len(line)
            key, sep, value = line.decode("ascii").partition("=")
            if not sep:
                raise ValueError("bad header line %r" % line)
            fields[key.strip()] = value.strip()
            if key.strip() == "ElementDataFile":
                break
    if fields.get("ElementDataFile") != "LOCAL":
        raise ValueError("no 'ElementDataFile = LOCAL'")
    if fields.get("NDims") != "3" or fields.get("BinaryDataByteOrderMSB") != "False":
        raise ValueError("not a 3D little-endian image")
    dims = [int(v) for v in fields["DimSize"].split()]
    spacing = [float(v) for v in fields["ElementSpacing"].split()]
    scalar_type = MET_TO_SCALAR[fields["ElementType"]]
    data_bytes = product(dims) * SCALAR_TYPES[scalar_type][2]
    file_bytes = os.path.getsize(path)
    if len(dims) != 3 or len(spacing) != 3 or file_bytes != header_bytes + data_bytes:
        raise ValueError("size %d != header %d + data %d" % (file_bytes, header_bytes, data_bytes))
    t = [float(v) for v in fields.get("TransformMatrix", "1 0 0 0 1 0 0 0 1").split()]
    return {"dims": dims, "spacing": spacing, "scalar_type": scalar_type,
            "data_bytes": data_bytes, "file_bytes": file_bytes,
            "axes": [t[0:3], t[3:6], t[6:9]]}


# --------------------------------------------------------------------------
# Checks
# --------------------------------------------------------------------------

def check_geometry(name, dims, spacing, expected_dims, expected_spacing):
    if tuple(int(d) for d in dims) != tuple(expected_dims):
        raise CheckFailed("%s: dims %s, expected %s" % (name, list(dims), list(expected_dims)))
    if any(abs(float(s) - e) > SPACING_TOLERANCE for s, e in zip(spacing, expected_spacing)):
        raise CheckFailed("%s: spacing %s, expected %s"
                          % (name, [float(s) for s in spacing], list(expected_spacing)))


def check_byte_count(name, what, actual, dims, scalar_type):
    expected = product(dims) * SCALAR_TYPES[scalar_type][2]
    if actual != expected:
        raise CheckFailed("%s: %s has %d bytes, expected %s x %d bytes = %d"
                          % (name, what, actual, " x ".join(map(str, dims)),
                             SCALAR_TYPES[scalar_type][2], expected))


def check_ct_range(vmin, vmax):
    if not -1100 <= vmin <= -900:
        raise CheckFailed("ct_head: minimum %d HU, expected about -1024" % vmin)
    if not 2000 <= vmax <= 4000:
        raise CheckFailed("ct_head: maximum %d HU, expected within 2000..4000" % vmax)


def check_mri_range(vmin, vmax):
    if vmin < 0 or vmax > 255:
        raise CheckFailed("mri_head: range %s..%s, expected within 0..255" % (vmin, vmax))
    if vmax <= 100:
        raise CheckFailed("mri_head: maximum %s, expected > 100" % vmax)


# --------------------------------------------------------------------------
# Head CT (InVesalius Cranium.inv3)
# --------------------------------------------------------------------------

def describe_inv3(tar):
    """List the members of an .inv3 tar and parse its plists; return main.plist (or None)."""
    main = None
    for member in tar.getmembers():
        log("  inv3 member %-28s %10d bytes" % (member.name, member.size))
    for member in tar.getmembers():
        if not member.isfile() or not member.name.endswith(".plist"):
            continue
        try:
            plist = plistlib.loads(tar.extractfile(member).read())
        except Exception as exc:  # plistlib raises several types
            log("  %s: not a readable plist (%s)" % (member.name, exc))
            continue
        base = os.path.basename(member.name)
        if base == "main.plist":
            main = plist
            matrix = plist.get("matrix", {})
            log("  main.plist: modality=%s name=%r invesalius=%s format_version=%s"
                % (plist.get("modality"), plist.get("name"), plist.get("invesalius_version"),
                   plist.get("format_version")))
            log("  main.plist: matrix %s dtype=%s shape(z,y,x)=%s spacing(x,y,z)=%s"
                % (matrix.get("filename"), matrix.get("dtype"), matrix.get("shape"),
                   plist.get("spacing")))
            log("  main.plist: orientation=%s scalar_range=%s window_width=%s window_level=%s"
                % (plist.get("orientation"), plist.get("scalar_range"),
                   plist.get("window_width"), plist.get("window_level")))
        elif base.startswith("mask_"):
            log("  %s: name=%r threshold_range=%s mask_shape=%s"
                % (base, plist.get("name"), plist.get("threshold_range"), plist.get("mask_shape")))
        elif base.startswith("surface_"):
            log("  %s: %s" % (base, ", ".join("%s=%s" % (k, plist[k]) for k in sorted(plist)
                                             if not isinstance(plist[k], (dict, list)))))
        else:
            log("  %s: keys %s" % (base, sorted(plist) or "(empty)"))
    return main


def ct_geometry_from_plist(main):
    """(dims xyz, spacing xyz, dtype, matrix file name, metadata) from main.plist."""
    matrix = main.get("matrix", {}) if main else {}
    shape = matrix.get("shape")
    spacing = main.get("spacing") if main else None
    if not (isinstance(shape, list) and len(shape) == 3
            and isinstance(spacing, list) and len(spacing) == 3):
        log("  main.plist missing or incomplete; using the expected geometry")
        return CT_EXPECTED_DIMS, CT_EXPECTED_SPACING, "int16", "matrix.dat", {}
    dims = (int(shape[2]), int(shape[1]), int(shape[0]))  # numpy (z, y, x) -> x, y, z
    metadata = {key: main[key] for key in ("modality", "name", "orientation", "scalar_range",
                                           "invesalius_version", "window_width", "window_level")
                if key in main}
    metadata["matrix_shape_zyx"] = shape
    return dims, tuple(float(s) for s in spacing), matrix.get("dtype", "int16"), \
        matrix.get("filename", "matrix.dat"), metadata


def prepare_ct(apt, cache_dir, use_system, force):
    source, version, how = locate_package_file(apt, CT_PACKAGE, CT_PACKAGE_FILE, cache_dir,
                                               use_system, force)
    log("ct_head: using %s (%s %s, %s)" % (source, CT_PACKAGE, version, how))
    try:
        with tarfile.open(source, "r:gz") as tar:
            main = describe_inv3(tar)
            dims, spacing, dtype, matrix_name, metadata = ct_geometry_from_plist(main)
            members = [m for m in tar.getmembers()
                       if m.isfile() and os.path.basename(m.name) == matrix_name]
            if not members:
                members = [m for m in tar.getmembers() if m.isfile() and m.name.endswith("matrix.dat")]
            if not members:
                raise CheckFailed("ct_head: no *matrix.dat member in %s" % source)
            raw = tar.extractfile(members[0]).read()
    except (tarfile.TarError, OSError, EOFError) as exc:
        raise CheckFailed("ct_head: cannot read %s as a gzip'd tar: %s" % (source, exc))

    log("ct_head: plist geometry dims %s spacing %s dtype %s; expected %s %s int16"
        % (list(dims), list(spacing), dtype, list(CT_EXPECTED_DIMS), list(CT_EXPECTED_SPACING)))
    if dtype != "int16":
        raise CheckFailed("ct_head: matrix dtype %r, expected int16" % dtype)
    check_geometry("ct_head", dims, spacing, CT_EXPECTED_DIMS, CT_EXPECTED_SPACING)
    check_byte_count("ct_head", members[0].name, len(raw), dims, "int16")

    # matrix.dat is little-endian int16 (InVesalius memmaps it on x86).
    values = voxels_to_array(raw, "int16", little_endian=True)
    vmin, vmax = value_range(values)
    log("ct_head: value range %d .. %d HU" % (vmin, vmax))
    check_ct_range(vmin, vmax)

    out = cache_dir / "ct_head.mha"
    file_bytes = write_mha(out, dims, spacing, "int16", little_endian_bytes(values), CT_DIRECTION)
    log("ct_head: wrote %s (%d bytes)" % (out, file_bytes))
    return {
        "path": str(out),
        "file": out.name,
        "dims": list(dims),
        "spacing": list(spacing),
        "origin": [0.0, 0.0, 0.0],
        "axes": [list(a) for a in CT_DIRECTION],
        "scalar_type": "int16",
        "met_element_type": "MET_SHORT",
        "value_range": [vmin, vmax],
        "data_bytes": len(raw),
        "file_bytes": file_bytes,
        "source": {"package": CT_PACKAGE, "version": version, "file": "/" + CT_PACKAGE_FILE,
                   "member": members[0].name, "obtained_by": how},
        "source_metadata": metadata,
        "licence": "GPL-2 (Debian package invesalius-examples, InVesalius / CTI Renato Archer); "
                   "do not commit the data",
        "isovalues": {"skin": -500, "bone": 400},
        "notes": "HU. Skin about -500 (stay above -600: foam padding), bone about 400 "
                 "(1000+ keeps only cortical bone). A head holder shows as a partial cylinder.",
    }


# --------------------------------------------------------------------------
# MRI head (mricron ch2.nii.gz)
# --------------------------------------------------------------------------

def parse_nifti1_header(data):
    """Parse the NIfTI-1 fields needed here from the first bytes of a .nii file."""
    if len(data) < 348:
        raise CheckFailed("mri_head: NIfTI file shorter than a header (%d bytes)" % len(data))
    if struct.unpack_from("<i", data, 0)[0] == 348:
        endian = "<"
    elif struct.unpack_from(">i", data, 0)[0] == 348:
        endian = ">"
    else:
        raise CheckFailed("mri_head: sizeof_hdr is not 348: not a NIfTI-1 file")
    dim = struct.unpack_from(endian + "8h", data, 40)
    datatype, bitpix = struct.unpack_from(endian + "2h", data, 70)
    pixdim = struct.unpack_from(endian + "8f", data, 76)
    vox_offset, scl_slope, scl_inter = struct.unpack_from(endian + "3f", data, 108)
    qform_code, sform_code = struct.unpack_from(endian + "2h", data, 252)
    srow = struct.unpack_from(endian + "12f", data, 280)
    magic = data[344:348]
    if magic not in (b"n+1\0", b"ni1\0"):
        raise CheckFailed("mri_head: NIfTI magic %r, expected 'n+1'" % magic)
    ndim = dim[0]
    if not 3 <= ndim <= 7 or any(d != 1 for d in dim[4:ndim + 1]):
        raise CheckFailed("mri_head: NIfTI dim %s is not a single 3D volume" % (list(dim),))
    if datatype not in NIFTI_DATATYPES:
        raise CheckFailed("mri_head: NIfTI datatype %d not supported" % datatype)
    scalar_type = NIFTI_DATATYPES[datatype]
    if bitpix != 8 * SCALAR_TYPES[scalar_type][2]:
        raise CheckFailed("mri_head: bitpix %d does not match datatype %d" % (bitpix, datatype))
    return {
        "little_endian": endian == "<",
        "dims": tuple(int(d) for d in dim[1:4]),
        "spacing": tuple(abs(float(p)) for p in pixdim[1:4]),
        "datatype": datatype,
        "scalar_type": scalar_type,
        "vox_offset": int(vox_offset),
        "scl_slope": float(scl_slope),
        "scl_inter": float(scl_inter),
        "qform_code": qform_code,
        "sform_code": sform_code,
        "srow": [list(srow[0:4]), list(srow[4:8]), list(srow[8:12])],
        "magic": magic.rstrip(b"\0").decode("ascii"),
    }


def nifti_axes_lps(header):
    """The direction matrix in LPS (rows of 3, the voxel axes as columns) from the NIfTI sform:
    its columns normalised, x and y negated (RAS to LPS), rounded to 6 places; the identity
    without an sform."""
    if header["sform_code"] <= 0:
        return IDENTITY
    lengths = [sum(header["srow"][r][c] ** 2 for r in range(3)) ** 0.5 or 1.0 for c in range(3)]
    return tuple(tuple(round(sign * header["srow"][r][c] / lengths[c], 6) + 0.0
                       for c in range(3))
                 for r, sign in zip(range(3), (-1, -1, 1)))


def prepare_mri(apt, cache_dir, use_system, force):
    source, version, how = locate_package_file(apt, MRI_PACKAGE, MRI_PACKAGE_FILE, cache_dir,
                                               use_system, force)
    log("mri_head: using %s (%s %s, %s)" % (source, MRI_PACKAGE, version, how))
    try:
        with gzip.open(source, "rb") as f:
            nii = f.read()
    except (OSError, EOFError) as exc:
        raise CheckFailed("mri_head: cannot decompress %s: %s" % (source, exc))

    header = parse_nifti1_header(nii)
    dims, spacing, scalar_type = header["dims"], header["spacing"], header["scalar_type"]
    log("mri_head: NIfTI-1 %s-endian, dims %s, spacing %s, datatype %d (%s), vox_offset %d, "
        "scl_slope %g, scl_inter %g, sform_code %d, origin %s"
        % ("little" if header["little_endian"] else "big", list(dims), list(spacing),
           header["datatype"], scalar_type, header["vox_offset"], header["scl_slope"],
           header["scl_inter"], header["sform_code"], [row[3] for row in header["srow"]]))
    if header["scl_slope"] not in (0.0, 1.0) or header["scl_inter"] != 0.0:
        log("mri_head: note: scl_slope/scl_inter not applied; values are the stored ones")
    check_geometry("mri_head", dims, spacing, MRI_EXPECTED_DIMS, MRI_EXPECTED_SPACING)
    raw = nii[header["vox_offset"]:]
    check_byte_count("mri_head", "NIfTI voxel data", len(raw), dims, scalar_type)

    values = voxels_to_array(raw, scalar_type, header["little_endian"])
    vmin, vmax = value_range(values)
    log("mri_head: value range %s .. %s" % (vmin, vmax))
    check_mri_range(vmin, vmax)

    original = cache_dir / "ch2.nii.gz"
    if source.resolve() != original.resolve():
        shutil.copyfile(source, original)
    out = cache_dir / "mri_head.mha"
    axes = nifti_axes_lps(header)
    log("mri_head: axes in LPS (from the %s): %s" % (
        "sform" if header["sform_code"] > 0 else "missing sform: identity", axes))
    file_bytes = write_mha(out, dims, spacing, scalar_type, little_endian_bytes(values), axes)
    log("mri_head: wrote %s (%d bytes) and %s" % (out, file_bytes, original))
    return {
        "path": str(out),
        "file": out.name,
        "original_path": str(original),
        "original_bytes": original.stat().st_size,
        "dims": list(dims),
        "spacing": list(spacing),
        "origin": [0.0, 0.0, 0.0],
        "axes": [list(a) for a in axes],
        "scalar_type": scalar_type,
        "met_element_type": SCALAR_TYPES[scalar_type][0],
        "value_range": [vmin, vmax],
        "data_bytes": len(raw),
        "file_bytes": file_bytes,
        "source": {"package": MRI_PACKAGE, "version": version, "file": "/" + MRI_PACKAGE_FILE,
                   "obtained_by": how},
        "source_metadata": {key: header[key] for key in
                            ("datatype", "scl_slope", "scl_inter", "qform_code", "sform_code",
                             "srow", "magic")},
        "licence": "BSD-3-clause per the mricron-data Debian copyright file (ch2 / Colin 27 "
                   "template, MRIcron by Chris Rorden); do not commit the data",
        "isovalues": {"skin": 30},
        "notes": "T1 MRI template, scalp included; skin about 25-40. The .mha keeps the NIfTI "
                 "sform's axes (in LPS) but not its origin (0 0 0); ch2.nii.gz keeps both.",
    }


# --------------------------------------------------------------------------
# Cache validation and driver
# --------------------------------------------------------------------------

DATASETS = {
    "ct": ("ct_head", prepare_ct),
    "mri": ("mri_head", prepare_mri),
}


def cached_entry(cache_dir, manifest, name):
    """The manifest entry of name if its files exist and match it, else None."""
    entry = manifest.get("datasets", {}).get(name)
    if not isinstance(entry, dict):
        return None
    path = cache_dir / (name + ".mha")
    try:
        info = parse_mha(path)
    except (OSError, ValueError, KeyError, UnicodeDecodeError):
        return None
    if (info["file_bytes"] != entry.get("file_bytes") or info["data_bytes"] != entry.get("data_bytes")
            or info["dims"] != entry.get("dims") or info["axes"] != entry.get("axes")):
        return None  # (a file written before the axes were: written again, with them)
    if "original_path" in entry:
        original = Path(entry["original_path"])
        if not original.is_file() or original.stat().st_size != entry.get("original_bytes"):
            return None
    return entry


def parse_args(argv):
    parser = argparse.ArgumentParser(
        description="Fetch the real head CT and MRI volumes from Debian packages, convert them "
                    "to MetaImage (.mha), check them and cache them outside the source tree.")
    parser.add_argument("--cache-dir", help="cache directory (default: $MEDISO_DATA_DIR, else "
                        "${XDG_CACHE_HOME:-$HOME/.cache}/medical-isosurfaces)")
    parser.add_argument("--only", choices=sorted(DATASETS), help="fetch only this dataset")
    parser.add_argument("--force", action="store_true", help="redo everything, ignoring the cache")
    # Internal/testing: ignore installed files, never apt-get install; always use
    # apt-get download + dpkg -x (the plain-user path).
    parser.add_argument("--no-install", action="store_true", help=argparse.SUPPRESS)
    return parser.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    cache_dir = resolve_cache_dir(args.cache_dir)
    log("cache directory: %s" % cache_dir)
    try:
        cache_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        log_error("unavailable: cannot create cache directory %s: %s" % (cache_dir, exc))
        return 2

    manifest = load_manifest(cache_dir)
    apt = AptSession()
    wanted = [args.only] if args.only else sorted(DATASETS)
    unavailable, failed = [], []
    for key in wanted:
        name, prepare = DATASETS[key]
        if not args.force:
            entry = cached_entry(cache_dir, manifest, name)
            if entry is not None:
                log("%s: cached: %s" % (name, entry["path"]))
                continue
        try:
            entry = prepare(apt, cache_dir, not args.no_install, args.force)
        except Unavailable as exc:
            unavailable.append("%s: %s" % (name, exc))
            continue
        except CheckFailed as exc:
            failed.append(str(exc))
            continue
        except OSError as exc:
            failed.append("%s: I/O error: %s" % (name, exc))
            continue
        manifest.setdefault("datasets", {})[name] = entry
        try:
            save_manifest(cache_dir, manifest)
        except OSError as exc:
            failed.append("%s: cannot write %s: %s" % (name, MANIFEST_NAME, exc))

    for message in failed:
        log_error("check failed: " + message)
    for message in unavailable:
        log_error("unavailable: " + message)
    if failed:
        return 1
    if unavailable:
        return 2
    log("ready: %s" % ", ".join(str(cache_dir / (DATASETS[k][0] + ".mha")) for k in wanted))
    log("manifest: %s" % (cache_dir / MANIFEST_NAME))
    return 0


if __name__ == "__main__":
    sys.exit(main())
