"""Acceptance set beyond the catalog: ~30 posted systems the built-in scenes do not cover.

Every expectation is independent of the engine: a hand-written Lagrangian and loads given to
sympy's LagrangesMethod (tests/support/beyond/systems.py), our own integration of those equations
(scipy DOP853 at rtol 1e-12), our own linearization, or a closed form (steady precession,
Euler's equations, cyclotron motion, Kepler's equation, constant accelerations of a wedge and
a double Atwood machine from Newton's laws). The engine is only asked through its entries:
`derive_model`, `simulate`, `equilibria`, and its errors.

Tests failing today because of a known engine issue carry ``xfail(strict=True)`` with the item
("issue 11 item N"), so the suite flips loudly when the fix lands.
"""

from __future__ import annotations

import functools
import json
import math
import os
import subprocess
import sys
import zlib

import numpy as np
import pytest
import scipy.optimize
from beyond.reference import Reference, engine_reference, linear_modes
from beyond.systems import SYSTEMS, System, inertia_matrix
from scipy.integrate import solve_ivp

from mechanics.derive import derive_model
from mechanics.equilibria import equilibria
from mechanics.simulate import SimulationRequest, simulate
from mechanics.spec import SpecError

G = 9.81
ITEM6 = "issue 11 item 6: degenerate input must be refused (422) naming the field"

#: test kind -> {system id: reason}: what fails today, with the issue item it waits for.
KNOWN: dict[str, dict[str, str]] = {
    "matrices": {},
    "run": {},
    "warnings": {},
}


def cases(kind: str, ids=None):
    """Parametrize over systems, marking slow ones and today's known failures of this kind."""
    out = []
    for sid in ids or SYSTEMS:
        marks = []
        if SYSTEMS[sid].slow:
            marks.append(pytest.mark.slow)
        reason = KNOWN[kind].get(sid) or SYSTEMS[sid].known.get(kind)
        if reason:
            marks.append(pytest.mark.xfail(strict=True, reason=reason))
        out.append(pytest.param(sid, id=sid, marks=marks))
    return out


@functools.cache
def derived(sid: str):
    return derive_model(SYSTEMS[sid].spec)


@functools.cache
def reference(sid: str) -> Reference:
    return SYSTEMS[sid].reference()


@functools.cache
def engine(sid: str) -> Reference:
    d = derived(sid)
    spec = SYSTEMS[sid].spec
    return engine_reference(
        d.work.mass_matrix, d.work.forcing, spec["coordinates"], list(spec["parameters"])
    )


def request(system: System, **overrides) -> SimulationRequest:
    run = {**system.run, **overrides}
    return SimulationRequest(
        parameters=run.get("parameters", {}),
        initial=run["initial"],
        t_end=run["t_end"],
        fps=run["fps"],
        method="DOP853",
        rtol=1e-11,
        atol=1e-12,
        check_sensitivity=False,
    )


@functools.cache
def engine_run(sid: str) -> dict:
    system = SYSTEMS[sid]
    return simulate(scene=system.spec, request=request(system))


def initial_state(system: System, initial: dict, names=None) -> np.ndarray:
    names = names or system.spec["coordinates"]
    return np.array(
        [initial.get(q, 0.0) for q in names] + [initial.get(f"{q}_dot", 0.0) for q in names]
    )


def rng_for(sid: str) -> np.random.Generator:
    return np.random.default_rng(zlib.crc32(sid.encode()))


def close(actual, expected, rel: float) -> bool:
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    return bool(
        np.max(np.abs(actual - expected)) <= rel * max(1.0, float(np.max(np.abs(expected))))
    )


def trajectory(result: dict, names) -> tuple[np.ndarray, np.ndarray]:
    q = np.array([result["q"][n] for n in names])
    qd = np.array([result["q_dot"][n] for n in names])
    return np.array(result["t"]), np.vstack([q, qd])


# --- (1) M and f against LagrangesMethod ---------------------------------------------------


def states_by_side(system: System, own: bool, count: int = 6):
    """Random states with every spring on the side of its anchor the spec starts on (own), or
    with at least one spring on the other side."""
    rng, out = rng_for(system.id + str(own)), []
    while len(out) < count:
        (state,) = system.states(rng, 1)
        if system.spring_sides is None or (system.side(state[1]) == system.own_side) == own:
            out.append(state)
    return out


@pytest.mark.parametrize("sid", cases("matrices"))
def test_mass_matrix_and_forcing_match_lagranges_method(sid):
    compare_matrices(SYSTEMS[sid], states_by_side(SYSTEMS[sid], own=True))


SPRINGS_ON_A_LINE = [s.id for s in SYSTEMS.values() if s.spring_sides is not None]


@pytest.mark.parametrize("sid", SPRINGS_ON_A_LINE)
def test_mass_matrix_and_forcing_on_the_other_side_of_an_anchor(sid):
    """At states with a spring on the other side of its anchor, the derivation a run from there
    gets (the branch variant: ℓ = −p instead of p) matches the reference written with |d|."""
    system = SYSTEMS[sid]
    model = derived(sid).model
    spec = system.spec
    for state in states_by_side(system, own=False):
        time, q, u = state
        values = {model.names[n]: float(v) for n, v in spec["parameters"].items()}
        values.update(
            {model.names[f"{n}_dot"]: float(v) for n, v in zip(spec["coordinates"], u, strict=True)}
        )
        values.update(
            {model.names[n]: float(v) for n, v in zip(spec["coordinates"], q, strict=True)}
        )
        values[model.names["t"]] = float(time)
        branches = {
            i: (s.sign if float(s.branch.xreplace(values)) > 0 else -s.sign)
            for i, s in enumerate(model.springs)
            if s.branch is not None
        }
        other = derive_model(spec, branches)
        theirs = engine_reference(
            other.work.mass_matrix,
            other.work.forcing,
            spec["coordinates"],
            list(spec["parameters"]),
        )
        ours = reference(sid)
        M_ref, f_ref = ours.numeric(time, q, u, system.parameters)
        M, f = theirs.numeric(time, q, u, system.parameters)
        assert close(M, M_ref, 1e-9) and close(f, f_ref, 1e-9), (branches, f, f_ref)


def compare_matrices(system: System, states) -> None:
    sid = system.id
    ours, theirs, p = reference(sid), engine(sid), system.parameters
    assert theirs.names == ours.names
    for time, q, u in states:
        M_ref, f_ref = ours.numeric(time, q, u, p)
        M, f = theirs.numeric(time, q, u, p)
        where = f"at t={time:.3f}, q={np.round(q, 4).tolist()}, q_dot={np.round(u, 4).tolist()}"
        assert close(M, M_ref, 1e-9), f"M differs {where}:\n{M}\nexpected\n{M_ref}"
        assert close(f, f_ref, 1e-9), f"f differs {where}:\n{f}\nexpected\n{f_ref}"


# --- (2) simulate against our own integration, (5) without false alarms --------------------


@pytest.mark.parametrize("sid", cases("run"))
def test_simulation_matches_own_integration(sid):
    system = SYSTEMS[sid]
    result = engine_run(sid)
    assert result["stats"]["status"] == "ok", result["warnings"]
    names = system.spec["coordinates"]
    t, y = trajectory(result, names)
    assert t[-1] == pytest.approx(system.run["t_end"], abs=1.0 / system.run["fps"])
    p = {**system.parameters, **system.run.get("parameters", {})}
    expected = reference(sid).integrate(p, initial_state(system, system.run["initial"]), t)
    for i, name in enumerate([*names, *(f"{n}_dot" for n in names)]):
        err = np.max(np.abs(y[i] - expected[i]))
        scale = max(1.0, float(np.max(np.abs(expected[i]))))
        assert err <= 1e-7 * scale, f"{name}: max deviation {err:.3e} (scale {scale:.3g})"


@pytest.mark.parametrize("sid", cases("warnings"))
def test_correct_run_has_no_energy_drift_warning(sid):
    result = engine_run(sid)
    drift = [w for w in result["warnings"] if "drift" in w.lower() or "conserved" in w.lower()]
    assert not drift, f"false alarm on an accurate run: {drift}; stats {result['stats']}"


# --- closed forms ---------------------------------------------------------------------------


def engine_accelerations(sid: str, time: float, q, u, parameters=None) -> np.ndarray:
    p = {**SYSTEMS[sid].parameters, **(parameters or {})}
    return engine(sid).accelerations(time, q, u, p)


def test_heavy_top_steady_precession_closed_form():
    """m g h = φ̇ (I3 ω3 − I1' φ̇ cos θ), I1' = I1 + m h²: then θ stays put and φ̇ is constant."""
    sid = "heavy_symmetric_top"
    p = SYSTEMS[sid].parameters
    m, h, I1, I3 = p["m"], p["h"], p["I1"], p["I3"]
    theta0, precession = 0.7, 1.3
    I1p = I1 + m * h**2
    omega3 = (m * G * h / precession + I1p * precession * math.cos(theta0)) / I3
    spin = omega3 - precession * math.cos(theta0)
    acc = engine_accelerations(sid, 0.0, [0.2, theta0, -0.4], [precession, 0.0, spin])
    assert np.max(np.abs(acc)) < 1e-9 * max(1.0, spin * precession), acc
    initial = {"phi": 0.0, "theta": theta0, "phi_dot": precession, "psi_dot": spin}
    result = simulate(scene=SYSTEMS[sid].spec, request=request(SYSTEMS[sid], initial=initial))
    t = np.array(result["t"])
    assert np.max(np.abs(np.array(result["q"]["theta"]) - theta0)) < 1e-7
    assert np.max(np.abs(np.array(result["q"]["phi"]) - precession * t)) < 1e-7


def _omega_and_rate(q, u, a):
    """ω (body axes) and ω̇ from Euler-angle rates and accelerations, by hand (z-x-z)."""
    phi, th, psi = q
    dphi, dth, dpsi = u
    J = np.array(
        [
            [math.sin(th) * math.sin(psi), math.cos(psi), 0.0],
            [math.sin(th) * math.cos(psi), -math.sin(psi), 0.0],
            [math.cos(th), 0.0, 1.0],
        ]
    )
    dJ = np.array(
        [
            [
                math.cos(th) * dth * math.sin(psi) + math.sin(th) * math.cos(psi) * dpsi,
                -math.sin(psi) * dpsi,
                0.0,
            ],
            [
                math.cos(th) * dth * math.cos(psi) - math.sin(th) * math.sin(psi) * dpsi,
                -math.cos(psi) * dpsi,
                0.0,
            ],
            [-math.sin(th) * dth, 0.0, 0.0],
        ]
    )
    return J @ u, J @ a + dJ @ u


def test_free_body_obeys_eulers_equations():
    """I ω̇ = −ω × (I ω) in body axes, for a full (non-diagonal) central inertia tensor."""
    sid = "free_rigid_body"
    inertia = inertia_matrix(SYSTEMS[sid].parameters)
    for time, q, u in SYSTEMS[sid].states(rng_for(sid + "euler"), 8):
        a = engine_accelerations(sid, time, q, u)
        w, w_dot = _omega_and_rate(q, u, a)
        expected = np.linalg.solve(inertia, -np.cross(w, inertia @ w))
        assert close(w_dot, expected, 1e-9), (q, u, w_dot, expected)


@pytest.mark.slow
def test_free_body_run_conserves_energy_and_angular_momentum():
    sid = "free_rigid_body"
    inertia = inertia_matrix(SYSTEMS[sid].parameters)
    names = SYSTEMS[sid].spec["coordinates"]
    _, y = trajectory(engine_run(sid), names)
    energy, momentum = [], []
    for k in range(y.shape[1]):
        w, _ = _omega_and_rate(y[:3, k], y[3:, k], np.zeros(3))
        energy.append(w @ inertia @ w / 2)
        momentum.append(np.linalg.norm(inertia @ w))
    assert np.ptp(energy) < 1e-8 * energy[0]
    assert np.ptp(momentum) < 1e-8 * momentum[0]


@pytest.mark.parametrize("sid", ["pendulum_horizontally_driven_pivot", "kapitza_pendulum"])
def test_driven_pivot_closed_form(sid):
    """θ̈ = −(g sin θ + ẍ_s cos θ + ÿ_s sin θ)/l for a pivot at (x_s(t), y_s(t))."""
    p = SYSTEMS[sid].parameters
    vertical = sid.startswith("kapitza")
    for time, q, u in SYSTEMS[sid].states(rng_for(sid + "closed"), 6):
        th = q[0]
        drive = -p["a"] * p["w"] ** 2 * math.cos(p["w"] * time)
        xs_dd, ys_dd = (0.0, drive) if vertical else (drive, 0.0)
        expected = -(G * math.sin(th) + xs_dd * math.cos(th) + ys_dd * math.sin(th)) / p["l"]
        assert engine_accelerations(sid, time, q, u)[0] == pytest.approx(
            expected, rel=1e-9, abs=1e-9
        )


def test_kapitza_pendulum_stays_inverted():
    """a²ω² = 25 > 2 g l: the inverted position is stable on average."""
    theta = np.array(engine_run("kapitza_pendulum")["q"]["theta"])
    assert np.max(np.abs(theta - math.pi)) < 0.3


def test_drag_projectile_closed_form():
    sid = "drag_projectile"
    p, run = SYSTEMS[sid].parameters, SYSTEMS[sid].run["initial"]
    tau = p["m"] / p["c"]
    t, y = trajectory(engine_run(sid), ["x", "y"])
    decay = 1.0 - np.exp(-t / tau)
    x = run["x_dot"] * tau * decay
    vt = G * tau  # terminal speed
    yy = (run["y_dot"] + vt) * tau * decay - vt * t
    assert np.max(np.abs(y[0] - x)) < 1e-8 * max(1.0, np.max(np.abs(x)))
    assert np.max(np.abs(y[1] - yy)) < 1e-8 * max(1.0, np.max(np.abs(yy)))


@pytest.mark.parametrize(
    ("sid", "charge"),
    [
        ("lorentz_positive_charge", None),
        ("lorentz_negative_charge", None),
        ("lorentz_negative_charge", -3.0),  # a negative value posted in the request
    ],
    ids=["positive", "negative", "negative_from_request"],
)
def test_cyclotron_motion_closed_form(sid, charge):
    """m v̇ = q v × B ẑ: v turns at ω = qB/m (clockwise for q > 0), speed and centre fixed."""
    system = SYSTEMS[sid]
    overrides = {} if charge is None else {"parameters": {"qe": charge}}
    result = simulate(scene=system.spec, request=request(system, **overrides))
    assert result["stats"]["status"] == "ok"
    p = {**system.parameters, **overrides.get("parameters", {})}
    w = p["qe"] * p["B"] / p["m"]
    s = system.run["initial"]
    x0, y0, vx, vy = s["x"], s["y"], s["x_dot"], s["y_dot"]
    t, y = trajectory(result, ["x", "y"])
    x = x0 + (vx * np.sin(w * t) - vy * np.cos(w * t) + vy) / w
    yy = y0 + (vx * np.cos(w * t) - vx + vy * np.sin(w * t)) / w
    assert np.max(np.abs(y[0] - x)) < 1e-7
    assert np.max(np.abs(y[1] - yy)) < 1e-7


def test_disk_in_cylinder_closed_form():
    """T = ¾ m (R − r)² θ̇²: θ̈ = −2 g sin θ / (3 (R − r))."""
    sid = "disk_rolling_in_cylinder"
    p = SYSTEMS[sid].parameters
    for time, q, u in SYSTEMS[sid].states(rng_for(sid + "closed")):
        expected = -2 * G * math.sin(q[0]) / (3 * (p["R"] - p["r"]))
        assert engine_accelerations(sid, time, q, u)[0] == pytest.approx(expected, rel=1e-9)


def wedge_accelerations(p) -> tuple[float, float]:
    M, m, a = p["M"], p["m"], p["alpha"]
    den = M + m * math.sin(a) ** 2
    return -m * G * math.sin(a) * math.cos(a) / den, (M + m) * G * math.sin(a) / den


def test_wedge_closed_form():
    sid = "block_on_moving_wedge"
    X_dd, s_dd = wedge_accelerations(SYSTEMS[sid].parameters)
    for time, q, u in SYSTEMS[sid].states(rng_for(sid + "closed")):
        assert engine_accelerations(sid, time, q, u) == pytest.approx([X_dd, s_dd], rel=1e-9)
    init = SYSTEMS[sid].run["initial"]
    t, y = trajectory(engine_run(sid), ["X", "s"])
    assert np.max(np.abs(y[0] - (init["X_dot"] * t + X_dd * t**2 / 2))) < 1e-8
    assert np.max(np.abs(y[1] - (init["s"] + s_dd * t**2 / 2))) < 1e-8


def test_double_atwood_matches_newton():
    """Newton: m_i a_i = T_i − m_i g, T1 = 2 T2 (massless pulley), a1 = −ẍ, a2 = ẍ − ÿ,
    a3 = ẍ + ÿ; solved for ẍ, ÿ, T1, T2."""
    sid = "double_atwood"
    p = SYSTEMS[sid].parameters
    m1, m2, m3 = p["m1"], p["m2"], p["m3"]
    A = np.array([[-m1, 0, -1, 0], [m2, -m2, 0, -1], [m3, m3, 0, -1], [0, 0, 1, -2]], dtype=float)
    b = np.array([-m1 * G, -m2 * G, -m3 * G, 0.0])
    x_dd, y_dd, *_ = np.linalg.solve(A, b)
    for time, q, u in SYSTEMS[sid].states(rng_for(sid + "closed")):
        assert engine_accelerations(sid, time, q, u) == pytest.approx([x_dd, y_dd], rel=1e-9)


def test_kepler_orbit_follows_keplers_equation():
    """Started at periapsis: r(t) = a (1 − e cos E), E − e sin E = n t; H = r × v constant."""
    sid = "kepler_3d"
    p, init = SYSTEMS[sid].parameters, SYSTEMS[sid].run["initial"]
    mu = p["mu"]
    r0, v0 = init["x"], math.hypot(init["y_dot"], init["z_dot"])
    a = -mu / (2 * (v0**2 / 2 - mu / r0))
    e = 1 - r0 / a
    n = math.sqrt(mu / a**3)
    t, y = trajectory(engine_run(sid), ["x", "y", "z"])
    anomaly = np.array(
        [
            scipy.optimize.brentq(lambda E, M=n * ti: E - e * math.sin(E) - M, -1, n * ti + 2)
            for ti in t
        ]
    )
    r = np.linalg.norm(y[:3], axis=0)
    assert np.max(np.abs(r - a * (1 - e * np.cos(anomaly)))) < 1e-7
    H = np.cross(y[:3].T, y[3:].T)
    assert np.max(np.abs(H - H[0])) < 1e-8


def test_spherical_pendulum_conserves_vertical_angular_momentum():
    sid = "spherical_pendulum_z_up"
    result = engine_run(sid)
    theta, phi_dot = np.array(result["q"]["theta"]), np.array(result["q_dot"]["phi"])
    lz = np.sin(theta) ** 2 * phi_dot
    assert np.ptp(lz) < 1e-8 * abs(lz[0])


# --- (3) equilibria against our own linearization --------------------------------------------


def turntable_closed_form(p) -> list[float]:
    """Rest length = a: stiffness 2kx along x, 2ky along y, none across, at the centre. In the
    table's frame s² − (ωx² + ωy² + 2Ω²) s + (ωx² − Ω²)(ωy² − Ω²) = 0 for s = ω²."""
    wx2, wy2, om2 = 2 * p["kx"] / p["m"], 2 * p["ky"] / p["m"], p["Omega"] ** 2
    return sorted(
        math.sqrt(s) for s in np.roots([1, -(wx2 + wy2 + 2 * om2), (wx2 - om2) * (wy2 - om2)])
    )


def isotropic(p) -> list[float]:
    w0 = math.sqrt(2 * (p["kx"] + p["ky"]) / p["m"])  # rest length 0: ½k|r − a|² is isotropic
    return sorted([w0 - abs(p["Omega"]), w0 + abs(p["Omega"])])


EQUILIBRIA = [
    (
        "bead_on_spinning_parabola",
        [0.0],
        lambda p: [math.sqrt(2 * G * p["a"] - p["Omega"] ** 2)],
        "",
    ),
    ("disk_rolling_in_cylinder", [0.0], lambda p: [math.sqrt(2 * G / (3 * (p["R"] - p["r"])))], ""),
    (
        "elastic_pendulum_cartesian",
        [0.0, -(1.0 + G / 30.0)],
        lambda p: sorted([math.sqrt(p["k"] / p["m"]), math.sqrt(G / (p["l0"] + G / p["k"]))]),
        "",
    ),
    ("turntable_isotropic", [0.0, 0.0], isotropic, ""),
    ("turntable_negative_omega", [0.0, 0.0], isotropic, ""),
    ("turntable_gyro_stabilized", [0.0, 0.0], turntable_closed_form, ""),
    ("turntable_springs_rest_length", [0.0, 0.0], None, ""),
    ("rod_pendulum_on_turntable", None, None, "slow"),
    ("triple_pendulum", [0.0, 0.0, 0.0], None, ""),
]


def own_equilibrium(sid: str, guess) -> np.ndarray:
    ours, p = reference(sid), SYSTEMS[sid].parameters
    n = len(guess)
    return scipy.optimize.fsolve(
        lambda q: ours.numeric(0.0, q, np.zeros(n), p)[1], guess, xtol=1e-13
    )


@pytest.mark.parametrize(
    ("sid", "q0", "closed"),
    [
        pytest.param(
            sid,
            q0,
            closed,
            id=sid,
            marks=[pytest.mark.slow] if why == "slow" else [],
        )
        for sid, q0, closed, why in EQUILIBRIA
    ],
)
@pytest.mark.timeout(600)  # sympy's solve takes ~20 s of CPU for the rod on a turntable
def test_equilibrium_stability_and_frequencies(sid, q0, closed):
    p = SYSTEMS[sid].parameters
    q0 = own_equilibrium(sid, q0 if q0 is not None else [0.3])
    growth, freqs = linear_modes(reference(sid), q0, p)
    if closed is not None:
        assert freqs == pytest.approx(closed(p), rel=1e-6)  # our linearization vs closed form
        freqs = closed(p)
    stable = growth < 1e-6
    found = equilibria(derived(sid), p)["equilibria"]
    names = SYSTEMS[sid].spec["coordinates"]
    near = [e for e in found if np.allclose([e["q"][n] for n in names], q0, atol=1e-6)]
    assert near, f"no equilibrium at {q0.tolist()} among {[e['q'] for e in found]}"
    assert near[0]["stable"] is stable
    if stable:
        assert sorted(near[0]["frequencies"]) == pytest.approx(freqs, rel=1e-6)


# --- springs on both sides of their anchors, and stops ---------------------------------------


@pytest.mark.parametrize(
    ("sid", "initial"),
    [
        ("spring_line_left_of_anchor", {"x": 1.4, "x_dot": -0.2}),
        ("spring_chain_between_walls", {"x1": 0.9, "x2": 2.1, "x3": 2.9}),
        ("two_masses_spring_line", {"x1": 0.0, "x2": -1.3}),
        ("elastic_pendulum_no_initial", {"r": -1.2, "theta": 0.4}),
    ],
    ids=["line_right_of_anchor", "chain_all_right", "line_crossed_order", "elastic_negative_r"],
)
def test_run_from_the_other_side_of_an_anchor(sid, initial):
    """A run posted on the other side of an anchor than the spec's own state: V = ½k(|d| − ℓ0)²
    there too (the same system, integrated by us with |d|)."""
    system = SYSTEMS[sid]
    run = dict(system.run, initial=initial, t_end=1.0)
    result = simulate(scene=system.spec, request=request(system, **run))
    assert result["stats"]["status"] == "ok", result["warnings"]
    names = system.spec["coordinates"]
    t, y = trajectory(result, names)
    expected = reference(sid).integrate(system.parameters, initial_state(system, initial), t)
    assert np.max(np.abs(y - expected)) < 1e-7 * max(1.0, float(np.max(np.abs(expected))))


def test_spring_run_stops_where_the_length_reaches_zero():
    """Crossing the anchor: ℓ → 0, where ½k(|x| − ℓ0)² has a kink; the run must stop there."""
    sid = "spring_line_left_of_anchor"
    system = SYSTEMS[sid]
    initial = {"x": -0.5, "x_dot": 4.0}
    ours, p = reference(sid), system.parameters

    def rhs(time, y):
        return [y[1], ours.accelerations(time, y[:1], y[1:], p)[0]]

    def at_anchor(time, y):
        return y[0]

    at_anchor.terminal = True
    sol = solve_ivp(rhs, (0, 2), [-0.5, 4.0], events=at_anchor, rtol=1e-12, atol=1e-12)
    t_cross = float(sol.t_events[0][0])
    result = simulate(scene=system.spec, request=request(system, initial=initial, t_end=2.0))
    assert result["stats"]["status"] != "ok"
    assert result["warnings"]
    assert t_cross - 1.0 / system.run["fps"] - 1e-9 <= result["t"][-1] <= t_cross + 1e-6


def test_stop_condition_ends_the_run_where_the_block_leaves_the_wedge():
    """stops: when = Lw − s; s(t) = s0 + ½ s̈ t² reaches Lw at t* = √(2 (Lw − s0) / s̈)."""
    system = SYSTEMS["block_on_moving_wedge"]
    p = system.parameters
    spec = {
        **system.spec,
        "stops": [{"name": "bottom", "message": "the block reached the floor", "when": "Lw - s"}],
    }
    _, s_dd = wedge_accelerations(p)
    t_star = math.sqrt(2 * (p["Lw"] - system.run["initial"]["s"]) / s_dd)
    result = simulate(scene=spec, request=request(system, t_end=1.5))
    assert result["stats"]["status"] != "ok"
    assert any("floor" in w or "stop" in w for w in result["warnings"]), result["warnings"]
    assert t_star - 1.0 / system.run["fps"] - 1e-9 <= result["t"][-1] <= t_star + 1e-6


def test_negative_rotation_rate_from_the_request():
    """Omega < 0 posted in the request is accepted and gives the mirrored physics."""
    system = SYSTEMS["turntable_springs_rest_length"]
    overrides = {"parameters": {"Omega": -2.0}}
    result = simulate(scene=system.spec, request=request(system, **overrides))
    assert result["stats"]["status"] == "ok"
    t, y = trajectory(result, ["x", "y"])
    p = {**system.parameters, "Omega": -2.0}
    expected = reference(system.id).integrate(p, initial_state(system, system.run["initial"]), t)
    assert np.max(np.abs(y - expected)) < 1e-7 * max(1.0, float(np.max(np.abs(expected))))


# --- (4) degenerate input is refused, naming the field ---------------------------------------

PENDULUM = {
    "coordinates": ["theta"],
    "parameters": {"m": 1.0, "l": 1.0, "g": G},
    "bodies": [{"name": "bob", "mass": "m", "position": ["l*sin(theta)", "-l*cos(theta)", 0]}],
    "gravity": {"acceleration": "g"},
}


def with_(spec: dict, **changes) -> dict:
    return json.loads(json.dumps({**spec, **changes}))


DEGENERATE = [
    (
        "zero_mass_parameter",
        with_(PENDULUM, parameters={"m": 0.0, "l": 1.0, "g": G}),
        "parameters.m",
        "",
    ),
    (
        "negative_mass_parameter",
        with_(PENDULUM, parameters={"m": -1.0, "l": 1.0, "g": G}),
        "parameters.m",
        "",
    ),
    (
        "zero_mass_number",
        with_(PENDULUM, bodies=[{**PENDULUM["bodies"][0], "mass": 0}]),
        "bodies[0].mass",
        "",
    ),
    (
        "negative_mass_number",
        with_(PENDULUM, bodies=[{**PENDULUM["bodies"][0], "mass": -2.0}]),
        "bodies[0].mass",
        "",
    ),
    (
        "mass_expression_zero",
        with_(PENDULUM, bodies=[{**PENDULUM["bodies"][0], "mass": "0*m"}]),
        "bodies[0].mass",
        "",
    ),
    (
        "coordinate_without_inertia",
        with_(PENDULUM, coordinates=["theta", "phi"]),
        "coordinates[1]",
        "",
    ),
]


@pytest.mark.parametrize(
    ("spec", "field"),
    [
        pytest.param(
            spec, fld, id=name, marks=[pytest.mark.xfail(strict=True, reason=why)] if why else []
        )
        for name, spec, fld, why in DEGENERATE
    ],
)
def test_degenerate_spec_is_refused_naming_the_field(spec, field):
    with pytest.raises(SpecError) as caught:
        derive_model(spec)
    fields = [e["field"] for e in caught.value.errors]
    assert any(f.startswith(field) for f in fields), fields


def test_zero_mass_posted_in_a_simulation_request_is_refused():
    with pytest.raises(SpecError) as caught:
        simulate(scene=PENDULUM, request=SimulationRequest(parameters={"m": 0.0}, t_end=1.0))
    assert [e["field"] for e in caught.value.errors] == ["parameters.m"]


def test_zero_mass_is_a_422_through_the_api():
    from fastapi.testclient import TestClient

    from app.main import app

    bad = with_(PENDULUM, parameters={"m": 0.0, "l": 1.0, "g": G})
    r = TestClient(app).post("/api/v1/derive", json={"scene": bad})
    assert r.status_code == 422
    assert r.json()["detail"][0]["field"] == "parameters.m"


# --- determinism ---------------------------------------------------------------------------

_DERIVE = (
    "import json, sys; sys.path.insert(0, 'tests/support');"
    "from beyond.systems import SYSTEMS; from mechanics.derive import derive_model;"
    "print(json.dumps(derive_model(SYSTEMS[sys.argv[1]].spec).to_json()['equations'],"
    " sort_keys=True))"
)


@pytest.mark.slow
@pytest.mark.parametrize("sid", ["turntable_springs_rest_length", "spring_chain_between_walls"])
def test_derivation_is_the_same_under_any_hash_seed(sid):
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    outputs = []
    for seed in ("1", "2"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        done = subprocess.run(
            [sys.executable, "-c", _DERIVE, sid],
            cwd=root,
            env=env,
            capture_output=True,
            text=True,
            timeout=120,
            check=True,
        )
        outputs.append(done.stdout)
    assert outputs[0] == outputs[1]
