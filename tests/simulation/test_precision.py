"""Work–precision runs (mechanics/precision.py, POST /api/v1/precision), checked against theory.

The expected orders are the textbook ones (Euler 1, RK4 4, DOP853 8), and the long run is checked
against closed forms for the linear oscillator worked out below, never against the code's output.
The route is mounted on a small app of its own here (app/main.py wires it for the server).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from fastapi import FastAPI
from fastapi.testclient import TestClient

from app import derivations
from app.errors import register_error_handlers
from app.routes import precision as route
from mechanics.numeric import compiled_scene
from mechanics.precision import (
    PrecisionRequest,
    fitted_order,
    leave_out_pre_asymptotic,
    long_run,
    precision,
)
from mechanics.scenes import load_scene, scene_ids

api = FastAPI()
api.include_router(route.router)
register_error_handlers(api)
client = TestClient(api)


@pytest.fixture(scope="module", autouse=True)
def _pool_closed_after():
    yield
    derivations.stop_pool()


def fitted(result: dict, method: str) -> dict:
    return next(m for m in result["methods"] if m["method"] == method)


def test_euler_fitted_order_is_one_on_the_pendulum():
    # 1 s from θ = 1 rad with h = 1e-3 … 6.25e-5: errors ~1e-3 … 1e-4, far above the floor and
    # below the ceiling (Euler's error over one second is h·t·|y''|/2 ≈ h for this swing).
    result = precision(
        "simple_pendulum",
        request=PrecisionRequest(
            methods=["euler"],
            initial={"theta": 1.0},
            t_end=1.0,
            steps=[1e-3 / 2**k for k in range(5)],
        ),
    )
    euler = fitted(result, "euler")
    assert euler["points_in_fit"] == 5
    assert euler["fitted_order"] == pytest.approx(1.0, abs=0.3)


def test_rk4_fitted_order_is_four_on_the_pendulum():
    result = precision(
        "simple_pendulum",
        request=PrecisionRequest(
            methods=["rk4"],
            initial={"theta": 1.0},
            t_end=10.0,
            steps=[0.0125 / 2**k for k in range(4)],
        ),
    )
    rk4 = fitted(result, "rk4")
    assert rk4["points_in_fit"] == 4
    assert rk4["fitted_order"] == pytest.approx(4.0, abs=0.3)
    # the step taken is the one asked (it divides the sample interval 0.05 s exactly)
    assert [p["h"] for p in rk4["points"]] == pytest.approx([0.0125 / 2**k for k in range(4)])
    # 4 evaluations a step, t_end / h steps
    assert [p["rhs_evaluations"] for p in rk4["points"]] == [4 * 800 * 2**k for k in range(4)]


def test_dop853_fitted_order_against_work_is_eight_on_the_pendulum():
    # Adaptive: error against RHS evaluations (minus the slope). Tolerances 1e-5 … 1e-10 keep the
    # errors (~1e-4 … 1e-9) far above the reference's (1e-13). On this problem the slope depends
    # on the amplitude and the range (8 to 10 over θ₀ ∈ [0.3, 2], t_end ∈ [5, 20]:
    # docs/precision.md) — θ₀ = 1 rad over 10 s is in the range where it settles at 8.
    result = precision(
        "simple_pendulum",
        request=PrecisionRequest(
            methods=["DOP853"],
            initial={"theta": 1.0},
            t_end=10.0,
            tolerances=[10.0**-k for k in range(5, 11)],
        ),
    )
    dop = fitted(result, "DOP853")
    assert dop["points_in_fit"] == 6
    assert dop["fitted_order"] == pytest.approx(8.0, abs=0.3)
    assert dop["fitted_against"] == "RHS evaluations"
    # tighter tolerance: more work, smaller error
    evals = [p["rhs_evaluations"] for p in dop["points"]]
    assert evals == sorted(evals)


def test_the_fit_is_the_slope_of_a_power_law():
    h = [0.1, 0.05, 0.02, 0.01]
    assert fitted_order(h, [3 * x**2.5 for x in h]) == pytest.approx(2.5)
    assert fitted_order([1000, 2000], [1e-3, 1e-3 / 2**8]) == pytest.approx(-8)
    assert fitted_order([0.1], [1.0]) is None


def test_coarse_points_still_creeping_towards_p_are_left_out():
    # err = h⁴ (1 − 5h), as RK4's on the pendulum, approaching p from below: local slopes
    # 4 + log2((1 − 10x)/(1 − 5x)) for a pair (2x, x) = 3.42, 3.78, 3.90, 3.95, 3.98: the first
    # differs from the next by 0.36 (> 5 %), the second from the third by 0.12 (< 5 %)
    h = [0.1 / 2**k for k in range(6)]
    points = [{"h": x, "error": x**4 * (1 - 5 * x), "excluded": None} for x in h]
    leave_out_pre_asymptotic(points)
    assert points[0]["excluded"].startswith("not yet asymptotic")
    assert [p["excluded"] for p in points[1:]] == [None] * 5
    everything = fitted_order(h, [p["error"] for p in points])
    kept = fitted_order(h[1:], [p["error"] for p in points[1:]])
    assert abs(kept - 4) < abs(everything - 4)


def test_euler_energy_error_is_the_closed_form_growth_of_the_linear_oscillator():
    # Euler on y' = iωy multiplies y by 1 + iν, the energy by 1 + ν² a step (ν = ωh): after N
    # steps E = E₀(1 + ν²)ᴺ. From rest at θ₀ = 1e-3 (linear), T peaks at q = 0, a quarter
    # period in (t ≈ 0.50 s, N/2 steps), so |ΔE|/max T = ((1 + ν²)ᴺ − 1)/(1 + ν²)^(N/2).
    result = precision(
        "simple_pendulum",
        request=PrecisionRequest(
            methods=["euler"], initial={"theta": 1e-3}, t_end=1.0, steps=[1e-3]
        ),
    )
    (point,) = fitted(result, "euler")["points"]
    nu2 = 9.81 * 1e-3**2
    expected = ((1 + nu2) ** 1000 - 1) / (1 + nu2) ** 500
    assert point["energy_error"] == pytest.approx(expected, rel=2e-3)


def test_points_at_the_floor_or_not_converging_are_shown_but_left_out():
    result = precision(
        "simple_pendulum",
        request=PrecisionRequest(
            methods=["euler", "rk4"], initial={"theta": 1.0}, t_end=10.0, steps=[0.1, 1e-4]
        ),
    )
    euler, rk4 = fitted(result, "euler"), fitted(result, "rk4")
    # Euler with h = 0.1 over 10 s: E grows by (1 + h²ω²) a step: nothing right is left
    assert "not converging" in euler["points"][0]["excluded"]
    # RK4 at 1e-4: C·h⁴ ≈ 1e-4 · (1e-4/0.0125)⁴ ~ 1e-13: at the reference's floor
    assert "floor" in rk4["points"][1]["excluded"]
    assert rk4["fitted_order"] is None and rk4["points_in_fit"] == 1


def pendulum_at(theta: float):
    """The built-in pendulum compiled, its parameters (m, l, g) and a start at rest at θ."""
    return compiled_scene("simple_pendulum"), [1.0, 1.0, 9.81], np.array([theta, 0.0, 0.0])


def test_long_run_is_cut_by_its_budget_and_says_so():
    lr = long_run(*pendulum_at(0.1), t_end=10.0, seconds=0.2)
    for run in lr["runs"].values():
        assert run["status"] == "stopped"
        assert "wall-time budget" in run["message"]
        assert run["wall_time"] < 1.0
    # what was reached is still reported, windows of 10 periods each
    assert len(lr["runs"]["symplectic_euler"]["energy_error"]) < 100


def test_long_run_symplectic_euler_bounded_rk4_drifts_as_theory_says():
    """Linear oscillator (θ₀ = 0.1 rad), ν = ωh.

    RK4 on y' = iωy multiplies y by R(iν) = 1 + iν − ν²/2 − iν³/6 + ν⁴/24 a step, and
    |R|² = (1 − ν²/2 + ν⁴/24)² + (ν − ν³/6)² = 1 − ν⁶/72 + ν⁸/576: the energy (∝ |y|²) shrinks by
    that factor every step, one way, so after N steps |ΔE|/E = 1 − |R|^(2N).

    Symplectic Euler (v ← v − hω²q, q ← q + hv) conserves I = v² + ω²q² − hω²qv exactly
    (substitute: I₁ = v₁v + ω²q² = I). Started at rest (qv = 0), E − E₀ = ½hω²·qv, and
    ω|q||v| ≤ E, so |E − E₀| ≤ (ν/2)·E for ever: bounded, never drifting (and the bound is
    reached: the error sits near it from the first periods on).
    """
    lr = long_run(*pendulum_at(0.1), t_end=10.0, seconds=120.0)  # the physics, not the budget
    sym, rk4 = lr["runs"]["symplectic_euler"], lr["runs"]["rk4"]
    assert sym["status"] == rk4["status"] == "ok"
    omega = math.sqrt(9.81)  # small-oscillation ω = √(g/l), l = 1
    assert lr["period"] == pytest.approx(2 * math.pi / omega, rel=2e-3)  # 0.1 rad: +0.06 %
    nu = omega * lr["h"]
    n_steps = round(lr["periods"] * lr["period"] / lr["h"])
    assert n_steps == 30_000 and lr["periods"] == 1000

    s = np.array(sym["energy_error"])
    tenth = len(s) // 10
    assert s[-tenth:].max() <= 2 * s[:tenth].max()
    # |E − E₀| ≤ (ν/2)·E and E ≤ E₀/(1 − ν/2); max T ≥ E₀ (at q = 0, where qv = 0, E = E₀ = T):
    # |E − E₀| / max T ≤ (ν/2)/(1 − ν/2), with 5 % for the pendulum's O(θ₀²) non-linearity
    assert s.max() <= 1.05 * (nu / 2) / (1 - nu / 2)

    r = np.array(rk4["energy_error"])
    tenths = [r[k * tenth : (k + 1) * tenth].max() for k in range(10)]
    assert all(b > a for a, b in zip(tenths, tenths[1:], strict=False))  # monotone drift
    predicted = 1 - (1 - nu**6 / 72 + nu**8 / 576) ** n_steps
    assert r[-1] == pytest.approx(predicted, rel=0.05)
    assert r[-1] > 10 * r[0]


def post(**body):
    return client.post("/api/v1/precision", json=body)


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"methods": ["euler", "rk4", "RK45", "DOP853", "Radau", "BDF", "LSODA"]}, "methods"),
        ({"methods": ["leapfrog"]}, "methods[0]"),
        ({"methods": ["rk4", "rk4"]}, "methods"),
        ({"tolerances": [1e-3] * 9}, "tolerances"),
        ({"tolerances": [1e-14]}, "tolerances[0]"),
        ({"steps": [1e-6]}, "steps[0]"),
        ({"steps": [-0.1]}, "steps[0]"),
        ({"t_end": 0}, "t_end"),
        ({"t_end": 1000}, "t_end"),
        ({"parameters": {"lenght": 1}}, "parameters.lenght"),
        ({"bogus": 1}, "bogus"),
    ],
)
def test_bad_requests_are_422_naming_the_field(body, field):
    r = post(scene_id="simple_pendulum", **body)
    assert r.status_code == 422, r.text
    assert any(d["field"] == field for d in r.json()["detail"]), r.json()


def test_unknown_scene_is_404():
    r = post(scene_id="no_such_scene")
    assert r.status_code == 404
    assert r.json()["detail"][0]["field"] == "scene_id"


def test_built_in_answer_is_kept_and_served_again():
    body = {
        "scene_id": "simple_pendulum",
        "methods": ["rk4"],
        "steps": [0.02, 0.01],
        "t_end": 2.0,
    }
    first = post(**body)
    assert first.status_code == 200, first.text
    hits = route.answers.hits
    again = post(**body)
    assert again.content == first.content
    assert route.answers.hits == hits + 1


def test_posted_spec_runs_in_the_pool_like_the_built_in_scene():
    spec = load_scene("simple_pendulum")
    body = {"methods": ["rk4"], "steps": [0.0125, 0.00625], "t_end": 10.0}
    body["initial"] = {"theta": 1.0}
    posted = post(scene=spec, **body)
    built_in = post(scene_id="simple_pendulum", **body)
    assert posted.status_code == 200, posted.text
    a, b = fitted(posted.json(), "rk4"), fitted(built_in.json(), "rk4")
    assert a["fitted_order"] == pytest.approx(4.0, abs=0.3)
    # the same equations and steps: the same errors (the cost in seconds may differ)
    assert [p["error"] for p in a["points"]] == pytest.approx([p["error"] for p in b["points"]])


@pytest.mark.slow
@pytest.mark.parametrize("scene_id", scene_ids())
def test_every_built_in_scene_gives_a_diagram(scene_id):
    r = post(
        scene_id=scene_id,
        methods=["symplectic_euler", "rk4", "DOP853"],
        steps=[0.01, 0.005],
        tolerances=[1e-6, 1e-8],
        t_end=1.0,
    )
    assert r.status_code == 200, r.text
    body = r.json()
    assert [m["method"] for m in body["methods"]] == ["symplectic_euler", "rk4", "DOP853"]
    for m in body["methods"]:
        assert len(m["points"]) == 2
        assert all(p["rhs_evaluations"] > 0 for p in m["points"])


def test_openapi_documents_the_route_with_the_registry_as_enum():
    document = client.get("/openapi.json").json()
    post_op = document["paths"]["/api/v1/precision"]["post"]
    assert {"404", "422", "503"} <= set(post_op["responses"])
    schema = document["components"]["schemas"]["PrecisionIn"]["properties"]["methods"]
    from mechanics.integrators import METHODS

    assert schema["items"]["enum"] == list(METHODS)
    assert schema["maxItems"] == 6


def test_runs_are_compared_only_up_to_where_the_model_ends():
    """From rest in the cone (r₀ = 1) the particle reaches the vertex at
    t = √(2 r₀ / (g sin α cos α)); the runs compared used to go on through it (the particle at
    r ≈ −205 m by t = 10 s, an error scale of 206). Now t_end is that time, and said."""
    from mechanics.precision import PrecisionRequest, precision

    alpha, g, r0 = 0.5, 9.81, 1.0
    vertex = math.sqrt(2 * r0 / (g * math.sin(alpha) * math.cos(alpha)))
    req = PrecisionRequest(methods=["rk4"], initial={"r": r0, "phi_dot": 0.0})
    out = precision("particle_in_cone", None, req)
    assert out["stopped"]["t"] == pytest.approx(vertex, rel=1e-6)
    assert "vertex" in out["stopped"]["message"]
    assert out["t_end"] == pytest.approx(vertex, rel=1e-6)
    # |y| stays within the motion up to the vertex: r ≤ r0, speeds below √(2 g h)
    assert out["error_scale"] < 1 + r0 + math.sqrt(2 * g * r0 / math.tan(alpha)) * 2
    steady = precision("simple_pendulum", None, PrecisionRequest(methods=["rk4"]))
    assert steady["stopped"] is None and steady["t_end"] == 10


def test_symplectic_is_claimed_only_where_the_mass_matrix_is_constant():
    """Symplectic Euler steps (q, q̇): a linear change of the canonical (q, p) only when
    p = M q̇ with M constant. The pendulum's M = m l² is; the double pendulum's off-diagonal
    m₂ l₁ l₂ cos(θ₁ − θ₂) is not (by hand), so there neither the method's row nor the long run
    may call it symplectic."""
    t1, t2 = sp.symbols("theta1 theta2")
    m2, l1, l2 = sp.symbols("m2 l1 l2", positive=True)
    assert sp.diff(m2 * l1 * l2 * sp.cos(t1 - t2), t1) != 0
    for scene_id, constant in (("simple_pendulum", True), ("double_pendulum", False)):
        out = precision(
            scene_id,
            request=PrecisionRequest(
                methods=["symplectic_euler"], t_end=1.0, steps=[0.01], long_run=True
            ),
        )
        assert fitted(out, "symplectic_euler")["symplectic"] is constant, scene_id
        assert out["long_run"]["symplectic_here"] is constant, scene_id
    # and through the API, whose schema keeps the field
    body = {"scene_id": "double_pendulum", "methods": ["symplectic_euler"], "t_end": 1.0}
    r = client.post("/api/v1/precision", json={**body, "steps": [0.01], "long_run": True})
    assert r.status_code == 200, r.text
    assert r.json()["long_run"]["symplectic_here"] is False
    assert r.json()["methods"][0]["symplectic"] is False
