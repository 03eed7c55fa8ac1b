"""A variant's keys: each part's answer from the engine's derivation, each checked by the
second route (mechanics/assignments/verify.py) before any student sees the variant.

The key is what mechanics.check judges against (`expected_quantity`), written out in plain text
(the notation a student types) and LaTeX. A variant is deployable only if every key is verified;
otherwise `VariantKeys.why_not` says which part and why.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from mechanics.check import expected_quantity
from mechanics.derive import Derivation, derivation_of_spec
from mechanics.expr import to_latex, to_plain

from . import oscillations
from .variants import Variant
from .verify import Check, verify_key


@dataclass(frozen=True)
class PartKey:
    part: str
    plain: str
    latex: str
    check: Check

    def to_json(self) -> dict[str, Any]:
        return {
            "part": self.part,
            "plain": self.plain,
            "latex": self.latex,
            "verified": self.check.ok,
            "verification": self.check.status,
            "why": self.check.why,
        }


@dataclass(frozen=True)
class VariantKeys:
    keys: list[PartKey]

    @property
    def deployable(self) -> bool:
        return all(k.check.ok for k in self.keys)

    @property
    def why_not(self) -> str:
        """'' when deployable; else the first part whose key is not confirmed, and why."""
        for k in self.keys:
            if not k.check.ok:
                return f"part '{k.part}': key {k.check.status}: {k.check.why}"
        return ""

    def to_json(self) -> dict[str, Any]:
        return {
            "deployable": self.deployable,
            "why_not": self.why_not,
            "parts": [k.to_json() for k in self.keys],
        }


def derivation(variant: Variant) -> Derivation:
    """The engine's derivation of the variant's scene, once per process (mechanics.derive)."""
    return derivation_of_spec(variant.spec_text())


def coordinate_index(d: Derivation, part: dict[str, Any]) -> int | None:
    name = part.get("coordinate")
    return None if name is None else d.model.coordinate_names.index(name)


def shown(d: Derivation, quantity: str, j: int | None, expr: Any) -> tuple[str, str]:
    """The key as a student would write it (plain) and as the notes print it (LaTeX)."""
    if quantity == "eom":
        w = d.work
        lhs, rhs = w.eom_lhs[j], w.Q[j]
        return f"{to_plain(lhs)} = {to_plain(rhs)}", f"{to_latex(lhs)} = {to_latex(rhs)}"
    return to_plain(expr), to_latex(expr)


def variant_keys(variant: Variant) -> VariantKeys:
    """Every part's key, each verified by the second route."""
    d = derivation(variant)
    out = []
    for part in variant.parts:
        if part["quantity"] in oscillations.QUANTITIES:
            out.append(_oscillation_key(d, part))
            continue
        j = coordinate_index(d, part)
        expr = expected_quantity(d, part["quantity"], j)
        plain, latex = shown(d, part["quantity"], j, expr)
        try:
            check = verify_key(d, part["quantity"], j, expr)
        except Exception as exc:  # sympy's mechanics refusing a model is "cannot confirm"
            check = Check("unconfirmed", f"the second route failed: {type(exc).__name__}")
        out.append(PartKey(part["id"], plain, latex, check))
    return VariantKeys(out)


def _oscillation_key(d: Derivation, part: dict[str, Any]) -> PartKey:
    """An equilibrium's or a frequency's key; one that cannot be made (an unstable equilibrium,
    no root) is a key that cannot be confirmed, with the reason."""
    try:
        expr = oscillations.key(d, part)
    except (ValueError, NotImplementedError, TypeError) as exc:
        return PartKey(part["id"], "", "", Check("unconfirmed", str(exc)))
    try:
        check = oscillations.verify(d, part, expr)
    except Exception as exc:
        check = Check("unconfirmed", f"the second route failed: {type(exc).__name__}")
    return PartKey(part["id"], to_plain(expr), to_latex(expr), check)


def deploy_job(template_document: dict[str, Any], seed: str) -> dict[str, Any]:
    """One variant and its verified keys as JSON (a pool job: module level, picklable)."""
    from .template import parse_template
    from .variants import build_variant

    variant = build_variant(parse_template(template_document), seed)
    return {"variant": variant.to_json(), "keys": variant_keys(variant).to_json()}
