"""A template's variant from a seed: the same seed gives the same variant on any server, after a
restart, in any Python, because every choice is read from sha256(template hash, seed, name), not
from a random generator whose stream could change between versions.

A variant records the engine version and the template's hash: a regrade years later can tell
whether the key it checks against is still the one the student saw (mechanics/assignments/
grading.py compares them).
"""

from __future__ import annotations

import hashlib
import json
import re
from dataclasses import asdict, dataclass
from typing import Any

from mechanics.cache import ENGINE_VERSION
from mechanics.spec import parse_spec

from .template import Template, canonical, template_hash

#: Spec fields that hold expressions: a given parameter's number is written into these only.
EXPRESSION_KEYS = frozenset(
    {"mass", "position", "components", "k", "rest_length", "c", "vector", "expression"}
    | {"acceleration", "angle", "ixx", "iyy", "izz", "ixy", "iyz", "izx", "when", "only_if"}
)
MAX_SEED_LENGTH = 200


@dataclass(frozen=True)
class Variant:
    """One student's (or one printed exam's) version of a template."""

    template_id: str
    template_sha256: str
    engine_version: int
    seed: str
    parameters: dict[str, float]
    switches: dict[str, str]
    spec: dict[str, Any]
    parts: list[dict[str, Any]]

    @property
    def id(self) -> str:
        """A short name of this variant's content (template hash + seed say it already)."""
        text = f"{self.template_sha256}\x00{self.seed}"
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def to_json(self) -> dict[str, Any]:
        return {"id": self.id, **asdict(self)}

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Variant:
        fields = {k: v for k, v in data.items() if k != "id"}
        return cls(**fields)

    def spec_text(self) -> str:
        """The variant's scene as canonical JSON (mechanics.derive's cache key)."""
        return json.dumps(self.spec, sort_keys=True, separators=(",", ":"))


def pick(template_sha: str, seed: str, name: str, count: int) -> int:
    """An index in [0, count) fixed by (template, seed, name): sha256, read as an integer."""
    digest = hashlib.sha256(f"{template_sha}\x00{seed}\x00{name}".encode()).digest()
    return int.from_bytes(digest[:8], "big") % count


def _number(value: float) -> str:
    """A readable exact decimal: 2.0 -> '2', 0.25 -> '0.25' (the checker reads decimals exactly)."""
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def substitute(spec: dict[str, Any], values: dict[str, float]) -> dict[str, Any]:
    """The spec with each named parameter written into its expressions as a number, and dropped
    from ``parameters`` and ``units``: the student then sees and writes 2.5, not m."""
    if not values:
        return spec
    pattern = re.compile(
        r"(?<![A-Za-z0-9_])(" + "|".join(map(re.escape, values)) + r")(?![A-Za-z0-9_])"
    )

    def in_expr(value: Any) -> Any:
        if isinstance(value, str):
            return pattern.sub(lambda m: f"({_number(values[m.group(1)])})", value)
        if isinstance(value, list):
            return [in_expr(v) for v in value]
        if isinstance(value, dict):
            return {k: in_expr(v) if k == "components" else walk(v, k) for k, v in value.items()}
        return value

    def walk(value: Any, key: str | None = None) -> Any:
        if key in EXPRESSION_KEYS:
            return in_expr(value)
        if isinstance(value, dict):
            return {k: walk(v, k) for k, v in value.items()}
        if isinstance(value, list):
            return [walk(v) for v in value]
        return value

    out = walk(spec)
    for table in ("parameters", "units"):
        out[table] = {k: v for k, v in out.get(table, {}).items() if k not in values}
    return out


def _apply_option(spec: dict[str, Any], option: Any) -> None:
    for table, names in option.remove.items():
        spec[table] = [item for item in spec.get(table, []) if item.get("name") not in names]
    for table, items in option.add.items():
        spec[table] = list(spec.get(table, [])) + json.loads(json.dumps(items))
    spec["parameters"] = {**spec.get("parameters", {}), **option.parameters}


def build_variant(template: Template, seed: str | int) -> Variant:
    """The variant of ``template`` for ``seed``; raises SpecError if a switch's option makes a
    spec that does not parse (the template's author is told which field)."""
    seed = str(seed)[:MAX_SEED_LENGTH]
    sha = template_hash(template)
    spec = template.base_spec()
    switches = {}
    for switch in template.switches:
        option = switch.options[pick(sha, seed, f"switch:{switch.name}", len(switch.options))]
        switches[switch.name] = option.label
        _apply_option(spec, option)
    values = {}
    for name, rng in template.parameters.items():
        choices = rng.choices()
        values[name] = choices[pick(sha, seed, f"parameter:{name}", len(choices))]
    spec["parameters"] = {**spec.get("parameters", {}), **values}
    given = {n: v for n, v in values.items() if template.parameters[n].given}
    spec = substitute(spec, given)
    parse_spec(spec)  # a switch that breaks the scene is the template's error, said here
    parts = [p.model_dump(mode="json") for p in template.parts]
    return Variant(template.id, sha, ENGINE_VERSION, seed, values, switches, spec, parts)


def deploy_seeds(count: int, pinned: list[str] | None = None) -> list[str]:
    """The seeds of a deployment: the pinned ones (printed exams), then "1", "2", ... up to
    ``count`` variants in all."""
    seeds = list(dict.fromkeys(pinned or []))
    n = 1
    while len(seeds) < count:
        if str(n) not in seeds:
            seeds.append(str(n))
        n += 1
    return seeds


def variant_fingerprint(variant: Variant) -> str:
    """sha256 of everything a student's variant is (spec and parts): two servers that built the
    same seed agree on it (tests/assignments/test_variants.py)."""
    body = {"spec": variant.spec, "parts": variant.parts, "parameters": variant.parameters}
    return hashlib.sha256(canonical(body).encode()).hexdigest()
