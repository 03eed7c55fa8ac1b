"""The scene spec: the one JSON/TOML format that declares a mechanical system.

Built-in scenes and course tools send the same document. Pydantic checks its shape (and the
generated OpenAPI schema documents it); `check_names` then checks every expression against the
names the scene declares, so an error can name the field it sits in
(``bodies[1].position[0]: unknown name 'lenght'``).
"""

from __future__ import annotations

import math
import re
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    StringConstraints,
    field_validator,
)

from mechanics.constant_mass import variable_mass_errors
from mechanics.units import BASE, UnitError, parse_unit

#: Budgets on a posted spec: a spec past them is refused before any algebra runs.
MAX_COORDINATES = 6
MAX_BODIES = 8
MAX_ITEMS = 16  # frames, points, springs, dampers, forces, torques, potentials (each)
MAX_PARAMETERS = 40
MAX_EXPR_LENGTH = 400
MAX_TEXT = 400

IDENT = r"^[A-Za-z][A-Za-z0-9_]{0,23}$"
Ident = Annotated[str, StringConstraints(pattern=IDENT)]


def _not_a_bool(value: Any) -> Any:
    """JSON true is not the number 1: pydantic's lax float took it as one, so a spec saying
    ``"mass": true`` ran with a mass of 1 and no word about it."""
    if isinstance(value, bool):
        raise ValueError("must be a number or an expression, not true or false")
    return value


#: A number: JSON true and "3" are refused (strict), an integer is a number.
Number = Annotated[float, Field(strict=True)]
#: An expression in the plain-text convention, or a number.
Expr = Annotated[
    Annotated[str, StringConstraints(max_length=MAX_EXPR_LENGTH)] | float | int,
    BeforeValidator(_not_a_bool),
]
Text = Annotated[str, StringConstraints(max_length=MAX_TEXT)]

#: Names a scene may not take for itself: they mean something in every expression.
RESERVED = frozenset(
    {"t", "pi", "N", "O"}
    | {"sin", "cos", "tan", "cot", "sec", "csc", "asin", "acos", "atan", "atan2"}
    | {"sinh", "cosh", "tanh", "exp", "log", "sqrt", "abs", "sign"}
)


class SpecError(ValueError):
    """A spec that parses as JSON but does not describe a system; carries every problem found."""

    def __init__(self, errors: list[dict[str, str]]) -> None:
        self.errors = errors
        super().__init__("; ".join(f"{e['field']}: {e['message']}" for e in errors))


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class FramePosition(_Model):
    """Components along a frame's axes, measured from the origin O or from another point."""

    frame: Ident = "N"
    components: Annotated[list[Expr], Field(min_length=2, max_length=3)]
    from_: Ident | None = Field(default=None, alias="from")

    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)


Position = Annotated[list[Expr], Field(min_length=2, max_length=3)] | FramePosition


class Frame(_Model):
    """A frame rotated from its parent about one of the parent's axes (angle may use q and t)."""

    name: Ident
    parent: Ident = "N"
    axis: Literal["x", "y", "z"]
    angle: Expr
    unit_vectors: Annotated[list[Ident], Field(min_length=3, max_length=3)] | None = None


class PointSpec(_Model):
    name: Ident
    position: Position


class Inertia(_Model):
    """Central inertia tensor in the body frame (about the centre of mass)."""

    ixx: Expr
    iyy: Expr
    izz: Expr
    ixy: Expr = 0
    iyz: Expr = 0
    izx: Expr = 0


class Body(_Model):
    name: Ident
    kind: Literal["particle", "rigid_body"] = "particle"
    mass: Expr
    position: Position
    frame: Ident | None = None
    inertia: Inertia | None = None


class Gravity(_Model):
    acceleration: Expr
    direction: Annotated[list[Number], Field(min_length=2, max_length=3)] = [0, -1, 0]

    @field_validator("direction")
    @classmethod
    def _nonzero(cls, v: list[float]) -> list[float]:
        if not all(math.isfinite(c) for c in v) or not any(v):
            raise ValueError("direction must be a finite, non-zero vector")
        return v


class Spring(_Model):
    a: Ident
    b: Ident
    k: Expr
    rest_length: Expr = 0
    name: Ident | None = None


class Damper(_Model):
    a: Ident
    b: Ident
    c: Expr
    name: Ident | None = None


class Force(_Model):
    on: Ident
    vector: Position
    name: Ident | None = None


class Potential(_Model):
    name: Ident
    expression: Expr


class Stop(_Model):
    """Where the model stops holding, so a run ends there instead of showing motion it forbids.

    ``when`` (q, q̇, t and parameters) is positive while the model holds; the run stops where it
    reaches 0 (``crossing = "any"``: where it changes sign either way, e.g. a velocity that
    reverses). ``tension`` instead names a body whose string tension must stay positive (the
    string goes slack at 0): the tension toward the point it hangs from (``from``), or, with
    ``along``, the constraint force on it along that direction (the string of an Atwood machine
    pulls straight up: ``along = [0, 1, 0]``). ``only_if``, when given, must be ≥ 0 at that
    moment for the stop to apply (static friction can hold the block: μ cos α − sin α ≥ 0).
    """

    name: Ident
    message: Text
    when: Expr | None = None
    tension: Ident | None = None
    along: Annotated[list[Number], Field(min_length=2, max_length=3)] | None = None
    crossing: Literal["falls", "any"] = "falls"
    only_if: Expr | None = None


def _items(model: type) -> Any:
    return Annotated[list[model], Field(max_length=MAX_ITEMS)]


class SceneSpec(_Model):
    """A mechanical system: coordinates, parameters, frames, points, bodies, what acts on them."""

    title: Text = "Untitled system"
    summary: Text = ""
    coordinates: Annotated[list[Ident], Field(min_length=1, max_length=MAX_COORDINATES)]
    #: Coordinates that never go negative (a radius): lets sqrt(r**2) print as r, not |r|.
    positive_coordinates: Annotated[list[Ident], Field(max_length=MAX_COORDINATES)] = []
    parameters: Annotated[dict[Ident, Number], Field(max_length=MAX_PARAMETERS)] = {}
    #: a unit per parameter or coordinate at most (a 439 kB map was a 2.3 MB error)
    units: Annotated[
        dict[Ident, Annotated[str, StringConstraints(max_length=40)]],
        Field(max_length=MAX_PARAMETERS + MAX_COORDINATES),
    ] = {}
    frames: _items(Frame) = []
    points: _items(PointSpec) = []
    bodies: Annotated[list[Body], Field(min_length=1, max_length=MAX_BODIES)]
    gravity: Gravity | None = None
    springs: _items(Spring) = []
    dampers: _items(Damper) = []
    forces: _items(Force) = []
    torques: _items(Force) = []
    potentials: _items(Potential) = []
    stops: _items(Stop) = []
    initial: Annotated[dict[str, Number], Field(max_length=2 * MAX_COORDINATES)] = {}

    @field_validator("parameters", "initial")
    @classmethod
    def _finite(cls, v: dict[str, float]) -> dict[str, float]:
        for name, value in v.items():
            if not math.isfinite(value):
                raise ValueError(f"{name} must be a finite number")
        return v


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


def parse_spec(data: Any) -> SceneSpec:
    """Validate a raw document (dict from JSON or TOML) into a SceneSpec, or raise SpecError."""
    from pydantic import ValidationError

    try:
        spec = SceneSpec.model_validate(data)
    except ValidationError as exc:
        raise SpecError(
            [{"field": field_path(e["loc"]), "message": e["msg"]} for e in exc.errors()]
        ) from None
    check_names(spec)
    return spec


_UNION_TAGS = frozenset({"float", "int", "str", "FramePosition"})


def field_path(loc: tuple[Any, ...] | list[Any]) -> str:
    """('bodies', 1, 'position', 0) -> 'bodies[1].position[0]'; skips pydantic's union tags."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif isinstance(part, str) and ("[" in part or "-" in part or part in _UNION_TAGS):
            continue  # pydantic names union branches ('list[...]', 'float'); noise to users
        else:
            out += f".{part}" if out else str(part)
    return out
