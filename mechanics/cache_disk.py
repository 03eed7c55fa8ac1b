"""The cache's local disk: entries, lock files, and what a disk that cannot write costs.

Why a module of its own: a cache is an optimisation, so a full, read-only or over-quota disk
must only cost speed. Every write here (an entry, a lock) sits inside the error handling; the
first failure is logged once, marks the disk unwritable for `RETRY_SECONDS` (entries are not
written and computations are not locked across processes meanwhile: each process answers from
its computation and its memory), and the next write after that tries again.

Lock files are never empty: the owner's record (token, host, pid, deadline) is written to a
temporary file which is then hard-linked to ``<key>.lock``, so the lock appears with its content
or not at all. A lock is stale, and broken at once, when it is empty or unreadable (a writer of
the old format that died, a disk that filled mid-write), when its deadline or the store's lock
time has passed, or when its owner was a process of this host that is gone.
"""

from __future__ import annotations

import errno
import json
import logging
import os
import socket
import tempfile
import threading
import time
import uuid
from collections import Counter
from pathlib import Path
from typing import Any

log = logging.getLogger("mechanics.cache")

SIZE_ENV_VAR = "LAGRANGE_LAB_CACHE_MB"
DEFAULT_MB = 256
#: After a write failed, the disk is not written for this long; then one write tries again.
RETRY_SECONDS = 30.0

#: Shared by the process: until when the disk is known unwritable, and whether that was logged.
_state: dict[str, Any] = {"down_until": 0.0, "logged": False}
_guard = threading.Lock()
_writes: Counter = Counter()

#: errnos of a file system that cannot make hard links: lock files are then made with O_EXCL.
_NO_LINKS = {errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EMLINK, errno.EXDEV}


def writable() -> bool:
    """False while the disk is known unwritable (a recent write failed), else True."""
    return time.monotonic() >= _state["down_until"]


def _failed(what: str, exc: OSError) -> None:
    """A write failed: log once per outage, stop writing for `RETRY_SECONDS`."""
    with _guard:
        _state["down_until"] = time.monotonic() + RETRY_SECONDS
        first = not _state["logged"]
        _state["logged"] = True
    if first:
        log.warning(
            "cache: cannot write %s to the disk cache (%s); answering without it, "
            "retrying in %.0f s",
            what,
            exc.strerror or exc,
            RETRY_SECONDS,
        )


def _succeeded() -> None:
    if _state["logged"]:
        with _guard:
            _state["logged"] = False
        log.warning("cache: the disk cache is writable again")


class DiskBackend:
    """One folder per store under the cache folder; ``<key>.entry`` and ``<key>.lock`` files.

    Stores are objects with ``name`` and ``lock_seconds`` (mechanics.cache.Store)."""

    HOST = socket.gethostname()
    PRUNE_EVERY = 32

    def __init__(self, root: Path) -> None:
        self.root = root

    def read(self, s: Any, key: str) -> bytes | None:
        path = self.root / s.name / f"{key}.entry"
        try:
            data = path.read_bytes()
        except FileNotFoundError:
            return None
        except OSError as exc:
            log.warning("cache: cannot read a %s entry (%s); recomputing", s.name, exc.strerror)
            return None
        try:
            os.utime(path)  # recently used: pruned last
        except OSError:
            pass
        return data

    def write(self, s: Any, key: str, data: bytes) -> None:
        if not writable():
            return
        folder, tmp = self.root / s.name, None
        try:
            folder.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{key[:16]}.", suffix=".tmp")
            with os.fdopen(fd, "wb") as f:
                f.write(data)
            os.replace(tmp, folder / f"{key}.entry")  # atomic: readers see all or nothing
            tmp = None
        except OSError as exc:
            _failed(f"an entry of {s.name}", exc)
            return
        finally:
            if tmp is not None:
                _unlink(Path(tmp))
        _succeeded()
        if (_tick(s.name) - 1) % self.PRUNE_EVERY == 0:  # the first write, then every 32nd
            self.prune(folder, max_bytes())

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

    def acquire(self, s: Any, key: str) -> str | None:
        """A token when this process may compute (the lock is ours, or the disk cannot hold a
        lock: then it computes unlocked), None when a live lock is someone else's."""
        token = uuid.uuid4().hex
        if not writable():
            return token
        lock = self.root / s.name / f"{key}.lock"
        record = {"token": token, "host": self.HOST, "pid": os.getpid()}
        body = json.dumps(record | {"until": time.time() + s.lock_seconds}).encode()
        for _ in range(2):
            try:
                lock.parent.mkdir(parents=True, exist_ok=True)
                _create(lock, body)
            except FileExistsError:
                if not self.stale(s, lock):
                    return None
                log.warning("cache: breaking a stale %s lock", s.name)
                _unlink(lock)
                continue
            except OSError as exc:
                _failed(f"a lock of {s.name}", exc)
                return token
            return token
        return None

    def release(self, s: Any, key: str, token: str) -> None:
        lock = self.root / s.name / f"{key}.lock"
        if lock_owner(lock).get("token") == token:  # never someone else's lock
            _unlink(lock)

    def locked(self, s: Any, key: str) -> bool:
        lock = self.root / s.name / f"{key}.lock"
        return lock.exists() and not self.stale(s, lock)

    def counted(self, s: Any) -> None:
        """Computations are counted across servers only in Redis."""

    def stale(self, s: Any, lock: Path) -> bool:
        """Empty or unreadable, past its deadline or the store's lock time, or its process on
        this host is gone (kill -9)."""
        try:
            age = time.time() - lock.stat().st_mtime
        except FileNotFoundError:
            return True
        except OSError:
            return False
        owner = lock_owner(lock)
        if not owner or age > s.lock_seconds:
            return True
        until = owner.get("until")
        if isinstance(until, (int, float)) and time.time() > until:
            return True
        if owner.get("host") == self.HOST and isinstance(owner.get("pid"), int):
            try:
                os.kill(owner["pid"], 0)
            except ProcessLookupError:
                return True
            except OSError:
                pass
        return False


def _create(lock: Path, body: bytes) -> None:
    """Make ``lock`` holding ``body``, atomically, or raise FileExistsError if it exists."""
    fd, tmp = tempfile.mkstemp(dir=lock.parent, prefix=".lock-", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(body)
        try:
            os.link(tmp, lock)  # appears whole or not at all; EEXIST if someone holds it
            return
        except FileExistsError:
            raise
        except OSError as exc:
            if exc.errno not in _NO_LINKS:
                raise
        fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(body)
        except OSError:
            _unlink(lock)  # never leave an empty lock behind
            raise
    finally:
        _unlink(Path(tmp))


def lock_owner(lock: Path) -> dict:
    """The record a lock file holds, or {} (missing, empty, not JSON)."""
    try:
        owner = json.loads(lock.read_bytes())
    except (OSError, ValueError):
        return {}
    return owner if isinstance(owner, dict) else {}


def max_bytes() -> int:
    """Each store's bound: ``$LAGRANGE_LAB_CACHE_MB`` (256 MB when unset or not a number)."""
    raw = os.environ.get(SIZE_ENV_VAR, "")
    try:
        mb = float(raw) if raw else DEFAULT_MB
    except ValueError:
        mb = DEFAULT_MB
    return int((mb if mb > 0 else DEFAULT_MB) * 1024 * 1024)


def _tick(store: str) -> int:
    with _guard:
        _writes[store] += 1
        return _writes[store]


def _unlink(path: Path) -> None:
    try:
        path.unlink()
    except OSError:
        pass
