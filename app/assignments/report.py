"""Scores and the class report of an assignment: each student's best penalised score per part,
and per part the score histogram and the count of each outcome code (JSON and CSV)."""

from __future__ import annotations

import csv
import io
from collections import Counter, defaultdict
from typing import Any

from mechanics.assignments import grading

from .service import assignment_row
from .store import Store, attempt_of

HISTOGRAM_BINS = 10


def scores(store: Store, assignment_id: str) -> dict[str, Any]:
    """Each student's best penalised score per part and the weighted total."""
    row = assignment_row(store, assignment_id)
    parts = row.template["parts"]
    weights = [{"id": p["id"], "weight": p.get("weight", 1.0)} for p in parts]
    by_student: dict[str, dict[str, list]] = defaultdict(lambda: defaultdict(list))
    pending = Counter()
    for sub in store.submissions(assignment_id):
        if sub.status == "graded":
            by_student[sub.student][sub.part].append(attempt_of(sub))
        else:
            pending[sub.student] += 1
    seeds = {}
    variants = {v.id: v.seed for v in store.variants(assignment_id)}
    for e in store.enrolments(assignment_id):
        seeds[e.student] = variants.get(e.variant_id)
    students = []
    for student in sorted(set(seeds) | set(by_student)):
        part_scores = {p["id"]: grading.part_score(by_student[student][p["id"]]) for p in parts}
        students.append(
            {
                "student": student,
                "seed": seeds.get(student),
                "parts": part_scores,
                "attempts": {
                    p["id"]: sum(1 for a in by_student[student][p["id"]] if a.counted)
                    for p in parts
                },
                "pending": pending[student],
                "total": round(grading.total_score(weights, part_scores), 6),
            }
        )
    return {"assignment_id": assignment_id, "students": students}


def report(store: Store, assignment_id: str) -> dict[str, Any]:
    """Per part: the distribution of the students' scores (10 bins) and the count of each
    outcome code over the decided submissions, with the share of students who had it once."""
    table = scores(store, assignment_id)
    row = assignment_row(store, assignment_id)
    students = table["students"]
    codes: dict[str, Counter] = defaultdict(Counter)
    who: dict[str, dict[str, set]] = defaultdict(lambda: defaultdict(set))
    for sub in store.submissions(assignment_id):
        if sub.status == "graded" and sub.decided and sub.code:
            codes[sub.part][sub.code] += 1
            who[sub.part][sub.code].add(sub.student)
    parts = []
    for p in row.template["parts"]:
        values = [s["parts"][p["id"]] for s in students]
        bins = [0] * HISTOGRAM_BINS
        for v in values:
            bins[min(HISTOGRAM_BINS - 1, int(v * HISTOGRAM_BINS))] += 1
        parts.append(
            {
                "part": p["id"],
                "students": len(values),
                "mean": round(sum(values) / len(values), 6) if values else None,
                "histogram": bins,
                "codes": [
                    {
                        "code": code,
                        "submissions": n,
                        "students": len(who[p["id"]][code]),
                        "share": round(len(who[p["id"]][code]) / len(values), 6) if values else 0.0,
                    }
                    for code, n in codes[p["id"]].most_common()
                ],
            }
        )
    return {"assignment_id": assignment_id, "students": len(students), "parts": parts}


def report_csv(data: dict[str, Any]) -> str:
    """The report as CSV: one row per (part, outcome code); cells never start with = + - @."""
    out = io.StringIO()
    writer = csv.writer(out)
    writer.writerow(["part", "code", "submissions", "students", "share", "mean_score"])
    for part in data["parts"]:
        for c in part["codes"]:
            writer.writerow(
                [part["part"], c["code"], c["submissions"], c["students"], c["share"], part["mean"]]
            )
    return out.getvalue()
