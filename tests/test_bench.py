"""The benchmarks keep working (they are run by hand, so nothing else would notice them rot).

Speed itself is not asserted here: only that each table is produced and the verdicts follow
from the numbers in it.
"""

from __future__ import annotations

import math

from benchmarks.integrate import TARGET_ENERGY, bench_target, print_target, speedup


def test_speedup_compares_with_the_most_accurate_baseline_we_can_match():
    rows = [
        {"method": "ours", "setting": 1e-6, "wall": 0.010, "error": 1e-3, "note": "ok"},
        {"method": "ours", "setting": 1e-9, "wall": 0.020, "error": 1e-7, "note": "ok"},
        {"method": "slow", "setting": 1e-9, "wall": 0.500, "error": 1e-8, "note": "ok"},
        {"method": "student a", "wall": 0.050, "error": 1e-2, "note": "baseline"},
        {"method": "student b", "wall": 0.400, "error": 1e-6, "note": "baseline"},
        {"method": "student c", "wall": 9.000, "error": 1e-12, "note": "baseline"},  # unmatched
    ]
    ratio, label = speedup(rows)
    assert math.isclose(ratio, 0.400 / 0.020) and "student b" in label and "ours" in label


def test_the_50_ms_target_table_runs_and_judges_each_row(capsys):
    rows = bench_target(runs=1)
    assert len(rows) == 9 and rows[-1]["what"].startswith("HTTP POST /api/v1/simulate")
    (compiled,) = [r for r in rows if r["what"] == "dop853_c rtol 1e-11"]
    assert compiled["energy"] <= TARGET_ENERGY  # the accuracy half of the target
    print_target(rows)
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 2 + len(rows)
    for row, line in zip(rows, lines[2:], strict=True):
        met = row["wall"] * 1e3 <= 50 and row["energy"] <= TARGET_ENERGY
        assert line.startswith(row["what"]) and line.endswith("not met" if not met else " met")
