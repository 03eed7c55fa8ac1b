"""Equilibria, stability and normal modes against closed forms (notes II.A; small oscillations)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fastapi.testclient import TestClient

from app.main import app

client = TestClient(app)


def post(**body):
    r = client.post("/api/v1/equilibria", json=body)
    assert r.status_code == 200, r.text
    return r.json()


def at(result, **q):
    for e in result["equilibria"]:
        if all(math.isclose(e["q"][k], v, abs_tol=1e-9) for k, v in q.items()):
            return e
    raise AssertionError(f"no equilibrium at {q}: {[e['q'] for e in result['equilibria']]}")


def test_pendulum_hangs_stably_with_omega_squared_g_over_l():
    g, length = 9.81, 2.0
    r = post(scene_id="simple_pendulum", parameters={"g": g, "l": length})
    down, up = at(r, theta=0.0), at(r, theta=math.pi)
    assert down["stable"] and not up["stable"]
    assert (down["kind"], up["kind"]) == ("stable", "unstable")
    assert down["frequencies"] == pytest.approx([math.sqrt(g / length)], rel=1e-12)
    assert [s["id"] for s in r["steps"]] == ["virtual_work", "stability"]


def test_coupled_oscillators_modes_k_over_m_and_3k_over_m():
    k, m = 4.0, 0.5
    r = post(scene_id="coupled_oscillators", parameters={"k": k, "k12": k, "m": m})
    e = at(r, x1=0.0, x2=0.0)
    assert e["kind"] == "stable"
    assert e["frequencies"] == pytest.approx([math.sqrt(k / m), math.sqrt(3 * k / m)], rel=1e-12)
    in_phase, out_of_phase = (np.array(v) for v in e["modes"])
    assert abs(in_phase[0] / in_phase[1] - 1) < 1e-12
    assert abs(out_of_phase[0] / out_of_phase[1] + 1) < 1e-12


@pytest.mark.parametrize("omega", [6.0, 8.0])
def test_hoop_off_axis_equilibrium_exists_above_critical_spin(omega):
    g, R = 9.81, 0.5
    r = post(scene_id="bead_on_hoop", parameters={"Omega": omega, "g": g, "R": R})
    bottom = at(r, theta=0.0)
    assert not bottom["stable"]  # Ω² > g/R: the bottom is unstable
    theta0 = math.acos(g / (R * omega**2))
    for sign in (1, -1):
        e = at(r, theta=sign * theta0)
        assert e["stable"]
        assert "acos" in e["symbolic"]["theta"] and "<= 1" in e["exists_when"]
        w2 = omega**2 - g**2 / (R**2 * omega**2)
        assert e["frequencies"] == pytest.approx([math.sqrt(w2)], rel=1e-10)


def test_hoop_below_critical_spin_has_stable_bottom_with_g_over_r_minus_omega_squared():
    g, R, omega = 9.81, 0.5, 3.0
    r = post(scene_id="bead_on_hoop", parameters={"Omega": omega, "g": g, "R": R})
    assert sorted(round(e["q"]["theta"], 9) for e in r["equilibria"]) == [0.0, round(math.pi, 9)]
    assert at(r, theta=0.0)["frequencies"] == pytest.approx([math.sqrt(g / R - omega**2)])


def test_free_cart_moves_with_its_pendulum():
    """Cart free on its track: ω² = (g/l)(M + m)/M, not g/l."""
    M, m, g, length = 1.0, 0.5, 9.81, 1.0
    r = post(scene_id="cart_pendulum", parameters={"F": 0.0, "M": M, "m": m, "g": g, "l": length})
    e = at(r, theta=0.0)
    assert e["free"] == ["x"]
    assert e["frequencies"] == pytest.approx([math.sqrt(g / length * (M + m) / M)])


def test_no_equilibrium_and_drives_are_explained():
    assert post(scene_id="central_force")["equilibria"] == []
    driven = post(scene_id="spring_mass_damper")
    assert driven["equilibria"] == [] and "time" in driven["warnings"][0]
    undriven = post(scene_id="spring_mass_damper", parameters={"F0": 0.0})
    assert at(undriven, x=0.0)["stable"]
    assert at(undriven, x=0.0)["kind"] == "asymptotically stable"


def test_bad_parameters_are_422():
    r = client.post(
        "/api/v1/equilibria", json={"scene_id": "simple_pendulum", "parameters": {"m": -1}}
    )
    assert r.status_code == 422 and r.json()["detail"][0]["field"] == "parameters.m"
    r = client.post(
        "/api/v1/equilibria", json={"scene_id": "simple_pendulum", "parameters": {"nope": 1}}
    )
    assert r.status_code == 422


def test_the_linearized_equations_are_shown_with_their_matrices():
    """Coupled oscillators: M = m I, K = [[k + k12, −k12], [−k12, k + k12]], no damping."""
    k, k12, m = 4.0, 1.5, 0.5
    r = post(scene_id="coupled_oscillators", parameters={"k": k, "k12": k12, "m": m})
    line = [p for p in r["steps"][1]["plain"] if p.startswith("M = ")][0]  # about x1 = x2 = 0
    assert f"M = {[[m, 0.0], [0.0, m]]}" in line
    assert f"K = {[[k + k12, -k12], [-k12, k + k12]]}" in line
    assert r"\delta \ddot" in r["steps"][1]["latex"][0]


def test_coupled_oscillators_rest_wherever_the_spring_forces_balance_on_the_line():
    """Springs along a line act on both sides of their anchors: V = Σ ½k(|Δx| − a)². Every listed
    equilibrium makes ∂V/∂x vanish (checked here by finite differences), and none repeats."""
    k, k12, m, a = 10.0, 1.0, 1.0, 1.0
    r = post(scene_id="coupled_oscillators", parameters={"k": k, "k12": k12, "m": m, "a": a})

    def V(x1, x2):
        p1, p2 = a + x1, 2 * a + x2
        return (
            k * (abs(p1) - a) ** 2 + k12 * (abs(p2 - p1) - a) ** 2 + k * (abs(3 * a - p2) - a) ** 2
        ) / 2

    h = 1e-6
    seen = set()
    for e in r["equilibria"]:
        x1, x2 = e["q"]["x1"], e["q"]["x2"]
        assert abs(V(x1 + h, x2) - V(x1 - h, x2)) / (2 * h) < 1e-6
        assert abs(V(x1, x2 + h) - V(x1, x2 - h)) / (2 * h) < 1e-6
        seen.add((round(x1, 6), round(x2, 6)))
    assert len(seen) == len(r["equilibria"]) >= 1
