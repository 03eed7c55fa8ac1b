"""Where every term comes from (mechanics/provenance.py): on every built-in scene and a few posted
specs, the traced terms add back up to the displayed equations exactly, each term's sources add
up to the term, and hand-derived cases (the Coriolis term of polar coordinates, the double
pendulum's coupling) are traced to the origins a textbook names.

The sums are rebuilt from the JSON's plain text (what a course tool receives), read back through
the app's whitelist parser, so the check covers the printed forms, not only the engine's memory.
"""

from __future__ import annotations

import pytest
import sympy as sp
from beyond.systems import SYSTEMS
from sympy.physics.vector import dynamicsymbols

from mechanics.derive import derivation_of_scene, derive_model
from mechanics.expr import parse
from mechanics.model import symbols_for
from mechanics.provenance import MAX_TERMS, TOO_LARGE, is_zero, provenance_json
from mechanics.scenes import scene_ids

POSTED = [
    "triple_pendulum",
    "heavy_symmetric_top",
    "turntable_isotropic",
    "dashpot_two_masses_plane",
    "drag_projectile",
    "block_on_moving_wedge",
    "lorentz_positive_charge",
    "pendulum_horizontally_driven_pivot",
    "double_atwood",
]


def reader(derivation):
    names = symbols_for(derivation.model.spec)[2]
    return lambda text: parse(text, names, field="provenance")


def equations(derivation, prov):
    """(label, traced equation, what it must add up to) for every equation in the provenance."""
    w, names = derivation.work, derivation.model.coordinate_names
    out = [("T", prov["T"], w.T), ("V", prov["V"], w.V)]
    for j, n in enumerate(names):
        out.append((f"Q_{n}", prov["Q"][n], w.Q[j]))
        out.append((f"EoM {n} lhs", prov["eom"][n]["lhs"], w.eom_lhs[j]))
        out.append((f"EoM {n} rhs", prov["eom"][n]["rhs"], w.Q[j]))
    return out


def check_sums(derivation) -> dict:
    prov = provenance_json(derivation)
    read = reader(derivation)
    for label, eq, displayed in equations(derivation, prov):
        assert eq["traced"], label
        total = sp.Add(*(read(t["plain"]) for t in eq["terms"]))
        assert is_zero(total - displayed), f"{label}: the terms do not add up to the equation"
        for t in eq["terms"]:
            parts = sp.Add(*(read(s["contribution_plain"]) for s in t["sources"]))
            assert t["sources"], f"{label}: {t['plain']} has no origin"
            assert is_zero(parts - read(t["plain"])), f"{label}: sources of {t['plain']}"
        for c in eq["cancelled"]:
            rest = sp.Add(*(read(s["contribution_plain"]) for s in c["sources"]))
            assert is_zero(rest), f"{label}: the cancelled pieces do not cancel"
    # Every EoM of the whole equation: Σ lhs terms − Σ rhs terms = eom_lhs − Q.
    for j, n in enumerate(derivation.model.coordinate_names):
        eom = prov["eom"][n]
        whole = sp.Add(*(read(t["plain"]) for t in eom["lhs"]["terms"]))
        whole -= sp.Add(*(read(t["plain"]) for t in eom["rhs"]["terms"]))
        assert is_zero(whole - (derivation.work.eom_lhs[j] - derivation.work.Q[j])), n
        # M q̈ = f by term ids: the q̈_k terms over q̈_k are M_jk; f_j = Σ plus − Σ minus.
        lhs = {t["id"]: read(t["plain"]) for t in eom["lhs"]["terms"]}
        rhs = {t["id"]: read(t["plain"]) for t in eom["rhs"]["terms"]}
        for k, ids in enumerate(prov["matrix"]["M"][j]):
            qdd = derivation.model.qdd[k]
            entry = sp.Add(*(lhs[i] for i in ids)) / qdd
            assert is_zero(entry - derivation.work.mass_matrix[j, k]), (n, k)
        f = prov["matrix"]["f"][j]
        forcing = sp.Add(*(rhs[i] for i in f["plus"])) - sp.Add(*(lhs[i] for i in f["minus"]))
        assert is_zero(forcing - derivation.work.forcing[j]), n
        listed = {i for ids in prov["matrix"]["M"][j] for i in ids} | set(f["minus"])
        assert listed == set(lhs), n  # every left-side term is in M or in f
    return prov


@pytest.mark.parametrize("scene_id", scene_ids())
def test_terms_add_up_on_every_built_in_scene(scene_id):
    check_sums(derivation_of_scene(scene_id))


@pytest.mark.parametrize("sid", POSTED)
def test_terms_add_up_on_posted_specs(sid):
    check_sums(derive_model(SYSTEMS[sid].spec))


def find(eq, expected, read):
    hits = [t for t in eq["terms"] if is_zero(read(t["plain"]) - expected)]
    assert len(hits) == 1, [t["plain"] for t in eq["terms"]]
    return hits[0]


def test_coriolis_term_comes_from_the_e_theta_component_through_d_dt():
    """Polar coordinates by hand: v = ṙ ê_r + r θ̇ ê_θ, so T has ½ m (r θ̇)² from ê_θ, and
    d/dt ∂/∂θ̇ (½ m r² θ̇²) = m r² θ̈ + 2 m r ṙ θ̇: the Coriolis term is that piece alone."""
    d = derivation_of_scene("central_force")
    prov = provenance_json(d)
    read = reader(d)
    r, th = dynamicsymbols("r", positive=True), dynamicsymbols("theta")
    m = sp.Symbol("m", nonnegative=True)
    t = sp.Symbol("t")
    coriolis = 2 * m * r * r.diff(t) * th.diff(t)
    term = find(prov["eom"]["theta"]["lhs"], read("2*m*r*r_dot*theta_dot"), read)
    assert is_zero(read(term["plain"]) - coriolis.subs(t, dynamicsymbols._t))
    [source] = term["sources"]
    origin = prov["origins"][source["origin"]]
    assert source["kind"] == origin["kind"] == "kinetic" and source["body"] == "planet"
    assert source["piece"] == "d/dt ∂T/∂q̇"
    assert origin["frame"] == "P" and origin["motion"] == "translational"
    assert [c["unit"] for c in origin["components"]] == ["e_theta"]
    # ... and it came through T's term ½ m r² θ̇², itself from the ê_θ component alone.
    t_term = find(prov["T"], read("m*r**2*theta_dot**2/2"), read)
    assert source["via"] == t_term["id"]
    assert [s["origin"] for s in t_term["sources"]] == [source["origin"]]
    # The centripetal term −m r θ̇² is the −∂T/∂r piece of the same component.
    [cent] = find(prov["eom"]["r"]["lhs"], read("-m*r*theta_dot**2"), read)["sources"]
    assert cent["piece"] == "−∂T/∂q" and cent["origin"] == source["origin"]


def test_double_pendulum_coupling_is_the_dot_product_of_both_links():
    """r₂ = r₁ + l₂(sin θ₂, −cos θ₂): v₂·v₂ has the cross term 2 v₁·v_link, and
    m₂ v₁·v_link = m₂ l₁ l₂ cos(θ₁ − θ₂) θ̇₁ θ̇₂ by hand."""
    d = derivation_of_scene("double_pendulum")
    prov = provenance_json(d)
    read = reader(d)
    th1, th2 = read("theta1"), read("theta2")
    m2, l1, l2 = read("m2"), read("l1"), read("l2")
    tt = dynamicsymbols._t
    coupling = m2 * l1 * l2 * sp.cos(th1 - th2) * th1.diff(tt) * th2.diff(tt)
    term = find(prov["T"], coupling, read)
    [source] = term["sources"]
    origin = prov["origins"][source["origin"]]
    assert source["body"] == "bob2" and origin["motion"] == "translational"
    assert [(c["link"], c["from"]) for c in origin["components"]] == [
        ("bob1", "O"),
        ("bob2", "bob1"),
    ]
    # Both bobs' weights feed θ₁'s gravity term g l₁ (m₁ + m₂) sin θ₁, one share each.
    g = read("g")
    gravity = find(prov["eom"]["theta1"]["lhs"], g * l1 * (read("m1") + m2) * sp.sin(th1), read)
    weights = [prov["origins"][s["origin"]] for s in gravity["sources"]]
    assert sorted((w["source"], w["name"]) for w in weights) == [
        ("weight", "bob1"),
        ("weight", "bob2"),
    ]
    assert {s["piece"] for s in gravity["sources"]} == {"∂V/∂q"}


def test_same_term_same_id_across_equations():
    """Q_x of the damped oscillator is the EoM's right side: the very same terms and ids."""
    d = derivation_of_scene("spring_mass_damper")
    prov = provenance_json(d)
    name = d.model.coordinate_names[0]
    ids_q = sorted(t["id"] for t in prov["Q"][name]["terms"])
    ids_rhs = sorted(t["id"] for t in prov["eom"][name]["rhs"]["terms"])
    assert ids_q == ids_rhs and len(ids_q) == 2
    origins = [prov["origins"][s["origin"]] for t in prov["Q"][name]["terms"] for s in t["sources"]]
    assert {o["kind"] for o in origins} == {"generalized force"}
    assert sorted(o["source"] for o in origins) == ["damper", "force"]


def test_too_many_terms_says_so(monkeypatch):
    import mechanics.provenance as pv

    monkeypatch.setattr(pv, "MAX_TERMS", 1)
    prov = provenance_json(derivation_of_scene("central_force"))
    assert prov["T"] == {"traced": False, "reason": TOO_LARGE, "terms": [], "cancelled": []}
    assert MAX_TERMS >= 100


def test_equations_of_motion_past_the_budget_say_so(monkeypatch):
    """Past MAX_CONTRIBUTIONS the EoMs are not traced (a six-link chain would double its derive
    time); T, V and Q_j still are."""
    import mechanics.provenance as pv

    monkeypatch.setattr(pv, "MAX_CONTRIBUTIONS", 10)
    prov = provenance_json(derivation_of_scene("double_pendulum"))
    assert prov["T"]["traced"] and prov["V"]["traced"]
    for eom in prov["eom"].values():
        assert eom["lhs"] == {"traced": False, "reason": TOO_LARGE, "terms": [], "cancelled": []}


@pytest.mark.parametrize("scene_id", ["spring_mass_damper", "physical_pendulum", "central_force"])
def test_the_json_has_the_documented_shape(scene_id):
    """The documented model (app/provenance_schema.py) reads the JSON without losing a key."""
    from app.provenance_schema import Provenance

    prov = provenance_json(derivation_of_scene(scene_id))
    parsed = Provenance.model_validate(prov).model_dump(exclude_none=True)
    assert set(parsed) == set(prov)
    for n, eom in prov["eom"].items():
        for side in ("lhs", "rhs"):
            for term, dumped in zip(
                eom[side]["terms"], parsed["eom"][n][side]["terms"], strict=True
            ):
                assert dumped["sources"] == term["sources"]


def test_the_json_is_the_same_in_another_process():
    """A derivation is a function of its spec (the cache shares it between processes): the
    provenance must not depend on the hash seed (sets of sympy expressions iterate by hash)."""
    import json
    import os
    import subprocess
    import sys

    code = (
        "import json; from mechanics.derive import derivation_of_scene; "
        "from mechanics.provenance import provenance_json; "
        "print(json.dumps(provenance_json(derivation_of_scene('double_pendulum')), sort_keys=True))"
    )
    outputs = set()
    for seed in ("1", "2"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        run = subprocess.run(
            [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
        )
        outputs.add(run.stdout)
    assert len(outputs) == 1
    mine = json.dumps(provenance_json(derivation_of_scene("double_pendulum")), sort_keys=True)
    assert outputs == {mine + "\n"}
