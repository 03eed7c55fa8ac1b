"""REST under /api/v1/assignments (issue 27, items 6 and 9): every instructor route refused for a
student's token, no route leaks a key to a student, errors in the app's one shape, a database
that cannot be reached said so with a 503, the routes in the OpenAPI document with examples."""

from __future__ import annotations

import json

import pytest
from fastapi.testclient import TestClient

from app.assignments import routes, tokens
from app.assignments.db import forget_engines
from app.assignments.store import Store
from app.main import app

TEMPLATE = {
    "id": "pend_api",
    "title": "Pendulum",
    "scene": "simple_pendulum",
    "parameters": {"l": {"values": [0.5, 1.0]}, "m": {"values": [2.0, 3.0], "given": True}},
    "parts": [
        {"id": "T", "quantity": "T"},
        {"id": "eom", "quantity": "eom", "coordinate": "theta", "weight": 2},
    ],
}
#: Every route, with path parameters that exist once the module's assignment is deployed, and
#: a body the route accepts.
ROUTES = [
    ("GET", "/api/v1/assignments/templates", None),
    ("POST", "/api/v1/assignments/templates", {"template": TEMPLATE}),
    ("GET", "/api/v1/assignments/templates/pend_api", None),
    ("POST", "/api/v1/assignments/templates/pend_api/deploy", {"assignment_id": "x2", "count": 1}),
    ("GET", "/api/v1/assignments/week1/preview", None),
    ("POST", "/api/v1/assignments/week1/close?closed=false", None),
    ("POST", "/api/v1/assignments/students/tokens", {"students": ["zz"]}),
    ("GET", "/api/v1/assignments/week1/scores", None),
    ("GET", "/api/v1/assignments/week1/report", None),
    ("GET", "/api/v1/assignments/week1/report?format=csv", None),
    ("GET", "/api/v1/assignments/week1/mine", None),
    ("POST", "/api/v1/assignments/week1/parts/T/submit", {"answer": "m*l*theta_dot"}),
    ("GET", "/api/v1/assignments/outcome-codes", None),
]
STUDENT_ROUTES = {"/api/v1/assignments/week1/mine", "/api/v1/assignments/week1/parts/T/submit"}
PUBLIC_ROUTES = {"/api/v1/assignments/outcome-codes"}


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    folder = tmp_path_factory.mktemp("assignments-api")
    mp = pytest.MonkeyPatch()
    mp.setenv("LAGRANGE_LAB_DATABASE_URL", f"sqlite:///{folder / 'a.sqlite3'}")
    mp.setenv("LAGRANGE_LAB_POOL_WORKERS", "2")
    routes.reset_store()
    with TestClient(app) as c:
        yield c
    routes.reset_store()
    forget_engines()
    mp.undo()


@pytest.fixture(scope="module")
def teacher(client):
    return {"Authorization": f"Bearer {tokens.create(Store(), 'instructor', 'ada')}"}


@pytest.fixture(scope="module")
def deployed(client, teacher):
    r = client.post("/api/v1/assignments/templates", json={"template": TEMPLATE}, headers=teacher)
    assert r.status_code == 201, r.text
    r = client.post(
        "/api/v1/assignments/templates/pend_api/deploy",
        json={"assignment_id": "week1", "count": 3, "seeds": ["exam-A"]},
        headers=teacher,
    )
    assert r.status_code == 201, r.text
    return r.json()


@pytest.fixture(scope="module")
def pupils(client, teacher, deployed):
    r = client.post(
        "/api/v1/assignments/students/tokens", json={"students": ["s1", "s2"]}, headers=teacher
    )
    assert r.status_code == 201
    return {s: {"Authorization": f"Bearer {t}"} for s, t in r.json()["tokens"].items()}


def call(client, method, path, body, headers):
    return client.request(method, path, json=body, headers=headers)


def test_deploy_answers_the_preview_with_verified_keys(deployed):
    assert [v["seed"] for v in deployed["variants"]] == ["exam-A", "1", "2"]
    for v in deployed["variants"]:
        assert v["deployable"], v["why_not"]
        assert {k["part"] for k in v["keys"]} == {"T", "eom"}
        assert all(k["verified"] and k["plain"] and k["latex"] for k in v["keys"])


INSTRUCTOR_ROUTES = [r for r in ROUTES if r[1] not in STUDENT_ROUTES | PUBLIC_ROUTES]
PRIVATE_ROUTES = [r for r in ROUTES if r[1] not in PUBLIC_ROUTES]


@pytest.mark.parametrize(
    ("method", "path", "body"), INSTRUCTOR_ROUTES, ids=[f"{m} {p}" for m, p, _ in INSTRUCTOR_ROUTES]
)
def test_every_instructor_route_refuses_a_students_token(client, pupils, method, path, body):
    r = call(client, method, path, body, pupils["s1"])
    assert r.status_code == 403, r.text
    assert r.json() == {
        "detail": [
            {"field": "authorization", "message": "an instructor's token is needed for this"}
        ]
    }


@pytest.mark.parametrize(
    ("method", "path", "body"), PRIVATE_ROUTES, ids=[f"{m} {p}" for m, p, _ in PRIVATE_ROUTES]
)
def test_no_route_answers_without_a_known_token(client, deployed, method, path, body):
    for headers in ({}, {"Authorization": "Bearer llab_not-a-token"}):
        r = call(client, method, path, body, headers)
        assert r.status_code == 401, r.text
        assert r.json()["detail"][0]["field"] == "authorization"


def test_an_instructor_cannot_submit_as_a_student(client, teacher, deployed):
    r = client.post(
        "/api/v1/assignments/week1/parts/T/submit", json={"answer": "1"}, headers=teacher
    )
    assert r.status_code == 403


def test_no_route_leaks_a_key_to_a_student(client, deployed, pupils):
    """Every answer a student can get, for each student, is searched for every key of every
    variant, as plain text and as LaTeX."""
    keys = [k for v in deployed["variants"] for k in v["keys"]]
    texts = []
    for headers in pupils.values():
        for method, path, body in ROUTES:
            texts.append(call(client, method, path, body, headers).text)
        texts.append(client.get("/api/v1/assignments/week1/mine", headers=headers).text)
    for text in texts:
        assert '"keys"' not in text and "expected_latex" not in text
        for k in keys:
            for shown in (k["plain"], k["latex"], json.dumps(k["latex"])[1:-1]):
                assert shown not in text, shown


def test_a_student_sees_their_own_variant_and_scores(client, deployed, pupils):
    mine = client.get("/api/v1/assignments/week1/mine", headers=pupils["s2"]).json()
    seeds = [v["seed"] for v in deployed["variants"]]
    assert mine["seed"] in seeds
    variant = deployed["variants"][seeds.index(mine["seed"])]
    m, length = variant["parameters"]["m"], variant["parameters"]["l"]
    assert mine["parameters"] == {"m": m, "l": length}
    assert "m" not in mine["scene"]["parameters"]  # the given mass is a number in the scene
    r = client.post(
        "/api/v1/assignments/week1/parts/T/submit",
        json={"answer": f"{m}*l^2*theta_dot^2/2", "request_id": "first"},
        headers=pupils["s2"],
    )
    assert r.status_code == 200, r.text
    done = r.json()
    assert (done["status"], done["code"], done["score"], done["attempt"]) == (
        "graded",
        "T.correct",
        1.0,
        1,
    )
    mine = client.get("/api/v1/assignments/week1/mine", headers=pupils["s2"]).json()
    assert mine["parts"][0]["score"] == 1.0
    assert mine["score"] == pytest.approx(1 / 3)  # T weighs 1 of 3


def test_scores_and_the_report_as_json_and_csv(client, teacher, deployed, pupils):
    client.post(
        "/api/v1/assignments/week1/parts/eom/submit",
        json={"answer": "l*theta_ddot + g*theta = 0"},
        headers=pupils["s1"],
    )
    scores = client.get("/api/v1/assignments/week1/scores", headers=teacher).json()
    assert {s["student"] for s in scores["students"]} >= {"s1"}
    report = client.get("/api/v1/assignments/week1/report", headers=teacher).json()
    eom = next(p for p in report["parts"] if p["part"] == "eom")
    assert {"code": "eom.small_angle", "submissions": 1, "students": 1} == {
        k: v for k, v in eom["codes"][0].items() if k != "share"
    }
    csv = client.get("/api/v1/assignments/week1/report?format=csv", headers=teacher)
    assert csv.headers["content-type"].startswith("text/csv")
    assert "eom,eom.small_angle,1,1," in csv.text


def test_errors_are_in_the_one_shape(client, teacher, pupils, deployed):
    r = client.get("/api/v1/assignments/nope/preview", headers=teacher)
    assert r.status_code == 404 and r.json()["detail"][0]["field"] == "assignment_id"
    r = client.get("/api/v1/assignments/templates/nope", headers=teacher)
    assert r.status_code == 404 and r.json()["detail"][0]["field"] == "template_id"
    r = client.post(
        "/api/v1/assignments/week1/parts/T/submit", json={"answer": ""}, headers=pupils["s1"]
    )
    assert r.status_code == 422 and r.json()["detail"][0]["field"] == "answer"
    r = client.post(
        "/api/v1/assignments/week1/parts/nope/submit", json={"answer": "1"}, headers=pupils["s1"]
    )
    assert r.status_code == 404 and r.json()["detail"][0]["field"] == "part_id"
    bad = {**TEMPLATE, "parts": [{"id": "e", "quantity": "eom"}]}
    r = client.post("/api/v1/assignments/templates", json={"template": bad}, headers=teacher)
    assert r.status_code == 422
    assert r.json()["detail"][0]["field"] == "parts[0].coordinate"
    r = client.post(
        "/api/v1/assignments/templates/pend_api/deploy",
        json={"assignment_id": "week1"},
        headers=teacher,
    )
    assert r.status_code == 409 and r.json()["detail"][0]["field"] == "assignment_id"


def test_an_unreadable_answer_is_no_attempt(client, pupils, deployed):
    r = client.post(
        "/api/v1/assignments/week1/parts/T/submit", json={"answer": "(m*l"}, headers=pupils["s1"]
    )
    assert r.status_code == 200
    assert (r.json()["code"], r.json()["counted"]) == ("T.unreadable", False)


def test_an_unreachable_database_is_a_503_that_says_so(client, teacher, tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("LAGRANGE_LAB_DATABASE_URL", f"sqlite:///{blocker / 'x.sqlite3'}")
    routes.reset_store()
    try:
        r = client.get("/api/v1/assignments/templates", headers=teacher)
    finally:
        monkeypatch.undo()
        routes.reset_store()
    assert r.status_code == 503
    (problem,) = r.json()["detail"]
    assert problem["field"] == "database"
    assert problem["message"].startswith("the assignment database is unreachable")


def test_the_routes_are_documented_with_examples(client):
    spec = client.get("/openapi.json").json()
    paths = [p for p in spec["paths"] if p.startswith("/api/v1/assignments")]
    assert len(paths) >= 10
    submit = spec["paths"]["/api/v1/assignments/{assignment_id}/parts/{part_id}/submit"]["post"]
    assert {"401", "403", "409", "429", "503"} <= set(submit["responses"])
    assert spec["components"]["schemas"]["SubmitBody"]["examples"]


def test_submissions_are_limited_per_student(client, pupils, deployed, monkeypatch):
    monkeypatch.setenv("LAGRANGE_LAB_SUBMISSIONS_PER_MINUTE", "1")
    url = "/api/v1/assignments/week1/parts/eom/submit"
    answers = ("theta_ddot = 0", "l*theta_ddot = 0")
    codes = [
        client.post(url, json={"answer": a}, headers=pupils["s2"]).status_code for a in answers
    ]
    assert codes[-1] == 429
    r = client.post(url, json={"answer": "g = 0"}, headers=pupils["s2"])
    assert r.json()["detail"][0]["field"] == "answer"
    other = client.get("/api/v1/assignments/week1/mine", headers=pupils["s1"])
    assert other.status_code == 200  # reading is not limited, nor another student


def test_a_graded_assignment_shows_only_the_steps_that_give_no_open_part_away():
    from app.assignments.service import shown_steps

    parts = [
        {"quantity": "T", "solved": False, "attempts_left": 2},
        {"quantity": "eom", "solved": False, "attempts_left": None},
    ]
    assert shown_steps("graded", False, parts) == ["fbd", "coordinates"]
    parts[0]["attempts_left"] = 1  # one wrong attempt: T is not done, nothing more is shown
    assert shown_steps("graded", False, parts) == ["fbd", "coordinates"]
    parts[0]["solved"] = True  # T right (at 0.9): velocities and energies shown, not the forces
    shown = shown_steps("graded", False, parts)
    assert {"kinematics", "energy"} <= set(shown) and not {"forces", "lagrange"} & set(shown)
    assert "lagrange" in shown_steps("graded", True, parts)  # closed: everything
    assert "lagrange" in shown_steps("practice", False, parts)


def test_a_request_id_is_one_submission_of_one_part(client, teacher, deployed):
    """Hostile play-test, item 2: a request_id reused on another part (or with another answer)
    answered 200 with the earlier submission of a different part, and the new answer was never
    stored; now a 409 naming request_id. The same request again is still the same submission."""
    r = client.post(
        "/api/v1/assignments/students/tokens", json={"students": ["rid"]}, headers=teacher
    )
    headers = {"Authorization": f"Bearer {r.json()['tokens']['rid']}"}
    url = "/api/v1/assignments/week1/parts/{}/submit"
    first = client.post(url.format("T"), json={"answer": "1", "request_id": "r1"}, headers=headers)
    assert first.status_code == 200 and first.json()["part"] == "T"
    again = client.post(url.format("T"), json={"answer": "1", "request_id": "r1"}, headers=headers)
    assert again.status_code == 200
    assert again.json()["submission_id"] == first.json()["submission_id"]
    for part, answer in (("eom", "1 = 0"), ("T", "2")):
        r = client.post(
            url.format(part), json={"answer": answer, "request_id": "r1"}, headers=headers
        )
        assert r.status_code == 409, r.text
        assert r.json()["detail"][0]["field"] == "request_id"
    mine = client.get("/api/v1/assignments/week1/mine", headers=headers).json()
    assert {p["id"]: p["attempts_used"] for p in mine["parts"]} == {"T": 1, "eom": 0}
    # another student may use the same id
    r = client.post(
        "/api/v1/assignments/students/tokens", json={"students": ["rid2"]}, headers=teacher
    )
    other = {"Authorization": f"Bearer {r.json()['tokens']['rid2']}"}
    r = client.post(url.format("eom"), json={"answer": "1 = 0", "request_id": "r1"}, headers=other)
    assert r.status_code == 200 and r.json()["part"] == "eom"


def test_the_bearer_scheme_is_case_insensitive(client, pupils, deployed):
    """Hostile play-test, item 3: RFC 7235 section 2.1 makes the scheme's name case-insensitive."""
    token = pupils["s1"]["Authorization"].removeprefix("Bearer ")
    for scheme in ("bearer", "BEARER", "Bearer"):
        headers = {"Authorization": f"{scheme} {token}"}
        r = client.get("/api/v1/assignments/week1/mine", headers=headers)
        assert r.status_code == 200, (scheme, r.text)
    for bad in (f"Basic {token}", "bearer", "bearer  ", token):
        r = client.get("/api/v1/assignments/week1/mine", headers={"Authorization": bad})
        assert r.status_code == 401 and r.json()["detail"][0]["field"] == "authorization"
