"""``python -m benchmarks class``: a class that types its own answers, side by side.

The issue-24 measurement: 200 students (benchmarks/load.py), each sending values of its own
(parameters, initial state, answers to check), 2 s think time, with and without clients posting
heavy specs all along, and /simulate run with two methods side by side: the API's default (what a
REST client gets by sending no method) and ``DOP853``, the default before (scipy's stepper in
Python). Each configuration gets a fresh server and an empty cache; the machine's load average is
printed with each, since on a shared machine it moves every number.

    python -m benchmarks class --students 200 --think 2 --duration 60 --posters 0 4
"""

from __future__ import annotations

import argparse
import collections
import sys

from benchmarks.load import TARGETS_MS, percentile, print_config, run_config

ROUTES = (*TARGETS_MS, "healthz")


def _cell(result: dict, route: str) -> str:
    tally = result["tally"]
    ms = [x * 1e3 for x in tally.latencies.get(route, [])]
    errors = tally.errors.get(route, 0)
    if not ms:
        return f"{'-':>17} {errors:>4}"
    return f"{percentile(ms, 50):7.0f}/{percentile(ms, 95):<7.0f}  {errors:>4}"


def side_by_side(results: list[dict]) -> None:
    """p50/p95 (ms) and errors per route, one column per configuration."""
    names = [f"{r['method']}, {r['posters']} posters" for r in results]
    print("\n## side by side: p50/p95 ms and errors per route")
    print(f"{'route':<12} " + " ".join(f"{n:>23}" for n in names))
    for route in ROUTES:
        print(f"{route:<12} " + " ".join(f"{_cell(r, route):>23}" for r in results))
    loads = [" → ".join(f"{x:.1f}" for x in r["load"]) for r in results]
    print(f"{'load avg':<12} " + " ".join(f"{x:>23}" for x in loads))
    totals = [
        f"{sum(r['tally'].errors.values())} err, {sum(r['tally'].server_errors.values())} 5xx"
        for r in results
    ]
    print(f"{'all errors':<12} " + " ".join(f"{x:>23}" for x in totals))
    for r, name in zip(results, names, strict=True):
        outcomes = collections.Counter((kind, status) for kind, status, _ in r["tally"].hostile)
        if outcomes:
            said = ", ".join(f"{k} {s}: {n}" for (k, s), n in sorted(outcomes.items(), key=str))
            print(f"{name}: {said}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks class", description=__doc__)
    parser.add_argument("--students", type=int, default=200)
    parser.add_argument("--think", type=float, default=2.0)
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--workers", type=int, default=2, help="server processes (default 2)")
    parser.add_argument("--posters", type=int, nargs="+", default=[0, 4])
    parser.add_argument(
        "--methods",
        nargs="+",
        default=["default", "DOP853"],
        help="the students' /simulate method; 'default' sends none (default: default DOP853)",
    )
    args = parser.parse_args(argv)
    if not (0 < args.students <= 1000 and 1 <= args.workers <= 8 and args.duration > 0):
        parser.error("--students 1..1000, --workers 1..8, --duration > 0")
    results = []
    for posters in args.posters:
        for method in args.methods:
            result = run_config(
                args.workers,
                args.students,
                args.think,
                args.duration,
                0,
                method=None if method == "default" else method,
                posters=posters,
            )
            print_config(result)
            results.append(result)
            sys.stdout.flush()
    side_by_side(results)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
