"""Failures of a client/server session end with a clear error, never a hang.

Plain python3, run through Testing/Scripts/netns.sh (loopback-only namespace,
own Xvfb). Usage: TestClientServerFailures.py PVSERVER PVPYTHON PLUGIN
Three cases, each with its own pvserver (plugin on PV_PLUGIN_PATH):
1. The server dies (SIGKILL) in the middle of a long update: the client must
   end by itself within BOUND seconds and report the lost connection.
2. The client dies (SIGKILL) with a session open: pvserver must notice and exit
   within BOUND seconds.
3. Values the server rejects: LOD -1 (the filter keeps its level and says so)
   and MemoryBudget 0 with AutoLOD (no level fits): the client receives both
   errors from the server, and the session goes on (a valid LOD afterwards
   gives a surface).
The processes' own output is printed with each line prefixed by "| "; what
ParaView prints for an expected error is part of the check, not a failure.
"""
import os
import signal
import subprocess
import sys
import tempfile
import time

BOUND = 30.0
pvserver, pvpython, plugin = sys.argv[1:4]
work = tempfile.mkdtemp()
port = 11111
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import Checks  # noqa: E402  (Testing/Python/checks.py)

check = Checks(verbose=True)


def start_server():
    log = open(os.path.join(work, "pvserver.log"), "w+")
    env = dict(os.environ, PV_PLUGIN_PATH=os.path.dirname(plugin))
    server = subprocess.Popen([pvserver, "--no-mpi", "--force-offscreen-rendering",
                               "--server-port=%d" % port], stdin=subprocess.DEVNULL,
                              stdout=log, stderr=subprocess.STDOUT, env=env)
    deadline = time.time() + 60
    while time.time() < deadline:
        log.seek(0)
        if "Accepting connection" in log.read():
            return server, log
        if server.poll() is not None:
            break
        time.sleep(0.1)
    log.seek(0)
    print(log.read())
    sys.exit("pvserver did not start")


def start_client(body):
    script = os.path.join(work, "client.py")
    with open(script, "w") as f:
        f.write("import sys, time\nimport paraview.simple as simple\n"
                "simple.Connect('localhost', %d, timeout=30)\n"
                "ns = {'__name__': 'proxies'}\nsimple._add_functions(ns)\n"
                "print('CONNECTED', flush=True)\n" % port)
        f.write(body)
    out = open(os.path.join(work, "client.log"), "w+")
    client = subprocess.Popen([pvpython, "--force-offscreen-rendering", script],
                              stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT)
    return client, out


def wait_for(log, text, process, timeout=60):
    deadline = time.time() + timeout
    while time.time() < deadline:
        log.seek(0)
        if text in log.read():
            return True
        if process.poll() is not None:
            return False
        time.sleep(0.05)
    return False


def show(name, log):
    log.seek(0)
    print("--- %s output" % name)
    for line in log.read().splitlines():
        print("| " + line)


def stop(process):
    if process.poll() is None:
        process.kill()
    process.wait()


# 1. The server dies mid-update.
server, server_log = start_server()
client, client_log = start_client(
    "p = ns['MedicalPhantom'](Dimensions=[384, 384, 384], NoiseStandardDeviation=20)\n"
    "c = ns['BlockLODContour'](Input=p, ContourBy=['POINTS', 'HU'], Isosurfaces=[400])\n"
    "print('UPDATING', flush=True)\n"
    "try:\n"
    "    c.UpdatePipeline()\n"
    "    print('update returned', flush=True)\n"
    "except Exception as e:\n"
    "    print('update raised: %s' % e, flush=True)\n"
    "print('connection alive:', simple.servermanager.ActiveConnection is not None, flush=True)\n")
started = wait_for(client_log, "UPDATING", client)
check(started, "case 1: the client connected and started a long update")
time.sleep(1.0)
check(server.poll() is None, "case 1: the update was still running on the server when killed")
killed_at = time.time()
server.send_signal(signal.SIGKILL)
server.wait()
try:
    code = client.wait(timeout=BOUND)
    elapsed = time.time() - killed_at
    check(True, "case 1: the client ended %.1f s after the server died (exit status %d)"
          % (elapsed, code))
except subprocess.TimeoutExpired:
    check(False, "case 1: the client still runs %.0f s after the server died" % BOUND)
    stop(client)
client_log.seek(0)
text = client_log.read()
check(any(s in text for s in ("Server disconnected", "connection closed", "Connection closed",
                              "Could not receive", "socket", "Socket")),
      "case 1: the client reports the lost connection")
show("client", client_log)

# 2. The client dies with a session open.
server, server_log = start_server()
client, client_log = start_client(
    "p = ns['MedicalPhantom'](Dimensions=[64, 64, 64])\np.UpdatePipeline()\n"
    "print('READY', flush=True)\ntime.sleep(600)\n")
check(wait_for(client_log, "READY", client), "case 2: the client connected and made data")
client.send_signal(signal.SIGKILL)
client.wait()
killed_at = time.time()
try:
    code = server.wait(timeout=BOUND)
    check(True, "case 2: pvserver exited %.1f s after the client died (exit status %d)"
          % (time.time() - killed_at, code))
except subprocess.TimeoutExpired:
    check(False, "case 2: pvserver still runs %.0f s after its client died" % BOUND)
    stop(server)
show("pvserver", server_log)

# 3. Values the server rejects.
server, server_log = start_server()
client, client_log = start_client(
    "p = ns['MedicalPhantom'](Dimensions=[64, 64, 64])\n"
    "c = ns['BlockLODContour'](Input=p, ContourBy=['POINTS', 'HU'], Isosurfaces=[400], LOD=2)\n"
    "c.UpdatePipeline()\n"
    "c.LOD = -1\nc.UpdatePipeline()\ntime.sleep(0.5)\n"
    "c.LOD = 3\nc.AutoLOD = 1\nc.MemoryBudget = 0\nc.UpdatePipeline()\ntime.sleep(0.5)\n"
    "c.AutoLOD = 0\nc.UpdatePipeline()\n"
    "print('TRIANGLES %d' % c.GetDataInformation().GetNumberOfCells(), flush=True)\n"
    "simple.Disconnect()\n")
try:
    code = client.wait(timeout=BOUND + 30)
except subprocess.TimeoutExpired:
    code = None
    stop(client)
check(code == 0, "case 3: the client finished normally (exit status %s)" % code)
client_log.seek(0)
text = client_log.read()
check("LOD -1 is outside 0..3" in text, "case 3: the client got the server's error for LOD -1")
check("MemoryBudget 0 MB is too small" in text,
      "case 3: the client got the server's error for MemoryBudget 0")
triangles = [int(line.split()[1]) for line in text.splitlines() if line.startswith("TRIANGLES")]
check(bool(triangles) and triangles[0] > 1000, "case 3: the session goes on (level 3: %s triangles)"
      % (triangles[0] if triangles else "no"))
show("client", client_log)
stop(server)

check.finish("client/server failures: all checks passed")
