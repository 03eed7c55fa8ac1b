"""Step 4 (notes III, eq. 24–29): kinetic energy T and potential energy V."""

from __future__ import annotations

import sympy as sp

from mechanics.expr import to_plain
from mechanics.model import Model, reference_value
from mechanics.steps import Line, Step, Work, eq_line, sub, tidy

#: Letters the derivation gives a meaning of its own: T and V the energies, L the Lagrangian.
#: The letters a scene's own parameter or coordinate may take, and what the derivation writes
#: for the quantity instead.
SCRIPT_LETTERS = {
    "T": r"\mathcal{T}",
    "V": r"\mathcal{V}",
    "L": r"\mathcal{L}",
    "E": r"\mathcal{E}",
    "Q": r"\mathcal{Q}",
}
MEANINGS = {
    "T": "kinetic energy",
    "V": "potential energy",
    "L": "Lagrangian",
    "E": "energy",
    "Q": "generalized forces",
}


def letter(model: Model, name: str) -> str:
    """T, V, L, E or Q as the derivation prints it: script when the scene has a parameter or
    coordinate of that name, so that "L = L m (…)" never reads as one symbol with two meanings
    (nor a posted force Q as the Q_j beside it).

    A posted spec may well call a length L (a textbook does); refusing it would turn away a
    correct scene, so the energy takes the other letter instead.
    """
    taken = set(model.spec.parameters) | set(model.spec.coordinates)
    return SCRIPT_LETTERS[name] if name in taken else name


def script_note(model: Model, *names: str) -> str:
    """The sentence that says which letters are script here, and why ('' when none is)."""
    taken = [n for n in names if letter(model, n) != n]
    if not taken:
        return ""
    written = " and ".join(
        f"the {MEANINGS[n]} as ${letter(model, n)}{'_j' if n == 'Q' else ''}$" for n in taken
    )
    return (
        f" The scene has a parameter or coordinate named {' and '.join(taken)}, so this "
        f"derivation writes {written}."
    )


def spring_words(name: str) -> str:
    """'spring k1', but 'spring' for a spring named "spring" (not "the spring spring")."""
    return name if name.lower().startswith("spring") else f"spring {name}"


def potential_parts(model: Model) -> list[tuple[str, str, sp.Expr]]:
    """(kind, name, V part): each conservative force's share of V, datum at O."""
    parts = []
    if model.gravity is not None:
        g, down = model.gravity
        for b in model.bodies:
            parts.append(("weight", b.name, -b.mass * g * b.position.dot(down)))
    parts += [("spring", s.name, s.energy) for s in model.springs]
    parts += [("potential", name, e) for name, e in model.potentials]
    return parts


def energies(model: Model, work: Work) -> Step:
    """T = ½ m v·v (+ ½ ω·I_G·ω for rigid bodies); V = m g h + ½ k (ℓ − ℓ0)² + extra potentials."""
    lines: list[Line] = []
    T_, V_ = letter(model, "T"), letter(model, "V")
    T = sp.S.Zero
    for b in model.bodies:
        v = model.velocity(b.name)
        Tb = b.mass * v.dot(v) / 2
        if b.frame is not None:
            w = b.frame.ang_vel_in(model.N)
            Tb += w.dot(b.inertia.dot(w)) / 2
        Tb = tidy(Tb, model)
        lines.append(eq_line(f"T_{b.name}", f"{T_}_{{{sub(b.name)}}}", Tb))
        T += Tb
    V = sp.S.Zero
    for _, name, part in potential_parts(model):
        part = tidy(part, model)
        lines.append(eq_line(f"V_{name}", f"{V_}_{{{sub(name)}}}", part))
        V += part
    work.T = tidy(T, model)
    work.V = tidy(V, model)
    lines += [eq_line("T", T_, work.T), eq_line("V", V_, work.V)]
    text = (
        rf"${T_} = \tfrac12 m\,\vec v\cdot\vec v$ for each particle (eq. 24) and "
        r"$\tfrac12 m\,\vec v_G\cdot\vec v_G + \tfrac12\,\vec\omega\cdot I_G\,\vec\omega$ for each "
        rf"rigid body (eq. 25); ${V_}$ sums $m g h$ of each body above the datum (eq. 29), "
        r"$\tfrac12 k(\ell - \ell_0)^2$ of each spring (eq. 27) and any given potential."
    ) + script_note(model, "T", "V")
    for s in model.springs:
        if s.branch is None:
            continue
        p = to_plain(s.branch)
        text += (
            f" The {spring_words(s.name)} lies along a line, so ℓ = |{p}|; it is written ℓ = {p}, "
            f"taking {p} > 0 (the side of its anchor the spec's initial state is on, or this side "
            "when that state is at the anchor). A run that starts on the other side is derived "
            "with the opposite sign, and one that reaches ℓ = 0 stops there."
        )
        # (with a rest length of 0 at the spec's values, V = ½ k p² is smooth through the anchor)
        at_anchor = reference_value(s.branch, model.spec, model.names) == 0
        if at_anchor and reference_value(s.rest_length, model.spec, model.names) != 0:
            work.warnings.append(
                f"The spec's initial state puts the {spring_words(s.name)} at its anchor (ℓ = 0), "
                "where it has no direction: give `initial` a state off the anchor to simulate it."
            )
    return Step("energy", "Kinetic and potential energy", text, lines)
