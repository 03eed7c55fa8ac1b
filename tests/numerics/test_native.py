"""The compiled path (generated C right-hand side + DOP853 loop in C) against independent oracles.

Oracles: scipy's own DOP853 (the same algorithm, so the same steps and samples), the lambdified
Python right-hand side (the same expressions, evaluated by another printer and runtime), the
closed-form normal modes of a chain of springs (for the M q̈ = f path solved in C), and the
lecture notes' conservation laws. The failure modes (no compiler, a broken compiler, a singular
mass matrix, a non-finite state, the budgets) are each provoked and must be reported, not hidden.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys

import numpy as np
import pytest
import sympy as sp
from scipy.special import ellipk

from mechanics import native
from mechanics.expr import FUNCTIONS
from mechanics.integrators import integrate
from mechanics.numeric import compiled_scene, compiled_spec
from mechanics.scenes import scene_ids
from mechanics.simulate import SimulationRequest, simulate

G = 9.81


def test_this_machine_can_compile():
    """CI installs a C compiler; without it every other test here would test the fallback."""
    assert native.available() is None


def _params(c) -> list[float]:
    return [c.derivation.model.spec.parameters[k] for k in c.parameters]


SCENES = scene_ids()


@pytest.mark.parametrize("scene", SCENES)
def test_the_generated_c_equals_the_python_right_hand_side(scene):
    c = compiled_scene(scene)
    p = _params(c)
    python, compiled = c.rhs(p), c.native_rhs(p)
    rng = np.random.default_rng(7)
    for _ in range(20):
        y = rng.uniform(-2, 2, 2 * c.n + 1)
        if scene in ("central_force", "elastic_pendulum", "particle_in_cone"):
            y[0] = abs(y[0]) + 0.5  # a radius
        t = float(rng.uniform(0, 5))
        expected = python(t, y)
        got = compiled(t, y)
        assert got == pytest.approx(expected, rel=1e-12, abs=1e-12), scene


@pytest.mark.parametrize(
    ("scene", "t_end", "tol"),
    [
        ("simple_pendulum", 20, 1e-12),
        ("double_pendulum", 5, 1e-10),
        ("spherical_pendulum", 10, 1e-9),
        ("spring_mass_damper", 10, 1e-8),  # driven and damped: the work W_NC rides along
        ("central_force", 20, 1e-11),
        ("cart_pendulum", 10, 1e-6),
    ],
)
def test_the_c_loop_takes_the_steps_of_scipys_dop853(scene, t_end, tol):
    """Same tableau, step control and dense output as scipy: same accepted steps, the same RHS
    count, and samples equal up to rounding."""
    runs = [
        simulate(
            scene,
            request=SimulationRequest(
                method=m, t_end=t_end, fps=30, rtol=tol, atol=tol, check_sensitivity=False
            ),
        )
        for m in ("DOP853", "dop853_c")
    ]
    scipy_run, c_run = (r["stats"] for r in runs)
    assert c_run["status"] == scipy_run["status"] == "ok"
    assert c_run["steps"] == scipy_run["steps"]
    assert c_run["rhs_evaluations"] == scipy_run["rhs_evaluations"]
    for name in runs[0]["q"]:
        a, b = np.asarray(runs[0]["q"][name]), np.asarray(runs[1]["q"][name])
        assert np.abs(a - b).max() <= 1e-9 * max(1.0, np.abs(a).max()), name
    assert np.allclose(runs[0]["energy"]["W_nc"], runs[1]["energy"]["W_nc"], rtol=1e-9, atol=1e-12)


def test_pendulum_at_170_degrees_keeps_the_elliptic_integral_period():
    """Zero crossings of θ, located on the samples by the (cubic) Hermite data, every T/2."""
    theta0 = math.radians(170)
    expected = 4 * math.sqrt(1 / G) * ellipk(math.sin(theta0 / 2) ** 2)
    req = SimulationRequest(
        initial={"theta": theta0},
        t_end=12,
        fps=200,
        method="dop853_c",
        rtol=1e-12,
        atol=1e-12,
        check_sensitivity=False,
    )
    r = simulate("simple_pendulum", request=req)
    t, th, thd = (np.asarray(x) for x in (r["t"], r["q"]["theta"], r["q_dot"]["theta"]))
    roots = []
    for i in np.nonzero(np.sign(th[:-1]) != np.sign(th[1:]))[0]:
        s = t[i] - th[i] / thd[i]  # one Newton step from each side, then the secant
        s2 = t[i + 1] - th[i + 1] / thd[i + 1]
        roots.append((s + s2) / 2)
    assert len(roots) >= 4
    halves = np.diff(roots)
    assert halves == pytest.approx(np.full(len(halves), expected / 2), rel=1e-6)
    E = 0.5 * thd**2 - G * np.cos(th)
    assert np.abs(E - E[0]).max() < 1e-10 * G


# --- the M q̈ = f path (n > 3): solved in C ----------------------------------------------------


def chain(n: int) -> dict:
    """n equal masses between two walls, n + 1 equal springs.

    Normal modes: ω_j = 2 sqrt(k/m) sin(jπ/(2(n+1))), shapes sin(i j π/(n+1)) (i = 1..n)."""
    bodies = [
        {"name": f"m{i}", "mass": "m", "position": [f"{i + 1}*a + x{i}", 0, 0]} for i in range(n)
    ]
    points = [
        {"name": "wall_left", "position": [0, 0, 0]},
        {"name": "wall_right", "position": [f"{n + 1}*a", 0, 0]},
    ]
    ends = ["wall_left", *[f"m{i}" for i in range(n)], "wall_right"]
    springs = [
        {"name": f"s{i}", "a": ends[i], "b": ends[i + 1], "k": "k", "rest_length": "a"}
        for i in range(n + 1)
    ]
    return {
        "title": f"chain of {n}",
        "coordinates": [f"x{i}" for i in range(n)],
        "parameters": {"m": 1.0, "k": 10.0, "a": 1.0},
        "bodies": bodies,
        "points": points,
        "springs": springs,
        "initial": {},
    }


@pytest.mark.parametrize("mode", [1, 3])
def test_a_chain_of_four_oscillates_at_its_closed_form_normal_mode(mode):
    n, k, m = 4, 10.0, 1.0
    spec = chain(n)
    c = compiled_spec(spec)
    assert not c.solved and "lab_solve" in c.native_source  # M q̈ = f is solved in C
    shape = [math.sin(mode * (i + 1) * math.pi / (n + 1)) for i in range(n)]
    omega = 2 * math.sqrt(k / m) * math.sin(mode * math.pi / (2 * (n + 1)))
    req = SimulationRequest(
        initial={f"x{i}": 0.01 * s for i, s in enumerate(shape)},
        t_end=5,
        fps=20,
        method="dop853_c",
        rtol=1e-12,
        atol=1e-14,
        check_sensitivity=False,
    )
    r = simulate(scene=spec, request=req)
    t = np.asarray(r["t"])
    for i, s in enumerate(shape):
        expected = 0.01 * s * np.cos(omega * t)
        assert np.abs(np.asarray(r["q"][f"x{i}"]) - expected).max() < 1e-10


def test_a_four_link_pendulum_in_c_equals_python():
    """A mass matrix that depends on q (cos(θi − θj) couplings), solved by elimination in C."""
    bodies, prev = [], None
    for i in range(4):
        comps = [f"sin(q{i})", f"-cos(q{i})", 0]
        pos = comps if prev is None else {"frame": "N", "components": comps, "from": prev}
        bodies.append({"name": f"b{i}", "mass": "m", "position": pos})
        prev = f"b{i}"
    spec = {
        "title": "four links",
        "coordinates": [f"q{i}" for i in range(4)],
        "parameters": {"m": 1.0, "g": 9.81},
        "bodies": bodies,
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
        "initial": {"q0": 1.0},
    }
    c = compiled_spec(spec)
    assert not c.solved
    p = _params(c)
    rng = np.random.default_rng(3)
    for _ in range(20):
        y = rng.uniform(-3, 3, 9)
        assert c.native_rhs(p)(0.0, y) == pytest.approx(c.rhs(p)(0.0, y), rel=1e-9, abs=1e-9)


def test_a_singular_mass_matrix_in_c_stops_the_run_and_says_so():
    """M = diag(max(q0, 0), 1, 1, 1), f = 0 and q0 = 1 − t: M is exactly singular from t = 1."""
    ts, *rest = sp.symbols("t_ q0:4 u0:4")
    q, u = rest[:4], rest[4:]
    mass = [sp.Max(q[0], 0) if (i == j == 0) else int(i == j) for i in range(4) for j in range(4)]
    src = native.rhs_source([ts, *q, *u], 4, sp.S.Zero, mass=mass, forcing=[0, 0, 0, 0])
    rhs = native.compile_rhs(src, [], 9)
    y0 = np.array([1.0, 0, 0, 0, -1.0, 0, 0, 0, 0])
    run = integrate(rhs, y0, np.linspace(0, 2, 21), method="dop853_c", native=rhs)
    assert run.status == "stopped" and "mass matrix became singular" in run.message
    assert run.t[-1] <= 1.0 and np.allclose(run.y[:, 0], 1 - run.t)


# --- what reaches the compiler --------------------------------------------------------------


def test_user_names_never_reach_the_c_code():
    """Parameter and coordinate names that are C keywords or libc functions: the C only has
    array slots, so they cannot collide or inject anything."""
    spec = {
        "title": "names",
        "coordinates": ["main"],
        "parameters": {"system": 2.0, "exit": 1.0, "printf": 9.81},
        "bodies": [
            {"name": "b", "mass": "exit", "position": ["system*sin(main)", "-system*cos(main)"]}
        ],
        "gravity": {"acceleration": "printf", "direction": [0, -1, 0]},
        "initial": {"main": 0.5},
    }
    c = compiled_spec(spec)
    source = c.native_source
    for word in ("main(", "system", "exit", "printf"):
        assert word not in source
    r = simulate(
        scene=spec,
        request=SimulationRequest(method="dop853_c", t_end=1, check_sensitivity=False),
    )
    assert r["stats"]["status"] == "ok" and not r["warnings"]


@pytest.mark.parametrize(
    "expr",
    [
        sp.Function("system")(sp.Symbol("q_0")),
        sp.Symbol("q_0") + sp.Symbol("evil"),
    ],
)
def test_anything_but_numbers_slots_and_libm_is_refused(expr):
    args = list(sp.symbols("t_ q_0 u_0"))
    with pytest.raises(native.NativeUnavailable):
        native.rhs_source(args, 1, sp.S.Zero, accelerations=[expr])


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_every_function_a_spec_may_use_prints_as_the_same_c_function(name):
    """C's libm against Python's math at a point inside each function's domain."""
    args = list(sp.symbols("t_ q_0 u_0"))
    fn = FUNCTIONS[name]
    expr = fn(args[1], args[2]) if name == "atan2" else fn(args[1])
    rhs = native.compile_rhs(native.rhs_source(args, 1, sp.S.Zero, accelerations=[expr]), [], 3)
    x, v = 0.37, -0.8
    expected = sp.lambdify(args, expr, modules="math")(0.0, x, v)
    assert rhs(0.0, np.array([x, v, 0.0]))[1] == pytest.approx(expected, rel=1e-14)


def test_a_compiled_scene_is_built_once_then_loaded_from_disk(monkeypatch, tmp_path):
    monkeypatch.setenv("LAGRANGE_LAB_CACHE", str(tmp_path))
    native._rhs_library.cache_clear()
    c = compiled_scene("simple_pendulum")
    c.native_rhs(_params(c))
    assert len(list((tmp_path / "native").glob("rhs-*.so"))) == 1
    native._rhs_library.cache_clear()

    def no_compiler(*args, **kwargs):
        raise AssertionError("compiled again")

    monkeypatch.setattr(subprocess, "run", no_compiler)
    y = np.array([0.5, 0.0, 0.0])
    assert c.native_rhs(_params(c))(0.0, y)[1] == pytest.approx(-G * math.sin(0.5))
    native._rhs_library.cache_clear()


@pytest.mark.parametrize(("cc", "words"), [("none", "no C compiler"), ("false", "compiler failed")])
def test_without_a_working_compiler_scipy_runs_the_same_method_and_says_so(
    monkeypatch, tmp_path, cc, words
):
    monkeypatch.setenv("LAGRANGE_LAB_CACHE", str(tmp_path))
    monkeypatch.setenv(native.ENV_VAR, cc)
    native._kernel.cache_clear()
    native._rhs_library.cache_clear()
    try:
        req = SimulationRequest(method="dop853_c", t_end=5, rtol=1e-10, atol=1e-10)
        r = simulate("simple_pendulum", request=req)
        ref = simulate(
            "simple_pendulum",
            request=SimulationRequest(method="DOP853", t_end=5, rtol=1e-10, atol=1e-10),
        )
    finally:
        native._kernel.cache_clear()
        native._rhs_library.cache_clear()
    assert r["stats"]["status"] == "ok" and r["q"] == ref["q"]
    (note,) = [w for w in r["warnings"] if "scipy's DOP853" in w]
    assert words in note


# --- budgets and failures inside the C loop ---------------------------------------------------


def test_the_step_budget_and_the_wall_clock_stop_the_c_loop():
    c = compiled_scene("double_pendulum")
    rhs = c.native_rhs(_params(c))
    y0 = np.array([2.0, 0.5, 0.0, 0.0, 0.0])
    t_eval = np.linspace(0, 100, 1001)
    run = integrate(rhs, y0, t_eval, method="dop853_c", native=rhs, max_steps=50)
    assert run.status == "stopped" and "step budget (50)" in run.message and run.nsteps == 50
    assert 0 < run.t[-1] < 100
    run = integrate(
        rhs, y0, t_eval, method="dop853_c", native=rhs, rtol=1e-14, atol=1e-14, max_wall_time=0.0
    )
    assert run.status == "stopped" and "wall-time budget" in run.message
    assert len(run.t) == len(run.y) >= 1


def test_a_python_exception_in_a_callback_is_raised_not_swallowed():
    def broken(t, y):
        if t > 1:
            raise RuntimeError("bug in the model")
        return np.array([y[1], -y[0]])

    with pytest.raises(RuntimeError, match="bug in the model"):
        integrate(broken, [1.0, 0.0], np.linspace(0, 3, 4), method="dop853_c")


def test_the_generated_c_is_the_same_text_in_every_process():
    """The disk cache is keyed by the source: a process with another hash seed (set iteration
    order) must print the same C, or every worker would compile every scene again."""
    script = (
        "from mechanics.numeric import compiled_scene;"
        "print(compiled_scene('double_pendulum').native_source)"
    )
    outputs = {
        subprocess.run(
            [sys.executable, "-c", script],
            capture_output=True,
            text=True,
            check=True,
            env={**os.environ, "PYTHONHASHSEED": seed},
        ).stdout
        for seed in ("1", "2")
    }
    assert outputs == {compiled_scene("double_pendulum").native_source + "\n"}


def test_the_disk_cache_of_libraries_stays_bounded(monkeypatch, tmp_path):
    monkeypatch.setenv("LAGRANGE_LAB_CACHE", str(tmp_path))
    monkeypatch.setattr(native, "MAX_LIBRARIES", 2)
    native._rhs_library.cache_clear()
    args = list(sp.symbols("t_ q_0 u_0"))
    try:
        for k in range(4):
            src = native.rhs_source(args, 1, sp.S.Zero, accelerations=[-(k + 1) * args[1]])
            rhs = native.compile_rhs(src, [], 3)
            assert rhs(0.0, np.array([1.0, 0.0, 0.0]))[1] == -(k + 1)  # loaded ones keep working
    finally:
        native._rhs_library.cache_clear()
    assert len(list((tmp_path / "native").glob("rhs-*.so"))) == 2


def test_shapes_are_checked_before_c_reads_or_writes_by_index():
    """The generated C indexes params and the state blindly: a wrong shape must stop in Python."""
    c = compiled_scene("double_pendulum")
    p = _params(c)
    with pytest.raises(ValueError, match="params"):
        native.compile_rhs(c.native_source, p[:-1], 5)
    with pytest.raises(ValueError, match="states"):
        native.compile_rhs(c.native_source, p, 3)
    rhs = c.native_rhs(p)
    with pytest.raises(ValueError, match="y0 has 3"):
        native.dop853(
            rhs,
            np.zeros(3),
            np.linspace(0, 1, 3),
            rtol=1e-6,
            atol=1e-6,
            max_steps=10,
            max_seconds=1,
        )


def test_a_broken_compiler_is_not_run_again_on_every_request(monkeypatch, tmp_path):
    monkeypatch.setenv("LAGRANGE_LAB_CACHE", str(tmp_path))
    monkeypatch.setenv(native.ENV_VAR, "false")
    native._kernel.cache_clear()
    native._rhs_library.cache_clear()
    runs = []
    real = subprocess.run
    monkeypatch.setattr(subprocess, "run", lambda *a, **k: runs.append(a) or real(*a, **k))
    req = SimulationRequest(method="dop853_c", t_end=1)
    try:
        simulate("simple_pendulum", request=req)
        first = len(runs)
        r = simulate("simple_pendulum", request=req)
    finally:
        native._kernel.cache_clear()
        native._rhs_library.cache_clear()
    assert 1 <= first <= 2  # the loop, and the scene's C if it was tried
    assert len(runs) == first  # the second request (and its sensitivity re-run) ran nothing
    assert any("compiler failed" in w for w in r["warnings"])
