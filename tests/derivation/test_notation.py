"""One symbol, one meaning (instructor play-test): the derivation, the free-body diagram and
Newton's method never use one letter for two things a student must tell apart.

T is the kinetic energy, so a rod's tension is F_T; L is the Lagrangian, so a length is l (and a
posted spec that calls a parameter L gets a script 𝓛); N is the inertial frame, defined where it
is first used, so the normal force is the vector N⃗ with its body; the notes' k counts constraints
only where no spring constant k exists; the mass matrix is bold 𝐌 beside a cart mass M; weights
are F⃗_g (the notes' eq. 28), W being work. The diagram's arrows are measured from the SVG that
fbd.js draws (run in node): lengths in the ratio of the forces, closed forms for the sizes.
"""

from __future__ import annotations

import json
import math
import re
import shutil
import subprocess
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.derive import derivation_of_scene, derive, derive_scene
from mechanics.scenes import load_scene, scene_ids
from mechanics.steps import Work
from mechanics.steps import matrix_form as matrix_step

client = TestClient(app)
ROOT = Path(__file__).resolve().parents[2]
SCENES = scene_ids()

#: Letters the derivation means something by: energies, Lagrangian, energy total, work, Q_j.
#: (M is allowed: the mass matrix is bold, and the cart's M is the textbook's.)
RESERVED_LETTERS = {"T", "V", "L", "E", "W", "Q"}


def steps(derivation: dict) -> dict[str, dict]:
    return {s["id"]: s for s in derivation["steps"]}


def head(latex: str) -> str:
    """The letter a label starts with: `\\vec{F}_{T,\\text{bob}}` → F, `T_{\\text{bob}} = …` → T."""
    m = re.match(r"\s*(?:\\vec\{([^}]*)\}|\\mathcal\{([A-Z])\}|([A-Za-z]))", latex)
    assert m, latex
    return m[1] or (m[2] and rf"\mathcal{{{m[2]}}}") or m[3]


# ---------------------------------------------------------------------------- 1. tension ≠ T
@pytest.mark.parametrize("scene_id", SCENES)
def test_no_force_is_written_with_the_kinetic_energys_letter(scene_id):
    s = steps(derive_scene(scene_id))
    kinetic = {
        head(line)
        for line, label in zip(s["energy"]["latex"], s["energy"]["labels"], strict=True)
        if label == "T" or label.startswith("T_")
    }
    assert kinetic == {"T"}
    fbd = s["fbd"]["data"]
    forces = [f["label"] for b in fbd["bodies"] for f in b["forces"]]
    forces += [c["label"] for b in fbd["bodies"] for c in b["constraint_forces"]]
    for label in forces:
        assert head(label) not in RESERVED_LETTERS, label
    for b in fbd["bodies"]:
        for c in b["constraint_forces"]:
            assert c["name"] != "T" and c["symbol"][0] not in RESERVED_LETTERS, c
    for note in fbd["constraints"]:  # the sentences name forces as the diagram does
        assert not re.search(r"\b(pull|tension|force|reaction) [TNR]\b", note), note
        assert "$N$" not in note and "$T$" not in note and "$f_s$" not in note, note


def test_the_pendulums_tension_is_f_t_in_the_diagram_and_in_newtons_method():
    bob = next(b for b in steps(derive_scene("simple_pendulum"))["fbd"]["data"]["bodies"])
    (rod,) = bob["constraint_forces"]
    assert rod["name"] == "F_T" and rod["label"] == r"\vec{F}_{T,\text{bob}}"
    r = client.post("/api/v1/newton", json={"scene_id": "simple_pendulum"})
    assert r.status_code == 200, r.text
    lines = [
        (label, latex)
        for s in r.json()["steps"]
        for label, latex in zip(s["labels"], s["latex"], strict=True)
    ]
    tension = [latex for label, latex in lines if label == "tension bob"]
    assert tension and all(t.startswith(r"F_{T,\text{bob}} = ") for t in tension)
    assert not any(re.search(r"(^|[^\\A-Za-z_{])T(_|\s*=)", latex) for _, latex in lines), lines


# ---------------------------------------------------------------------------- 2. L, T, V taken
@pytest.mark.parametrize("scene_id", SCENES)
def test_no_catalog_parameter_or_coordinate_takes_a_letter_the_derivation_uses(scene_id):
    spec = load_scene(scene_id)
    taken = (set(spec["parameters"]) | set(spec["coordinates"])) & RESERVED_LETTERS
    assert not taken, f"{scene_id}: {sorted(taken)}"


def rod_about_its_end(length: str) -> dict:
    """The physical pendulum with its length called `length` (θ̈ = −3g sin θ / 2·length)."""
    return {
        "title": "rod",
        "coordinates": ["theta"],
        "parameters": {"m": 1.0, length: 1.0, "g": 9.81},
        "initial": {"theta": 1.0},
        "frames": [{"name": "R", "parent": "N", "axis": "z", "angle": "theta"}],
        "bodies": [
            {
                "name": "rod",
                "kind": "rigid_body",
                "mass": "m",
                "frame": "R",
                "position": {"frame": "R", "components": [0, f"-{length}/2", 0]},
                "inertia": {"ixx": f"m*{length}**2/12", "iyy": 0, "izz": f"m*{length}**2/12"},
            }
        ],
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }


def test_a_posted_parameter_named_l_makes_the_lagrangian_script():
    """Allowed (a textbook calls a rod's length L), but no line reads "L = L m (…)": the
    Lagrangian is 𝓛, said so in the step, and the equations are the same as with l."""
    s = steps(derive(rod_about_its_end("L")))
    lag = s["lagrange"]
    assert lag["latex"][0].startswith(r"\mathcal{L} = T - V = ")
    for latex in lag["latex"][1:4]:
        assert r"\partial \mathcal{L}" in latex
    assert not any(re.match(r"\s*L\s*=", x) for x in lag["latex"])
    assert "named L" in lag["text"] and r"$\mathcal{L}$" in lag["text"]
    assert r"\partial L" not in lag["text"]
    plain = steps(derive(rod_about_its_end("l")))
    assert plain["lagrange"]["latex"][0].startswith("L = T - V = ")  # unchanged where no clash
    assert "named" not in plain["lagrange"]["text"]
    # same physics: θ̈ = −3 g sin θ / (2 L), by the parallel-axis theorem I_O = m L²/3
    (acc,) = [
        p
        for p, lab in zip(s["matrix"]["plain"], s["matrix"]["labels"], strict=True)
        if lab == "theta_ddot"
    ]
    assert acc.replace(" ", "") in {
        "theta_ddot=-3*g*sin(theta)/(2*L)",
        "theta_ddot=-3*g*sin(theta)/(2L)",
    }


def test_a_posted_parameter_named_t_or_v_makes_that_energy_script():
    spec = rod_about_its_end("l")
    spec["parameters"] |= {"T": 2.0, "V": 3.0}
    spec["bodies"][0]["mass"] = "m*T/V"
    s = steps(derive(spec))
    energy = dict(zip(s["energy"]["labels"], s["energy"]["latex"], strict=True))
    assert energy["T"].startswith(r"\mathcal{T} = ") and energy["V"].startswith(r"\mathcal{V} = ")
    assert energy["T_rod"].startswith(r"\mathcal{T}_{\text{rod}} = ")
    assert "named T and V" in s["energy"]["text"]
    assert s["lagrange"]["latex"][0].startswith(r"L = \mathcal{T} - \mathcal{V} = ")


# ---------------------------------------------------------------------------- 3. N defined
@pytest.mark.parametrize("scene_id", SCENES)
def test_the_frame_n_is_defined_where_it_is_first_used(scene_id):
    s = steps(derive_scene(scene_id))
    assert "N is the fixed (inertial) frame, the notes' F" in s["kinematics"]["text"]
    fbd = s["fbd"]
    if any("/N}" in x for x in fbd["latex"]):  # ω_{D/N} already in the first step
        assert "N is the fixed (inertial) frame, the notes' F" in fbd["text"]


def test_the_rolling_disks_normal_force_is_a_vector_with_its_body():
    (note,) = steps(derive_scene("rolling_disk"))["fbd"]["data"]["constraints"]
    assert r"$\vec{F}_{N,\text{disk}}$" in note and r"$\vec{F}_{f,\text{disk}}$" in note


# ---------------------------------------------------------------------------- 4. k, M, W
@pytest.mark.parametrize("scene_id", SCENES)
def test_the_constraint_count_is_right_and_not_called_k_beside_a_spring_constant(scene_id):
    spec = load_scene(scene_id)
    s = steps(derive_scene(scene_id))["coordinates"]
    particles = sum(1 for b in spec["bodies"] if b.get("kind", "particle") == "particle")
    rigid = len(spec["bodies"]) - particles
    count = 3 * particles + 6 * rigid - len(spec["coordinates"])  # n = 3N − k, rigid: 6 each
    assert s["data"]["k"] == count
    assert "3N" not in s["text"]  # N is the inertial frame
    if "k" in spec["parameters"]:
        assert "$k =" not in s["text"] and f"absorbs {count} holonomic" in s["text"]
    else:
        assert f"$k = {count}$" in s["text"]


def bare_m(latex: str) -> list[str]:
    """Every M that is not the bold mass matrix."""
    rest = re.sub(r"\\mathbf\s*\{?M\}?", "", latex)
    return re.findall(r"(?<![\\A-Za-z])M(?![A-Za-z])", rest)


def test_the_mass_matrix_is_bold_beside_the_carts_mass_m():
    s = steps(derive_scene("cart_pendulum"))["matrix"]
    lines = dict(zip(s["labels"], s["latex"], strict=True))
    assert lines["M"].startswith(r"\mathbf{M} = ") and lines["det M"].startswith(
        r"\det \mathbf{M} = "
    )
    maths = re.findall(r"\$([^$]*)\$", s["text"])
    assert [m for m in maths if bare_m(m)] == ["M"]  # only the note naming the cart's own M
    assert "Bold $\\mathbf M$ is the mass matrix" in s["text"]


def test_the_unsolved_warning_writes_the_mass_matrix_bold(monkeypatch):
    d = derivation_of_scene("cart_pendulum")
    monkeypatch.setattr(matrix_step, "SOLVE_OPS_BUDGET", 0)
    work = Work(T=d.work.T, V=d.work.V, Q=list(d.work.Q), eom_lhs=list(d.work.eom_lhs))
    matrix_step.mass_matrix_form(d.model, work)
    (warning,) = work.warnings
    assert "𝐌" in warning and not re.search(r"\bM\b", warning), warning


@pytest.mark.parametrize("scene_id", SCENES)
def test_weights_are_f_g_not_w(scene_id):
    for b in steps(derive_scene(scene_id))["fbd"]["data"]["bodies"]:
        for f in b["forces"]:
            if f["kind"] == "weight":
                assert f["label"].startswith(r"\vec{F}_{g,"), f["label"]


# ---------------------------------------------------------------------------- 6. spring spring
@pytest.mark.parametrize("scene_id", SCENES)
def test_no_spring_spring(scene_id):
    d = derive_scene(scene_id)
    for text in [s["text"] for s in d["steps"]] + list(d.get("warnings", [])):
        assert not re.search(r"spring spring", text, re.I), text


def test_the_spring_named_spring_reads_once_and_another_keeps_its_kind():
    energy = steps(derive_scene("spring_mass_damper"))["energy"]["text"]
    assert "The spring lies along a line" in energy
    spec = load_scene("spring_mass_damper")
    spec["springs"][0]["name"] = "k1"
    assert "The spring k1 lies along a line" in steps(derive(spec))["energy"]["text"]


# ---------------------------------------------------------------------------- 5. arrows to scale
NODE = shutil.which("node")
DRAW = """
import { readFileSync } from "node:fs";
globalThis.document = { createElement: () => ({ style: { setProperty() {} }, dataset: {},
  getContext: () => ({ font: "", measureText: (t) => ({ width: 7 * t.length }) }) }) };
const { drawFBD, fbdLegend, MIN_ARROW } = await import(process.argv[1]);
const d = JSON.parse(readFileSync(0, "utf8"));
const svg = { dataset: {}, setAttribute() {}, innerHTML: "" };
const kinds = drawFBD(svg, d.spec, d.result, d.spec.parameters, d.i, {}, d.placed);
const box = { dataset: {}, children: [], replaceChildren(...c) { this.children = c; } };
fbdLegend(box, kinds);
console.log(JSON.stringify({ svg: svg.innerHTML, min: MIN_ARROW,
  legend: box.children.map((c) => c.innerHTML ?? c.textContent) }));
"""


def draw(scene_id: str, i: int = 10) -> dict:
    """fbd.js's drawFBD on a real run and derivation, in node (a stub canvas measures text)."""
    spec = load_scene(scene_id)
    body = {"scene_id": scene_id, "t_end": 1, "fps": 20, "constraint_forces": True}
    r = client.post("/api/v1/simulate", json=body)
    assert r.status_code == 200, r.text
    placed = steps(derive_scene(scene_id))["fbd"]["data"]
    data = json.dumps({"spec": spec, "result": r.json(), "placed": placed, "i": i})
    out = subprocess.run(
        [NODE, "--input-type=module", "-e", DRAW, str(ROOT / "static/js/fbd.js")],
        input=data,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def arrows(svg: str) -> list[tuple[str, float]]:
    """(colour, length) of each drawn force arrow: from the line's foot to the head's tip."""
    found = []
    for g in re.finditer(
        r'<g[^>]*><line x1="([-\d.]+)" y1="([-\d.]+)"[^>]*stroke="(#\w+)"[^>]*/>'
        r'<polygon points="([-\d.]+),([-\d.]+)',
        svg,
    ):
        x1, y1, colour, x2, y2 = g.groups()
        found.append((colour, math.hypot(float(x2) - float(x1), float(y2) - float(y1))))
    return found


needs_node = pytest.mark.skipif(NODE is None, reason="node is not installed")
WEIGHT, CONSTRAINT = "#2f9e44", "#495057"


@needs_node
def test_atwood_arrows_are_in_the_ratio_of_the_forces():
    """By hand: weights m1 g, m2 g and a rope tension 2 m1 m2 g/(m1 + m2) on each mass."""
    m1, m2, g = 2.0, 1.0, 9.81
    drawn = draw("atwood_machine")
    weights = sorted(length for c, length in arrows(drawn["svg"]) if c == WEIGHT)
    tensions = [length for c, length in arrows(drawn["svg"]) if c == CONSTRAINT]
    assert len(weights) == 2 and len(tensions) == 2
    px_per_newton = weights[1] / (m1 * g)
    assert weights[0] == pytest.approx(px_per_newton * m2 * g, abs=0.2)  # 2 : 1, not 1.5 : 1
    for length in tensions:
        assert length == pytest.approx(px_per_newton * 2 * m1 * m2 * g / (m1 + m2), abs=0.2)
    assert any(
        text.startswith("arrows to scale") and "except" not in text for text in drawn["legend"]
    )
    assert not any(text.startswith("T ") or " T tension" in text for text in drawn["legend"])
    assert any("<i>F</i><sub>T</sub> tension" in text for text in drawn["legend"])


@needs_node
def test_rolling_disk_friction_is_short_and_the_legend_says_so():
    """m g = 9.81 N, F_N = m g cos α = 8.61 N, F_f = m g sin α / 3 = 1.57 N (by hand): F_N to
    scale against the weight; F_f would be shorter than the minimum, is drawn at it and named."""
    m, g, alpha = 1.0, 9.81, 0.5
    drawn = draw("rolling_disk")
    (weight,) = [length for c, length in arrows(drawn["svg"]) if c == WEIGHT]
    normal, friction = sorted(
        (length for c, length in arrows(drawn["svg"]) if c == CONSTRAINT), reverse=True
    )
    assert normal / weight == pytest.approx(math.cos(alpha), abs=0.01)
    f_s = m * g * math.sin(alpha) / 3
    assert f_s / (m * g) * weight < drawn["min"]  # too small to draw to scale ...
    assert friction == pytest.approx(drawn["min"], abs=0.2)  # ... so drawn at the minimum
    (scale,) = [text for text in drawn["legend"] if text.startswith("arrows to scale")]
    assert "<i>F</i><sub>f,disk</sub>" in scale and "minimum length" in scale
