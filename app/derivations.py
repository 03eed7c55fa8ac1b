"""The web layer's ways into the engine: built-in derivations from memory, the rest in the pool.

A built-in scene is trusted and the same for everyone: its derivation is serialised once per process
and then served from a dict, so a warm request costs a lookup. Everything that runs sympy on user
input (a posted spec, a student's answer, equilibria and Newton's method of any scene) is a job for
the pool of warm worker processes (mechanics/pool.py): under a wall-time and memory budget, with
fair admission per client, in a process that can be killed without harming the server.

The pool is started with the app (`start_pool`, from its lifespan, before the threadpool serves
anything) and closed with it; a request that finds no pool (a test client without lifespan) starts
one. Its size and per-client limit come from the environment:

- ``LAGRANGE_LAB_DERIVE_SECONDS``: the wall-time budget of one job, queueing included (20 s);
- ``LAGRANGE_LAB_POOL_WORKERS``: worker processes per server process (the number of cores, ≥ 2);
- ``LAGRANGE_LAB_POOL_PER_CLIENT``: jobs one client may have running at once (half the workers);
- ``LAGRANGE_LAB_TRUST_FORWARDED``: ``1`` when behind a proxy that sets X-Forwarded-For (the
  client is then its last address, the one the proxy saw); otherwise the peer address is.

A built-in scene's simulation is numeric work on trusted equations and runs in this process (a
thread of the server), without the pool's round trip; its own budget is the integrator's wall
time. Those runs pass a `FairGate` (`in_process`) with the pool's rule of admission: a few at once
(so 45 heavy runs do not share the cores 45 ways and all run out of time, nor hold every thread
of the server), one client's runs beyond its limit waiting behind its own.
"""

from __future__ import annotations

import asyncio
import json
import logging
import os
import threading
import time
from collections import Counter
from collections.abc import AsyncIterator, Callable
from contextlib import asynccontextmanager
from dataclasses import dataclass, field
from functools import partial
from typing import Any

from fastapi import HTTPException, Request
from starlette.concurrency import run_in_threadpool

from app.schemas import DeriveResponse
from mechanics.budget import BudgetExceeded
from mechanics.fair_share import LEDGER, CpuLedger, reserve_for, thread_cpu
from mechanics.pool import WorkerLost, WorkerPool, busy_message
from mechanics.scenes import scene_ids
from mechanics.spec import SceneSpec, parse_spec

log = logging.getLogger(__name__)

DERIVE_SECONDS_ENV = "LAGRANGE_LAB_DERIVE_SECONDS"
DEFAULT_DERIVE_SECONDS = 20.0
CHECK_SECONDS_ENV = "LAGRANGE_LAB_CHECK_SECONDS"
DEFAULT_CHECK_SECONDS = 5.0
POOL_WORKERS_ENV = "LAGRANGE_LAB_POOL_WORKERS"
POOL_PER_CLIENT_ENV = "LAGRANGE_LAB_POOL_PER_CLIENT"
TRUST_FORWARDED_ENV = "LAGRANGE_LAB_TRUST_FORWARDED"
WARM_ENV = "LAGRANGE_LAB_WARM"
#: Threads for blocking work per server process (anyio's default is 40).
THREADS = 256

SIMPLIFY_SCENE = (
    "simplify the scene (fewer coordinates or bodies, simpler expressions) and try again"
)

_ready: dict[str, bytes] = {}
_pool: WorkerPool | None = None
_pool_lock = threading.Lock()


def derive_seconds() -> float:
    """The wall-time budget of one job: ``$LAGRANGE_LAB_DERIVE_SECONDS`` or 20 s."""
    raw = os.environ.get(DERIVE_SECONDS_ENV)
    if raw is None:
        return DEFAULT_DERIVE_SECONDS
    try:
        seconds = float(raw)
    except ValueError:
        seconds = -1.0
    if not 0 < seconds < float("inf"):
        log.warning("%s=%r is not a positive number of seconds; using 20", DERIVE_SECONDS_ENV, raw)
        return DEFAULT_DERIVE_SECONDS
    return seconds


def check_seconds() -> float:
    """The wall-time budget of checking an answer on a built-in scene:
    ``$LAGRANGE_LAB_CHECK_SECONDS`` or 5 s (an honest answer takes milliseconds)."""
    try:
        seconds = float(os.environ.get(CHECK_SECONDS_ENV, DEFAULT_CHECK_SECONDS))
    except ValueError:
        seconds = -1.0
    return seconds if 0 < seconds < float("inf") else DEFAULT_CHECK_SECONDS


def _positive_int(name: str, default: int) -> int:
    raw = os.environ.get(name, "")
    if raw.strip().isdigit() and int(raw) > 0:
        return int(raw)
    if raw:
        log.warning("%s=%r is not a positive integer; using %d", name, raw, default)
    return default


def start_pool() -> WorkerPool:
    """The running pool, started (workers warm) if there is none."""
    global _pool
    with _pool_lock:
        if _pool is None:
            size = _positive_int(POOL_WORKERS_ENV, max(2, os.cpu_count() or 1))
            per_client = _positive_int(POOL_PER_CLIENT_ENV, max(1, size // 2))
            _pool = WorkerPool(size=size, per_client=per_client).start()
        return _pool


def stop_pool() -> None:
    """Close the pool: its workers exit and are reaped."""
    global _pool
    with _pool_lock:
        pool, _pool = _pool, None
    if pool is not None:
        pool.close()


@asynccontextmanager
async def pool_lifespan(app: Any) -> AsyncIterator[None]:
    """The app's lifespan: the pool starts (its workers warm) before the first request and is
    closed, its workers reaped, when the server stops. Unless ``LAGRANGE_LAB_WARM=0``, every
    built-in scene is then made ready in the background (`warm_up`)."""
    pool = start_pool()
    # Routes that wait on the pool (equilibria, check, newton, a posted spec's jobs) hold a thread
    # while they wait, and static files are read in threads too: with anyio's default of 40, a
    # class's waiting requests would hold every thread and a page's files would queue behind
    # them. Waiting threads cost little; the pool and the gates bound the work itself.
    import anyio.to_thread

    anyio.to_thread.current_default_thread_limiter().total_tokens = THREADS
    stop = threading.Event()
    if os.environ.get(WARM_ENV, "1").strip() != "0":
        threading.Thread(target=warm_up, args=(pool, stop), name="warm-up", daemon=True).start()
    try:
        yield
    finally:
        stop.set()
        stop_pool()


#: The pool's client name for the warm-up: its jobs queue fairly behind real clients' ones.
WARM_CLIENT = "warm-up"
warm_state: dict[str, Any] = {"done": 0, "of": 0, "seconds": None}


def _one_key_per_worker(scene_id: str, size: int) -> list[str]:
    """Affinity keys that the pool sends to each of its ``size`` workers (it hashes them with
    crc32, mechanics/pool.py), the scene's own first."""
    import zlib

    keys: dict[int, str] = {zlib.crc32(scene_id.encode()) % size: scene_id}
    k = 0
    while len(keys) < size and k < 1000:
        key = f"{scene_id}#{k}"
        keys.setdefault(zlib.crc32(key.encode()) % size, key)
        k += 1
    return list(keys.values())


def warm_up(pool: WorkerPool, stop: threading.Event) -> None:
    """Every built-in scene derived, compiled and its equilibria found, before students ask:
    in this process (its simulations run here) and in the pool worker each scene's analysis
    requests go to. One scene at a time, as one more client of the pool, so a request that
    arrives meanwhile waits at most for one scene's work (and finds it done if it is the one
    being warmed: the caches are single flight)."""
    from mechanics.warm import warm_in_process, warm_in_worker

    start = time.perf_counter()
    ids = scene_ids()
    warm_state.update(done=0, of=len(ids), seconds=None)
    for scene_id in ids:
        if stop.is_set():
            return
        try:
            warm_in_process(scene_id)
            # in every worker: a scene's requests go to its own worker when it is free, to
            # another when it is busy (a class asks for the same scene at once)
            for affinity in _one_key_per_worker(scene_id, pool.size):
                pool.run(
                    warm_in_worker,
                    scene_id,
                    seconds=max(60.0, derive_seconds()),
                    client=WARM_CLIENT,
                    affinity=affinity,
                    what=f"warming {scene_id}",
                    advice="it will be derived on first use",
                )
        except Exception as exc:  # noqa: BLE001 — a failed warm-up is a slower first request
            log.warning("warming %s failed (%s): it will be derived on first use", scene_id, exc)
        warm_state["done"] += 1
    try:
        from app.routes.scenes import _catalog

        _catalog()  # the catalog page's one answer: every scene's spec and first second
    except Exception as exc:  # noqa: BLE001 — the catalog is then computed on first visit
        log.warning("warming the catalog failed (%s)", exc)
    warm_state["seconds"] = round(time.perf_counter() - start, 2)
    log.info("%d built-in scenes ready in %.1f s", len(ids), warm_state["seconds"])


def client_of(http: Request) -> str:
    """Who is asking, for the per-client limit: the peer address, or the address the trusted
    proxy saw (the last in X-Forwarded-For) when ``LAGRANGE_LAB_TRUST_FORWARDED=1``."""
    if os.environ.get(TRUST_FORWARDED_ENV) == "1":
        forwarded = http.headers.get("x-forwarded-for", "").split(",")[-1].strip()
        if forwarded:
            return forwarded
    return http.client.host if http.client is not None else ""


def in_pool(
    http: Request,
    job: Any,
    *args: Any,
    affinity: str | None,
    what: str,
    advice: str = SIMPLIFY_SCENE,
    seconds: float | None = None,
    field: str = "scene",
) -> Any:
    """``job(*args)`` in a pool worker under the budget; a lost worker is a 503, not a 500.

    ``what`` and ``advice`` make the message past the budget: "{what} took longer than 20 s;
    {advice}".
    """
    pool = _pool or start_pool()
    try:
        return pool.run(
            job,
            *args,
            seconds=seconds or derive_seconds(),
            client=client_of(http),
            affinity=affinity,
            what=what,
            advice=advice,
        )
    except BudgetExceeded as exc:
        exc.field = field  # a check past its budget is about the answer, not the scene
        raise
    except WorkerLost as lost:  # in the one error shape (app/errors.py), like a time budget's
        detail = [{"field": "scene", "message": f"{lost}; try again"}]
        raise HTTPException(status_code=503, detail=detail) from None


def posted_key(scene: SceneSpec) -> str:
    """A posted scene's key for the pool (see mechanics.jobs.spec_key), after the cross-field
    checks (names declared once, references that resolve): cheap, and a spec that fails them need
    not cost a worker."""
    from mechanics.jobs import spec_key

    document = scene.model_dump(mode="json", by_alias=True, exclude_unset=True)
    parse_spec(document)
    return spec_key(document)


def scene_json(scene_id: str) -> bytes | None:
    """The derivation of a built-in scene as JSON bytes, or None if there is no such scene."""
    body = _ready.get(scene_id)
    if body is None:
        if scene_id not in scene_ids():
            return None
        from mechanics.derive import derive_scene

        body = _ready[scene_id] = _encode(derive_scene(scene_id))
    return body


def posted_json(http: Request, scene: SceneSpec) -> bytes:
    """The derivation of a posted scene as JSON bytes: from the shared cache (memory, disk or
    Redis; a posted copy of a built-in scene is the same entry), else computed once in the pool."""
    from mechanics.derive import derive_cached
    from mechanics.jobs import derivation_json

    key = posted_key(scene)
    return _encode(
        derive_cached(
            json.loads(key),
            compute=lambda: in_pool(
                http, derivation_json, key, affinity=key, what="deriving this scene"
            ),
        )
    )


def _encode(result: dict[str, Any]) -> bytes:
    """Validate against the documented response once, when computed, and keep its JSON."""
    return DeriveResponse.model_validate(result).model_dump_json().encode()


def on_scene(
    http: Request, request: Any, job: Any, *args: Any, what: str, advice: str = SIMPLIFY_SCENE
) -> Any:
    """``job(scene_id, key, *args)`` in the pool for the scene a request names (a built-in one by
    id, a posted one by its key), the one way the analysis routes reach the engine."""
    if request.scene_id is not None:
        if request.scene_id not in scene_ids():
            raise HTTPException(status_code=404, detail=f"unknown scene '{request.scene_id}'")
        scene_id, key = request.scene_id, None
    else:
        scene_id, key = None, posted_key(request.scene)
    affinity = scene_id or key
    # judging an answer against a built-in scene's cached derivation takes milliseconds: a
    # shorter budget keeps a hostile answer from holding a worker for the derivation's 20 s
    # (a prediction integrates two models as well: it keeps the derivation's budget), and past
    # its budget the 503 is about the answer, not the scene
    name = getattr(job, "__name__", "")
    checking = name in ("answer_check", "answer_predict")
    short = name == "answer_check" and scene_id is not None
    seconds = min(check_seconds(), derive_seconds()) if short else None

    def compute() -> Any:
        return in_pool(
            http,
            job,
            scene_id,
            key,
            *args,
            affinity=affinity,
            what=what,
            advice=advice,
            seconds=seconds,
            field="answer" if checking else "scene",
        )

    store = RESULT_STORES.get(getattr(job, "__name__", ""))
    if store is None:
        return compute()
    from mechanics import cache
    from mechanics.derive import derivation_key, scene_key

    scene = scene_key(scene_id) if scene_id is not None else derivation_key(json.loads(key))
    return cache.get_or_compute(store, {**scene, "job": store, "args": list(args)}, compute)


#: Per-scene results worth sharing (same scene, same arguments, same answer), by the job that
#: computes them: a class of 200 asks for the same equilibria and types the same answers.
#: Refusals and budget errors are raised, never stored.
RESULT_STORES = {"equilibria_json": "equilibria", "newton": "newton", "answer_check": "check"}


#: In-process runs (built-in scenes' simulations) at once per server process: twice the cores, so
#: a few clients' long runs leave room for everyone's short ones while the cores are not shared
#: so many ways that every run runs out of its wall time.
IN_PROCESS_RUNS = 2 * max(1, os.cpu_count() or 1)
#: In-process runs one client may have at once; its further runs wait behind its own.
IN_PROCESS_PER_CLIENT = 1
#: How long an in-process run may wait for its turn; its own wall time starts when it starts.
IN_PROCESS_START_SECONDS = 10.0


@dataclass(eq=False)
class _Ticket:
    client: str
    loop: asyncio.AbstractEventLoop
    turn: asyncio.Future = field(repr=False)
    granted: bool = False


class FairGate:
    """At most ``total`` runs at once and ``per_client`` of one client's; waiting runs start in
    arrival order, skipping the clients at their limit (the rule of mechanics/pool.py, for work
    in this process's threads). Waiting holds no thread: a flood of waiting requests leaves the
    threadpool to ``/healthz``, pages and everyone else.

    Fair over time too (mechanics/fair_share.py): clients with CPU credit go first, and a client
    in debt may not take the last free place.

    Thread-safe and not bound to one event loop (each waiter is woken on its own loop).
    """

    def __init__(self, total: int, per_client: int, ledger: CpuLedger | None = None) -> None:
        self.total = max(1, total)
        self.per_client = max(1, per_client)
        self.ledger = ledger or LEDGER
        self.reserve = reserve_for(self.total)
        self._lock = threading.Lock()
        self._running: Counter[str] = Counter()
        self._waiting: list[_Ticket] = []

    @asynccontextmanager
    async def turn(self, client: str, seconds: float, what: str) -> AsyncIterator[None]:
        """Hold one of the places while the block runs; raise BudgetExceeded("time") (a 503) if
        none is granted within ``seconds``."""
        await self._enter(client, seconds, what)
        try:
            yield
        finally:
            self._leave(client)

    def running(self) -> int:
        with self._lock:
            return sum(self._running.values())

    async def _enter(self, client: str, seconds: float, what: str) -> None:
        loop = asyncio.get_running_loop()
        ticket = _Ticket(client, loop, loop.create_future())
        with self._lock:
            self._waiting.append(ticket)
            self._grant()
        try:
            await asyncio.wait_for(ticket.turn, seconds)
        except (TimeoutError, asyncio.CancelledError) as stopped:
            with self._lock:
                if not ticket.granted:
                    self._waiting.remove(ticket)
                    if isinstance(stopped, TimeoutError):
                        raise BudgetExceeded("time", self._busy(client, seconds, what)) from None
                    raise
            if isinstance(stopped, asyncio.CancelledError):  # granted as it was cancelled
                self._leave(client)
                raise

    def _leave(self, client: str) -> None:
        with self._lock:
            self._running[client] -= 1
            if self._running[client] <= 0:
                del self._running[client]
            self._grant()

    def _grant(self) -> None:
        """Give free places to waiting tickets in the ledger's order (under the lock)."""
        for ticket in self.ledger.ordered(self._waiting, key=lambda t: t.client):
            free = self.total - sum(self._running.values())
            if free <= 0:
                return
            if self._running[ticket.client] >= self.per_client:
                continue
            if not self.ledger.may_take(ticket.client, free, self.reserve):
                continue
            self._waiting.remove(ticket)
            try:
                ticket.loop.call_soon_threadsafe(_wake, ticket.turn)
            except RuntimeError:  # its event loop is gone: nobody is waiting on it
                continue
            ticket.granted = True
            self._running[ticket.client] += 1

    def _busy(self, client: str, seconds: float, what: str) -> str:
        """Under the lock, this ticket already out of the queue: the client's tickets still in
        it are the ones waiting behind (ten sent at once are not "1 running")."""
        queued = sum(1 for ticket in self._waiting if ticket.client == client)
        return busy_message(
            self._running[client],
            self.per_client,
            seconds,
            what,
            f"no {what} could start",
            queued=queued,
            debt=self.ledger.describe(client),
        )


def _wake(turn: asyncio.Future) -> None:
    if not turn.done():
        turn.set_result(None)


in_process_gate = FairGate(IN_PROCESS_RUNS, IN_PROCESS_PER_CLIENT)


async def in_process(
    http: Request,
    fn: Callable[..., Any],
    *args: Any,
    what: str,
    timing: dict[str, float] | None = None,
) -> Any:
    """``fn(*args)`` in a thread of this process once the gate lets it start (a 503 if it cannot
    within ``IN_PROCESS_START_SECONDS``); its own budget starts then, not while it waited.
    ``timing`` gets the seconds spent waiting for the gate ("gate") and in the thread ("thread"),
    for the answer's Server-Timing header: under a crowd, the two tell queueing from work."""
    t0 = time.perf_counter()
    client = client_of(http)
    async with in_process_gate.turn(client, IN_PROCESS_START_SECONDS, what):
        t1 = time.perf_counter()
        try:  # its thread's CPU time is charged to the client (mechanics/fair_share.py)
            return await run_in_threadpool(thread_cpu, partial(fn, *args), client)
        finally:
            if timing is not None:
                timing["gate"], timing["thread"] = t1 - t0, time.perf_counter() - t1


def server_timing(seconds: dict[str, float]) -> dict[str, str]:
    """A ``Server-Timing`` header (W3C) of named durations, in ms: browsers' devtools show it,
    and the load benchmark reads it to tell where a slow answer's time went."""
    value = ", ".join(f"{name};dur={1e3 * s:.1f}" for name, s in seconds.items())
    return {"server-timing": value} if value else {}
