"""What a student is told about a wrong answer to an open graded part holds no key (hostile
play-test of the assignments feature, item 1): the checker's feedback to "1" on the pendulum's T
was "Missing term 5 l² θ̇²/4", the key itself. While a graded part is open (attempts left, not
answered right, the assignment open) a student sees only the outcome's parameter-free
description; the full feedback is kept for the instructor and shown once the part is closed.

Each shipped template is deployed in graded mode and sent wrong answers of several kinds ("1",
"0", a term's sign flipped, a term left out) on every part; every answer a student can get (the
submit's answer and GET .../mine) is searched for each key expression and each of its additive
terms, in plain text and in LaTeX, as mechanics.expr writes them (derived here from the engine's
derivation of the variant, not taken from the preview)."""

from __future__ import annotations

import json

import pytest
import sympy as sp
from fastapi.testclient import TestClient

from app.assignments import routes, tokens
from app.assignments.db import forget_engines
from app.assignments.store import Store
from app.main import app
from mechanics.assignments import oscillations
from mechanics.assignments.keys import coordinate_index, derivation
from mechanics.assignments.template import shipped_templates
from mechanics.assignments.variants import Variant
from mechanics.check import expected_quantity
from mechanics.expr import to_latex, to_plain

API = "/api/v1/assignments"
#: Fields of a student's answer that are the student's own text (a sign-flipped key echoes the
#: key's other terms) or the scene as given: not searched.
OWN = {"answer", "answer_latex", "scene", "parameters", "prompt", "title"}
#: A needle this short ("g", "2 m") would match ordinary words; none of the keys' terms is.
SHORTEST = 5


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    folder = tmp_path_factory.mktemp("assignments-feedback")
    mp = pytest.MonkeyPatch()
    mp.setenv("LAGRANGE_LAB_DATABASE_URL", f"sqlite:///{folder / 'a.sqlite3'}")
    mp.setenv("LAGRANGE_LAB_POOL_WORKERS", "2")
    mp.setenv("LAGRANGE_LAB_SUBMISSIONS_PER_MINUTE", "10000")
    routes.reset_store()
    with TestClient(app) as c:
        yield c
    routes.reset_store()
    forget_engines()
    mp.undo()


@pytest.fixture(scope="module")
def teacher(client):
    return {"Authorization": f"Bearer {tokens.create(Store(), 'instructor', 'ada')}"}


def deploy_graded(client, teacher, template_id: str, max_attempts: int = 50) -> dict:
    """The shipped template as a graded assignment with one variant; its preview."""
    document = shipped_templates()[template_id].model_dump(mode="json", exclude_defaults=True)
    document |= {"id": f"g_{template_id}"[:24], "mode": "graded", "max_attempts": max_attempts}
    r = client.post(f"{API}/templates", json={"template": document}, headers=teacher)
    assert r.status_code == 201, r.text
    assignment = f"a_{template_id}_{max_attempts}"[:40]
    r = client.post(
        f"{API}/templates/{document['id']}/deploy",
        json={"assignment_id": assignment, "count": 1},
        headers=teacher,
    )
    assert r.status_code == 201, r.text
    return r.json()


def pupil(client, teacher, name: str) -> dict:
    r = client.post(f"{API}/students/tokens", json={"students": [name]}, headers=teacher)
    return {"Authorization": f"Bearer {r.json()['tokens'][name]}"}


def key_expressions(variant: Variant, part: dict) -> list[sp.Expr]:
    """The part's key as expressions (an equation of motion: both sides and their difference)."""
    d = derivation(variant)
    if part["quantity"] in oscillations.QUANTITIES:
        return [sp.sympify(oscillations.key(d, part))]
    j = coordinate_index(d, part)
    if part["quantity"] == "eom":
        lhs, rhs = d.work.eom_lhs[j], d.work.Q[j]
        return [lhs, rhs, sp.expand(lhs - rhs)]
    return [expected_quantity(d, part["quantity"], j)]


def needles(exprs: list[sp.Expr]) -> set[str]:
    """Every key expression and each of its additive terms, plain and LaTeX (and LaTeX as a JSON
    string escapes it)."""
    out = set()
    for expr in exprs:
        for e in {expr, *sp.Add.make_args(sp.expand(expr)), *sp.Add.make_args(expr)}:
            for text in (to_plain(e), to_latex(e)):
                out |= {text, json.dumps(text)[1:-1]}
    return {n for n in out if len(n.replace(" ", "")) >= SHORTEST}


def wrong_answers(variant: Variant, part: dict) -> dict[str, str]:
    """'1', '0', one term's sign flipped, one term left out (a one-term key: doubled)."""
    exprs = key_expressions(variant, part)
    key = exprs[2] if part["quantity"] == "eom" else exprs[0]
    terms = sp.Add.make_args(sp.expand(key))
    flipped = sp.Add(-terms[0], *terms[1:])
    dropped = sp.Add(*terms[1:]) if len(terms) > 1 else 2 * key
    if part["quantity"] == "eom":
        return {
            "one": "1 = 0",
            "zero": "0 = 0",
            "sign": f"{to_plain(flipped)} = 0",
            "missing": f"{to_plain(dropped)} = 0",
        }
    return {"one": "1", "zero": "0", "sign": to_plain(flipped), "missing": to_plain(dropped)}


def searchable(data) -> str:
    """Every string of a JSON answer but the student's own text and the given scene."""
    if isinstance(data, dict):
        return "\n".join(searchable(v) for k, v in data.items() if k not in OWN)
    if isinstance(data, list):
        return "\n".join(searchable(v) for v in data)
    return str(data)


@pytest.mark.parametrize("template_id", sorted(shipped_templates()))
def test_no_feedback_to_a_wrong_answer_holds_the_key(client, teacher, template_id):
    preview = deploy_graded(client, teacher, template_id)
    assignment = preview["assignment_id"]
    (shown,) = [v for v in preview["variants"] if v["deployable"]]
    variant = Variant.from_json(shown["variant"])
    headers = pupil(client, teacher, f"s_{template_id}")
    answers = []
    for part in variant.parts:
        exprs = key_expressions(variant, part)
        keys = needles(exprs)
        assert keys or all(len(to_plain(e)) < SHORTEST for e in exprs), part  # ("0")
        for kind, answer in wrong_answers(variant, part).items():
            r = client.post(
                f"{API}/{assignment}/parts/{part['id']}/submit",
                json={"answer": answer},
                headers=headers,
            )
            assert r.status_code == 200, (kind, answer, r.text)
            answers.append((part["id"], kind, r.json(), keys))
    mine = client.get(f"{API}/{assignment}/mine", headers=headers).json()
    every_key = set().union(*(k for *_, k in answers))
    for part_id, kind, body, keys in answers:
        if body["code"].split(".")[-1] in ("correct", "correct_up_to_constant"):
            continue  # a "wrong" answer that is right after all (0 as an equilibrium)
        text = searchable(body)
        leaked = [k for k in keys if k in text]
        assert not leaked, (part_id, kind, body["feedback"], leaked)
    text = searchable(mine)
    assert not [k for k in every_key if k in text]


def test_the_full_feedback_is_kept_and_shown_once_the_part_is_closed(client, teacher):
    """The instructor's report holds the checker's feedback; the student gets it when the
    assignment is closed (and, with max_attempts 1, after the one attempt)."""
    preview = deploy_graded(client, teacher, "pendulum_energies", max_attempts=2)
    assignment = preview["assignment_id"]
    variant = Variant.from_json(preview["variants"][0]["variant"])
    part = next(p for p in variant.parts if p["id"] == "T")
    key = key_expressions(variant, part)[0]
    headers = pupil(client, teacher, "closer")
    r = client.post(f"{API}/{assignment}/parts/T/submit", json={"answer": "1"}, headers=headers)
    assert r.status_code == 200
    open_feedback = r.json()["feedback"]
    assert not any(to_latex(key) in line for line in open_feedback), open_feedback
    assert r.json()["code"] == "T.missing_term"
    assert open_feedback[0] == "A term is missing."
    # the second (last) attempt closes the part: its feedback is the checker's, in full
    r = client.post(f"{API}/{assignment}/parts/T/submit", json={"answer": "0"}, headers=headers)
    mine = client.get(f"{API}/{assignment}/mine", headers=headers).json()
    (t,) = [p for p in mine["parts"] if p["id"] == "T"]
    assert t["attempts_left"] == 0
    assert any(to_latex(key) in line for line in t["last"]["feedback"]), t["last"]["feedback"]
    # another part, still open, until the assignment is closed
    r = client.post(f"{API}/{assignment}/parts/V/submit", json={"answer": "1"}, headers=headers)
    assert "Missing term" not in json.dumps(r.json()["feedback"]), r.json()
    client.post(f"{API}/{assignment}/close", headers=teacher)
    mine = client.get(f"{API}/{assignment}/mine", headers=headers).json()
    (v,) = [p for p in mine["parts"] if p["id"] == "V"]
    key_v = key_expressions(variant, next(p for p in variant.parts if p["id"] == "V"))[0]
    assert any(to_latex(key_v) in line for line in v["last"]["feedback"]), v["last"]


def test_practice_mode_keeps_the_full_feedback(client, teacher):
    """A practice assignment gives away nothing it grades: the checker's words at once."""
    document = shipped_templates()["pendulum_energies"].model_dump(
        mode="json", exclude_defaults=True
    )
    document |= {"id": "practice_pend", "mode": "practice"}
    assert client.post(f"{API}/templates", json={"template": document}, headers=teacher).is_success
    r = client.post(
        f"{API}/templates/practice_pend/deploy",
        json={"assignment_id": "practice1", "count": 1},
        headers=teacher,
    )
    variant = Variant.from_json(r.json()["variants"][0]["variant"])
    key = key_expressions(variant, next(p for p in variant.parts if p["id"] == "T"))[0]
    headers = pupil(client, teacher, "practiser")
    r = client.post(f"{API}/practice1/parts/T/submit", json={"answer": "1"}, headers=headers)
    assert any(to_latex(key) in line for line in r.json()["feedback"]), r.json()


def test_the_same_wrong_answer_again_is_no_new_attempt(client, teacher):
    """Typing an answer again returned the earlier attempt, whose number the one-row-per-attempt
    index refused a second time: a 409 "being scored" after every renumbering (found by the
    test above: "0" and "-0" to an equilibrium)."""
    preview = deploy_graded(client, teacher, "pendulum_energies", max_attempts=3)
    headers = pupil(client, teacher, "repeater")
    url = f"{API}/{preview['assignment_id']}/parts/T/submit"
    for _ in range(2):
        r = client.post(url, json={"answer": "1"}, headers=headers)
        assert r.status_code == 200, r.text
    mine = client.get(f"{API}/{preview['assignment_id']}/mine", headers=headers).json()
    (t,) = [p for p in mine["parts"] if p["id"] == "T"]
    assert (t["attempts_used"], t["attempts_left"]) == (1, 2)
