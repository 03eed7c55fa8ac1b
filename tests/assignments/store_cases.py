"""What every database must do for assignments (issue 27, item 5), written once and run on
SQLite (test_store_sqlite.py) and on a real PostgreSQL (test_store_postgres.py): each module
gives a fixture ``url`` of an empty database."""

from __future__ import annotations

import pytest
from sqlalchemy import inspect, select, text
from sqlalchemy.exc import IntegrityError

from app.assignments import report, service, tokens
from app.assignments.db import DatabaseUnavailable, engine_for, make_engine, migrate
from app.assignments.models import Base, SubmissionRow, TokenRow
from app.assignments.store import Store
from mechanics.assignments.template import parse_template

PENDULUM = {
    "id": "pend",
    "title": "Pendulum",
    "scene": "simple_pendulum",
    "retry_penalty": 0.25,
    "max_attempts": 3,
    "parameters": {"l": {"values": [0.5, 1.0, 2.0]}},
    "parts": [{"id": "T", "quantity": "T"}, {"id": "V", "quantity": "V", "weight": 3}],
}
RIGHT_T = "m*l^2*theta_dot^2/2"
RIGHT_V = "-m*g*l*cos(theta)"


@pytest.fixture
def store(url):
    service.forget_verdicts()  # each case judges its answers afresh
    return Store(engine_for(url))


@pytest.fixture
def deployed(store):
    service.deploy(store, parse_template(PENDULUM), "week1", 2, ["exam-A"])
    return store


def test_migrations_make_the_tables_the_models_declare(url):
    engine = engine_for(url)
    found = inspect(engine)
    for table in Base.metadata.sorted_tables:
        columns = {c["name"] for c in found.get_columns(table.name)}
        assert columns == {c.name for c in table.columns}, table.name
    indexes = {i["name"] for i in found.get_indexes("submissions")}
    assert "uq_submission_attempt" in indexes
    migrate(engine)  # twice: nothing to do, no error
    with engine.connect() as c:
        assert c.execute(text("select version_num from alembic_version")).scalar() == "0002"


def test_a_token_is_stored_only_as_its_hash(store, url):
    token = tokens.create(store, "instructor", "ada")
    with engine_for(url).connect() as c:
        rows = c.execute(select(TokenRow.__table__)).all()
    assert len(rows) == 1 and token not in repr(rows)
    assert store.token(tokens.digest(token)).subject == "ada"
    assert store.token(tokens.digest(token + "x")) is None


def test_deploy_stores_every_variant_with_its_verified_keys(deployed):
    preview = service.preview(deployed, "week1")
    assert [v["seed"] for v in preview["variants"]] == ["exam-A", "1"]
    for v in preview["variants"]:
        assert v["deployable"] and v["keys"] and all(k["verified"] for k in v["keys"])


def test_a_restart_serves_the_same_variant_and_scores(deployed, url):
    first = service.submit(deployed, "week1", "s1", "T", RIGHT_T)
    view = service.student_view(deployed, "week1", "s1")
    again = Store(make_engine(url))  # a new engine: another server, or this one restarted
    assert service.student_view(again, "week1", "s1") == view
    assert first["score"] == 1.0 and view["parts"][0]["score"] == 1.0


def test_the_same_answer_is_judged_once_for_a_class(deployed):
    calls = []

    def counted(job, *args, **kwargs):
        calls.append(args)
        return job(*args)

    for student in ("m1", "m2", "m3"):
        service.submit(deployed, "week1", student, "V", "m*g*l*cos(theta)", run=counted)
    variants = {deployed.variant_of("week1", s).seed for s in ("m1", "m2", "m3")}
    assert len(calls) == len(variants)  # once per variant, not once per student


def test_the_answer_is_stored_before_it_is_judged(deployed):
    def killed(*args, **kwargs):
        raise KeyboardInterrupt  # the server stops while judging

    with pytest.raises(KeyboardInterrupt):
        service.submit(deployed, "week1", "s2", "T", RIGHT_T, run=killed)
    (row,) = deployed.pending("week1")
    assert (row.student, row.answer, row.status) == ("s2", RIGHT_T, "pending")
    assert service.regrade_pending(deployed, "week1") == 1
    assert deployed.pending("week1") == []
    assert report.scores(deployed, "week1")["students"][0]["parts"]["T"] == 1.0


def test_a_retried_request_is_not_a_second_submission(deployed, url):
    a = service.submit(deployed, "week1", "s3", "T", "m*l^2*theta_dot^2", request_id="r1")
    b = service.submit(deployed, "week1", "s3", "T", "m*l^2*theta_dot^2", request_id="r1")
    assert a == b
    with engine_for(url).connect() as c:
        n = c.execute(select(SubmissionRow.id).where(SubmissionRow.student == "s3")).all()
    assert len(n) == 1


def test_penalties_and_best_score_across_the_database(deployed):
    wrong = service.submit(deployed, "week1", "s4", "V", "m*g*l*cos(theta)")
    right = service.submit(deployed, "week1", "s4", "V", RIGHT_V)
    assert (wrong["attempt"], wrong["score"], wrong["code"]) == (1, 0.0, "V.negated")
    assert (right["attempt"], right["score"]) == (2, 0.75)
    (row,) = report.scores(deployed, "week1")["students"]
    assert row["parts"] == {"T": 0.0, "V": 0.75}
    assert row["total"] == pytest.approx(0.75 * 3 / 4)


def test_attempts_run_out_and_the_rate_limit_holds(deployed, monkeypatch):
    for answer in ("0", "1*m", "2*m"):
        service.submit(deployed, "week1", "s5", "T", answer + "*l^2*theta_dot^2")
    with pytest.raises(service.Refused) as used_up:
        service.submit(deployed, "week1", "s5", "T", RIGHT_T)
    assert (used_up.value.status, used_up.value.field) == (409, "answer")
    monkeypatch.setenv(service.RATE_ENV, "3")
    with pytest.raises(service.Refused) as limited:
        service.submit(deployed, "week1", "s5", "V", RIGHT_V)
    assert limited.value.status == 429


def test_the_report_counts_outcome_codes(deployed):
    service.submit(deployed, "week1", "a", "T", "m*l^2*theta_dot^2")  # factor 2
    service.submit(deployed, "week1", "b", "T", "m*l^2*theta_dot^2")
    service.submit(deployed, "week1", "b", "T", RIGHT_T)
    service.submit(deployed, "week1", "c", "T", "m*l^2*theta_dot^2/2 + exp(-10^6*theta_dot^2)")
    data = report.report(deployed, "week1")
    part = data["parts"][0]
    codes = {c["code"]: (c["submissions"], c["students"]) for c in part["codes"]}
    assert codes == {"T.wrong_factor": (2, 2), "T.correct": (1, 1)}  # cannot_decide: not counted
    assert part["students"] == 3
    assert part["histogram"][0] == 2 and part["histogram"][7] == 1  # 0, 0, 0.75
    csv = report.report_csv(data)
    assert "T,T.wrong_factor,2,2," in csv


def test_an_assignment_and_its_variants_are_stored_together_or_not_at_all(store):
    template = PENDULUM
    rows = [
        {
            "seed": "1",
            "engine_version": 1,
            "variant": {},
            "keys": {},
            "deployable": True,
            "why_not": "",
        },
        {
            "seed": "1",
            "engine_version": 1,
            "variant": {},
            "keys": {},
            "deployable": True,
            "why_not": "",
        },
    ]
    with pytest.raises(IntegrityError):
        store.create_assignment("half", template, "0" * 64, rows)
    assert store.assignment("half") is None and store.variants("half") == []


def test_a_closed_assignment_refuses_submissions(deployed):
    deployed.set_closed("week1", True)
    with pytest.raises(service.Refused) as closed:
        service.submit(deployed, "week1", "s6", "T", RIGHT_T)
    assert closed.value.status == 409


def test_an_unreachable_database_says_so(unreachable_url):
    with pytest.raises(DatabaseUnavailable):
        engine_for(unreachable_url)


def test_a_variant_from_another_engine_keeps_its_key_only_if_it_still_holds(deployed, url):
    """A regrade on a newer engine: the stored key must still be judged right, else the part
    cannot be decided (no attempt used) rather than graded against another key."""
    from sqlalchemy import update

    from app.assignments.models import VariantRow

    chosen = deployed.variant_of("week1", "old")
    keys = dict(chosen.keys)
    keys["parts"] = [
        {**k, "plain": "2*" + k["plain"]} if k["part"] == "T" else k for k in keys["parts"]
    ]  # a key this engine does not agree with
    variant = {**chosen.variant, "engine_version": -1}
    with engine_for(url).begin() as c:
        c.execute(
            update(VariantRow).where(VariantRow.id == chosen.id).values(variant=variant, keys=keys)
        )
    fresh = Store(make_engine(url))
    t = service.submit(fresh, "week1", "old", "T", RIGHT_T)
    assert (t["code"], t["counted"]) == ("T.cannot_decide", False)
    v = service.submit(fresh, "week1", "old", "V", RIGHT_V)  # its key still holds
    assert (v["code"], v["score"]) == ("V.correct", 1.0)


def test_two_tabs_submitting_at_once_get_two_attempt_numbers(deployed):
    """Both read 'no attempt used' before either is scored; the database's unique attempt
    number (migration 0002) makes the second renumber itself as attempt 2."""
    import threading

    both_judging = threading.Barrier(2, timeout=30)

    def together(job, *args, **kwargs):
        both_judging.wait()
        return job(*args)

    results = []

    def tab(answer):
        results.append(service.submit(deployed, "week1", "tabs", "T", answer, run=together))

    threads = [threading.Thread(target=tab, args=(a,)) for a in ("m*l^2*theta_dot^2", RIGHT_T)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert sorted(r["attempt"] for r in results) == [1, 2]
