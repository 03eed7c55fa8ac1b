"""Each client's share of the CPU over time: a token bucket of CPU-seconds per client.

Why: counting only the jobs a client has running at once (one each) is fair to a class that asks
for milliseconds of work and a poster that asks for 20 s of sympy again and again only while both
are waiting; the poster's next job starts as soon as its last ends, so four posters keep every
worker busy and a student's answer check waits behind 20 s jobs past its 5 s budget (issue 24).
A bucket remembers: every client starts with ``capacity`` CPU-seconds, earns ``rate`` a second
back (up to the capacity), and pays what its jobs cost. Waiting work is then ordered by standing
(clients with credit first, in arrival order; then those in debt, the smallest debt first), and a
client in debt may not take the last ``reserve`` free places, so work that keeps within its share
always finds a place within the time its neighbours' short jobs take.

One ledger per server process (`LEDGER`), shared by the pool (mechanics/pool.py) and the gate of
in-process runs (app/derivations.py). Thread-safe.

    >>> ledger = CpuLedger(capacity=2.0, rate=0.5, clock=lambda: 0.0)
    >>> ledger.charge("poster", 10.0)
    >>> ledger.in_debt("poster"), ledger.in_debt("student")
    (True, False)
    >>> [c for c in ledger.ordered(["poster", "student"])]
    ['student', 'poster']
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable
from typing import TypeVar

__all__ = ["CpuLedger", "LEDGER", "reserve_for", "thread_cpu"]

T = TypeVar("T")

#: CPU-seconds a client may spend at once before its work yields to others': a student's whole
#: visit (derive, a dozen runs and checks) costs well under a second; a posted scene's derivation
#: may cost this much.
DEFAULT_CAPACITY = 10.0
#: CPU-seconds a client earns back per second: a quarter of a core, so a client in debt by one
#: 20 s derivation is back in credit within about a minute.
DEFAULT_RATE = 0.25
#: Clients not seen for this long are forgotten (their bucket would be full again anyway).
FORGET_AFTER = 600.0


class CpuLedger:
    """Token buckets of CPU-seconds, one per client (see the module's docstring)."""

    def __init__(
        self,
        capacity: float = DEFAULT_CAPACITY,
        rate: float = DEFAULT_RATE,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.capacity, self.rate, self.clock = capacity, rate, clock
        self._lock = threading.Lock()
        self._buckets: dict[str, tuple[float, float]] = {}  # client -> (balance, as of when)
        self._swept = clock()

    def _balance(self, client: str, now: float) -> float:
        balance, when = self._buckets.get(client, (self.capacity, now))
        return min(self.capacity, balance + self.rate * max(0.0, now - when))

    def balance(self, client: str) -> float:
        """The client's CPU-seconds of credit now (negative: in debt)."""
        with self._lock:
            return self._balance(client, self.clock())

    def in_debt(self, client: str) -> bool:
        """Has the client used more than its share lately?"""
        return self.balance(client) < 0

    def charge(self, client: str, seconds: float) -> None:
        """The client's job cost ``seconds`` of CPU (of wall time, for a job killed at its cap)."""
        if not seconds > 0:
            return
        with self._lock:
            now = self.clock()
            self._buckets[client] = (self._balance(client, now) - seconds, now)
            if now - self._swept > FORGET_AFTER:
                self._sweep(now)

    def _sweep(self, now: float) -> None:
        """Forget the clients whose bucket has refilled (under the lock)."""
        self._swept = now
        for client in [c for c in self._buckets if self._balance(c, now) >= self.capacity]:
            del self._buckets[client]

    def ordered(self, clients: Iterable[T], key: Callable[[T], str] | None = None) -> list[T]:
        """The waiting items in the order they should get a place: clients with credit in
        arrival order, then the ones in debt, the smallest debt first (a stable sort)."""
        items = list(clients)
        with self._lock:
            now = self.clock()
            standing = [self._balance(key(i) if key else str(i), now) for i in items]
        order = sorted(
            range(len(items)),
            key=lambda k: (0, 0.0, k) if standing[k] >= 0 else (1, -standing[k], k),
        )
        return [items[k] for k in order]

    def may_take(self, client: str, free: int, reserve: int) -> bool:
        """May this client take one of ``free`` places? Not the last ``reserve`` ones while it
        is in debt: they are kept for work within its share."""
        return free > reserve or not self.in_debt(client)

    def describe(self, client: str) -> str:
        """Why the client's work waits behind others', in words; "" when it does not."""
        balance = self.balance(client)
        if balance >= 0:
            return ""
        return (
            f"your recent requests used {self.capacity - balance:.0f} s of CPU, past this "
            f"server's share of {self.capacity:g} s plus {self.rate:g} s a second, so others' "
            "work goes first until it is earned back"
        )


def reserve_for(places: int) -> int:
    """Places kept for clients within their share: one, where there are at least two."""
    return 1 if places >= 2 else 0


def thread_cpu(fn: Callable[[], T], client: str, ledger: CpuLedger | None = None) -> T:
    """``fn()`` in this thread, its CPU time charged to ``client`` (even when it raises)."""
    start = time.thread_time()
    try:
        return fn()
    finally:
        (ledger or LEDGER).charge(client, time.thread_time() - start)


#: This server process's ledger.
LEDGER = CpuLedger()
