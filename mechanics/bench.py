"""Benchmarks: ``python -m mechanics.bench derive`` (and ``integrate``, in bench_integrate.py).

Side by side in one process, per built-in scene: the engine's cold derivation (every step,
simplified), its warm answer over HTTP, and sympy's LagrangesMethod followed by simplify() of the
mass matrix and forcing on the same system — the baseline a careful student would write. Ratios
rather than absolute times, because the machine's speed drifts.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import sympy as sp
from sympy.core.cache import clear_cache

from mechanics import oracle
from mechanics.derive import derivation_of_scene
from mechanics.scenes import scene_ids


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
    parser = argparse.ArgumentParser(prog="python -m mechanics.bench")
    sub = parser.add_subparsers(dest="what", required=True)
    d = sub.add_parser("derive", help="derivation cost per built-in scene vs sympy")
    d.add_argument("scenes", nargs="*", help="scene ids (default: all)")
    i = sub.add_parser("integrate", help="work-precision table of the integrators vs a baseline")
    i.add_argument("scenes", nargs="*", help="scene ids of the problems to run (default: all)")
    i.add_argument("--html", default="work-precision.html", help="where to write the diagram")
    args = parser.parse_args(argv)
    if args.what == "derive":
        print_derive(bench_derive(args.scenes or scene_ids()))
    else:
        from mechanics.bench_integrate import main as integrate_main

        integrate_main(args.scenes, args.html)
    return 0


if __name__ == "__main__":
    sys.exit(main())
