"""tidy() holds a root of a sum as one symbol (steps/radicals.py) but still cancels an integer
inverse power of a sum: the regression of commit dde0e63, which held 1/(m₁ + m₂) too, so the
Atwood rope's force printed g m₁ ((m₂ − m₁)/(m₁ + m₂) + 1) on Newton's panel and the ladder's
free-body diagram lost its two normal forces (bisected; fixed in the same round).

Expected values by hand:
- Atwood: a = g (m₂ − m₁)/(m₁ + m₂) for m₁ (up positive), T = m₁ (g + a) = 2 g m₁ m₂/(m₁ + m₂).
- Ladder: |G − O|² / (sin²θ + cos²θ) with G = (L/2)(sin θ, cos θ) is L²/4.
- A primary's pull −∂/∂x (−G M m/r) = −G M m (x − a)/r³ with r² = (x − a)² + y²: one term, the
  square under the root not multiplied out.
"""

from __future__ import annotations

import sympy as sp

from mechanics.steps import tidy

g, m1, m2, L, theta = sp.symbols("g m_1 m_2 L theta", positive=True)
x, y, a, G, M, m = sp.symbols("x y a G M m", real=True)


def test_an_inverse_power_of_a_sum_of_masses_is_put_over_one_denominator():
    acceleration = g * (m2 - m1) / (m1 + m2)
    tension = tidy(m1 * (g + acceleration))
    assert tension == 2 * g * m1 * m2 / (m1 + m2)


def test_an_inverse_power_of_a_trig_sum_cancels_by_sin2_plus_cos2():
    G_ = L / 2 * sp.Matrix([sp.sin(theta), sp.cos(theta)])
    ratio = G_.dot(G_) / (sp.sin(theta) ** 2 + sp.cos(theta) ** 2)
    assert tidy(ratio) == L**2 / 4


def test_a_root_of_a_sum_is_still_held_as_written():
    r2 = (x - a) ** 2 + y**2
    pull = tidy(sp.diff(G * M * m / sp.sqrt(r2), x))
    assert sp.simplify(pull + G * M * m * (x - a) / r2 ** sp.Rational(3, 2)) == 0
    (root,) = [p for p in pull.atoms(sp.Pow) if p.base.is_Add and not p.exp.is_integer]
    assert root.exp == sp.Rational(-3, 2) and root.base == r2  # not expanded
    assert len(sp.Add.make_args(sp.expand(pull, deep=False, mul=False))) == 1
