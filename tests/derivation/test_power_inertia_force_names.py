"""Three engine trust leftovers: a zero power that has |·| or sgn in it, a mass or inertia that
depends on the coordinates (refused since issue 23, item 6), and /newton's forces by name.

1. A force c (sgn(ẋ)|ẋ| − ẋ) is 0 for every real ẋ, yet sympy cannot simplify it: the conserved
   step said it did work and left E off. The zero test must stay sound (a power that is not 0,
   even only on ẋ = ẏ, is never called 0): each verdict is checked against F·v evaluated by
   numpy at random states and on every kink (ẋ = 0, ẋ = ẏ, …), F·v written by hand from the
   spec's strings, not the engine's Q_j.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from mechanics.derive import derive_model
from mechanics.equilibria import _power_at
from mechanics.steps.conserved import nc_power

PARAMETERS = {"m": 1.0, "k": 1.0, "c": 0.3}


def particle(fx: str, fy: str = "0") -> dict:
    """A particle in the trap V = k (x² + y²)/2, as a course tool would post it, with one force."""
    return {
        "title": "Particle with a force",
        "coordinates": ["x", "y"],
        "parameters": PARAMETERS,
        "bodies": [{"name": "p", "mass": "m", "position": ["x", "y", 0]}],
        "potentials": [{"name": "trap", "expression": "k*(x**2 + y**2)/2"}],
        "forces": [{"name": "f", "on": "p", "vector": [fx, fy, 0]}],
    }


#: Forces whose power F·v is 0 at every real state.
NO_WORK = [
    "c*(sign(x_dot)*abs(x_dot) - x_dot)",
    "c*(x_dot*sign(x_dot) - abs(x_dot))",
    "c*(sign(x_dot - y_dot)*abs(x_dot - y_dot) - x_dot + y_dot)",
    "c*(sign(x_dot/3 - c*y_dot)*abs(x_dot/3 - c*y_dot) - x_dot/3 + c*y_dot)",
    "c*(sign(x_dot*y_dot)*abs(x_dot*y_dot) - x_dot*y_dot)",
    "c*sign(x)*(abs(x_dot) - x_dot*sign(x_dot))",
]
#: Forces that do work somewhere. The last two do only on a kink: c (|sgn(ẋ − ẏ)| − 1) is −c
#: on ẋ = ẏ alone, (sgn(ẋ)² − 1) ẏ is −ẏ at ẋ = 0 alone, so the u = 0 case must be judged.
WORK = [
    "c*abs(x_dot)",
    "c*x_dot*abs(x_dot)",
    "sign(x_dot)",
    "-c*sign(x_dot)",
    "c*(sign(x_dot)*abs(x_dot) + x_dot)",
    "c*(abs(sign(x_dot - y_dot)) - 1)",
]
WORK_Y = [("0", "(sign(x_dot)**2 - 1)*y_dot")]


def power_by_hand(fx: str, fy: str) -> callable:
    """F·v = Fx ẋ + Fy ẏ as a numpy function of (x, y, ẋ, ẏ), from the spec's own strings."""
    x, y, xd, yd = sp.symbols("x y x_dot y_dot", real=True)
    table = {"x": x, "y": y, "x_dot": xd, "y_dot": yd, "abs": sp.Abs, "sign": sp.sign}
    table.update({k: sp.Float(v) for k, v in PARAMETERS.items()})
    power = sp.sympify(fx, locals=table) * xd + sp.sympify(fy, locals=table) * yd
    return sp.lambdify((x, y, xd, yd), power, "numpy")


def states() -> np.ndarray:
    """Random states, then the same with ẋ = 0, ẏ = 0, ẋ = ẏ, ẋ = −ẏ and x = 0 (the kinks)."""
    rng = np.random.default_rng(5)
    s = rng.uniform(-2, 2, size=(4, 40))
    kinks = [s.copy() for _ in range(5)]
    kinks[0][2] = 0
    kinks[1][3] = 0
    kinks[2][2] = kinks[2][3]
    kinks[3][2] = -kinks[3][3]
    kinks[4][0] = 0
    return np.concatenate([s, *kinks], axis=1)


def verdicts(fx: str, fy: str = "0") -> tuple[bool, str, str]:
    """Is E listed as conserved, the conserved step's text, and equilibria's power kind at 0."""
    d = derive_model(particle(fx, fy))
    step = next(s for s in d.steps if s.id == "conserved")
    values = {d.model.params[k]: sp.Float(v) for k, v in PARAMETERS.items()}
    kind = _power_at(d, values, [0.0, 0.0]).kind
    # the engine's power is F·v too (so the numbers below judge the verdict on the same thing)
    engine = sp.lambdify(
        (*d.model.q, *d.model.qd), nc_power(d.model, d.work).xreplace(values), "numpy"
    )
    X = states()
    assert np.allclose(
        np.broadcast_to(engine(*X), X.shape[1]), power_by_hand(fx, fy)(*X), atol=1e-12
    )
    return any(c["name"] == "energy" for c in d.work.conserved), step.text, kind


@pytest.mark.parametrize("force", NO_WORK)
def test_a_force_that_does_no_work_case_by_case_keeps_energy_conserved(force):
    """F·v is 0 at every sampled state and on every kink, so E = T + V is conserved: the step
    lists it and says no work is done, and equilibria's power is "no work" (it was "no sign")."""
    P = np.broadcast_to(power_by_hand(force, "0")(*states()), states().shape[1])
    assert np.max(np.abs(P)) <= 1e-12, force  # the premise, checked independently of the engine
    conserved, text, kind = verdicts(force)
    assert conserved and "do no work" in text and "do work" not in text, text
    assert kind == "no work", force


@pytest.mark.parametrize(("fx", "fy"), [(f, "0") for f in WORK] + WORK_Y)
def test_a_force_that_does_work_somewhere_is_never_called_workless(fx, fy):
    """F·v ≠ 0 at some state (for the last ones only on ẋ = ẏ or ẋ = 0): E is not conserved, the
    step says the forces do work, and equilibria never calls the power 0."""
    P = power_by_hand(fx, fy)(*states())
    assert np.max(np.abs(P)) > 1e-3, (fx, fy)  # the premise
    conserved, text, kind = verdicts(fx, fy)
    assert not conserved and "do work" in text, text
    assert kind not in ("no work", "none"), (fx, fy)


def test_the_step_says_the_force_itself_is_zero_not_gyroscopic():
    """c (sgn(ẋ)|ẋ| − ẋ) is no magnetic force: it is 0 itself, and the text says which."""
    _, text, _ = verdicts(NO_WORK[0])
    assert "themselves are 0" in text and "magnetic" not in text, text


def test_a_force_at_rest_alone_does_no_work_there():
    """c (|sgn ẋ| − 1) is −c at ẋ = 0 only, where its power −c ẋ is 0: E is conserved (the
    case ẋ = 0 is judged, not skipped), the force is not 0 itself. Equilibria judges the part
    that moves, c |sgn ẋ|, whose power c ẋ has no sign: rightly not "no work" there."""
    force = "c*(abs(sign(x_dot)) - 1)"
    assert np.max(np.abs(power_by_hand(force, "0")(*states()))) <= 1e-12
    conserved, text, kind = verdicts(force)
    assert conserved and "do no work" in text and "themselves are 0" not in text, text
    assert kind == "no sign"


# --- 2. a mass or inertia that depends on the coordinates: refused (issue 23, item 6) --------


def trap(mass: str, centre: float, initial: float = 0.0) -> dict:
    """A particle of mass m (2 − x) in the trap k ((x − centre)² + y²)/2: the forces balance at
    (centre, 0) alone, where the mass is m (2 − centre)."""
    return {
        "title": "Particle whose mass depends on x",
        "coordinates": ["x", "y"],
        "parameters": {"m": 1.0, "k": 1.0},
        "initial": {"x": initial},
        "bodies": [{"name": "p", "mass": mass, "position": ["x", "y", 0]}],
        "potentials": [{"name": "trap", "expression": f"k*((x - {centre})**2 + y**2)/2"}],
    }


def wheel(izz: str, centre: float, extra: dict | None = None) -> dict:
    """A wheel turned by θ about its fixed centre (z), with a torsion spring k (θ − centre)²/2."""
    return {
        "title": "Wheel whose moment depends on its angle",
        "coordinates": ["theta"],
        "parameters": {"m": 1.0, "k": 1.0, "I0": 1.0},
        "frames": [{"name": "R", "parent": "N", "axis": "z", "angle": "theta"}],
        "bodies": [
            {
                "name": "wheel",
                "kind": "rigid_body",
                "mass": "m",
                "frame": "R",
                "position": [0, 0, 0],
                "inertia": {"ixx": "I0", "iyy": "I0", "izz": izz},
                **(extra or {}),
            }
        ],
        "potentials": [{"name": "spring", "expression": f"k*(theta - {centre})**2/2"}],
    }


ROD_SIN2 = {
    "title": "Rod whose central moment vanishes at the bottom",
    "coordinates": ["theta"],
    "parameters": {"m": 1.0, "l": 1.0, "g": 9.81},
    "frames": [{"name": "R", "parent": "N", "axis": "z", "angle": "theta"}],
    "bodies": [
        {
            "name": "rod",
            "kind": "rigid_body",
            "mass": "m",
            "frame": "R",
            "position": {"frame": "R", "components": [0, "-l/2", 0]},
            "inertia": {"ixx": "m*l**2/12", "iyy": "m*l**2/12", "izz": "m*l**2*sin(theta)**2/12"},
        }
    ],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
}


@pytest.mark.parametrize(
    ("spec", "field"),
    [
        (trap("m*(2 - x)", 3.0), "bodies[0].mass"),
        (trap("m*(2 - x)", 2.0), "bodies[0].mass"),
        (trap("m*(2 - x)", 3.0, initial=3.0), "bodies[0].mass"),
        (wheel("I0*(1 - theta)", 2.0), "bodies[0].inertia.izz"),
        (wheel("I0*(1 - theta)", 0.5), "bodies[0].inertia.izz"),
        (ROD_SIN2, "bodies[0].inertia.izz"),
    ],
)
def test_a_mass_or_inertia_depending_on_the_coordinates_is_refused_naming_the_field(spec, field):
    """These specs were once derived and their equilibria judged one by one (a point where
    m (2 − x) ≤ 0 left out, naming the field). Since issue 23 (item 6) a mass or inertia in the
    coordinates is refused outright, before any equilibrium: Lagrange's equations here need
    constant masses (tests/spec/test_variable_mass.py). The refusal names the same field, in the
    engine and through /api/v1/equilibria."""
    from fastapi.testclient import TestClient

    from app.main import app
    from mechanics.spec import SpecError

    with pytest.raises(SpecError) as caught:
        derive_model(spec)
    assert [e["field"] for e in caught.value.errors] == [field]
    r = TestClient(app).post("/api/v1/equilibria", json={"scene": spec})
    assert r.status_code == 422, r.text
    assert [e["field"] for e in r.json()["detail"]] == [field], r.json()


# --- 3. /api/v1/newton names its forces as the free-body diagram does -------------------------


@pytest.fixture(scope="module")
def client():
    from fastapi.testclient import TestClient

    from app.main import app

    return TestClient(app)


def scene_ids_of_catalog() -> list[str]:
    from mechanics.scenes import scene_ids

    return list(scene_ids())


@pytest.mark.parametrize("scene_id", scene_ids_of_catalog())
def test_newton_names_each_force_as_the_free_body_diagram_of_the_same_scene(
    client, scene_id, monkeypatch
):
    """Body by body, /newton's ``forces`` are the diagram's (its ``fbd`` step from /derive): the
    same labels and kinds in the same order, constraint forces under the diagram's names; an
    applied force is F_g for a weight and F_<name> / M_<name> by the spec's own name of the spring,
    damper, force or torque (read from the spec, not from a label). The fields that were there
    stay (additive only)."""
    monkeypatch.setenv("LAGRANGE_LAB_DERIVE_SECONDS", "120")  # a cold double pendulum on a
    # loaded 2-core machine: the time budget is not what this test is about
    newton = client.post("/api/v1/newton", json={"scene_id": scene_id})
    derive = client.post("/api/v1/derive", json={"scene_id": scene_id})
    assert newton.status_code == derive.status_code == 200, (newton.text, derive.text)
    out = newton.json()
    assert {"steps", "constraint_forces", "equations", "agrees_with_lagrange"} <= set(out)
    fbd = next(s for s in derive.json()["steps"] if s["id"] == "fbd")["data"]["bodies"]
    spec = client.get(f"/api/v1/scenes/{scene_id}").json()["spec"]
    named = {s["name"] for s in spec.get("springs", [])} | {
        x["name"] for group in ("forces", "torques", "dampers") for x in spec.get(group, [])
    }
    expected = []
    for drawn in fbd:
        for f in drawn["forces"]:
            expected.append((drawn["body"], f["label"], f["kind"]))
        for f in drawn["constraint_forces"]:
            expected.append((drawn["body"], f["label"], "constraint"))
    assert [(f["body"], f["latex"], f["kind"]) for f in out["forces"]] == expected
    constraint = [(d["body"], f["name"], f["what"]) for d in fbd for f in d["constraint_forces"]]
    got = [(f["body"], f["name"], f["what"]) for f in out["forces"] if f["kind"] == "constraint"]
    assert got == constraint
    for f in out["forces"]:
        if f["kind"] == "weight":
            assert f["name"] == "F_g"
        elif f["kind"] != "constraint":
            letter, _, name = f["name"].partition("_")
            assert name in named and letter == ("M" if f["kind"] == "torque" else "F"), f
            assert f["what"] is None


@pytest.mark.parametrize(
    ("scene_id", "names"),
    [
        ("simple_pendulum", {"bob": "F_T"}),  # the rod's tension
        ("bead_on_hoop", {"bead": "F_N"}),  # the hoop's normal force
        ("atwood_machine", {"mass1": "F_T", "mass2": "F_T"}),  # the string's tension
        ("rolling_disk", {"disk": "F_C"}),  # normal force and static friction together
    ],
)
def test_each_constraint_force_carries_its_name(client, scene_id, names):
    """A tension is F_T, a hoop's push F_N; the rolling disk's ground exerts F_N and F_f, whose
    sum m a − ΣF is the resultant F_C (and the diagram draws the two)."""
    out = client.post("/api/v1/newton", json={"scene_id": scene_id}).json()
    assert {f["body"]: f["name"] for f in out["constraint_forces"]} == names
    if scene_id == "rolling_disk":
        drawn = {f["name"] for f in out["forces"] if f["kind"] == "constraint"}
        assert drawn == {"F_N", "F_f"}


def test_the_openapi_schema_documents_the_force_names(client):
    """The new fields are in the OpenAPI document, each described, beside the old ones."""
    schemas = client.get("/openapi.json").json()["components"]["schemas"]
    newton = schemas["NewtonResponse"]
    assert {"steps", "constraint_forces", "equations", "agrees_with_lagrange", "forces"} <= set(
        newton["properties"]
    )
    assert newton["properties"]["forces"]["items"]["$ref"].endswith("/DiagramForceOut")
    force = schemas["DiagramForceOut"]["properties"]
    assert all(force[k].get("description") for k in ("body", "name", "kind", "latex", "what"))
    assert "F_T" in force["name"]["description"]
    assert schemas["ConstraintForceOut"]["properties"]["name"].get("description")
