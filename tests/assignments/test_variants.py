"""Variants from a seed (issue 27, item 2): the same seed gives the same variant on any server,
after a restart; each variant records the engine version and the template's sha256."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys

from mechanics.assignments.template import parse_template, shipped_templates, template_hash
from mechanics.assignments.variants import build_variant, deploy_seeds, substitute
from mechanics.cache import ENGINE_VERSION


def test_the_same_seed_gives_the_same_variant_in_a_fresh_process():
    """A restarted server (a new interpreter, another hash seed) builds the same variant."""
    template = shipped_templates()["damped_oscillator"]
    here = build_variant(template, "student-17").to_json()
    code = (
        "import json; from mechanics.assignments.template import shipped_templates;"
        "from mechanics.assignments.variants import build_variant;"
        "print(json.dumps(build_variant(shipped_templates()['damped_oscillator'],"
        " 'student-17').to_json(), sort_keys=True))"
    )
    env = {"PYTHONHASHSEED": "12345", "PATH": ""}
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
    )
    assert json.loads(out.stdout) == json.loads(json.dumps(here))


def test_a_choice_is_sha256_of_template_seed_and_name():
    """The documented rule, recomputed by hand: int(sha256(hash \\0 seed \\0 name)[:8]) mod n."""
    template = shipped_templates()["damped_oscillator"]
    sha = template_hash(template)
    for seed in ("1", "2", "alice", "bob"):
        variant = build_variant(template, seed)
        ks = [5.0, 10.0, 15.0, 20.0]
        digest = hashlib.sha256(f"{sha}\x00{seed}\x00parameter:k".encode()).digest()
        assert variant.parameters["k"] == ks[int.from_bytes(digest[:8], "big") % 4]
        digest = hashlib.sha256(f"{sha}\x00{seed}\x00switch:damping".encode()).digest()
        label = ["damped", "undamped"][int.from_bytes(digest[:8], "big") % 2]
        assert variant.switches["damping"] == label


def test_values_stay_on_the_grid_and_every_one_is_reached():
    template = shipped_templates()["damped_oscillator"]
    seen = {build_variant(template, str(s)).parameters["k"] for s in range(60)}
    assert seen == {5.0, 10.0, 15.0, 20.0}


def test_a_variant_records_engine_version_and_template_hash():
    template = shipped_templates()["pendulum_energies"]
    variant = build_variant(template, 3)
    assert variant.engine_version == ENGINE_VERSION
    assert variant.template_sha256 == template_hash(template)
    assert variant.seed == "3"


def test_a_given_number_is_written_into_the_scene_and_leaves_other_names_alone():
    spec = {
        "coordinates": ["x"],
        "parameters": {"m": 1.0, "m1": 2.0},
        "units": {"m": "kg", "m1": "kg"},
        "bodies": [{"name": "m", "mass": "m + m1*mm", "position": ["m*x", 0, 0]}],
    }
    out = substitute(spec, {"m": 2.5})
    assert out["bodies"][0]["mass"] == "(2.5) + m1*mm"
    assert out["bodies"][0]["position"] == ["(2.5)*x", 0, 0]
    assert out["bodies"][0]["name"] == "m"  # a name, not an expression
    assert out["parameters"] == {"m1": 2.0} and out["units"] == {"m1": "kg"}


def test_the_given_mass_reaches_the_key():
    """T of the pendulum with m given: ½ m l² θ̇² with m's number in it (hand derivation)."""
    from mechanics.assignments.keys import variant_keys

    variant = build_variant(shipped_templates()["pendulum_energies"], "9")
    m = variant.parameters["m"]
    assert "m" not in variant.spec["parameters"]
    key = variant_keys(variant).keys[0]
    import sympy as sp

    length, w = sp.symbols("l theta_dot")
    assert (
        sp.simplify(
            sp.sympify(key.plain.replace("^", "**")) - sp.nsimplify(m) * length**2 * w**2 / 2
        )
        == 0
    )


def test_a_switch_removes_the_damper():
    template = shipped_templates()["damped_oscillator"]
    by_label = {}
    for s in range(20):
        v = build_variant(template, str(s))
        by_label.setdefault(v.switches["damping"], v)
    assert set(by_label) == {"damped", "undamped"}
    assert by_label["undamped"].spec.get("dampers") == []
    assert by_label["damped"].spec["dampers"][0]["name"] == "damper"


def test_a_switch_that_breaks_the_scene_is_refused_when_built():
    import pytest

    from mechanics.spec import SpecError

    document = {
        "id": "t",
        "title": "t",
        "scene": "simple_pendulum",
        "switches": [
            {
                "name": "s",
                "options": [
                    {"label": "a", "add": {"springs": [{"a": "nowhere", "b": "bob", "k": "1"}]}}
                ],
            }
        ],
        "parts": [{"id": "T", "quantity": "T"}],
    }
    with pytest.raises(SpecError):
        build_variant(parse_template(document), "1")


def test_pinned_seeds_come_first_then_numbers():
    assert deploy_seeds(4, ["exam-A", "2"]) == ["exam-A", "2", "1", "3"]
    assert deploy_seeds(2) == ["1", "2"]
