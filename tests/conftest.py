"""Shared test setup: the tests never read or write the user's own derivation cache, and the tests
that time themselves run last and alone when the suite is spread over workers (`-n 2`)."""

from __future__ import annotations

import os
import shutil
import tempfile

import pytest

_saved: dict[str, str | None] = {}
_owned: list[str] = []
#: The session's cache folder, as the controller made it (read by xdist workers).
_SESSION_CACHE = "LAGRANGE_LAB_TEST_SESSION_CACHE"


def pytest_configure(config: pytest.Config) -> None:
    # At configure time, before collection, so even import-time code sees the private folder.
    # One folder per test session: the xdist controller makes it, its workers (and the servers and
    # pool workers they start) inherit it through the environment, so a scene derived and compiled
    # by one process is read by the others instead of being derived again in each.
    _saved["LAGRANGE_LAB_CACHE"] = os.environ.get("LAGRANGE_LAB_CACHE")
    inherited = os.environ.get(_SESSION_CACHE) if hasattr(config, "workerinput") else None
    if inherited and os.path.isdir(inherited):
        os.environ["LAGRANGE_LAB_CACHE"] = inherited
    else:
        folder = tempfile.mkdtemp(prefix="lagrange-lab-cache-")
        os.environ["LAGRANGE_LAB_CACHE"] = folder
        os.environ[_SESSION_CACHE] = folder
        _owned.append(folder)
    # The servers tests start do not warm every scene in the background (2 cores: it would slow
    # every other test); tests/serving/test_warm_up.py switches it on where it is the subject.
    os.environ.setdefault("LAGRANGE_LAB_WARM", "0")


def pytest_unconfigure(config: pytest.Config) -> None:
    for folder in _owned:  # only the process that made the session's folder removes it
        shutil.rmtree(folder, ignore_errors=True)
    if _saved.get("LAGRANGE_LAB_CACHE") is None:
        os.environ.pop("LAGRANGE_LAB_CACHE", None)
    else:
        os.environ["LAGRANGE_LAB_CACHE"] = _saved["LAGRANGE_LAB_CACHE"]


#: Tests that hold a wall clock to a bound tight enough (a second or a few) that a second worker
#: running beside them on a 2-core machine could break it: a false alarm, not a slow server. They
#: are marked `serial`; under pytest-xdist they run after every other test, on one worker, with
#: the other one stopped. Named by node id (prefix), so the scheduler in the controller, which
#: collects nothing, knows them too.
SERIAL = (
    "tests/api/test_simulate_fairness.py::test_a_flood_from_one_client_neither_fails_nor_delays",
    "tests/serving/test_budget.py::test_runaway_work_is_stopped_at_the_time_budget",
    "tests/serving/test_budget.py::test_one_clients_queue_does_not_delay_another_client",
    "tests/serving/test_pool.py::test_one_clients_heavy_requests_do_not_delay_another_client",
    "tests/serving/test_pool.py::test_hostile_answers_are_refused_within_the_budget",
    "tests/numerics/test_fixed_step.py::test_a_finite_time_blow_up_is_told_as_one",
    "tests/api/test_api.py::test_a_100_kb_expression_is_refused_fast",
    "tests/numerics/test_integrators.py::test_stiff_linear_problem_is_solved_quickly",
    "tests/answers/test_check_proofs.py::"
    "test_an_undecidable_hostile_answer_is_refused_a_proof_quickly",
    "tests/browser/test_live.py::test_a_drag_keeps_sixty_frames_a_second",
    "tests/browser/test_live.py::test_a_slider_input_is_drawn_within_a_few_frames",
    "tests/browser/test_drag3d.py::test_a_3d_drag_keeps_sixty_frames_a_second",
    # the installed server's runs wait at most a few seconds for their turn, then answer 503 (its
    # browser test saw four 503s beside a browser worker, load 13-20); the whole module, so its
    # wheel and venv are built once
    "tests/install/test_install.py::",
)


def is_serial(nodeid: str) -> bool:
    return nodeid.startswith(SERIAL)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if is_serial(item.nodeid):
            item.add_marker(pytest.mark.serial)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log):  # noqa: ANN201 (xdist's types)
    """xdist's `load` scheduling, the `serial` tests held back to the end (see `SERIAL`)."""
    if config.getvalue("dist") != "load":
        return None
    from xdist.scheduler import LoadScheduling

    class SerialLast(LoadScheduling):
        """Every other test is shared out as usual; the first worker to run dry is shut down, and
        the last one, once it is alone, gets the held tests."""

        held: list[int] = []  # noqa: RUF012 (replaced per instance in schedule)

        def schedule(self) -> None:
            if self.collection is not None or not self._check_nodes_have_same_collection():
                return super().schedule()  # a later call, or xdist's own refusal to go on
            self.collection = next(iter(self.node2collection.values()))
            self.held = [i for i, nodeid in enumerate(self.collection) if is_serial(nodeid)]
            held = set(self.held)
            self.pending[:] = [i for i in range(len(self.collection)) if i not in held]
            if self.maxschedchunk is None:
                self.maxschedchunk = len(self.collection)
            # as xdist's first share: a quarter of each worker's part, in collection order
            chunk = max(2, min(len(self.pending) // len(self.nodes) // 4, self.maxschedchunk))
            for node in self.nodes:
                self._send_tests(node, chunk)
            for node in self.nodes:
                self.check_schedule(node)
            return None

        @property
        def tests_finished(self) -> bool:
            return not self.held and super().tests_finished

        def check_schedule(self, node, duration: float = 0) -> None:
            if node.shutting_down or self.pending or not self.held:
                return super().check_schedule(node, duration)
            if len(self.node2pending[node]) >= 2:
                return None  # still busy with its share
            others = [n for n in self.nodes if n is not node]
            if any(not n.shutting_down for n in others):
                node.shutdown()  # another worker is still running: that one will be the last
                return None
            if others:
                return None  # the others are finishing their last test; remove_node calls back
            self.pending[:], self.held = self.held, []
            self._send_tests(node, len(self.pending))
            node.shutdown()
            return None

        def remove_node(self, node):
            crashed = super().remove_node(node)
            if self.held:
                for other in self.nodes:
                    self.check_schedule(other)
            return crashed

    return SerialLast(config, log)
