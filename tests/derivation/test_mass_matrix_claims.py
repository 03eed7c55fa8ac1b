"""What the mass-matrix step says of M must hold for the system shown: 'positive definite at
every configuration' only where det M > 0 everywhere; where coordinates have poles (a spherical
pendulum at θ = 0, polar coordinates at r = 0) it says where M is definite instead. The
expectations come from mass matrices written by hand."""

from __future__ import annotations

import numpy as np
import pytest

from mechanics.jobs import derivation_of

EVERYWHERE = "positive definite at every configuration"
rng = np.random.default_rng(7)


def _matrix_step(scene_id: str):
    return next(s for s in derivation_of(scene_id, None).steps if s.id == "matrix")


def _matrix_text(scene_id: str) -> str:
    return _matrix_step(scene_id).text


def _double_pendulum_det(m1, m2, l1, l2, th1, th2):
    c = np.cos(th1 - th2)
    M = np.array([[(m1 + m2) * l1**2, m2 * l1 * l2 * c], [m2 * l1 * l2 * c, m2 * l2**2]])
    return np.linalg.det(M)


def _cart_pendulum_det(M_cart, m, length, th):
    c = m * length * np.cos(th)
    M = np.array([[M_cart + m, c], [c, m * length**2]])
    return np.linalg.det(M)


def _spherical_det(m, length, th):
    return np.linalg.det(np.diag([m * length**2, m * length**2 * np.sin(th) ** 2]))


@pytest.mark.parametrize(
    ("scene_id", "det"),
    [
        ("double_pendulum", lambda p, q: _double_pendulum_det(*p[:4], *q)),
        ("cart_pendulum", lambda p, q: _cart_pendulum_det(*p[:3], q[0])),
    ],
)
def test_definite_everywhere_is_said_only_where_it_holds(scene_id, det):
    # by hand: det M > 0 at every sampled configuration and positive parameters ...
    for _ in range(200):
        p = rng.uniform(0.05, 5.0, size=4)
        q = rng.uniform(-np.pi, np.pi, size=2)
        assert det(p, q) > 0
    assert det(np.ones(4), np.zeros(2)) > 0  # ... the aligned configuration too
    assert EVERYWHERE in _matrix_text(scene_id)


def test_a_spherical_pendulum_is_not_called_definite_at_its_poles():
    assert _spherical_det(1.0, 1.0, 0.0) == 0.0  # by hand: M singular at θ = 0
    step = _matrix_step("spherical_pendulum")
    assert EVERYWHERE not in step.text
    assert "semidefinite" in step.text and r"\neq 0" in step.text
    [det] = [line for line in step.lines if line.label == "det M"]
    assert r"\sin^{2}" in det.latex  # the determinant it points to, shown below


def test_a_posted_polar_particle_says_where_m_is_definite():
    """r not declared positive: det M = m² r² vanishes at r = 0."""
    from fastapi.testclient import TestClient

    from app.main import app

    spec = {
        "title": "polar particle",
        "coordinates": ["r", "theta"],
        "parameters": {"m": 1.0, "k": 2.0},
        "initial": {"r": 1.0, "theta": 0.0, "theta_dot": 1.0},
        "bodies": [{"name": "p", "mass": "m", "position": ["r*cos(theta)", "r*sin(theta)", 0]}],
        "potentials": [{"name": "spring", "expression": "k*r**2/2"}],
    }
    with TestClient(app) as c:
        r = c.post("/api/v1/derive", json={"scene": spec})
    assert r.status_code == 200, r.text
    step = next(s for s in r.json()["steps"] if s["id"] == "matrix")
    assert EVERYWHERE not in step["text"], step["text"]
    assert any(tex.startswith(r"\det") and "r^{2}" in tex for tex in step["latex"]), step["latex"]
