"""Trust in stops: a stop is never silently ignored, never fires falsely, and fires on time.

The pendulum θ̈ = −(g/l) sin θ gives every expected time: scipy's event search on these
hand-written equations (not the app's), or closed forms where there are some. A position
x = l√θ has no value past θ = 0; the motion up to there follows from energy conservation with
T = ½ m l² θ̇² (1/(4θ) + sin²θ), V = −m g l cos θ, so the time to reach θ = 0 from rest at θ₀ is
∫ √(M(θ) / (2 m g l (cos θ − cos θ₀))) dθ over (0, θ₀), integrated by quad.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from fastapi.testclient import TestClient
from scipy.integrate import quad, solve_ivp

from app.main import app
from mechanics.integrators import METHODS
from mechanics.simulate import SimulationRequest, simulate
from mechanics.spec import SpecError

G, L = 9.81, 1.0
TIGHT = {"rtol": 1e-11, "atol": 1e-12}


def pendulum(stop: dict | None = None, position: list | None = None, **extra) -> dict:
    spec = {
        "title": "Pendulum",
        "coordinates": ["theta"],
        "parameters": {"m": 1.0, "l": L, "g": G},
        "bodies": [
            {
                "name": "bob",
                "mass": "m",
                "position": position or ["l*sin(theta)", "-l*cos(theta)", 0],
            }
        ],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
        "initial": {"theta": 0.5},
        **extra,
    }
    if stop is not None:
        spec["stops"] = [{"name": "edge", "message": "the model ends", **stop}]
    return spec


def request(method: str = "DOP853", **kw) -> SimulationRequest:
    fixed = {"dt": 1e-3} if METHODS[method].kind == "fixed" else {}
    return SimulationRequest(method=method, **fixed, **{"t_end": 3.0, "fps": 30, **TIGHT, **kw})


def first_zero(theta0: float, omega0: float, t_end: float = 3.0) -> float:
    """When θ first reaches 0 on the hand-written pendulum (scipy's own event search)."""

    def at_zero(t, y):
        return y[0]

    at_zero.terminal = True
    sol = solve_ivp(
        lambda t, y: [y[1], -G / L * math.sin(y[0])],
        (0, t_end),
        [theta0, omega0],
        rtol=1e-12,
        atol=1e-12,
        events=at_zero,
    )
    return float(sol.t_events[0][0])


def refused(spec: dict, req: SimulationRequest | None = None) -> list[dict]:
    with pytest.raises(SpecError) as err:
        simulate(scene=spec, request=req or request())
    return err.value.errors


# --- a stop that cannot be evaluated ------------------------------------------------------------


def test_a_stop_undefined_at_the_start_is_refused_naming_its_field():
    """sqrt(θ − 5) is NaN for every θ the pendulum reaches: it was never checked, silently."""
    (error,) = refused(pendulum({"when": "sqrt(theta - 5)"}))
    assert error["field"] == "stops[0].when"
    assert "undefined" in error["message"]


def test_a_stop_that_becomes_undefined_during_the_run_stops_it_where_it_does():
    """sqrt(θ + 0.3) reaches 0 (then is undefined) where θ = −0.3: a pendulum from rest at 0.5
    gets there at the time of that crossing."""

    def at(t, y):
        return y[0] + 0.3

    at.terminal = True
    sol = solve_ivp(
        lambda t, y: [y[1], -G / L * math.sin(y[0])],
        (0, 3),
        [0.5, 0.0],
        rtol=1e-12,
        atol=1e-12,
        events=at,
    )
    result = simulate(scene=pendulum({"when": "sqrt(theta + 0.3)"}), request=request())
    assert result["stats"]["stop"]["name"] == "edge"
    assert result["stats"]["stop"]["t"] == pytest.approx(sol.t_events[0][0], abs=1e-6)


# --- a stop that cannot change sign ----------------------------------------------------------


@pytest.mark.parametrize("crossing", ["falls", "any"])
@pytest.mark.parametrize("when", ["theta**2", "theta_dot**2 + theta**2", "-theta**2"])
def test_a_stop_that_can_only_touch_zero_is_refused(when, crossing):
    """θ² never changes sign: a run never sees it reach 0 (it never fired), or, with
    crossing = any, a 'bounce' near θ = 0 fired it at the wrong time (0.48 s, not 0.51 s)."""
    (error,) = refused(pendulum({"when": when, "crossing": crossing}))
    assert error["field"] == "stops[0].when"
    assert "never changes sign" in error["message"]


@pytest.mark.parametrize("when", ["1 + theta**2", "theta/theta", "2"])
def test_a_stop_that_is_never_zero_is_refused(when):
    (error,) = refused(pendulum({"when": when}))
    assert error["field"] == "stops[0].when"
    assert "never reaches 0" in error["message"]


@pytest.mark.parametrize("when", ["theta", "1 - theta**2", "cos(theta) - 0.9", "theta_dot"])
def test_a_stop_that_changes_sign_is_accepted(when):
    simulate(scene=pendulum({"when": when, "crossing": "any"}), request=request(t_end=0.1))


def test_a_refused_stop_is_a_422_through_the_api():
    with TestClient(app) as client:
        r = client.post(
            "/api/v1/simulate", json={"scene": pendulum({"when": "theta**2"}), "t_end": 1}
        )
    assert r.status_code == 422, r.text
    assert [e["field"] for e in r.json()["detail"]] == ["stops[0].when"]


# --- a state exactly on a stop's surface ------------------------------------------------------


def test_a_sign_change_stop_at_zero_when_released_moving_does_not_end_the_run_at_the_start():
    """θ = 0 moving at 1 rad/s: the value leaves 0 at once; it changes sign next where the
    pendulum comes back through θ = 0 (half a swing later, by the hand-written equations)."""
    spec = pendulum({"when": "theta", "crossing": "any"}, initial={"theta": 0.0, "theta_dot": 1})
    # after rising, θ comes back to 0 at the first zero of the motion started just after it
    dt = 1e-9
    back = dt + first_zero(dt * 1.0, 1.0 - G / L * math.sin(0.0) * dt)
    result = simulate(scene=spec, request=request())
    stop = result["stats"]["stop"]
    assert stop["t"] > 0.5
    assert stop["t"] == pytest.approx(back, abs=1e-6)


def test_a_velocity_stop_at_release_from_rest_fires_at_the_turning_point():
    """θ̇ = 0 at release is not a reversal; the next one is at the far turning point, half a
    period later: θ goes 0.5 → −0.5, i.e. twice the time to reach θ = 0."""
    spec = pendulum({"when": "theta_dot", "crossing": "any"})
    result = simulate(scene=spec, request=request())
    assert result["stats"]["stop"]["t"] == pytest.approx(2 * first_zero(0.5, 0.0), abs=1e-6)


def test_a_guarded_sign_change_stop_at_zero_still_ends_the_run_at_the_start():
    """Static friction holds a block at rest (`only_if` ≥ 0): the incline's motion ends at t = 0."""
    result = simulate(
        scene_id="incline_friction",
        request=SimulationRequest(parameters={"mu": 0.8}, initial={"s_dot": 0.0}, t_end=1),
    )
    assert result["stats"]["stop"]["name"] == "sticks"
    assert result["stats"]["stop"]["t"] == 0.0


def test_a_falling_stop_at_zero_heading_into_its_forbidden_side_ends_the_run_at_the_start():
    """θ = 0 moving at −1 rad/s with `when` = θ: it enters θ < 0 at once. It used to run a whole
    swing there and stop at t = 2.02 s, showing motion the model forbids."""
    spec = pendulum({"when": "theta"}, initial={"theta": 0.0, "theta_dot": -1.0})
    result = simulate(scene=spec, request=request())
    assert result["stats"]["stop"]["t"] == 0.0
    assert result["t"] == [0.0]


def test_a_falling_stop_at_zero_heading_into_its_allowed_side_runs():
    spec = pendulum({"when": "theta"}, initial={"theta": 0.0, "theta_dot": 1.0})
    result = simulate(scene=spec, request=request())
    stop = result["stats"]["stop"]
    assert stop["t"] > 0.5  # it comes back to θ = 0 half a swing later, not at the start
    assert min(result["q"]["theta"]) >= -1e-9


def test_a_falling_stop_at_zero_at_rest_on_its_surface_runs():
    """The pendulum at rest at θ = 0 stays there: nothing crosses, nothing stops."""
    result = simulate(scene=pendulum({"when": "theta"}, initial={"theta": 0.0}), request=request())
    assert result["stats"]["status"] == "ok"
    assert max(abs(x) for x in result["q"]["theta"]) == 0.0


# --- a declared-positive coordinate -----------------------------------------------------------


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "RK45", "Radau", "rk4"])
@pytest.mark.parametrize(("theta0", "omega0"), [(0.5, 0.0), (0.5, -10.0), (0.5, 6.0), (3.0, 0.0)])
def test_a_positive_coordinate_stops_where_the_hand_written_pendulum_reaches_zero(
    method, theta0, omega0
):
    spec = pendulum(positive_coordinates=["theta"], initial={"theta": theta0})
    result = simulate(scene=spec, request=request(method, initial={"theta_dot": omega0}))
    stop = result["stats"]["stop"]
    assert stop["name"] == "theta_at_zero"
    tol = 1e-6 if method != "rk4" else 1e-5
    assert stop["t"] == pytest.approx(first_zero(theta0, omega0), abs=tol)
    assert all(th > -1e-9 for th in result["q"]["theta"])
    # the pendulum's θ = 0 is no singularity: the message must not say it is one
    assert "singular" not in stop["message"]


@pytest.mark.parametrize("omega0", [10.0, 6.5])
def test_a_positive_coordinate_that_stays_positive_never_stops(omega0):
    """Over the top (ω₀ = 10, or 6.5 > the 2√(g/l)·cos(θ₀/2) ≈ 6.1 needed from 0.5): θ grows."""
    spec = pendulum(positive_coordinates=["theta"])
    result = simulate(scene=spec, request=request(initial={"theta_dot": omega0}))
    assert result["stats"]["status"] == "ok"
    assert min(result["q"]["theta"]) > 0


# --- a position's domain ----------------------------------------------------------------------


def sqrt_position_time(theta0: float) -> float:
    """Time from rest at θ₀ to θ = 0 for x = l√θ, y = −l cos θ, by energy (θ = θ₀ sin²φ)."""

    def integrand(phi: float) -> float:
        th = theta0 * math.sin(phi) ** 2
        dth = 2 * theta0 * math.sin(phi) * math.cos(phi)
        # M/(2 m g l (cos θ − cos θ₀)) with M = m l² (1/(4θ) + sin²θ); 1/(4θ) folded with dθ
        mass_sin = L**2 * (1 / (4 * theta0) + math.sin(th) ** 2 * math.sin(phi) ** 2)
        drop = 2 * G * L * (math.cos(th) - math.cos(theta0))
        return math.sqrt(mass_sin / drop) * dth / math.sin(phi) if phi > 0 else 0.0

    return quad(integrand, 0, math.pi / 2, limit=200, epsabs=1e-12, epsrel=1e-12)[0]


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "RK45"])
def test_a_position_with_a_root_stops_at_the_end_of_its_domain(method):
    """x = l√θ: the run stops at θ = 0 where the energy integral puts it; it used to run on
    past it (θ < 0, x undefined), flagged only by its energy drift."""
    spec = pendulum(position=["l*sqrt(theta)", "-l*cos(theta)", 0])
    result = simulate(scene=spec, request=request(method))
    stop = result["stats"]["stop"]
    assert stop["name"] == "bob_domain_end"
    assert "undefined past theta = 0" in stop["message"]
    assert stop["t"] == pytest.approx(sqrt_position_time(0.5), abs=1e-5)
    assert all(th > -1e-6 for th in result["q"]["theta"])
    assert not any("drifted" in w for w in result["warnings"])


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "RK45", "LSODA"])
def test_a_bead_on_a_parabola_in_a_folded_coordinate_stops_at_the_vertex(method):
    """x = √θ, y = θ is the bead on y = x² with θ = x²; θ cannot go past the vertex, where the
    bead would carry on to x < 0, and the steps bounced off θ = 0 instead (a mirrored motion,
    flagged only by a 78 % energy drift). In x, ½(1 + 4x²)ẋ² = g(x₀² − x²), so with
    x = x₀ sin φ the time to the vertex is ∫₀^{π/2} √((1 + 4x₀² sin²φ)/(2g)) dφ."""
    x0 = math.sqrt(0.5)
    expected = quad(
        lambda p: math.sqrt((1 + 4 * x0**2 * math.sin(p) ** 2) / (2 * G)), 0, math.pi / 2
    )
    spec = pendulum(position=["sqrt(theta)", "theta", 0])
    result = simulate(scene=spec, request=SimulationRequest(method=method, t_end=2.0))
    stop = result["stats"]["stop"]
    assert stop["name"] == "bob_domain_end"
    assert stop["t"] == pytest.approx(expected[0], abs=1e-4)
    assert not any("drifted" in w for w in result["warnings"])


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "rk4"])
def test_a_pendulum_in_the_square_of_its_angle_stops_where_the_angle_reaches_zero(method):
    """x = l sin√θ, y = −l cos√θ is the pendulum in φ = √θ (T = ½ m l² φ̇²), folded: θ = φ²
    touches 0 where φ passes 0, never changes sign there, and cannot go on. The stop is at the
    hand-written pendulum's first zero of φ from φ₀ = √θ₀, φ̇₀ = θ̇₀/(2√θ₀). It ran on, or
    (rk4) ended 'non-finite' with no reason."""
    theta0, omega0 = 0.5, -1.0
    phi0, phidot0 = math.sqrt(theta0), omega0 / (2 * math.sqrt(theta0))
    spec = pendulum(position=["l*sin(sqrt(theta))", "-l*cos(sqrt(theta))", 0])
    result = simulate(scene=spec, request=request(method, initial={"theta_dot": omega0}))
    stop = result["stats"]["stop"]
    assert stop["name"] == "bob_domain_end"
    tol = 1e-5 if method != "rk4" else 1e-4  # rk4 at dt = 1e-3 stops a step's error away
    assert stop["t"] == pytest.approx(first_zero(phi0, phidot0), abs=tol)


def test_a_position_whose_root_never_ends_has_no_domain_stop():
    """√(l² + θ²) is defined for every θ: no stop, and the pendulum-like run is ok."""
    spec = pendulum(position=["l*sin(theta)", "-sqrt(l**2 + theta**2)", 0])
    result = simulate(scene=spec, request=request(t_end=1.0))
    assert "stop" not in result["stats"]


def test_a_position_started_outside_its_domain_is_refused():
    spec = pendulum(position=["l*sqrt(theta)", "-l*cos(theta)", 0], initial={"theta": -0.2})
    errors = refused(spec)
    assert errors[0]["field"] == "initial.theta"  # the coordinate that puts it there


# --- a root of a square in a position ----------------------------------------------------------


@pytest.mark.parametrize(
    "text",
    [
        "l*sqrt(sin(theta)**2)",
        "l*sqrt(theta**2)",
        "(sin(theta)**2)**(1/2)",
        "(sin(theta)**2)**0.5",
        "l*sqrt(theta**2 - 2*theta + 1)",
        "sqrt(l**2*theta**2)",
        "l*sqrt(1 - cos(theta)**2)",
    ],
)
def test_a_root_of_a_square_of_a_coordinate_in_a_position_is_refused_like_abs(text):
    """√(f²) = |f|: a kink where f = 0 (|sin θ| at θ = 0), refused as abs() is."""
    spec = pendulum(position=[text, "-l*cos(theta)", 0])
    with TestClient(app) as client:
        for route in ("derive", "simulate"):
            r = client.post(f"/api/v1/{route}", json={"scene": spec})
            assert r.status_code == 422, (route, r.text)
            (error,) = r.json()["detail"]
            assert error["field"] == "bodies[0].position[0]"
            assert "sqrt() of a square" in error["message"]


@pytest.mark.parametrize(
    "text", ["sqrt(l**2)*sin(theta)", "l*sin(theta)*sqrt(4)", "sqrt(1 + theta**2)"]
)
def test_a_root_of_a_constant_or_of_a_positive_expression_passes(text):
    from mechanics.derive import derive_model

    derive_model(pendulum(position=[text, "-l*cos(theta)", 0]))


def test_a_root_of_a_square_stays_allowed_outside_positions():
    """A force may hold |v| (drag ∝ v|v|): it is not differentiated in time."""
    from mechanics.derive import derive_model

    spec = pendulum(
        forces=[{"on": "bob", "vector": ["-theta_dot*sqrt(theta_dot**2)", 0, 0]}],
    )
    derive_model(spec)


def test_ignore_samples_helper_is_consistent():
    """The pendulum's samples are finite and the run is ok (sanity for the fixtures above)."""
    result = simulate(scene=pendulum(), request=request(t_end=1.0))
    assert result["stats"]["status"] == "ok"
    assert np.all(np.isfinite(result["q"]["theta"]))
