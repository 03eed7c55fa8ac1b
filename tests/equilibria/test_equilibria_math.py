"""The equilibria's reasons carry their math as $…$ LaTeX, so that the page typesets it.

A reason written as plain text showed a student 'grows like e^(3.132 t)' with a caret, and its
LaTeX line in the stability step escaped the caret into 'e\\^{}(4.047 t)'. Here every reason of
every catalog scene and of the posted specs of test_equilibria_nc.py is read apart into its
words and its math: the words hold no notation (no caret, no '**', no '_dot', no ∂ or λ, no
bare K or C), and each math part passes the LaTeX export's own whitelist (an independent reader
of the LaTeX). The numbers in the math are checked against closed forms: the inverted simple
pendulum grows like e^{√(g/l) t}.
"""

from __future__ import annotations

import functools
import math
import re

import pytest
import sympy as sp
from test_equilibria_nc import cubic, top, trap, ziegler

from mechanics.derive import derivation_of_scene, derive_model
from mechanics.equilibria import equilibria, reason_plain
from mechanics.export_latex import safe_math
from mechanics.scenes import load_scene, scene_ids

#: Notation that means math and must not stand in the words of a reason.
NOTATION = ("^", "**", "_dot", "∂", "λ", "Σ", "±", "q̇", "ω", "\\", "−")


def posted_specs() -> list[tuple[str, dict]]:
    """Every posted spec of test_equilibria_nc.py, with the parameters it is judged at."""
    wind = load_scene("spherical_pendulum")
    wind["parameters"]["F"] = 2.0
    wind["forces"] = [{"name": "wind", "on": wind["bodies"][0]["name"], "vector": ["F", 0, 0]}]
    return [
        ("cubic pumping", cubic(0.1)),
        ("cubic draining", cubic(-0.1)),
        ("damped x only", trap(["-c*x_dot + c*x_dot**2", 0, 0])),
        ("cross damping", trap(["-c*(x_dot - y_dot)", "c*(x_dot - y_dot)", 0])),
        ("magnetic trap", trap(["q*B*y_dot", "-q*B*x_dot", 0], k=1.0, B=0.5)),
        ("magnetic anti-trap", trap(["q*B*y_dot", "-q*B*x_dot", 0], k=-1.0, B=3.0)),
        ("damper in time", trap(["-c*x_dot*cos(t)", 0, 0])),
        *((f"Ziegler P = {P}", ziegler(P)) for P in (1.0, 2.0, 2.2, 3.0)),
        ("top", top()),
        ("top spun", top(I3=0.5)),
        ("pendulum in a wind", wind),
    ]


def words_and_math(reason: str) -> tuple[list[str], list[str]]:
    parts = reason.split("$")
    assert len(parts) % 2 == 1, f"an unpaired $ in {reason!r}"
    return parts[0::2], parts[1::2]


def assert_speaks_math(reason: str) -> None:
    words, maths = words_and_math(reason)
    for text in words:
        for mark in NOTATION:
            assert mark not in text, f"{mark!r} outside $…$ in {reason!r}"
        assert not re.search(r"\b[KCM]\b", text), f"a bare matrix name in {reason!r}"
    for tex in maths:
        assert tex.strip() and safe_math(tex), f"not LaTeX the export reads: {tex!r}"


#: Every built-in scene and posted system whose equilibria are read here, by name. Their
#: equilibria are computed when a test first asks (issue 25: the module computed all 28 at
#: import, 19 s of every worker's collection), then kept for the session.
POSTED_SPECS = dict(posted_specs())
NAMES = sorted([*scene_ids(), *POSTED_SPECS])


@functools.cache
def result_of(name: str) -> dict:
    """The equilibria of a built-in scene or a posted system, computed once per process."""
    if name in POSTED_SPECS:
        return equilibria(derive_model(POSTED_SPECS[name]), {})
    return equilibria(derivation_of_scene(name), {})


@pytest.mark.parametrize("name", NAMES)
def test_every_reason_carries_its_math_as_latex(name):
    for e in result_of(name)["equilibria"]:
        assert_speaks_math(e["reason"])
        plain = reason_plain(e["reason"])
        assert "$" not in plain and "\\" not in plain, plain


def test_the_checks_would_see_the_old_plain_text():
    """The reasons as they were written before: each is caught (the test can fail)."""
    for old in (
        "an eigenvalue has positive real part (λ = 3.132): grows like e^(3.132 t)",
        "the power Σ Q_j q̇_j = c*x_dot**4 has no sign",
        "K is positive definite (eigenvalues ±3.132i)",
        "the stiffness matrix K = ∂²V/∂q²",
    ):
        with pytest.raises(AssertionError):
            assert_speaks_math(old)


def test_the_reasons_cover_every_kind_of_sentence():
    """The specs above reach each verdict, so the check reads every sentence the module has."""
    kinds = {e["kind"] for name in NAMES for e in result_of(name)["equilibria"]}
    assert kinds == {"stable", "gyroscopically stable", "marginal", "unstable"} | (
        kinds & {"asymptotically stable"}
    )


def test_the_inverted_pendulum_grows_like_e_to_the_root_g_over_l_t():
    """θ̈ = (g/l) sin θ ≈ (g/l) δθ at the top: λ = ±√(g/l), δθ ∝ e^{√(g/l) t}; at the bottom
    λ = ±i√(g/l). The math in the reason states exactly these numbers."""
    p = load_scene("simple_pendulum")["parameters"]
    rate = f"{math.sqrt(p['g'] / p['l']):.4g}"
    bottom, top_ = sorted(result_of("simple_pendulum")["equilibria"], key=lambda e: e["q"]["theta"])
    assert rf"$\lambda = \pm {rate}i$" in bottom["reason"]
    assert rf"$e^{{{rate}\,t}}$" in top_["reason"] and rf"$\lambda = {rate}$" in top_["reason"]


def test_the_stability_step_writes_names_and_powers_as_latex():
    """Its line was \\text{theta = 0: stable} … e\\^{}(3.132 t): now the coordinate is \\theta,
    the power e^{…}, and only words sit in \\text (no escaped caret, no $ inside)."""
    step = result_of("simple_pendulum")["steps"][1]
    verdicts = [line for line in step["latex"] if r"\text{because }" in line]
    assert verdicts and all(line.startswith(r"\theta = ") for line in verdicts)
    for line in verdicts:
        assert r"\^{}" not in line and "$" not in line
        words = re.findall(r"\\text\{((?:[^{}\\]|\\.)*)\}", line)
        assert all("^" not in w.replace(r"\^", "") for w in words), words
        assert safe_math(re.sub(r"\\text\{(?:[^{}\\]|\\.)*\}", "", line)), line
    assert any(r"e^{3.132\,t}" in line for line in verdicts)
    _, step_maths = words_and_math(step["text"])
    assert all(safe_math(tex) for tex in step_maths)
    assert all("because" in p and "$" not in p for p in step["plain"] if "because" in p)


def test_a_power_is_written_as_latex_not_python():
    """The cubic force's power F ẋ = c ẋ⁴ (by hand) appears as c \\dot{x}^{4}, not c*x_dot**4;
    it is the non-conservative forces' power (Q_j^NC, the forces step's letter), not Q_j's."""
    (e,) = result_of("cubic pumping")["equilibria"]
    assert r"$\sum_j Q_j^{NC} \dot q_j = c \dot{x}^{4}$" in e["reason"]
    assert "Σ_j Q_j^NC q̇_j = c ẋ^4" in reason_plain(e["reason"])


# --- one meaning per symbol: a parameter named E or Q ------------------------------------------


def named_e_and_q(damped: bool) -> dict:
    """A spring of stiffness E; with ``damped`` a dashpot force −Q ẋ (a textbook's E and Q)."""
    spec = {
        "title": "E and Q as parameters",
        "coordinates": ["x"],
        "parameters": {"m": 1.0, "E": 4.0, "Q": 0.5},
        "bodies": [{"name": "b", "mass": "m", "position": ["x", 0, 0]}],
        "springs": [{"name": "s", "a": "O", "b": "b", "k": "E"}],
    }
    if damped:
        spec["forces"] = [{"name": "f", "on": "b", "vector": ["-Q*x_dot", 0, 0]}]
    return spec


def step(spec: dict, step_id: str) -> dict:
    return next(s for s in derive_model(spec).steps if s.id == step_id).to_json()


@pytest.mark.parametrize("damped", [False, True])
def test_a_parameter_named_e_or_q_leaves_those_letters_to_it(damped):
    """The energy (½ m ẋ² + ½ E x², by hand) is written 𝓔, the generalized forces 𝒬_j; the
    letters E and Q, alone in the LaTeX, are the parameters. Without the parameters the
    steps keep E and Q."""
    spec = named_e_and_q(damped)
    conserved, forces = step(spec, "conserved"), step(spec, "forces")
    for s in (conserved, forces):
        _, maths = words_and_math(s["text"])
        # E and Q as the energy or a generalized force (E =, dE/dt, Q_j, Q^NC), never the
        # parameters E and Q themselves (the spring's −E x may appear)
        energy_or_force = r"(?<![\\{A-Za-z])(?:d?E\s*=|dE/dt|Q_|Q\^)"
        assert not any(re.search(energy_or_force, m) for m in maths), maths
    assert r"\mathcal{Q}_j" in forces["text"] and "named Q" in forces["text"]
    assert forces["latex"] == [r"\mathcal{Q}_{x}^{NC} = " + ("- Q \\dot{x}" if damped else "0")]
    if damped:  # energy changes: dE/dt = Σ Q_j q̇_j
        assert r"d\mathcal{E}/dt = \sum_j \mathcal{Q}_j^{NC} \dot q_j" in conserved["text"]
    else:  # the energy line: 𝓔 = T + V = ½ m ẋ² + ½ E x², E the parameter
        (line,) = conserved["latex"]
        assert line.startswith(r"\mathcal{E} = T + V = ") and "named E" in conserved["text"]
        x, x_dot, E, m = sp.symbols("x x_dot E m")
        stated = sp.sympify(conserved["plain"][0].split("=", 1)[1], {"E": E})
        assert sp.simplify(stated - (m * x_dot**2 / 2 + E * x**2 / 2)) == 0

    plain = {**named_e_and_q(damped), "parameters": {"m": 1.0, "k": 4.0, "c": 0.5}}
    plain["springs"] = [{"name": "s", "a": "O", "b": "b", "k": "k"}]
    if damped:
        plain["forces"] = [{"name": "f", "on": "b", "vector": ["-c*x_dot", 0, 0]}]
    for s in (step(plain, "conserved"), step(plain, "forces")):
        assert "mathcal" not in s["text"] + "".join(s["latex"]) and "named" not in s["text"]


def test_the_forces_step_says_the_conservative_forces_are_in_v():
    """Eq. 31 sums every force; the step computes only Q_j^NC, and says how the two relate:
    Q_j = Q_j^NC − ∂V/∂q_j. A pendulum's weight is in V, so its Q_θ^NC = 0 (by hand)."""
    s = step(load_scene("simple_pendulum"), "forces")
    assert r"$Q_j = -\partial V/\partial q_j$" in s["text"] and "through $V$" in s["text"]
    assert s["latex"] == [r"Q_{\theta}^{NC} = 0"]
    s = step(load_scene("spring_mass_damper"), "forces")
    assert "already in $V$" in s["text"]
    assert r"$Q_j = Q_j^{NC} - \partial V/\partial q_j$" in s["text"]
    damped = step(named_e_and_q(True), "forces")
    assert r"\mathcal{Q}_j = \mathcal{Q}_j^{NC} - \partial V/\partial q_j" in damped["text"]
    assert r"\vec F_i^{NC}" in damped["text"]
