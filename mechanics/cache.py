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
- ``native-source`` the generated C of a scene's right-hand side (text); keyed by spec + branches.
- ``live-module`` a posted scene's live equations printed as a JavaScript module (text), keyed by
  its digest, so that every worker process serves the module any of them printed.
  Only the source is shared: mechanics/native compiles it and verifies the library on this
  machine, and never takes a binary from another one.

Every entry is keyed by ``key_for(store, key_parts)``: sha256 of the canonical JSON (sorted keys,
no whitespace) of the store, `ENGINE_VERSION` and what defines the value. An entry is a JSON
header line (format, store, key, engine version, sha256 and length of the payload) and the
payload, the value's JSON. It is verified on every read from disk or Redis; an entry is ignored,
logged, recomputed and overwritten — never served — when

1. it is not a header line and a payload (a stray file, an entry of the old format);
2. its header names another format, store, key or engine version;
3. its payload is not as long as the header says, or its sha256 differs (truncated, altered);
4. its payload is not JSON;
5. the caller's ``validate(value)`` is false or raises (a value of the wrong shape).

Where entries live:

- the local disk, the embedded default: ``$LAGRANGE_LAB_CACHE`` or ``~/.cache/lagrange-lab``,
  one folder per store, written atomically (temporary file + ``os.replace``), each store bounded
  by ``$LAGRANGE_LAB_CACHE_MB`` (256 MB; the least recently used entries go first);
- Redis, when ``$LAGRANGE_LAB_REDIS_URL`` is set: shared by every server, entries expire after
  their store's TTL. When Redis cannot be reached the disk is used instead; that is logged once
  per outage and Redis is tried again after `REDIS_RETRY_SECONDS`.

Single flight: identical concurrent requests wait for one computation. In a process, the first
thread computes and the others wait for its value (or its exception). Across processes and
servers, the computer holds a lock that expires (Redis ``SET NX PX``; on disk an ``O_EXCL`` file,
stale past the store's lock time or when its process is gone), so ``kill -9`` never leaves a lock
behind for long; the others poll for the value, and compute themselves if the lock goes without
one (the computation raised) or their wait times out.

    >>> get_or_compute("newton", {"spec": {"answer": 42}}, lambda: {"answer": 42})
    {'answer': 42}

Values are JSON (dicts, lists, strings, numbers); a caller gets the value as read back from its
JSON whether it was computed or found, and must not change it (it may be shared in memory).
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import socket
import tempfile
import threading
import time
import uuid
from collections import Counter, OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = [
    "ENGINE_VERSION",
    "STORES",
    "cache_dir",
    "get",
    "get_or_compute",
    "key_for",
    "shared_computations",
    "stats",
]

log = logging.getLogger(__name__)

#: Bump when the output of any store changes (a derivation step, equilibria, the generated C...),
#: so entries of the old engine are never served. Part of every key and every entry.
ENGINE_VERSION = "17"

ENV_VAR = "LAGRANGE_LAB_CACHE"
REDIS_ENV_VAR = "LAGRANGE_LAB_REDIS_URL"
SIZE_ENV_VAR = "LAGRANGE_LAB_CACHE_MB"
DEFAULT_MB = 256
FORMAT = 1
REDIS_PREFIX = "lagrange-lab:"
#: After Redis failed, the disk serves for this long before Redis is tried again.
REDIS_RETRY_SECONDS = 10.0
DAY = 24 * 3600


@dataclass(frozen=True)
class Store:
    """A named store: how long Redis keeps an entry, how long a computation may hold the lock,
    and how many values each process keeps in memory."""

    name: str
    ttl_seconds: int
    lock_seconds: float = 60.0
    memory_items: int = 128


STORES: dict[str, Store] = {
    s.name: s
    for s in (
        Store("derivation", ttl_seconds=30 * DAY, memory_items=64),
        Store("equilibria", ttl_seconds=7 * DAY, memory_items=512),
        Store("newton", ttl_seconds=30 * DAY),
        Store("check", ttl_seconds=7 * DAY, memory_items=1024),
        Store("native-source", ttl_seconds=30 * DAY, memory_items=64),
        Store("live-module", ttl_seconds=30 * DAY),
    )
}


def cache_dir() -> Path:
    """Where disk entries live: ``$LAGRANGE_LAB_CACHE``, else ``~/.cache/lagrange-lab``.

    Read on every call, so tests (and a second deployment on the same machine) can point it
    elsewhere without reloading anything.
    """
    configured = os.environ.get(ENV_VAR)
    return Path(configured).expanduser() if configured else Path.home() / ".cache" / "lagrange-lab"


def key_for(store: str, key_parts: Any) -> str:
    """The key of the value ``key_parts`` define in ``store``: sha256 of canonical JSON.

    Canonical (sorted keys, no whitespace) so the same spec written in another order is the same
    entry; the store and the engine version are hashed in, so an engine change is a new key.
    """
    _store(store)
    canonical = json.dumps(
        {"store": store, "engine": ENGINE_VERSION, "parts": key_parts},
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
    return backend.computations(store) if isinstance(backend, _RedisBackend) else None


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
    header = {"format": FORMAT, "store": s.name, "key": key, "engine": ENGINE_VERSION}
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
    expected = {"format": FORMAT, "store": s.name, "key": key, "engine": ENGINE_VERSION}
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


class _Backend:
    """Where entries and locks live; every method swallows its own failures."""

    def read(self, s: Store, key: str) -> bytes | None: ...
    def write(self, s: Store, key: str, data: bytes) -> None: ...
    def acquire(self, s: Store, key: str) -> str | None: ...
    def release(self, s: Store, key: str, token: str) -> None: ...
    def locked(self, s: Store, key: str) -> bool: ...
    def counted(self, s: Store) -> None: ...


class _DiskBackend(_Backend):
    """One folder per store under `cache_dir()`; ``<key>.entry`` files and ``<key>.lock`` files."""

    HOST = socket.gethostname()
    PRUNE_EVERY = 32

    def __init__(self, root: Path) -> None:
        self.root = root

    def read(self, s: Store, key: str) -> bytes | None:
        path = self.root / s.name / f"{key}.entry"
        try:
            data = path.read_bytes()
        except FileNotFoundError:
            return None
        except OSError as exc:
            log.warning("cache: cannot read %s (%s); recomputing", path, exc)
            return None
        try:
            os.utime(path)  # recently used: pruned last
        except OSError:
            pass
        return data

    def write(self, s: Store, key: str, data: bytes) -> None:
        folder, tmp = self.root / s.name, None
        try:
            folder.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{key[:16]}.", suffix=".tmp")
            with os.fdopen(fd, "wb") as f:
                f.write(data)
            os.replace(tmp, folder / f"{key}.entry")  # atomic: readers see all or nothing
            tmp = None
        except OSError as exc:
            log.warning("cache: cannot write %s/%s (%s); carrying on without it", s.name, key, exc)
        finally:
            if tmp is not None:
                _unlink(Path(tmp))
        if (_tick(s.name) - 1) % self.PRUNE_EVERY == 0:  # the first write, then every 32nd
            self.prune(folder, _max_bytes())

    def prune(self, folder: Path, max_bytes: int) -> None:
        """Keep the store under ``max_bytes``: least recently used entries go first (and
        temporary files a killed writer left, once they are an hour old)."""
        try:
            entries = [(e.stat().st_mtime, e.stat().st_size, e.path) for e in os.scandir(folder)]
        except OSError:
            return
        now, total = time.time(), sum(size for _, size, _ in entries)
        for mtime, size, path in sorted(entries):
            if path.endswith(".tmp") and now - mtime > 3600:
                _unlink(Path(path))
            elif path.endswith(".entry") and total > max_bytes:
                _unlink(Path(path))
                total -= size

    def acquire(self, s: Store, key: str) -> str | None:
        lock = self.root / s.name / f"{key}.lock"
        token = uuid.uuid4().hex
        body = json.dumps({"token": token, "host": self.HOST, "pid": os.getpid()}).encode()
        for _ in range(2):
            try:
                lock.parent.mkdir(parents=True, exist_ok=True)
                fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
            except FileExistsError:
                if not self._stale(s, lock):
                    return None
                log.warning("cache: breaking the stale lock %s", lock)
                _unlink(lock)
                continue
            except OSError as exc:
                log.warning("cache: cannot lock %s (%s); computing unlocked", lock, exc)
                return token
            with os.fdopen(fd, "wb") as f:
                f.write(body)
            return token
        return None

    def release(self, s: Store, key: str, token: str) -> None:
        lock = self.root / s.name / f"{key}.lock"
        if _lock_owner(lock).get("token") == token:  # never someone else's lock
            _unlink(lock)

    def locked(self, s: Store, key: str) -> bool:
        lock = self.root / s.name / f"{key}.lock"
        return lock.exists() and not self._stale(s, lock)

    def _stale(self, s: Store, lock: Path) -> bool:
        """Older than the store's lock time, or its process on this host is gone (kill -9)."""
        try:
            age = time.time() - lock.stat().st_mtime
        except FileNotFoundError:
            return True
        if age > s.lock_seconds:
            return True
        owner = _lock_owner(lock)
        if owner.get("host") == self.HOST and isinstance(owner.get("pid"), int):
            try:
                os.kill(owner["pid"], 0)
            except ProcessLookupError:
                return True
            except OSError:
                pass
        return False


def _lock_owner(lock: Path) -> dict:
    try:
        owner = json.loads(lock.read_bytes())
    except (OSError, ValueError):
        return {}
    return owner if isinstance(owner, dict) else {}


class _RedisBackend(_Backend):
    """Entries as Redis strings with their store's TTL, locks as ``SET NX PX`` keys. Any Redis
    failure marks Redis down (logged once) and the same operation goes to the disk instead."""

    RELEASE = "if redis.call('get', KEYS[1]) == ARGV[1] then return redis.call('del', KEYS[1]) end"

    def __init__(self, client: Any, disk: _DiskBackend) -> None:
        self.client, self.disk = client, disk
        # a fixed Lua script (no user text), run by its SHA: the lock is deleted only by its owner
        self._release = client.register_script(self.RELEASE)

    def read(self, s: Store, key: str) -> bytes | None:
        return self._do(lambda: self.client.get(_rkey(s, key)), lambda: self.disk.read(s, key))

    def write(self, s: Store, key: str, data: bytes) -> None:
        ms = s.ttl_seconds * 1000
        self._do(
            lambda: self.client.set(_rkey(s, key), data, px=ms),
            lambda: self.disk.write(s, key, data),
        )

    def acquire(self, s: Store, key: str) -> str | None:
        token, ms = uuid.uuid4().hex, int(s.lock_seconds * 1000)
        return self._do(
            lambda: (
                token if self.client.set(_rkey(s, key, "lock"), token, nx=True, px=ms) else None
            ),
            lambda: self.disk.acquire(s, key),
        )

    def release(self, s: Store, key: str, token: str) -> None:
        self._do(
            lambda: self._release(keys=[_rkey(s, key, "lock")], args=[token]),
            lambda: self.disk.release(s, key, token),
        )

    def locked(self, s: Store, key: str) -> bool:
        return self._do(
            lambda: bool(self.client.exists(_rkey(s, key, "lock"))),
            lambda: self.disk.locked(s, key),
        )

    def counted(self, s: Store) -> None:
        self._do(lambda: self.client.incr(f"{REDIS_PREFIX}computed:{s.name}"), lambda: None)

    def computations(self, store: str) -> int | None:
        raw = self._do(
            lambda: self.client.get(f"{REDIS_PREFIX}computed:{store}") or 0, lambda: None
        )
        return None if raw is None else int(raw)

    def _do(self, redis_op: Callable[[], Any], disk_op: Callable[[], Any]) -> Any:
        import redis

        try:
            result = redis_op()
        except (redis.RedisError, OSError) as exc:
            _redis_failed(exc)
            return disk_op()
        if _redis_state["logged"]:
            _redis_state["logged"] = False
            log.warning("cache: Redis answers again; sharing through it")
        return result


def _rkey(s: Store, key: str, suffix: str = "") -> str:
    return f"{REDIS_PREFIX}{s.name}:{key}" + (f":{suffix}" if suffix else "")


_redis_state: dict[str, Any] = {"down_until": 0.0, "logged": False}
_redis_clients: dict[str, Any] = {}
_redis_guard = threading.Lock()


def _redis_up() -> bool:
    return time.monotonic() >= _redis_state["down_until"]


def _redis_failed(exc: BaseException) -> None:
    with _redis_guard:
        _redis_state["down_until"] = time.monotonic() + REDIS_RETRY_SECONDS
        if not _redis_state["logged"]:
            _redis_state["logged"] = True
            log.warning(
                "cache: Redis is unreachable (%s); using the local disk, retrying every %.0f s",
                exc,
                REDIS_RETRY_SECONDS,
            )


def _backend() -> _Backend:
    """Redis when ``$LAGRANGE_LAB_REDIS_URL`` is set and not known to be down, else the disk."""
    disk = _DiskBackend(cache_dir())
    url = os.environ.get(REDIS_ENV_VAR, "").strip()
    if not url or not _redis_up():
        return disk
    with _redis_guard:
        client = _redis_clients.get(url)
        if client is None:
            try:
                import redis

                client = redis.Redis.from_url(
                    url, socket_connect_timeout=1.0, socket_timeout=5.0, health_check_interval=30
                )
            except (ImportError, ValueError) as exc:
                client = None
                error = exc
            else:
                _redis_clients[url] = client
    if client is None:
        _redis_failed(error)
        return disk
    return _RedisBackend(client, disk)


_writes: Counter = Counter()


def _tick(store: str) -> int:
    with _stats_guard:
        _writes[store] += 1
        return _writes[store]


def _max_bytes() -> int:
    raw = os.environ.get(SIZE_ENV_VAR, "")
    try:
        mb = float(raw) if raw else DEFAULT_MB
    except ValueError:
        mb = DEFAULT_MB
    return int((mb if mb > 0 else DEFAULT_MB) * 1024 * 1024)


def _unlink(path: Path) -> None:
    try:
        path.unlink()
    except OSError:
        pass
