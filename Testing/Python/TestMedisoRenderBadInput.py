#!/usr/bin/env python3
"""mediso-render on bad input: every case gets a clear message and its exit status, never a crash.

    python3 TestMedisoRenderBadInput.py MEDISO_RENDER TEMP_DIR

Plain python3 (no ParaView): writes its own small MetaImage files. Exit statuses of mediso-render:
2 bad options, 3 a volume that cannot be read or used, 4 no usable OpenGL (no EGL display, too old
a context, the bricks an isovalue crosses over the GPU budget). A good volume is rendered too, so that the
failures are the input's and not the program's.
"""
import os
import struct
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)

check = Checks()


def write_mha(path, dims, element="MET_SHORT", values=None, extra="", fmt="<h", truncate=0,
              header_only=False):
    count = dims[0] * dims[1] * dims[2]
    header = ("ObjectType = Image\nNDims = 3\nDimSize = %d %d %d\nElementType = %s\n"
              "ElementSpacing = 1 1 1\n%sElementDataFile = LOCAL\n" % (dims[0], dims[1], dims[2],
                                                                       element, extra))
    with open(path, "wb") as f:
        f.write(header.encode())
        if header_only:
            return path
        if values is None:
            values = [((i * 37) % 200) - 100 for i in range(count)]
        data = b"".join(struct.pack(fmt, v) for v in values)
        f.write(data[:len(data) - truncate] if truncate else data)
    return path


def run(binary, args, env=None):
    e = dict(os.environ)
    e.update(env or {})
    p = subprocess.run([binary] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                       env=e, timeout=120)
    return p.returncode, p.stdout + p.stderr


def expect(binary, name, args, status, words, env=None):
    code, text = run(binary, args, env)
    message = text.strip().splitlines()[-1] if text.strip() else ""
    print("%s: exit %d: %s" % (name, code, message))
    check(code >= 0, "%s: killed by signal %d" % (name, -code))
    check(code == status, "%s: exit status %d, expected %d" % (name, code, status))
    for w in words:
        check(w in text, "%s: the message does not say %r:\n%s" % (name, w, text))


def main():
    binary, temp = sys.argv[1], sys.argv[2]
    os.makedirs(temp, exist_ok=True)
    good = write_mha(os.path.join(temp, "good.mha"), (6, 5, 4))

    # The good volume renders (the program and the context work here).
    out = os.path.join(temp, "good.png")
    code, text = run(binary, [good, "--iso", "0", "--size", "64x48", "--output", out, "--stats"])
    print("good volume: exit %d" % code)
    if code == 4:
        print("SKIP: no usable OpenGL context here: " + text.strip().splitlines()[-1])
        return 125
    check(code == 0 and os.path.getsize(out) > 100, "a good volume does not render:\n" + text)
    check('"primitives": ' in text, "--stats prints no primitives")

    # Options.
    expect(binary, "no volume", ["--iso", "0"], 2, ["no volume"])
    expect(binary, "no isovalue", [good], 2, ["--iso"])
    expect(binary, "bad size", [good, "--iso", "0", "--size", "64by48"], 2, ["--size"])
    expect(binary, "huge size", [good, "--iso", "0", "--size", "99999x10"], 2, ["--size"])
    expect(binary, "unknown option", [good, "--iso", "0", "--shiny"], 2, ["unknown option --shiny"])
    expect(binary, "not a number", [good, "--iso", "abc"], 2, ["not a finite number"])
    expect(binary, "nan isovalue", [good, "--iso", "nan"], 2, ["not a finite number"])
    expect(binary, "bad colour", [good, "--iso", "0:2,0,0"], 2, ["0 to 1"])
    expect(binary, "nine isovalues", [good] + sum((["--iso", str(v)] for v in range(9)), []), 2,
           ["at most 8"])
    expect(binary, "bad api", [good, "--iso", "0", "--api", "vulkan"], 2, ["--api"])
    expect(binary, "clip plane without a normal", [good, "--iso", "0", "--clip", "0,0,0,1"], 2,
           ["--clip"])
    expect(binary, "clip plane of 3 numbers", [good, "--iso", "0", "--clip", "1,0,0"], 2, ["--clip"])
    expect(binary, "seven clip planes", [good, "--iso", "0"] + ["--clip", "1,0,0,0"] * 7, 2,
           ["at most 6"])
    expect(binary, "empty crop box", [good, "--iso", "0", "--crop", "3,1,0,4,0,3"], 2, ["--crop"])

    # Volumes.
    expect(binary, "missing file", [os.path.join(temp, "none.mha"), "--iso", "0"], 3,
           ["cannot be opened"])
    garbage = os.path.join(temp, "garbage.mha")
    with open(garbage, "wb") as f:
        f.write(bytes(range(256)) * 8)
    expect(binary, "not a MetaImage", [garbage, "--iso", "0"], 3, ["not a MetaImage"])
    expect(binary, "truncated data",
           [write_mha(os.path.join(temp, "short.mha"), (6, 5, 4), truncate=7), "--iso", "0"], 3,
           ["are needed"])
    expect(binary, "unsupported type",
           [write_mha(os.path.join(temp, "ll.mha"), (6, 5, 4), "MET_LONG_LONG", fmt="<q"),
            "--iso", "0"], 3, ["not supported"])
    expect(binary, "compressed",
           [write_mha(os.path.join(temp, "z.mha"), (6, 5, 4), extra="CompressedData = True\n"),
            "--iso", "0"], 3, ["compressed"])
    two_d = os.path.join(temp, "2d.mha")
    with open(two_d, "w") as f:
        f.write("ObjectType = Image\nNDims = 2\nDimSize = 6 5\nElementType = MET_SHORT\n"
                "ElementDataFile = LOCAL\n")
    expect(binary, "2D image", [two_d, "--iso", "0"], 3, ["3D"])
    expect(binary, "a flat volume",
           [write_mha(os.path.join(temp, "flat.mha"), (6, 5, 1)), "--iso", "0"], 3,
           ["at least 2 points"])
    expect(binary, "huge dimensions",
           [write_mha(os.path.join(temp, "huge.mha"), (60000, 60000, 60000), header_only=True),
            "--iso", "0"], 3, ["are needed"])
    zero = os.path.join(temp, "zero-spacing.mha")
    with open(zero, "wb") as f:
        f.write(b"ObjectType = Image\nNDims = 3\nDimSize = 6 5 4\nElementType = MET_UCHAR\n"
                b"ElementSpacing = 1 0 1\nElementDataFile = LOCAL\n" + bytes(120))
    expect(binary, "zero spacing", [zero, "--iso", "0"], 3, ["positive"])
    nan = float("nan")
    expect(binary, "all NaN",
           [write_mha(os.path.join(temp, "nan.mha"), (6, 5, 4), "MET_FLOAT",
                      values=[nan] * 120, fmt="<f"), "--iso", "0"], 3, ["NaN"])

    # Volumes it makes itself (phantom:N, --resample, --write-volume).
    expect(binary, "phantom too small", ["phantom:1", "--iso", "0"], 3, ["whole number from 2"])
    expect(binary, "phantom not a size", ["phantom:abc", "--iso", "0"], 3, ["whole number from 2"])
    expect(binary, "phantom too large", ["phantom:99999", "--iso", "0"], 3, ["whole number from 2"])
    expect(binary, "resample to 1 point", [good, "--iso", "0", "--resample", "1x4x4"], 2,
           ["--resample"])
    expect(binary, "resample with 2 sizes", [good, "--iso", "0", "--resample", "4x4"], 2,
           ["WxHxD"])
    expect(binary, "resample not whole", [good, "--iso", "0", "--resample", "4.5x4x4"], 2,
           ["whole number"])
    expect(binary, "volume written nowhere",
           [good, "--write-volume", os.path.join(temp, "no-such-dir", "v.mha")], 1,
           ["cannot be written"])

    # The context's limits, and no usable context. A volume over GL_MAX_3D_TEXTURE_SIZE is kept as
    # bricks (issue 31) and drawn; only bricks that alone exceed the GPU budget fail.
    long_volume = write_mha(os.path.join(temp, "long.mha"), (2, 2, 20000))
    code, text = run(binary, [long_volume, "--iso", "1", "--stats", "--size", "64x64"])
    print("over GL_MAX_3D_TEXTURE_SIZE: exit %d: %s" % (code, text.strip().splitlines()[-1:]))
    check(code == 0 and '"bricks": 0,' not in text and '"active_bricks"' in text,
          "over GL_MAX_3D_TEXTURE_SIZE: drawn from bricks (exit %d):\n%s" % (code, text))
    expect(binary, "active bricks over the GPU budget",
           [long_volume, "--iso", "1", "--gpu-budget-mb", "0.01", "--size", "64x64"], 4,
           ["over the budget"])
    expect(binary, "texture limit too small", [good, "--iso", "0", "--max-texture-size", "8"], 2,
           ["--max-texture-size"])
    expect(binary, "no GPU budget", [good, "--iso", "0", "--gpu-budget-mb", "0"], 2,
           ["--gpu-budget-mb"])
    expect(binary, "no EGL display", [good, "--iso", "0"], 4, ["no EGL"],
           env={"__EGL_VENDOR_LIBRARY_FILENAMES": os.path.join(temp, "no-such-vendor.json")})
    expect(binary, "an OpenGL ES 2 context only", [good, "--iso", "0"], 4, ["OpenGL"],
           env={"MESA_GLES_VERSION_OVERRIDE": "2.0"})
    expect(binary, "an OpenGL 3.1 context only", [good, "--iso", "0", "--api", "gl"], 4, ["OpenGL"],
           env={"MESA_GL_VERSION_OVERRIDE": "3.1"})
    expect(binary, "a bad EGL platform", [good, "--iso", "0"], 4, ["MEDISO_EGL_PLATFORM"],
           env={"MEDISO_EGL_PLATFORM": "x11"})

    check.finish("TestMedisoRenderBadInput passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
