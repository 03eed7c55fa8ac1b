"""Connection limits in uvicorn's HTTP protocols, however the app is served.

uvicorn closes an idle kept-alive connection after ``timeout_keep_alive`` seconds, but before this
module nothing bounded a connection that opens and never finishes its request headers (a byte now
and then: slowloris), headers of any size (32 MiB were read whole; twenty such took a server to
1.09 GiB), or how many connections one client holds (a slowloris that reconnects every 10 s
defeats any per-connection deadline). Here, per connection:

- its request headers must arrive within ``header_seconds`` of the connection opening or of the
  request's first byte; past that the connection is closed;
- they may be at most ``max_header_bytes``; past that it is answered 431 and closed, having held
  no more than that;
- a client (a peer address) may hold at most ``client_connections`` connections to this server
  process; a further one is answered 429 and closed. Behind a trusted proxy
  (``LAGRANGE_LAB_TRUST_FORWARDED=1``) every connection comes from the proxy, so this limit is
  the proxy's to set (docs/deploy.md).

`install_connection_guard` puts this into uvicorn's own protocol classes (httptools and h11), so
it holds for ``lagrange-lab serve``, ``python -m uvicorn app.main:app`` and gunicorn's
``uvicorn.workers.UvicornWorker`` alike: importing ``app.main`` installs it, and uvicorn builds
every connection's protocol after importing the app. The body's own deadline is the app's
(app/middleware.py ``RequestDeadline``: 408).

A body the app refused unread (413, app/middleware.py) is discarded as it arrives, so the client
reads its answer; past ``DRAIN_BYTES`` of it the connection is closed instead of draining a
400 MB upload to its end (`HeaderDeadlineProtocol`, the protocol of ``lagrange-lab serve``).
"""

from __future__ import annotations

import asyncio
import functools
import json
from collections import Counter
from typing import Any

from uvicorn.protocols.http.httptools_impl import HttpToolsProtocol

from app.errors import error_body
from app.settings import settings

#: Seconds a client has to send a request's headers (slow mobile links need well under one).
HEADER_TIMEOUT = settings.header_seconds
#: Bytes of an unread request body discarded after the answer before the connection is closed.
DRAIN_BYTES = 8 * 1024 * 1024

#: Open connections per client address in this process (the event loop's thread only).
_open: Counter[str] = Counter()


class _Guard:
    """One connection's limits, driven by its protocol's data_received and connection_lost."""

    def __init__(self, protocol: Any, transport: asyncio.Transport) -> None:
        self.protocol = protocol
        self.transport = transport
        self.loop = asyncio.get_running_loop()
        peer = transport.get_extra_info("peername")
        self.client = str(peer[0]) if isinstance(peer, tuple) and peer else ""
        self.seconds = float(getattr(protocol, "header_timeout", None) or settings.header_seconds)
        self.max_bytes = settings.max_header_bytes
        self.counted = not settings.trust_forwarded
        self.pending = False  # waiting for a request's headers
        self.header_bytes = 0
        self.tail = b""
        self.cycle: Any = None  # the protocol's request cycle when headers last completed
        self.deadline: asyncio.TimerHandle | None = None
        if self.counted:
            _open[self.client] += 1
            if _open[self.client] > settings.client_connections:
                self.refuse(
                    429,
                    "Too Many Requests",
                    "connection",
                    f"more than {settings.client_connections} connections from one client",
                )
                return
        self.begin_headers()

    def begin_headers(self) -> None:
        self.pending, self.header_bytes, self.tail = True, 0, b""
        self.cancel_deadline()
        self.deadline = self.loop.call_later(self.seconds, self.too_slow)

    def cancel_deadline(self) -> None:
        if self.deadline is not None:
            self.deadline.cancel()
            self.deadline = None

    def before(self, data: bytes) -> bool:
        """Whether the protocol may read ``data``: False once the connection is refused."""
        if self.transport.is_closing():
            return False
        cycle = getattr(self.protocol, "cycle", None)
        if not self.pending and cycle is not None and cycle.response_complete:
            if not cycle.more_body:
                self.begin_headers()  # the first byte of the next request on this connection
        if self.pending:
            seen = self.tail + data
            end = seen.find(b"\r\n\r\n")
            self.header_bytes += len(data) if end < 0 else end + 4 - len(self.tail)
            self.tail = seen[-3:]
            if self.header_bytes > self.max_bytes:
                self.refuse(
                    431,
                    "Request Header Fields Too Large",
                    "headers",
                    f"request headers over {self.max_bytes} bytes",
                )
                return False
        return True

    def after(self) -> None:
        cycle = getattr(self.protocol, "cycle", None)
        if self.pending and cycle is not None and cycle is not self.cycle:
            self.cycle = cycle
            self.pending = False
            self.cancel_deadline()

    def too_slow(self) -> None:
        self.deadline = None
        if self.pending and not self.transport.is_closing():
            self.transport.close()

    def refuse(self, status: int, reason: str, field: str, message: str) -> None:
        """Answer ``status`` in the one error shape and close, whatever the request was."""
        body = json.dumps(error_body(field, message)).encode()
        head = (
            f"HTTP/1.1 {status} {reason}\r\ncontent-type: application/json\r\n"
            f"content-length: {len(body)}\r\nconnection: close\r\n\r\n"
        )
        self.pending = False
        self.cancel_deadline()
        if not self.transport.is_closing():
            self.transport.write(head.encode() + body)
            self.transport.close()

    def lost(self) -> None:
        self.cancel_deadline()
        if self.counted:
            _open[self.client] -= 1
            if _open[self.client] <= 0:
                del _open[self.client]
            self.counted = False


def _guarded(cls: type) -> None:
    """Wrap ``cls``'s connection_made, data_received and connection_lost with a `_Guard`."""
    if cls.__dict__.get("_lagrange_lab_guarded"):
        return
    made, received, lost = cls.connection_made, cls.data_received, cls.connection_lost

    @functools.wraps(made)
    def connection_made(self: Any, transport: asyncio.Transport, *args: Any) -> None:
        made(self, transport, *args)
        self._lagrange_lab_guard = _Guard(self, transport)

    @functools.wraps(received)
    def data_received(self: Any, data: bytes) -> None:
        guard = getattr(self, "_lagrange_lab_guard", None)
        if guard is None:
            received(self, data)
        elif guard.before(data):
            received(self, data)
            guard.after()

    @functools.wraps(lost)
    def connection_lost(self: Any, exc: Exception | None) -> None:
        guard = getattr(self, "_lagrange_lab_guard", None)
        if guard is not None:
            guard.lost()
        lost(self, exc)

    def send_400_response(self: Any, msg: str) -> None:
        """uvicorn's own answer to a request it cannot parse (a negative or huge Content-Length,
        two of them, a NUL in a header) was plain text: it is the one error shape too."""
        guard = getattr(self, "_lagrange_lab_guard", None) or _Guard(self, self.transport)
        guard.refuse(400, "Bad Request", "request", f"malformed HTTP request ({msg.rstrip('.')})")

    cls.connection_made = connection_made
    cls.data_received = data_received
    cls.connection_lost = connection_lost
    if hasattr(cls, "send_400_response"):
        cls.send_400_response = send_400_response
    cls._lagrange_lab_guarded = True


def install_connection_guard() -> None:
    """Guard every uvicorn HTTP/1.1 protocol class that is installed (idempotent)."""
    _guarded(HttpToolsProtocol)
    try:
        from uvicorn.protocols.http.h11_impl import H11Protocol
    except ImportError:  # h11 is uvicorn's own dependency; nothing to guard without it
        return
    _guarded(H11Protocol)


class HeaderDeadlineProtocol(HttpToolsProtocol):
    """``HttpToolsProtocol`` (guarded: `install_connection_guard`) with its own header deadline
    and a bounded drain of an unread body.

    uvicorn builds one per connection; pass it as ``uvicorn.run(..., http=HeaderDeadlineProtocol)``
    or, for another deadline, ``functools.partial(HeaderDeadlineProtocol, header_timeout=s)``.
    """

    def __init__(self, *args: Any, header_timeout: float = HEADER_TIMEOUT, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.header_timeout = header_timeout
        self._drained = 0

    def on_message_begin(self) -> None:
        super().on_message_begin()
        self._drained = 0

    def on_body(self, body: bytes) -> None:
        if self.cycle is not None and self.cycle.response_complete:
            self._drained += len(body)  # answered already: uvicorn discards it; bound how much
            if self._drained > DRAIN_BYTES and not self.transport.is_closing():
                self.transport.close()
            return
        super().on_body(body)


install_connection_guard()
