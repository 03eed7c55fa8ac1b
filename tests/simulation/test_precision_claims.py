"""What the work–precision answer may claim (mechanics/precision.py, POST /api/v1/precision).

Found by a hostile play-test: a bounded-energy claim on a damped oscillator, a "long run" of 891 s
for an Atwood machine whose mass reaches the pulley at 0.89 s, every point of a chaotic run blamed
on its method, and steps longer than the run accepted. Each expectation here is worked out
independently: by hand with sympy (the power of the forces, L's time dependence), by closed form
(Atwood's a = (m₁ − m₂) g/(m₁ + m₂), a rolling body's monotone speed, det of a step's Jacobian) or
by an independent integration (scipy's DOP853 on the scene's equations at two tolerances).
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
import sympy as sp
from fastapi import FastAPI
from fastapi.testclient import TestClient
from scipy.integrate import solve_ivp

from app import derivations
from app.errors import register_error_handlers
from app.routes import precision as route
from mechanics.integrators import integrate
from mechanics.numeric import compiled_scene, compiled_spec
from mechanics.precision import PrecisionRequest, precision
from mechanics.scenes import load_scene

api = FastAPI()
api.include_router(route.router)
register_error_handlers(api)
client = TestClient(api)


@pytest.fixture(scope="module", autouse=True)
def _pool_closed_after():
    yield
    derivations.stop_pool()


def post(body: dict) -> dict:
    r = client.post("/api/v1/precision", json=body)
    assert r.status_code == 200, r.text
    return r.json()


def row(result: dict, method: str) -> dict:
    return next(m for m in result["methods"] if m["method"] == method)


# ---------------------------------------------------------------- 1. the symplectic claim


def spring_power(c: float, f0: float) -> sp.Expr:
    """dE/dt of the driven, damped block by hand: E = ½ m ẋ² + ½ k x², m ẍ = −k x − c ẋ + F0 cos ωt,
    so dE/dt = ẋ (m ẍ + k x) = −c ẋ² + F0 cos(ωt) ẋ."""
    t, x0, v = sp.symbols("t x0 v", real=True)
    m, k, w = sp.Rational(1), sp.Integer(10), sp.Rational(5, 2)
    xdd = (-k * x0 - sp.nsimplify(c) * v + sp.nsimplify(f0) * sp.cos(w * t)) / m
    return sp.simplify(v * (m * xdd + k * x0))


def test_a_damped_driven_oscillator_is_not_called_symplectic():
    """The play-test's request: symplectic_here and methods[].symplectic were true (the code
    asked only whether M is constant), and the page showed an energy error of 6680 % of max T
    with no caveat."""
    assert spring_power(0.4, 0.5) != 0  # the scene's own c = 0.4, F0 = 0.5 do work
    body = {
        "scene_id": "spring_mass_damper",
        "methods": ["symplectic_euler", "rk4"],
        "t_end": 5,
        "long_run": True,
    }
    out = post(body)
    assert row(out, "symplectic_euler")["symplectic"] is False
    assert "do work" in row(out, "symplectic_euler")["not_symplectic"]
    assert row(out, "rk4")["not_symplectic"] is None  # never claimed: nothing to take back
    lr = out["long_run"]
    assert lr["symplectic_here"] is False and "energy is not conserved" in lr["not_symplectic"]


def test_the_same_oscillator_without_damper_and_drive_is_symplectic_no_false_alarm():
    """c = F0 = 0: dE/dt = 0 by hand, M = m constant, ẍ = −k x/m a force of x alone: symplectic
    Euler's step is symplectic, det of its Jacobian 1 (checked on the step itself)."""
    assert spring_power(0.0, 0.0) == 0
    out = post(
        {
            "scene_id": "spring_mass_damper",
            "methods": ["symplectic_euler"],
            "parameters": {"c": 0, "F0": 0},
            "t_end": 5,
            "steps": [0.01],
            "long_run": True,
        }
    )
    assert row(out, "symplectic_euler")["symplectic"] is True
    assert row(out, "symplectic_euler")["not_symplectic"] is None
    assert out["long_run"]["symplectic_here"] is True and out["long_run"]["not_symplectic"] is None
    c = compiled_scene("spring_mass_damper")
    defaults = load_scene("spring_mass_damper")["parameters"]
    params = [{"c": 0.0, "F0": 0.0}.get(n, defaults[n]) for n in c.parameters]
    assert step_jacobian_det(c, params, [0.3, 0.2], 0.05) == pytest.approx(1.0, abs=1e-8)


def step_jacobian_det(c, params, state, h) -> float:
    """det ∂(q, q̇)₁/∂(q, q̇)₀ of one symplectic Euler step, by central differences: 1 for a
    volume-preserving (a fortiori a symplectic) map."""
    n = c.n
    extras = c.extras
    base = np.array([*state, *([0.0] * extras)], dtype=float)

    def step(y):
        run = integrate(c.rhs(params), y, [0.0, h], method="symplectic_euler", dt=h, second_order=n)
        return run.y[-1, : 2 * n]

    eps = 1e-6
    J = np.empty((2 * n, 2 * n))
    for j in range(2 * n):
        d = np.zeros_like(base)
        d[j] = eps
        J[:, j] = (step(base + d) - step(base - d)) / (2 * eps)
    return float(np.linalg.det(J))


def test_friction_is_not_called_symplectic_and_its_motion_has_no_long_run():
    """The block's friction −μ m g cos α sgn(ṡ) has power −μ m g cos α |ṡ| ≠ 0 for ṡ ≠ 0 (by
    hand); the block slides down at constant a = g (sin α − μ cos α) > 0 from ṡ = 1: ṡ never
    changes sign, so there is no period and no long run, and no '1000 periods' either."""
    scene = load_scene("incline_friction")
    p = scene["parameters"]
    a = p["g"] * (math.sin(p["alpha"]) - p["mu"] * math.cos(p["alpha"]))
    assert a > 0 and scene["initial"].get("s_dot", 0) >= 0
    out = post(
        {
            "scene_id": "incline_friction",
            "methods": ["symplectic_euler", "rk4"],
            "t_end": 5,
            "long_run": True,
        }
    )
    assert row(out, "symplectic_euler")["symplectic"] is False
    assert "do work" in row(out, "symplectic_euler")["not_symplectic"]
    assert out["long_run"] is None
    assert "does not repeat" in out["long_run_declined"]


def moving_support_pendulum(amplitude: float) -> dict:
    """The simple pendulum hung from a support at y = A cos(ωt): by hand,
    L = ½ m (l² θ̇² − 2 A ω l θ̇ sin θ sin ωt + A² ω² sin² ωt) + m g (l cos θ − A cos ωt): L
    depends on t explicitly unless A = 0."""
    spec = load_scene("simple_pendulum")
    spec["parameters"] = {**spec["parameters"], "A": amplitude, "w": 3.0}
    spec["bodies"][0]["position"] = ["l*sin(theta)", "A*cos(w*t) - l*cos(theta)", 0]
    return spec


def test_a_moving_support_is_not_called_symplectic_and_a_still_one_is():
    t, th, thd = sp.symbols("t theta thetadot")
    m, length, g, A, w = sp.symbols("m l g A w", positive=True)
    x, y = length * sp.sin(th), A * sp.cos(w * t) - length * sp.cos(th)
    xd = sp.diff(x, th) * thd
    yd = sp.diff(y, th) * thd + sp.diff(y, t)
    L = m * (xd**2 + yd**2) / 2 - m * g * y
    assert sp.diff(L, t) != 0 and sp.simplify(sp.diff(L.subs(A, 0), t)) == 0
    request = PrecisionRequest(methods=["symplectic_euler"], t_end=1.0, steps=[0.01])
    moving = precision(scene=moving_support_pendulum(0.05), request=request)
    assert row(moving, "symplectic_euler")["symplectic"] is False
    assert "depends explicitly on t" in row(moving, "symplectic_euler")["not_symplectic"]
    still = precision(scene=moving_support_pendulum(0.0), request=request)
    assert row(still, "symplectic_euler")["symplectic"] is True


def test_a_magnetic_force_is_not_called_symplectic():
    """A charge in a plane, on a spring, in a field B ẑ: F = q v × B = B (ẏ, −ẋ). It does no work
    (F·v = 0, so E is conserved and M = m is constant), yet symplectic Euler's explicit update
    v ← v + h F(v)/m has det (1 + (hB/m)²) ≠ 1 (by hand, with its q ← q + h v): not even
    volume-preserving, so not symplectic. The check before this fix looked at M only."""
    spec = {
        "title": "Charge on a spring in a magnetic field",
        "coordinates": ["x", "y"],
        "parameters": {"m": 1.0, "k": 4.0, "B": 2.0},
        "initial": {"x": 1.0, "y": 0.0, "x_dot": 0.0, "y_dot": 0.5},
        "points": [{"name": "origin", "position": [0, 0, 0]}],
        "bodies": [{"name": "charge", "kind": "particle", "mass": "m", "position": ["x", "y", 0]}],
        "springs": [{"name": "spring", "a": "origin", "b": "charge", "k": "k", "rest_length": 0}],
        "forces": [{"name": "lorentz", "on": "charge", "vector": ["B*y_dot", "-B*x_dot", 0]}],
    }
    out = precision(
        scene=spec,
        request=PrecisionRequest(methods=["symplectic_euler"], t_end=1.0, steps=[0.01]),
    )
    assert row(out, "symplectic_euler")["symplectic"] is False
    assert "depend on the velocities" in row(out, "symplectic_euler")["not_symplectic"]
    h, b = 0.05, 2.0
    c = compiled_spec(spec)
    params = [spec["parameters"][name] for name in c.parameters]
    det = step_jacobian_det(c, params, [1.0, 0.0, 0.0, 0.5], h)
    assert det == pytest.approx(1 + (h * b) ** 2, rel=1e-5) and abs(det - 1) > 1e-3


# ---------------------------------------------------------------- 2. no long run past a stop


def test_no_long_run_past_the_atwood_machines_stop():
    """x from rest with ẍ = (m₁ − m₂) g/(m₁ + m₂) = g/3; mass2 reaches the pulley at x = l + d,
    t = √(2 (l + d)/(g/3)) ≈ 0.892 s. The answer used that as an invented period and ran 891 s
    of motion the model forbids ("status ok")."""
    p = load_scene("atwood_machine")["parameters"]
    accel = (p["m1"] - p["m2"]) * p["g"] / (p["m1"] + p["m2"])
    t_stop = math.sqrt(2 * (p["l"] + p["d"]) / accel)
    out = post(
        {
            "scene_id": "atwood_machine",
            "methods": ["symplectic_euler", "rk4"],
            "t_end": 5,
            "long_run": True,
        }
    )
    assert out["stopped"]["t"] == pytest.approx(t_stop, rel=1e-3)
    assert out["long_run"] is None
    assert f"{t_stop:.3g} s" in out["long_run_declined"]
    assert "pulley" in out["long_run_declined"]
    # the comparisons ran to the stop only, and a step longer than that motion says so
    short = post(
        {"scene_id": "atwood_machine", "methods": ["rk4"], "t_end": 5, "steps": [2.0, 0.01]}
    )
    first = row(short, "rk4")["points"][0]
    assert first["h"] <= t_stop * (1 + 1e-6) and "longer than the motion" in first["excluded"]


def test_a_rolling_disk_that_never_comes_back_has_no_periods():
    """Rolling down the incline from its start its speed grows like a t (a constant): the
    first coordinate never turns, so '1000 periods' of it named no time scale at all."""
    out = post({"scene_id": "rolling_disk", "methods": ["rk4"], "t_end": 5, "long_run": True})
    assert out["long_run"] is None and "does not repeat" in out["long_run_declined"]
    assert out["stopped"] is None


def test_a_pendulum_still_gets_its_long_run_with_the_claim():
    out = post(
        {
            "scene_id": "simple_pendulum",
            "methods": ["rk4"],
            "initial": {"theta": 0.1},
            "t_end": 2,
            "steps": [0.01],
            "long_run": True,
        }
    )
    lr = out["long_run"]
    assert out["long_run_declined"] is None and lr["symplectic_here"] is True
    # small swings: period 2π √(l/g), +0.06 % at 0.1 rad
    assert lr["period"] == pytest.approx(2 * math.pi / math.sqrt(9.81), rel=2e-3)
    assert 100 <= lr["periods"] <= 1000 and lr["periods"] % 20 == 0
    for run in lr["runs"].values():  # sized to what fits: both reach the end they report
        assert run["t"][-1] == pytest.approx(lr["periods"] * lr["period"], rel=1e-9)


# ---------------------------------------------------------------- 3. chaos


def two_references(scene_id: str, t_end: float, tolerances=(1e-12, 1e-9)) -> tuple:
    """scipy's DOP853 on the scene's equations at two tolerances: where they part by 1 % of the
    motion, neither is a reference any more."""
    c = compiled_scene(scene_id)
    spec = load_scene(scene_id)
    params = [spec["parameters"][name] for name in c.parameters]
    initial = spec["initial"]
    y0 = [initial.get(q, 0.0) for q in c.coordinates]
    y0 += [initial.get(f"{q}_dot", 0.0) for q in c.coordinates] + [0.0] * c.extras
    t = np.linspace(0.0, t_end, 2001)
    runs = [
        solve_ivp(c.rhs(params), (0, t_end), y0, "DOP853", t_eval=t, rtol=tol, atol=tol).y
        for tol in tolerances
    ]
    n = c.n
    span = np.max(np.abs(runs[0][:n]), axis=1)[:, None] + 1e-12
    apart = np.max(np.abs(runs[0][:n] - runs[1][:n]) / span, axis=0)
    parted = t[np.argmax(apart >= 1e-2)] if np.any(apart >= 1e-2) else None
    return parted


@pytest.mark.timeout(120)
def test_a_chaotic_run_past_its_horizon_warns_and_does_not_blame_the_methods():
    parted = two_references("double_pendulum", 40.0)
    assert parted is not None and parted < 40  # independently: the motion is unpredictable by 40 s
    out = post({"scene_id": "double_pendulum", "methods": ["rk4", "DOP853", "euler"], "t_end": 40})
    assert len(out["warnings"]) == 1
    warning = out["warnings"][0]
    assert (
        "chaotic" in warning
        and "predictability horizon" in warning
        and "not the methods" in warning
    )
    told = float(warning.split("from t ≈ ")[1].split(" s")[0])
    # 1e-13/1e-10 part later than 1e-12/1e-9 (by about ln 10/λ), and before t_end
    assert parted * 0.8 <= told < 40
    blamed = [
        p["excluded"]
        for m in out["methods"]
        for p in m["points"]
        if p["excluded"] and "not converging" in p["excluded"]
    ]
    assert blamed == []  # past the horizon a point says so, not "not converging yet"
    horizon = [
        p for p in row(out, "DOP853")["points"] if p["excluded"] and "horizon" in p["excluded"]
    ]
    assert horizon


def test_no_chaos_warning_on_regular_motions_or_before_the_horizon():
    assert two_references("simple_pendulum", 40.0) is None
    for scene_id, t_end in (("simple_pendulum", 40), ("double_pendulum", 5)):
        out = post(
            {"scene_id": scene_id, "methods": ["DOP853"], "t_end": t_end, "tolerances": [1e-8]}
        )
        assert out["warnings"] == [], (scene_id, out["warnings"])


# ---------------------------------------------------------------- 4. bounds


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"steps": [5, 2, 1.5], "t_end": 1}, "steps[0]"),
        ({"steps": [0.5, 2], "t_end": 1}, "steps[1]"),
        ({"t_end": 1e-300}, "t_end"),
        ({"t_end": 0}, "t_end"),
    ],
)
def test_a_step_longer_than_the_run_or_a_vanishing_run_is_refused_by_field(body, field):
    r = client.post(
        "/api/v1/precision", json={"scene_id": "simple_pendulum", "methods": ["rk4"], **body}
    )
    assert r.status_code == 422, r.text
    assert field in [e["field"] for e in r.json()["detail"]], r.text


def test_a_step_of_exactly_t_end_is_taken_as_asked():
    out = post({"scene_id": "simple_pendulum", "methods": ["rk4"], "t_end": 1, "steps": [1.0]})
    assert row(out, "rk4")["points"][0]["h"] == pytest.approx(1.0)


@pytest.mark.timeout(120)
def test_the_heaviest_request_answers_within_five_seconds():
    """Six methods at 8 settings over 100 s of the double pendulum, and the long run."""
    body = {
        "scene_id": "double_pendulum",
        "methods": ["euler", "symplectic_euler", "rk4", "implicit_midpoint", "DOP853", "RK45"],
        "t_end": 100,
        "steps": [0.2 / 2**k for k in range(8)],
        "tolerances": [10.0**-k for k in range(3, 11)],
        "long_run": True,
    }
    post({**body, "t_end": 1, "steps": [0.1], "tolerances": [1e-3], "long_run": False})  # warm
    start = time.perf_counter()
    out = post(body)
    assert time.perf_counter() - start < 5.0
    assert out["cut"] is True  # and it says the budget cut it
