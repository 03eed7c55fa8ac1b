"""The scene spec: the one JSON/TOML format that declares a mechanical system.

Built-in scenes and course tools send the same document. Pydantic checks its shape (and the
generated OpenAPI schema documents it); `check_names` then checks every expression against the
names the scene declares, so an error can name the field it sits in
(``bodies[1].position[0]: unknown name 'lenght'``).
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    StringConstraints,
    field_validator,
)

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

    frame: Ident = Field(
        "N",
        description=(
            'The frame whose axes the components are measured along ("N" is the fixed, inertial '
            'frame). Example: "B"'
        ),
    )
    components: Annotated[list[Expr], Field(min_length=2, max_length=3)] = Field(
        description=(
            "The position's components along the frame's x, y (and z) axes, in metres: expressions "
            'in the coordinates, parameters and t. Example: [0, "-l"]'
        )
    )
    from_: Ident | None = Field(
        default=None,
        alias="from",
        description=(
            "The point (or body) the components are measured from; the origin O when left out. "
            'Example: "cart"'
        ),
    )

    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)


Position = Annotated[list[Expr], Field(min_length=2, max_length=3)] | FramePosition


class Frame(_Model):
    """A frame rotated from its parent about one of the parent's axes (angle may use q and t)."""

    name: Ident = Field(
        description='The frame\'s name, used by positions, bodies and forces. Example: "B"'
    )
    parent: Ident = Field(
        "N",
        description='The frame it is rotated from ("N", the fixed frame, by default). Example: "N"',
    )
    axis: Literal["x", "y", "z"] = Field(
        description=(
            'The parent\'s axis it turns about: "x", "y" or "z" ("z" turns the x–y plane). '
            'Example: "z"'
        )
    )
    angle: Expr = Field(
        description=(
            "The rotation angle in radians: an expression in the coordinates, parameters and t. "
            'Example: "theta"'
        )
    )
    unit_vectors: Annotated[list[Ident], Field(min_length=3, max_length=3)] | None = Field(
        None,
        description=(
            "Names for the frame's three unit vectors in the derivation's text (optional). "
            'Example: ["e_r", "e_theta", "e_z"]'
        ),
    )


class PointSpec(_Model):
    name: Ident = Field(
        description=(
            "The point's name (a pivot, a spring's anchor, a cart's hinge). Example: \"hinge\""
        )
    )
    position: Position = Field(
        description=(
            'Where it is, in metres: [x, y] or [x, y, z] in the fixed frame, or {"frame", '
            '"components", "from"}. Example: ["x", 0]'
        )
    )


class Inertia(_Model):
    """Central inertia tensor in the body frame (about the centre of mass)."""

    ixx: Expr = Field(
        description=(
            "Moment of inertia about the body frame's x axis through the centre of mass, in kg·m². "
            'Example: "m*R**2/4"'
        )
    )
    iyy: Expr = Field(
        description=(
            "Moment of inertia about the body frame's y axis through the centre of mass, in kg·m². "
            'Example: "m*R**2/4"'
        )
    )
    izz: Expr = Field(
        description=(
            "Moment of inertia about the body frame's z axis through the centre of mass, in kg·m². "
            'Example: "m*R**2/2"'
        )
    )
    ixy: Expr = Field(0, description="Product of inertia xy, in kg·m² (0 by default). Example: 0")
    iyz: Expr = Field(0, description="Product of inertia yz, in kg·m² (0 by default). Example: 0")
    izx: Expr = Field(0, description="Product of inertia zx, in kg·m² (0 by default). Example: 0")


class Body(_Model):
    name: Ident = Field(
        description=(
            'The body\'s name (drawn beside it; springs, forces and stops name it). Example: "bob"'
        )
    )
    kind: Literal["particle", "rigid_body"] = Field(
        "particle",
        description=(
            '"particle" (a point mass) or "rigid_body" (with a frame and an inertia). Example: '
            '"particle"'
        ),
    )
    mass: Expr = Field(
        description=(
            'Its mass in kg: a number or a parameter\'s name (constant in time). Example: "m"'
        )
    )
    position: Position = Field(
        description=(
            "Where its centre of mass is, in metres: [x, y] or [x, y, z] in the fixed frame (y "
            'up), or {"frame", "components", "from"}. Example: ["l*sin(theta)", "-l*cos(theta)"]'
        )
    )
    frame: Ident | None = Field(
        None,
        description=(
            'A rigid body\'s own frame (one of "frames"), which turns with it. Example: "B"'
        ),
    )
    inertia: Inertia | None = Field(
        None,
        description=(
            'A rigid body\'s central inertia in its frame, in kg·m²: {"ixx", "iyy", "izz", ...}. '
            'Example: {"ixx": 0, "iyy": 0, "izz": "m*R**2/2"}'
        ),
    )


class Gravity(_Model):
    acceleration: Expr = Field(
        description=(
            'The acceleration of gravity in m/s²: a number or a parameter\'s name. Example: "g"'
        )
    )
    direction: Annotated[list[Number], Field(min_length=2, max_length=3)] = Field(
        [0, -1, 0],
        description=(
            "Which way gravity pulls, as a vector in the fixed frame ([0, -1, 0], down, by "
            "default). Example: [0, -1, 0]"
        ),
    )

    @field_validator("direction")
    @classmethod
    def _nonzero(cls, v: list[float]) -> list[float]:
        if not all(math.isfinite(c) for c in v) or not any(v):
            raise ValueError("direction must be a finite, non-zero vector")
        return v


class Spring(_Model):
    a: Ident = Field(description='One end: a point or a body (O is the origin). Example: "O"')
    b: Ident = Field(description='The other end: a point or a body. Example: "bob"')
    k: Expr = Field(description='Its stiffness in N/m. Example: "k"')
    rest_length: Expr = Field(
        0, description='Its natural length in metres (0 by default). Example: "l0"'
    )
    name: Ident | None = Field(
        None, description='A name for it in the derivation\'s text (optional). Example: "spring"'
    )


class Damper(_Model):
    a: Ident = Field(description='One end: a point or a body. Example: "O"')
    b: Ident = Field(description='The other end: a point or a body. Example: "block"')
    c: Expr = Field(
        description='Its damping coefficient in N·s/m (force = c × relative speed). Example: "c"'
    )
    name: Ident | None = Field(
        None, description='A name for it in the derivation\'s text (optional). Example: "dashpot"'
    )


class Force(_Model):
    on: Ident = Field(description='The body (or point) it acts on. Example: "block"')
    vector: Position = Field(
        description=(
            "The force in N (a torque: N·m), as [x, y] or [x, y, z] in the fixed frame, or "
            '{"frame", "components"}: expressions in q, q̇, t and parameters. Example: '
            '["F0*cos(w*t)", 0]'
        )
    )
    name: Ident | None = Field(
        None, description='A name for it in the derivation\'s text (optional). Example: "drive"'
    )


class Potential(_Model):
    name: Ident = Field(
        description='A name for the potential energy in the derivation. Example: "V_grav"'
    )
    expression: Expr = Field(
        description=(
            "The potential energy in J: an expression in the coordinates and parameters. Example: "
            '"-G*M*m/r"'
        )
    )


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

    name: Ident = Field(description='The stop\'s name. Example: "slack"')
    message: Text = Field(
        description='What the page says when the run stops there. Example: "the string goes slack"'
    )
    when: Expr | None = Field(
        None,
        description=(
            "An expression that is positive while the model holds; the run stops where it reaches "
            '0. Example: "r"'
        ),
    )
    tension: Ident | None = Field(
        None,
        description=(
            "A body whose string tension must stay positive (the run stops where the string goes "
            'slack). Example: "bob"'
        ),
    )
    along: Annotated[list[Number], Field(min_length=2, max_length=3)] | None = Field(
        None,
        description=(
            "With tension: the direction of the constraint force on that body that must stay "
            "positive. Example: [0, 1, 0]"
        ),
    )
    crossing: Literal["falls", "any"] = Field(
        "falls",
        description=(
            '"falls" (stop where when falls through 0, the default) or "any" (either way). '
            'Example: "falls"'
        ),
    )
    only_if: Expr | None = Field(
        None,
        description=(
            'When given, the stop applies only where this is ≥ 0. Example: "mu*cos(alpha) - '
            'sin(alpha)"'
        ),
    )


def _items(model: type) -> Any:
    return Annotated[list[model], Field(max_length=MAX_ITEMS)]


class SceneSpec(_Model):
    """A mechanical system: coordinates, parameters, frames, points, bodies, what acts on them."""

    title: Text = Field(
        "Untitled system",
        description="The system's name, shown as the page's title. Example: \"Pendulum on a cart\"",
    )
    summary: Text = Field(
        "",
        description=(
            'One sentence under the title. Example: "A bob hanging from a cart on a spring."'
        ),
    )
    coordinates: Annotated[list[Ident], Field(min_length=1, max_length=MAX_COORDINATES)] = Field(
        description=(
            "The generalized coordinates q_j, one name each (angles in rad, lengths in m); their "
            'rates are name_dot. Example: ["x", "theta"]'
        )
    )
    #: Coordinates that never go negative (a radius): lets sqrt(r**2) print as r, not |r|.
    positive_coordinates: Annotated[list[Ident], Field(max_length=MAX_COORDINATES)] = Field(
        [],
        description=(
            "Coordinates that never go negative (a radius), so sqrt(r**2) prints as r. Example: "
            '["r"]'
        ),
    )
    parameters: Annotated[dict[Ident, Number], Field(max_length=MAX_PARAMETERS)] = Field(
        {},
        description=(
            "The constants, each a name and its value in SI units (kg, m, s, N/m, ...). Example: "
            '{"m": 1.0, "l": 1.0, "g": 9.81}'
        ),
    )
    #: a unit per parameter or coordinate at most (a 439 kB map was a 2.3 MB error)
    units: Annotated[
        dict[Ident, Annotated[str, StringConstraints(max_length=40)]],
        Field(max_length=MAX_PARAMETERS + MAX_COORDINATES),
    ] = Field(
        {},
        description=(
            "A unit for each parameter or coordinate, for the labels (kg, m, rad, N/m, m/s^2). "
            'Example: {"m": "kg", "theta": "rad"}'
        ),
    )
    frames: _items(Frame) = Field(
        [],
        description=(
            'Rotated frames: {"name", "parent", "axis", "angle"}, for rigid bodies and positions '
            'given in a turning frame. Example: [{"name": "B", "axis": "z", "angle": "phi"}]'
        ),
    )
    points: _items(PointSpec) = Field(
        [],
        description=(
            'Named massless points (pivots, anchors, hinges): {"name", "position"}. Example: '
            '[{"name": "hinge", "position": ["x", 0]}]'
        ),
    )
    bodies: Annotated[list[Body], Field(min_length=1, max_length=MAX_BODIES)] = Field(
        description=(
            'The masses: {"name", "kind", "mass", "position"} (rigid bodies also "frame" and '
            '"inertia"). Example: [{"name": "bob", "mass": "m", "position": ["l*sin(theta)", '
            '"-l*cos(theta)"]}]'
        )
    )
    gravity: Gravity | None = Field(
        None,
        description=(
            'Uniform gravity: {"acceleration", "direction"}; left out, there is none. Example: '
            '{"acceleration": "g"}'
        ),
    )
    springs: _items(Spring) = Field(
        [],
        description=(
            'Linear springs between two points or bodies: {"a", "b", "k", "rest_length"}. Example: '
            '[{"a": "O", "b": "cart", "k": "k", "rest_length": "L0"}]'
        ),
    )
    dampers: _items(Damper) = Field(
        [],
        description=(
            'Linear dampers between two points or bodies: {"a", "b", "c"}. Example: [{"a": "O", '
            '"b": "cart", "c": "c"}]'
        ),
    )
    forces: _items(Force) = Field(
        [],
        description=(
            'Applied (non-conservative) forces on a body, in N: {"on", "vector"}. Example: [{"on": '
            '"cart", "vector": ["F0*cos(w*t)", 0]}]'
        ),
    )
    torques: _items(Force) = Field(
        [],
        description=(
            'Applied torques on a rigid body, in N·m: {"on", "vector"}. Example: [{"on": "disk", '
            '"vector": [0, 0, "tau"]}]'
        ),
    )
    potentials: _items(Potential) = Field(
        [],
        description=(
            'Extra potential energies, in J: {"name", "expression"}. Example: [{"name": "V_g", '
            '"expression": "-G*M*m/r"}]'
        ),
    )
    stops: _items(Stop) = Field(
        [],
        description=(
            "Where the model stops holding (a string going slack, a bead leaving its rod): "
            '{"name", "message", "when"}. Example: [{"name": "out", "message": "the bead leaves '
            'the rod", "when": "L - r"}]'
        ),
    )
    initial: Annotated[dict[str, Number], Field(max_length=2 * MAX_COORDINATES)] = Field(
        {},
        description=(
            "The starting state: each coordinate and its rate (name_dot), in SI units (rad, m, "
            'rad/s, m/s). Example: {"theta": 0.5, "theta_dot": 0}'
        ),
    )

    @field_validator("parameters", "initial")
    @classmethod
    def _finite(cls, v: dict[str, float]) -> dict[str, float]:
        for name, value in v.items():
            if not math.isfinite(value):
                raise ValueError(f"{name} must be a finite number")
        return v


def parse_spec(data: Any) -> SceneSpec:
    """Validate a raw document (dict from JSON or TOML) into a SceneSpec, or raise SpecError."""
    from pydantic import ValidationError

    try:
        spec = SceneSpec.model_validate(data)
    except ValidationError as exc:
        raise SpecError(
            [{"field": field_path(e["loc"]), "message": e["msg"]} for e in exc.errors()]
        ) from None
    from mechanics.spec_names import check_names  # it reads the models above

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
