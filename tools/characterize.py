"""What the app answers, saved so that a move of code can be shown to change none of it (issue 25).

Run by hand, not a test (tests state independent expectations; this pins today's bytes):

    python tools/characterize.py save OUT_DIR      # every answer below, one JSON file each
    python tools/characterize.py diff OLD NEW      # the files that differ, and where

It asks the app in-process (FastAPI's TestClient, a fresh cache folder) for `/derive`,
`/simulate` (defaults and two methods), `/equilibria`, `/newton`, 20 `/check` answers,
`/check/predict`, `/precision` and the live module, for the 14 built-in scenes and 5 posted
specs. What a run measures of the machine (wall times, the cache's own timings) is dropped
before saving: those differ between two runs of the same code.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

#: Keys whose values are the machine's timings, not the app's answers.
VOLATILE = {"seconds", "wall_ms", "elapsed", "elapsed_ms", "ms", "cpu_ms", "took_ms", "time_ms"}

#: Answers to check, on three scenes: right ones, wrong ones of each kind the checker names.
CHECKS = [
    ("simple_pendulum", "T", None, "1/2 m l^2 theta'^2"),
    ("simple_pendulum", "T", None, "m l^2 theta'^2"),
    ("simple_pendulum", "V", None, "-m g l cos(theta)"),
    ("simple_pendulum", "V", None, "m g l cos(theta)"),
    ("simple_pendulum", "L", None, "1/2 m l^2 theta'^2 + m g l cos(theta)"),
    ("simple_pendulum", "L", None, "1/2 m l^2 theta'^2"),
    ("simple_pendulum", "eom", "theta", "theta'' + g/l sin(theta) = 0"),
    ("simple_pendulum", "eom", "theta", "theta'' - g/l sin(theta) = 0"),
    ("simple_pendulum", "eom", "theta", "theta'' + g/l theta = 0"),
    ("simple_pendulum", "p", "theta", "m l^2 theta'"),
    ("cart_pendulum", "eom", "theta", "l theta'' + cos(theta) x'' + g sin(theta) = 0"),
    ("cart_pendulum", "eom", "theta", "l theta'' - cos(theta) x'' + g sin(theta) = 0"),
    ("cart_pendulum", "T", None, "1/2 (M + m) x'^2 + 1/2 m l^2 theta'^2"),
    ("double_pendulum", "V", None, "-(m1 + m2) g l1 cos(theta1) - m2 g l2 cos(theta2)"),
    ("double_pendulum", "V", None, "-(m1 - m2) g l1 cos(theta1) - m2 g l2 cos(theta2)"),
    ("bead_on_hoop", "T", None, "1/2 m R^2 (theta'^2 + w^2 sin(theta)^2)"),
    ("spring_mass_damper", "Q", "x", "-c x'"),
    ("spring_mass_damper", "Q", "x", "-c x' - k x"),
    ("particle_in_cone", "eom", "phi", "r phi'' + 2 r' phi' = 0"),
    ("atwood_machine", "eom", "x", "(m1 + m2) x'' = (m1 - m2) g"),
]

#: Posted specs beyond the catalog (a spring in a plane, a cycloid bead, a driven pendulum, a
#: turntable puck and a ladder with its wall stop).
_TESTS = Path(__file__).resolve().parent.parent / "tests"


def _posted() -> dict[str, dict]:
    sys.path.insert(0, str(_TESTS))
    import specs_beyond

    return {
        "ladder": specs_beyond.ladder(),
        "cylinder_in_cylinder": specs_beyond.cylinder_in_cylinder(),
        "turntable_cartesian": specs_beyond.turntable_cartesian(),
        "turntable_polar": specs_beyond.turntable_polar(),
        "driven_pendulum": {
            "title": "driven pendulum",
            "coordinates": ["theta"],
            "parameters": {"m": 1.0, "l": 1.0, "g": 9.81, "F": 0.5, "w": 2.0},
            "initial": {"theta": 0.4},
            "bodies": [
                {
                    "name": "bob",
                    "kind": "particle",
                    "mass": "m",
                    "position": ["l*sin(theta)", "-l*cos(theta)", 0],
                }
            ],
            "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
            "forces": [{"body": "bob", "vector": ["F*cos(w*t)", 0, 0]}],
        },
    }


def _strip(value):
    if isinstance(value, dict):
        return {k: _strip(v) for k, v in value.items() if k not in VOLATILE}
    if isinstance(value, list):
        return [_strip(v) for v in value]
    return value


def _requests(scene_ids: list[str], posted: dict[str, dict]):
    """(file name, method, path, body) for every answer saved."""
    targets = [(sid, {"scene_id": sid}) for sid in scene_ids]
    targets += [(name, {"scene": spec}) for name, spec in posted.items()]
    for name, ref in targets:
        yield f"{name}.derive", "POST", "/api/v1/derive", ref
        yield f"{name}.simulate", "POST", "/api/v1/simulate", {**ref, "t_end": 3}
        for method in ("rk4", "Radau"):
            body = {**ref, "t_end": 3, "method": method}
            if method == "rk4":
                body["dt"] = 0.01
            yield f"{name}.simulate.{method}", "POST", "/api/v1/simulate", body
        yield f"{name}.equilibria", "POST", "/api/v1/equilibria", ref
        yield f"{name}.newton", "POST", "/api/v1/newton", ref
        yield f"{name}.precision", "POST", "/api/v1/precision", {**ref, "t_end": 2}
        if "scene_id" in ref:
            yield f"{name}.live", "GET", f"/api/v1/scenes/{name}/live", None
        else:
            yield f"{name}.live", "POST", "/api/v1/scenes/live", ref
    for i, (sid, quantity, coordinate, answer) in enumerate(CHECKS):
        body = {"scene_id": sid, "quantity": quantity, "answer": answer}
        if coordinate:
            body["coordinate"] = coordinate
        yield f"check.{i:02d}.{sid}.{quantity}", "POST", "/api/v1/check", body
    yield (
        "predict.simple_pendulum",
        "POST",
        "/api/v1/check/predict",
        {
            "scene_id": "simple_pendulum",
            "quantity": "eom",
            "coordinate": "theta",
            "answer": "theta'' - g/l sin(theta) = 0",
        },
    )


def save(out: Path) -> None:
    os.environ["LAGRANGE_LAB_CACHE"] = tempfile.mkdtemp(prefix="characterize-")
    os.environ.setdefault("LAGRANGE_LAB_WARM", "0")
    from fastapi.testclient import TestClient

    from app.main import app
    from mechanics.scenes import scene_ids

    out.mkdir(parents=True, exist_ok=True)
    with TestClient(app) as client:
        for name, method, path, body in _requests(scene_ids(), _posted()):
            r = client.request(method, path, json=body)
            try:
                payload = _strip(r.json())
            except ValueError:
                payload = r.text
            record = {"status": r.status_code, "body": payload}
            text = json.dumps(record, indent=1, sort_keys=True, ensure_ascii=False)
            (out / f"{name}.json").write_text(text + "\n")
            print(f"{r.status_code} {name}", flush=True)


def _first_difference(a, b, where: str = "") -> str:
    if type(a) is not type(b):
        return f"{where}: {type(a).__name__} -> {type(b).__name__}"
    if isinstance(a, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                return f"{where}.{k}: only in {'new' if k in b else 'old'}"
            if a[k] != b[k]:
                return _first_difference(a[k], b[k], f"{where}.{k}")
    if isinstance(a, list):
        if len(a) != len(b):
            return f"{where}: {len(a)} -> {len(b)} items"
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            if x != y:
                return _first_difference(x, y, f"{where}[{i}]")
    return f"{where}: {str(a)[:80]!r} -> {str(b)[:80]!r}"


def diff(old: Path, new: Path) -> int:
    changed = 0
    for path in sorted(
        set(p.name for p in old.glob("*.json")) | set(p.name for p in new.glob("*.json"))
    ):
        a, b = old / path, new / path
        if not a.exists() or not b.exists():
            print(f"{path}: only in {'new' if b.exists() else 'old'}")
            changed += 1
        elif a.read_bytes() != b.read_bytes():
            print(
                f"{path}: {_first_difference(json.loads(a.read_text()), json.loads(b.read_text()))}"
            )
            changed += 1
    print(f"{changed} answers differ")
    return 1 if changed else 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "save":
        save(Path(sys.argv[2]))
    elif len(sys.argv) == 4 and sys.argv[1] == "diff":
        sys.exit(diff(Path(sys.argv[2]), Path(sys.argv[3])))
    else:
        sys.exit(__doc__)
