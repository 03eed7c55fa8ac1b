"""What a budget is, and what happens past it: the refusal, the memory cap, exceptions that travel.

A spec or an answer can be small and still make sympy grind for minutes or swell to gigabytes; a
thread cannot be stopped, a process can. The work runs in a warm worker process (mechanics/pool.py)
which is killed at the time cap; the memory cap is the worker's address-space limit, set afresh
for each job, so a job past it fails with MemoryError inside the worker, reported as
``BudgetExceeded("size", ...)``.

    >>> str(BudgetExceeded("time", "derivation took longer than 20 s"))
    'derivation took longer than 20 s'
"""

from __future__ import annotations

import pickle
import resource
from typing import Any, Literal

__all__ = ["BudgetExceeded", "DEFAULT_MEMORY_BYTES", "limit_memory", "lift_memory_limit"]

#: Address space one job may add to what its worker holds when it starts: generous for any honest
#: scene or answer.
DEFAULT_MEMORY_BYTES = 2 * 1024**3


class BudgetExceeded(RuntimeError):
    """Work refused for costing too much: ``kind`` says which budget ("time" or "size")."""

    def __init__(self, kind: Literal["time", "size"], message: str, field: str = "scene") -> None:
        self.kind = kind
        self.message = message
        self.field = field  # what the client should change: the scene, or a check's answer
        super().__init__(kind, message)

    def __str__(self) -> str:
        return self.message

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.kind, self.message, self.field))


def limit_memory(extra_bytes: int) -> None:
    """Cap this process's address space at what it holds now plus ``extra_bytes``.

    Counting from the current size (not from zero) keeps a worker with a large virtual footprint
    (thread stacks, BLAS buffers, its caches) from being unable to allocate anything at all, and
    gives every job the same headroom however much earlier jobs cached.
    """
    try:
        with open("/proc/self/statm") as f:
            current = int(f.read().split()[0]) * resource.getpagesize()
    except OSError:  # no /proc (macOS): count from zero, the cap still applies
        current = 0
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    limit = current + extra_bytes
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    resource.setrlimit(resource.RLIMIT_AS, (limit, hard))


def lift_memory_limit() -> None:
    """Back to the hard limit between jobs (the soft limit may be raised up to it again)."""
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    resource.setrlimit(resource.RLIMIT_AS, (hard, hard))


def portable(exc: BaseException) -> tuple[type, tuple, dict]:
    """An exception as (type, args, attributes): survives classes whose __init__ takes other
    arguments than their ``args`` (plain pickling calls ``type(*args)`` and breaks on those)."""
    state = (type(exc), exc.args, dict(vars(exc)))
    try:
        pickle.loads(pickle.dumps(state))
        return state
    except Exception:  # a class defined in a function, an unpicklable attribute, ...
        return (RuntimeError, (f"{type(exc).__name__}: {exc}",), {})


def rebuild(state: tuple[type, tuple, dict]) -> BaseException:
    """The exception `portable` described, with its type and attributes."""
    cls, args, attributes = state
    exc = cls.__new__(cls, *args)
    exc.args = args
    exc.__dict__.update(attributes)
    return exc
