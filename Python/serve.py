"""The web client's server: the page, each volume once, and the operations that need the server.

    pvpython --no-mpi Python/serve.py --plugin build/.../MedicalIsosurfaces.so --wasm build-web/bin \\
        [--data FILE_OR_DICOM_DIR ...] [--port 8765] [--host 127.0.0.1] [--token TOKEN]

Run by Scripts/serve.sh, which installs and builds what is needed first. Opens the volumes with
ParaView's readers (Python/serve_operations.py), prints the page's URL (with the session's token)
and serves it with aiohttp (docs/web.md has the API). Without --data: the fetched head CT, or the
plugin's MedicalPhantom when the CT is not there (--data phantom:N asks for the phantom at N^3).

Operations on a surface (smoothing, hole filling, clipping, decimation) arrive on the WebSocket
/api/ws as parameters; they run one at a time in a pvpython worker process
(serve_operations.py), so that the event loop keeps serving every page meanwhile.
"""
import argparse
import asyncio
import collections
import gzip
import json
import math
import os
import secrets
import shutil
import signal
import socket
import sys
import tempfile
import time
from urllib.parse import urlsplit

from aiohttp import WSMsgType, web

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
STATIC = os.path.join(ROOT, "Web", "static")
sys.path.insert(0, HERE)
import serve_operations  # noqa: E402  (the volumes' readers, and the worker's program)

# Level k of a volume samples the points at multiples of LEVEL_STRIDES[k] along each axis: the
# strides of the C++ BlockLOD core, mediso::LevelStride(k) = BlockCells >> k = 8 >> k
# (Filters/Core/BlockLOD.h), which TestWebServerLevels checks against BlockLODContour at each
# level. The one difference: the C++'s coarse copy (MakeCoarseCopy) also takes the last point of
# an axis whose length minus one is not a multiple of the stride; the levels sent to the page
# leave that partial layer out (docs/web.md, "The server").
LEVEL_STRIDES = (8, 4, 2, 1)
MAX_MESSAGE = 64 * 1024        # a request on the WebSocket (docs/web.md)
MAX_FRAME = 1024 * 1024        # above this aiohttp closes the socket (1009, message too big)
MAX_STEPS = 8
MAX_PENDING = 4                # operations queued or running per page
MAX_SESSIONS = 64              # WebSockets open at once
RESULTS_PER_SESSION = 8        # the oldest result of a page goes when a ninth arrives
MAX_RESULTS = 32               # and the oldest of all when the server holds more
RESULT_GRACE_S = 300           # a closed page's results stay downloadable this long
CANCEL_GRACE_S = 10            # a cancelled operation that runs on past this ends its worker
WORKER_START_S = 300
# The pvpython this server runs in (its sys.executable names VTK's python instead).
PVPYTHON = os.path.realpath("/proc/self/exe") if os.path.exists("/proc/self/exe") else \
    shutil.which("pvpython")
FORMATS = {"stl": "model/stl", "ply": "application/octet-stream",
           "vtp": "application/octet-stream"}


def log(message):
    print("serve: " + message, flush=True)


class ArgumentParser(argparse.ArgumentParser):
    """argparse that says a bad argument in one line ("serve: ...", exit 2), no usage block."""

    def error(self, message):
        if "expected one argument" in message:  # e.g. --token -abc: argparse reads -abc as an option
            message += " (a value that begins with '-' is given as --name=VALUE)"
        self.exit(2, "serve: %s\n" % message)


def _port(text):
    try:
        port = int(text)
    except ValueError:
        port = -1
    if not 1 <= port <= 65535:
        raise argparse.ArgumentTypeError("%r is not a port number (1-65535)" % text)
    return port


def _seconds(text):
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    if not (math.isfinite(seconds) and seconds > 0):
        raise argparse.ArgumentTypeError("%r is not a positive number of seconds" % text)
    return seconds


def _plugin(text):
    path = os.path.abspath(text)
    if not os.path.isfile(path):
        raise argparse.ArgumentTypeError("no such file: %s" % text)
    return path


def parse_args(argv):
    p = ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--data", action="append", default=[],
                   help="a volume file (MetaImage, VTK XML image, NIfTI .nii/.nii.gz), a DICOM "
                        "series folder, or phantom:N (repeat for several)")
    p.add_argument("--port", type=_port, default=8765)
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (default 127.0.0.1: this machine only)")
    p.add_argument("--token", default="",
                   help="the session's token (default: a random one; one that begins with '-' "
                        "is given as --token=VALUE)")
    p.add_argument("--plugin", required=True, type=_plugin, help="MedicalIsosurfaces.so")
    p.add_argument("--wasm", default=os.path.join(ROOT, "build-web", "bin"),
                   help="folder of mediso.js and mediso.wasm")
    p.add_argument("--max-operation-seconds", type=_seconds, default=900.0,
                   help="an operation running longer is stopped with an error")
    return p.parse_args(argv)


class Dataset:
    """A volume the server serves: its values (the worker's export, memory-mapped) and geometry."""

    def __init__(self, ident, volume):
        import numpy
        self.ident = ident
        self.name = volume["name"]
        self.dims = volume["dims"]
        self.spacing = volume["spacing"]
        self.origin = volume["origin"]
        self.direction = volume["direction"]
        self.type = volume["type"]
        self.range = volume["range"]
        self.values = numpy.load(volume["values"], mmap_mode="r")
        self.encoded = {}  # level -> gzip'd shuffled bytes

    def level(self, k):
        """Level k's values: the points at multiples of LEVEL_STRIDES[k] along each axis."""
        step = LEVEL_STRIDES[k]
        return self.values[::step, ::step, ::step]

    def describe(self):
        levels = []
        for k in range(len(LEVEL_STRIDES)):
            v = self.level(k)
            step = LEVEL_STRIDES[k]
            levels.append({"dims": [v.shape[2], v.shape[1], v.shape[0]],
                           "spacing": [s * step for s in self.spacing], "bytes": int(v.nbytes)})
        return {"id": self.ident, "name": self.name, "dims": self.dims, "spacing": self.spacing,
                "origin": self.origin, "direction": self.direction, "type": self.type,
                "range": self.range, "bytes": int(self.values.nbytes), "levels": levels}

    def encode(self, k):
        """Level k byte-shuffled and gzip'd (made once)."""
        import numpy
        if k not in self.encoded:
            v = numpy.ascontiguousarray(self.level(k))
            size = v.dtype.itemsize
            planes = v.view(numpy.uint8).reshape(-1, size).T  # byte b of every value, in a row
            self.encoded[k] = gzip.compress(numpy.ascontiguousarray(planes).tobytes(), 6)
        return self.encoded[k]


def open_datasets(volumes):
    """Dataset for each volume the worker read and exported."""
    datasets = [Dataset("d%d" % i, v) for i, v in enumerate(volumes)]
    for d in datasets:
        log("%s: %s, %s %s, range %g..%g" % (d.ident, d.name, "x".join(map(str, d.dims)), d.type,
                                             d.range[0], d.range[1]))
    return datasets


# ------------------------------------------------------------------------------ validation
class BadRequest(Exception):
    """A message the server refuses; the text names what is wrong."""

    def __init__(self, text, ident=None):
        super().__init__(text)
        self.ident = ident


def _short(value):
    text = json.dumps(value) if not isinstance(value, str) else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _fields(obj, where, required, optional=()):
    if not isinstance(obj, dict):
        raise BadRequest("%s: an object" % where)
    for key in obj:
        if key not in required and key not in optional:
            raise BadRequest("%s: unknown field %s" % (where, _short(key)))
    for key in required:
        if key not in obj:
            raise BadRequest("%s: %s is missing" % (where, key))


def _number(value, where, lo=None, hi=None, above=None):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise BadRequest("%s: not a number (%s)" % (where, _short(value)))
    value = float(value)
    if not math.isfinite(value):
        raise BadRequest("%s: not a finite number" % where)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise BadRequest("%s: %g is outside %g-%g" % (where, value, lo, hi))
    if above is not None and not value > above:
        raise BadRequest("%s: %g is not above %g" % (where, value, above))
    return value


def _integer(value, where, lo, hi):
    if isinstance(value, bool) or not isinstance(value, int):
        raise BadRequest("%s: not an integer (%s)" % (where, _short(value)))
    if not lo <= value <= hi:
        raise BadRequest("%s: %d is outside %d-%d" % (where, value, lo, hi))
    return value


def _vector(value, where):
    if not isinstance(value, list) or len(value) != 3:
        raise BadRequest("%s: three numbers" % where)
    return [_number(v, where) for v in value]


def _step(step, where):
    if not isinstance(step, dict) or len(step) != 1:
        raise BadRequest("%s: one operation, e.g. {\"smooth\": {...}}" % where)
    (name, params), = step.items()
    where = "%s.%s" % (where, name)
    if name == "smooth":
        _fields(params, where, ("iterations",), ("relaxation",))
        out = {"iterations": _integer(params["iterations"], where + ".iterations", 1, 500)}
        if "relaxation" in params:
            out["relaxation"] = _number(params["relaxation"], where + ".relaxation", 0, 1)
    elif name == "fillHoles":
        _fields(params, where, ("size",))
        out = {"size": _number(params["size"], where + ".size", above=0)}
    elif name == "clip":
        _fields(params, where, ("origin", "normal"))
        out = {"origin": _vector(params["origin"], where + ".origin"),
               "normal": _vector(params["normal"], where + ".normal")}
        if math.sqrt(sum(c * c for c in out["normal"])) < 1e-12:
            raise BadRequest("%s.normal: the zero vector" % where)
    elif name == "decimate":
        _fields(params, where, ("reduction",))
        out = {"reduction": _number(params["reduction"], where + ".reduction", 0, 0.99)}
    else:
        raise BadRequest("%s: unknown operation %s (smooth, fillHoles, clip, decimate)"
                         % (where.rsplit(".", 1)[0], _short(name)))
    return {name: out}


def parse_message(text, datasets):
    """A validated request from a WebSocket text frame; BadRequest otherwise."""
    size = len(text.encode("utf-8"))
    if size > MAX_MESSAGE:
        raise BadRequest("message too long: %d bytes (at most %d)" % (size, MAX_MESSAGE))
    try:
        message = json.loads(text)  # NaN and Infinity parse, and are refused as not finite
    except (ValueError, RecursionError) as e:
        raise BadRequest("not JSON: %s" % str(e)[:80])
    if not isinstance(message, dict):
        raise BadRequest("a message is a JSON object")
    ident = message.get("id")
    if isinstance(ident, bool) or not isinstance(ident, int) or abs(ident) > 2 ** 53:
        raise BadRequest("id: an integer (%s)" % _short(ident))
    op = message.get("op")
    try:
        if op == "cancel":
            _fields(message, "cancel", ("op", "id"))
            return {"op": "cancel", "id": ident}
        if op != "surface":
            raise BadRequest("op: unknown operation %s (surface, cancel)" % _short(op))
        _fields(message, "surface", ("op", "id", "dataset", "isovalue", "level"), ("steps",))
        dataset = datasets.get(message["dataset"]) if isinstance(message["dataset"], str) else None
        if dataset is None:
            raise BadRequest("dataset: no dataset %s (this server has %s)"
                             % (_short(message["dataset"]), ", ".join(sorted(datasets))))
        isovalue = _number(message["isovalue"], "isovalue")
        if not dataset.range[0] <= isovalue <= dataset.range[1]:
            raise BadRequest("isovalue: %g is outside the data range %g..%g"
                             % (isovalue, dataset.range[0], dataset.range[1]))
        level = _integer(message["level"], "level", 0, len(LEVEL_STRIDES) - 1)
        steps = message.get("steps", [])
        if not isinstance(steps, list) or len(steps) > MAX_STEPS:
            raise BadRequest("steps: a list of at most %d operations" % MAX_STEPS)
        steps = [_step(s, "steps[%d]" % i) for i, s in enumerate(steps)]
    except BadRequest as e:
        e.ident = ident
        raise
    return {"op": "surface", "id": ident, "dataset": dataset, "isovalue": isovalue,
            "level": level, "steps": steps}


# ------------------------------------------------------------------------------ operations
class Session:
    """One page's WebSocket: its operations and its results."""

    def __init__(self, ws, number):
        self.ws = ws
        self.number = number
        self.jobs = {}                               # the page's id -> Job in flight
        self.results = collections.OrderedDict()     # rid -> Result, oldest first
        self.closed = False

    async def send(self, message):
        if self.closed or self.ws.closed:
            return
        try:
            await self.ws.send_str(json.dumps(message))
        except (ConnectionError, RuntimeError):
            self.closed = True


class Job:
    def __init__(self, number, session, request):
        self.number = number
        self.session = session
        self.request = request
        self.rid = "r" + secrets.token_hex(8)
        self.running = False
        self.cancelled = 0.0  # when the page cancelled it (time.monotonic())


class Result:
    def __init__(self, rid, session, summary, folder):
        self.rid = rid
        self.session = session
        self.summary = summary
        self.folder = folder
        self.expires = None  # set when its page closes

    def path(self, fmt):
        return os.path.join(self.folder, "%s.%s" % (self.rid, fmt))

    def remove(self):
        for fmt in FORMATS:
            try:
                os.remove(self.path(fmt))
            except FileNotFoundError:
                pass


class StartFailed(Exception):
    """The worker did not start; the text says why, in one line."""


def _ended(code):
    """How a process ended, from its exit status: "SIGSEGV", "exit 1"."""
    if code is not None and code < 0:
        try:
            return signal.Signals(-code).name
        except ValueError:
            return "signal %d" % -code
    return "exit %s" % code


class Operations:
    """The queue of operations and the one worker process that runs them in turn."""

    def __init__(self, args, specs):
        self.args = args
        self.specs = specs
        self.index = {"d%d" % i: i for i in range(len(specs))}  # as open_datasets names them
        self.folder = tempfile.mkdtemp(prefix="mediso-results-")
        self.queue = collections.deque()
        self.wake = asyncio.Event()
        self.starting = asyncio.Lock()
        self.results = {}
        self.process = None
        self.running = None
        self.restarts = 0
        self.unavailable = None
        self.numbers = 0
        self.task = None

    # -- the worker process
    async def start_worker(self, export=None):
        """Starts the worker; it reads the volumes. export: the first start, which also writes
        their values there for the server and returns their descriptions. Raises StartFailed
        with one line (naming the volume whose reading ended the process, if one did)."""
        command = [PVPYTHON, "--no-mpi", os.path.join(HERE, "serve_operations.py"),
                   "--plugin", self.args.plugin, "--results", self.folder] + \
            (["--export", export] if export else []) + self.specs
        process = await asyncio.create_subprocess_exec(
            *command, stdin=asyncio.subprocess.PIPE, stdout=asyncio.subprocess.PIPE,
            limit=1 << 20, start_new_session=True)
        reading = None  # the volume it reads (its "opening" message comes first)
        try:
            deadline = asyncio.get_running_loop().time() + WORKER_START_S
            while True:
                line = await asyncio.wait_for(process.stdout.readline(),
                                              deadline - asyncio.get_running_loop().time())
                if not line:  # the process ended: a crash, an abort, a memory kill
                    ended = _ended(await process.wait())
                    message = {"fatal": "it exited (%s)" % ended} if reading is None else {
                        "fatal": "%s: cannot be read: the reader ended its process (%s)"
                        % (self.specs[reading], ended)}
                    break
                message = json.loads(line)
                if "opening" not in message:
                    break
                reading = message["opening"]
        except (asyncio.TimeoutError, ValueError) as e:
            message = {"fatal": "it did not start (%s)" % (type(e).__name__)}
        if not message.get("ready"):
            if process.returncode is None:
                process.kill()
                await process.wait()
            raise StartFailed(message.get("fatal", "no ready message"))
        self.process = process
        return message

    async def stop_worker(self):
        process, self.process = self.process, None
        if process and process.returncode is None:
            process.kill()
            await process.wait()

    async def ensure_worker(self):
        async with self.starting:  # one start at a time: at server start and for a job
            return await self._ensure_worker()

    async def _ensure_worker(self):
        if self.process is not None and self.process.returncode is None:
            return True
        for attempt in range(3):
            try:
                await self.start_worker()
                self.unavailable = None
                return True
            except (StartFailed, OSError) as e:
                self.unavailable = "the server's operation process cannot start: %s" % e
                log(self.unavailable)
                await asyncio.sleep(1 + attempt)
        return False

    # -- requests from pages
    async def submit(self, session, request):
        ident = request["id"]
        if ident in session.jobs:
            raise BadRequest("id: %d is already an operation in progress" % ident, ident)
        if len(session.jobs) >= MAX_PENDING:
            raise BadRequest("at most %d operations in progress per page" % MAX_PENDING, ident)
        self.numbers += 1
        job = Job(self.numbers, session, request)
        session.jobs[ident] = job
        self.queue.append(job)
        self.wake.set()
        if self.running is not None or len(self.queue) > 1:
            await session.send({"id": ident, "progress": 0.0, "stage": "queued",
                                "position": len(self.queue)})

    async def cancel(self, session, ident):
        job = session.jobs.get(ident)
        if job is None:
            raise BadRequest("no operation %d in progress" % ident, ident)
        await self.cancel_job(job)

    async def cancel_job(self, job):
        if job.cancelled:
            return
        job.cancelled = time.monotonic()
        if job.running:
            if self.process is not None and self.process.returncode is None:
                self.process.send_signal(signal.SIGUSR1)  # the worker aborts at its next step
        else:
            self.queue.remove(job)
            self.finish(job)
            await job.session.send({"id": job.request["id"], "cancelled": True})

    def finish(self, job):
        job.session.jobs.pop(job.request["id"], None)

    async def session_closed(self, session):
        session.closed = True
        for job in list(session.jobs.values()):
            await self.cancel_job(job)
        for result in session.results.values():
            result.expires = time.monotonic() + RESULT_GRACE_S

    # -- the loop that runs the queue
    async def run(self):
        while True:
            while not self.queue:
                self.wake.clear()
                try:
                    await asyncio.wait_for(self.wake.wait(), 60)
                except asyncio.TimeoutError:
                    pass
                self.expire_results()
            job = self.queue.popleft()
            self.running = job
            job.running = True
            try:
                await self.run_job(job)
            except Exception as e:  # the loop must go on whatever one operation does
                log("operation %d failed: %r" % (job.number, e))
                await job.session.send({"id": job.request["id"],
                                        "error": "internal error: %s" % type(e).__name__})
            finally:
                self.running = None
                job.running = False
                self.finish(job)
            self.expire_results()

    async def run_job(self, job):
        ident = job.request["id"]
        if not await self.ensure_worker():
            await job.session.send({"id": ident, "error": self.unavailable})
            return
        r = job.request
        line = {"job": job.number, "rid": job.rid, "dataset": self.index[r["dataset"].ident],
                "isovalue": r["isovalue"], "level": r["level"], "steps": r["steps"]}
        for attempt in (1, 2):  # a worker that died while idle is replaced once
            if job.cancelled:  # while the worker started
                await job.session.send({"id": ident, "cancelled": True})
                return
            process = self.process
            try:
                process.stdin.write((json.dumps(line) + "\n").encode())
                await process.stdin.drain()
                break
            except (BrokenPipeError, ConnectionResetError):
                await self.stop_worker()
                self.restarts += 1
                if attempt == 2 or not await self.ensure_worker():
                    await job.session.send({"id": ident, "error": self.unavailable or
                                            "the server's operation process is not running"})
                    return
        started = time.monotonic()
        read = None
        while True:
            if read is None:
                read = asyncio.ensure_future(process.stdout.readline())
            done, _ = await asyncio.wait({read}, timeout=0.25)
            if not done:
                now = time.monotonic()
                stuck = job.cancelled and now - job.cancelled > CANCEL_GRACE_S
                if stuck or now - started > self.args.max_operation_seconds:
                    # A filter that does not poll abort, or an operation past its time: the
                    # worker goes, and the next operation starts a new one.
                    read.cancel()
                    await self.stop_worker()
                    self.restarts += 1
                    await job.session.send({"id": ident, "cancelled": True} if stuck else {
                        "id": ident, "error": "the operation took longer than %g s and was "
                        "stopped" % self.args.max_operation_seconds})
                    return
                continue
            raw, read = read.result(), None
            if not raw:
                code = await process.wait()
                self.process = None
                self.restarts += 1
                log("the operation process ended (exit %s) during operation %d; it will be "
                    "restarted" % (code, job.number))
                await job.session.send({"id": ident, "error": "the server's operation process "
                                        "ended unexpectedly (exit %s); it has been restarted"
                                        % code})
                return
            message = json.loads(raw)
            if message.get("job") != job.number:
                continue
            if "progress" in message:
                if not job.cancelled:
                    await job.session.send({"id": ident, "progress": message["progress"],
                                            "stage": message["stage"]})
                continue
            if message.get("done"):
                await self.keep_result(job, message)
            elif message.get("cancelled"):
                await job.session.send({"id": ident, "cancelled": True})
            else:
                await job.session.send({"id": ident, "error": message.get("error", "failed")})
            return

    async def keep_result(self, job, message):
        session = job.session
        r = job.request
        summary = {"id": r["id"], "done": True, "result": job.rid,
                   "triangles": message["triangles"], "points": message["points"],
                   "boundaryEdges": message["boundaryEdges"], "bounds": message["bounds"],
                   "bytes": message["bytes"], "stages": message["stages"],
                   "seconds": message["seconds"], "dataset": r["dataset"].ident,
                   "isovalue": r["isovalue"], "level": r["level"]}
        if message.get("warnings"):
            summary["warnings"] = message["warnings"]
        result = Result(job.rid, session, summary, self.folder)
        if job.cancelled or session.closed:
            result.remove()
            if job.cancelled:
                await session.send({"id": r["id"], "cancelled": True})
            return
        self.results[job.rid] = result
        session.results[job.rid] = result
        while len(session.results) > RESULTS_PER_SESSION:
            _, old = session.results.popitem(last=False)
            self.drop(old)
        while len(self.results) > MAX_RESULTS:  # the oldest of any page
            old = next(iter(self.results.values()))
            old.session.results.pop(old.rid, None)
            self.drop(old)
        await session.send(summary)

    def drop(self, result):
        self.results.pop(result.rid, None)
        result.remove()

    def expire_results(self):
        now = time.monotonic()
        for result in [r for r in self.results.values() if r.expires and r.expires < now]:
            result.session.results.pop(result.rid, None)
            self.drop(result)

    async def close(self):
        if self.task:
            self.task.cancel()
        await self.stop_worker()
        shutil.rmtree(self.folder, ignore_errors=True)

    def status(self):
        return {"queued": len(self.queue), "running": self.running is not None,
                "worker": {"pid": self.process.pid if self.process else None,
                           "restarts": self.restarts, "unavailable": self.unavailable},
                "results": len(self.results)}


# ------------------------------------------------------------------------------ the app
def make_app(args, datasets, operations):
    token = args.token
    by_id = {d.ident: d for d in datasets}
    wasm_files = {"mediso.js", "mediso.wasm", "mediso-mt.js", "mediso-mt.wasm",
                  "mediso-mt.worker.js"}
    sessions = set()
    counter = [0]

    @web.middleware
    async def authenticate(request, handler):
        given = request.query.get("token") or request.cookies.get("mediso_token")
        if not given or not secrets.compare_digest(given.encode(), token.encode()):
            return web.Response(status=403, text="403: this server needs the token of its URL\n")
        response = await handler(request)
        if isinstance(response, web.StreamResponse) and not response.prepared:  # not a socket
            if request.query.get("token"):
                response.set_cookie("mediso_token", token, httponly=True, samesite="Strict")
            # Cross-origin isolation: the page may then use threads (SharedArrayBuffer).
            response.headers["Cross-Origin-Opener-Policy"] = "same-origin"
            response.headers["Cross-Origin-Embedder-Policy"] = "require-corp"
        return response

    async def index(request):
        return web.FileResponse(os.path.join(STATIC, "index.html"))

    async def static(request):
        name = request.match_info["name"]
        if name in wasm_files:
            path = os.path.join(args.wasm, name)
        elif name in os.listdir(STATIC):
            path = os.path.join(STATIC, name)
        else:
            raise web.HTTPNotFound()
        if not os.path.isfile(path):
            raise web.HTTPNotFound(text="%s is not built: run Scripts/build-web.sh\n" % name)
        return web.FileResponse(path)

    async def list_datasets(request):
        return web.json_response({"datasets": [d.describe() for d in datasets]})

    encoding = {}  # (dataset, level) -> the future of its bytes: each level is encoded once

    async def volume(request):
        d = by_id.get(request.match_info["ident"])
        if d is None:
            raise web.HTTPNotFound(text="no such dataset\n")
        try:
            k = int(request.query.get("level", "3"))
        except ValueError:
            k = -1
        if not 0 <= k < len(LEVEL_STRIDES):
            raise web.HTTPBadRequest(text="level is 0, 1, 2 or 3\n")
        key = (d.ident, k)
        if key not in encoding:
            encoding[key] = asyncio.get_running_loop().run_in_executor(None, d.encode, k)
        body = await asyncio.shield(encoding[key])
        level = d.describe()["levels"][k]
        headers = {"Content-Encoding": "gzip", "Content-Type": "application/octet-stream",
                   "X-Mediso-Dims": ",".join(map(str, level["dims"])),
                   "X-Mediso-Spacing": ",".join(repr(s) for s in level["spacing"]),
                   "X-Mediso-Origin": ",".join(repr(s) for s in d.origin),
                   "X-Mediso-Type": d.type, "X-Mediso-Raw-Bytes": str(level["bytes"]),
                   "Cache-Control": "no-store"}
        return web.Response(body=body, headers=headers)

    async def result(request):
        fmt = request.query.get("format", "stl")
        if fmt not in FORMATS:
            raise web.HTTPBadRequest(text="format is stl, ply or vtp\n")
        r = operations.results.get(request.match_info["rid"])
        if r is None or not os.path.isfile(r.path(fmt)):
            raise web.HTTPNotFound(text="no such result (a page keeps its last %d results, and "
                                   "they go %d s after it closes)\n"
                                   % (RESULTS_PER_SESSION, RESULT_GRACE_S))
        s = r.summary
        name = "%s-%g-level%d.%s" % (os.path.splitext(by_id[s["dataset"]].name)[0],
                                     s["isovalue"], s["level"], fmt)
        name = "".join(c if c.isalnum() or c in "-._" else "_" for c in name)
        return web.FileResponse(r.path(fmt), headers={
            "Content-Type": FORMATS[fmt], "Cache-Control": "no-store",
            "Content-Disposition": 'attachment; filename="%s"' % name})

    async def status(request):
        return web.json_response(dict(operations.status(), sessions=len(sessions),
                                      datasets=len(datasets)))

    def same_origin(request):
        origin = request.headers.get("Origin")
        if origin is None:
            return True  # not a browser: the token is what counts
        return urlsplit(origin).netloc == request.host

    async def websocket(request):
        if not same_origin(request):
            return web.Response(status=403, text="403: WebSocket from another origin\n")
        if len(sessions) >= MAX_SESSIONS:
            return web.Response(status=503, text="503: too many pages open\n")
        ws = web.WebSocketResponse(max_msg_size=MAX_FRAME)
        await ws.prepare(request)
        counter[0] += 1
        session = Session(ws, counter[0])
        sessions.add(session)
        try:
            async for msg in ws:
                if msg.type == WSMsgType.TEXT:
                    await handle(session, msg.data)
                elif msg.type == WSMsgType.BINARY:
                    await session.send({"id": None, "error": "binary frames are not accepted: "
                                        "send JSON text"})
                else:
                    break
        finally:
            sessions.discard(session)
            await operations.session_closed(session)
        return ws

    async def handle(session, text):
        try:
            request = parse_message(text, by_id)
            if request["op"] == "surface":
                await operations.submit(session, request)
            else:
                await operations.cancel(session, request["id"])
        except BadRequest as e:
            await session.send({"id": e.ident, "error": str(e)})

    async def on_startup(app):
        operations.task = asyncio.get_running_loop().create_task(operations.run())

    async def on_cleanup(app):
        await operations.close()

    app = web.Application(middlewares=[authenticate], client_max_size=64 * 1024)
    app.router.add_get("/", index)
    app.router.add_get("/static/{name}", static)
    app.router.add_get("/api/datasets", list_datasets)
    app.router.add_get("/api/volume/{ident}", volume)
    app.router.add_get("/api/result/{rid}", result)
    app.router.add_get("/api/status", status)
    app.router.add_get("/api/ws", websocket)
    app.on_startup.append(on_startup)
    app.on_cleanup.append(on_cleanup)
    return app


def main(argv):
    args = parse_args(argv)
    try:  # first: a port in use is said before any volume is read
        family = socket.getaddrinfo(args.host, args.port, type=socket.SOCK_STREAM)[0][0]
        listener = socket.create_server((args.host, args.port), family=family)
    except OSError as e:
        # create_server adds "(while attempting to bind ...)" to the system's reason.
        reason = os.strerror(e.errno) if e.errno and not isinstance(e, socket.gaierror) else \
            e.strerror or e
        raise SystemExit("serve: cannot listen on %s:%d: %s" % (args.host, args.port, reason))
    args.token = args.token or secrets.token_urlsafe(18)
    specs = args.data or serve_operations.default_sources()
    if not args.data and specs[0].startswith(serve_operations.PHANTOM):
        log("the head CT is not fetched (python3 Python/fetch_data.py): serving the phantom")
    specs = [s if s.startswith(serve_operations.PHANTOM) else os.path.abspath(s) for s in specs]
    return asyncio.run(serve(args, specs, listener))


async def serve(args, specs, listener):
    """Reads the volumes in the worker, then serves until SIGINT or SIGTERM."""
    operations = Operations(args, specs)
    try:
        # The worker reads the volumes, not this process: a reader that crashes or aborts on a
        # bad file ends the worker, and the server says which file in one line.
        ready = await operations.start_worker(export=operations.folder)
    except (StartFailed, OSError) as e:
        await operations.close()
        raise SystemExit("serve: %s" % e)
    for note in ready["notes"]:
        log(note)
    datasets = open_datasets(ready["volumes"])
    app = make_app(args, datasets, operations)
    runner = web.AppRunner(app, access_log=None)
    await runner.setup()
    await web.SockSite(runner, listener).start()
    host = "[%s]" % args.host if ":" in args.host else args.host
    if args.host not in ("127.0.0.1", "localhost", "::1"):
        log("listening on %s: anyone who can reach it and has the URL can use it" % args.host)
    log("open http://%s:%d/?token=%s" % (host, args.port, args.token))
    stop = asyncio.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        asyncio.get_running_loop().add_signal_handler(signum, stop.set)
    await stop.wait()
    await runner.cleanup()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
