"""HTTP hygiene around the app, as plain ASGI middleware (no per-request task or body copy).

- ``SecurityHeaders``: CSP (a fresh nonce per response for the pages' inline scripts), nosniff,
  no framing, no referrer, on every response, errors included; and the server's time to the
  answer's first byte as ``Server-Timing: app``.
- ``HeadAsGet``: ``HEAD`` answers what ``GET`` would, without the body (RFC 9110 §9.3.2).
- ``OneValuePerKey``: an API query string that gives a key twice is refused with 422 naming the
  key, before any route reads it (a route's ``Query`` would take the last value silently).
- ``BodyLimit``: a body past the limit is refused with 413 as it streams in, whether it announced
  its length or came chunked; it is never read into memory whole.
- ``RequestDeadline``: a body must arrive whole within ``body_seconds`` of its headers (else 408,
  and the connection is closed); an answer sent before its request's body arrived whole closes
  the connection (so a body trickled to a route that ignores it holds nothing); request headers
  past ``max_header_bytes`` are a 431 on any server (app/server.py refuses them as they arrive
  under uvicorn, reading no further).
"""

from __future__ import annotations

import asyncio
import secrets
import time
from collections import Counter
from urllib.parse import parse_qsl

from starlette.datastructures import Headers, MutableHeaders
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from app.errors import error_body
from app.responses import ORJSONResponse

#: Everything the pages load comes from the app itself. Styles may be inline: MathJax's SVG
#: output, plotly and Swagger UI set style attributes and insert <style> elements.
_CSP = (
    "default-src 'self'; "
    "script-src 'self' 'nonce-{nonce}'; "
    "style-src 'self' 'unsafe-inline'; "
    "img-src 'self' data: blob:; "
    "font-src 'self' data:; "
    "connect-src 'self'; "
    "worker-src 'self' blob:; "
    "object-src 'none'; "
    "base-uri 'none'; "
    "form-action 'self'; "
    "frame-ancestors 'none'"
)


class SecurityHeaders:
    """Adds the security headers to every response; the CSP nonce is ``request.state.csp_nonce``,
    for templates to put on their inline ``<script>`` elements."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        nonce = secrets.token_urlsafe(16)
        scope.setdefault("state", {})["csp_nonce"] = nonce
        start = time.perf_counter()

        async def send_with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                headers = MutableHeaders(scope=message)
                # From the request's arrival to its answer's first byte: with a route's own parts
                # (app/derivations.py server_timing) it tells queueing in the server from the
                # network and the client, in devtools and in the load benchmark.
                headers.append(
                    "Server-Timing", f"app;dur={1e3 * (time.perf_counter() - start):.1f}"
                )
                headers.setdefault("Content-Security-Policy", _CSP.format(nonce=nonce))
                headers.setdefault("X-Content-Type-Options", "nosniff")
                headers.setdefault("X-Frame-Options", "DENY")
                headers.setdefault("Referrer-Policy", "no-referrer")
            await send(message)

        await self.app(scope, receive, send_with_headers)


class HeadAsGet:
    """Runs a ``HEAD`` request as ``GET`` and sends the headers only (Content-Length included)."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or scope["method"] != "HEAD":
            await self.app(scope, receive, send)
            return

        async def send_headers_only(message: Message) -> None:
            if message["type"] in ("http.response.body", "http.response.pathsend"):
                if message.get("more_body", False):
                    return
                message = {"type": "http.response.body", "body": b"", "more_body": False}
            await send(message)

        await self.app({**scope, "method": "GET"}, receive, send_headers_only)


class OneValuePerKey:
    """Refuses an ``/api/`` request whose query string gives a key more than once, with 422 in
    the one error shape naming each such key (hostile play-test: ``?format=csv&format=json``
    exported JSON where the GET exports refused it). The query is split as Starlette splits it
    for the routes (app/routes/export.py reads ``request.query_params``). Pages are left alone:
    their scripts read their own query, and an HTML page is no place for a JSON error."""

    def __init__(self, app: ASGIApp, prefix: str = "/api/") -> None:
        self.app = app
        self.prefix = prefix

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] == "http" and scope["path"].startswith(self.prefix):
            query = scope.get("query_string", b"").decode("latin-1")
            counts = Counter(key for key, _ in parse_qsl(query, keep_blank_values=True))
            twice = [(key, n) for key, n in counts.items() if n > 1]
            if twice:
                detail = [
                    {"field": k, "message": f"given {n} times: give it once"} for k, n in twice
                ]
                await ORJSONResponse({"detail": detail}, status_code=422)(scope, receive, send)
                return
        await self.app(scope, receive, send)


class BodyLimit:
    """Refuses a request body over ``max_bytes`` with 413 in the one error shape (field `body`).

    A declared Content-Length over the limit is refused before the app runs. A chunked body is
    counted as the app reads it; past the limit the app is told the client left and whatever it
    answers is dropped for the 413. The server discards the rest of the body as it arrives (never
    holding it), so a client still sending reads its 413 instead of a reset connection; the
    ``lagrange-lab serve`` protocol (app/server.py) closes the connection past a bounded drain.
    """

    def __init__(self, app: ASGIApp, max_bytes: int) -> None:
        self.app = app
        self.max_bytes = max_bytes
        self.detail = f"request body over {_size(max_bytes)}"

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        length = Headers(scope=scope).get("content-length", "")
        if length.isdigit() and int(length) > self.max_bytes:
            await self._refuse(scope, receive, send)
            return

        received = 0
        over = False
        started = False

        async def counted_receive() -> Message:
            nonlocal received, over
            if over:
                return {"type": "http.disconnect"}
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > self.max_bytes:
                    over = True
                    return {"type": "http.disconnect"}
            return message

        async def guarded_send(message: Message) -> None:
            nonlocal started
            if over:
                return  # the app's answer to a body it never got whole; the 413 replaces it
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, counted_receive, guarded_send)
        except Exception:
            if not over:
                raise
        if over and not started:
            await self._refuse(scope, receive, send)

    async def _refuse(self, scope: Scope, receive: Receive, send: Send) -> None:
        body = error_body("body", self.detail)
        await ORJSONResponse(body, status_code=413)(scope, receive, send)


def _size(n: int) -> str:
    return f"{n // (1024 * 1024)} MiB" if n % (1024 * 1024) == 0 else f"{n} bytes"


class RequestDeadline:
    """Bounds how long a request may take to arrive, whatever serves the app (issue 24: a body
    sent a byte at a time was held for ever; the server's deadline stopped at the headers).

    The body's clock starts when the app gets the request (its headers have arrived): each
    receive waits at most what is left of ``body_seconds``; past it the app is told the client
    left and the client is answered 408 in the one error shape, with ``Connection: close``. An
    answer started while the body is still on its way (a route that never reads it) also says
    ``Connection: close``, so the server closes the connection instead of waiting for the rest.
    """

    def __init__(self, app: ASGIApp, body_seconds: float, max_header_bytes: int) -> None:
        self.app = app
        self.body_seconds = body_seconds
        self.max_header_bytes = max_header_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        size = len(scope.get("raw_path") or b"") + len(scope.get("query_string", b""))
        size += sum(len(k) + len(v) + 4 for k, v in scope.get("headers", ()))
        if size > self.max_header_bytes:
            body = error_body("headers", f"request headers over {self.max_header_bytes} bytes")
            await ORJSONResponse(body, status_code=431, headers={"connection": "close"})(
                scope, receive, send
            )
            return
        headers = Headers(scope=scope)
        complete = headers.get("content-length", "0") in ("", "0") and (
            "transfer-encoding" not in headers
        )
        deadline = asyncio.get_running_loop().time() + self.body_seconds
        late = started = False

        async def timed_receive() -> Message:
            nonlocal complete, late
            if complete:
                return await receive()
            if late:
                return {"type": "http.disconnect"}
            left = deadline - asyncio.get_running_loop().time()
            try:
                message = await asyncio.wait_for(receive(), timeout=max(left, 0.0))
            except TimeoutError:
                late = True
                return {"type": "http.disconnect"}
            if message["type"] != "http.request" or not message.get("more_body", False):
                complete = True
            return message

        async def closing_send(message: Message) -> None:
            nonlocal started
            if late:
                return  # the app's answer to a body it never got whole; the 408 replaces it
            if message["type"] == "http.response.start":
                started = True
                if not complete:
                    MutableHeaders(scope=message)["connection"] = "close"
            await send(message)

        try:
            await self.app(scope, timed_receive, closing_send)
        except Exception:
            if not late:
                raise
        if late and not started:
            body = error_body(
                "body", f"the request body did not arrive within {self.body_seconds:g} s"
            )
            response = ORJSONResponse(body, status_code=408, headers={"connection": "close"})
            await response(scope, receive, send)
