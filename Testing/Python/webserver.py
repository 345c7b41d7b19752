"""The web server's tests' shared part: start Python/serve.py, talk to it, record failures.

    server = Server(["phantom:64", "/path/ct.mha"])   # pvpython Python/serve.py on a free port
    async with server.client() as http: ...           # an aiohttp session
    checks = Checks(); checks(ok, "what"); checks.finish(server)

The tests run in pvpython (it has Debian's python3-aiohttp and VTK). They skip (exit 125) when
aiohttp or the plugin is missing. Everything the server prints is printed again at the end, so a
VTK error or a traceback in the server fails the test through ctest's FAIL_REGULAR_EXPRESSION.
"""
import asyncio
import atexit
import os
import secrets
import shutil
import socket
import subprocess
import sys
import threading
import time

import checks  # Testing/Python/checks.py

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SERVE = os.path.join(ROOT, "Python", "serve.py")
PVPYTHON = os.path.realpath("/proc/self/exe") if os.path.exists("/proc/self/exe") else \
    shutil.which("pvpython")


def skip(reason):
    print("SKIP: " + reason)
    sys.exit(125)


try:
    import aiohttp  # noqa: F401
except ImportError:
    skip("python3-aiohttp is not installed (apt-get install python3-aiohttp)")

PLUGIN = os.environ.get("MEDISO_PLUGIN", "")
if not os.path.isfile(PLUGIN):
    skip("MEDISO_PLUGIN does not name the built plugin (%r)" % PLUGIN)


def data_cache():
    sys.path.insert(0, os.path.join(ROOT, "Python"))
    from fetch_data import resolve_cache_dir
    return resolve_cache_dir(None)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Checks(checks.Checks):
    """Prints every check ("ok: ..." too); finish() stops the servers and prints their output."""

    def __init__(self):
        super().__init__(verbose=True)

    def finish(self, *servers, passed="all checks passed"):
        for server in servers:
            server.stop()
            print("---- server output (%s)" % " ".join(server.data))
            print("".join(server.lines), end="", flush=True)
            self(server.exit_code in (0, -15), "the server ended cleanly (exit %s)"
                 % server.exit_code)
        super().finish(passed)


class Server:
    """Python/serve.py in its own pvpython, on 127.0.0.1 and a free port."""

    def __init__(self, data, token=None, extra=()):
        self.data = list(data)
        self.token = token or secrets.token_urlsafe(12)
        self.port = free_port()
        self.base = "http://127.0.0.1:%d" % self.port
        self.lines = []
        self.exit_code = None
        command = [PVPYTHON, "--no-mpi", SERVE, "--plugin", PLUGIN, "--token=" + self.token,
                   "--port", str(self.port)] + list(extra)
        for d in self.data:
            command += ["--data", d]
        self.process = subprocess.Popen(command, stdout=subprocess.PIPE,
                                        stderr=subprocess.STDOUT, text=True,
                                        stdin=subprocess.DEVNULL)
        atexit.register(self.stop)  # whatever ends the test, the server goes with it
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()
        deadline = time.monotonic() + 180
        while not any("serve: open http" in line for line in self.lines):
            if self.process.poll() is not None or time.monotonic() > deadline:
                self.stop()
                print("".join(self.lines))
                raise SystemExit("FAILED: the server did not start (exit %s)" % self.exit_code)
            time.sleep(0.1)
        asyncio.run(self._wait_ready(deadline))

    def _read(self):
        for line in self.process.stdout:
            self.lines.append(line)

    async def _wait_ready(self, deadline):
        """Until the server answers and its operation worker is up."""
        import aiohttp
        async with aiohttp.ClientSession() as http:
            while time.monotonic() < deadline:
                try:
                    async with http.get(self.url("/api/status")) as r:
                        status = await r.json()
                        if status["worker"]["pid"]:
                            return
                except aiohttp.ClientError:
                    pass
                await asyncio.sleep(0.2)
        raise SystemExit("FAILED: the server's worker did not start")

    def url(self, path, token=True):
        if token is True:
            token = self.token
        if token is None:
            return self.base + path
        return self.base + path + ("&" if "?" in path else "?") + "token=" + token

    def ws_url(self, token=True):
        return self.url("/api/ws", token).replace("http://", "ws://")

    def alive(self):
        return self.process.poll() is None

    def stop(self):
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(30)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self.reader.join(5)
        self.exit_code = self.process.returncode


async def operation(ws, request, timeout=300):
    """Sends one operation on an open WebSocket; returns (progress messages, final answer)."""
    import json
    await ws.send_json(request)
    progress = []
    deadline = time.monotonic() + timeout
    while True:
        msg = await ws.receive(timeout=max(1.0, deadline - time.monotonic()))
        if msg.type != aiohttp.WSMsgType.TEXT:
            return progress, {"closed": msg.type.name}
        answer = json.loads(msg.data)
        if answer.get("id") != request.get("id"):
            continue
        if "progress" in answer:
            progress.append(answer)
            continue
        return progress, answer


def decode(body, dtype, count):
    """The values of a gzip'd, byte-shuffled /api/volume body."""
    import gzip
    import numpy
    raw = gzip.decompress(body)
    size = numpy.dtype(dtype).itemsize
    planes = numpy.frombuffer(raw, numpy.uint8).reshape(size, count)
    return numpy.ascontiguousarray(planes.T).view(dtype).ravel()


def surface_request(ident, dataset, isovalue, level=3, steps=()):
    return {"op": "surface", "id": ident, "dataset": dataset, "isovalue": isovalue,
            "level": level, "steps": list(steps)}
