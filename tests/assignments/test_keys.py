"""Every key verified by a second route before a student sees it (issue 27, item 3).

The second route is sympy's own mechanics (kinetic_energy, LagrangesMethod) on the spec's
bodies; a key that disagrees with it, or that sympy cannot show equal, makes the variant
undeployable, and the preview says why.
"""

from __future__ import annotations

import pytest
import sympy as sp

import mechanics.check
from mechanics.assignments import verify
from mechanics.assignments.keys import derivation, variant_keys
from mechanics.assignments.template import shipped_templates
from mechanics.assignments.variants import build_variant

from .support import one_part


@pytest.mark.parametrize("template_id", sorted(shipped_templates()))
def test_every_shipped_templates_keys_are_verified(template_id):
    for seed in ("1", "2"):
        keys = variant_keys(build_variant(shipped_templates()[template_id], seed))
        assert keys.deployable, keys.why_not
        assert keys.why_not == ""


def test_the_pendulum_keys_are_the_textbook_ones():
    """T = ½ m l² θ̇², V = −m g l cos θ, and m l² θ̈ + m g l sin θ = 0, by hand."""
    variant = one_part("simple_pendulum", "T")
    d = derivation(variant)
    m, length, g = (d.model.params[n] for n in ("m", "l", "g"))
    th, thd = d.model.q[0], d.model.qd[0]
    assert sp.simplify(d.work.T - m * length**2 * thd**2 / 2) == 0
    assert sp.simplify(d.work.V + m * g * length * sp.cos(th)) == 0


def test_a_wrong_key_is_caught_by_the_second_route():
    variant = one_part("simple_pendulum", "T")
    d = derivation(variant)
    m, length = d.model.params["m"], d.model.params["l"]
    wrong = m * length**2 * d.model.qd[0] ** 2  # twice T
    check = verify.verify_key(d, "T", None, wrong)
    assert check.status == "disagrees" and not check.ok
    assert "LagrangesMethod" in check.why


def test_a_wrong_equation_of_motion_key_is_caught():
    variant = one_part("cart_pendulum", "eom", "theta")
    d = derivation(variant)
    w = d.work
    wrong = w.eom_lhs[1] - w.Q[1] + d.model.params["m"] * d.model.qdd[0]  # a stray m ẍ
    assert verify.verify_key(d, "eom", 1, wrong).status == "disagrees"


def test_a_key_equal_only_at_the_samples_is_unconfirmed_not_verified():
    """A bump exp(−10⁶ θ̇²) is below the tolerance at every sampled θ̇: the route cannot
    tell, and says so instead of calling the key verified."""
    variant = one_part("simple_pendulum", "T")
    d = derivation(variant)
    sneaky = d.work.T + sp.exp(-(10**6) * d.model.qd[0] ** 2 - 100)
    check = verify.verify_key(d, "T", None, sneaky)
    assert check.status == "unconfirmed"


def test_the_second_route_does_not_use_the_checker(monkeypatch):
    """Not the same code judging itself: with the checker's proofs disabled, keys still verify."""

    def refuse(*args, **kwargs):
        raise AssertionError("the verification called the checker")

    for name in ("zero_proof", "constant_proof", "check", "expected_quantity"):
        monkeypatch.setattr(mechanics.check, name, refuse)
    variant = one_part("spring_mass_damper", "eom", "x")
    d = derivation(variant)
    w = d.work
    assert verify.verify_key(d, "eom", 0, w.eom_lhs[0] - w.Q[0]).ok
    assert verify.verify_key(d, "Q", 0, w.Q[0]).ok


def test_an_undeployable_variant_says_which_part_and_why(monkeypatch):
    variant = one_part("simple_pendulum", "T")

    def disagree(d, quantity, j, engine):
        return verify.Check("disagrees", "the two routes differ")

    monkeypatch.setattr("mechanics.assignments.keys.verify_key", disagree)
    keys = variant_keys(variant)
    assert not keys.deployable
    assert keys.why_not == "part 'p': key disagrees: the two routes differ"


def test_a_frequency_key_is_the_hand_derived_one_and_verified():
    """The rod about its end: I = m l²/3, K = m g l/2, so ω = √(3 g / (2 l)) (by hand)."""
    from mechanics.assignments.oscillations import key, verify

    variant = one_part("physical_pendulum", "frequency")
    d = derivation(variant)
    omega = key(d, variant.parts[0])
    g, length = d.model.params["g"], d.model.params["l"]
    assert sp.simplify(omega**2 - 3 * g / (2 * length)) == 0
    assert verify(d, variant.parts[0], omega).ok
    assert verify(d, variant.parts[0], 2 * omega).status == "disagrees"


def test_a_frequency_about_an_unstable_equilibrium_is_never_deployed():
    from mechanics.assignments.template import parse_template
    from mechanics.assignments.variants import build_variant

    document = {
        "id": "t",
        "title": "t",
        "scene": "simple_pendulum",
        "parts": [{"id": "w", "quantity": "frequency", "near": 3.0}],
    }  # θ = π: on top
    keys = variant_keys(build_variant(parse_template(document), "1"))
    assert not keys.deployable and "not stable" in keys.why_not


def test_the_double_pendulums_normal_modes_are_the_hand_derived_ones():
    """Equal masses and lengths: ω² = (2 ∓ √2) g / l (the textbook result), both verified."""
    from mechanics.assignments.oscillations import key, verify

    variant = one_part("double_pendulum", "frequency")
    d = derivation(variant)
    p = d.model.params
    equal = {p["m2"]: p["m1"], p["l2"]: p["l1"]}
    for mode, sign in ((1, -1), (2, +1)):
        part = {**variant.parts[0], "mode": mode}
        omega = key(d, part)
        by_hand = (2 + sign * sp.sqrt(2)) * p["g"] / p["l1"]
        values = {p["m1"]: 1.3, p["l1"]: 0.7, p["g"]: 9.81}
        assert complex((omega**2).subs(equal).subs(values)) == pytest.approx(
            complex(by_hand.subs(values))
        )
        assert verify(d, part, omega).ok


def test_a_free_coordinate_has_no_frequency_to_ask():
    """The cart is free to roll: one mode has ω = 0, so the variant is not deployed."""
    keys = variant_keys(one_part("cart_pendulum", "frequency"))
    assert not keys.deployable and "free coordinate" in keys.why_not
