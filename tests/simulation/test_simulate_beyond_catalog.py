"""Simulation trust, fourth round: a physics play-tester's findings on runs beyond the catalog.

Every expected value is independent of the code under test: closed forms of the motion
(x(t) of a block under a constant force, the small-angle pendulum), the play-tester's own
reading of the physics (a spring of length 0, a block that sticks when |k x| ≤ μ m g), or a
count made here (the coordinates of the spherical pendulum).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from fastapi.testclient import TestClient

from app.main import app

G = 9.81


@pytest.fixture(scope="module")
def client():
    with TestClient(app) as c:
        yield c


def post(client, spec: dict, **body) -> tuple[int, dict]:
    r = client.post("/api/v1/simulate", json={"scene": spec, **body})
    return r.status_code, r.json()


def accuracy_warnings(body: dict) -> list[str]:
    return [w for w in body["warnings"] if "kinetic-energy scale" in w]


# 1. A tiny swing of a heavy bob: |V| = m g l = 9810 J, T ≤ 5e-11 J. One ulp of V is 3.7 % of T.
TINY = {
    "title": "tiny swing",
    "coordinates": ["theta"],
    "parameters": {"m": 1000.0, "l": 1.0, "g": G},
    "bodies": [{"name": "bob", "mass": "m", "position": ["l*sin(theta)", "-l*cos(theta)", 0]}],
    "gravity": {"acceleration": "g"},
    "initial": {"theta": 1e-7, "theta_dot": 0},
}


@pytest.mark.parametrize(
    "options",
    [
        {"method": "DOP853", "rtol": 1e-12, "atol": 1e-13},
        {"method": "dop853_c", "rtol": 1e-12, "atol": 1e-13},
        {"method": "symplectic_euler", "dt": 0.0005},
    ],
)
def test_round_off_of_a_large_potential_is_not_called_an_integration_error(client, options):
    status, body = post(client, TINY, t_end=10, **options)
    assert status == 200, body
    t, theta = np.array(body["t"]), np.array(body["q"]["theta"])
    # small-angle closed form; the sin θ ≈ θ error is ~θ0³ = 1e-21, far below what is compared
    exact = 1e-7 * np.cos(math.sqrt(G) * t)
    # atol = 1e-13 bounds each step's error; Euler's phase error is O(h)
    tol = 2e-12 if options["method"] != "symplectic_euler" else 1e-10
    assert np.max(np.abs(theta - exact)) < tol
    assert accuracy_warnings(body) == []
    assert not any("rtol" in w or "smaller step" in w for w in body["warnings"])


def test_a_real_energy_error_on_the_same_swing_is_still_told(client):
    """Explicit Euler multiplies the energy of a harmonic swing by 1 + (ω h)² each step, so by
    (1 + 9.81e-4)^2000 ≈ 7 over 20 s: measured here with the small-angle energy
    ½ m l² θ̇² + ½ m g l θ², which has no 9810 J term to round."""
    status, body = post(client, TINY, t_end=20, method="euler", dt=0.01)
    assert status == 200, body
    theta, omega = np.array(body["q"]["theta"]), np.array(body["q_dot"]["theta"])
    small = 0.5 * 1000.0 * omega**2 + 0.5 * 1000.0 * G * theta**2
    assert small[-1] / small[0] == pytest.approx((1 + G * 1e-4) ** 2000, rel=0.05)
    (said,) = accuracy_warnings(body)
    assert "drifts" in said and "round-off" not in said


# 2. A potential with sign(x): V = k x sign(x) = k|x|, so F = −k sign(x).
SIGN = {
    "title": "x",
    "coordinates": ["x"],
    "parameters": {"m": 1.0, "k": 1.0},
    "bodies": [{"name": "p", "mass": "m", "position": ["x", 0, 0]}],
    "initial": {"x": 0.5},
    "potentials": [{"name": "s", "expression": "k*x*sign(x)"}],
}


def v_shaped_well(t: np.ndarray) -> np.ndarray:
    """x(t) for m = k = 1, x0 = 0.5 at rest in V = |x|: constant acceleration ∓1 on each side,
    crossing 0 at t = 1 with speed 1, at rest at x = −0.5 at t = 2 (period 4)."""
    first = 0.5 - t**2 / 2
    s = t - 1
    second = -s + s**2 / 2
    return np.where(t <= 1, first, second)


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "RK45"])
@pytest.mark.parametrize("expression", ["k*x*sign(x)", "k*abs(x)"])
def test_sign_in_a_potential_runs_with_the_force_minus_k_sign_x(client, method, expression):
    spec = {**SIGN, "potentials": [{"name": "s", "expression": expression}]}
    status, body = post(client, spec, t_end=2, method=method, rtol=1e-10, atol=1e-10)
    assert status == 200, body
    t, x = np.array(body["t"]), np.array(body["q"]["x"])
    assert np.max(np.abs(x - v_shaped_well(t))) < 1e-6
    assert accuracy_warnings(body) == []


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "rk4"])
@pytest.mark.parametrize("expression", ["k*sign(x)", "k*sign(x)*(x - 1)"])
def test_a_potential_that_jumps_is_refused_naming_it(client, method, expression):
    """V = k sign(x) jumps by 2k at x = 0: its force is the impulse 2kδ(x), which no step
    samples. Refused, never run as if the step were not there (nor a 500)."""
    spec = {**SIGN, "potentials": [{"name": "s", "expression": expression}]}
    status, body = post(client, spec, t_end=2, method=method, dt=0.01)
    assert status == 422, body
    (error,) = body["detail"]
    assert error["field"] == "potentials[0].expression"
    assert "jumps where x = 0" in error["message"]


def test_the_live_javascript_of_a_sign_potential_has_no_delta():
    from mechanics.jscode import live_module
    from mechanics.numeric import compiled_spec

    module = live_module(compiled_spec(SIGN))
    assert "DiracDelta" not in module.source


# 3. A spring from (0, h) to a bead on the x axis: along a line only when h = 0 at run time.
WIRE = {
    "title": "bead on wire with offset spring",
    "coordinates": ["x"],
    "parameters": {"m": 1.0, "k": 10.0, "h": 0.0, "L0": 1.0},
    "points": [{"name": "A", "position": [0, "h", 0]}],
    "bodies": [{"name": "bead", "mass": "m", "position": ["x", 0, 0]}],
    "springs": [{"a": "A", "b": "bead", "k": "k", "rest_length": "L0"}],
    "initial": {"x": 0.3, "x_dot": -5.0},
}


def first_zero_of_x() -> float:
    """For x > 0 and h = 0, ℓ = x and the bead oscillates about L0 with ω = √(k/m):
    x(t) = L0 + (x0 − L0) cos ωt + (v0/ω) sin ωt; the first t with x = 0."""
    from scipy.optimize import brentq

    w = math.sqrt(10.0)

    def x(t: float) -> float:
        return 1.0 + (0.3 - 1.0) * math.cos(w * t) + (-5.0 / w) * math.sin(w * t)

    ts = np.linspace(0, 1, 10001)
    k = int(np.argmax(np.array([x(s) for s in ts]) <= 0))
    return brentq(x, ts[k - 1], ts[k], xtol=1e-14)


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "rk4"])
def test_a_spring_collinear_through_a_parameter_value_stops_at_zero_length(client, method):
    status, body = post(client, WIRE, t_end=1, method=method, dt=0.001)
    assert status == 200, body
    stop = body["stats"]["stop"]
    assert stop is not None and stop["name"].endswith("_at_anchor")
    assert stop["t"] == pytest.approx(first_zero_of_x(), abs=1e-6)
    assert abs(body["q"]["x"][-1]) < 1e-6
    assert min(body["q"]["x"]) > -1e-6  # never carried past the anchor


def test_the_same_spring_off_the_line_passes_under_its_anchor(client):
    """h = 0.6: ℓ ≥ 0.6, never 0, so the bead crosses x = 0 with no stop."""
    status, body = post(client, WIRE, t_end=1, parameters={"h": 0.6})
    assert status == 200, body
    assert body["stats"].get("stop") is None
    assert min(body["q"]["x"]) < -0.1


# 4. Coulomb friction on a spring-held block: m = k = 1, μ m g = 0.3 · 9.81 = 2.943 N.
MU_G = 0.3 * G
COULOMB = {
    "title": "x",
    "coordinates": ["x"],
    "parameters": {"m": 1.0, "k": 1.0, "mu": 0.3, "g": G},
    "bodies": [{"name": "p", "mass": "m", "position": ["x", 0, 0]}],
    "initial": {"x": 0.5},
    "forces": [{"on": "p", "vector": ["-mu*m*g*sign(x_dot)", 0, 0]}],
    "potentials": [{"name": "s", "expression": "k*x**2/2"}],
}


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "Radau", "rk4"])
def test_a_block_held_by_static_friction_sticks_at_once_and_says_why(client, method):
    """|k x0| = 0.5 N ≤ μ m g: it never moves. It used to chatter for 10 s of server time
    ("stiff system: try Radau or BDF", Radau reaching t = 2e-11 s)."""
    status, body = post(client, COULOMB, t_end=2, method=method, dt=0.01)
    assert status == 200, body
    assert body["stats"]["stop"]["t"] == 0.0
    assert body["stats"]["wall_time"] < 2.0
    said = " ".join(body["warnings"])
    assert "sticks" in said and "sign(0) = 0" in said and "sign(x_dot)" in said
    assert "stiff" not in said and "Radau" not in said


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "RK45"])
@pytest.mark.parametrize(
    "x0, t_stick, x_stick",
    [
        # each half swing is harmonic about ±μmg/k, against the motion; it ends at rest after
        # half a period (π s), mirrored about that centre, and sticks once |k x| ≤ μ m g
        (5.0, math.pi, 2 * MU_G - 5.0),  # 5 → 0.886: sticks after one half swing
        (10.0, 2 * math.pi, -2 * MU_G - (2 * MU_G - 10.0)),  # 10 → −4.114 → −1.772
    ],
)
def test_a_sliding_block_stops_where_it_sticks_not_where_it_reverses(
    client, method, x0, t_stick, x_stick
):
    status, body = post(client, COULOMB, t_end=10, method=method, initial={"x": x0})
    assert status == 200, body
    stop = body["stats"]["stop"]
    assert stop is not None and stop["name"] == "sticks_x_dot"
    assert stop["t"] == pytest.approx(t_stick, abs=1e-5)
    assert body["q"]["x"][-1] == pytest.approx(x_stick, abs=1e-5)
    assert abs(body["q"]["x"][-1]) <= MU_G  # k = 1: static friction holds it there


# 5a. The spherical pendulum has two coordinates, θ and the cyclic φ.
def test_the_phase_plane_sentence_counts_a_cyclic_coordinate():
    from mechanics.divergence import classify_divergence

    t = np.linspace(0.0, 20.0, 1201)
    d = np.minimum(1e-9 * np.exp(1.3 * t), 0.2)  # looks exponential; the prior forbids chaos
    said = classify_divergence(t, d, 1.0, n_dof=1, autonomous=True, cyclic=("phi",)).message
    assert "with one coordinate" not in said
    assert "phi is cyclic (its momentum conserved), which leaves one coordinate" in said
    alone = classify_divergence(t, d, 1.0, n_dof=1, autonomous=True).message
    assert "there is one coordinate and no explicit time" in alone


def test_the_spherical_pendulum_run_is_not_told_it_has_one_coordinate(client):
    scene = client.post("/api/v1/derive", json={"scene_id": "spherical_pendulum"}).json()["scene"]
    assert scene["coordinates"] == ["theta", "phi"]  # two, as the play-tester counted
    body = client.post(
        "/api/v1/simulate",
        json={
            "scene_id": "spherical_pendulum",
            "t_end": 60,
            "method": "RK45",
            "rtol": 1e-6,
            "atol": 1e-6,
            "initial": {"theta": 3.0, "phi_dot": 0.3},
        },
    ).json()
    said = " ".join(body["warnings"])
    assert "drift apart in phase" in said  # the sentence that counted "one coordinate"
    assert "with one coordinate" not in said and "phi is cyclic" in said


# 5b. A mass m (1 − t) was run and named where it reached 0; since issue 23 (item 6) a mass
# written in t is refused before any method runs (Lagrange's equations need constant masses):
# tests/spec/test_variable_mass.py posts this spec and expects the 422 on bodies[0].mass.


@pytest.mark.parametrize("method", ["Radau", "BDF"])
def test_an_implicit_run_released_on_the_friction_jump_is_told_so(client, method):
    """Released from rest at x0 = 5 (k x0 > μ m g: it slides, to 2μmg/k − 5 = 0.886 at t = π),
    Radau crept to 4.97 and BDF ran off to −245, with only an energy-balance warning advising
    a tighter rtol. Explicit methods slide correctly (test above)."""
    status, body = post(client, COULOMB, t_end=10, method=method, initial={"x": 5.0})
    assert status == 200, body
    said = " ".join(body["warnings"])
    assert "starts at x_dot = 0, where sign(x_dot)" in said and "explicit method" in said


def test_steps_held_down_at_a_friction_jump_are_not_called_stiffness():
    """Where no sticking stop can be made (equations not solved for q̈, or a declared stop of
    the spec's own), a run that chatters at sign(ẋ) = 0 runs out of time: the advice names
    the jump, not stiffness."""
    from mechanics.integrators import Trajectory
    from mechanics.numeric import compiled_spec
    from mechanics.simulate import SimulationRequest, _why_it_stopped

    c = compiled_spec(COULOMB)
    run = Trajectory(
        np.array([0.0]),
        np.array([[0.5, 0.0, 0.0]]),
        "stopped",
        "wall-time budget of 10 s exhausted at t = 3.3e-05 s",
        10**6,
        10**5,
        0,
        10.0,
        t_reached=3.3e-5,
    )
    (said,) = _why_it_stopped(c, [1.0, 1.0, 0.3, G], SimulationRequest(), run)
    assert "not by stiffness" in said and "sign(x_dot)" in said and "sign(0) = 0" in said
    assert "try Radau" not in said


@pytest.mark.parametrize("method", ["DOP853", "Radau"])
@pytest.mark.parametrize("drag", ["-c*sign(x_dot)*x_dot**2", "c*(sign(x_dot)*abs(x_dot) - x_dot)"])
def test_a_sign_with_no_jump_is_neither_a_stop_nor_a_warning(client, method, drag):
    """Quadratic drag −c sign(ẋ) ẋ² is continuous at ẋ = 0 (and the second force is 0): the
    spring-held block released from rest swings through x = 0 with no stop and no warning.
    Its first turn, with drag vanishing at rest, is near x = −0.5 at t ≈ π (ω = 1)."""
    spec = {**COULOMB, "parameters": {**COULOMB["parameters"], "c": 0.01}}
    spec["forces"] = [{"on": "p", "vector": [drag, 0, 0]}]
    status, body = post(client, spec, t_end=4, method=method)
    assert status == 200, body
    assert body["stats"].get("stop") is None
    assert not any("sign(x_dot)" in w or "sticks" in w for w in body["warnings"])
    x = np.array(body["q"]["x"])
    assert -0.5 <= x.min() < -0.49


def test_the_zero_length_stop_is_found_by_the_c_loop_itself(client):
    """A spring crossing its anchor is smooth on each side: the C run's samples show it, so the
    run is not handed to scipy (no note that it was), and it stops as the others do."""
    status, body = post(client, WIRE, t_end=1, method="dop853_c")
    assert status == 200, body
    assert not any("stepped by scipy" in w for w in body["warnings"])
    assert body["stats"]["stop"]["t"] == pytest.approx(first_zero_of_x(), abs=1e-6)


@pytest.mark.parametrize("y0, stops", [(0.0, True), (0.1, False)])
def test_a_plane_spring_stops_only_when_the_body_goes_through_its_anchor(client, y0, stops):
    """A particle on a spring (ℓ0 = 1) from the origin, in the plane: launched along the x axis
    (y ≡ 0) toward the anchor, its motion is the wire's (ℓ = |x|) and it reaches ℓ = 0 when x
    does; launched 0.1 off the axis it passes beside the anchor and goes on."""
    spec = {
        "title": "plane spring",
        "coordinates": ["x", "y"],
        "parameters": {"m": 1.0, "k": 10.0, "L0": 1.0},
        "bodies": [{"name": "b", "mass": "m", "position": ["x", "y", 0]}],
        "springs": [{"a": "O", "b": "b", "k": "k", "rest_length": "L0"}],
        "initial": {"x": 0.3, "y": y0, "x_dot": -5.0},
    }
    status, body = post(client, spec, t_end=1)
    assert status == 200, body
    stop = body["stats"].get("stop")
    if stops:
        assert stop is not None and stop["name"].endswith("_at_anchor")
        assert stop["t"] == pytest.approx(first_zero_of_x(), abs=1e-6)  # the wire's motion
    else:
        assert stop is None and min(body["q"]["x"]) < -0.1
