"""The names a spec uses, checked across fields: each declared once, each reference resolving,
and which parameters are nonnegative by nature (a mass, a length, a stiffness).

Pydantic checks one field at a time (mechanics/spec.py); what needs the whole spec lives here.
"""

from __future__ import annotations

import math
import re
from typing import Any

from mechanics.constant_mass import variable_mass_errors
from mechanics.spec import RESERVED, FramePosition, SceneSpec, SpecError
from mechanics.units import BASE, UnitError, parse_unit

#: Units of quantities that are nonnegative by nature: mass, length, stiffness, damping, inertia.
NONNEGATIVE_UNITS = frozenset(
    {"kg", "m", "N/m", "N*s/m", "N s/m", "kg*m^2", "kg m^2", "kg*m**2", "kg/s"}
)


def nonnegative_parameters(spec: SceneSpec) -> dict[str, str]:
    """Parameters that are nonnegative by nature, each with what it is, for messages.

    Only these may be assumed ≥ 0 in the algebra (sqrt(l**2) = l) and refused when negative: a
    charge, a rotation rate or an offset can be negative, and an assumption the API does not
    enforce would make the derivation wrong for a value it accepts. Nature is read from the
    role a parameter plays on its own (a body's mass, a spring's k) or from its unit.
    """
    roles: dict[str, str] = {}

    def role(value: Any, what: str) -> None:
        if isinstance(value, str) and value.strip() in spec.parameters:
            roles.setdefault(value.strip(), what)

    for b in spec.bodies:
        role(b.mass, "a mass")
        if b.inertia is not None:
            for key in ("ixx", "iyy", "izz"):
                role(getattr(b.inertia, key), "a moment of inertia")
    for s in spec.springs:
        role(s.k, "a spring stiffness")
        role(s.rest_length, "a rest length")
    for d in spec.dampers:
        role(d.c, "a damping coefficient")
    if spec.gravity is not None:
        role(spec.gravity.acceleration, "the gravitational acceleration")
    for name, unit in spec.units.items():
        if name in spec.parameters and unit.strip() in NONNEGATIVE_UNITS:
            roles.setdefault(name, f"a quantity in {unit.strip()}")
    return roles


_DOT = re.compile(r"^(?P<q>.+?)_(?P<d>d?dot)$")


def check_names(spec: SceneSpec) -> None:
    """Cross-field checks pydantic cannot do: declared-once names and references that resolve.

    Expressions themselves are checked where they are parsed (the model builder), with the same
    field paths; here the structure: every frame, point and body a field refers to must exist.
    """
    errors: list[dict[str, str]] = []

    def err(field: str, message: str) -> None:
        errors.append({"field": field, "message": message})

    declared: dict[str, str] = {}

    def declare(name: str, field: str) -> None:
        if name in RESERVED:
            err(field, f"'{name}' is reserved")
        elif name in declared:
            err(field, f"'{name}' is already declared at {declared[name]}")
        elif _DOT.match(name) and _DOT.match(name)["q"] in spec.coordinates:
            err(
                field, f"'{name}' clashes with the velocity of coordinate '{_DOT.match(name)['q']}'"
            )
        else:
            declared[name] = field

    for i, q in enumerate(spec.coordinates):
        declare(q, f"coordinates[{i}]")
    for name in spec.parameters:
        declare(name, f"parameters.{name}")
    frames = {"N"}
    for i, f in enumerate(spec.frames):
        declare(f.name, f"frames[{i}].name")
        if f.parent not in frames:
            err(f"frames[{i}].parent", f"unknown frame '{f.parent}' (declare parents first)")
        if f.unit_vectors is not None and len(set(f.unit_vectors)) < len(f.unit_vectors):
            err(
                f"frames[{i}].unit_vectors",
                "three different names, one per axis: "
                f"{', '.join(f.unit_vectors)} would print two axes alike",
            )
        frames.add(f.name)
    places = {"O"}
    for i, p in enumerate(spec.points):
        declare(p.name, f"points[{i}].name")
        places.add(p.name)
    for i, b in enumerate(spec.bodies):
        declare(b.name, f"bodies[{i}].name")
        places.add(b.name)
        if b.kind == "rigid_body":
            if b.frame is None:
                err(f"bodies[{i}].frame", "a rigid body needs its body-fixed frame")
            if b.inertia is None:
                err(f"bodies[{i}].inertia", "a rigid body needs its central inertia")
        if b.frame is not None and b.frame not in frames:
            err(f"bodies[{i}].frame", f"unknown frame '{b.frame}'")

    def check_position(pos: Any, field: str, known: set[str]) -> None:
        if isinstance(pos, FramePosition):
            if pos.frame not in frames:
                err(f"{field}.frame", f"unknown frame '{pos.frame}'")
            if pos.from_ is not None and pos.from_ not in known:
                err(f"{field}.from", f"unknown point or body '{pos.from_}'")

    known = {"O"}
    for i, p in enumerate(spec.points):
        check_position(p.position, f"points[{i}].position", known | {b.name for b in spec.bodies})
        known.add(p.name)
    for i, b in enumerate(spec.bodies):
        check_position(b.position, f"bodies[{i}].position", places - {b.name})
    for group, items in (("springs", spec.springs), ("dampers", spec.dampers)):
        for i, s in enumerate(items):
            for end in ("a", "b"):
                if getattr(s, end) not in places:
                    err(f"{group}[{i}].{end}", f"unknown point or body '{getattr(s, end)}'")
            if s.a == s.b:
                err(f"{group}[{i}].b", "both ends are the same place")
    bodies = {b.name: b for b in spec.bodies}
    for i, f in enumerate(spec.forces):
        if f.on == "O":
            err(
                f"forces[{i}].on",
                "O is the fixed origin: a force on it does no work and moves nothing (the "
                "support takes it); apply it to a body or a point that moves",
            )
        elif f.on not in places:
            err(f"forces[{i}].on", f"unknown point or body '{f.on}'")
        check_position(f.vector, f"forces[{i}].vector", places)
    for i, f in enumerate(spec.torques):
        if f.on not in bodies or bodies[f.on].kind != "rigid_body":
            err(f"torques[{i}].on", f"'{f.on}' is not a rigid body of this scene")
        check_position(f.vector, f"torques[{i}].vector", places)
    for i, stop in enumerate(spec.stops):
        if (stop.when is None) == (stop.tension is None):
            err(f"stops[{i}].when", "give exactly one of 'when' (an expression) or 'tension'")
        if stop.tension is not None and stop.tension not in bodies:
            err(f"stops[{i}].tension", f"unknown body '{stop.tension}'")
        if stop.along is not None and (
            stop.tension is None or not all(map(math.isfinite, stop.along)) or not any(stop.along)
        ):
            err(f"stops[{i}].along", "a finite, non-zero direction, only with 'tension'")
        if stop.tension is not None and stop.crossing != "falls":
            err(f"stops[{i}].crossing", "a string goes slack when its tension falls to 0")
    for i, q in enumerate(spec.positive_coordinates):
        if q not in spec.coordinates:
            err(f"positive_coordinates[{i}]", f"unknown coordinate '{q}'")
    for name, what in nonnegative_parameters(spec).items():
        if spec.parameters[name] < 0:
            err(f"parameters.{name}", f"must be ≥ 0: {name} is {what}")
    for i, b in enumerate(spec.bodies):
        if isinstance(b.mass, (int, float)) and b.mass <= 0:
            err(f"bodies[{i}].mass", "must be > 0: a body needs a positive mass")
    errors += variable_mass_errors(spec)  # Lagrange's equations need constant masses
    allowed_initial = set(spec.coordinates) | {f"{q}_dot" for q in spec.coordinates}
    for name in spec.initial:
        if name not in allowed_initial:
            err(f"initial.{name}", f"unknown coordinate or velocity '{name}'")
    for name, unit in spec.units.items():
        if name not in spec.parameters and name not in spec.coordinates:
            err(f"units.{name}", f"unknown parameter or coordinate '{name}'")
            continue
        try:
            parse_unit(unit)
        except UnitError:
            err(
                f"units.{name}",
                f"cannot read the unit '{unit}': write products and quotients of "
                f"{', '.join(BASE)} with integer powers (kg*m^2, m/s^2, N*s/m)",
            )
    if errors:
        raise SpecError(errors)
