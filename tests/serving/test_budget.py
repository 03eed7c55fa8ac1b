"""The pool's budget: answers come back, runaway work is stopped, and nothing is left running."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

from mechanics.budget import BudgetExceeded
from mechanics.pool import WorkerLost, WorkerPool
from mechanics.spec import SpecError, parse_spec


@pytest.fixture(scope="module")
def pool():
    pool = WorkerPool(size=2, per_client=2).start()
    yield pool
    pool.close()


def alive(pid: int) -> bool:
    """Running (not merely a zombie waiting to be reaped)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (FileNotFoundError, ProcessLookupError):  # gone, or reaped while its stat was read
        return False


def test_returns_the_value_with_args_and_kwargs(pool):
    assert pool.run(int, "101010", base=2, seconds=10) == 42


def test_a_result_larger_than_a_pipe_buffer_arrives_whole(pool):
    text = pool.run(str.__mul__, "x", 3_000_000, seconds=10)
    assert len(text) == 3_000_000


def test_runaway_work_is_stopped_at_the_time_budget_and_its_worker_replaced(pool):
    before = set(pool.pids())
    start = time.monotonic()
    with pytest.raises(BudgetExceeded) as caught:
        pool.run(time.sleep, 60, seconds=1, what="sleeping")
    assert time.monotonic() - start < 2.5
    assert caught.value.kind == "time"
    assert "sleeping took longer than 1 s" in str(caught.value)
    after = set(pool.pids())
    assert len(after) == 2 and len(after - before) == 1
    assert not any(alive(pid) for pid in before - after)
    assert pool.run(abs, -3, seconds=10) == 3


def test_an_exception_comes_back_with_its_type_and_attributes(pool):
    with pytest.raises(ZeroDivisionError):
        pool.run(divmod, 1, 0, seconds=10)
    # SpecError's __init__ takes a list, not its message: plain pickling would fail to rebuild it.
    with pytest.raises(SpecError) as caught:
        pool.run(parse_spec, {"coordinates": ["x"], "bodies": "none"}, seconds=10)
    assert caught.value.errors and caught.value.errors[0]["field"].startswith("bodies")


def test_a_memory_hog_fails_cleanly_and_its_worker_is_replaced(pool):
    with pytest.raises(BudgetExceeded) as caught:
        pool.run(bytearray, 5 * 1024**3, seconds=30)
    assert caught.value.kind == "size"
    assert "GiB" in str(caught.value)
    assert pool.run(len, "abc", seconds=10) == 3


def test_a_worker_killed_mid_job_is_reported_and_replaced(pool):
    killed = pool.pids()

    def kill_the_busy_worker() -> None:
        time.sleep(0.5)
        for pid in killed:
            os.kill(pid, signal.SIGKILL)

    threading.Thread(target=kill_the_busy_worker).start()
    with pytest.raises(WorkerLost, match="killed by signal 9"):
        pool.run(time.sleep, 30, seconds=20)
    while any(alive(pid) for pid in killed):  # SIGKILL lands at once, but not in no time
        time.sleep(0.05)
    assert pool.run(abs, -1, seconds=10) == 1  # an idle worker that was killed too: replaced
    assert pool.run(abs, -2, seconds=10) == 2
    assert len(pool.pids()) == 2


def test_safe_to_call_from_many_threads_at_once(pool):
    results: dict[int, int] = {}

    def call(i: int) -> None:
        results[i] = pool.run(pow, i, 2, seconds=30, client=f"c{i % 3}")

    threads = [threading.Thread(target=call, args=(i,)) for i in range(16)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results == {i: i * i for i in range(16)}


def test_one_clients_queue_does_not_delay_another_client():
    pool = WorkerPool(size=2, per_client=1).start()
    try:
        done: dict[str, float] = {}
        start = time.monotonic()

        def heavy(i: int) -> None:
            try:
                pool.run(time.sleep, 1.5, seconds=20, client="heavy")
            finally:
                done[f"heavy{i}"] = time.monotonic() - start

        threads = [threading.Thread(target=heavy, args=(i,)) for i in range(4)]
        for t in threads:
            t.start()
        time.sleep(0.3)  # the heavy client's jobs are queued first
        assert pool.run(abs, -7, seconds=20, client="honest") == 7
        quick = time.monotonic() - start
        for t in threads:
            t.join()
        assert quick < 2.0, (quick, done)
        # the heavy client's own jobs ran one at a time, one after the other
        assert sorted(done.values())[-1] > 4 * 1.5 - 0.3, done
    finally:
        pool.close()


def test_a_job_that_cannot_start_within_its_budget_is_refused_with_the_reason():
    pool = WorkerPool(size=1, per_client=1).start()
    try:
        threading.Thread(target=lambda: pool.run(time.sleep, 2, seconds=10, client="a")).start()
        time.sleep(0.3)
        with pytest.raises(BudgetExceeded, match="you already have 1 request running"):
            pool.run(abs, 1, seconds=0.5, client="a")
        with pytest.raises(BudgetExceeded, match="the server is busy"):
            pool.run(abs, 1, seconds=0.5, client="b")
        assert pool.run(abs, -1, seconds=10, client="b") == 1  # once the worker is free again
    finally:
        pool.close()


def test_close_leaves_no_process_behind():
    pool = WorkerPool(size=2).start()
    pids = pool.pids()
    assert all(alive(pid) for pid in pids)
    pool.close()
    assert not any(alive(pid) for pid in pids)
    with pytest.raises(WorkerLost):
        pool.run(abs, 1, seconds=1)
