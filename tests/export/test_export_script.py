"""POST /api/v1/export/script: the script, run in a fresh interpreter (numpy and scipy only),
reproduces the API's trajectory of the same request.

The check is independent of the app's integrators: the script steps with scipy's solve_ivp (or its
own few lines for the fixed-step methods) on equations printed as plain Python, while the API ran
its own stepping loop (or the C DOP853). Bound: the two runs integrate the same state with the same
right-hand side, so they differ by rounding grown over the run; we require every q and q̇ sample to
agree within the run's tolerance, rtol·max(1, |y|) + atol (for fixed-step methods, which have no
tolerance, 1e-9·max(1, |y|)). Runs are kept short where the motion is chaotic (the double
pendulum), where any rounding difference grows exponentially.
"""

from __future__ import annotations

import ast
import json
import re
import subprocess
import sys

import numpy as np
import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.export_script import ScriptError, checked_expression
from mechanics.scenes import scene_ids

client = TestClient(app)

#: A posted spec with four coordinates: above three, the app keeps M and f and solves M q̈ = f
#: numerically, so the script does too (numpy.linalg.solve): the other branch of the printer.
CHAIN = {
    "title": 'Four carts "on" a track \\ springs',
    "coordinates": ["x1", "x2", "x3", "x4"],
    "parameters": {"m": 1.0, "k": 10.0, "c": 0.3},
    "bodies": [
        {"name": f"cart{i}", "mass": "m" if i % 2 else "2*m", "position": [f"x{i}", 0, 0]}
        for i in range(1, 5)
    ],
    "springs": [
        {"a": f"cart{i}", "b": f"cart{i + 1}", "k": "k", "rest_length": 1} for i in range(1, 4)
    ],
    "dampers": [{"a": "cart1", "b": "cart2", "c": "c"}],
    "initial": {"x1": 0.0, "x2": 1.3, "x3": 2.0, "x4": 3.2, "x4_dot": 0.5},
}

CASES = [
    ({"scene_id": "simple_pendulum", "method": "DOP853", "rtol": 1e-10, "atol": 1e-10}, None),
    ({"scene_id": "double_pendulum", "method": "RK45", "t_end": 2, "rtol": 1e-9}, None),
    ({"scene_id": "double_pendulum", "method": "dop853_c", "t_end": 2, "rtol": 1e-10}, None),
    ({"scene_id": "spherical_pendulum", "method": "Radau", "t_end": 2, "rtol": 1e-8}, None),
    ({"scene_id": "spring_mass_damper", "method": "LSODA", "t_end": 3, "rtol": 1e-8}, None),
    ({"scene_id": "cart_pendulum", "method": "rk4", "dt": 0.01, "t_end": 3}, 1e-9),
    ({"scene_id": "elastic_pendulum", "method": "symplectic_euler", "dt": 0.002, "t_end": 2}, 1e-9),
    ({"scene_id": "bead_on_hoop", "method": "implicit_midpoint", "dt": 0.01, "t_end": 2}, 1e-9),
    ({"scene_id": "rolling_disk", "method": "euler", "dt": 0.001, "t_end": 1}, 1e-9),
    (
        {
            "scene_id": "simple_pendulum",
            "parameters": {"l": 0.7, "m": 3.0},
            "initial": {"theta": 0.3, "theta_dot": -1.1},
            "method": "DOP853",
            "t_end": 4,
            "fps": 25,
        },
        None,
    ),
    ({"scene": CHAIN, "method": "DOP853", "t_end": 3, "rtol": 1e-10, "atol": 1e-10}, None),
]


def _run_script(source: str, tmp_path) -> dict:
    path = tmp_path / "run.py"
    path.write_text(source)
    out = tmp_path / "out.json"
    done = subprocess.run(
        [sys.executable, "-I", str(path), "--json", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(out.read_text())


@pytest.mark.parametrize(
    "body, fixed_tol", CASES, ids=[f"{b.get('scene_id', 'chain')}-{b['method']}" for b, _ in CASES]
)
def test_script_reproduces_the_api_trajectory(body, fixed_tol, tmp_path):
    body = {**body, "check_sensitivity": False}
    api = client.post("/api/v1/simulate", json=body)
    assert api.status_code == 200, api.text
    run = api.json()
    script = client.post("/api/v1/export/script", json=body)
    assert script.status_code == 200, script.text
    assert script.headers["content-type"].startswith("text/x-python")
    ours = _run_script(script.text, tmp_path)
    assert ours["t"] == pytest.approx(run["t"], abs=1e-12)
    rtol = body.get("rtol", 1e-9)
    atol = body.get("atol", 1e-9)
    for part in ("q", "q_dot"):
        for name, series in run[part].items():
            expected, got = np.array(series), np.array(ours[part][name])
            scale = np.maximum(1.0, np.abs(expected))
            bound = fixed_tol * scale if fixed_tol else rtol * scale + atol
            worst = np.max(np.abs(got - expected) - bound)
            assert worst <= 0, f"{part}.{name} differs by more than the tolerance ({worst:.3g})"


@pytest.mark.slow
@pytest.mark.parametrize("scene_id", scene_ids())
def test_every_builtin_scenes_script_reproduces_its_default_run(scene_id, tmp_path):
    """Each scene at its defaults (DOP853, 2 s). A run the app ends at a stop condition is
    compared over the samples before the stop (the script lists stops, it does not apply them)."""
    body = {"scene_id": scene_id, "t_end": 2, "method": "DOP853", "check_sensitivity": False}
    run = client.post("/api/v1/simulate", json=body).json()
    script = client.post("/api/v1/export/script", json=body)
    assert script.status_code == 200, script.text
    ours = _run_script(script.text, tmp_path)
    shared = len(run["t"]) - (1 if run["stats"]["status"] == "stopped" else 0)
    assert ours["t"][:shared] == pytest.approx(run["t"][:shared], abs=1e-12)
    for part in ("q", "q_dot"):
        for name, series in run[part].items():
            expected = np.array(series[:shared])
            got = np.array(ours[part][name][:shared])
            bound = 1e-9 * np.maximum(1.0, np.abs(expected)) + 1e-9
            assert np.all(np.abs(got - expected) <= bound), f"{scene_id} {part}.{name}"


def test_the_script_names_no_user_identifier_in_its_code():
    """Parameter and coordinate names appear only inside string literals: the code itself uses
    numbered slots. A hostile title stays a string literal."""
    spec = {**CHAIN, "title": "'''\"\"\"; import os; os.system('x') #"}
    r = client.post("/api/v1/export/script", json={"scene": spec, "t_end": 1})
    assert r.status_code == 200, r.text
    tree = ast.parse(r.text)
    equations = next(n for n in tree.body if getattr(n, "name", "") == "equations")
    names = {n.id for n in ast.walk(equations) if isinstance(n, ast.Name)}
    template = {"y", "p", "t", "_", "math", "abs", "float", "np", "q_ddot", "mass", "forcing"}
    slots = {n for n in names if re.fullmatch(r"[xyp]_\d+", n)}
    assert names - slots <= template, names - slots - template
    imports = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    imports |= {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    assert imports <= {"argparse", "json", "math", "sys", "numpy", "scipy.integrate"}
    title = next(
        n.value.value
        for n in tree.body
        if isinstance(n, ast.Assign) and getattr(n.targets[0], "id", "") == "TITLE"
    )
    assert title == spec["title"]


@pytest.mark.parametrize(
    "code",
    [
        "__import__('os').system('x')",
        "math.sin(y_0).__class__",
        "open('/etc/passwd')",
        "os.getcwd()",
        "theta + 1",
        "'text'",
        "[y_0 for y_0 in p]",
        "lambda: 1",
    ],
)
def test_the_whitelist_refuses_anything_but_arithmetic_on_slots(code):
    with pytest.raises(ScriptError):
        checked_expression(code)


def test_the_whitelist_accepts_what_sympy_prints():
    assert checked_expression("-p_1*math.sin(y_0)/p_0 + x_3**2 + abs(y_2)") is not None
    assert checked_expression("(0.0 if y_1 == 0 else math.copysign(1, y_1))")


def test_get_script_reads_the_page_query_string(tmp_path):
    """The page's own query (?l=2&theta=0.5&method=rk4&dt=0.02&t_end=1) gives the same run as
    the POST with those values."""
    r = client.get(
        "/api/v1/export/scenes/simple_pendulum/run.py?l=2&theta=0.5&method=rk4&dt=0.02&t_end=1"
    )
    assert r.status_code == 200, r.text
    assert 'filename="simple_pendulum_run.py"' in r.headers["content-disposition"]
    ours = _run_script(r.text, tmp_path)
    api = client.post(
        "/api/v1/simulate",
        json={
            "scene_id": "simple_pendulum",
            "parameters": {"l": 2},
            "initial": {"theta": 0.5},
            "method": "rk4",
            "dt": 0.02,
            "t_end": 1,
        },
    ).json()
    assert np.max(np.abs(np.array(ours["q"]["theta"]) - api["q"]["theta"])) < 1e-9


def test_script_errors_name_the_field():
    r = client.post(
        "/api/v1/export/script",
        json={"scene_id": "simple_pendulum", "parameters": {"lenght": 1.0}},
    )
    assert r.status_code == 422
    assert r.json()["detail"][0]["field"] == "parameters.lenght"
    r = client.post("/api/v1/export/script", json={"scene_id": "no_such_scene"})
    assert r.status_code == 404
    r = client.get("/api/v1/export/scenes/simple_pendulum/run.py?method=rk4&dt=0")
    assert r.status_code == 422 and r.json()["detail"][0]["field"] == "dt"
    r = client.get("/api/v1/export/scenes/simple_pendulum/run.py?theta=nan")
    assert r.status_code == 422
    assert r.json()["detail"] == [
        {"field": "theta", "message": "must be a finite number, not 'nan'"}
    ]


@pytest.mark.parametrize("title", ["%(x)s", "100% %(prog)s", "%(prog)s %(x)s", "50 %", "%%"])
def test_a_title_with_percent_signs_keeps_the_scripts_help_working(title, tmp_path):
    """argparse %-formats a description holding "%(prog)": a posted title "%(prog)s %(x)s" made
    the exported script's --help raise KeyError (issue 24, item 6). The help prints the title
    as written."""
    from mechanics.scenes import load_scene

    scene = load_scene("simple_pendulum")
    scene["title"] = title
    r = client.post("/api/v1/export/script", json={"scene": scene, "t_end": 1})
    assert r.status_code == 200, r.text
    path = tmp_path / "run.py"
    path.write_text(r.text)
    done = subprocess.run(
        [sys.executable, str(path), "--help"], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    assert f"Integrate {title}" in " ".join(done.stdout.split())
