"""An assignment template: a scene, the numbers and switches that vary, the parts asked.

A template is data, like a scene (STYLE.md, "A scene is data"): a small TOML or JSON document an
instructor writes or a course tool posts. Its canonical JSON's sha256 (`template_hash`) is stored
with every variant built from it, so a later regrade knows it uses the same template.

    id = "pendulum_energies"
    title = "Simple pendulum: energies and the equation of motion"
    scene = "simple_pendulum"            # a built-in scene id, or [scene_spec] a whole spec
    mode = "graded"                      # or "practice": the whole derivation is shown
    retry_penalty = 0.1                  # each retry after the first costs 10 % of the part
    max_attempts = 3                     # 0: unlimited
    [parameters.l]
    range = [0.5, 2.0]
    step = 0.25                          # or: values = [0.5, 1.0, 1.5]
    [[switches]]
    name = "damper"
    options = [{ label = "none" }, { label = "damper", add = { dampers = [...] } }]
    [[parts]]
    id = "T"
    quantity = "T"
    weight = 1
"""

from __future__ import annotations

import hashlib
import json
import math
import tomllib
from decimal import Decimal
from functools import lru_cache
from importlib import resources
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from mechanics.scenes import load_scene
from mechanics.spec import IDENT, SpecError, field_path, parse_spec

Ident = Annotated[str, Field(pattern=IDENT)]
#: The checker's quantities (mechanics/check.py QUANTITIES) a part may ask for.
QUANTITIES = ("T", "V", "L", "Q", "eom", "accel", "momentum", "equilibrium", "frequency")
PER_COORDINATE = frozenset({"Q", "eom", "accel", "momentum"})
#: Most values one parameter range may offer: a range past it needs a coarser step.
MAX_VALUES = 1000
MAX_PARTS = 12
MAX_SWITCHES = 6


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class ParameterRange(_Model):
    """Where a parameter's value is drawn from: ``values``, or ``range`` stepped by ``step``
    (so the numbers stay readable: 0.5, 0.75, 1.0, not 0.7316...)."""

    values: list[float] | None = None
    range: Annotated[list[float], Field(min_length=2, max_length=2)] | None = None
    step: float | None = None
    #: True: the number is written into the scene (the student's answer has 2.5, not m);
    #: False: the parameter stays a symbol, and its value is what the checker samples near.
    given: bool = False

    @model_validator(mode="after")
    def _one_source(self) -> ParameterRange:
        if (self.values is None) == (self.range is None):
            raise ValueError("give either values = [...] or range = [low, high] with a step")
        if self.values is not None and not self.values:
            raise ValueError("values must not be empty")
        if self.range is not None:
            low, high = self.range
            if self.step is None or not self.step > 0 or not math.isfinite(self.step):
                raise ValueError("a range needs a positive step")
            if not (math.isfinite(low) and math.isfinite(high) and low <= high):
                raise ValueError("range must be [low, high] with low <= high")
            if (high - low) / self.step + 1 > MAX_VALUES:
                raise ValueError(f"range / step gives more than {MAX_VALUES} values")
        return self

    def choices(self) -> list[float]:
        """Every value this range can give, in order, each rounded to the step's decimals."""
        if self.values is not None:
            return list(self.values)
        low, high = self.range  # type: ignore[misc]
        step = Decimal(repr(self.step))
        count = int((Decimal(repr(high)) - Decimal(repr(low))) / step) + 1
        return [float(Decimal(repr(low)) + i * step) for i in range(count)]


class SwitchOption(_Model):
    """One structural option: items appended to the spec's lists (``add``), items dropped by
    name (``remove``), parameters added (``parameters``)."""

    label: Ident
    add: dict[str, list[dict[str, Any]]] = {}
    remove: dict[str, list[str]] = {}
    parameters: dict[Ident, float] = {}


class Switch(_Model):
    name: Ident
    options: Annotated[list[SwitchOption], Field(min_length=1, max_length=8)]


class Part(_Model):
    """One question: a quantity the checker judges, its weight and any partial credit by
    outcome code (``partial = { "L.up_to_total_derivative" = 0.5 }``)."""

    id: Ident
    quantity: Literal["T", "V", "L", "Q", "eom", "accel", "momentum", "equilibrium", "frequency"]
    coordinate: Ident | None = None
    #: equilibrium / frequency: the equilibrium asked is the one nearest this value of q (several
    #: coordinates: every coordinate at this value)
    near: float | None = None
    #: frequency of a scene with several coordinates: which normal mode (1: the slowest)
    mode: int = Field(default=1, ge=1, le=3)
    weight: float = Field(default=1.0, gt=0, le=100)
    prompt: str = Field(default="", max_length=400)
    partial: dict[str, Annotated[float, Field(ge=0, le=1)]] = {}


class Template(_Model):
    id: Ident
    title: str = Field(max_length=200)
    scene: Ident | None = None
    scene_spec: dict[str, Any] | None = None
    mode: Literal["graded", "practice"] = "graded"
    retry_penalty: float = Field(default=0.1, ge=0, le=1)
    max_attempts: int = Field(default=0, ge=0, le=100)
    parameters: dict[Ident, ParameterRange] = {}
    switches: Annotated[list[Switch], Field(max_length=MAX_SWITCHES)] = []
    parts: Annotated[list[Part], Field(min_length=1, max_length=MAX_PARTS)]

    @model_validator(mode="after")
    def _one_scene(self) -> Template:
        if (self.scene is None) == (self.scene_spec is None):
            raise ValueError("give either scene = '<built-in id>' or a [scene_spec] table")
        ids = [p.id for p in self.parts]
        if len(set(ids)) != len(ids):
            raise ValueError("part ids must be unique")
        return self

    def base_spec(self) -> dict[str, Any]:
        """The scene document every variant starts from (a fresh copy)."""
        if self.scene_spec is not None:
            return json.loads(json.dumps(self.scene_spec))
        return load_scene(self.scene)  # type: ignore[arg-type]


def canonical(document: dict[str, Any]) -> str:
    """A template as canonical JSON text: equal templates, equal text, equal hash."""
    return json.dumps(document, sort_keys=True, separators=(",", ":"), ensure_ascii=False)


def template_hash(template: Template) -> str:
    """sha256 of the template's canonical JSON (defaults left out, so spelling one out does
    not change the hash)."""
    document = template.model_dump(mode="json", exclude_defaults=True)
    return hashlib.sha256(canonical(document).encode()).hexdigest()


def parse_template(data: dict[str, Any]) -> Template:
    """Validate a template document, its scene and its parts' coordinates; raise SpecError with
    field paths (``parts[1].coordinate``) for anything wrong."""
    try:
        template = Template.model_validate(data)
    except ValidationError as exc:
        errors = [
            {"field": field_path(e["loc"]) or "template", "message": e["msg"]} for e in exc.errors()
        ]
        raise SpecError(errors) from None
    try:
        spec = parse_spec(template.base_spec())
    except KeyError:
        raise SpecError(
            [{"field": "scene", "message": f"unknown scene '{template.scene}'"}]
        ) from None
    except SpecError as exc:
        raise SpecError([{**e, "field": f"scene_spec.{e['field']}"} for e in exc.errors]) from None
    errors = []
    for i, part in enumerate(template.parts):
        limit = 1 if part.quantity == "equilibrium" else 3
        if part.quantity in ("equilibrium", "frequency") and len(spec.coordinates) > limit:
            errors.append(
                {
                    "field": f"parts[{i}].quantity",
                    "message": f"{part.quantity} parts need a scene with at most {limit} "
                    "coordinate(s)",
                }
            )
    for name in template.parameters:
        if name not in spec.parameters:
            errors.append(
                {"field": f"parameters.{name}", "message": "not a parameter of the scene"}
            )
    for i, part in enumerate(template.parts):
        if part.quantity in PER_COORDINATE and part.coordinate not in spec.coordinates:
            errors.append(
                {
                    "field": f"parts[{i}].coordinate",
                    "message": f"one of {', '.join(spec.coordinates)} is needed",
                }
            )
        if part.quantity in ("equilibrium", "frequency"):
            continue
        if part.quantity not in PER_COORDINATE and part.coordinate is not None:
            errors.append(
                {
                    "field": f"parts[{i}].coordinate",
                    "message": f"{part.quantity} is not asked per coordinate",
                }
            )
    if errors:
        raise SpecError(errors)
    return template


def parse_template_text(text: str, fmt: Literal["toml", "json"] = "toml") -> Template:
    """A template from TOML or JSON text; unreadable text is a SpecError on field 'template'."""
    try:
        data = tomllib.loads(text) if fmt == "toml" else json.loads(text)
    except (tomllib.TOMLDecodeError, json.JSONDecodeError) as exc:
        raise SpecError(
            [{"field": "template", "message": f"not valid {fmt.upper()}: {exc}"}]
        ) from None
    if not isinstance(data, dict):
        raise SpecError([{"field": "template", "message": "must be a table / object"}])
    return parse_template(data)


@lru_cache(maxsize=1)
def shipped_templates() -> dict[str, Template]:
    """The templates shipped in mechanics/assignments/templates/, by id."""
    folder = resources.files(__package__) / "templates"
    out = {}
    for entry in sorted(folder.iterdir(), key=lambda e: e.name):
        if entry.name.endswith(".toml"):
            template = parse_template_text(entry.read_text(encoding="utf-8"))
            out[template.id] = template
    return out
