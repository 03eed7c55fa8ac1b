"""The scene's equations printed as JavaScript (mechanics/jscode.py) against the Python numerics
they are printed beside (mechanics/numeric.py's lambdify, an independent printer): the right-hand
side, the positions and the energies at random states agree to 1e-12, evaluated by node. And the
gate: nothing but Math's functions, slots, temporaries, numbers and operators is ever served.

Needs node (``/usr/bin/node``) for the evaluations; without it those tests skip with a reason
(the whitelist tests run anyway).
"""

from __future__ import annotations

import json
import shutil
import subprocess

import numpy as np
import pytest
import sympy as sp

from mechanics.jscode import JsUnavailable, checked_expression, live_module
from mechanics.numeric import _args, _plain, compiled_scene, compiled_spec, evaluate
from mechanics.scenes import scene_ids

NODE = shutil.which("node")
needs_node = pytest.mark.skipif(
    NODE is None, reason="node is not installed (apt-get install nodejs)"
)

#: Reads {"cases": [[t, y, p], ...]} on stdin, prints rhs, places, axes and energy of each case.
DRIVER = """
import * as m from "./live.mjs";
let text = "";
process.stdin.on("data", (c) => { text += c; });
process.stdin.on("end", () => {
  const { cases } = JSON.parse(text);
  const out = cases.map(([t, y, p]) => {
    const dy = new Float64Array(y.length), pl = new Float64Array(3 * m.dims.points);
    const ax = new Float64Array(9 * m.dims.frames), e = new Float64Array(2);
    const st = new Float64Array(2 * m.dims.stops);
    const code = m.rhs(t, Float64Array.from(y), Float64Array.from(p), dy);
    m.places(t, y, p, pl); m.axes(t, y, p, ax); m.energy(t, y, p, e); m.stops(t, y, p, st);
    return { code, dy: [...dy], places: [...pl], axes: [...ax], energy: [...e], stops: [...st] };
  });
  process.stdout.write(JSON.stringify({ dims: m.dims, out }));
});
"""


def run_node(source: str, cases: list, tmp_path) -> dict:
    (tmp_path / "live.mjs").write_text(source)
    (tmp_path / "driver.mjs").write_text(DRIVER)
    done = subprocess.run(
        [NODE, "driver.mjs"],
        input=json.dumps({"cases": cases}),
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=60,
        check=True,
    )
    return json.loads(done.stdout)


def _params(c) -> list[float]:
    return [c.derivation.model.spec.parameters[k] for k in c.parameters]


def _states(c, seed: int, count: int = 12) -> list[tuple[float, np.ndarray]]:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        y = rng.uniform(-2, 2, 2 * c.n + c.extras)
        y[: c.n] = np.where(np.abs(y[: c.n]) < 0.3, 0.5, y[: c.n])  # radii away from 0
        if c.derivation.model.spec.positive_coordinates:
            y[: c.n] = np.abs(y[: c.n]) + 0.5
        out.append((float(rng.uniform(0, 5)), y))
    return out


def _agree(c, tmp_path, seed: int = 7) -> None:
    live = live_module(c)
    p = _params(c)
    states = _states(c, seed)
    got = run_node(live.source, [[t, y.tolist(), p] for t, y in states], tmp_path)
    assert got["dims"] == {
        "n": c.n,
        "extras": c.extras,
        "params": len(p),
        "points": len(c.places),
        "frames": len(c.frames),
        "stops": sum(st.when is not None for st in c.stop_specs),
    }
    assert live.points == list(c.places) and live.frames == list(c.frames)
    python = c.rhs(p)
    for (t, y), js in zip(states, got["out"], strict=True):
        assert js["code"] == 0
        assert js["dy"] == pytest.approx(python(t, y), rel=1e-12, abs=1e-12)
        ts, q, qd = np.array([t]), y[: c.n, None], y[c.n : 2 * c.n, None]
        places = [v[0] for fn in c.places.values() for v in evaluate(fn, ts, q, qd, p)]
        assert js["places"] == pytest.approx(places, rel=1e-12, abs=1e-12)
        axes = [v[0] for fn in c.frames.values() for v in evaluate(fn, ts, q, qd, p)]
        assert js["axes"] == pytest.approx(axes, rel=1e-12, abs=1e-12)
        energy = [v[0] for v in evaluate(c.energy, ts, q, qd, p)]
        assert js["energy"] == pytest.approx(energy, rel=1e-12, abs=1e-12)
        assert js["stops"] == pytest.approx(_stop_values(c, t, y, p), rel=1e-12, abs=1e-12)


def _stop_values(c, t: float, y: np.ndarray, p: list[float]) -> list[float]:
    """Each printed stop's value and guard (1 without one), by sympy's own lambdify."""
    args, subs = _args(c.derivation)
    out = []
    for st in c.stop_specs:
        if st.when is None:
            continue  # a tension stop: not printed (Newton's method)
        for e in (st.when, st.only_if if st.only_if is not None else sp.Integer(1)):
            fn = sp.lambdify(args, _plain(e, subs), modules="math")
            out.append(float(fn(t, *y[: 2 * c.n], *p)))
    return out


@needs_node
@pytest.mark.parametrize("scene", scene_ids())
def test_the_javascript_equals_the_python_numerics(scene, tmp_path):
    _agree(compiled_scene(scene), tmp_path)


def four_links(names: tuple[str, ...] = ("q0", "q1", "q2", "q3")) -> dict:
    bodies, prev = [], None
    for i, q in enumerate(names):
        comps = [f"sin({q})", f"-cos({q})", 0]
        pos = comps if prev is None else {"frame": "N", "components": comps, "from": prev}
        bodies.append({"name": f"b{i}", "mass": "m", "position": pos})
        prev = f"b{i}"
    return {
        "title": "four links",
        "coordinates": list(names),
        "parameters": {"m": 1.0, "g": 9.81},
        "bodies": bodies,
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
        "initial": {names[0]: 1.0},
    }


@needs_node
def test_four_links_solve_m_qdd_equals_f_in_javascript(tmp_path):
    """n > 3: M and f printed, M q̈ = f solved by elimination in the browser."""
    c = compiled_spec(four_links())
    assert not c.solved
    _agree(c, tmp_path, seed=3)


def test_user_names_never_reach_the_javascript():
    """Coordinates, parameters and bodies named like JavaScript's globals and keywords: the
    module holds slots only, so nothing can collide with or call them."""
    spec = {
        "title": "names",
        "coordinates": ["constructor"],
        "parameters": {"fetch": 2.0, "alert": 1.0, "window": 9.81},
        "bodies": [
            {
                "name": "document",
                "mass": "alert",
                "position": ["fetch*sin(constructor)", "-fetch*cos(constructor)"],
            }
        ],
        "gravity": {"acceleration": "window", "direction": [0, -1, 0]},
        "initial": {"constructor": 0.5},
    }
    live = live_module(compiled_spec(spec))
    for word in ("constructor", "fetch", "alert", "window", "document"):
        assert word not in live.source
    assert live.coordinates == ["constructor"] and "document" in live.points  # names go as data


@pytest.mark.parametrize(
    "code",
    [
        "alert(1)",
        "y[0] + evil",
        "Math.random()",
        "y[0]; fetch(1)",
        "'text'",
        "`x${1}`",
        "{}",
        "x1 // comment",
        "window.y[0]",
        "Math.sin.constructor",
        "y[0]=1",
        "x1 += 2",
    ],
)
def test_anything_but_math_slots_numbers_and_operators_is_refused(code):
    with pytest.raises(JsUnavailable):
        checked_expression(code)


@pytest.mark.parametrize(
    "code",
    [
        "Math.sin(y[0])*p[2] + x12/(1 + 2.5e-3*t)",
        "((y[1] > 0) ? (Math.sign(y[1])) : (-1.0e+20))",
        "((y[0] == 0) ? (1/2) : ((y[0] >= 1 && y[1] != 0) ? (1) : (0)))",
        "Math.pow(Math.abs(y[0]), 3/2) - Math.PI*p[0]",
    ],
)
def test_printed_expressions_pass_the_gate(code):
    assert checked_expression(code) == code
