"""POST /api/v1/simulate: shapes, physics checked against closed forms, and bad input as 422."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from app.main import app

client = TestClient(app)


def post(**body):
    return client.post("/api/v1/simulate", json=body)


def test_simple_pendulum_small_angle_period_matches_2pi_sqrt_l_over_g():
    length, g = 2.0, 9.81
    r = post(
        scene_id="simple_pendulum",
        parameters={"l": length, "g": g},
        initial={"theta": 0.01},
        t_end=10,
        fps=200,
        rtol=1e-11,
        atol=1e-11,
    )
    assert r.status_code == 200, r.text
    body = r.json()
    t, theta = body["t"], body["q"]["theta"]
    # upward zero crossings of θ̇ ... use θ's downward zero crossings, linearly interpolated
    crossings = [
        t[i] + (t[i + 1] - t[i]) * theta[i] / (theta[i] - theta[i + 1])
        for i in range(len(t) - 1)
        if theta[i] > 0 >= theta[i + 1]
    ]
    period = crossings[1] - crossings[0]
    assert period == pytest.approx(2 * math.pi * math.sqrt(length / g), rel=1e-4)
    assert body["stats"]["energy_error"] < 1e-8
    assert set(body["energy"]) == {"T", "V", "E", "W_nc", "W_drive"}
    assert len(body["positions"]["bob"]["x"]) == len(t)


def test_damped_oscillator_reports_energy_balance_not_energy():
    r = post(scene_id="spring_mass_damper", t_end=5, rtol=1e-10, atol=1e-10)
    stats = r.json()["stats"]
    assert "energy_error" not in stats
    assert stats["energy_balance_error"] < 1e-7
    E = r.json()["energy"]["E"]
    assert E[-1] != pytest.approx(E[0], rel=1e-3)  # damping and drive really change E


def test_posted_scene_runs_like_a_builtin():
    spec = client.get("/api/v1/scenes/simple_pendulum").json()["spec"]
    a = post(scene=spec, t_end=1).json()
    b = post(scene_id="simple_pendulum", t_end=1).json()
    assert a["q"]["theta"][-1] == pytest.approx(b["q"]["theta"][-1], rel=1e-9)


def test_fixed_step_method_and_zero_duration():
    r = post(scene_id="double_pendulum", method="rk4", dt=0.005, t_end=1)
    assert r.status_code == 200
    assert r.json()["stats"]["steps"] >= 200
    r0 = post(scene_id="double_pendulum", t_end=0)
    assert r0.status_code == 200 and r0.json()["t"] == [0.0]


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"parameters": {"m": -1.0}}, "parameters.m"),
        ({"parameters": {"mass": 1.0}}, "parameters.mass"),
        ({"initial": {"phi": 1.0}}, "initial.phi"),
        ({"t_end": 1e9}, "t_end"),
        ({"fps": 0}, "fps"),
        ({"method": "magic"}, "method"),
        ({"method": "rk4"}, "dt"),
        ({"rtol": 0}, "rtol"),
        ({"method": "euler", "dt": 1e-9, "t_end": 100}, "dt"),
    ],
)
def test_bad_input_is_a_422_naming_the_field(body, field):
    r = post(scene_id="simple_pendulum", **body)
    assert r.status_code == 422, r.text
    assert field in [d["field"] for d in r.json()["detail"]]


def test_nan_parameter_is_refused_and_server_keeps_serving():
    r = client.post(
        "/api/v1/simulate",
        content='{"scene_id": "simple_pendulum", "parameters": {"m": NaN}}',
        headers={"content-type": "application/json"},
    )
    assert r.status_code == 422
    assert client.get("/healthz").status_code == 200


def test_unknown_scene_is_404():
    assert post(scene_id="no_such_scene").status_code == 404


def test_the_methods_endpoint_lists_the_registry_and_the_pages_offer_every_method(monkeypatch):
    from mechanics import native
    from mechanics.integrators import METHODS

    listed = client.get("/api/v1/methods").json()
    assert [m["name"] for m in listed] == list(METHODS)
    by_name = {m["name"]: m for m in listed}
    assert by_name["rk4"]["order"] == 4 and by_name["rk4"]["kind"] == "fixed"
    assert by_name["dop853_c"]["available"] and by_name["dop853_c"]["note"] == ""
    js = (Path(__file__).parents[2] / "static/js/integrator.js").read_text()
    offered = re.findall(r'\["(\w+)", "', js.split("export const METHODS")[1].split("];")[0])
    assert sorted(offered) == sorted(METHODS)
    # without a compiler the method still answers, and says what runs instead
    monkeypatch.setenv(native.ENV_VAR, "none")
    native._kernel.cache_clear()
    try:
        (c,) = [m for m in client.get("/api/v1/methods").json() if m["name"] == "dop853_c"]
    finally:
        native._kernel.cache_clear()
    assert not c["available"] and "scipy's DOP853" in c["note"]


def test_a_posted_scene_runs_compiled_in_the_budgeted_child_like_a_builtin():
    spec = client.get("/api/v1/scenes/double_pendulum").json()["spec"]
    a = post(scene=spec, t_end=3, method="dop853_c", rtol=1e-10, atol=1e-10).json()
    b = post(scene_id="double_pendulum", t_end=3, method="DOP853", rtol=1e-10, atol=1e-10).json()
    assert a["warnings"] == [] and a["stats"]["method"] == "dop853_c"
    assert a["stats"]["steps"] == b["stats"]["steps"]
    assert a["q"]["theta2"][-1] == pytest.approx(b["q"]["theta2"][-1], rel=1e-9)


# --- the default method (issue 24, item 1) -----------------------------------------------------


def test_the_default_method_is_dop853_in_c_and_takes_scipys_dop853_steps():
    """No method named: DOP853's steps taken in C. The oracle is scipy's DOP853 itself (the
    same tableau and step control): the same accepted steps and samples equal to rounding."""
    asked = {"scene_id": "double_pendulum", "t_end": 4, "rtol": 1e-10, "atol": 1e-10}
    default, scipy = post(**asked).json(), post(**asked, method="DOP853").json()
    assert default["stats"]["method"] == "dop853_c"
    assert default["stats"]["method_requested"] == "dop853_c"
    assert scipy["stats"]["method"] == scipy["stats"]["method_requested"] == "DOP853"
    assert default["stats"]["steps"] == scipy["stats"]["steps"]
    for name in ("theta1", "theta2"):
        assert default["q"][name] == pytest.approx(scipy["q"][name], rel=1e-9, abs=1e-11)
    assert not any("scipy's DOP853" in w for w in default["warnings"])


def test_without_a_c_compiler_the_default_runs_scipys_dop853_and_says_so(monkeypatch):
    from mechanics import native

    monkeypatch.setenv(native.ENV_VAR, "none")
    native._kernel.cache_clear()
    try:
        # a t_end of its own: a built-in run is remembered by its request (app/memo.py)
        body = post(scene_id="simple_pendulum", t_end=3.25).json()
    finally:
        native._kernel.cache_clear()
    assert body["stats"]["method"] == "DOP853"  # what ran, not what was asked
    assert body["stats"]["method_requested"] == "dop853_c"
    assert any("scipy's DOP853" in w and "C compiler" in w for w in body["warnings"])


def test_a_scene_whose_stop_chatters_is_stepped_by_scipy_and_its_stats_say_so():
    """incline_friction's stop (the block sticking) is crossed either way: stepped in Python,
    watched every step; the stats name DOP853, the method that ran."""
    body = post(scene_id="incline_friction", t_end=2.5).json()
    assert body["stats"]["method"] == "DOP853"
    assert body["stats"]["method_requested"] == "dop853_c"
    assert any("reversal is caught every step" in w for w in body["warnings"])
