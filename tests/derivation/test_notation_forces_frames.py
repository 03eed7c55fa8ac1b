"""One symbol, one meaning, round 2 (student play-test): the transport theorem's relative rate is
taken in the frame that turns, named as the model names it; no constraint force is called by a
letter that is the inertial frame N, another frame, or a parameter of the scene (a rolling disk's
radius R), and Newton's panel calls each force what the free-body diagram calls it; the energy's
rate is the non-conservative forces' power; the forces step's plain copy keeps ^NC; the FBD legend
sets its symbols as math and does not change while the run plays (lecture mode's step height
jumped), and in lecture mode the labels are placed at the size they are shown (no overlaps).
"""

from __future__ import annotations

import json
import random
import re
import shutil
import subprocess
from pathlib import Path

import pytest
import sympy as sp
from fastapi.testclient import TestClient

from app.main import app
from mechanics.derive import derivation_of_scene, derive_scene
from mechanics.expr import to_latex
from mechanics.newton import newton_json
from mechanics.scenes import load_scene, scene_ids

client = TestClient(app)
ROOT = Path(__file__).resolve().parents[2]
SCENES = scene_ids()


def steps(derivation: dict) -> dict[str, dict]:
    return {s["id"]: s for s in derivation["steps"]}


def force_name(latex: str) -> str:
    """`\\vec{F}_{T,\\text{bob}} = …` → F_T; `\\vec{R}_{\\text{disk}} = …` → R (a bare letter)."""
    m = re.match(r"\s*\\vec\{(\w+)\}_\{(?:(\\text\{\w+\}|\w+),)?", latex)
    assert m, latex
    index = (m.group(2) or "").replace(r"\text{", "").rstrip("}")
    return f"{m.group(1)}_{index}" if index else m.group(1)


def names_taken(scene_id: str) -> set[str]:
    """The scene's parameters and frames, and N, the inertial frame."""
    spec = load_scene(scene_id)
    return {*spec.get("parameters", {}), *(f["name"] for f in spec.get("frames", [])), "N"}


# ---------------------------------------------------------------------------- 1. transport theorem
@pytest.mark.parametrize("scene_id", SCENES)
def test_the_transport_theorem_takes_the_rate_in_the_frame_that_turns(scene_id):
    """Notes eq. 9: v_F = ṙ_B + ω_B/F × r_B, the rate seen in B, the turning frame. Which frame a
    body's position is written in is read off the step's own lines (the rate line's subscript)."""
    kin = steps(derive_scene(scene_id))["kinematics"]
    text = kin["text"]
    assert "(d\\vec r/dt)_F" not in text
    rate_frames = {
        m.group(1)
        for line in kin["latex"]
        if (m := re.match(r"\\left\(\\frac\{d\\vec\{r\}\}\{dt\}\\right\)_\{(\w+)\}", line))
    }
    assert set(kin["data"]["transport_frames"]) == rate_frames
    for B in rate_frames:
        assert rf"(d\vec r/dt)_{{{B}}} + \vec\omega_{{{B}/N}} \times \vec r" in text
    if scene_id in ("physical_pendulum", "bead_on_hoop", "particle_in_cone", "spherical_pendulum"):
        assert rate_frames, "a scene whose body is written in a turning frame"


def test_the_physical_pendulums_rate_is_seen_in_its_rod_frame_R():
    spec = load_scene("physical_pendulum")
    (rod,) = spec["bodies"]
    assert rod["frame"] == "R"  # the rod's own frame, as the model has it
    text = steps(derive_scene("physical_pendulum"))["kinematics"]["text"]
    assert r"$\vec v = (d\vec r/dt)_{R} + \vec\omega_{R/N} \times \vec r$" in text


# ---------------------------------------------------------------------------- 2. force names
@pytest.mark.parametrize("scene_id", SCENES)
def test_no_force_is_named_by_a_frame_or_a_parameter_and_newton_uses_the_fbds_names(scene_id):
    taken = names_taken(scene_id)
    fbd = steps(derive_scene(scene_id))["fbd"]["data"]["bodies"]
    for body in fbd:
        for f in body["constraint_forces"]:
            assert f["name"] not in taken, (f, taken)
            assert force_name(f["label"]) == f["name"]
            assert f["name"].startswith("F_"), f  # one family with the weight F_g
    newton = newton_json(derivation_of_scene(scene_id))
    (solved,) = [s for s in newton["steps"] if s["id"] == "constraint_forces"]
    own = {b["body"]: b["constraint_forces"] for b in fbd}
    for label, line in zip(solved["labels"], solved["latex"], strict=True):
        if not label.startswith("constraint force on "):
            continue
        body = label.removeprefix("constraint force on ")
        name = force_name(line)
        assert name not in taken and name.split("_")[0] != name, (line, taken)
        if len(own[body]) == 1 and own[body][0]["part"] == "rest":  # one force: one name
            assert name == own[body][0]["name"], (line, own[body])
    assert "constraint force R" not in " ".join(s["text"] for s in newton["steps"])


def test_the_rolling_disks_normal_force_is_not_the_frame_n_nor_newtons_the_radius_r():
    d = steps(derive_scene("rolling_disk"))
    assert r"\vec\omega_{D/N}" in d["fbd"]["text"]  # N is the frame here ...
    (note,) = d["fbd"]["data"]["constraints"]
    assert r"\vec{N}" not in note and r"\vec{F}_{N,\text{disk}}" in note  # ... not a force
    (solved,) = [
        s
        for s in newton_json(derivation_of_scene("rolling_disk"))["steps"]
        if s["id"] == "constraint_forces"
    ]
    (line,) = solved["latex"]
    assert line.startswith(r"\vec{F}_{C,\text{disk}} = \vec{F}_{N,\text{disk}} + \vec{F}_{f,")


def test_the_atwood_ropes_force_is_f_t_on_both_panels_with_its_value():
    """By hand: the rope pulls each mass up with 2 m1 m2 g/(m1 + m2)."""
    (solved,) = [
        s
        for s in newton_json(derivation_of_scene("atwood_machine"))["steps"]
        if s["id"] == "constraint_forces"
    ]
    m1, m2, g = sp.symbols("m1 m2 g", positive=True)
    for line, body in zip(solved["latex"], ("mass1", "mass2"), strict=True):
        assert line.startswith(rf"\vec{{F}}_{{T,\text{{{body}}}}} = ")
        assert to_latex(2 * g * m1 * m2 / (m1 + m2)) in line


# ---------------------------------------------------------------------------- 3. dE/dt
@pytest.mark.parametrize("scene_id", SCENES)
def test_the_energys_rate_is_the_non_conservative_power(scene_id):
    text = steps(derive_scene(scene_id))["conserved"]["text"]
    assert not re.search(r"Q}?_j \\dot q_j", text), text  # Σ Q_j q̇_j would count V twice


def test_the_cart_pendulums_de_dt_is_q_x_nc_times_x_dot_along_the_motion():
    """E = T + V differentiated along the equations of motion (q̈ solved) equals Q_x^NC ẋ at
    random states; the whole Q_x = Q_x^NC − ∂V/∂x would add −(∂V/∂x) ẋ, which is not zero here."""
    d = derivation_of_scene("cart_pendulum")
    m, w = d.model, d.work
    text = steps(d.to_json())["conserved"]["text"]
    assert r"$dE/dt = \sum_j Q_j^{NC} \dot q_j$" in text
    E = w.T + w.V
    qdd = dict(zip(m.qdd, d.solved_accelerations, strict=True))
    t = m.names["t"]
    to_sym = {x: sp.Dummy() for x in [*m.qdd, *m.qd, *m.q]}
    plain = E.xreplace(to_sym)
    rate = plain.diff(t) + sum(
        plain.diff(to_sym[q]) * to_sym[qd] + plain.diff(to_sym[qd]) * to_sym[qa]
        for q, qd, qa in zip(m.q, m.qd, m.qdd, strict=True)
    )
    back = {v: k for k, v in to_sym.items()}
    rate = rate.xreplace(back).xreplace(qdd)
    power_nc = sum(Q * qd for Q, qd in zip(w.Q, m.qd, strict=True))
    dV = sum(
        w.V.xreplace(to_sym).diff(to_sym[q]).xreplace(back) * qd
        for q, qd in zip(m.q, m.qd, strict=True)
    )
    rng = random.Random(3)
    for _ in range(4):
        at = {s: rng.uniform(0.3, 1.2) for s in [*m.params.values(), *m.q, *m.qd, t]}
        assert float(rate.subs(at)) == pytest.approx(float(power_nc.subs(at)), rel=1e-9, abs=1e-9)
    assert abs(float(dV.subs(at))) > 1e-3  # the conservative part is not zero: the fix matters


# ---------------------------------------------------------------------------- 4. plain Q^NC
@pytest.mark.parametrize("scene_id", SCENES)
def test_the_forces_steps_plain_copy_says_nc(scene_id):
    forces = steps(derive_scene(scene_id))["forces"]
    assert len(forces["plain"]) == len(forces["latex"])
    for plain, latex in zip(forces["plain"], forces["latex"], strict=True):
        assert "^{NC}" in latex and re.match(r"^Q_\w+\^NC = ", plain), plain


@pytest.mark.parametrize(
    ("scene_id", "conservative"),
    [
        ("atwood_machine", lambda s: s["g"] * (s["m1"] - s["m2"])),  # the weights' difference
        ("rolling_disk", lambda s: s["g"] * s["m"] * sp.sin(s["alpha"])),  # down the slope
    ],
)
def test_without_nc_forces_the_sentence_gives_the_whole_q_not_zero(scene_id, conservative):
    """By hand: Atwood (x the drop of m1) Q_x = −∂V/∂x = g (m1 − m2); disk on a slope
    Q_x = m g sin α; the line beside it says Q_x^NC = 0, so the sentence must not call Q_x zero."""
    forces = steps(derive_scene(scene_id))["forces"]
    assert forces["plain"] == ["Q_x^NC = 0"]
    s = {n: sp.Symbol(n) for n in ("g", "m1", "m2", "m", "alpha")}
    assert rf"Q_{{x}} = -\partial V/\partial x = {to_latex(conservative(s))}$" in forces["text"]


# ---------------------------------------------------------------------------- 5, 6. the legend
NODE = shutil.which("node")
needs_node = pytest.mark.skipif(NODE is None, reason="node is not installed")
DRAW = """
import { readFileSync } from "node:fs";
const px = (font) => parseFloat(/([\\d.]+)px/.exec(font)[1]);
const lecture = process.argv[2] === "lecture";
globalThis.document = {
  body: { classList: { contains: (c) => lecture && c === "lecture" } },
  createElement: () => { const ctx = { font: "10px x",
    measureText(t) { return { width: 0.6 * px(this.font) * t.length }; } };
    return { style: { setProperty() {} }, dataset: {}, getContext: () => ctx }; } };
const { drawFBD, fbdLegend } = await import(process.argv[1]);
const d = JSON.parse(readFileSync(0, "utf8"));
const out = [];
const box = { dataset: {}, children: [], replaceChildren(...c) { this.children = c; } };
for (const i of d.frames) {
  const svg = { dataset: {}, setAttribute() {}, innerHTML: "",
    getBoundingClientRect: () => ({ width: d.shown }) };
  const kinds = drawFBD(svg, d.spec, d.result, d.spec.parameters, i, {}, d.placed);
  fbdLegend(box, kinds);
  out.push({ i, svg: svg.innerHTML, now: (kinds.now || kinds).short,
    legend: box.children.map((c) => c.innerHTML || c.textContent).join(" | ") });
}
console.log(JSON.stringify(out));
"""


def draw(scene_id: str, frames: list[int], t_end: float = 10, lecture: bool = False) -> list:
    spec = load_scene(scene_id)
    body = {"scene_id": scene_id, "t_end": t_end, "fps": 20, "constraint_forces": True}
    r = client.post("/api/v1/simulate", json=body)
    assert r.status_code == 200, r.text
    placed = steps(derive_scene(scene_id))["fbd"]["data"]
    data = {"spec": spec, "result": r.json(), "placed": placed, "frames": frames, "shown": 560}
    out = subprocess.run(
        [
            NODE,
            "--input-type=module",
            "-e",
            DRAW,
            str(ROOT / "static/js/fbd.js"),
            "lecture" if lecture else "page",
        ],
        input=json.dumps(data),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


@needs_node
def test_the_legend_is_the_same_at_every_instant_of_the_double_pendulum():
    """The weights are short at some instants and not at others (the bobs' rods pull hard when
    they swing fast): the legend names them once for the run, so its height never changes."""
    drawn = draw("double_pendulum", list(range(0, 200, 7)))
    assert len({json.dumps(d["now"]) for d in drawn}) > 1  # it does vary from instant to instant
    legends = {d["legend"] for d in drawn}
    assert len(legends) == 1, legends
    (legend,) = legends
    for d in drawn:  # every force short at some instant is named
        for label in d["now"]:  # "F_g,bob1"
            text, _, sub = label.partition("_")
            assert f"<i>{text}</i><sub>{sub}</sub>" in legend


@needs_node
@pytest.mark.parametrize("scene_id", ["double_pendulum", "rolling_disk", "atwood_machine"])
def test_the_legends_symbols_are_set_as_math_not_raw_underscores(scene_id):
    (d,) = draw(scene_id, [10], t_end=1)
    text = re.sub(r"<[^>]+>", "", d["legend"])
    assert "_" not in text, d["legend"]
    assert "<sub>" in d["legend"]
    assert "weight <i>F</i><sub>g</sub>" in d["legend"] or scene_id == "rolling_disk"


def text_boxes(svg: str) -> list[tuple[str, list[float], float]]:
    """(text, [left, top, right, bottom], font size) of every text, measured as the stub does."""
    out = []
    for m in re.finditer(
        r'<text x="([-\d.]+)" y="([-\d.]+)" font-size="([\d.]+)"[^>]*>([^<]*)'
        r'(?:<tspan font-size="([\d.]+)"[^>]*>([^<]*)</tspan>)?</text>',
        svg,
    ):
        x, y, size = float(m.group(1)), float(m.group(2)), float(m.group(3))
        main, sub = m.group(4), m.group(6) or ""
        width = 0.6 * size * len(main) + 0.6 * 0.75 * size * len(sub)
        out.append((main + sub, [x, y - size, x + width, y + (0.3 * size if sub else 0)], size))
    return out


@needs_node
def test_lecture_labels_are_placed_at_their_shown_size_and_do_not_overlap():
    """Lecture mode shows every label at ≥ 24 CSS px; placed at 13 units and enlarged after,
    the double pendulum's F_T,bob2 sat on bob2. Shown 560 px wide for a 440-unit diagram."""
    k = 560 / 440
    for d in draw("double_pendulum", [0, 40, 80, 120, 160], lecture=True):
        boxes = [b for b in text_boxes(d["svg"]) if not b[0].startswith("t = ")]
        names = [b for b in boxes if b[0] in ("bob1", "bob2")]
        assert len(names) == 2
        for text, _, size in boxes:
            assert size * k >= 24 - 1e-6, (text, size)  # nothing left for legibleLabels to grow
        for a in range(len(boxes)):
            for b in range(a + 1, len(boxes)):
                p, q = boxes[a][1], boxes[b][1]
                overlap = p[0] < q[2] - 0.5 and q[0] < p[2] - 0.5
                overlap = overlap and p[1] < q[3] - 0.5 and q[1] < p[3] - 0.5
                assert not overlap, (d["i"], boxes[a], boxes[b])
