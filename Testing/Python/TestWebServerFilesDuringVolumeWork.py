"""pvpython test: the page's files answer while the volume work is held (docs/web.md, "The page's
start-up": the stalled module requests; Python/serve_work.py).

Python/serve.py's app runs here in-process, on 127.0.0.1, over datasets whose every piece of
volume work (fingerprint, level encoding, the bricks' manifest) waits on one gate, so that the
server's start alone queues more volume work than any pool has threads and holds every thread
it reaches. A level-0 request is sent first and waits behind that work. Then one of the page's
files gets a new version (so its gzip must be made again, as after an edit or a rebuild while the
server runs) and is asked for twice, gzip'd and plain (aiohttp's FileResponse, whose stat, open
and reads also run in threads). Both must answer while the gate is still shut, and the level-0
request only after it opens: an order, not a timing. Where the file work shares the volume
work's threads (asyncio's default executor, as before serve_work.py), the file requests wait for
the gate; the test then fails after a generous bound (60 s) and opens the gate to end.

No plugin, no worker process and no real volume: the server's handlers, its start-up and its
static files are the real ones; the datasets and the operations are stand-ins.
"""
import asyncio
import gzip
import os
import socket
import sys
import tempfile
import threading

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import checks  # noqa: E402  (Testing/Python/checks.py)

try:
    import aiohttp
    from aiohttp import web
except ImportError:
    print("SKIP: python3-aiohttp is not installed (apt-get install python3-aiohttp)")
    sys.exit(125)
import numpy  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "Python"))
import serve  # noqa: E402

BOUND_S = 60  # only the failing case waits this long
DATASETS = 12  # 3 jobs each at the start: 36, more than any pool's threads (32 at most)
THREADS = min(32, (os.cpu_count() or 1) + 4)  # the default executor's, and serve_work's
TOKEN = "t-files-during-volume-work"
check = checks.Checks(verbose=True)


class Held:
    """Counts the volume jobs that started and holds each until the gate opens."""

    def __init__(self):
        self.gate = threading.Event()
        self.lock = threading.Lock()
        self.started = 0

    def __call__(self):
        with self.lock:
            self.started += 1
        self.gate.wait()


class HeldDataset:
    """What serve.py's handlers and start-up read of a dataset; its volume work waits on `held`."""

    def __init__(self, ident, held):
        self.ident, self.held = ident, held
        self.name, self.type, self.dims = ident + ".raw", "u1", (2, 2, 2)
        self.origin, self.digest, self.modified = (0.0, 0.0, 0.0), None, None

    def fingerprint(self):
        self.held()
        self.digest = "f" + self.ident
        return self.digest

    def encode(self, k):
        self.held()
        return gzip.compress(bytes(8), mtime=0)

    def level(self, k):
        self.held()
        return numpy.zeros((2, 2, 2), numpy.uint8)

    def etag(self, k):
        return '"%s-%d"' % (self.digest, k)

    def describe(self):
        return {"levels": [{"dims": [2, 2, 2], "spacing": [1.0, 1.0, 1.0], "bytes": 8}] * 4}


class NoOperations:
    """The operations' worker is not what this test is about."""

    async def run(self):
        pass

    async def close(self):
        pass


class Args:
    def __init__(self, wasm):
        self.token, self.wasm = TOKEN, wasm


async def until(test, what):
    """Waits (polling) for test() within BOUND_S; the check says whether it came."""
    for _ in range(BOUND_S * 20):
        if test():
            return check(True, what)
        await asyncio.sleep(0.05)
    return check(False, what + " (not within %d s)" % BOUND_S)


async def main(wasm):
    script = os.path.join(wasm, "mediso.js")
    with open(script, "w") as f:
        f.write("// the first version\n" * 200)
    held = Held()
    app = serve.make_app(Args(wasm), [HeldDataset("d%d" % i, held) for i in range(DATASETS)],
                         NoOperations())
    state = app[serve.STATE]
    runner = web.AppRunner(app, access_log=None)
    await runner.setup()  # the start-up: the files' gzips, then every dataset's volume work
    listener = socket.create_server(("127.0.0.1", 0))
    await web.SockSite(runner, listener).start()
    base = "http://127.0.0.1:%d" % listener.getsockname()[1]
    done = []  # the requests in the order they answered
    try:
        first = state.files.compressed[script][2]
        await until(first.done, "the start-up gzip'd the page's files (they were asked first)")
        await until(lambda: held.started >= THREADS,
                    "the start-up's volume work holds every one of the pool's %d threads" % THREADS)
        async with aiohttp.ClientSession() as http:
            async def get(name, path, headers=None):
                async with http.get(base + path, params={"token": TOKEN},
                                    headers=headers or {}) as r:
                    answer = (r.status, r.headers.get("Content-Encoding"), await r.read())
                done.append(name)
                return answer

            level0 = asyncio.ensure_future(get("level 0", "/api/volume/d0", {}))
            with open(script, "w") as f:
                f.write("// the second version, a new size\n" * 300)
            second = ("// the second version, a new size\n" * 300).encode()
            zipped = asyncio.ensure_future(get("gzip'd", "/static/mediso.js"))
            plain = asyncio.ensure_future(
                get("plain", "/static/mediso.js", {"Accept-Encoding": "identity"}))
            await until(lambda: zipped.done() and plain.done(),
                        "the page's file answered, gzip'd and plain, with the volume work held")
            check(not level0.done(), "the level-0 request still waits behind the held work")
            if zipped.done():
                status, encoding, body = zipped.result()
                check(status == 200 and encoding == "gzip" and body == second,
                      "gzip'd: 200, Content-Encoding gzip, the file's new version (%s, %s, %d "
                      "bytes of %d)" % (status, encoding, len(body), len(second)))
            if plain.done():
                status, encoding, body = plain.result()
                check(status == 200 and encoding is None and body == second,
                      "plain: 200, no Content-Encoding, the file's new version (%s, %s, %d bytes)"
                      % (status, encoding, len(body)))
            held.gate.set()
            await until(level0.done, "the level-0 request answered once the gate opened")
            if level0.done():
                check(level0.result()[0] == 200, "level 0: 200 (%s)" % level0.result()[0])
            check(done[-1:] == ["level 0"], "the order of the answers: %s" % done)
            for task in (zipped, plain):
                task.cancel()
    finally:
        held.gate.set()
        # The start-up's futures, retrieved, so that a failed one is said here, not at exit.
        pending = list(state.encoding.values()) + list(state.fingerprints.values())
        results = await asyncio.gather(*pending, return_exceptions=True)
        errors = [r for r in results if isinstance(r, BaseException)]
        check(not errors, "the held volume work ended without an error (%s)" % errors[:1])
        await runner.cleanup()


with tempfile.TemporaryDirectory(prefix="mediso-files-") as folder:
    asyncio.run(main(folder))
check.finish("TestWebServerFilesDuringVolumeWork: all checks passed")
