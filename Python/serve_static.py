"""The page's own files, compressed on the wire (docs/web.md, "The page's start-up").

The page's scripts, style sheet and WebAssembly module are most of what a first visit moves before
its first image (2.4 MB as they are, 0.7 MB gzip'd: about 0.45 s of a 30 Mbit/s link). aiohttp's
static route sends a file as it is on disk unless a precompressed `.gz` lies beside it, and the
source tree and the build folder should hold no such copies; so each file is gzip'd here, once per
version (its modification time and size), and kept in memory.

    GET /static/<name>    a file of Web/static, or one of the WebAssembly build's (--wasm); only a
                          plain file directly in its folder, by name (no path is resolved)

A client that accepts gzip gets the compressed bytes (`Content-Encoding: gzip`, `Vary:
Accept-Encoding`) with the validators of that representation (`ETag` of the version and the
encoding, `Last-Modified`); `If-None-Match` or `If-Modified-Since` that match get 304. Others, and
files that gzip does not shrink (images), get aiohttp's FileResponse as before. No Cache-Control is
added: the browser keeps the files by their date as it did (the pthreads of the threaded module load
its script again, from that copy).
"""
import asyncio
import gzip
import mimetypes
import os
from email.utils import formatdate

from aiohttp import web

# Suffixes worth compressing: text and the WebAssembly module (which gzip shrinks about 3.5-fold).
COMPRESSIBLE = (".js", ".mjs", ".css", ".html", ".wasm", ".json", ".svg", ".txt")
LEVEL = 9  # once per file version; the bytes crossing a slow link matter more than the CPU here


class StaticFiles:
    """Named files of some folders, each gzip'd once per version.

    `folders`: [(folder, names)] looked up in order; names None: any plain file of the folder
    (not a dotfile), else only those names. `not_modified(request, etag, modified)`: serve.py's
    validator check (as for the volume). `missing(name)`: the 404's text for a listed name whose
    file is not there (the WebAssembly build not made yet)."""

    def __init__(self, folders, not_modified, missing=None):
        self.folders = folders
        self.not_modified = not_modified
        self.missing = missing
        self.compressed = {}  # path -> (mtime_ns, size, future of the gzip'd bytes)

    def find(self, name):
        """The path of file `name`, or raises 404."""
        if not name or name.startswith(".") or os.path.basename(name) != name or "\0" in name:
            raise web.HTTPNotFound()
        for folder, names in self.folders:
            if names is not None and name not in names:
                continue
            path = os.path.join(folder, name)
            if os.path.isfile(path):
                return path
            if names is not None:
                raise web.HTTPNotFound(text=self.missing(name) if self.missing else "")
        raise web.HTTPNotFound()

    def gzipped(self, path, stat):
        """A future of `path`'s gzip'd bytes at version `stat` (made once, off the event loop, on
        the default executor: the volume work has its own, serve_work.py)."""
        entry = self.compressed.get(path)
        if entry is None or entry[:2] != (stat.st_mtime_ns, stat.st_size):
            loop = asyncio.get_running_loop()
            entry = (stat.st_mtime_ns, stat.st_size, loop.run_in_executor(None, compress, path))
            self.compressed[path] = entry
        return entry[2]

    def warm(self):
        """Compresses every file now (the server's start), so that the first page waits for none."""
        for folder, names in self.folders:
            try:
                listed = names if names is not None else os.listdir(folder)
            except OSError:
                continue
            for name in listed:
                path = os.path.join(folder, name)
                if name.endswith(COMPRESSIBLE) and not name.startswith(".") and os.path.isfile(path):
                    self.gzipped(path, os.stat(path))

    async def handler(self, request):
        return await self.respond(request, self.find(request.match_info["name"]))

    async def respond(self, request, path):
        """File `path`, gzip'd where the client accepts it and gzip helps."""
        if not path.endswith(COMPRESSIBLE) or "gzip" not in request.headers.get("Accept-Encoding", ""):
            return web.FileResponse(path)
        stat = os.stat(path)
        body = await asyncio.shield(self.gzipped(path, stat))
        if body is None:  # the file went away while it was read
            raise web.HTTPNotFound()
        headers = {"ETag": '"%x-%x-gzip"' % (stat.st_mtime_ns, stat.st_size),
                   "Last-Modified": formatdate(stat.st_mtime, usegmt=True),
                   "Vary": "Accept-Encoding"}
        if self.not_modified(request, headers["ETag"], stat.st_mtime):
            return web.Response(status=304, headers=headers)
        kind = mimetypes.guess_type(path)[0] or "application/octet-stream"
        return web.Response(body=body, content_type=kind,
                            headers=dict(headers, **{"Content-Encoding": "gzip"}))


def compress(path):
    """`path`'s bytes gzip'd (mtime 0: the same bytes give the same stream), or None."""
    try:
        with open(path, "rb") as f:
            return gzip.compress(f.read(), LEVEL, mtime=0)
    except OSError:
        return None

