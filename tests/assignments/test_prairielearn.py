"""``lagrange-lab export prairielearn TEMPLATE DIR`` (issue 27, item 10): the question's
``generate(data)`` and ``grade(data)`` called the way PrairieLearn calls them."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys

import pytest

from mechanics.assignments.template import shipped_templates
from mechanics.assignments.variants import build_variant


@pytest.fixture(scope="module")
def question(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pl") / "pendulum"
    out = subprocess.run(
        [sys.executable, "-m", "app", "export", "prairielearn", "pendulum_energies", str(folder)],
        capture_output=True,
        text=True,
        check=True,
    )
    assert sorted(p.rsplit("/", 1)[-1] for p in out.stdout.split()) == [
        "info.json",
        "question.html",
        "server.py",
    ]
    spec = importlib.util.spec_from_file_location("pl_server", folder / "server.py")
    server = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(server)
    return folder, server


def generated(server, seed: int) -> dict:
    data = {"variant_seed": seed, "params": {}, "correct_answers": {}, "options": {}}
    server.generate(data)
    return data


def graded(server, data: dict, answers: dict) -> dict:
    data = {
        **data,
        "submitted_answers": answers,
        "partial_scores": {},
        "format_errors": {},
        "score": 0,
        "feedback": {},
    }
    server.grade(data)
    return data


def test_the_question_directory(question):
    folder, _ = question
    info = json.loads((folder / "info.json").read_text())
    assert info["type"] == "v3" and len(info["uuid"]) == 36
    html = (folder / "question.html").read_text()
    for part in ("T", "V", "L", "eom"):
        assert f'answers-name="{part}"' in html


def test_generate_builds_lagrange_labs_variant_for_the_seed(question):
    _, server = question
    data = generated(server, 4242)
    mine = build_variant(shipped_templates()["pendulum_energies"], "4242")
    assert data["params"]["variant"]["parameters"] == mine.parameters
    assert data["params"]["variant"]["spec"] == mine.spec
    assert set(data["correct_answers"]) == {"T", "V", "L", "eom"}
    # nothing the student sees holds a key
    shown = json.dumps({k: v for k, v in data["params"].items() if k != "variant"})
    assert not any(key in shown for key in data["correct_answers"].values())


def test_grade_fills_partial_scores_with_the_checkers_verdicts(question):
    _, server = question
    data = generated(server, 7)
    m = data["params"]["variant"]["parameters"]["m"]
    answers = {
        "T": f"{m}*l^2*theta_dot^2/2",  # right, by hand: ½ m l² θ̇²
        "V": f"{m}*g*l*cos(theta)",  # the sign of the whole
        "L": f"{m}*l^2*theta_dot^2/2 + {m}*g*l*cos(theta) + 2*theta*theta_dot",  # + d(θ²)/dt
        "eom": "l*theta_ddot + g*sin(theta) = 0",  # the equation divided by m l
    }
    out = graded(server, data, answers)
    scores = {k: v["score"] for k, v in out["partial_scores"].items()}
    assert scores == {"T": 1.0, "V": 0.0, "L": 0.5, "eom": 1.0}
    assert out["partial_scores"]["V"]["feedback"].startswith("V.negated")
    assert out["score"] == pytest.approx((1 + 0 + 0.5 + 2) / 5)


def test_unreadable_and_undecidable_answers_are_format_errors(question):
    _, server = question
    data = generated(server, 7)
    out = graded(server, data, {"T": "(theta_dot", "V": "", "L": "x"})
    assert set(out["format_errors"]) >= {"T", "V"}
    assert "T" not in out["partial_scores"]


def test_a_graded_questions_feedback_holds_no_key(question):
    """Hostile play-test, item 1: PrairieLearn shows the grader's feedback after every try, and
    the checker's "Missing term $\\frac{...}$" to an answer "1" was the key. A graded template's
    question says only the outcome's description: no math at all."""
    _, server = question
    data = generated(server, 7)
    out = graded(server, data, {"T": "1", "V": "0", "L": "1", "eom": "1 = 0"})
    for name, result in out["partial_scores"].items():
        assert result["score"] == 0.0
        assert "$" not in result["feedback"], result
        assert data["correct_answers"][name] not in result["feedback"]
    assert out["partial_scores"]["T"]["feedback"] == "T.missing_term: A term is missing."
