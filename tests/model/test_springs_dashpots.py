"""Springs on either side of their anchor, and dashpots that act only along their line.

Every expectation is written here by hand: the spring force −k(|d| − ℓ₀) d̂ and the dashpot force
−c((v_b − v_a)·ê)ê, integrated with scipy's solve_ivp, and the textbook elastic pendulum
r̈ = r θ̇² + g cos θ − (k/m)(r − ℓ₀). The engine's output is only ever compared to them.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
import sympy as sp
from independent import own_run
from scipy.integrate import solve_ivp

from mechanics.derive import derive_model
from mechanics.numeric import compiled_spec
from mechanics.scenes import load_scene
from mechanics.simulate import SimulationRequest, simulate
from mechanics.spec import SpecError

M, K, L0 = 1.0, 10.0, 1.0
TIGHT = {"rtol": 1e-11, "atol": 1e-12}


def block_on_spring(initial: dict[str, float] | None = None) -> dict:
    """A block on the x axis tied to O by a spring of rest length L0: it may sit on either side."""
    spec = {
        "title": "Block on a spring",
        "coordinates": ["x"],
        "parameters": {"m": M, "k": K, "L0": L0},
        "bodies": [{"name": "block", "mass": "m", "position": ["x", 0, 0]}],
        "springs": [{"name": "spring", "a": "O", "b": "block", "k": "k", "rest_length": "L0"}],
    }
    if initial is not None:
        spec["initial"] = initial
    return spec


def line_spring_rhs(t: float, y: np.ndarray) -> list[float]:
    x, v = y
    return [v, -K / M * (abs(x) - L0) * np.sign(x)]


def plain(expr: sp.Expr, model) -> tuple[list[sp.Symbol], list[sp.Symbol], sp.Expr]:
    """expr with q(t), q̇(t) replaced by plain symbols, for lambdify."""
    qs = [sp.Symbol(f"q{i}") for i in range(len(model.q))]
    us = [sp.Symbol(f"u{i}") for i in range(len(model.q))]
    expr = expr.xreplace(dict(zip(model.qd, us, strict=True)))
    return qs, us, expr.xreplace(dict(zip(model.q, qs, strict=True)))


def potential_function(spec: dict):
    d = derive_model(spec)
    qs, _, v = plain(d.work.V, d.model)
    values = {d.model.params[k]: val for k, val in spec["parameters"].items()}
    return sp.lambdify(qs, v.subs(values), modules="numpy")


# --- a spring along a line, on both sides of its anchor --------------------------------------


@pytest.mark.parametrize("x0", [-1.2, -0.7, 1.5, 0.4])
def test_derived_potential_is_half_k_stretch_squared_on_the_side_of_the_initial_state(x0):
    V = potential_function(block_on_spring({"x": x0}))
    for x in np.sign(x0) * np.array([0.05, 0.5, 1.0, 1.7, 3.0]):
        assert V(x) == pytest.approx(0.5 * K * (abs(x) - L0) ** 2, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize(
    "spec_initial, request_x",
    [
        (None, 1.5),
        (None, -1.2),
        ({"x": -1.2}, -1.2),
        ({"x": -1.2}, 1.5),  # derived on the left, run on the right
        ({"x": 1.5}, -1.2),  # derived on the right, run on the left
        ({"x": 1.5}, 1.5),
    ],
)
def test_a_spring_along_a_line_moves_right_on_either_side_and_never_crosses_its_anchor(
    spec_initial, request_x
):
    spec = block_on_spring(spec_initial)
    result = simulate(
        scene=spec,
        request=SimulationRequest(
            initial={"x": request_x, "x_dot": 0.3}, t_end=4.0, fps=25, **TIGHT
        ),
    )
    assert result["stats"]["status"] == "ok"
    assert "stop" not in result["stats"]
    t = np.array(result["t"])
    x = np.array(result["q"]["x"])
    own = own_run(line_spring_rhs, [request_x, 0.3], t)
    np.testing.assert_allclose(x, own.y[0], rtol=0, atol=1e-7)
    np.testing.assert_allclose(result["q_dot"]["x"], own.y[1], rtol=0, atol=1e-7)
    assert np.all(np.sign(x) == np.sign(request_x)), "the block passed through the anchor"
    expected_v = 0.5 * K * (np.abs(x) - L0) ** 2
    np.testing.assert_allclose(result["energy"]["V"], expected_v, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("x0, v0", [(0.3, -8.0), (-0.3, 8.0), (1.5, -12.0)])
def test_a_block_driven_into_the_anchor_stops_there_when_own_event_says(x0, v0):
    def at_anchor(t, y):
        return y[0]

    at_anchor.terminal = True
    own = solve_ivp(
        line_spring_rhs,
        (0.0, 5.0),
        [x0, v0],
        method="DOP853",
        rtol=1e-12,
        atol=1e-13,
        events=at_anchor,
    )
    (t_hit,) = own.t_events[0]
    result = simulate(
        scene=block_on_spring(),
        request=SimulationRequest(initial={"x": x0, "x_dot": v0}, t_end=5.0, fps=50, **TIGHT),
    )
    stop = result["stats"]["stop"]
    assert stop["name"].endswith("_at_anchor")
    assert stop["name"] == "spring_at_anchor"
    assert stop["t"] == pytest.approx(t_hit, abs=1e-6)
    assert result["stats"]["status"] == "stopped"
    assert result["t"][-1] == pytest.approx(t_hit, abs=1e-6)
    assert abs(result["q"]["x"][-1]) < 1e-5
    x = np.array(result["q"]["x"][:-1])
    assert np.all(np.sign(x) == np.sign(x0))
    assert any("Stopped" in w and "spring" in w for w in result["warnings"]), result["warnings"]


@pytest.mark.parametrize("spec_initial", [None, {"x": 1.5}, {"x": -1.2}])
def test_a_run_starting_on_the_anchor_is_refused_naming_initial_x(spec_initial):
    with pytest.raises(SpecError) as err:
        simulate(
            scene=block_on_spring(spec_initial),
            request=SimulationRequest(initial={"x": 0.0}, t_end=1.0),
        )
    assert "initial.x" in {e["field"] for e in err.value.errors}


# --- a spring between two moving masses on a line ---------------------------------------------

M1, M2 = 1.0, 2.0


def two_masses(initial: dict[str, float] | None = None) -> dict:
    spec = {
        "title": "Two masses and a spring on a line",
        "coordinates": ["x1", "x2"],
        "parameters": {"m1": M1, "m2": M2, "k": K, "L0": L0},
        "bodies": [
            {"name": "a", "mass": "m1", "position": ["x1", 0, 0]},
            {"name": "b", "mass": "m2", "position": ["x2", 0, 0]},
        ],
        "springs": [{"name": "link", "a": "a", "b": "b", "k": "k", "rest_length": "L0"}],
    }
    if initial is not None:
        spec["initial"] = initial
    return spec


def two_masses_rhs(t: float, y: np.ndarray) -> list[float]:
    x1, x2, v1, v2 = y
    d = x2 - x1
    f_b = -K * (abs(d) - L0) * np.sign(d)
    return [v1, v2, -f_b / M1, f_b / M2]


@pytest.mark.parametrize(
    "spec_initial, start",
    [
        (None, (0.0, 1.5, 0.2, -0.4)),  # b right of a
        (None, (1.5, 0.0, 0.2, -0.4)),  # b left of a: the other side
        ({"x1": 0.0, "x2": 1.4}, (2.0, 0.6, -0.1, 0.3)),  # derived for one side, run on the other
        ({"x1": 2.0, "x2": 0.6}, (0.0, 1.4, -0.1, 0.3)),
    ],
)
def test_a_spring_between_two_masses_works_with_either_mass_on_either_side(spec_initial, start):
    result = simulate(
        scene=two_masses(spec_initial),
        request=SimulationRequest(
            initial=dict(zip(["x1", "x2", "x1_dot", "x2_dot"], start, strict=True)),
            t_end=4.0,
            fps=25,
            **TIGHT,
        ),
    )
    assert "stop" not in result["stats"]
    t = np.array(result["t"])
    own = own_run(two_masses_rhs, list(start), t)
    np.testing.assert_allclose(result["q"]["x1"], own.y[0], rtol=0, atol=1e-7)
    np.testing.assert_allclose(result["q"]["x2"], own.y[1], rtol=0, atol=1e-7)
    d = np.array(result["q"]["x2"]) - np.array(result["q"]["x1"])
    assert np.all(np.sign(d) == np.sign(start[1] - start[0]))
    np.testing.assert_allclose(
        result["energy"]["V"], 0.5 * K * (np.abs(d) - L0) ** 2, rtol=1e-10, atol=1e-12
    )


def test_two_masses_colliding_stop_where_the_spring_reaches_zero_length():
    start = [0.0, 0.5, 3.0, -10.0]

    def meet(t, y):
        return y[1] - y[0]

    meet.terminal = True
    own = solve_ivp(
        two_masses_rhs, (0, 3), start, method="DOP853", rtol=1e-12, atol=1e-13, events=meet
    )
    (t_hit,) = own.t_events[0]
    result = simulate(
        scene=two_masses(),
        request=SimulationRequest(
            initial=dict(zip(["x1", "x2", "x1_dot", "x2_dot"], start, strict=True)),
            t_end=3.0,
            fps=50,
            **TIGHT,
        ),
    )
    assert result["stats"]["stop"]["name"] == "link_at_anchor"
    assert result["stats"]["stop"]["t"] == pytest.approx(t_hit, abs=1e-6)
    assert any("Stopped" in w for w in result["warnings"])


# --- the elastic pendulum, its spring along r ------------------------------------------------


def elastic_pendulum_without_initial() -> dict:
    spec = copy.deepcopy(load_scene("elastic_pendulum"))
    spec.pop("initial", None)
    return spec


def test_elastic_pendulum_without_initial_has_the_textbook_r_ddot_at_random_states():
    spec = elastic_pendulum_without_initial()
    p = spec["parameters"]
    c = compiled_spec(spec)
    params = [p[k] for k in c.parameters]
    rhs = c.rhs(params)
    n = c.n
    assert c.coordinates == ["r", "theta"]
    rng = np.random.default_rng(11)
    for _ in range(25):
        r, th = rng.uniform(0.05, 3.0), rng.uniform(-3.0, 3.0)
        rd, thd = rng.uniform(-4, 4), rng.uniform(-4, 4)
        y = np.array([r, th, rd, thd, *[0.0] * c.extras])
        out = rhs(0.0, y)
        r_ddot = r * thd**2 + p["g"] * np.cos(th) - p["k"] / p["m"] * (r - p["l0"])
        th_ddot = -(2 * rd * thd + p["g"] * np.sin(th)) / r
        assert out[n] == pytest.approx(r_ddot, rel=1e-10, abs=1e-10)
        assert out[n + 1] == pytest.approx(th_ddot, rel=1e-10, abs=1e-10)


def test_elastic_pendulum_without_initial_runs_like_the_textbook_equations():
    spec = elastic_pendulum_without_initial()
    p = spec["parameters"]
    start = {"r": 1.3, "theta": 0.6, "r_dot": 0.0, "theta_dot": 0.5}
    result = simulate(
        scene=spec, request=SimulationRequest(initial=start, t_end=3.0, fps=20, **TIGHT)
    )

    def textbook(t, y):
        r, th, rd, thd = y
        return [
            rd,
            thd,
            r * thd**2 + p["g"] * np.cos(th) - p["k"] / p["m"] * (r - p["l0"]),
            -(2 * rd * thd + p["g"] * np.sin(th)) / r,
        ]

    own = own_run(textbook, [start[k] for k in ("r", "theta", "r_dot", "theta_dot")], result["t"])
    np.testing.assert_allclose(result["q"]["r"], own.y[0], atol=1e-7)
    np.testing.assert_allclose(result["q"]["theta"], own.y[1], atol=1e-7)


@pytest.mark.parametrize("initial", [{}, {"r": 0.0, "theta": 0.3}])
def test_elastic_pendulum_at_r_zero_is_refused_naming_initial_r(initial):
    with pytest.raises(SpecError) as err:
        simulate(
            scene=elastic_pendulum_without_initial(),
            request=SimulationRequest(initial=initial, t_end=1.0),
        )
    assert "initial.r" in {e["field"] for e in err.value.errors}


# --- a spring in the plane: ℓ = √(x² + y²), no branch --------------------------------------


def planar_spring() -> dict:
    return {
        "title": "Planar spring",
        "coordinates": ["x", "y"],
        "parameters": {"m": M, "k": K, "L0": L0},
        "bodies": [{"name": "bob", "mass": "m", "position": ["x", "y", 0]}],
        "springs": [{"name": "spring", "a": "O", "b": "bob", "k": "k", "rest_length": "L0"}],
        "initial": {"x": 1.3, "y": -0.4},
    }


def test_a_planar_spring_keeps_its_square_root_length_and_moves_right():
    spec = planar_spring()
    d = derive_model(spec)
    assert d.model.springs[0].branch is None
    x, y = sp.symbols("q0 q1")
    _, _, v = plain(d.work.V, d.model)
    k, l0 = d.model.params["k"], d.model.params["L0"]
    assert sp.simplify(v - k * (sp.sqrt(x**2 + y**2) - l0) ** 2 / 2) == 0

    start = [1.3, -0.4, 0.5, 2.0]

    def own(t, s):
        x, y, vx, vy = s
        r = np.hypot(x, y)
        f = -K * (r - L0) / (M * r)
        return [vx, vy, f * x, f * y]

    result = simulate(
        scene=spec,
        request=SimulationRequest(
            initial=dict(zip(["x", "y", "x_dot", "y_dot"], start, strict=True)),
            t_end=3.0,
            fps=20,
            **TIGHT,
        ),
    )
    sol = own_run(own, start, result["t"])
    np.testing.assert_allclose(result["q"]["x"], sol.y[0], atol=1e-7)
    np.testing.assert_allclose(result["q"]["y"], sol.y[1], atol=1e-7)
    r = np.hypot(result["q"]["x"], result["q"]["y"])
    np.testing.assert_allclose(result["energy"]["V"], 0.5 * K * (r - L0) ** 2, atol=1e-10)


# --- dashpots: F_b = −c((v_b − v_a)·ê)ê -------------------------------------------------------

C = 0.7


def two_bodies_with_dashpot() -> dict:
    return {
        "title": "Two bodies and a dashpot in the plane",
        "coordinates": ["x1", "y1", "x2", "y2"],
        "parameters": {"m1": M1, "m2": M2, "c": C, "k": K},
        "bodies": [
            {"name": "a", "mass": "m1", "position": ["x1", "y1", 0]},
            {"name": "b", "mass": "m2", "position": ["x2", "y2", 0]},
        ],
        "dampers": [{"name": "pot", "a": "a", "b": "b", "c": "c"}],
        "springs": [{"a": "a", "b": "b", "k": "k"}],
        "initial": {"x1": 0.0, "y1": 0.0, "x2": 1.0, "y2": 0.5},
    }


def dashpot_force_on_b(ra, rb, va, vb, c=C) -> np.ndarray:
    e = (rb - ra) / np.linalg.norm(rb - ra)
    return -c * np.dot(vb - va, e) * e


def test_the_generalized_forces_of_a_planar_dashpot_act_only_along_its_line():
    spec = two_bodies_with_dashpot()
    d = derive_model(spec)
    qs, us, exprs = zip(*(plain(Q, d.model) for Q in d.work.Q), strict=True)
    values = {d.model.params[k]: v for k, v in spec["parameters"].items()}
    Q = sp.lambdify([*qs[0], *us[0]], [e.subs(values) for e in exprs], modules="numpy")
    rng = np.random.default_rng(5)
    for _ in range(20):
        q, u = rng.uniform(-2, 2, 4), rng.uniform(-3, 3, 4)
        f_b = dashpot_force_on_b(q[:2], q[2:], u[:2], u[2:])
        np.testing.assert_allclose(Q(*q, *u), [*(-f_b), *f_b], rtol=1e-10, atol=1e-12)


def test_a_dashpot_pair_moves_like_the_hand_written_equations_and_its_work_matches():
    spec = two_bodies_with_dashpot()
    start = [0.0, 0.0, 1.0, 0.5, 0.3, -1.0, -0.5, 2.0]

    def own(t, s):
        ra, rb, va, vb = s[0:2], s[2:4], s[4:6], s[6:8]
        d = rb - ra
        damping = dashpot_force_on_b(ra, rb, va, vb)
        f_b = damping - K * d  # the spring has zero rest length: −k d
        # W_NC: the dashpot's pair of forces does work F_b·(v_b − v_a)
        return [*va, *vb, *(-f_b / M1), *(f_b / M2), np.dot(damping, vb - va)]

    names = ["x1", "y1", "x2", "y2"]
    initial = dict(zip(names + [f"{n}_dot" for n in names], start, strict=True))
    result = simulate(
        scene=spec, request=SimulationRequest(initial=initial, t_end=3.0, fps=20, **TIGHT)
    )
    sol = own_run(own, [*start, 0.0], result["t"])
    for i, name in enumerate(names):
        np.testing.assert_allclose(result["q"][name], sol.y[i], atol=1e-7)
    np.testing.assert_allclose(result["energy"]["W_nc"], sol.y[8], atol=1e-7)
    assert result["stats"]["energy_balance_error"] < 1e-7


@pytest.mark.parametrize("x0", [1.0, -1.0])
def test_a_mass_moving_across_a_dashpot_line_feels_no_damping(x0):
    spec = {
        "title": "Dashpot from O",
        "coordinates": ["x", "y"],
        "parameters": {"m": M, "c": C},
        "bodies": [{"name": "bob", "mass": "m", "position": ["x", "y", 0]}],
        "dampers": [{"a": "O", "b": "bob", "c": "c"}],
        "initial": {"x": x0, "y": 0.0},
    }
    d = derive_model(spec)
    values = {d.model.params[k]: v for k, v in spec["parameters"].items()}
    rows = [plain(Q, d.model) for Q in d.work.Q]
    qs, us = rows[0][0], rows[0][1]
    Q = sp.lambdify([*qs, *us], [r[2].subs(values) for r in rows], modules="numpy")
    # moving perpendicular to the line O–bob: no force at all
    np.testing.assert_allclose(Q(x0, 0.0, 0.0, 1.7), [0.0, 0.0], atol=1e-14)
    # moving along it and across it: only the along-part, −c ẋ, whatever the side
    np.testing.assert_allclose(Q(x0, 0.0, 0.4, 1.7), [-C * 0.4, 0.0], atol=1e-14)
    # an oblique line: only the projection on ê = (3, 4)/5
    e = np.array([0.6, 0.8])
    v = np.array([2.0, -1.0])
    np.testing.assert_allclose(Q(3.0, 4.0, *v), -C * np.dot(v, e) * e, atol=1e-12)
