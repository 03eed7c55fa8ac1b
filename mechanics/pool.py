"""A pool of warm worker processes for untrusted sympy work, under per-request time and memory caps.

Why processes: sympy on a student's answer or a posted spec can run for minutes; a thread cannot be
stopped, a process can, so a job past its deadline has its worker killed and replaced, and the
request gets ``BudgetExceeded("time")`` on time. Why warm: importing sympy and the engine costs a
second, and a worker keeps what it derived (mechanics/jobs.py), so the next request for the same
spec, sent to the same worker by a hash of its key (``affinity``), reuses it. Why a forkserver:
workers are forked from a clean single-threaded process that imported the engine once
(``preload``), never from the threaded server (a fork of which can deadlock) and never holding the
server's listening socket.

Admission is fair: a client (an address) has at most ``per_client`` jobs running; its further
requests wait behind its own while everyone else's go first, in arrival order. Fair over time too:
each job's CPU time is charged to its client (mechanics/fair_share.py), clients in debt wait
behind those with credit and may not take the last free worker. Time spent waiting counts against
a request's budget; one that cannot start within it is refused.

Nothing outlives the server: each worker watches a pipe whose only write end the server holds, and
exits when it reads EOF (the server closed the pool, exited or was killed with SIGKILL).

    >>> pool = WorkerPool(size=2, preload=()).start()
    >>> pool.run(pow, 2, 10, seconds=5)
    1024
    >>> pool.close()
"""

from __future__ import annotations

import ctypes
import logging
import multiprocessing
import os
import pickle
import signal
import sys
import threading
import time
import traceback
import zlib
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from multiprocessing.connection import Connection
from multiprocessing.process import BaseProcess
from typing import Any, TypeVar

from mechanics.budget import (
    DEFAULT_MEMORY_BYTES,
    BudgetExceeded,
    lift_memory_limit,
    limit_memory,
    portable,
    rebuild,
)
from mechanics.fair_share import LEDGER, CpuLedger, reserve_for

__all__ = ["WorkerPool", "WorkerLost"]

log = logging.getLogger(__name__)

T = TypeVar("T")

#: How long a closing pool waits for an idle worker to leave by itself before killing it.
_CLOSE_GRACE_SECONDS = 2.0


class WorkerLost(RuntimeError):
    """The worker running a job died without answering (killed from outside, a native crash), or
    the pool closed under it. The job may be retried; the server itself is fine."""


@dataclass
class _Slot:
    """One place in the pool and the worker currently in it."""

    index: int
    process: BaseProcess | None = None
    conn: Connection | None = None
    broken: bool = False  # its worker must be replaced before the slot is used again


class WorkerPool:
    """``size`` warm workers; ``run`` a picklable function in one of them under a budget."""

    def __init__(
        self,
        size: int = 2,
        per_client: int | None = None,
        memory_bytes: int = DEFAULT_MEMORY_BYTES,
        preload: Sequence[str] = ("mechanics.jobs",),
        ledger: CpuLedger | None = None,
    ) -> None:
        self.size = max(1, size)
        self.ledger = ledger or LEDGER
        self.reserve = reserve_for(self.size)
        self.per_client = max(1, per_client or self.size // 2)
        self.memory_bytes = memory_bytes
        self._preload = list(preload)
        self._ctx = multiprocessing.get_context("forkserver")
        self._slots = [_Slot(i) for i in range(self.size)]
        self._cond = threading.Condition()
        self._free: list[int] = []  # idle slots, least recently used first
        self._running: Counter[str] = Counter()  # jobs in workers, per client
        self._waiting: list[tuple[object, str]] = []  # (ticket, client), in arrival order
        self._closed = False
        # multiprocessing's bookkeeping of children is not thread-safe; routes run in a threadpool.
        self._processes = threading.Lock()
        self._lifeline: Connection | None = None  # the write end: never written, closed last
        self._lifeline_reader: Connection | None = None

    # --- life cycle -----------------------------------------------------------------------------

    def start(self) -> WorkerPool:
        """Start the forkserver (which imports ``preload`` once) and every worker; returns self."""
        if self._preload:
            self._ctx.set_forkserver_preload(self._preload)
        self._lifeline_reader, self._lifeline = self._ctx.Pipe(duplex=False)
        for slot in self._slots:
            self._spawn(slot)
        with self._cond:
            self._free = [slot.index for slot in self._slots]
            self._cond.notify_all()
        return self

    def close(self) -> None:
        """Stop every worker and reap it; requests still waiting get WorkerLost."""
        with self._cond:
            if self._closed:
                return
            self._closed = True
            self._free = []
            self._cond.notify_all()
        for slot in self._slots:
            if slot.conn is not None:
                slot.conn.close()  # an idle worker reads EOF and leaves
        deadline = time.monotonic() + _CLOSE_GRACE_SECONDS
        for slot in self._slots:
            self._reap(slot, patience=max(0.0, deadline - time.monotonic()))
        if self._lifeline is not None:
            self._lifeline.close()
            self._lifeline_reader.close()

    def pids(self) -> list[int]:
        """The workers' process ids (for tests and operators)."""
        return [s.process.pid for s in self._slots if s.process is not None and s.process.pid]

    # --- running a job --------------------------------------------------------------------------

    def run(
        self,
        fn: Callable[..., T],
        *args: Any,
        seconds: float,
        client: str = "",
        affinity: str | None = None,
        what: str = "the work",
        advice: str = "simplify it and try again",
        **kwargs: Any,
    ) -> T:
        """``fn(*args, **kwargs)`` in a worker, or raise.

        Raises BudgetExceeded("time") if it cannot start or finish within ``seconds`` (the
        worker is then killed and replaced), BudgetExceeded("size") if it runs out of its memory
        cap, WorkerLost if its worker died, and otherwise whatever ``fn`` raised, with its type
        and attributes. ``affinity`` (a spec's key) sends equal keys to the same worker when it is
        free; ``what`` names the work and ``advice`` says what to do past the time budget, in the
        messages a person reads ("deriving this scene took longer than 20 s; ...").
        """
        asked = time.monotonic()
        deadline = asked + seconds
        slot = self._admit(client, affinity, deadline, seconds)
        waited = time.monotonic() - asked
        if waited > seconds / 4:  # past the budget, the queue is the cause, not the work
            advice = (
                f"{waited:.1f} s of the {seconds:g} went waiting for a free worker (the server "
                "was busy): try again shortly"
            )
        try:
            job = (fn, args, kwargs)
            return self._execute(slot, job, deadline, seconds, what, advice, client)
        finally:
            self._release(slot, client)

    def _execute(
        self,
        slot: _Slot,
        job: tuple,
        deadline: float,
        seconds: float,
        what: str,
        advice: str,
        client: str = "",
    ) -> Any:
        payload = pickle.dumps((*job, self.memory_bytes), pickle.HIGHEST_PROTOCOL)
        started = time.monotonic()
        try:
            conn = self._deliver(slot, payload)
            answered = conn.poll(max(0.0, deadline - time.monotonic()))
            if not answered:
                slot.broken = True
                self.ledger.charge(client, time.monotonic() - started)  # killed: its wall time
                raise BudgetExceeded(
                    "time",
                    f"{what} took longer than {seconds:g} s; {advice}",
                )
            status, value, retire, cpu = pickle.loads(conn.recv_bytes())
        except (EOFError, OSError) as exc:
            slot.broken = True
            self.ledger.charge(client, time.monotonic() - started)
            raise WorkerLost(f"the process {what} stopped{self._exit_note(slot)}") from exc
        self.ledger.charge(client, cpu)
        slot.broken = retire
        if status == "ok":
            return value
        raise rebuild(value)

    def _deliver(self, slot: _Slot, payload: bytes) -> Connection:
        """Send a job to the slot's worker; one that died while idle (the job never reached it)
        is replaced and the job sent to its successor."""
        try:
            slot.conn.send_bytes(payload)
        except OSError:
            self._replace(slot)
            if slot.conn is None:
                raise
            slot.conn.send_bytes(payload)
        return slot.conn

    def _exit_note(self, slot: _Slot) -> str:
        if self._closed:
            return " (the server is shutting down)"
        with self._processes:
            slot.process.join(0.5)
            code = slot.process.exitcode
        if code is None:
            return ""
        return f" (killed by signal {-code})" if code < 0 else f" (exit code {code})"

    # --- admission ------------------------------------------------------------------------------

    def _admit(self, client: str, affinity: str | None, deadline: float, seconds: float) -> _Slot:
        ticket = object()
        with self._cond:
            self._waiting.append((ticket, client))
            try:
                while True:
                    if self._closed:
                        raise WorkerLost("the server is shutting down")
                    index = self._grant(ticket, affinity)
                    if index is not None:
                        self._free.remove(index)
                        self._running[client] += 1
                        return self._slots[index]
                    remaining = deadline - time.monotonic()
                    if remaining <= 0:
                        raise BudgetExceeded("time", self._busy_message(client, seconds))
                    # at least once a second: a client in debt earns credit back while it waits
                    self._cond.wait(min(remaining, 1.0))
            finally:
                self._waiting.remove((ticket, client))
                self._cond.notify_all()  # the tickets behind this one may be eligible now

    def _grant(self, ticket: object, affinity: str | None) -> int | None:
        """The slot this ticket gets now, or None: free slots go to waiting tickets in the
        ledger's order (clients with CPU credit first, in arrival order), skipping the tickets
        whose client already has ``per_client`` jobs running, and those of clients in debt when
        only the reserved slots are free."""
        free = len(self._free)
        running = Counter(self._running)
        for waiting, client in self.ledger.ordered(self._waiting, key=lambda w: w[1]):
            if free == 0:
                return None
            if running[client] >= self.per_client:
                continue
            if not self.ledger.may_take(client, free, self.reserve):
                continue
            if waiting is ticket:
                return self._choose(affinity)
            running[client] += 1
            free -= 1
        return None

    def _choose(self, affinity: str | None) -> int:
        if affinity is not None:
            preferred = zlib.crc32(affinity.encode()) % self.size
            if preferred in self._free:
                return preferred
        return self._free[0]

    def _busy_message(self, client: str, seconds: float) -> str:
        queued = sum(1 for _, c in self._waiting if c == client) - 1  # besides this one
        debt = self.ledger.describe(client)
        return busy_message(
            self._running[client],
            self.per_client,
            seconds,
            "request",
            "no worker was free",
            queued=max(0, queued),
            debt=debt,
        )

    def _release(self, slot: _Slot, client: str) -> None:
        if slot.broken and not self._closed:
            self._replace(slot)
        with self._cond:
            self._running[client] -= 1
            if self._running[client] <= 0:
                del self._running[client]
            if not self._closed and slot.process is not None:
                self._free.append(slot.index)
            self._cond.notify_all()

    # --- processes ------------------------------------------------------------------------------

    def _spawn(self, slot: _Slot) -> None:
        ours, theirs = self._ctx.Pipe(duplex=True)
        process = self._ctx.Process(
            target=_worker_main,
            args=(theirs, self._lifeline_reader),
            name=f"lagrange-lab-worker-{slot.index}",
            daemon=True,
        )
        with self._processes:
            process.start()
        theirs.close()
        slot.process, slot.conn, slot.broken = process, ours, False

    def _replace(self, slot: _Slot) -> None:
        """Kill the slot's worker (it may be mid-job), reap it, and start a fresh one."""
        self._reap(slot, patience=0.0)
        try:
            self._spawn(slot)
        except Exception:  # the slot stays empty: the pool runs one worker short
            log.exception("could not start a replacement worker")

    def _reap(self, slot: _Slot, patience: float) -> None:
        process, conn = slot.process, slot.conn
        slot.process, slot.conn = None, None
        if conn is not None:
            conn.close()
        if process is None:
            return
        with self._processes:
            process.join(patience)
            if process.is_alive():
                process.kill()
            process.join()
            process.close()


# --- inside a worker ----------------------------------------------------------------------------


def _worker_main(conn: Connection, lifeline: Connection) -> None:
    """Answer jobs until the server closes the connection (or dies)."""
    _exit_with_server(lifeline)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the server's: it closes the pool
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    while True:
        try:
            request = conn.recv_bytes()
        except (EOFError, OSError):
            return
        reply, retire = _answer(request)
        try:
            conn.send_bytes(reply)
        except OSError:
            return
        if retire:
            return


def _answer(request: bytes) -> tuple[bytes, bool]:
    """Run one job under its memory cap: the pickled ("ok"|"error", value, retire, CPU seconds)
    and retire.

    A worker that ran out of memory retires after answering: whatever it half-built is gone with
    it, and the pool starts a fresh one.
    """
    memory_bytes = DEFAULT_MEMORY_BYTES
    cpu = time.process_time()  # what the job cost, for its client's share (fair_share.py)
    try:
        fn, args, kwargs, memory_bytes = pickle.loads(request)
        limit_memory(memory_bytes)
        try:
            value = fn(*args, **kwargs)
            reply = ("ok", value, False, time.process_time() - cpu)
            return pickle.dumps(reply, pickle.HIGHEST_PROTOCOL), False
        finally:
            lift_memory_limit()
    except MemoryError:
        error = BudgetExceeded(
            "size",
            f"it needed more than {memory_bytes / 1024**3:g} GiB of memory; "
            "simplify it and try again",
        )
        return pickle.dumps(("error", portable(error), True, time.process_time() - cpu)), True
    except BaseException as exc:  # everything, even SystemExit, goes back to the server
        exc.add_note("in the worker process:\n" + traceback.format_exc())
        return pickle.dumps(("error", portable(exc), False, time.process_time() - cpu)), False


def _exit_with_server(lifeline: Connection) -> None:
    """Exit when the server is gone, however it went (close, exit, SIGKILL).

    The server holds the only write end of ``lifeline`` and never writes: a read returns only at
    EOF, when the server's process has ended. Linux also gets PR_SET_PDEATHSIG, for the case the
    forkserver (this process's parent) is killed.
    """

    def watch() -> None:
        try:
            lifeline.recv_bytes()
        except (EOFError, OSError):
            pass
        os._exit(1)

    threading.Thread(target=watch, name="lifeline", daemon=True).start()
    if sys.platform == "linux":
        try:
            pr_set_pdeathsig = 1
            ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, signal.SIGKILL)
        except (OSError, AttributeError):
            pass


def busy_message(
    mine: int,
    per_client: int,
    seconds: float,
    what: str,
    busy: str,
    queued: int = 0,
    debt: str = "",
) -> str:
    """Why a job could not start in time, in words that tell the client what to do: its own
    queue (wait for its answers) or the server's (try again shortly). ``queued`` counts the
    client's other jobs still waiting: ten sent at once read "1 running" while nine waited.
    ``debt`` says why a client past its share of CPU over time waits (fair_share.describe)."""
    if mine >= per_client:
        waiting = f" and {queued} more waiting" if queued else ""
        return (
            f"you already have {mine} {what}{'s' if mine > 1 else ''} running (a client gets "
            f"{per_client} at a time){waiting}, and this one could not start within "
            f"{seconds:g} s; wait for the answers, then try again"
        )
    if debt:  # CPU over time (mechanics/fair_share.py): the client's own use is the cause
        return f"this {what} could not start within {seconds:g} s: {debt}; try again in a minute"
    return f"the server is busy: {busy} within {seconds:g} s; try again shortly"
