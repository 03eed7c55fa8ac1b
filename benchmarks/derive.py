"""Benchmarks: ``python -m benchmarks derive`` (and ``integrate``, in bench_integrate.py).

Side by side in one process, per built-in scene: the engine's cold derivation (every step,
simplified), its warm answer over HTTP, and sympy's LagrangesMethod followed by simplify() of the
mass matrix and forcing on the same system — the baseline a careful student would write. Ratios
rather than absolute times, because the machine's speed drifts.

Then systems larger than any built-in scene (a triple pendulum, a heavy symmetric top through
three Euler rotations, a six-link chain, and benchmarks/systems.py's restricted three-body
problem and conical pendulums of two and three links), each derived cold: a fresh process with an
empty cache, the way a posted scene is first derived. Wall and CPU seconds, median of a few runs,
and the 1-minute load average when each system started (the machine is shared: CPU seconds are
the steadier number under load).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import sympy as sp
from sympy.core.cache import clear_cache

from benchmarks.systems import LARGE_SYSTEMS
from mechanics import oracle
from mechanics.derive import derivation_of_scene
from mechanics.scenes import scene_ids


def chain_spec(n: int) -> dict:
    """n bobs on n rods, each angle measured from the downward vertical (absolute angles)."""
    bodies = []
    for i in range(1, n + 1):
        components = [f"l{i}*sin(theta{i})", f"-l{i}*cos(theta{i})", 0]
        position = (
            components
            if i == 1
            else {"frame": "N", "components": components, "from": f"bob{i - 1}"}
        )
        bodies.append({"name": f"bob{i}", "mass": f"m{i}", "position": position})
    parameters = {"g": 9.81} | {f"{p}{i}": 1.0 for i in range(1, n + 1) for p in ("m", "l")}
    return {
        "title": f"{n}-link chain",
        "coordinates": [f"theta{i}" for i in range(1, n + 1)],
        "parameters": parameters,
        "bodies": bodies,
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }


#: A heavy symmetric top: frames z by psi, x by theta, z by phi; inertia A, A, C about its centre
#: of mass, which sits l along the body axis from the fixed point O.
HEAVY_TOP = {
    "title": "Heavy symmetric top",
    "coordinates": ["psi", "theta", "phi"],
    "parameters": {"m": 1.0, "A": 1.0, "C": 0.5, "l": 1.0, "g": 9.81},
    "frames": [
        {"name": "P", "parent": "N", "axis": "z", "angle": "psi"},
        {"name": "Q", "parent": "P", "axis": "x", "angle": "theta"},
        {"name": "B", "parent": "Q", "axis": "z", "angle": "phi"},
    ],
    "bodies": [
        {
            "name": "top",
            "kind": "rigid_body",
            "mass": "m",
            "frame": "B",
            "position": {"frame": "B", "components": [0, 0, "l"]},
            "inertia": {"ixx": "A", "iyy": "A", "izz": "C"},
        }
    ],
    "gravity": {"acceleration": "g", "direction": [0, 0, -1]},
}

#: Systems past the built-in catalog, derived cold by `bench_systems` (and checked against
#: LagrangesMethod in tests/derivation/test_determinism.py).
SYSTEMS = {
    "triple_pendulum": chain_spec(3),
    "heavy_top": HEAVY_TOP,
    "six_link_chain": chain_spec(6),
    **LARGE_SYSTEMS,  # issue 23, item 8: the three-body problem, conical pendulums
}

#: One cold derivation in a fresh process: prints import and derive seconds (wall, CPU) as JSON.
_COLD_CHILD = """
import json, sys, time
w0, c0 = time.perf_counter(), time.process_time()
from mechanics.derive import derive
w1, c1 = time.perf_counter(), time.process_time()
out = derive(json.loads(sys.argv[1]))
w2, c2 = time.perf_counter(), time.process_time()
print(json.dumps({"import_s": w1 - w0, "derive_s": w2 - w1, "derive_cpu_s": c2 - c1,
                  "total_s": w2 - w0, "solved": out["equations"]["accelerations"] is not None}))
"""


def bench_systems(names: list[str], runs: int = 3) -> list[dict]:
    """Cold derive cost of each named system: fresh process, empty cache, median of ``runs``."""
    rows = []
    for name in names:
        samples = []
        load = os.getloadavg()[0]
        for _ in range(runs):
            with tempfile.TemporaryDirectory(prefix="lagrange-lab-bench-") as empty:
                env = os.environ | {"LAGRANGE_LAB_CACHE": empty}
                done = subprocess.run(
                    [sys.executable, "-c", _COLD_CHILD, json.dumps(SYSTEMS[name])],
                    env=env,
                    capture_output=True,
                    text=True,
                    check=True,
                )
            samples.append(json.loads(done.stdout))
        row = {"system": name, "solved": samples[0]["solved"], "load": load}
        for key in ("import_s", "derive_s", "derive_cpu_s", "total_s"):
            row[key] = statistics.median(s[key] for s in samples)
        rows.append(row)
    return rows


def print_systems(rows: list[dict]) -> None:
    head = (
        f"{'system (cold, fresh process)':<30} {'import s':>8} {'derive s':>8} {'CPU s':>6} "
        f"{'total s':>7} {'load':>5}  q̈ solved"
    )
    print(head)
    print("-" * len(head))
    for r in rows:
        print(
            f"{r['system']:<30} {r['import_s']:8.2f} {r['derive_s']:8.2f} "
            f"{r['derive_cpu_s']:6.2f} {r['total_s']:7.2f} {r['load']:5.2f}  "
            f"{'yes' if r['solved'] else 'no'}"
        )


def _size(exprs) -> int:
    return int(sum(sp.count_ops(e) for e in exprs))


def _http_server():
    """A real uvicorn server on a free loopback port (in a thread) and a keep-alive client:
    returns send(path, body) -> response bytes."""
    import http.client
    import json
    import socket
    import threading

    import uvicorn

    from app.main import app

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    threading.Thread(target=server.run, daemon=True).start()
    while not server.started:
        time.sleep(0.01)
    conn = http.client.HTTPConnection("127.0.0.1", port)

    def send(path: str, body: dict) -> bytes:
        conn.request("POST", path, json.dumps(body), {"content-type": "application/json"})
        response = conn.getresponse()
        data = response.read()
        if response.status != 200:
            raise RuntimeError(f"{path} {body}: HTTP {response.status}")
        return data

    return send


def _http_client():
    """POST /api/v1/derive for a scene id, over real HTTP."""
    send = _http_server()
    return lambda scene_id: send("/api/v1/derive", {"scene_id": scene_id})


def bench_derive(ids: list[str], warm_runs: int = 50, baseline_budget: float = 60.0) -> list[dict]:
    """Cold and warm derive time, printed size, and the sympy baseline, per scene."""
    post = _http_client()
    # One untimed round first, so lazy imports inside sympy count against neither side.
    oracle.lagranges_method(derivation_of_scene("simple_pendulum").model)
    rows = []
    for scene_id in ids:
        clear_cache()
        derivation_of_scene.cache_clear()
        start = time.perf_counter()
        d = derivation_of_scene(scene_id)
        cold = time.perf_counter() - start
        printed = d.work.accelerations if d.work.accelerations is not None else d.work.eom_lhs
        post(scene_id)  # fill the response cache
        warm = []
        for _ in range(warm_runs):
            t0 = time.perf_counter()
            post(scene_id)
            warm.append(time.perf_counter() - t0)
        clear_cache()
        t0 = time.perf_counter()
        lm = oracle.lagranges_method(d.model)
        formed = time.perf_counter() - t0
        simplified_size = None
        M, f = lm.mass_matrix, lm.forcing
        if time.perf_counter() - t0 < baseline_budget:
            M, f = sp.simplify(M), sp.simplify(f)
            simplified_size = _size(list(M) + list(f))
        base = time.perf_counter() - t0
        ours_size = _size(list(d.work.mass_matrix) + list(d.work.forcing))
        rows.append(
            {
                "scene": scene_id,
                "cold_s": cold,
                "warm_ms": statistics.median(warm) * 1e3,
                "printed_ops": _size(printed),
                "Mf_ops": ours_size,
                "sympy_form_s": formed,
                "sympy_total_s": base,
                "sympy_Mf_ops": simplified_size,
                "ratio": cold / base,
            }
        )
    return rows


def print_derive(rows: list[dict]) -> None:
    head = (
        f"{'scene':<20} {'cold s':>7} {'warm ms':>8} {'q̈/EoM ops':>10} {'M,f ops':>8} "
        f"{'sympy LM s':>10} {'LM+simp s':>9} {'simp ops':>8} {'cold/LM+simp':>12}"
    )
    print(head)
    print("-" * len(head))
    for r in rows:
        print(
            f"{r['scene']:<20} {r['cold_s']:7.3f} {r['warm_ms']:8.2f} {r['printed_ops']:10d} "
            f"{r['Mf_ops']:8d} {r['sympy_form_s']:10.3f} {r['sympy_total_s']:9.3f} "
            f"{r['sympy_Mf_ops'] if r['sympy_Mf_ops'] is not None else '-':>8} "
            f"{r['ratio']:12.2f}"
        )
    print(
        f"\nworst cold: {max(r['cold_s'] for r in rows):.3f} s; "
        f"worst warm: {max(r['warm_ms'] for r in rows):.2f} ms; "
        f"worst cold/(LM+simplify): {max(r['ratio'] for r in rows):.2f}"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks")
    sub = parser.add_subparsers(dest="what", required=True)
    d = sub.add_parser(
        "derive", help="derivation cost per built-in scene vs sympy, then larger systems cold"
    )
    d.add_argument(
        "scenes", nargs="*", help=f"scene ids and/or {', '.join(SYSTEMS)} (default: all)"
    )
    d.add_argument("--runs", type=int, default=3, help="cold runs per larger system (median)")
    i = sub.add_parser("integrate", help="work-precision table of the integrators vs a baseline")
    i.add_argument("scenes", nargs="*", help="scene ids of the problems to run (default: all)")
    i.add_argument("--html", default="work-precision.html", help="where to write the diagram")
    load = sub.add_parser(
        "load", help="a crowd of simulated students against a real server on loopback"
    )
    load.add_argument("--students", type=int, default=50, help="crowd size (default 50)")
    load.add_argument("--think", type=float, default=2.0, help="mean think time, s (default 2)")
    load.add_argument("--duration", type=float, default=20.0, help="seconds per run (default 20)")
    load.add_argument(
        "--workers", type=int, nargs="+", default=[1, 2], help="server workers to try (1 2)"
    )
    load.add_argument(
        "--hostile", type=int, nargs="+", default=[0, 10], help="hostile requests per run (0 10)"
    )
    args = parser.parse_args(argv)
    if args.what == "load":
        from benchmarks.load import main as load_main

        if not 1 <= args.students <= 1000 or not 0 < args.duration <= 600:
            parser.error("--students must be 1..1000 and --duration 0..600 s")
        if args.think < 0 or any(w < 1 or w > 8 for w in args.workers):
            parser.error("--think must be ≥ 0 and --workers 1..8")
        if any(h < 0 or h > 100 for h in args.hostile):
            parser.error("--hostile must be 0..100")
        return load_main(args.students, args.think, args.duration, args.workers, args.hostile)
    if args.what == "derive":
        scenes = [s for s in args.scenes if s not in SYSTEMS] if args.scenes else scene_ids()
        systems = [s for s in args.scenes if s in SYSTEMS] if args.scenes else list(SYSTEMS)
        if scenes:
            print_derive(bench_derive(scenes))
        if systems:
            print("\n" if scenes else "", end="")
            print_systems(bench_systems(systems, max(1, min(args.runs, 9))))
    else:
        from benchmarks.integrate import main as integrate_main

        integrate_main(args.scenes, args.html)
    return 0


if __name__ == "__main__":
    sys.exit(main())
