"""What opening a share link costs the server: once per link, bounded by the link's size.

A link (``/s/{token}``, ``/api/v1/export/share/{token}``) carries a whole state, a posted spec
included, and opening it checks that the page it opens can run it (app/routes/export.py), which
for a posted spec derives and compiles it in the worker pool. Before this module each GET did
that again, under the 20 s budget of a posted scene: a 185-character link cost 20 s of a pool
worker per visit, four visitors made honest answer checks fail, and any page could send visitors
to it with an ``<img>`` (issue 24, item 5). Now:

- the outcome of opening a link (its state, or the 4xx that refuses it) is kept in memory,
  keyed by the link, for the `SIZE` most recently opened links; visitors who open a link while
  it is being checked wait for that one check;
- the check's time budget grows with the link's length (`link_seconds`): a few seconds for a
  short link, the posted scene's budget only for one as long as a large spec. A check that does
  not finish within it cannot decide; the link then opens unchecked (the page's own run says
  whether it runs, under the visitor's own budget), and that outcome is kept for
  `UNDECIDED_SECONDS`, so the work is not started again by every visit;
- the check runs in the pool under the visitor's address (app/derivations.py ``in_pool``), so
  the pool's per-client limit counts it against whoever opens the link.
"""

from __future__ import annotations

import asyncio
import time
from collections import OrderedDict
from collections.abc import Awaitable, Callable
from typing import Any

from fastapi import HTTPException

#: Links whose outcome is kept (a link is at most 12,000 characters: ~3 MB at most).
SIZE = 256
#: A check's budget: BASE_SECONDS plus a second per CHARS_PER_SECOND characters of the link.
BASE_SECONDS = 1.0
CHARS_PER_SECOND = 200
#: How long "could not decide in time" is kept before a visit tries the check again.
UNDECIDED_SECONDS = 600.0
#: Refusals that depend on the link alone, and are kept like its state.
_KEPT_STATUS = frozenset({404, 422})


def link_seconds(token: str, ceiling: float) -> float:
    """The time budget of checking a link of ``len(token)`` characters, at most ``ceiling``."""
    return min(ceiling, BASE_SECONDS + len(token) / CHARS_PER_SECOND)


class Undecided:
    """The outcome of a check that ran out of time: ``value`` is the state, unchecked."""

    def __init__(self, value: Any) -> None:
        self.value = value


class LinkMemo:
    """Outcomes of opening links, the most recent `SIZE`, and the checks running now (single
    flight: one check per link at a time, in this process)."""

    def __init__(self, size: int = SIZE) -> None:
        self.size = size
        self._done: OrderedDict[str, tuple[str, Any, float]] = OrderedDict()
        self._running: dict[str, asyncio.Future[tuple[str, Any, float]]] = {}
        self.computed = 0  # checks started, for tests and the benchmark

    async def get(self, token: str, compute: Callable[[], Awaitable[Any]]) -> Any:
        """The state of ``token``: kept, or awaited from the check running now, or ``compute()``
        (which returns the state, an `Undecided`, or raises the HTTPException that refuses it)."""
        kept = self._done.get(token)
        if kept is not None and kept[2] > time.monotonic():
            self._done.move_to_end(token)
            return _unpack(kept)
        running = self._running.get(token)
        if running is not None:
            return _unpack(await asyncio.shield(running))
        future: asyncio.Future[tuple[str, Any, float]] = asyncio.get_running_loop().create_future()
        self._running[token] = future
        self.computed += 1
        try:
            outcome = await self._outcome(compute)
        except BaseException as exc:  # a 503 (the pool busy) or a failure: not kept
            outcome = ("raise", exc, 0.0)
        finally:
            del self._running[token]
        future.set_result(outcome)
        if outcome[0] != "raise":
            self._done[token] = outcome
            self._done.move_to_end(token)
            while len(self._done) > self.size:
                self._done.popitem(last=False)
        return _unpack(outcome)

    @staticmethod
    async def _outcome(compute: Callable[[], Awaitable[Any]]) -> tuple[str, Any, float]:
        try:
            value = await compute()
        except HTTPException as exc:
            if exc.status_code not in _KEPT_STATUS:
                raise
            return "refused", exc, float("inf")
        if isinstance(value, Undecided):
            return "state", value.value, time.monotonic() + UNDECIDED_SECONDS
        return "state", value, float("inf")

    def clear(self) -> None:
        self._done.clear()


def _unpack(outcome: tuple[str, Any, float]) -> Any:
    kind, value, _ = outcome
    if kind == "refused":
        raise HTTPException(value.status_code, value.detail, headers=value.headers)
    if kind == "raise":
        raise value
    return value


#: This process's links.
memo = LinkMemo()
