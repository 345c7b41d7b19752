"""The web server's job runner: the pages' operations queued and run one at a time in the worker.

Python/serve.py hands each validated surface request to Operations.submit(); the queue runs in one
task (Operations.run) that sends each job to the worker process (Python/serve_operations.py) as a
JSON line and relays its progress and result to the page's WebSocket. The worker is started once
at server start (it reads the volumes, see start_worker) and again after it dies or is ended: a
crash, a job past --max-operation-seconds, or a cancelled job that runs on past CANCEL_GRACE_S.
Nothing here polls: the queue awaits its wake-up event or the next result's expiry, and a running
job awaits the worker's next line, its cancellation or its deadline, whichever comes first.
"""
import asyncio
import collections
import json
import os
import secrets
import shutil
import signal
import tempfile
import time
from dataclasses import dataclass, field
from typing import Optional

from serve_messages import REPORT, BadRequest

HERE = os.path.dirname(os.path.abspath(__file__))
MAX_PENDING = 4                # operations queued or running per page
RESULTS_PER_SESSION = 8        # the oldest result of a page goes when a ninth arrives
MAX_RESULTS = 32               # and the oldest of all when the server holds more
RESULT_GRACE_S = 300           # a closed page's results stay downloadable this long
CANCEL_GRACE_S = 10            # a cancelled operation that runs on past this ends its worker
WORKER_START_S = 300
FORMATS = {"stl": "model/stl", "ply": "application/octet-stream",
           "vtp": "application/octet-stream"}
# The pvpython this server runs in (its sys.executable names VTK's python instead).
PVPYTHON = os.path.realpath("/proc/self/exe") if os.path.exists("/proc/self/exe") else \
    shutil.which("pvpython")


def log(message):
    print("serve: " + message, flush=True)


@dataclass(eq=False)
class Session:
    """One page's WebSocket: its operations and its results."""
    ws: object
    number: int
    jobs: dict = field(default_factory=dict)  # the page's id -> Job in flight
    results: collections.OrderedDict = field(default_factory=collections.OrderedDict)  # oldest 1st
    closed: bool = False

    async def send(self, message):
        if self.closed or self.ws.closed:
            return
        try:
            await self.ws.send_str(json.dumps(message))
        except (ConnectionError, RuntimeError):
            self.closed = True


@dataclass(eq=False)
class Job:
    """A page's surface request on its way through the queue and the worker."""
    number: int
    session: Session
    request: dict
    rid: str = field(default_factory=lambda: "r" + secrets.token_hex(8))
    running: bool = False
    cancelled: float = 0.0  # when the page cancelled it (time.monotonic())
    cancel_event: asyncio.Event = field(default_factory=asyncio.Event)


@dataclass(eq=False)
class Result:
    """A finished surface: its summary for the page and its files in the results folder."""
    rid: str
    session: Session
    summary: dict
    folder: str
    expires: Optional[float] = None  # set when its page closes

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

    def __init__(self, specs, plugin, max_seconds):
        self.specs = specs
        self.plugin = plugin
        self.max_seconds = max_seconds
        self.index = {"d%d" % i: i for i in range(len(specs))}  # as serve.py names the datasets
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
                   "--plugin", self.plugin, "--results", self.folder] + \
            (["--export", export] if export else []) + self.specs
        process = await asyncio.create_subprocess_exec(
            *command, stdin=asyncio.subprocess.PIPE, stdout=asyncio.subprocess.PIPE,
            limit=1 << 20, start_new_session=True)
        reading = None  # the volume it reads (its "opening" message comes first)
        loop = asyncio.get_running_loop()
        try:
            deadline = loop.time() + WORKER_START_S
            while True:
                line = await asyncio.wait_for(process.stdout.readline(), deadline - loop.time())
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
        async with self.starting:  # one start at a time
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
        job.cancel_event.set()
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
        self.wake.set()  # the queue's next expiry may now be sooner

    # -- the loop that runs the queue
    async def run(self):
        while True:
            while not self.queue:
                self.wake.clear()
                expiries = [r.expires for r in self.results.values() if r.expires]
                try:  # until a job arrives or the next result expires
                    await asyncio.wait_for(self.wake.wait(), max(0.0, min(expiries) -
                                           time.monotonic()) if expiries else None)
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

    async def send_job(self, job):
        """Writes the job to the worker (replacing a worker that died while idle, once); the
        worker process, or None when the page has been answered already."""
        ident = job.request["id"]
        r = job.request
        line = {"job": job.number, "rid": job.rid, "dataset": self.index[r["dataset"].ident],
                "isovalue": r["isovalue"], "level": r["level"], "steps": r["steps"],
                "export": r["export"]}
        for attempt in (1, 2):
            if job.cancelled:  # while the worker started
                await job.session.send({"id": ident, "cancelled": True})
                return None
            process = self.process
            try:
                process.stdin.write((json.dumps(line) + "\n").encode())
                await process.stdin.drain()
                return process
            except (BrokenPipeError, ConnectionResetError):
                await self.stop_worker()
                self.restarts += 1
                if attempt == 2 or not await self.ensure_worker():
                    await job.session.send({"id": ident, "error": self.unavailable or
                                            "the server's operation process is not running"})
                    return None

    async def next_line(self, job, process, started):
        """The worker's next line; None when the job's deadline passed first: its time
        (max_seconds), or CANCEL_GRACE_S after the page cancelled it."""
        read = asyncio.ensure_future(process.stdout.readline())
        try:
            while True:
                deadline = started + self.max_seconds
                if job.cancelled:
                    deadline = min(deadline, job.cancelled + CANCEL_GRACE_S)
                waits = {read}
                if not job.cancelled:  # a cancellation moves the deadline
                    waits.add(asyncio.ensure_future(job.cancel_event.wait()))
                done, pending = await asyncio.wait(
                    waits, timeout=max(0.0, deadline - time.monotonic()),
                    return_when=asyncio.FIRST_COMPLETED)
                for waiting in pending - {read}:
                    waiting.cancel()
                if read in done:
                    return read.result()
                if time.monotonic() >= deadline:
                    return None
        finally:
            if not read.done():
                read.cancel()

    async def run_job(self, job):
        ident = job.request["id"]
        if not await self.ensure_worker():
            await job.session.send({"id": ident, "error": self.unavailable})
            return
        process = await self.send_job(job)
        if process is None:
            return
        started = time.monotonic()
        while True:
            raw = await self.next_line(job, process, started)
            if raw is None:
                # A filter that does not poll abort, or an operation past its time: the worker
                # goes, and the next operation starts a new one.
                stuck = job.cancelled and time.monotonic() - job.cancelled >= CANCEL_GRACE_S
                await self.stop_worker()
                self.restarts += 1
                await job.session.send({"id": ident, "cancelled": True} if stuck else {
                    "id": ident, "error": "the operation took longer than %g s and was "
                    "stopped" % self.max_seconds})
                return
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
                   "isovalue": r["isovalue"], "level": r["level"], "export": r["export"],
                   "report": {key: message["report"][key] for key in REPORT}}
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
