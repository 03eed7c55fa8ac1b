"""uvicorn's HTTP protocol with a deadline for request headers.

uvicorn closes an idle kept-alive connection after ``timeout_keep_alive`` seconds, but a connection
that opens and never finishes its headers (sends nothing, or a byte now and then) stays open for
ever: a few hundred of them hold a worker's sockets and file descriptors. Here every request's
headers must arrive within ``header_timeout`` seconds of the connection opening or of the request's
first byte; past that the connection is closed.

A body the app refused unread (413, app/middleware.py) is discarded as it arrives, so the client
reads its answer; past ``DRAIN_BYTES`` of it the connection is closed instead of draining a
400 MB upload to its end.
"""

from __future__ import annotations

import asyncio
from typing import Any

from uvicorn.protocols.http.httptools_impl import HttpToolsProtocol

#: Seconds a client has to send a request's headers (slow mobile links need well under one).
HEADER_TIMEOUT = 10.0
#: Bytes of an unread request body discarded after the answer before the connection is closed.
DRAIN_BYTES = 8 * 1024 * 1024


class HeaderDeadlineProtocol(HttpToolsProtocol):
    """``HttpToolsProtocol`` that closes a connection whose request headers come too slowly.

    uvicorn builds one per connection; pass it as ``uvicorn.run(..., http=HeaderDeadlineProtocol)``
    or, for another deadline, ``functools.partial(HeaderDeadlineProtocol, header_timeout=s)``.
    """

    def __init__(self, *args: Any, header_timeout: float = HEADER_TIMEOUT, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.header_timeout = header_timeout
        self._header_deadline: asyncio.TimerHandle | None = None
        self._drained = 0

    def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
        super().connection_made(transport)
        self._arm_header_deadline()

    def on_message_begin(self) -> None:
        super().on_message_begin()
        self._drained = 0
        self._arm_header_deadline()  # the next request on a kept-alive connection

    def on_body(self, body: bytes) -> None:
        if self.cycle is not None and self.cycle.response_complete:
            self._drained += len(body)  # answered already: uvicorn discards it; bound how much
            if self._drained > DRAIN_BYTES and not self.transport.is_closing():
                self.transport.close()
            return
        super().on_body(body)

    def on_headers_complete(self) -> None:
        self._disarm_header_deadline()
        super().on_headers_complete()

    def connection_lost(self, exc: Exception | None) -> None:
        self._disarm_header_deadline()
        super().connection_lost(exc)

    def _arm_header_deadline(self) -> None:
        self._disarm_header_deadline()
        self._header_deadline = self.loop.call_later(self.header_timeout, self._headers_too_slow)

    def _disarm_header_deadline(self) -> None:
        if self._header_deadline is not None:
            self._header_deadline.cancel()
            self._header_deadline = None

    def _headers_too_slow(self) -> None:
        self._header_deadline = None
        if not self.transport.is_closing():
            self.transport.close()
