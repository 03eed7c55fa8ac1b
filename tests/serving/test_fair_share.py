"""A client's fair share of CPU over time, not only of concurrent jobs (issue 24, item 1).

Four clients posting heavy specs one after another kept both pool workers busy with 20 s jobs,
one each (the per-client limit held), and every student's answer check, with its 5 s budget,
waited behind them and failed. The ledger (mechanics/fair_share.py) charges each job's CPU time to
its client; clients in debt wait behind clients with credit and may not take the last free place.

Expectations are stated from the rule itself: a token bucket of ``capacity`` CPU-seconds refilled
at ``rate`` per second, debtors after creditors, the smallest debt first, one place kept.
"""

from __future__ import annotations

import threading
import time
import zlib

import pytest

from app.derivations import FairGate
from mechanics.fair_share import CpuLedger, reserve_for, thread_cpu
from mechanics.pool import WorkerPool


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_a_bucket_pays_refills_at_its_rate_and_never_past_its_capacity():
    clock = Clock()
    ledger = CpuLedger(capacity=4.0, rate=0.5, clock=clock)
    assert ledger.balance("a") == 4.0  # a new client starts with a full bucket
    ledger.charge("a", 10.0)
    assert ledger.balance("a") == pytest.approx(-6.0)
    clock.now += 4.0  # 4 s × 0.5 CPU-s/s = 2 CPU-s earned back
    assert ledger.balance("a") == pytest.approx(-4.0) and ledger.in_debt("a")
    clock.now += 8.0
    assert ledger.balance("a") == pytest.approx(0.0) and not ledger.in_debt("a")
    clock.now += 1000.0
    assert ledger.balance("a") == 4.0
    ledger.charge("a", -3.0)  # nothing is earned by a negative charge
    assert ledger.balance("a") == 4.0


def test_waiting_work_goes_creditors_first_in_arrival_order_then_the_smallest_debt():
    ledger = CpuLedger(capacity=1.0, rate=0.0, clock=Clock())
    ledger.charge("heavy", 30.0)
    ledger.charge("medium", 5.0)
    ledger.charge("light", 0.5)  # still 0.5 s of credit
    queue = ["heavy", "s1", "medium", "light", "s2"]
    assert ledger.ordered(queue) == ["s1", "light", "s2", "medium", "heavy"]
    tickets = [(object(), c) for c in queue]  # the pool's (ticket, client) pairs
    assert [c for _, c in ledger.ordered(tickets, key=lambda w: w[1])][:3] == ["s1", "light", "s2"]


def test_a_client_in_debt_may_not_take_the_reserved_place():
    ledger = CpuLedger(capacity=1.0, rate=0.0, clock=Clock())
    ledger.charge("poster", 20.0)
    assert reserve_for(1) == 0 and reserve_for(2) == 1 and reserve_for(4) == 1
    assert ledger.may_take("poster", free=2, reserve=1)
    assert not ledger.may_take("poster", free=1, reserve=1)
    assert ledger.may_take("student", free=1, reserve=1)
    assert ledger.may_take("poster", free=1, reserve=0)  # a single place is never kept idle
    assert "20 s of CPU" in ledger.describe("poster") or "21 s of CPU" in ledger.describe("poster")
    assert ledger.describe("student") == ""


def test_a_threads_cpu_time_is_charged_not_its_sleep():
    ledger = CpuLedger(capacity=0.0, rate=0.0, clock=Clock())

    def work() -> int:
        time.sleep(0.3)  # waiting costs no CPU
        end = time.thread_time() + 0.1
        while time.thread_time() < end:
            pass
        return 7

    assert thread_cpu(work, "a", ledger) == 7
    assert 0.09 <= -ledger.balance("a") < 0.25


def _spin(seconds: float) -> float:
    """A pool job: burn ``seconds`` of CPU, return what it burned."""
    start = time.process_time()
    while time.process_time() - start < seconds:
        pass
    return time.process_time() - start


def _sleep(seconds: float) -> float:
    time.sleep(seconds)
    return seconds


@pytest.fixture
def pool():
    """Two workers, each of which has already imported this module (the first job a worker runs
    from a test module imports it: seconds of CPU, charged to a client of its own here)."""
    ledger = CpuLedger(capacity=5.0, rate=0.0)
    pool = WorkerPool(size=2, per_client=1, preload=(), ledger=ledger).start()
    for slot in range(2):
        key = next(f"k{i}" for i in range(100) if zlib.crc32(f"k{i}".encode()) % 2 == slot)
        pool.run(_sleep, 0.0, seconds=60, client="warm-up", affinity=key)
    yield pool
    pool.close()


def test_the_pool_charges_each_job_its_cpu_time(pool):
    pool.run(_spin, 0.3, seconds=20, client="spinner")
    pool.run(_sleep, 0.3, seconds=20, client="sleeper")
    assert 4.5 <= pool.ledger.balance("spinner") <= 4.75  # 5 of credit, 0.3 (+ overhead) used
    assert pool.ledger.balance("sleeper") > 4.9  # a sleeping job costs (almost) nothing


def test_posters_in_debt_leave_a_worker_for_a_student(pool):
    """Four posters in debt keep resubmitting 2 s jobs, one running each at most: without the
    reserve they hold both workers and a student's job waits up to a whole job; with it, the
    student's starts on the kept worker at once."""
    for poster in ("p1", "p2", "p3", "p4"):
        pool.ledger.charge(poster, 30.0)
    stop = time.monotonic() + 4.5

    def poster(name: str) -> None:
        while time.monotonic() < stop:
            try:
                pool.run(_sleep, 2.0, seconds=10, client=name)
            except Exception:  # noqa: BLE001 — a refused job just tries again
                time.sleep(0.05)

    threads = [threading.Thread(target=poster, args=(p,)) for p in ("p1", "p2", "p3", "p4")]
    for t in threads:
        t.start()
    time.sleep(0.5)  # the posters are in (one running, three waiting)
    waits = []
    for _ in range(4):
        start = time.monotonic()
        pool.run(_sleep, 0.05, seconds=10, client="student")
        waits.append(time.monotonic() - start - 0.05)
        time.sleep(0.3)
    for t in threads:
        t.join()
    assert max(waits) < 0.6, waits  # a round trip to an idle worker, not a 2 s job's wait


def test_the_gate_of_in_process_runs_keeps_a_place_from_clients_in_debt():
    import asyncio

    ledger = CpuLedger(capacity=0.5, rate=0.0)
    ledger.charge("poster", 30.0)
    gate = FairGate(total=2, per_client=1, ledger=ledger)
    order: list[str] = []

    async def main() -> None:
        async def hold(client: str, seconds: float) -> None:
            async with gate.turn(client, 5.0, "run"):
                order.append(client)
                await asyncio.sleep(seconds)

        first = asyncio.create_task(hold("other", 0.5))  # takes one of the two places
        await asyncio.sleep(0.05)
        debtor = asyncio.create_task(hold("poster", 0.1))  # may not take the last place
        await asyncio.sleep(0.1)
        assert order == ["other"]
        await hold("student", 0.0)  # the kept place: at once
        assert order == ["other", "student"]
        await asyncio.gather(first, debtor)
        assert order == ["other", "student", "poster"]  # once the other's run ended

    asyncio.run(main())
