"""Input whose equations do not determine a motion is refused, naming its field; input that only
looks odd (a negative charge, a negative rotation rate) is accepted and moves right.

The right motions are closed forms written here: cyclotron motion at ω = qB/m (sign included),
and the bead on a hoop spun backwards, placed in N with sympy's own ReferenceFrame.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
import sympy as sp
from fastapi.testclient import TestClient
from scipy.integrate import solve_ivp
from sympy.physics.vector import ReferenceFrame

from app.main import app
from mechanics.derive import derive_model
from mechanics.scenes import load_scene
from mechanics.simulate import SimulationRequest, simulate
from mechanics.spec import SpecError

PENDULUM = {
    "title": "Pendulum",
    "coordinates": ["theta"],
    "parameters": {"m": 1.0, "l": 1.0, "g": 9.81},
    "bodies": [{"name": "bob", "mass": "m", "position": ["l*sin(theta)", "-l*cos(theta)", 0]}],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    "initial": {"theta": 0.5},
}


def pendulum(**changes) -> dict:
    spec = copy.deepcopy(PENDULUM)
    for key, value in changes.items():
        spec[key] = value
    return spec


def refused_fields(call) -> set[str]:
    with pytest.raises(SpecError) as err:
        call()
    return {e["field"] for e in err.value.errors}


# Each posted spec that cannot move, with the field its refusal must name.
REFUSED_SPECS = {
    "zero mass parameter": (pendulum(parameters={"m": 0.0, "l": 1.0, "g": 9.81}), "parameters.m"),
    "negative mass parameter": (
        pendulum(parameters={"m": -1.0, "l": 1.0, "g": 9.81}),
        "parameters.m",
    ),
    "literal zero mass": (
        pendulum(
            bodies=[{"name": "bob", "mass": 0, "position": ["l*sin(theta)", "-l*cos(theta)", 0]}]
        ),
        "bodies[0].mass",
    ),
    "literal negative mass": (
        pendulum(
            bodies=[{"name": "bob", "mass": -2, "position": ["l*sin(theta)", "-l*cos(theta)", 0]}]
        ),
        "bodies[0].mass",
    ),
    "a coordinate that moves nothing": (
        pendulum(coordinates=["theta", "phi"]),
        "coordinates[1]",
    ),
}


@pytest.mark.parametrize("case", list(REFUSED_SPECS))
def test_a_spec_that_cannot_move_is_refused_naming_its_field(case):
    spec, field = REFUSED_SPECS[case]
    assert field in refused_fields(lambda: derive_model(spec))
    assert field in refused_fields(
        lambda: simulate(scene=spec, request=SimulationRequest(t_end=0.5))
    )


@pytest.mark.parametrize("value", [0.0, -1.0])
def test_a_request_with_a_zero_or_negative_mass_is_refused_naming_it(value):
    fields = refused_fields(
        lambda: simulate(
            scene_id="simple_pendulum",
            request=SimulationRequest(parameters={"m": value}, t_end=0.5),
        )
    )
    assert "parameters.m" in fields


def test_a_massless_body_among_massive_ones_is_still_refused():
    spec = {
        "title": "Two bobs, one without mass",
        "coordinates": ["x1", "x2"],
        "parameters": {"m1": 1.0, "m2": 0.0, "k": 3.0},
        "bodies": [
            {"name": "a", "mass": "m1", "position": ["x1", 0, 0]},
            {"name": "b", "mass": "m2", "position": ["x2", 0, 0]},
        ],
        "springs": [{"a": "a", "b": "b", "k": "k"}],
    }
    assert "parameters.m2" in refused_fields(lambda: derive_model(spec))


# --- odd but physical: a negative charge, a negative rotation rate ----------------------------


def charged_particle(q: float) -> dict:
    """F = q v × B with B = B ẑ: (q B ẏ, −q B ẋ, 0)."""
    return {
        "title": "Charge in a magnetic field",
        "coordinates": ["x", "y"],
        "parameters": {"m": 0.5, "q": q, "B": 2.0},
        "bodies": [{"name": "ion", "mass": "m", "position": ["x", "y", 0]}],
        "forces": [{"name": "lorentz", "on": "ion", "vector": ["q*B*y_dot", "-q*B*x_dot", 0]}],
        "initial": {"x": 0.2, "y": -0.1, "x_dot": 1.0, "y_dot": 0.5},
    }


def cyclotron(t: np.ndarray, omega: float, x0, y0, vx0, vy0):
    """ẍ = ω ẏ, ÿ = −ω ẋ with ω = qB/m: the velocity turns at −ω (clockwise for ω > 0)."""
    s, c = np.sin(omega * t), np.cos(omega * t)
    x = x0 + (vx0 * s + vy0 * (1 - c)) / omega
    y = y0 + (vy0 * s - vx0 * (1 - c)) / omega
    return x, y


@pytest.mark.parametrize("charge", [-1.5, 1.5])
@pytest.mark.parametrize("via", ["spec", "request"])
def test_a_charge_of_either_sign_circles_at_qB_over_m_the_right_way_round(charge, via):
    spec = charged_particle(charge if via == "spec" else -charge)
    overrides = {"q": charge} if via == "request" else {}
    result = simulate(
        scene=spec,
        request=SimulationRequest(parameters=overrides, t_end=4.0, fps=20, rtol=1e-11, atol=1e-12),
    )
    omega = charge * 2.0 / 0.5
    init = spec["initial"]
    x, y = cyclotron(
        np.array(result["t"]), omega, init["x"], init["y"], init["x_dot"], init["y_dot"]
    )
    np.testing.assert_allclose(result["q"]["x"], x, atol=1e-7)
    np.testing.assert_allclose(result["q"]["y"], y, atol=1e-7)
    # the magnetic force does no work: the speed stays √(1² + 0.5²)
    speed = np.hypot(result["q_dot"]["x"], result["q_dot"]["y"])
    np.testing.assert_allclose(speed, np.hypot(1.0, 0.5), rtol=1e-8)
    np.testing.assert_allclose(result["energy"]["W_nc"], 0.0, atol=1e-8)
    # sense of rotation: the angular momentum about the orbit's centre has the sign of −q
    cx = init["x"] + init["y_dot"] / omega
    cy = init["y"] - init["x_dot"] / omega
    lz = (np.array(result["q"]["x"]) - cx) * result["q_dot"]["y"] - (
        np.array(result["q"]["y"]) - cy
    ) * result["q_dot"]["x"]
    assert np.all(np.sign(lz) == -np.sign(charge))


def test_a_hoop_spun_backwards_moves_the_bead_the_other_way_round():
    spec = load_scene("bead_on_hoop")
    p = {**spec["parameters"], "Omega": -6.0}
    R, Om, g = p["R"], p["Omega"], p["g"]
    result = simulate(
        scene_id="bead_on_hoop",
        request=SimulationRequest(
            parameters={"Omega": Om}, t_end=2.0, fps=30, rtol=1e-11, atol=1e-12
        ),
    )
    t = np.array(result["t"])
    th0 = spec["initial"]["theta"]
    sol = solve_ivp(
        lambda _, y: [y[1], np.sin(y[0]) * (Om**2 * np.cos(y[0]) - g / R)],
        (0, t[-1]),
        [th0, spec["initial"].get("theta_dot", 0.0)],
        t_eval=t,
        rtol=1e-12,
        atol=1e-13,
        method="DOP853",
    )
    np.testing.assert_allclose(result["q"]["theta"], sol.y[0], atol=1e-7)
    # Where the bead is in N: the hoop frame H turned by Ω t about N.y, placed by sympy itself.
    N = ReferenceFrame("N")
    H = N.orientnew("H", "Axis", [sp.Symbol("a"), N.y])
    a, th = sp.Symbol("a"), sp.Symbol("th")
    r = R * sp.sin(th) * H.x - R * sp.cos(th) * H.y
    xyz = sp.lambdify((a, th), [r.dot(N.x), r.dot(N.y), r.dot(N.z)], modules="numpy")
    x, y, z = xyz(Om * t, sol.y[0])
    bead = result["positions"]["bead"]
    np.testing.assert_allclose(bead["x"], x, atol=1e-7)
    np.testing.assert_allclose(bead["y"], y, atol=1e-7)
    np.testing.assert_allclose(bead["z"], z, atol=1e-7)
    forward = simulate(scene_id="bead_on_hoop", request=SimulationRequest(t_end=2.0, fps=30))
    # same θ(t) (Ω enters squared), mirror-image path: z flips sign
    np.testing.assert_allclose(forward["q"]["theta"], result["q"]["theta"], atol=1e-6)
    np.testing.assert_allclose(forward["positions"]["bead"]["z"], -np.array(z), atol=1e-6)


# --- the same refusals over HTTP: 422 with field paths, never a 500 ---------------------------

BLOCK_ON_SPRING = {
    "title": "Block on a spring",
    "coordinates": ["x"],
    "parameters": {"m": 1.0, "k": 10.0, "L0": 1.0},
    "bodies": [{"name": "block", "mass": "m", "position": ["x", 0, 0]}],
    "springs": [{"a": "O", "b": "block", "k": "k", "rest_length": "L0"}],
}

REFUSED_REQUESTS = {
    **{
        f"derive: {case}": ("/api/v1/derive", {"scene": spec}, field)
        for case, (spec, field) in REFUSED_SPECS.items()
    },
    **{
        f"simulate: {case}": ("/api/v1/simulate", {"scene": spec, "t_end": 0.5}, field)
        for case, (spec, field) in REFUSED_SPECS.items()
    },
    "zero mass by request": (
        "/api/v1/simulate",
        {"scene_id": "simple_pendulum", "parameters": {"m": 0.0}, "t_end": 0.5},
        "parameters.m",
    ),
    "negative mass by request": (
        "/api/v1/simulate",
        {"scene_id": "simple_pendulum", "parameters": {"m": -1.0}, "t_end": 0.5},
        "parameters.m",
    ),
    "block on its spring's anchor": (
        "/api/v1/simulate",
        {"scene": BLOCK_ON_SPRING, "initial": {"x": 0.0}, "t_end": 0.5},
        "initial.x",
    ),
    "elastic pendulum at r = 0": (
        "/api/v1/simulate",
        {"scene_id": "elastic_pendulum", "initial": {"r": 0.0}, "t_end": 0.5},
        "initial.r",
    ),
    "Atwood mass beyond the pulley": (
        "/api/v1/simulate",
        {"scene_id": "atwood_machine", "initial": {"x": 1.5}, "t_end": 0.5},
        "initial",
    ),
}


@pytest.fixture(scope="module")
def client():
    with TestClient(app, raise_server_exceptions=False) as c:
        yield c


@pytest.mark.parametrize("case", list(REFUSED_REQUESTS))
def test_each_refusal_is_a_422_naming_its_field(client, case):
    path, body, field = REFUSED_REQUESTS[case]
    response = client.post(path, json=body)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"]
    assert isinstance(detail, list) and detail
    for item in detail:
        assert set(item) == {"field", "message"}
        assert item["field"] and item["message"]
    assert field in {d["field"] for d in detail}, detail


@pytest.mark.parametrize(
    "body",
    [
        {"scene": charged_particle(-1.5), "t_end": 0.5},
        {"scene_id": "bead_on_hoop", "parameters": {"Omega": -6.0}, "t_end": 0.5},
    ],
)
def test_a_negative_charge_or_rotation_rate_is_accepted_over_http(client, body):
    response = client.post("/api/v1/simulate", json=body)
    assert response.status_code == 200, response.text
    assert response.json()["stats"]["status"] == "ok"
