"""One cache for everything the engine computes once and serves many times.

A derivation costs seconds of sympy and never changes until the engine does, so its JSON is kept
under a content hash and every worker, and every server, reuses it. The cache is an optimisation
only: a failure to read or write it is logged and the value computed again; nothing here is ever
a reason for a 500.

The stores (`STORES`; a name outside this list is a programming error):

- ``derivation``    a scene's derivation, ``Derivation.to_json()``; keyed by the canonical spec.
- ``equilibria``    equilibria of a scene at given parameters; keyed by spec + parameters.
- ``newton``        Newton's method beside Lagrange's for a scene; keyed by the spec.
- ``check``         a judged answer; keyed by spec + quantity + answer + coordinate + reveal.
- ``live-module`` a posted scene's live equations printed as a JavaScript module (text), keyed by
  its digest, so that every worker process serves the module any of them printed.

The generated C of a scene's right-hand side is not shared: each machine generates it (7-26 ms
for the built-in scenes, less than a compile) and compiles and verifies its own library
(mechanics/native).

Every entry is keyed by ``key_for(store, key_parts)``: sha256 of the canonical JSON (sorted keys,
no whitespace) of the store, the engine (`engine_id()`: `ENGINE_VERSION` and `CODE_HASH`, a hash
of the engine's code and library versions, so two deployments with different code never share
an entry) and what defines the value. An entry is a JSON header line (format, store, key,
engine, sha256 and length of the payload) and the payload, the value's JSON. It is verified on
every read from disk or Redis; an entry is ignored, logged, recomputed and overwritten — never
served — when

1. it is not a header line and a payload (a stray file, an entry of the old format);
2. its header names another format, store, key or engine;
3. its payload is not as long as the header says, or its sha256 differs (truncated, altered);
4. its payload is not JSON;
5. the caller's ``validate(value)`` is false or raises (a value of the wrong shape).

Where entries live:

- the local disk, the embedded default: ``$LAGRANGE_LAB_CACHE`` or ``~/.cache/lagrange-lab``,
  one folder per store, written atomically (temporary file + ``os.replace``), each store bounded
  by ``$LAGRANGE_LAB_CACHE_MB`` (256 MB; the least recently used entries go first). A disk that
  cannot write (full, read-only, over quota) only costs speed: logged once, not written for
  30 s, values answered from the computation and memory (mechanics/cache_disk.py);
- Redis, when ``$LAGRANGE_LAB_REDIS_URL`` is set: shared by every server, entries expire after
  their store's TTL. Operations time out after 0.25 s; a failure opens a breaker shared by the
  process (logged once per outage: the disk serves at once, a background PING tries Redis every
  10 s) and writes go through a background thread (mechanics/cache_redis.py).

Single flight: identical concurrent requests wait for one computation. In a process, the first
thread computes and the others wait for its value (or its exception). Across processes and
servers, the computer holds a lock that expires (Redis ``SET NX PX``; on disk a lock file that
appears whole, stale when empty, past its deadline or when its process is gone), so ``kill -9``
never leaves a lock behind for long; the others poll for the value, and compute themselves if the
lock goes without one (the computation raised) or their wait times out.

    >>> get_or_compute("newton", {"spec": {"answer": 42}}, lambda: {"answer": 42})
    {'answer': 42}

Values are JSON (dicts, lists, strings, numbers); a caller gets the value as read back from its
JSON whether it was computed or found, and must not change it (it may be shared in memory).

Why about 430 lines: the stores, keys, the verification of an entry and single flight are one
answer to "when is a stored value served"; where entries live is in mechanics/cache_disk.py and
mechanics/cache_redis.py.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import sys
import threading
import time
from collections import Counter, OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mechanics import cache_disk, cache_redis
from mechanics.cache_disk import SIZE_ENV_VAR, DiskBackend
from mechanics.cache_redis import REDIS_PREFIX, RedisBackend

__all__ = [
    "CODE_HASH",
    "ENGINE_VERSION",
    "REDIS_PREFIX",
    "SIZE_ENV_VAR",
    "STORES",
    "cache_dir",
    "engine_id",
    "flush",
    "get",
    "get_or_compute",
    "key_for",
    "shared_computations",
    "stats",
]

log = logging.getLogger(__name__)

#: Bump when the output of any store changes (a derivation step, equilibria, the generated C...),
#: so entries of the old engine are never served. Part of every key and every entry.
ENGINE_VERSION = "18"

ENV_VAR = "LAGRANGE_LAB_CACHE"
REDIS_ENV_VAR = "LAGRANGE_LAB_REDIS_URL"
FORMAT = 1
#: The breaker of each outage (Redis; a disk that cannot write), shared by the process.
_redis_state = cache_redis._state
_disk_state = cache_disk._state
DAY = 24 * 3600


@dataclass(frozen=True)
class Store:
    """A named store: how long Redis keeps an entry, how long a computation may hold the lock,
    and how many values each process keeps in memory."""

    name: str
    ttl_seconds: int
    lock_seconds: float = 60.0
    memory_items: int = 128
    #: Write to Redis before the request answers (a client fetches the value from another
    #: worker right after); other stores write from a background thread.
    write_before_answer: bool = False


STORES: dict[str, Store] = {
    s.name: s
    for s in (
        Store("derivation", ttl_seconds=30 * DAY, memory_items=64),
        Store("equilibria", ttl_seconds=7 * DAY, memory_items=512),
        Store("newton", ttl_seconds=30 * DAY),
        Store("check", ttl_seconds=7 * DAY, memory_items=1024),
        Store("live-module", ttl_seconds=30 * DAY, write_before_answer=True),
    )
}


def cache_dir() -> Path:
    """Where disk entries live: ``$LAGRANGE_LAB_CACHE``, else ``~/.cache/lagrange-lab``.

    Read on every call, so tests (and a second deployment on the same machine) can point it
    elsewhere without reloading anything.
    """
    configured = os.environ.get(ENV_VAR)
    return Path(configured).expanduser() if configured else Path.home() / ".cache" / "lagrange-lab"


def _code_hash() -> str:
    """sha256 of the engine's code: every source of the mechanics package (its Python, C and
    built-in scenes, by relative path) and the versions of Python, sympy, numpy and scipy.

    Why: `ENGINE_VERSION` is bumped by hand, and two deployments that share a Redis (or a cache
    folder) with the same version but different code, or different libraries, would otherwise
    serve each other's derivations. Computed once, at import (about a megabyte of files).
    """
    from importlib import metadata

    root = Path(__file__).resolve().parent
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*")):
        if path.suffix in (".py", ".c", ".toml") and "__pycache__" not in path.parts:
            digest.update(path.relative_to(root).as_posix().encode() + b"\0")
            digest.update(path.read_bytes() + b"\0")
    versions = [f"python {sys.version_info[0]}.{sys.version_info[1]}"]
    for dist in ("sympy", "numpy", "scipy"):
        try:
            versions.append(f"{dist} {metadata.version(dist)}")
        except metadata.PackageNotFoundError:
            versions.append(f"{dist} none")
    digest.update("\n".join(versions).encode())
    return digest.hexdigest()


#: The engine's code, hashed once per process: part of every key and every entry's header.
CODE_HASH = _code_hash()


def engine_id() -> str:
    """What names this engine in keys and entries: `ENGINE_VERSION` and the first 16 hex digits
    of `CODE_HASH` (read at each call, so a changed version is a new key at once)."""
    return f"{ENGINE_VERSION}+{CODE_HASH[:16]}"


def key_for(store: str, key_parts: Any) -> str:
    """The key of the value ``key_parts`` define in ``store``: sha256 of canonical JSON.

    Canonical (sorted keys, no whitespace) so the same spec written in another order is the same
    entry; the store and the engine version are hashed in, so an engine change is a new key.
    """
    _store(store)
    canonical = json.dumps(
        {"store": store, "engine": engine_id(), "parts": key_parts},
        sort_keys=True,
        separators=(",", ":"),
        ensure_ascii=False,
    )
    return hashlib.sha256(canonical.encode()).hexdigest()


def get(store: str, key_parts: Any, validate: Callable[[Any], bool] | None = None) -> Any:
    """The verified value ``key_parts`` define in ``store``, or None (never computes)."""
    s, key = _store(store), key_for(store, key_parts)
    value = _memory(s).get(key)
    return value if value is not None else _read(_backend(), s, key, validate)


def get_or_compute(
    store: str,
    key_parts: Any,
    compute: Callable[[], Any],
    validate: Callable[[Any], bool] | None = None,
) -> Any:
    """The value ``key_parts`` define in ``store``: from memory, disk or Redis, else ``compute()``
    once (single flight in this process and across processes) and stored.

    ``validate`` checks an entry's value before it is served (and a computed one before it is
    stored). What ``compute`` raises reaches the caller and the threads waiting on it here; the
    lock is released, and waiters in other processes compute themselves.
    """
    s, key = _store(store), key_for(store, key_parts)
    memory = _memory(s)
    value = memory.get(key)
    if value is not None:
        _count(store, "memory")
        return value
    with _flights_guard:
        flight = _flights.get((store, key))
        leader = flight is None
        if leader:
            flight = _flights[store, key] = _Flight()
    if not leader:
        _count(store, "joined")
        return flight.wait(s.lock_seconds, lambda: _shared(s, key, compute, validate))
    try:
        flight.value = _shared(s, key, compute, validate)
        memory.put(key, flight.value)
        return flight.value
    except BaseException as exc:
        flight.error = exc
        raise
    finally:
        with _flights_guard:
            del _flights[store, key]
        flight.done.set()


def stats() -> dict[str, dict[str, int]]:
    """This process's counts per store: memory, hit, computed, waited, joined, invalid, ..."""
    with _stats_guard:
        return {store: dict(counts) for store, counts in _stats.items()}


def shared_computations(store: str) -> int | None:
    """How many times ``store``'s values were computed by every server sharing this Redis (a
    counter in Redis itself), or None without Redis."""
    backend = _backend()
    return backend.computations(store) if isinstance(backend, RedisBackend) else None


# --- single flight in this process ------------------------------------------------------------


@dataclass
class _Flight:
    done: threading.Event = field(default_factory=threading.Event)
    value: Any = None
    error: BaseException | None = None

    def wait(self, seconds: float, compute: Callable[[], Any]) -> Any:
        if not self.done.wait(seconds):
            log.warning("cache: waited %.0f s for another thread; computing here", seconds)
            return compute()
        if self.error is not None:
            raise self.error
        return self.value


_flights: dict[tuple[str, str], _Flight] = {}
_flights_guard = threading.Lock()


class _Memory:
    """A small LRU of verified values, per store and process."""

    def __init__(self, size: int) -> None:
        self.size, self.items, self.lock = size, OrderedDict(), threading.Lock()

    def get(self, key: str) -> Any:
        with self.lock:
            if key in self.items:
                self.items.move_to_end(key)
                return self.items[key]
        return None

    def put(self, key: str, value: Any) -> None:
        with self.lock:
            self.items[key] = value
            while len(self.items) > self.size:
                self.items.popitem(last=False)


_memories: dict[tuple[str, str, str], _Memory] = {}
_stats: dict[str, Counter] = {}
_stats_guard = threading.Lock()


def _memory(s: Store) -> _Memory:
    # Per cache folder and Redis URL, so pointing the cache elsewhere starts cold (as tests do).
    where = (str(cache_dir()), os.environ.get(REDIS_ENV_VAR, ""), s.name)
    with _stats_guard:
        return _memories.setdefault(where, _Memory(s.memory_items))


def _count(store: str, what: str) -> None:
    with _stats_guard:
        _stats.setdefault(store, Counter())[what] += 1


def _store(name: str) -> Store:
    try:
        return STORES[name]
    except KeyError:
        raise ValueError(f"no cache store {name!r} (the stores: {', '.join(STORES)})") from None


# --- single flight across processes and servers ---------------------------------------------

POLL_FIRST, POLL_MAX = 0.02, 0.25


def _shared(s: Store, key: str, compute: Callable[[], Any], validate) -> Any:
    backend = _backend()
    deadline = time.monotonic() + s.lock_seconds
    while True:
        value = _read(backend, s, key, validate)
        if value is not None:
            _count(s.name, "hit")
            return value
        token = backend.acquire(s, key)
        if token is not None:
            try:
                value = _read(backend, s, key, validate)  # written while we took the lock?
                if value is not None:
                    _count(s.name, "hit")
                    return value
                return _computed(backend, s, key, compute, validate)
            finally:
                backend.release(s, key, token)
        pause = POLL_FIRST
        while time.monotonic() < deadline:
            time.sleep(pause)
            pause = min(POLL_MAX, pause * 1.5)
            value = _read(backend, s, key, validate)
            if value is not None:
                _count(s.name, "waited")
                return value
            if not backend.locked(s, key):
                break  # the computer is gone without a value: take the lock and compute
        else:
            log.warning("cache: %s/%s still locked; computing here", s.name, key)
            return _computed(backend, s, key, compute, validate)


def _computed(backend: _Backend, s: Store, key: str, compute, validate) -> Any:
    value = compute()
    _count(s.name, "computed")
    backend.counted(s)
    try:
        payload = json.dumps(
            value, sort_keys=True, separators=(",", ":"), ensure_ascii=False, allow_nan=False
        ).encode()
    except (TypeError, ValueError) as exc:
        log.warning("cache: a %s value is not JSON (%s); not stored", s.name, exc)
        return value
    value = json.loads(payload)  # what a reader gets: a hit and a miss answer the same
    if not _valid(value, validate):
        log.warning("cache: a computed %s value fails its check; not stored", s.name)
        return value
    header = {"format": FORMAT, "store": s.name, "key": key, "engine": engine_id()}
    header |= {"sha256": hashlib.sha256(payload).hexdigest(), "bytes": len(payload)}
    backend.write(s, key, json.dumps(header, sort_keys=True).encode() + b"\n" + payload)
    return value


def _read(backend: _Backend, s: Store, key: str, validate) -> Any:
    """The entry's value if it passes every check of the module docstring, else None."""
    data = backend.read(s, key)
    if data is None:
        return None
    head, newline, payload = data.partition(b"\n")
    try:
        header = json.loads(head) if newline else None
    except ValueError:
        header = None
    expected = {"format": FORMAT, "store": s.name, "key": key, "engine": engine_id()}
    if not isinstance(header, dict) or any(header.get(k) != v for k, v in expected.items()):
        return _rejected(s, key, "not an entry of this store, key and engine version")
    if header.get("bytes") != len(payload):
        return _rejected(s, key, f"{len(payload)} bytes where {header.get('bytes')} were written")
    if header.get("sha256") != hashlib.sha256(payload).hexdigest():
        return _rejected(s, key, "its payload does not match its sha256")
    try:
        value = json.loads(payload)
    except ValueError:
        return _rejected(s, key, "its payload is not JSON")
    if value is None or not _valid(value, validate):
        return _rejected(s, key, "its value does not have the expected shape")
    return value


def _valid(value: Any, validate) -> bool:
    try:
        return validate is None or bool(validate(value))
    except Exception:  # a check that trips over a damaged value has answered: not valid
        return False


def _rejected(s: Store, key: str, why: str) -> None:
    _count(s.name, "invalid")
    log.warning("cache: ignoring %s entry %s (%s); recomputing", s.name, key, why)
    return None


# --- backends ---------------------------------------------------------------------------------

_Backend = DiskBackend | RedisBackend


def _backend() -> _Backend:
    """Redis when ``$LAGRANGE_LAB_REDIS_URL`` is set and its breaker is closed, else the disk."""
    disk = DiskBackend(cache_dir())
    url = os.environ.get(REDIS_ENV_VAR, "").strip()
    client = cache_redis.client_for(url) if url else None
    return disk if client is None else RedisBackend(client, disk)


def flush(timeout: float = 5.0) -> bool:
    """Wait (at most ``timeout`` s) for the writes to Redis this process left to its background
    thread; True when none is left. Tests call it before they look into Redis."""
    return cache_redis.flush(timeout)
