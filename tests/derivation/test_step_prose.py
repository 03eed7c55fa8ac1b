"""The steps' prose shows its math as math (issue 13, item 5): every formula in a sentence is
written as ``$...$`` (typeset on the page, kept as math in the LaTeX export), never as code-like
text such as ``Q_j`` or ``∂L/∂q̇_j``.
"""

from __future__ import annotations

import re

import pytest

from mechanics.export_latex import safe_math
from mechanics.jobs import derivation_of
from mechanics.scenes import scene_ids

#: What a formula written as plain text looks like: a letter with a subscript or a superscript,
#: a partial derivative, a sum, a dotted coordinate, a ½.
PSEUDO_MATH = re.compile(r"(?<![A-Za-z0-9])[A-Za-zα-ω][\u0307\u0308]?[_^][A-Za-z0-9{]|[∂Σ½]|q̇|q̈")


def _prose(scene_id: str) -> list[str]:
    d = derivation_of(scene_id, None)
    texts = []
    for step in d.steps:
        texts.append(step.text)
        if step.id == "fbd":
            texts += list((step.data or {}).get("constraints", []))
    return texts


@pytest.mark.parametrize("scene_id", scene_ids())
def test_every_formula_in_the_prose_is_math(scene_id):
    for text in _prose(scene_id):
        parts = text.split("$")
        assert len(parts) % 2 == 1, f"an unpaired $ in {text!r}"
        words, maths = parts[0::2], parts[1::2]
        for math in maths:
            assert math.strip() and safe_math(math), (math, text)
        for part in words:
            assert not PSEUDO_MATH.search(part), (PSEUDO_MATH.search(part).group(), text)


def test_the_probe_finds_code_like_math():
    """The check above would catch the sentences as they were before."""
    before = [
        "enter through Q_j. For ideal constraints",
        "d/dt ∂L/∂q̇_j − ∂L/∂q_j = Q_j^NC (eq. 36)",
        "so E changes by W^NC (eq. 23)",
        "T = ½ m v·v for each particle",
    ]
    assert all(PSEUDO_MATH.search(t) for t in before)
    assert not PSEUDO_MATH.search("bob_1 hangs from the pin at O; theta_dot")  # names stay


@pytest.mark.parametrize("scene_id", scene_ids())
def test_a_scenes_summary_reads_as_prose(scene_id):
    """The summary heads the scene's page and its catalog card, where nothing typesets it: its
    symbols are Unicode (θ, m₁, mL²), never code (x_ddot, Q^NC, theta)."""
    from mechanics.scenes import load_scene

    summary = load_scene(scene_id)["summary"]
    assert not PSEUDO_MATH.search(summary), summary
    assert not re.search(r"\b(theta|phi|alpha|Omega|omega|x_ddot|_dot)\b", summary), summary


@pytest.mark.parametrize(
    ("scene_id", "weight", "springs"),
    [
        ("simple_pendulum", True, False),
        ("spring_mass_damper", False, True),
        ("elastic_pendulum", True, True),
        ("central_force", False, False),
    ],
)
def test_the_datum_names_only_what_the_scene_has(scene_id, weight, springs):
    """A scene without gravity has no heights to measure V from, and draws no weight: the
    free-body step says so instead of leaving a student to look for the missing mg."""
    from mechanics.scenes import load_scene

    spec = load_scene(scene_id)
    assert (spec.get("gravity") is not None) == weight  # the scene as written
    assert bool(spec.get("springs")) == springs
    text = next(s.text for s in derivation_of(scene_id, None).steps if s.id == "fbd")
    assert ("height of O" in text) == weight
    assert ("rest length" in text) == springs
    assert ("no uniform gravity" in text) == (not weight)
