"""pvpython test: the web server's token, its refusal of paths, and its validation of messages.

Python/serve.py on the phantom (docs/web.md): every request and WebSocket without the token gets
403, with a wrong one too; ?token= sets an HttpOnly, SameSite=Strict cookie that then suffices;
datasets, static files and results are named, never reached by a path (../, %2e%2e, absolute
paths, the data file's own path); a WebSocket from another origin is refused; every bad message
(not JSON, not an object, a non-finite or out-of-range isovalue, unknown operations, steps and
fields, wrong types and ranges, a binary frame, a 100 KB message, deep nesting) gets an error
naming the fault on the same socket, which stays usable; a 2 MB frame closes that socket with
1009; and after all of it the server still serves and runs an operation. The token begins with
'-' (the harness gives it as --token=VALUE).
"""
import asyncio
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import webserver  # noqa: E402  (skips when aiohttp or the plugin is missing)
import aiohttp  # noqa: E402

checks = webserver.Checks()
# A token that begins with '-' (as one random token in 64 does) works: the harness passes it as
# --token=VALUE.
server = webserver.Server(["phantom:48"], token="-" + webserver.secrets.token_urlsafe(12))
checks(server.token.startswith("-"), "the server runs with a token that begins with '-'")
SECRET_FILE = os.path.abspath(webserver.SERVE)


async def status_of(http, path, token=True, **kwargs):
    async with http.get(server.url(path, token), allow_redirects=False, **kwargs) as r:
        return r.status, await r.read(), r


async def tokens(http):
    for path in ("/", "/static/app.js", "/static/mediso.js", "/api/datasets", "/api/volume/d0",
                 "/api/result/r0?format=stl", "/api/status", "/api/ws"):
        code, _, _ = await status_of(http, path, token=None)
        checks(code == 403, "%s without the token: %d" % (path, code))
        code, _, _ = await status_of(http, path, token="wrong" + server.token)
        checks(code == 403, "%s with a wrong token: %d" % (path, code))
    code, _, _ = await status_of(http, "/api/datasets", token="")
    checks(code == 403, "an empty token: %d" % code)
    try:
        async with http.ws_connect(server.ws_url(token=None)):
            checks(False, "a WebSocket without the token opens")
    except aiohttp.WSServerHandshakeError as e:
        checks(e.status == 403, "a WebSocket without the token: %d" % e.status)

    # The query token sets the cookie; the cookie alone then works (requests and WebSocket).
    # (unsafe=True: aiohttp's cookie jar otherwise keeps no cookie of an IP address)
    async with aiohttp.ClientSession(cookie_jar=aiohttp.CookieJar(unsafe=True)) as fresh:
        async with fresh.get(server.url("/api/datasets")) as r:
            cookie = r.headers.get("Set-Cookie", "")
            checks(r.status == 200 and "mediso_token=" + server.token in cookie,
                   "?token= answers 200 and sets the cookie (%s)" % cookie.split(";")[0][:30])
            checks("HttpOnly" in cookie and "SameSite=Strict" in cookie,
                   "the cookie is HttpOnly and SameSite=Strict")
        code, _, _ = await status_of(fresh, "/api/datasets", token=None)
        checks(code == 200, "the cookie alone: %d" % code)
        async with fresh.ws_connect(server.ws_url(token=None)) as ws:
            await ws.send_str("{}")
            answer = json.loads((await ws.receive(timeout=30)).data)
            checks("error" in answer, "a WebSocket on the cookie alone opens and answers")
    async with aiohttp.ClientSession(cookies={"mediso_token": "x" + server.token}) as wrong:
        code, _, _ = await status_of(wrong, "/api/datasets", token=None)
        checks(code == 403, "a wrong cookie: %d" % code)

    # A page of another origin cannot open the WebSocket, even with the token.
    try:
        async with http.ws_connect(server.ws_url(), headers={"Origin": "http://evil.example"}):
            checks(False, "a WebSocket from another origin opens")
    except aiohttp.WSServerHandshakeError as e:
        checks(e.status == 403, "a WebSocket from another origin: %d" % e.status)
    async with http.ws_connect(server.ws_url(), headers={"Origin": server.base}) as ws:
        checks(not ws.closed, "a WebSocket from the page's own origin opens")


async def raw_get(path):
    """The request line exactly as given (an HTTP client would resolve the dot segments)."""
    reader, writer = await asyncio.open_connection("127.0.0.1", server.port)
    writer.write(("GET %s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nConnection: close\r\n\r\n"
                  % (server.url(path), server.port)).replace(server.base, "").encode())
    await writer.drain()
    response = await reader.read()
    writer.close()
    head, _, body = response.partition(b"\r\n\r\n")
    return int(head.split()[1]), body


async def paths(http):
    secret = open(SECRET_FILE, "rb").read(200)
    for path in ("/static/../Python/serve.py", "/static/..%2fPython%2fserve.py",
                 "/static/%2e%2e%2f%2e%2e%2fetc%2fpasswd", "/static/..%2F..%2F..%2Fetc%2Fpasswd",
                 "/static/" + SECRET_FILE.replace("/", "%2f"), "/static/index.html%00.js",
                 "/static/serve.py", "/static/.", "/static/..",
                 "/api/volume/..%2f..%2fetc%2fpasswd", "/api/volume/%2fetc%2fpasswd",
                 "/api/volume/" + SECRET_FILE.replace("/", "%2f"),
                 "/api/volume/d0%2f..%2f..%2fPython%2fserve.py",
                 "/api/result/..%2f..%2fetc%2fpasswd?format=stl",
                 "/api/result/r0?format=..%2f..%2fetc%2fpasswd",
                 "/api/result/%2fetc%2fpasswd?format=stl", "/../../etc/passwd",
                 "/Python/serve.py", "/api/../Python/serve.py"):
        code, body = await raw_get(path)
        leaked = secret[:60] in body or b"root:" in body
        checks(code in (400, 403, 404) and not leaked,
               "%s: %d, nothing of a file outside the page" % (path, code))
    code, body, _ = await status_of(http, "/api/volume/d0?level=7")
    checks(code == 400, "level 7: %d %s" % (code, body.decode().strip()))
    code, body, _ = await status_of(http, "/api/volume/d0?level=three")
    checks(code == 400, "level three: %d" % code)
    code, body, _ = await status_of(http, "/api/result/r0?format=obj")
    checks(code == 400, "a result format the server does not write: %d" % code)
    code, _, _ = await status_of(http, "/static/index.html")
    checks(code == 200, "the page's own files are served: %d" % code)
    # Every file of the page is cross-origin isolated (the page's threads need it), cacheable by
    # date, and of its type: the scripts as JavaScript (ES modules run only then).
    for path, kind in (("/", "text/html"), ("/static/index.html", "text/html"),
                       ("/static/app.js", "text/javascript"), ("/static/style.css", "text/css"),
                       ("/static/mediso.js", "text/javascript"),
                       ("/static/mediso.wasm", "application/wasm")):
        code, _, r = await status_of(http, path)
        checks(code == 200 and r.content_type == kind and
               r.headers.get("Cross-Origin-Opener-Policy") == "same-origin" and
               r.headers.get("Cross-Origin-Embedder-Policy") == "require-corp" and
               "Last-Modified" in r.headers,
               "%s: %d %s, isolated (COOP %s, COEP %s), Last-Modified %s"
               % (path, code, r.content_type, r.headers.get("Cross-Origin-Opener-Policy"),
                  r.headers.get("Cross-Origin-Embedder-Policy"), r.headers.get("Last-Modified")))


BAD = [
    # (message text, words the error must hold)
    ('{"op":"surface","id":1,"dataset":"d0","isovalue":NaN,"level":3}', "isovalue: not a finite"),
    ('{"op":"surface","id":1,"dataset":"d0","isovalue":Infinity,"level":3}', "not a finite"),
    ('{"op":"surface","id":1,"dataset":"d0","isovalue":-1e999,"level":3}', "not a finite"),
    ('{"op":"surface","id":1,"dataset":"d0","isovalue":"400","level":3}', "isovalue: not a number"),
    ('{"op":"surface","id":1,"dataset":"d0","isovalue":null,"level":3}', "isovalue: not a number"),
    ('{"op":"surface","id":1,"dataset":"d0","isovalue":1e9,"level":3}', "outside the data range"),
    ('{"op":"surface","id":1,"dataset":"d0","isovalue":400}', "level is missing"),
    ('{"op":"surface","id":1,"dataset":"d0","isovalue":400,"level":4}', "level: 4 is outside"),
    ('{"op":"surface","id":1,"dataset":"d0","isovalue":400,"level":"3"}', "level: not an integer"),
    ('{"op":"surface","id":1,"dataset":"d0","isovalue":400,"level":2.5}', "level: not an integer"),
    ('{"op":"surface","id":1,"dataset":"../../etc/passwd","isovalue":400,"level":3}',
     "dataset: no dataset"),
    ('{"op":"surface","id":1,"dataset":"/etc/passwd","isovalue":400,"level":3}', "no dataset"),
    ('{"op":"surface","id":1,"dataset":%s,"isovalue":400,"level":3}' % json.dumps(SECRET_FILE),
     "no dataset"),
    ('{"op":"surface","id":1,"dataset":["d0"],"isovalue":400,"level":3}', "no dataset"),
    ('{"op":"surface","id":1,"dataset":"d0","isovalue":400,"level":3,"path":"/etc"}',
     "unknown field 'path'"),
    ('{"op":"render","id":1}', "op: unknown operation 'render'"),
    ('{"id":1}', "op: unknown operation"),
    ('{"op":"surface","dataset":"d0","isovalue":400,"level":3}', "id: an integer"),
    ('{"op":"surface","id":true,"dataset":"d0","isovalue":400,"level":3}', "id: an integer"),
    ('{"op":"surface","id":"7","dataset":"d0","isovalue":400,"level":3}', "id: an integer"),
    ('{"op":"surface","id":1e300,"dataset":"d0","isovalue":400,"level":3}', "id: an integer"),
    ('{"op":"cancel","id":99}', "no operation 99"),
    ('{"op":"cancel","id":99,"dataset":"d0"}', "unknown field"),
    ('[1, 2]', "a JSON object"),
    ('"surface"', "a JSON object"),
    ('{"op": "surface", "id": 1', "not JSON"),
    ('', "not JSON"),
    ('[' * 20000 + ']' * 20000, "not JSON"),
]
STEP_BAD = [
    ({"smooth": {"iterations": 0}}, "iterations: 0 is outside 1-500"),
    ({"smooth": {"iterations": 501}}, "iterations: 501 is outside"),
    ({"smooth": {"iterations": 1.5}}, "iterations: not an integer"),
    ({"smooth": {"iterations": 10, "relaxation": 2}}, "relaxation: 2 is outside 0-1"),
    ({"smooth": {"iterations": 10, "relaxation": float("nan")}}, "relaxation: not a finite"),
    ({"smooth": {}}, "iterations is missing"),
    ({"fillHoles": {"size": 0}}, "size: 0 is not above 0"),
    ({"fillHoles": {"size": -5}}, "size: -5 is not above 0"),
    ({"fillHoles": {"size": "big"}}, "size: not a number"),
    ({"clip": {"origin": [0, 0, 0], "normal": [0, 0, 0]}}, "normal: the zero vector"),
    ({"clip": {"origin": [0, float("inf"), 0], "normal": [0, 1, 0]}}, "origin: not a finite"),
    ({"clip": {"origin": [0, 0], "normal": [0, 1, 0]}}, "origin: three numbers"),
    ({"decimate": {"reduction": 1.0}}, "reduction: 1 is outside 0-0.99"),
    ({"decimate": {"reduction": 0.5, "method": "x"}}, "unknown field 'method'"),
    ({"explode": {}}, "unknown operation 'explode'"),
    ({"smooth": {"iterations": 5}, "decimate": {"reduction": 0.5}}, "one operation"),
    ("smooth", "one operation"),
]


async def messages(http):
    async with http.ws_connect(server.ws_url(), max_msg_size=0) as ws:
        async def ask(text):
            await ws.send_str(text)
            msg = await ws.receive(timeout=60)
            return json.loads(msg.data) if msg.type == aiohttp.WSMsgType.TEXT else {}

        for text, words in BAD:
            answer = await ask(text)
            checks(words in answer.get("error", ""),
                   "%s -> %s" % (text[:70], answer.get("error", answer)))
        for step, words in STEP_BAD:
            request = webserver.surface_request(5, "d0", 400, 3, [step])
            answer = await ask(json.dumps(request))
            checks(answer.get("id") == 5 and words in answer.get("error", ""),
                   "steps %s -> %s" % (json.dumps(step)[:60], answer.get("error", answer)))
        request = webserver.surface_request(6, "d0", 400, 3, [{"smooth": {"iterations": 1}}] * 9)
        answer = await ask(json.dumps(request))
        checks("steps: a list of at most 8" in answer.get("error", ""), "nine steps -> %s" % answer)
        await ws.send_bytes(b"\x00\x01")
        answer = json.loads((await ws.receive(timeout=60)).data)
        checks("binary frames are not accepted" in answer.get("error", ""),
               "a binary frame -> %s" % answer)
        big = json.dumps({"op": "surface", "id": 8, "pad": "x" * 100000})
        answer = await ask(big)
        checks("message too long: 100" in answer.get("error", "") and "at most 65536" in
               answer.get("error", ""), "a 100 KB message -> %s" % answer)
        # The socket is still usable after all of it: a real operation runs.
        progress, answer = await webserver.operation(
            ws, webserver.surface_request(9, "d0", 400, 1))
        checks(answer.get("done") is True and answer.get("triangles", 0) > 0,
               "the same socket then runs an operation: %s triangles" % answer.get("triangles"))

    # A 2 MB frame: the server closes that socket (1009: too big) and serves the others.
    async with http.ws_connect(server.ws_url(), max_msg_size=0) as ws:
        await ws.send_str("x" * (2 * 1024 * 1024))
        msg = await ws.receive(timeout=60)
        checks(msg.type in (aiohttp.WSMsgType.CLOSE, aiohttp.WSMsgType.CLOSED) and
               ws.close_code == 1009, "a 2 MB frame closes its socket with 1009 (%s, %s)"
               % (msg.type.name, ws.close_code))


async def main():
    async with aiohttp.ClientSession() as http:
        await tokens(http)
        await paths(http)
        await messages(http)
        checks(server.alive(), "the server is still running")
        code, body, _ = await status_of(http, "/api/datasets")
        checks(code == 200 and json.loads(body)["datasets"][0]["id"] == "d0",
               "and still serves /api/datasets (%d)" % code)
        code, body, _ = await status_of(http, "/api/status")
        status = json.loads(body)
        checks(status["worker"]["restarts"] == 0 and status["running"] is False,
               "its worker never restarted, nothing is left running (%s)" % status)


asyncio.run(main())
checks.finish(server)
