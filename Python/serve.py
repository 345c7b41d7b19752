"""The web client's server: the page, each volume once, and the operations that need the server.

    pvpython --no-mpi Python/serve.py --plugin build/.../MedicalIsosurfaces.so --wasm build-web/bin \\
        [--data FILE_OR_DICOM_DIR ...] [--port 8765] [--host 127.0.0.1] [--token=TOKEN]

Run by Scripts/serve.sh, which installs and builds what is needed first. The worker process
(Python/serve_operations.py) opens the volumes with ParaView's readers and hands their values over;
the server prints the page's URL (with the session's token) and serves it with aiohttp
(docs/web.md has the API). Without --data: the fetched head CT, or the plugin's MedicalPhantom when
the CT is not there (--data phantom:N asks for the phantom at N^3). A volume that cannot be read
stops the server at start with one line, whatever the reader does (even a crash: it runs in the
worker, not here).

Operations on a surface (smoothing, hole filling, clipping, decimation) arrive on the WebSocket
/api/ws as parameters (validated by Python/serve_messages.py); they run one at a time in the
worker (Python/serve_jobs.py runs the queue), so that the event loop keeps serving every page
meanwhile.

The aiohttp shape: the app's state is one ServerState under one key (STATE), the handlers are
module functions that read it, the page's files are served by name and gzip'd (serve_static.py),
and the startup and cleanup of the job runner are the app's signals.
"""
import argparse
import asyncio
import gzip
import math
import mimetypes
import os
import secrets
import signal
import socket
import sys
from dataclasses import dataclass, field
from email.utils import formatdate, parsedate_to_datetime
from typing import Optional
from urllib.parse import urlsplit

from aiohttp import WSMsgType, web

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
STATIC = os.path.join(ROOT, "Web", "static")
sys.path.insert(0, HERE)
import serve_bricks  # noqa: E402  (the bricks the page streams)
import serve_operations  # noqa: E402  (the volumes' default, and the worker's program)
from serve_jobs import (FORMATS, RESULT_GRACE_S, RESULTS_PER_SESSION, Operations,  # noqa: E402
                        Session, StartFailed, log)
from serve_messages import LEVEL_STRIDES, BadRequest, parse_message  # noqa: E402
import serve_upload  # noqa: E402  (a local volume uploaded once: POST /api/upload)
from serve_static import StaticFiles  # noqa: E402  (the page's files, gzip'd)
from serve_work import VOLUME_WORK  # noqa: E402  (the volume work's own threads)

MAX_FRAME = 1024 * 1024        # above this aiohttp closes the socket (1009, message too big)
MAX_SESSIONS = 64              # WebSockets open at once
# How /api/volume encodes a level (byte-shuffled, gzip level 6): part of its ETag, so that a
# change of the encoding is a new representation to the browser's cache.
VOLUME_ENCODING = "shuffle-gzip6"
# The volume may be kept by the browser, but is revalidated at each use (ETag, Last-Modified):
# a conditional request passes the token check like any other, so the bytes and the 304 both
# need the token. "private": no shared cache keeps it.
VOLUME_CACHE_CONTROL = "private, no-cache"
# The page's WebAssembly build, served beside Web/static from --wasm.
WASM_FILES = ("mediso.js", "mediso.wasm", "mediso-mt.js", "mediso-mt.wasm", "mediso-mt.worker.js")
# The page loads its scripts as ES modules, which browsers run only when served as JavaScript.
mimetypes.add_type("text/javascript", ".js")
mimetypes.add_type("text/javascript", ".mjs")
mimetypes.add_type("application/wasm", ".wasm")


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
                        "series folder, or phantom:N[:noise=HU][:seed=K] (repeat for several)")
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


@dataclass(eq=False)
class Dataset:
    """A volume the server serves: its values (the worker's export, memory-mapped) and geometry."""
    ident: str
    name: str
    dims: list
    spacing: list
    origin: list
    direction: list
    type: str  # numpy's name: serve_operations.SCALAR_TYPES
    range: list
    values: object  # numpy array, (z, y, x)
    format: dict  # {"name", "space"}: serve_operations.source_format
    modified: Optional[float] = None  # the source file's time (None: the phantom)
    encoded: dict = field(default_factory=dict)  # level -> gzip'd shuffled bytes
    digest: Optional[str] = None  # of the values and geometry (validators)

    @classmethod
    def load(cls, ident, volume):
        """The dataset of a volume the worker described and exported."""
        import numpy
        return cls(ident, volume["name"], volume["dims"], volume["spacing"], volume["origin"],
                   volume["direction"], volume["type"], volume["range"],
                   numpy.load(volume["values"], mmap_mode="r"), volume["format"],
                   volume.get("modified"))

    def fingerprint(self):
        """A digest of what /api/volume sends (values, type, geometry): the volume's ETag is
        made of it, so another volume under the same id gets another ETag (made once)."""
        if self.digest is None:
            import hashlib
            import json
            h = hashlib.blake2b(digest_size=12)
            h.update(json.dumps([self.dims, self.spacing, self.origin, self.type]).encode())
            h.update(memoryview(numpy_contiguous(self.values)).cast("B"))
            self.digest = h.hexdigest()
        return self.digest

    def etag(self, k):
        """Level k's ETag: the fingerprint, the level and the encoding (VOLUME_ENCODING)."""
        return '"%s-%d-%s"' % (self.fingerprint(), k, VOLUME_ENCODING)

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
                "range": self.range, "bytes": int(self.values.nbytes), "levels": levels,
                "format": self.format}

    def encode(self, k):
        """Level k byte-shuffled and gzip'd (made once)."""
        import numpy
        if k not in self.encoded:
            v = numpy.ascontiguousarray(self.level(k))
            size = v.dtype.itemsize
            planes = v.view(numpy.uint8).reshape(-1, size).T  # byte b of every value, in a row
            self.encoded[k] = gzip.compress(numpy.ascontiguousarray(planes).tobytes(), 6)
        return self.encoded[k]


def numpy_contiguous(values):
    import numpy
    return numpy.ascontiguousarray(values)


def open_datasets(volumes):
    """Dataset for each volume the worker read and exported."""
    datasets = [Dataset.load("d%d" % i, v) for i, v in enumerate(volumes)]
    for d in datasets:
        log("%s: %s, %s %s, range %g..%g" % (d.ident, d.name, "x".join(map(str, d.dims)), d.type,
                                             d.range[0], d.range[1]))
    return datasets


# ------------------------------------------------------------------------------ the app
@dataclass(eq=False)
class ServerState:
    """Everything the handlers share; one per app, under STATE."""
    token: str
    wasm: str
    datasets: list
    operations: Operations
    by_id: dict = field(default_factory=dict)
    sessions: set = field(default_factory=set)
    opened: int = 0                                # WebSockets opened so far (session numbers)
    encoding: dict = field(default_factory=dict)  # (dataset, level) -> future of its bytes
    fingerprints: dict = field(default_factory=dict)  # dataset -> future of its digest
    files: Optional[StaticFiles] = None  # the page's files (page_files), gzip'd once each

    def __post_init__(self):
        self.by_id = {d.ident: d for d in self.datasets}
        self.files = self.files or page_files(self.wasm)


# aiohttp 3.9 keys app state with web.AppKey (typed); Debian 12's aiohttp 3.8 has no AppKey and
# takes the string key, the one key of this app.
STATE = web.AppKey("state", ServerState) if hasattr(web, "AppKey") else "mediso.state"


@web.middleware
async def authenticate(request, handler):
    token = request.app[STATE].token
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
    return await request.app[STATE].files.respond(request, os.path.join(STATIC, "index.html"))


def page_files(wasm):
    """The page's files: the WebAssembly build's (its own folder) first, then Web/static's."""
    return StaticFiles([(wasm, WASM_FILES), (STATIC, None)], not_modified,
                       missing=lambda name: "%s is not built: run Scripts/build-web.sh\n" % name)


async def list_datasets(request):
    return web.json_response({"datasets": [d.describe() for d in request.app[STATE].datasets]})


async def volume(request):
    state = request.app[STATE]
    d = state.by_id.get(request.match_info["ident"])
    k = serve_bricks.requested_level(request, d)
    loop = asyncio.get_running_loop()
    if d.digest is None:  # once per dataset, off the event loop
        if d.ident not in state.fingerprints:
            state.fingerprints[d.ident] = loop.run_in_executor(VOLUME_WORK, d.fingerprint)
        await asyncio.shield(state.fingerprints[d.ident])
    validators = {"ETag": d.etag(k), "Cache-Control": VOLUME_CACHE_CONTROL}
    if d.modified is not None:
        validators["Last-Modified"] = formatdate(d.modified, usegmt=True)
    if not_modified(request, validators["ETag"], d.modified):
        return web.Response(status=304, headers=validators)
    key = (d.ident, k)
    if key not in state.encoding:  # each level is encoded once
        state.encoding[key] = loop.run_in_executor(VOLUME_WORK, d.encode, k)
    body = await asyncio.shield(state.encoding[key])
    level = d.describe()["levels"][k]
    headers = dict(validators, **{
        "Content-Encoding": "gzip", "Content-Type": "application/octet-stream",
        "X-Mediso-Dims": ",".join(map(str, level["dims"])),
        "X-Mediso-Spacing": ",".join(repr(s) for s in level["spacing"]),
        "X-Mediso-Origin": ",".join(repr(s) for s in d.origin),
        "X-Mediso-Type": d.type, "X-Mediso-Raw-Bytes": str(level["bytes"])})
    return web.Response(body=body, headers=headers)


def not_modified(request, etag, modified):
    """True when the request's validators match (RFC 9110 13.1): If-None-Match by weak
    comparison when given, else If-Modified-Since against the source's time."""
    given = request.headers.get("If-None-Match")
    if given is not None:
        tags = [t.strip() for t in given.split(",")]
        return "*" in tags or etag in [t[2:] if t.startswith("W/") else t for t in tags]
    since = request.headers.get("If-Modified-Since")
    if since is None or modified is None:
        return False
    try:
        return int(modified) <= parsedate_to_datetime(since).timestamp()
    except (TypeError, ValueError):
        return False


async def result(request):
    state = request.app[STATE]
    fmt = request.query.get("format", "stl")
    if fmt not in FORMATS:
        raise web.HTTPBadRequest(text="format is stl, ply or vtp\n")
    r = state.operations.results.get(request.match_info["rid"])
    if r is None or not os.path.isfile(r.path(fmt)):
        raise web.HTTPNotFound(text="no such result (a page keeps its last %d results, and "
                               "they go %d s after it closes)\n"
                               % (RESULTS_PER_SESSION, RESULT_GRACE_S))
    s = r.summary
    name = "%s-%g-level%d.%s" % (os.path.splitext(state.by_id[s["dataset"]].name)[0],
                                 s["isovalue"], s["level"], fmt)
    name = "".join(c if c.isalnum() or c in "-._" else "_" for c in name)
    return web.FileResponse(r.path(fmt), headers={
        "Content-Type": FORMATS[fmt], "Cache-Control": "no-store",
        "Content-Disposition": 'attachment; filename="%s"' % name})


async def status(request):
    state = request.app[STATE]
    return web.json_response(dict(state.operations.status(), sessions=len(state.sessions),
                                  datasets=len(state.datasets)))


def same_origin(request):
    origin = request.headers.get("Origin")
    if origin is None:
        return True  # not a browser: the token is what counts
    return urlsplit(origin).netloc == request.host


async def websocket(request):
    state = request.app[STATE]
    if not same_origin(request):
        return web.Response(status=403, text="403: WebSocket from another origin\n")
    if len(state.sessions) >= MAX_SESSIONS:
        return web.Response(status=503, text="503: too many pages open\n")
    ws = web.WebSocketResponse(max_msg_size=MAX_FRAME)
    await ws.prepare(request)
    state.opened += 1
    session = Session(ws, state.opened)
    state.sessions.add(session)
    try:
        async for msg in ws:
            if msg.type == WSMsgType.TEXT:
                await handle(state, session, msg.data)
            elif msg.type == WSMsgType.BINARY:
                await session.send({"id": None, "error": "binary frames are not accepted: "
                                    "send JSON text"})
            else:
                break
    finally:
        state.sessions.discard(session)
        await state.operations.session_closed(session)
    return ws


async def handle(state, session, text):
    try:
        request = parse_message(text, state.by_id)
        if request["op"] == "surface":
            await state.operations.submit(session, request)
        else:
            await state.operations.cancel(session, request["id"])
    except BadRequest as e:
        await session.send({"id": e.ident, "error": str(e)})


async def warm_up(state, prepare_bricks):
    """What a first page waits for, made in the background at the server's start (docs/web.md,
    "The page's start-up"): the page's files gzip'd, and for each dataset its fingerprint (the
    validators), level 0 encoded and the full level's brick manifest (what streaming asks for
    first). The handlers await the same futures, so a request that comes sooner waits for them."""
    state.files.warm()
    loop = asyncio.get_running_loop()
    for d in state.datasets:
        if (d.ident, 0) not in state.encoding:
            state.encoding[(d.ident, 0)] = loop.run_in_executor(VOLUME_WORK, d.encode, 0)
        if d.ident not in state.fingerprints:
            state.fingerprints[d.ident] = loop.run_in_executor(VOLUME_WORK, d.fingerprint)
        prepare_bricks(d, len(LEVEL_STRIDES) - 1)


async def start_jobs(app):
    operations = app[STATE].operations
    operations.task = asyncio.get_running_loop().create_task(operations.run())


async def stop_jobs(app):
    await app[STATE].operations.close()


def make_app(args, datasets, operations):
    app = web.Application(middlewares=[authenticate], client_max_size=64 * 1024)
    app[STATE] = ServerState(args.token, args.wasm, datasets, operations)
    app.router.add_get("/", index)
    # The WebAssembly build's files and those of Web/static, by name only (no path is resolved),
    # gzip'd where the browser takes it (serve_static.py), content types from the suffix.
    app.router.add_get("/static/{name}", app[STATE].files.handler)
    app.router.add_get("/api/datasets", list_datasets)
    app.router.add_get("/api/volume/{ident}", volume)
    bricks = serve_bricks.handler(
        lambda request: request.app[STATE].by_id.get(request.match_info["ident"]),
        not_modified, VOLUME_CACHE_CONTROL)
    app.router.add_get("/api/bricks/{ident}", bricks)
    app.router.add_get("/api/result/{rid}", result)
    app.router.add_get("/api/status", status)
    app.router.add_get("/api/ws", websocket)
    # A local volume the page read itself, uploaded once for the operations (serve_upload.py).
    app.router.add_post("/api/upload", serve_upload.handler(STATE, Dataset))
    app.on_startup.append(start_jobs)
    app.on_startup.append(lambda app: warm_up(app[STATE], bricks.prepare))
    app.on_cleanup.append(stop_jobs)
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
    operations = Operations(specs, args.plugin, args.max_operation_seconds)
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
