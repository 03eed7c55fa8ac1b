"""The cache's shared Redis, and why a dead or hung Redis costs a request at most a fraction of
a second.

A Redis that is stopped (SIGSTOP, a frozen VM, a black-holed route) accepts connections and never
answers, so every operation waits for its socket timeout; with redis-py's defaults (5 s, and
retries with back-off) a request that makes six operations froze for ~30 s. Here:

- every operation has a short connect and socket timeout (`TIMEOUT_SECONDS`) and no retries;
- a circuit breaker shared by the process: the first failure opens it (logged once per outage),
  and every later operation of every thread goes to the local disk at once, without touching
  Redis; after `RETRY_SECONDS` one probe (a PING in a background thread, never a request's)
  tries Redis, and closes the breaker when it answers;
- writes (an entry, the fleet's computation counter, a lock's release) leave the request's path:
  a background thread performs them in order (an entry before its lock's release), falling back
  to the disk like every other operation. `flush()` waits for them (tests, exit).

So a request pays at most one timeout per outage and process (a read that was in flight when
Redis stopped); the other processes find the outage the same way, each once.
"""

from __future__ import annotations

import atexit
import logging
import os
import queue
import threading
import time
import uuid
from collections.abc import Callable
from typing import Any

log = logging.getLogger("mechanics.cache")

REDIS_PREFIX = "lagrange-lab:"
#: While the breaker is open the disk serves; after this long one background PING tries Redis.
RETRY_SECONDS = 10.0
#: Connect and socket timeout of every Redis operation: a healthy Redis on a LAN answers in a
#: millisecond; an entry is at most tens of kB.
TIMEOUT_SECONDS = 0.25
#: Writes waiting for the background thread; past this the caller performs its own.
QUEUE_MAX = 1000

#: The breaker, shared by the process: ``logged`` is "open" (an outage was seen and logged and no
#: probe has answered since), ``down_until`` when the next probe may run.
_state: dict[str, Any] = {"down_until": 0.0, "logged": False, "probing": False}
_guard = threading.Lock()
_clients: dict[str, Any] = {}


def is_open() -> bool:
    """True while Redis is known down (skip it)."""
    return bool(_state["logged"]) or time.monotonic() < _state["down_until"]


def failed(exc: BaseException) -> None:
    """An operation failed: open the breaker (logged once per outage)."""
    with _guard:
        _state["down_until"] = time.monotonic() + RETRY_SECONDS
        first = not _state["logged"]
        _state["logged"] = True
    if first:
        log.warning(
            "cache: Redis is unreachable (%s); using the local disk, retrying every %.0f s",
            exc,
            RETRY_SECONDS,
        )


def _probe(client: Any) -> None:
    try:
        client.ping()
    except Exception as exc:  # noqa: BLE001 — any failure keeps the breaker open
        with _guard:
            _state["down_until"] = time.monotonic() + RETRY_SECONDS
            _state["probing"] = False
        log.debug("cache: Redis probe failed (%s)", exc)
        return
    with _guard:
        _state.update(logged=False, probing=False, down_until=0.0)
    log.warning("cache: Redis answers again; sharing through it")


def _maybe_probe(client: Any) -> None:
    """Start the one background probe when the breaker's time is up."""
    with _guard:
        if _state["probing"] or time.monotonic() < _state["down_until"]:
            return
        _state["probing"] = True
    threading.Thread(target=_probe, args=(client,), name="cache-redis-probe", daemon=True).start()


def client_for(url: str) -> Any | None:
    """This process's client of ``url`` (short timeouts, no retries), or None when there is no
    usable client (the failure opens the breaker) or the breaker is open."""
    with _guard:
        client = _clients.get(url)
    if client is None:
        try:
            import redis
            from redis.backoff import NoBackoff
            from redis.retry import Retry

            client = redis.Redis.from_url(
                url,
                socket_connect_timeout=TIMEOUT_SECONDS,
                socket_timeout=TIMEOUT_SECONDS,
                retry=Retry(NoBackoff(), 0),
                health_check_interval=30,
            )
        except (ImportError, ValueError) as exc:
            failed(exc)
            return None
        with _guard:
            client = _clients.setdefault(url, client)
    if is_open():
        _maybe_probe(client)
        return None
    return client


class RedisBackend:
    """Entries as Redis strings with their store's TTL, locks as ``SET NX PX`` keys. Any Redis
    failure opens the breaker and the same operation goes to ``disk`` instead."""

    RELEASE = "if redis.call('get', KEYS[1]) == ARGV[1] then return redis.call('del', KEYS[1]) end"

    def __init__(self, client: Any, disk: Any) -> None:
        self.client, self.disk = client, disk
        # a fixed Lua script (no user text), run by its SHA: the lock is deleted only by its owner
        self._release = client.register_script(self.RELEASE)

    def read(self, s: Any, key: str) -> bytes | None:
        return self._do(lambda: self.client.get(rkey(s, key)), lambda: self.disk.read(s, key))

    def write(self, s: Any, key: str, data: bytes) -> None:
        ms = s.ttl_seconds * 1000
        (_now if s.write_before_answer else _later)(
            self._do,
            lambda: self.client.set(rkey(s, key), data, px=ms),
            lambda: self.disk.write(s, key, data),
        )

    def acquire(self, s: Any, key: str) -> str | None:
        token, ms = uuid.uuid4().hex, int(s.lock_seconds * 1000)
        return self._do(
            lambda: token if self.client.set(rkey(s, key, "lock"), token, nx=True, px=ms) else None,
            lambda: self.disk.acquire(s, key),
        )

    def release(self, s: Any, key: str, token: str) -> None:
        _later(
            self._do,
            lambda: self._release(keys=[rkey(s, key, "lock")], args=[token]),
            lambda: self.disk.release(s, key, token),
        )

    def locked(self, s: Any, key: str) -> bool:
        return self._do(
            lambda: bool(self.client.exists(rkey(s, key, "lock"))),
            lambda: self.disk.locked(s, key),
        )

    def counted(self, s: Any) -> None:
        _later(self._do, lambda: self.client.incr(f"{REDIS_PREFIX}computed:{s.name}"), _nothing)

    def computations(self, store: str) -> int | None:
        raw = self._do(lambda: self.client.get(f"{REDIS_PREFIX}computed:{store}") or 0, _nothing)
        return None if raw is None else int(raw)

    def _do(self, redis_op: Callable[[], Any], disk_op: Callable[[], Any]) -> Any:
        """``redis_op``, or ``disk_op`` when the breaker is open or Redis fails now."""
        if is_open():
            return disk_op()
        import redis

        try:
            return redis_op()
        except (redis.RedisError, OSError) as exc:
            failed(exc)
            return disk_op()


def rkey(s: Any, key: str, suffix: str = "") -> str:
    """The Redis key of an entry (or its lock)."""
    return f"{REDIS_PREFIX}{s.name}:{key}" + (f":{suffix}" if suffix else "")


def _nothing() -> None:
    return None


# --- writes off the request's path ------------------------------------------------------------

_queue: queue.Queue = queue.Queue(QUEUE_MAX)
_writer: dict[str, Any] = {"pid": None}


def _work() -> None:
    while True:
        fn, args = _queue.get()
        try:
            fn(*args)
        except Exception:  # noqa: BLE001 — a write is an optimisation; never kill the thread
            log.exception("cache: a background write failed")
        finally:
            _queue.task_done()


def _now(fn: Callable[..., Any], *args: Any) -> None:
    fn(*args)


def _later(fn: Callable[..., Any], *args: Any) -> None:
    """Run ``fn(*args)`` on the background thread (started once per process, again after a
    fork); inline when its queue is full."""
    with _guard:
        if _writer["pid"] != os.getpid():
            _writer["pid"] = os.getpid()
            threading.Thread(target=_work, name="cache-redis-writer", daemon=True).start()
    try:
        _queue.put_nowait((fn, args))
    except queue.Full:
        fn(*args)


def flush(timeout: float = 5.0) -> bool:
    """Wait (at most ``timeout`` s) for the background writes; True when none is left."""
    deadline = time.monotonic() + timeout
    with _queue.all_tasks_done:
        while _queue.unfinished_tasks:
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            _queue.all_tasks_done.wait(left)
    return True


atexit.register(flush, 2.0)


def _after_fork() -> None:
    global _queue, _guard
    _queue = queue.Queue(QUEUE_MAX)  # the parent's pending writes are the parent's
    _guard = threading.Lock()  # another thread may have held it at the fork
    _writer["pid"] = None


os.register_at_fork(after_in_child=_after_fork)
