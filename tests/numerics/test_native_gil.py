"""While the C loop integrates, other Python threads of the server keep running (issue 24, item 1).

Built-in scenes' runs happen in the server's own threads (app/derivations.py `in_process`): if the
C loop held the GIL, one long run would freeze every other request of that process (pages,
/healthz, the event loop itself) for its whole duration. ctypes releases the GIL around a call
through ``ctypes.CDLL`` and keeps it through ``ctypes.PyDLL``; a Python right-hand side called
back from C re-takes it for each call only.

The measure: a ticker thread records the clock in a loop while the main thread runs the C loop;
the longest pause between two ticks inside the run is the longest time the ticker was shut out.
The control runs the same library through ``PyDLL`` (the GIL held) and must see the ticker shut
out for nearly the whole run, so the measure can tell the two apart.
"""

from __future__ import annotations

import ctypes
import threading
import time
from collections.abc import Callable

import numpy as np
import pytest
import sympy as sp

from mechanics import native
from mechanics.integrators import integrate
from mechanics.numeric import compiled_scene

pytestmark = pytest.mark.skipif(native.available() is not None, reason="no C compiler here")


def _oscillator() -> native.NativeRhs:
    """x'' = -k x in generated C (k = 1): a run's length is set by its t_end alone."""
    t, x, v, k = sp.symbols("t x v k")
    source = native.rhs_source([t, x, v, k], 1, sp.Integer(0), accelerations=[-k * x])
    return native.compile_rhs(source, [1.0], 3)


def _long_c_run(rhs: native.NativeRhs) -> native.NativeRun:
    """About a second of stepping (390 000 steps of DOP853 at rtol 1e-13)."""
    return native.dop853(
        rhs,
        np.array([1.0, 0.0, 0.0]),
        np.linspace(0.0, 6e4, 5),
        rtol=1e-13,
        atol=1e-13,
        max_steps=10**8,
        max_seconds=30.0,
    )


def _longest_pause(work: Callable[[], object]) -> tuple[float, float]:
    """(the longest gap between a ticker thread's ticks while ``work`` ran, how long it ran)."""
    ticks: list[float] = []
    stop = threading.Event()

    def ticker() -> None:
        while not stop.is_set():
            ticks.append(time.perf_counter())
            sum(range(50))  # a little Python between ticks: it needs the GIL

    thread = threading.Thread(target=ticker, daemon=True)
    thread.start()
    while not ticks:
        time.sleep(0.001)
    start = time.perf_counter()
    work()
    end = time.perf_counter()
    stop.set()
    thread.join()
    inside = [start, *(t for t in ticks if start < t < end), end]
    return max(b - a for a, b in zip(inside, inside[1:], strict=False)), end - start


def test_another_thread_runs_while_the_c_loop_integrates():
    rhs = _oscillator()
    pause, ran = _longest_pause(lambda: _long_c_run(rhs))
    assert ran > 0.1, "the run is too short to tell a held GIL from a free one"
    # held, the ticker would wait the whole run; free, only the OS's scheduling (2 shared cores)
    assert pause < ran / 3, f"the ticker was shut out {pause:.3f} s of a {ran:.3f} s run"


def test_the_measure_sees_a_held_gil(monkeypatch):
    """Control: the same kernel called through PyDLL (the GIL kept for the call) shuts the
    ticker out for nearly the whole run. Without this, the test above could pass by not
    measuring anything."""
    free = native._kernel()
    held = ctypes.PyDLL("lab_dop853 (GIL held)", handle=free._handle)
    held.lab_dop853.restype = free.lab_dop853.restype
    held.lab_dop853.argtypes = free.lab_dop853.argtypes
    monkeypatch.setattr(native, "_kernel", lambda: held)
    rhs = _oscillator()
    pause, ran = _longest_pause(lambda: _long_c_run(rhs))
    assert pause > 0.8 * ran


def test_a_scene_run_through_the_integrator_leaves_the_gil_free():
    """The path /simulate takes (mechanics/scene_run.py): integrate(method="dop853_c") with the
    scene's generated right-hand side."""
    c = compiled_scene("simple_pendulum")
    params = [c.derivation.model.spec.parameters[k] for k in c.parameters]
    y0 = np.array([2.0, 0.0, 0.0])

    def run() -> None:
        out = integrate(
            c.rhs(params),
            y0,
            np.linspace(0.0, 30000.0, 5),  # long enough to tell under any load
            method="dop853_c",
            rtol=1e-13,
            atol=1e-13,
            native=c.native_rhs(params),
            second_order=c.n,
        )
        assert out.method == "dop853_c" and out.status == "ok"

    pause, ran = _longest_pause(run)
    assert ran > 0.1, "the run is too short to tell a held GIL from a free one"
    assert pause < ran / 3, f"the ticker was shut out {pause:.3f} s of a {ran:.3f} s run"
