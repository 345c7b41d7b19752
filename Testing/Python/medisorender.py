"""mediso-render run by a test, and its --stats line read, one way for every test that draws.

    code, stats, text = run_stats(binary, ["phantom:48", "--iso", "400", "--stats", ...])

Plain python3. `code` is the exit status, `stats` the last JSON line (--stats; None without one),
`text` stdout and stderr together, for the checks' messages. write_short_volume() writes the
n^3 int16 MetaImage a test draws.
"""
import json
import subprocess
import sys
from array import array


def run_stats(binary, args, timeout=300):
    p = subprocess.run([binary] + args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       timeout=timeout)
    stats = None
    for line in p.stdout.splitlines():
        if line.startswith("{"):
            stats = json.loads(line)
    return p.returncode, stats, p.stdout


def write_short_volume(path, n, value):
    """An n^3 MetaImage of int16 `value(x, y, z)` (x fastest, spacing 1), its data in the file."""
    values = array("h", (value(x, y, z) for z in range(n) for y in range(n) for x in range(n)))
    if sys.byteorder != "little":
        values.byteswap()
    with open(path, "wb") as f:
        f.write(("ObjectType = Image\nNDims = 3\nDimSize = %d %d %d\nElementType = MET_SHORT\n"
                 "ElementSpacing = 1 1 1\nElementDataFile = LOCAL\n" % (n, n, n)).encode())
        f.write(values.tobytes())
    return path
