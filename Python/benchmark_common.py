"""What the benchmark scripts share: where the data is, the machine they ran on, and how their
tables are written.

    from benchmark_common import data_file, cpu_model, load_average, fmt_s, table
    from benchmark_common import ROOT, progress_printer, result_records, write_report

data_dir() is the project's one data-directory rule for Python (fetch_data.resolve_cache_dir:
$MEDISO_DATA_DIR, else ${XDG_CACHE_HOME:-$HOME/.cache}/medical-isosurfaces); the C++ tests
state the same rule in Testing/Cxx/MedicalTestUtilities.h (MedicalDataDirectory).
"""
import json
import os
import platform
import socket

from fetch_data import resolve_cache_dir

# The repository's root (the benchmarks find the build's binaries and scripts below it).
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# What starts a result line of BenchmarkHistoPyramidIsoMapper's output: a JSON object follows.
RESULT_TAG = "bench-result: "


def data_dir():
    """The folder Python/fetch_data.py fills (the real CT and MRI)."""
    return str(resolve_cache_dir(None))


def data_file(name):
    """A file of the data folder, e.g. data_file("ct_head.mha")."""
    return os.path.join(data_dir(), name)


def cpu_model():
    """The CPU's model name (from /proc/cpuinfo where there is one)."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def load_average():
    """The 1, 5 and 15 minute load averages as text (the machine may be shared)."""
    try:
        return "%.2f %.2f %.2f" % os.getloadavg()
    except OSError:
        return "unknown"


def mem_total_gb():
    """The machine's memory in GiB (0 where /proc/meminfo is missing)."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemTotal:"):
                    return int(line.split()[1]) / 1024.0 / 1024.0
    except OSError:
        pass
    return 0.0


def free_port():
    """A TCP port of 127.0.0.1 that was free a moment ago."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def fmt_s(seconds):
    """Seconds as the tables write them: 4 decimals under 0.1 s, else 3; "-" for none or NaN."""
    if seconds is None or seconds != seconds:
        return "-"
    return "%.4f" % seconds if seconds < 0.1 else "%.3f" % seconds


def table(headers, rows):
    """A Markdown table, the first column left-aligned and the others right-aligned, as lines."""
    lines = ["| " + " | ".join(headers) + " |",
             "|" + "|".join(["---"] + ["---:"] * (len(headers) - 1)) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return lines


def progress_printer(who):
    """A function that prints a progress line prefixed with `who`, at once (the runs are long)."""
    def progress(message):
        print(who + ": " + message, flush=True)
    return progress


def result_records(output):
    """The records (dicts) of BenchmarkHistoPyramidIsoMapper's output: its RESULT_TAG lines."""
    return [json.loads(line[len(RESULT_TAG):]) for line in output.splitlines()
            if line.startswith(RESULT_TAG)]


def write_report(lines, out):
    """Prints a report's lines and, where `out` names a file, writes them there too."""
    text = "\n".join(lines) + "\n"
    print(text)
    if out:
        with open(out, "w") as f:
            f.write(text)
