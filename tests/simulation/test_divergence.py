"""How two runs part, on synthetic differences whose law is known in closed form.

Each signal is built here from its law (e^{λ t} with a known λ, c·t, c·t², noise), so the
expected kind and rate are the law's, not numbers printed by the code.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mechanics.divergence import (
    SILENT_BELOW,
    TimeShift,
    best_time_shift,
    chaos_possible,
    classify_divergence,
    is_autonomous,
    worth_classifying,
)

T = np.linspace(0.0, 20.0, 1201)  # 20 s at 60 fps, as the app samples
RNG = np.random.default_rng(11)


def oscillating(envelope: np.ndarray, omega: float = 3.0) -> np.ndarray:
    """|Δq| of two runs crosses zero twice a period; the growth lives in its envelope."""
    return envelope * np.abs(np.cos(omega * T + 0.3))


def chaotic(rate: float = 1.3, start: float = 1e-9) -> np.ndarray:
    """e^{λ t} from a tolerance-sized error, saturating at the size of the motion."""
    return oscillating(np.minimum(start * np.exp(rate * T), 1.0))


def test_exponential_growth_recovers_its_rate_and_where_the_runs_part():
    v = classify_divergence(T, chaotic(), span=1.0, n_dof=2, autonomous=True)
    assert v.kind == "exponential"
    assert v.rate == pytest.approx(1.3, rel=0.1)
    assert v.doubling_time == pytest.approx(math.log(2) / 1.3, rel=0.1)
    # 1e-9 e^{1.3 t} reaches 1 % at t = ln(1e7)/1.3 = 12.4 s (the envelope peaks within a
    # half period, π/3 s, of that)
    assert v.trusted_until == pytest.approx(math.log(1e7) / 1.3, abs=math.pi / 3)
    assert "sensitive" in v.message and "λ ≈ 1.3" in v.message


@pytest.mark.parametrize("rate", [0.5, 1.0, 2.5])
def test_the_rate_is_recovered_across_rates(rate):
    v = classify_divergence(T, chaotic(rate, start=1e-12), span=1.0, n_dof=2, autonomous=True)
    assert v.kind == "exponential"
    assert v.rate == pytest.approx(rate, rel=0.1)


def test_exponential_growth_under_multiplicative_noise_is_still_recognised():
    noisy = chaotic() * np.exp(RNG.normal(0.0, 0.5, T.shape))
    v = classify_divergence(T, noisy, span=1.0, n_dof=2, autonomous=True)
    assert v.kind == "exponential"
    assert v.rate == pytest.approx(1.3, rel=0.1)


def test_the_difference_is_taken_relative_to_the_span():
    v = classify_divergence(T, 5.0 * chaotic(), span=5.0, n_dof=2, autonomous=True)
    assert v.kind == "exponential"
    assert v.trusted_until == pytest.approx(math.log(1e7) / 1.3, abs=math.pi / 3)


def test_a_small_linear_drift_is_polynomial_and_says_nothing():
    v = classify_divergence(T, oscillating(1e-7 * T), span=1.0, n_dof=2, autonomous=True)
    assert v.kind == "polynomial"
    assert v.power == pytest.approx(1.0, rel=0.1)
    assert v.rate == pytest.approx(1e-7, rel=0.1)  # relative difference per second
    assert v.message == ""  # a drift of 2e-6 of the span is the ordinary cost of a tolerance


def test_a_quadratic_drift_is_polynomial_of_power_two():
    v = classify_divergence(T, oscillating(1e-6 * T**2), span=1.0, n_dof=2, autonomous=True)
    assert v.kind == "polynomial"
    assert v.power == pytest.approx(2.0, rel=0.1)


def test_a_large_linear_drift_is_told_as_timing_not_as_chaos():
    # 0.4 % of the span per second: 8 % after 20 s, which a shift of 0.027 s undoes
    v = classify_divergence(
        T,
        oscillating(4e-3 * T),
        span=1.0,
        n_dof=2,
        autonomous=True,
        name="x",
        tolerances=(1e-6, 1e-3),
        time_shift=TimeShift(shift=0.027, left=0.1),
    )
    assert v.kind == "polynomial"
    assert v.power == pytest.approx(1.0, rel=0.1)
    assert v.rate == pytest.approx(4e-3, rel=0.1)
    assert v.timing_error == 0.027 and v.trusted_until is None
    text = v.message.lower()
    assert "linearly" in text and "7.9 %" in text and "0.027 s" in text and "shape agrees" in text
    assert "rtol 1e-06 and 0.001" in text and "looser run" in text
    assert "sensitive" not in text and "chao" not in text and "trust" not in text


def test_a_drift_no_time_shift_undoes_is_not_called_timing_only():
    v = classify_divergence(
        T, oscillating(4e-3 * T), 1.0, 2, True, time_shift=TimeShift(shift=0.01, left=0.9)
    )
    assert v.kind == "polynomial" and v.timing_error is None
    assert "shape agrees" not in v.message and "amplitude" in v.message


def test_best_time_shift_finds_a_phase_lag_and_sees_an_amplitude_change():
    t = np.linspace(0.0, 20.0, 1201)
    late = best_time_shift(t, np.sin(2.0 * t), np.sin(2.0 * (t - 0.05)))
    assert late.shift == pytest.approx(0.05, abs=0.01) and late.left < 0.05
    bigger = best_time_shift(t, np.sin(2.0 * t), 1.1 * np.sin(2.0 * t))
    assert bigger.left > 0.9


def test_a_tighter_comparison_run_puts_the_error_on_this_run():
    v = classify_divergence(
        T,
        oscillating(4e-3 * T),
        1.0,
        2,
        True,
        tolerances=(1e-2, 1e-3),
        time_shift=TimeShift(0.027, 0.1),
    )
    assert "this run's" in v.message


def test_noise_that_does_not_grow_is_none():
    noise = 1e-10 * RNG.lognormal(0.0, 1.0, T.shape)
    v = classify_divergence(T, noise, span=1.0, n_dof=2, autonomous=True)
    assert v.kind == "none" and v.message == ""


def test_identical_runs_are_none():
    v = classify_divergence(T, np.zeros_like(T), span=1.0, n_dof=2, autonomous=True)
    assert v.kind == "none" and v.message == ""


def test_one_autonomous_coordinate_cannot_be_chaotic_whatever_the_data_look_like():
    v = classify_divergence(
        T, chaotic(), span=1.0, n_dof=1, autonomous=True, tolerances=(1e-9, 1e-6)
    )
    assert v.kind == "polynomial"
    assert "sensitive" not in v.message and "chao" not in v.message
    assert "plane" in v.message  # the reason, in the notes' words
    # driven, one coordinate can be chaotic (the driven pendulum): the data decide
    v = classify_divergence(T, chaotic(), span=1.0, n_dof=1, autonomous=False)
    assert v.kind == "exponential"


def test_chaos_needs_two_degrees_of_freedom_or_a_drive():
    assert not chaos_possible(1, autonomous=True)
    assert not chaos_possible(0, autonomous=True)
    assert chaos_possible(2, autonomous=True)
    assert chaos_possible(1, autonomous=False)


def test_a_difference_with_no_clear_law_is_worded_neutrally():
    # flat, then a jump to 30 % of the span at 10 s: neither e^{λ t} nor t^p
    d = np.where(T < 10.0, 1e-8, 0.3)
    v = classify_divergence(T, d, span=1.0, n_dof=2, autonomous=True)
    assert v.kind in ("unclear", "none")
    assert "sensitive" not in v.message and "steadily" not in v.message
    assert "30 %" in v.message


def test_autonomy_is_read_off_the_equations():
    y = np.column_stack([np.linspace(0, 1, 7), np.linspace(1, 2, 7)])
    t = np.linspace(0, 3, 7)

    def free(time, state):
        return np.array([state[1], -math.sin(state[0])])

    def driven(time, state):
        return np.array([state[1], -math.sin(state[0]) + 0.5 * math.cos(2.5 * time)])

    assert is_autonomous(free, t, y)
    assert not is_autonomous(driven, t, y)


def test_a_mismatch_of_lengths_is_an_error():
    with pytest.raises(ValueError):
        classify_divergence(T, np.zeros(3), 1.0, 2, True)


def _shapes(t: np.ndarray, rng: np.random.Generator) -> list[np.ndarray]:
    """Growth laws the classifier tells apart, each up to 1 (scaled by the caller)."""
    wobble = 1 + 0.3 * np.sin(7 * t)
    return [
        np.exp(2.0 * (t - t[-1])),  # chaos
        (t / t[-1]) ** 1.0 * wobble,  # a drift in phase
        (t / t[-1]) ** 2.0,
        np.abs(np.sin(3 * t)) * (t / t[-1]),
        np.abs(rng.normal(size=t.size)),  # no law
        np.where(t > 0.5 * t[-1], 1.0, 1e-6),  # a step
    ]


@pytest.mark.parametrize("autonomous", [True, False])
def test_below_the_silent_level_no_growth_law_has_anything_to_say(autonomous):
    """Why simulate may skip the fits (worth_classifying): whatever the shape, runs that part
    by less than SILENT_BELOW of the span get no sentence; just above it, some do."""
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 10.0, 301)
    said_above = 0
    for d in _shapes(t, rng):
        d = d / np.max(d)
        quiet = classify_divergence(t, 0.999 * SILENT_BELOW * d, 1.0, 2, autonomous)
        assert quiet.message == ""
        loud = classify_divergence(t, 30 * SILENT_BELOW * d, 1.0, 2, autonomous)
        said_above += bool(loud.message)
    assert said_above >= 3


def test_worth_classifying_reads_the_largest_relative_difference_of_any_coordinate():
    t = np.linspace(0, 1, 50)
    y = np.column_stack([np.sin(t), 100 * np.cos(t), np.zeros_like(t), np.zeros_like(t)])
    other = y.copy()
    other[:, 1] += 0.5 * SILENT_BELOW * 100  # half the level, relative to q2's span of 100
    assert not worth_classifying(2, y, other)
    other[:, 0] += 2 * SILENT_BELOW * np.max(np.abs(np.sin(t)))  # twice it, in q1
    assert worth_classifying(2, y, other)
    other[:, 2] += 1.0  # velocities are not compared (compare_runs looks at coordinates)
    other[:, 0] = y[:, 0]
    assert not worth_classifying(2, y, other)
    other[5, 1] = np.nan  # a run that blew up is looked at
    assert worth_classifying(2, y, other)


@pytest.mark.parametrize("scene_id", ["double_pendulum", "simple_pendulum", "bead_on_hoop"])
@pytest.mark.parametrize("rtol", [1e-9, 1e-5])
def test_skipping_the_fits_changes_no_warning(scene_id, rtol, monkeypatch):
    from mechanics import simulate as sim

    req = sim.SimulationRequest(t_end=20, fps=30, method="dop853_c", rtol=rtol, atol=rtol)
    fast = sim.simulate(scene_id, None, req)["warnings"]
    monkeypatch.setattr(sim, "worth_classifying", lambda *a: True)
    assert sim.simulate(scene_id, None, req)["warnings"] == fast
