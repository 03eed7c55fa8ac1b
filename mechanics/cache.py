"""A tiny on-disk JSON cache for derivations, shared by every process that serves the app.

Deriving a built-in scene costs seconds of sympy; its result never changes until the engine does.
So the engine keeps results here under a key that includes its version, and a restart (or a second
uvicorn worker) starts warm. The cache is an optimisation only: any failure to read or write it is
logged and the caller simply computes the value again.

An entry is verified on read, never trusted: it records the engine version and key it was written
for, and the caller may pass a check of the value's shape. An entry from another version, for
another key, of another shape, or not JSON at all is ignored (and recomputed by the caller).

    >>> key = key_for({"scene": "simple_pendulum"}, version="1")
    >>> put(key, {"answer": 42}, version="1")
    >>> get(key, version="1")
    {'answer': 42}
    >>> get(key, version="2") is None
    True
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["cache_dir", "get", "put", "key_for"]

log = logging.getLogger(__name__)

ENV_VAR = "LAGRANGE_LAB_CACHE"


def cache_dir() -> Path:
    """Where entries live: ``$LAGRANGE_LAB_CACHE``, else ``~/.cache/lagrange-lab``.

    Read on every call, so tests (and a second deployment on the same machine) can point it
    elsewhere without reloading anything.
    """
    configured = os.environ.get(ENV_VAR)
    return Path(configured).expanduser() if configured else Path.home() / ".cache" / "lagrange-lab"


def key_for(obj: Any, version: str) -> str:
    """A stable name for ``obj`` as computed by engine ``version``: sha256 of canonical JSON.

    Canonical (sorted keys, no whitespace) so that the same spec written in a different order maps
    to the same entry; the version is hashed in so an engine change never serves stale results.
    """
    canonical = json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
    return hashlib.sha256(f"{version}\n{canonical}".encode()).hexdigest()


def get(key: str, *, version: str, valid: Callable[[dict], bool] | None = None) -> dict | None:
    """The value stored under ``key`` by engine ``version``, or None (never raises).

    None too when the entry is unreadable, was written by another version or for another key,
    or its value fails ``valid``: a stale or damaged entry is recomputed, never served.
    """
    try:
        with _path(key).open(encoding="utf-8") as f:
            entry = json.load(f)
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as exc:
        log.warning("cache: cannot read entry %s (%s); recomputing", key, exc)
        return None
    if not (
        isinstance(entry, dict)
        and entry.get("engine") == version
        and entry.get("key") == key
        and isinstance(entry.get("value"), dict)
    ):
        log.warning("cache: entry %s is not one of engine %s; recomputing", key, version)
        return None
    value = entry["value"]
    try:
        ok = valid is None or bool(valid(value))
    except Exception:  # a check that trips over a damaged value has answered: not valid
        ok = False
    if not ok:
        log.warning("cache: entry %s does not have the expected shape; recomputing", key)
        return None
    return value


def put(key: str, value: dict, *, version: str) -> None:
    """Store ``value`` under ``key``, as computed by engine ``version`` (never raises).

    Written to a temporary file in the same folder and moved into place with ``os.replace``, which
    is atomic: a reader in another worker sees the old entry or the new one, never half a file.
    """
    tmp: str | None = None
    try:
        path = _path(key)
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{key[:16]}.", suffix=".tmp")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            entry = {"engine": version, "key": key, "value": value}
            json.dump(entry, f, ensure_ascii=False, separators=(",", ":"), allow_nan=False)
        os.replace(tmp, path)
        tmp = None
    except (OSError, TypeError, ValueError) as exc:
        log.warning("cache: cannot write entry %s (%s); carrying on without it", key, exc)
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass


def _path(key: str) -> Path:
    # The key becomes a file name: refuse anything that could climb out of the cache folder.
    if not key or not all(c.isalnum() or c in "-_." for c in key) or key.startswith("."):
        raise ValueError(f"cache key must be a plain file name, got {key!r}")
    return cache_dir() / f"{key}.json"
