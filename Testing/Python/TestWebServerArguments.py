"""pvpython test: the web server refuses bad arguments and unreadable volumes in one line.

Python/serve.py is started with each bad argument (--port 99999, -1, abc, a port in use,
--token -abc, --max-operation-seconds 0, a missing --plugin) and with each volume it cannot read,
made here: NIfTI files with a zero dimension, an unknown datatype code and a header far larger than
the file (readers that crashed or aborted the process), a truncated MetaImage, a missing file, a
folder with no DICOM, and a reader that segfaults (simulated in the worker by a sitecustomize on
PYTHONPATH). Each must end the server at start with exit status 2 (arguments) or 1 (volumes), one
line "serve: ..." naming the file and why, and no traceback: the volumes are read in the worker
process, so a reader that crashes cannot take the server down.
"""
import os
import socket
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import webserver  # noqa: E402  (skips when aiohttp or the plugin is missing)
from checks import Checks  # noqa: E402
from nifti import nifti1_header  # noqa: E402  (Testing/Python/nifti.py)

check = Checks(verbose=True)
work = tempfile.mkdtemp(prefix="mediso-server-arguments-")


def run(*arguments, env=None):
    """serve.py with the arguments: (exit status, its output lines)."""
    command = [webserver.PVPYTHON, "--no-mpi", webserver.SERVE, "--plugin", webserver.PLUGIN,
               "--port", str(webserver.free_port())] + list(arguments)
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          stdin=subprocess.DEVNULL, timeout=120,
                          env=dict(os.environ, **(env or {})))
    return done.returncode, [line for line in done.stdout.splitlines() if line.strip()]


def refused(arguments, code, line, env=None, exact=True):
    """The server ends with `code` and says `line` (or, exact=False, a line that begins so)."""
    status, lines = run(*arguments, env=env)
    said = lines[-1] if lines else ""
    check(status == code, "%s: exit status %d (expected %d)" % (" ".join(arguments), status, code))
    check(said == line if exact else said.startswith(line) and len(said) > len(line),
          "%s: says %r" % (" ".join(arguments), said))
    check(not any("Traceback" in x for x in lines), "%s: no traceback" % " ".join(arguments))
    return lines


def nifti(name, dims, datatype=4, bitpix=16, payload=None):
    """A NIfTI-1 file (.nii, int16 unless told) with the given header fields."""
    header = nifti1_header(dims, datatype=datatype, bitpix=bitpix, slope=1.0)
    if payload is None:
        payload = bytes(max(0, dims[0] * dims[1] * dims[2]) * bitpix // 8)
    path = os.path.join(work, name)
    with open(path, "wb") as f:
        f.write(header + payload)
    return path


# --- arguments ---------------------------------------------------------------------------------
refused(["--port", "99999"], 2, "serve: argument --port: '99999' is not a port number (1-65535)")
refused(["--port=-1"], 2, "serve: argument --port: '-1' is not a port number (1-65535)")
refused(["--port", "abc"], 2, "serve: argument --port: 'abc' is not a port number (1-65535)")
refused(["--max-operation-seconds", "0"], 2,
        "serve: argument --max-operation-seconds: '0' is not a positive number of seconds")
refused(["--plugin", os.path.join(work, "none.so")], 2,
        "serve: argument --plugin: no such file: %s" % os.path.join(work, "none.so"))
# pvpython itself rewrites "-abc" to "--abc" (with a warning of its own); argparse then takes it
# for an option. The server says how to give such a token; --token=-abc works (the security test).
refused(["--token", "-abc"], 2, "serve: argument --token: expected one argument (a value that "
        "begins with '-' is given as --name=VALUE)")
with socket.socket() as busy:
    busy.bind(("127.0.0.1", 0))
    busy.listen()
    port = busy.getsockname()[1]
    refused(["--port", str(port), "--data", "phantom:8"], 1,
            "serve: cannot listen on 127.0.0.1:%d: Address already in use" % port)

# --- volumes it cannot read ----------------------------------------------------------------------
mha = os.path.join(work, "truncated.mha")
with open(mha, "wb") as f:
    f.write(b"ObjectType = Image\nNDims = 3\nDimSize = 64 64 64\nElementType = MET_SHORT\n"
            b"ElementDataFile = LOCAL\n" + bytes(1000))
refused(["--data", mha], 1, "serve: %s: MetaImage: M_ReadElementsData: data not read completely "
        "ideal = 524288 : actual = 1000" % mha)
missing = os.path.join(work, "missing.mha")
refused(["--data", "phantom:8", "--data", missing], 1,
        "serve: %s: no such file or folder" % missing)
folder = os.path.join(work, "no-dicom")
os.makedirs(folder)
with open(os.path.join(folder, "notes.txt"), "w") as f:
    f.write("not DICOM\n")
refused(["--data", folder], 1, "serve: %s: a folder, but it holds no DICOM files" % folder)
refused(["--data", "phantom:1"], 1, "serve: phantom:1: the phantom's size is an integer 2-1024")
refused(["--data", "phantom:8:noise=x"], 1,
        "serve: phantom:8:noise=x: noise is a number of HU from 0 to 10000, seed an integer ('noise=x')")

# A reader that segfaults: the worker dies, the server names the file and the signal.
crash = os.path.join(work, "segfaulting-reader.mha")
with open(crash, "w") as f:
    f.write("ObjectType = Image\n")
hooks = os.path.join(work, "hooks")
os.makedirs(hooks)
with open(os.path.join(hooks, "sitecustomize.py"), "w") as f:
    f.write("""import os, sys
if sys.argv and sys.argv[0].endswith("serve_operations.py"):
    isfile = os.path.isfile

    def crashing(path):  # as a reader that segfaults on this file
        if str(path).endswith("segfaulting-reader.mha"):
            import ctypes
            ctypes.string_at(0)
        return isfile(path)

    os.path.isfile = crashing
""")
refused(["--data", "phantom:8", "--data", crash], 1,
        "serve: %s: cannot be read: the reader ended its process (SIGSEGV)" % crash,
        env={"PYTHONPATH": hooks + os.pathsep + os.environ.get("PYTHONPATH", "")})

# NIfTI files that crashed or aborted VTK's reader (issue 29): whatever the reader does with them
# (an error of its own, or a crash), the server says one line naming the file.
for path in (nifti("zero-dimension.nii", (0, 16, 16)),
             nifti("unknown-datatype.nii", (16, 16, 16), datatype=1234),
             nifti("header-beyond-file.nii", (32767, 32767, 32767), payload=bytes(27000))):
    lines = refused(["--data", path], 1, "serve: %s: " % path, exact=False)
    check(len(lines) == 1, "%s: one line (%d)" % (os.path.basename(path), len(lines)))

check.finish("web server arguments: all checks passed")
