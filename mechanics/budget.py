"""Run untrusted work (a posted scene's derivation) in a child process with a time and memory cap.

A spec can be small and still make sympy grind for minutes or swell to gigabytes; a thread cannot be
stopped, a process can. The child is forked, so it inherits the already-imported engine (sympy
costs a second to import) and starts in milliseconds; its result comes back pickled through a pipe.

    >>> run_with_budget(pow, 2, 10, seconds=5)
    1024
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
import resource
import signal
import threading
import time
import traceback
from collections.abc import Callable
from multiprocessing.connection import Connection
from typing import Any, Literal, TypeVar

__all__ = ["BudgetExceeded", "run_with_budget", "DEFAULT_MEMORY_BYTES"]

#: Address space the child may add to what it inherits: generous for any honest scene.
DEFAULT_MEMORY_BYTES = 2 * 1024**3
#: After SIGTERM, how long the child gets before SIGKILL.
_GRACE_SECONDS = 1.0

_FORK = multiprocessing.get_context("fork")
#: multiprocessing's bookkeeping of children is not thread-safe; routes run in a threadpool.
_START_LOCK = threading.Lock()
#: At most one derivation per core at once, so a burst of posts cannot take every core and
#: every gigabyte; the rest queue, and the time queued counts against their own budget.
_SLOTS = threading.BoundedSemaphore(max(1, os.cpu_count() or 1))

T = TypeVar("T")


class BudgetExceeded(RuntimeError):
    """Work refused for costing too much: ``kind`` says which budget ("time" or "size")."""

    def __init__(self, kind: Literal["time", "size"], message: str) -> None:
        self.kind = kind
        self.message = message
        super().__init__(kind, message)

    def __str__(self) -> str:
        return self.message

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.kind, self.message))


def run_with_budget(
    fn: Callable[..., T],
    *args: Any,
    seconds: float,
    memory_bytes: int = DEFAULT_MEMORY_BYTES,
    **kwargs: Any,
) -> T:
    """Return ``fn(*args, **kwargs)`` computed in a forked child, or raise.

    Raises BudgetExceeded("time") past ``seconds`` (the child is terminated, then killed, and
    always reaped), BudgetExceeded("size") if the child runs out of its ``memory_bytes``, and
    otherwise re-raises whatever the child raised, with its type and attributes intact.
    """
    deadline = time.monotonic() + seconds
    if not _SLOTS.acquire(timeout=seconds):
        raise BudgetExceeded("time", f"the server is busy: no derivation slot within {seconds:g} s")
    try:
        return _run_in_child(fn, args, kwargs, seconds, deadline, memory_bytes)
    finally:
        _SLOTS.release()


def _run_in_child(
    fn: Callable[..., T],
    args: tuple,
    kwargs: dict,
    seconds: float,
    deadline: float,
    memory_bytes: int,
) -> T:
    receiver, sender = _FORK.Pipe(duplex=False)
    child = _FORK.Process(
        target=_child_main, args=(sender, memory_bytes, fn, args, kwargs), daemon=True
    )
    payload, answered = None, False
    try:
        with _START_LOCK:
            child.start()
        sender.close()  # only the child writes: its exit then reads as EOF here
        answered = receiver.poll(max(0.0, deadline - time.monotonic()))
        if not answered:
            raise BudgetExceeded(
                "time",
                f"derivation took longer than {seconds:g} s; simplify the scene "
                "(fewer coordinates or bodies, simpler expressions) and try again",
            )
        try:
            payload = receiver.recv_bytes()
        except EOFError:
            pass  # it died without a word: reported below, once its exit code is known
    finally:
        receiver.close()
        exitcode = _reap(child, patience=_GRACE_SECONDS if answered else 0.0)
    if payload is None:
        raise RuntimeError(f"derivation process died without an answer (exit code {exitcode})")
    status, value = pickle.loads(payload)
    if status == "ok":
        return value
    raise _rebuild(value)


def _reap(child: Any, patience: float) -> int | None:
    """Wait ``patience`` s for the child to exit, then terminate (and kill) it, and reap it, so no
    zombie outlives the call. Returns its exit code.

    Under the start lock: ``Process.start`` polls every other child, and two threads waiting on
    the same pid at once would leave one of them unsure whether it exited.
    """
    with _START_LOCK:
        child.join(patience)
        if child.is_alive():
            child.terminate()
            child.join(_GRACE_SECONDS)
            if child.is_alive():
                child.kill()
        child.join()
        exitcode = child.exitcode
        child.close()
    return exitcode


def _child_main(
    sender: Connection, memory_bytes: int, fn: Callable[..., Any], args: tuple, kwargs: dict
) -> None:
    # The parent may be uvicorn, whose SIGTERM handler only asks the server to stop: restore the
    # default so that terminate() ends this child.
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        _limit_memory(memory_bytes)
        payload = pickle.dumps(("ok", fn(*args, **kwargs)), pickle.HIGHEST_PROTOCOL)
    except MemoryError:
        error = BudgetExceeded(
            "size",
            f"derivation needed more than {memory_bytes / 1024**3:g} GiB of memory; "
            "simplify the scene and try again",
        )
        payload = pickle.dumps(("error", _portable(error)))
    except BaseException as exc:  # everything, even SystemExit, goes back to the parent
        exc.add_note("in the budgeted child process:\n" + traceback.format_exc())
        payload = pickle.dumps(("error", _portable(exc)))
    sender.send_bytes(payload)
    sender.close()


def _limit_memory(extra_bytes: int) -> None:
    """Cap the address space at what the fork inherited plus ``extra_bytes``.

    Counting from the inherited size (not from zero) keeps a parent with a large virtual footprint
    (thread stacks, BLAS buffers) from leaving its child unable to allocate anything at all.
    """
    try:
        with open("/proc/self/statm") as f:
            inherited = int(f.read().split()[0]) * resource.getpagesize()
    except OSError:  # no /proc (macOS): count from zero, the cap still applies
        inherited = 0
    limit = inherited + extra_bytes
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    resource.setrlimit(resource.RLIMIT_AS, (limit, hard))


def _portable(exc: BaseException) -> tuple[type, tuple, dict]:
    """An exception as (type, args, attributes): survives classes whose __init__ takes other
    arguments than their ``args`` (plain pickling calls ``type(*args)`` and breaks on those)."""
    state = (type(exc), exc.args, dict(vars(exc)))
    try:
        pickle.loads(pickle.dumps(state))
        return state
    except Exception:  # a class defined in a function, an unpicklable attribute, ...
        return (RuntimeError, (f"{type(exc).__name__}: {exc}",), {})


def _rebuild(state: tuple[type, tuple, dict]) -> BaseException:
    cls, args, attributes = state
    exc = cls.__new__(cls, *args)
    exc.args = args
    exc.__dict__.update(attributes)
    return exc
