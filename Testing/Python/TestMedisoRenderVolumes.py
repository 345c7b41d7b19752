#!/usr/bin/env python3
"""The volumes mediso-render makes itself: `--resample` and `phantom:N`.

    python3 TestMedisoRenderVolumes.py MEDISO_RENDER TEMP_DIR [BENCHMARK_PROGRAM]

Plain python3 (no ParaView). `--resample` on linear fields, where trilinear interpolation is
exact: a float field must come back as the field at the new points, an int16 field as the
trilinear value of its samples rounded half up; resampling to the same size gives the same
bytes; the spacing, origin and direction follow the bounds. `phantom:N` against the phantom that
BenchmarkHistoPyramidIsoMapper (VTK's MedicalPhantom source) writes, value for value, when that
program is given. Both volumes render with the same primitives as the files written from them.
"""
import json
import math
import os
import struct
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)

check = Checks()
FORMATS = {"MET_FLOAT": "f", "MET_SHORT": "h"}


def write_mha(path, dims, spacing, origin, element, values):
    header = ("ObjectType = Image\nNDims = 3\nDimSize = %d %d %d\nElementType = %s\n"
              "ElementSpacing = %r %r %r\nOffset = %r %r %r\nElementDataFile = LOCAL\n"
              % (tuple(dims) + (element,) + tuple(spacing) + tuple(origin)))
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(struct.pack("<%d%s" % (len(values), FORMATS[element]), *values))
    return path


def read_mha(path):
    with open(path, "rb") as f:
        data = f.read()
    fields, at = {}, 0
    while True:
        end = data.index(b"\n", at)
        key, _, value = data[at:end].decode().partition("=")
        fields[key.strip()] = value.strip()
        at = end + 1
        if key.strip() == "ElementDataFile":
            break
    dims = [int(v) for v in fields["DimSize"].split()]
    fmt = {"MET_FLOAT": "f", "MET_SHORT": "h", "MET_UCHAR": "B"}[fields["ElementType"]]
    order = ">" if fields.get("BinaryDataByteOrderMSB", fields.get("ElementByteOrderMSB", "False")) == "True" else "<"
    count = dims[0] * dims[1] * dims[2]
    raw = data[at:at + count * struct.calcsize(fmt)]
    return {"dims": dims, "type": fields["ElementType"],
            "spacing": [float(v) for v in fields.get("ElementSpacing", "1 1 1").split()],
            "origin": [float(v) for v in fields.get("Offset", "0 0 0").split()],
            "matrix": [float(v) for v in fields.get("TransformMatrix", "1 0 0 0 1 0 0 0 1").split()],
            "values": struct.unpack("%s%d%s" % (order, count, fmt), raw), "raw": raw}


def run(binary, args):
    p = subprocess.run([binary] + args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       timeout=600)
    return p.returncode, p.stdout


def primitives(binary, volume, iso):
    code, text = run(binary, [volume, "--iso", str(iso), "--size", "160x120", "--stats"])
    check(code == 0, "%s --iso %s: exit %d:\n%s" % (volume, iso, code, text))
    for line in text.splitlines():
        if line.startswith("{"):
            return json.loads(line)["primitives"]
    return None


def trilinear(values, dims, x, y, z):
    """The resampler's interpolation of the samples at index position (x, y, z)."""
    def axis(p, n):
        lo = min(int(math.floor(p)), n - 2)
        return lo, p - lo
    (i, wx), (j, wy), (k, wz) = axis(x, dims[0]), axis(y, dims[1]), axis(z, dims[2])

    def at(a, b, c):
        return float(values[a + dims[0] * (b + dims[1] * c)])

    def lerp(b, c):
        return at(i, b, c) + wx * (at(i + 1, b, c) - at(i, b, c))
    y0 = lerp(j, k) + wy * (lerp(j + 1, k) - lerp(j, k))
    y1 = lerp(j, k + 1) + wy * (lerp(j + 1, k + 1) - lerp(j, k + 1))
    return y0 + wz * (y1 - y0)


def check_resample(binary, temp):
    dims, spacing, origin = (9, 7, 5), (1.0, 2.0, 0.5), (10.0, -4.0, 3.0)
    out_dims = (17, 4, 9)

    def field(px, py, pz):
        return 3.0 * px + 5.0 * py - 2.0 * pz + 0.5

    points = [(origin[0] + i * spacing[0], origin[1] + j * spacing[1], origin[2] + k * spacing[2])
              for k in range(dims[2]) for j in range(dims[1]) for i in range(dims[0])]
    cases = {"MET_FLOAT": [field(*p) for p in points],
             "MET_SHORT": [int(round(10.0 * field(*p))) for p in points]}
    for element, values in cases.items():
        src = write_mha(os.path.join(temp, "linear-%s.mha" % element), dims, spacing, origin,
                        element, values)
        dst = os.path.join(temp, "linear-%s-resampled.mha" % element)
        code, text = run(binary, [src, "--resample", "%dx%dx%d" % out_dims, "--write-volume", dst])
        check(code == 0, "--resample %s: exit %d:\n%s" % (element, code, text))
        if code != 0:
            continue
        r = read_mha(dst)
        check(r["dims"] == list(out_dims), "%s: dims %s" % (element, r["dims"]))
        check(r["type"] == element, "%s: type became %s" % (element, r["type"]))
        want_spacing = [spacing[a] * (dims[a] - 1) / (out_dims[a] - 1) for a in range(3)]
        check(all(abs(r["spacing"][a] - want_spacing[a]) < 1e-12 for a in range(3)),
              "%s: spacing %s, expected %s" % (element, r["spacing"], want_spacing))
        check(r["origin"] == list(origin), "%s: origin %s" % (element, r["origin"]))
        check(r["matrix"] == [1, 0, 0, 0, 1, 0, 0, 0, 1], "%s: direction %s" % (element, r["matrix"]))
        worst, wrong = 0.0, 0
        n = 0
        for k in range(out_dims[2]):
            for j in range(out_dims[1]):
                for i in range(out_dims[0]):
                    got = r["values"][n]
                    n += 1
                    if element == "MET_FLOAT":
                        p = [origin[a] + (i, j, k)[a] * want_spacing[a] for a in range(3)]
                        worst = max(worst, abs(got - field(*p)) / (1.0 + abs(field(*p))))
                    else:
                        x = [(i, j, k)[a] * (dims[a] - 1) / (out_dims[a] - 1) for a in range(3)]
                        if got != math.floor(trilinear(values, dims, *x) + 0.5):
                            wrong += 1
        if element == "MET_FLOAT":
            print("float: worst relative error %.2g over %d points" % (worst, n))
            check(worst < 1e-5, "float: the linear field is off by %.3g" % worst)
        else:
            print("int16: %d of %d points differ from the rounded trilinear value" % (wrong, n))
            check(wrong == 0, "int16: %d points differ from the rounded trilinear value" % wrong)
        same = os.path.join(temp, "linear-%s-same.mha" % element)
        code, text = run(binary, [src, "--resample", "%dx%dx%d" % dims, "--write-volume", same])
        check(code == 0 and read_mha(same)["raw"] == read_mha(src)["raw"],
              "%s: resampling to the same size changed the values" % element)
        # It renders, with the primitives of the file it wrote.
        iso = 12.0 if element == "MET_FLOAT" else 120
        b = primitives(binary, dst, iso)
        code, text = run(binary, [src, "--resample", "%dx%dx%d" % out_dims, "--iso", str(iso),
                                  "--size", "160x120", "--stats"])
        c = next((json.loads(l)["primitives"] for l in text.splitlines() if l.startswith("{")), None)
        check(b is not None and b > 0 and b == c,
              "%s: resampled in place %s primitives, from the written file %s" % (element, c, b))


def check_phantom(binary, temp, benchmark):
    n = 40
    ours = os.path.join(temp, "phantom%d-render.mha" % n)
    code, text = run(binary, ["phantom:%d" % n, "--write-volume", ours])
    check(code == 0, "phantom:%d: exit %d:\n%s" % (n, code, text))
    if code != 0:
        return
    p = read_mha(ours)
    check(p["dims"] == [n, n, n] and p["type"] == "MET_SHORT", "phantom: %s %s" % (p["dims"], p["type"]))
    check(all(abs(s - 240.0 / (n - 1)) < 1e-12 for s in p["spacing"]), "phantom spacing %s" % p["spacing"])
    check(min(p["values"]) == -1000 and max(p["values"]) > 500,
          "phantom values %d..%d are not a CT head's" % (min(p["values"]), max(p["values"])))
    if benchmark:
        theirs = os.path.join(temp, "phantom%d-vtk.mha" % n)
        code, text = run(benchmark, ["--input", "phantom%d" % n, "--write-input", theirs])
        check(code == 0, "the benchmark's phantom: exit %d:\n%s" % (code, text))
        if code == 0:
            q = read_mha(theirs)
            differ = sum(1 for a, b in zip(p["values"], q["values"]) if a != b)
            print("phantom:%d against MedicalPhantom (VTK): %d of %d values differ" % (n, differ, n ** 3))
            check(q["dims"] == p["dims"] and differ == 0,
                  "phantom:%d differs from MedicalPhantom's: %d values" % (n, differ))
            # (VTK's MetaImage writer keeps single precision)
            check(all(abs(a - b) < 1e-6 * a for a, b in zip(p["spacing"], q["spacing"])),
                  "phantom spacing %s, MedicalPhantom's %s" % (p["spacing"], q["spacing"]))
            check(all(abs(a - b) < 1e-6 for a, b in zip(p["origin"], q["origin"])),
                  "phantom origin %s, MedicalPhantom's %s" % (p["origin"], q["origin"]))
    a, b = primitives(binary, "phantom:%d" % n, 400), primitives(binary, ours, 400)
    print("phantom:%d at 400 HU: %s primitives, %s from its file" % (n, a, b))
    check(a is not None and a > 0 and a == b, "phantom primitives %s, from its file %s" % (a, b))


def main():
    binary, temp = sys.argv[1], sys.argv[2]
    benchmark = sys.argv[3] if len(sys.argv) > 3 else ""
    os.makedirs(temp, exist_ok=True)
    check_resample(binary, temp)
    check_phantom(binary, temp, benchmark)
    check.finish("TestMedisoRenderVolumes passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
