"""Answers to identical requests, computed once: a small in-memory LRU with single flight.

A lecture hall opens the same scene at the same moment: 200 identical `/simulate` requests for a
built-in scene at its default parameters. The run is deterministic (the same request gives the
same trajectory, tests/derivation/test_determinism.py), so the first one computes and the others
wait for it (single flight) or find it done; a slider moved to a value someone else already
tried is served the same way. Only encoded answers are kept, bounded by count and by bytes, in
this process.

What is kept is exactly what the first request was answered: its stats still say what that run
cost (steps, evaluations, wall time), which is what it costs to compute.
"""

from __future__ import annotations

import asyncio
import gzip
import threading
from collections import OrderedDict
from collections.abc import Awaitable, Callable

#: At most this many answers and this many bytes of them per server process.
MAX_ENTRIES = 256
MAX_BYTES = 64 * 1024 * 1024


class AnswerMemo:
    """Encoded answers by request key; concurrent identical requests share one computation."""

    def __init__(self, max_entries: int = MAX_ENTRIES, max_bytes: int = MAX_BYTES) -> None:
        self.max_entries, self.max_bytes = max_entries, max_bytes
        self._answers: OrderedDict[str, bytes] = OrderedDict()
        self._bytes = 0
        self._lock = threading.Lock()
        self._flights: dict[str, asyncio.Future[bytes]] = {}
        self._gzipped: dict[str, tuple[bytes, bytes]] = {}  # key: (answer, its gzip)
        self.hits = self.misses = 0

    def gzipped(self, key: str, body: bytes) -> bytes:
        """``body`` (the answer kept for ``key``) gzipped, once: an answer asked for again is
        likely asked for many times, and compressing 200 kB costs more than finding it."""
        with self._lock:
            source, done = self._gzipped.get(key, (None, b""))
        if source is body:  # the twin of this very answer, not of another kept under the key
            return done
        done = gzip.compress(body, 6, mtime=0)
        with self._lock:
            if self._answers.get(key) is body:  # only while this answer itself is kept
                self._drop_gzipped(key)
                self._gzipped[key] = (body, done)
                self._bytes += len(done)
        return done

    def get(self, key: str) -> bytes | None:
        with self._lock:
            body = self._answers.get(key)
            if body is not None:
                self._answers.move_to_end(key)
                self.hits += 1
            return body

    def put(self, key: str, body: bytes) -> None:
        if len(body) > self.max_bytes // 8:  # one huge answer must not flush everyone's
            return
        with self._lock:
            self._drop(key)
            self._answers[key] = body
            self._bytes += len(body)
            while len(self._answers) > self.max_entries or self._bytes > self.max_bytes:
                self._drop(next(iter(self._answers)))

    def _drop(self, key: str) -> None:
        """Forget ``key``'s answer and its gzipped twin (the lock is held)."""
        old = self._answers.pop(key, None)
        self._bytes -= len(old) if old is not None else 0
        self._drop_gzipped(key)

    def _drop_gzipped(self, key: str) -> None:
        _, old = self._gzipped.pop(key, (None, b""))
        self._bytes -= len(old)

    async def get_or_compute(
        self, key: str, compute: Callable[[], Awaitable[tuple[bytes, bool]]]
    ) -> bytes:
        """The kept answer, the one being computed for the same key, or a new computation.

        ``compute`` returns the answer and whether it may be kept and shared: a run cut short by
        its wall time on a busy server is that request's answer, not the scene's.

        An error is not kept nor shared: each waiter then computes (and fails or succeeds) on its
        own, so a 503 for one client (busy) never becomes everyone's answer.
        """
        body = self.get(key)
        if body is not None:
            return body
        flight = self._flights.get(key)
        if flight is not None:
            shared = await asyncio.shield(flight)
            return shared if shared is not None else (await compute())[0]
        self.misses += 1
        flight = asyncio.get_running_loop().create_future()
        self._flights[key] = flight
        shared = None
        try:
            body, keep = await compute()
            if keep:
                self.put(key, body)
                shared = body
            return body
        finally:
            self._flights.pop(key, None)
            flight.set_result(shared)  # None: failed or not to keep, each waiter computes its own
