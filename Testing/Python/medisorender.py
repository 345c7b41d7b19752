"""mediso-render run by a test, and its --stats line read, one way for every test that draws.

    code, stats, text = run_stats(binary, ["phantom:48", "--iso", "400", "--stats", ...])

Plain python3. `code` is the exit status, `stats` the last JSON line (--stats; None without one),
`text` stdout and stderr together, for the checks' messages.
"""
import json
import subprocess


def run_stats(binary, args, timeout=300):
    p = subprocess.run([binary] + args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       timeout=timeout)
    stats = None
    for line in p.stdout.splitlines():
        if line.startswith("{"):
            stats = json.loads(line)
    return p.returncode, stats, p.stdout
