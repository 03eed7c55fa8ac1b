"""run_with_budget: answers come back, runaway work is stopped, and nothing is left running."""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
import time

import pytest

from mechanics.budget import BudgetExceeded, run_with_budget
from mechanics.spec import SpecError


def add(a: int, b: int = 0) -> int:
    return a + b


def sleep_then_return(seconds: float) -> str:
    time.sleep(seconds)
    return "woke"


def raise_spec_error() -> None:
    raise SpecError([{"field": "bodies[0].mass", "message": "unknown name 'M'"}])


def allocate(gib: int) -> int:
    return len(bytearray(gib * 1024**3))


def die_silently() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


@pytest.fixture(autouse=True)
def no_children_left():
    yield
    assert multiprocessing.active_children() == []


def test_returns_the_value_with_args_and_kwargs():
    assert run_with_budget(add, 2, b=40, seconds=10) == 42


def test_a_result_larger_than_a_pipe_buffer_arrives_whole():
    text = run_with_budget(str.__mul__, "x", 3_000_000, seconds=10)
    assert len(text) == 3_000_000


def test_runaway_work_is_stopped_at_the_time_budget():
    start = time.monotonic()
    with pytest.raises(BudgetExceeded) as caught:
        run_with_budget(sleep_then_return, 60, seconds=1)
    assert time.monotonic() - start < 2.5
    assert caught.value.kind == "time"
    assert "longer than 1 s" in str(caught.value)


def test_the_child_stops_at_once_even_if_the_parent_ignores_sigterm():
    # uvicorn's SIGTERM handler only asks the server to stop; a forked child must not inherit that
    # and live on until the SIGKILL that follows the 1 s grace period.
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: None)
    try:
        start = time.monotonic()
        with pytest.raises(BudgetExceeded):
            run_with_budget(sleep_then_return, 60, seconds=0.2)
        assert time.monotonic() - start < 0.9
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_an_exception_comes_back_with_its_type_and_attributes():
    with pytest.raises(ZeroDivisionError):
        run_with_budget(divmod, 1, 0, seconds=10)
    # SpecError's __init__ takes a list, not its message: plain pickling would fail to rebuild it.
    with pytest.raises(SpecError) as caught:
        run_with_budget(raise_spec_error, seconds=10)
    assert caught.value.errors == [{"field": "bodies[0].mass", "message": "unknown name 'M'"}]


def test_a_memory_hog_fails_cleanly_instead_of_taking_the_machine():
    with pytest.raises(BudgetExceeded) as caught:
        run_with_budget(allocate, 5, seconds=30)
    assert caught.value.kind == "size"
    assert "GiB" in str(caught.value)


def test_a_child_that_dies_without_answering_is_reported():
    with pytest.raises(RuntimeError, match="died without an answer"):
        run_with_budget(die_silently, seconds=10)


def test_safe_to_call_from_many_threads_at_once():
    results: dict[int, int] = {}

    def call(i: int) -> None:
        results[i] = run_with_budget(add, i, b=1, seconds=30)

    threads = [threading.Thread(target=call, args=(i,)) for i in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results == {i: i + 1 for i in range(8)}
