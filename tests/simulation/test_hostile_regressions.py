"""What a hostile user found in stops, springs and degenerate input, each against a closed form.

A block pushed by a constant force, x = 1 − t²/2 from rest at x = 1, reaches x = −1 at t = 2 and
x = 0 at t = √2; a unit oscillator from x = 0 with ẋ = 1 reverses at t = π/2.
"""

from __future__ import annotations

import math

import pytest

from mechanics import simulate as simulate_module
from mechanics.derive import derivation_of_scene, derive_model
from mechanics.equilibria import equilibria
from mechanics.scenes import load_scene
from mechanics.simulate import SimulationRequest, simulate
from mechanics.spec import SpecError

PUSHED = {
    "coordinates": ["x"],
    "parameters": {"m": 1.0},
    "bodies": [{"name": "b", "mass": "m", "position": ["x", 0, 0]}],
    "forces": [{"on": "b", "vector": ["-m", 0, 0]}],
    "initial": {"x": 1.0},
}
OSCILLATOR = {
    "coordinates": ["x"],
    "parameters": {"m": 1.0},
    "bodies": [{"name": "b", "mass": "m", "position": ["x", 0, 0]}],
    "forces": [{"on": "b", "vector": ["-m*x", 0, 0]}],
    "initial": {"x": 0.0, "x_dot": 1.0},
}
METHODS = ["DOP853", "dop853_c", "RK45", "LSODA", "Radau", "rk4"]


def run(spec, method="DOP853", **request):
    return simulate(scene=spec, request=SimulationRequest(method=method, dt=0.01, **request))


@pytest.mark.parametrize("method", METHODS)
def test_a_stop_whose_guard_never_holds_is_never_reported(method):
    spec = {
        **PUSHED,
        "stops": [
            {"name": "never", "when": "x - 0.5", "only_if": "-1", "message": "guard fails"},
            {"name": "floor", "when": "x + 1", "message": "reaches the floor"},
        ],
    }
    stop = run(spec, method, t_end=4)["stats"]["stop"]
    assert stop["name"] == "floor"
    assert stop["t"] == pytest.approx(2.0, abs=1e-6)


def test_a_stop_that_is_zero_for_good_is_never_reported():
    spec = {
        **PUSHED,
        "stops": [
            {"name": "zero", "when": "0", "message": "always zero"},
            {"name": "floor", "when": "x + 1", "message": "reaches the floor"},
        ],
    }
    stop = run(spec, t_end=4)["stats"]["stop"]
    assert (stop["name"], round(stop["t"], 6)) == ("floor", 2.0)


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "rk4", "LSODA"])
def test_a_condition_that_becomes_undefined_stops_where_it_does(method):
    spec = {**PUSHED, "stops": [{"name": "root", "when": "sqrt(x)", "message": "x < 0"}]}
    result = run(spec, method, t_end=3)
    assert result["stats"]["stop"]["name"] == "root"
    assert result["stats"]["stop"]["t"] == pytest.approx(math.sqrt(2), abs=1e-6)
    assert min(result["q"]["x"]) > -1e-6


@pytest.mark.parametrize("method", ["DOP853", "dop853_c", "rk4"])
def test_a_sign_change_stop_of_small_values_waits_for_the_real_reversal(method):
    spec = {
        **OSCILLATOR,
        "stops": [{"name": "rev", "when": "1e-9*x_dot", "crossing": "any", "message": "turns"}],
    }
    stop = run(spec, method, t_end=3)["stats"]["stop"]
    assert stop["t"] == pytest.approx(math.pi / 2, abs=1e-6)


@pytest.mark.parametrize("method", ["rk4", "symplectic_euler", "DOP853", "Radau"])
def test_a_block_at_rest_where_friction_holds_it_does_not_move(method):
    result = simulate(
        scene_id="incline_friction",
        request=SimulationRequest(
            parameters={"mu": 0.6}, initial={"s": 0, "s_dot": 0}, t_end=3, method=method, dt=0.01
        ),
    )
    assert result["stats"]["stop"] == {
        "name": "sticks",
        "t": 0.0,
        "message": result["stats"]["stop"]["message"],
    }
    assert result["q"]["s"] == [0.0]
    assert not [w for w in result["warnings"] if "drifted" in w]


def test_a_tiny_or_huge_string_direction_is_still_a_direction():
    """along = [0, 1e-200, 0] and [0, 1e200, 0] mean straight up, like [0, 1, 0]."""
    base = load_scene("atwood_machine")
    times = []
    for scale in (1.0, 1e-200, 1e200):
        spec = {**base, "stops": [dict(s) for s in base["stops"]]}
        spec["stops"][2]["along"] = [0, scale, 0]
        times.append(run(spec, t_end=3)["stats"]["stop"]["t"])
    closed = math.sqrt(2 * (1.0 + 0.3) / (9.81 / 3))  # mass2 reaches the pulley
    assert times == pytest.approx([closed] * 3, abs=1e-6)


def test_equilibria_of_a_zero_mass_are_refused_naming_it():
    with pytest.raises(SpecError) as err:
        equilibria(derivation_of_scene("simple_pendulum"), {"m": 0.0})
    assert [e["field"] for e in err.value.errors] == ["parameters.m"]


@pytest.mark.parametrize("mass", ["m - 2", "-1*m", "-1"])
def test_a_negative_mass_expression_is_refused_naming_the_body(mass):
    spec = {**PUSHED, "bodies": [{"name": "b", "mass": mass, "position": ["x", 0, 0]}]}
    with pytest.raises(SpecError) as err:
        derive_model(spec)
    assert any(e["field"] == "bodies[0].mass" for e in err.value.errors), err.value.errors


def test_a_spring_whose_ends_always_coincide_is_refused():
    spec = {
        **PUSHED,
        "points": [{"name": "Q", "position": ["x", 0, 0]}],
        "springs": [{"a": "Q", "b": "b", "k": 1, "rest_length": 1}],
    }
    with pytest.raises(SpecError) as err:
        derive_model(spec)
    assert err.value.errors[0]["field"] == "springs[0].b"


def test_a_planar_damper_started_at_zero_length_is_refused():
    spec = {
        "coordinates": ["x", "y"],
        "parameters": {"m": 1.0, "c": 1.0},
        "bodies": [{"name": "b", "mass": "m", "position": ["x", "y", 0]}],
        "dampers": [{"a": "O", "b": "b", "c": "c"}],
    }
    with pytest.raises(SpecError) as err:
        run(spec, t_end=1, initial={"x_dot": 1.0})
    assert "zero length" in err.value.errors[0]["message"]


def test_a_spring_far_from_its_anchor_is_not_taken_for_zero_length():
    """An unrelated coordinate's size does not make x = 0.5 look like x = 0."""
    spec = {
        "coordinates": ["x", "y"],
        "parameters": {"m": 1.0, "k": 1.0},
        "bodies": [
            {"name": "b", "mass": "m", "position": ["x", 0, 0]},
            {"name": "c", "mass": "m", "position": [0, "y", 1]},
        ],
        "springs": [{"a": "O", "b": "b", "k": "k", "rest_length": 1}],
        "initial": {"x": 0.5},
    }
    result = run(spec, t_end=0.5, initial={"x": 0.5, "y": 1e13})
    assert result["stats"]["status"] == "ok"


def test_springs_on_their_other_sides_cost_one_more_derivation(monkeypatch):
    """Sixteen springs all flipped by one request: one re-derivation, not sixteen."""
    springs = [{"a": f"A{i}", "b": "b", "k": 1, "rest_length": 0.5} for i in range(16)]
    points = [{"name": f"A{i}", "position": [f"a{i}", 0, 0]} for i in range(16)]
    spec = {
        **PUSHED,
        "forces": [],
        "parameters": {"m": 1.0, **{f"a{i}": 0.01 * i for i in range(16)}},
        "points": points,
        "springs": springs,
        "initial": {"x": 3.0},
    }
    calls = []
    real = simulate_module.compiled_spec
    monkeypatch.setattr(
        simulate_module, "compiled_spec", lambda s, b=(): calls.append(b) or real(s, b)
    )
    result = run(spec, t_end=0.1, initial={"x": -3.0})
    assert result["stats"]["status"] == "ok"
    assert len(calls) == 2 and len(calls[1]) == 16


def test_expansion_size_is_an_upper_estimate_exact_for_powers_of_sums():
    """(a + b + c + 1)ⁿ expands to C(n + 3, 3) terms: the estimate says so without expanding."""
    import sympy as sp

    from mechanics.check import _expansion_size

    a, b, c = sp.symbols("a b c")
    for n in (2, 3, 5):
        expr = (a + b + c + 1) ** n
        actual = len(sp.Add.make_args(sp.expand(expr)))
        assert actual == math.comb(n + 3, 3) == _expansion_size(expr, 10**6)
    assert _expansion_size((a + b + c + 1) ** 30, 320) == 321  # saturates, never computes 5456


@pytest.mark.timeout(60)
def test_a_huge_power_answer_is_judged_without_expanding_it():
    """(θ + θ̇ + m + 1)³⁰ as T took minutes of sympy expansion (5456 terms); it is judged wrong
    at random states and its units are named without expanding it."""
    from mechanics.check import check
    from mechanics.jobs import derivation_of

    verdict = check(derivation_of("elastic_pendulum", None), "T", "(theta + theta_dot + m + 1)**30")
    assert verdict.correct is False
    assert any("mixes units" in line for line in verdict.feedback)


# --- found by a hostile play-test of the new endpoints --------------------------------------


def test_answers_beyond_double_precision_are_judged_not_crashed():
    """exp(exp(exp(exp(θ)))) overflowed abs() in the check (a 500); 1/(sin²+cos²−1) was
    'off by a factor of ∞'. Neither may crash, and no factor ∞ or NaN may be claimed. (The
    nested exponentials and powers are refused by the parser since: tests/test_hostile_more.py.)"""
    from mechanics.check import check
    from mechanics.jobs import derivation_of

    d = derivation_of("simple_pendulum", None)
    for quantity, answer in [
        ("V", "exp(exp(theta))**8"),
        ("T", "exp(exp(theta_dot))*exp(exp(theta))"),
        ("V", "((sin(theta)+cos(theta))**8)**8"),
        ("T", "theta_dot**2/(sin(theta)**2+cos(theta)**2-1)"),
    ]:
        verdict = check(d, quantity, answer)
        assert verdict.correct is False
        text = " ".join(verdict.feedback)
        assert "infty" not in text and "NaN" not in text, (answer, text)
    divided = check(d, "T", "theta_dot**2/(sin(theta)**2+cos(theta)**2-1)")
    assert any("divides by zero" in line for line in divided.feedback)


def test_a_step_longer_than_the_run_is_one_step_not_a_crash():
    """steps = [1e10] with t_end = 10 divided by zero in the precision grid (a 500)."""
    from mechanics.precision import _grid

    times, dt = _grid(10.0, 1e10)
    assert times[0] == 0.0 and times[-1] == 10.0 and dt == 10.0


def test_a_share_token_nested_too_deep_is_refused_naming_it():
    import base64
    import zlib

    from mechanics.export_share import ShareError, decode_state

    token = "z" + base64.urlsafe_b64encode(zlib.compress(b"[" * 250_000, 9)).decode().rstrip("=")
    with pytest.raises(ShareError):
        decode_state(token)


def test_units_cannot_add_rows_or_columns_to_the_csv_header():
    import csv
    import io

    from mechanics.export_formats import trajectory_csv

    run = {"t": [0.0, 0.1], "q": {"theta": [1.0, 1.1]}, "q_dot": {"theta": [0.0, 0.2]}}
    units = {"theta": 'rad]\n=1+1,6,"6"\n#['}
    text = trajectory_csv(run, units)
    rows = list(csv.reader(io.StringIO(text)))
    header = rows[0]
    # one header row of t, θ, θ̇ (energies absent here), then the two samples: nothing added
    assert len(rows) == 3 and all(len(r) == len(header) == 3 for r in rows)
    assert [h.split(" ")[0] for h in header] == ["t", "theta", "theta_dot"]
    assert not any(ch in cell for cell in header for ch in '\n#"')
    assert not text.splitlines()[0].startswith("#")
