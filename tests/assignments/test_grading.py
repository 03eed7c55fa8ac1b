"""Grading (issue 27, item 4): a part scored in [0, 1], a retry costs the template's penalty, the
best penalised score counts, and 'cannot decide' or an unreadable answer uses no attempt."""

from __future__ import annotations

import pytest

from mechanics.assignments import grading
from mechanics.assignments.grading import AttemptsExhausted, Policy

from .support import one_part

RIGHT_T = "m*l^2*theta_dot^2/2"
WRONG_T = "m*l^2*theta_dot^2"
UNDECIDABLE_T = RIGHT_T + " + exp(-10^6*theta_dot^2)"


def attempt(variant, previous, answer, policy):
    judged = grading.judge(variant, variant.parts[0], answer)
    return grading.record(previous, answer, judged, policy)


@pytest.fixture(scope="module")
def pendulum_T():
    return one_part("simple_pendulum", "T")


def test_a_right_first_answer_scores_one(pendulum_T):
    a = attempt(pendulum_T, [], RIGHT_T, Policy(retry_penalty=0.25))
    assert (a.counted, a.number, a.raw, a.score) == (True, 1, 1.0, 1.0)


def test_each_retry_costs_the_penalty(pendulum_T):
    policy = Policy(retry_penalty=0.25)
    done = []
    for answer in (WRONG_T, "-" + RIGHT_T, RIGHT_T):
        done.append(attempt(pendulum_T, done, answer, policy))
    assert [a.score for a in done] == [0.0, 0.0, 0.5]  # third attempt: 1 − 2 × 0.25
    assert grading.part_score(done) == 0.5


def test_the_best_penalised_score_counts(pendulum_T):
    policy = Policy(retry_penalty=0.1)
    done = [attempt(pendulum_T, [], RIGHT_T, policy)]
    done.append(attempt(pendulum_T, done, WRONG_T, policy))
    assert grading.part_score(done) == 1.0


def test_the_penalty_never_makes_a_score_negative(pendulum_T):
    policy = Policy(retry_penalty=0.6)
    done = []
    for answer in (WRONG_T, WRONG_T + "+0*m", "3*" + WRONG_T, RIGHT_T):
        done.append(attempt(pendulum_T, done, answer, policy))
    assert done[-1].number == 4 and done[-1].score == 0.0


def test_cannot_decide_uses_no_attempt(pendulum_T):
    policy = Policy(max_attempts=1)
    first = attempt(pendulum_T, [], UNDECIDABLE_T, policy)
    assert (first.counted, first.score, first.judged.decided) == (False, None, False)
    assert grading.attempts_left([first], policy) == 1
    second = attempt(pendulum_T, [first], RIGHT_T, policy)
    assert (second.number, second.score) == (1, 1.0)


def test_an_unreadable_answer_uses_no_attempt(pendulum_T):
    a = attempt(pendulum_T, [], "m*l^2*(theta_dot", Policy())
    assert (a.counted, a.judged.code) == (False, "T.unreadable")


def test_attempts_run_out(pendulum_T):
    policy = Policy(max_attempts=2)
    done = [attempt(pendulum_T, [], WRONG_T, policy)]
    done.append(attempt(pendulum_T, done, "-" + RIGHT_T, policy))
    assert grading.attempts_left(done, policy) == 0
    with pytest.raises(AttemptsExhausted):
        attempt(pendulum_T, done, RIGHT_T, policy)


def test_the_same_answer_again_is_not_a_new_attempt(pendulum_T):
    policy = Policy(retry_penalty=0.5)
    first = attempt(pendulum_T, [], WRONG_T, policy)
    again = attempt(pendulum_T, [first], "  " + WRONG_T + " ", policy)
    assert again is first


def test_partial_credit_by_outcome_code():
    variant = one_part("simple_pendulum", "L")
    policy = Policy(partial={"L.up_to_total_derivative": 0.5})
    gauge = "m*l^2*theta_dot^2/2 + m*g*l*cos(theta) + 2*theta*theta_dot"
    a = attempt(variant, [], gauge, policy)
    assert (a.judged.code, a.raw, a.score) == ("L.up_to_total_derivative", 0.5, 0.5)


def test_a_datum_shifted_potential_is_full_credit():
    variant = one_part("simple_pendulum", "V")
    a = attempt(variant, [], "m*g*l*(1 - cos(theta))", Policy())
    assert a.score == 1.0


def test_an_equation_scaled_by_a_constant_is_full_credit():
    variant = one_part("simple_pendulum", "eom", "theta")
    a = attempt(variant, [], "l*theta_ddot + g*sin(theta) = 0", Policy())
    assert a.score == 1.0


def test_total_is_the_weighted_mean():
    parts = [{"id": "a", "weight": 1.0}, {"id": "b", "weight": 3.0}]
    assert grading.total_score(parts, {"a": 1.0, "b": 0.5}) == pytest.approx(0.625)


def test_a_regrade_on_another_engine_keeps_the_key_only_if_it_still_holds(pendulum_T):
    """A variant made by an older engine: its stored key must still be judged right."""
    old = pendulum_T.__class__(**{**pendulum_T.__dict__, "engine_version": -1})
    assert grading.key_still_holds(old, old.parts[0], RIGHT_T)
    assert not grading.key_still_holds(old, old.parts[0], WRONG_T)
    assert grading.key_still_holds(pendulum_T, pendulum_T.parts[0], WRONG_T)  # same engine


def test_an_equilibrium_and_a_frequency_are_graded():
    """The hanging rod: θ₀ = 0 and ω = √(3 g / (2 l)) (by hand)."""
    variant = one_part("physical_pendulum", "frequency")
    a = attempt(variant, [], "sqrt(3*g/(2*l))", Policy())
    assert (a.judged.code, a.score) == ("omega.correct", 1.0)
    b = attempt(variant, [], "sqrt(g/l)", Policy())
    assert (b.judged.code, b.score) == ("omega.wrong", 0.0)
    rest = one_part("physical_pendulum", "equilibrium")
    assert attempt(rest, [], "0", Policy()).judged.code == "q0.correct"
    assert attempt(rest, [], "theta", Policy()).judged.code == "q0.unreadable"


def test_a_normal_mode_is_graded():
    """The double pendulum with m1 = m2 = 1 and l1 = l2 = 1 given: ω₁ = √((2 − √2) g)."""
    given = {n: {"values": [1.0], "given": True} for n in ("m1", "m2", "l1", "l2")}
    variant = one_part("double_pendulum", "frequency", parameters=given)
    assert attempt(variant, [], "sqrt((2-sqrt(2))*g)", Policy()).judged.code == "omega.correct"
    fast = attempt(variant, [], "sqrt((2+sqrt(2))*g)", Policy())  # the other mode
    assert (fast.judged.code, fast.score) == ("omega.wrong", 0.0)
