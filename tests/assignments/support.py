"""Shared helpers of the assignment tests: a one-part variant of a built-in scene."""

from __future__ import annotations

from mechanics.assignments.template import parse_template
from mechanics.assignments.variants import Variant, build_variant


def one_part(scene: str, quantity: str, coordinate: str | None = None, **template) -> Variant:
    """The variant (seed "1") of a template asking one part of a built-in scene as it is."""
    part = {"id": "p", "quantity": quantity}
    if coordinate is not None:
        part["coordinate"] = coordinate
    document = {"id": "t", "title": "t", "scene": scene, "parts": [part], **template}
    return build_variant(parse_template(document), "1")
