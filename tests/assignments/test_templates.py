"""Assignment templates (issue 27, item 1): read from TOML or JSON, refused with a field path,
hashed canonically so a variant can say which template it came from."""

from __future__ import annotations

import json

import pytest

from mechanics.assignments.template import (
    parse_template,
    parse_template_text,
    shipped_templates,
    template_hash,
)
from mechanics.scenes import scene_ids
from mechanics.spec import SpecError

BASE = {
    "id": "pend",
    "title": "Pendulum",
    "scene": "simple_pendulum",
    "parts": [
        {"id": "T", "quantity": "T"},
        {"id": "eom", "quantity": "eom", "coordinate": "theta"},
    ],
}


def fields_of(document) -> list[str]:
    with pytest.raises(SpecError) as caught:
        parse_template(document)
    return [e["field"] for e in caught.value.errors]


def test_shipped_templates_are_built_on_the_catalog():
    shipped = shipped_templates()
    assert len(shipped) >= 3
    for template in shipped.values():
        assert template.scene in scene_ids()
        assert template.parts


def test_toml_and_json_of_one_template_have_one_hash():
    toml = """
id = "pend"
title = "Pendulum"
scene = "simple_pendulum"
[[parts]]
id = "T"
quantity = "T"
[[parts]]
id = "eom"
quantity = "eom"
coordinate = "theta"
"""
    a = parse_template_text(toml, "toml")
    b = parse_template_text(json.dumps(BASE), "json")
    assert template_hash(a) == template_hash(b)
    assert len(template_hash(a)) == 64


def test_a_default_spelled_out_keeps_the_hash_a_changed_penalty_does_not():
    same = parse_template({**BASE, "retry_penalty": 0.1, "mode": "graded"})
    other = parse_template({**BASE, "retry_penalty": 0.2})
    assert template_hash(same) == template_hash(parse_template(BASE))
    assert template_hash(other) != template_hash(parse_template(BASE))


def test_an_unknown_scene_names_the_scene_field():
    assert fields_of({**BASE, "scene": "no_such_scene"}) == ["scene"]


def test_an_equation_of_motion_without_its_coordinate_names_the_part():
    parts = [{"id": "eom", "quantity": "eom"}]
    assert fields_of({**BASE, "parts": parts}) == ["parts[0].coordinate"]


def test_a_coordinate_the_scene_lacks_names_the_part():
    parts = [{"id": "T", "quantity": "T"}, {"id": "Q", "quantity": "Q", "coordinate": "x"}]
    assert fields_of({**BASE, "parts": parts}) == ["parts[1].coordinate"]


def test_a_parameter_the_scene_lacks_is_refused():
    document = {**BASE, "parameters": {"k": {"values": [1.0]}}}
    assert fields_of(document) == ["parameters.k"]


def test_a_range_without_a_step_is_refused():
    document = {**BASE, "parameters": {"l": {"range": [1.0, 2.0]}}}
    assert fields_of(document) == ["parameters.l"]


def test_unknown_keys_and_bad_quantities_are_refused():
    assert "quantity" in fields_of({**BASE, "parts": [{"id": "x", "quantity": "H"}]})[0]
    assert fields_of({**BASE, "colour": "red"}) == ["colour"]


def test_text_that_is_not_toml_is_refused_on_the_template_field():
    with pytest.raises(SpecError) as caught:
        parse_template_text("id = = 3")
    assert caught.value.errors[0]["field"] == "template"


def test_a_posted_scene_spec_can_stand_in_for_a_built_in_one():
    spec = {
        "coordinates": ["x"],
        "parameters": {"m": 1.0, "k": 4.0},
        "bodies": [{"name": "b", "mass": "m", "position": ["x", 0, 0]}],
        "points": [{"name": "o", "position": [0, 0, 0]}],
        "springs": [{"a": "o", "b": "b", "k": "k"}],
    }
    template = parse_template(
        {**BASE, "scene": None, "scene_spec": spec, "parts": [{"id": "V", "quantity": "V"}]}
    )
    assert template.base_spec()["springs"][0]["k"] == "k"
    bad = {**spec, "bodies": [{"name": "b", "mass": "m", "position": ["x", 0]}]}
    del bad["bodies"][0]["mass"]
    errors = fields_of(
        {**BASE, "scene": None, "scene_spec": bad, "parts": [{"id": "V", "quantity": "V"}]}
    )
    assert errors == ["scene_spec.bodies[0].mass"]
