"""``/api/v1/assignments/...``: templates, deploy, preview with keys, a student's own variant,
submit a part, scores and the class report, for pages and course tools alike.

Every route needs ``Authorization: Bearer <token>``. Instructor routes refuse a student's token
(403); a student's routes answer only about that student's own variant, and no answer to a
student ever holds a key (while a graded part is open its feedback is only the outcome's
description: app/assignments/service.py `student_feedback`). Errors are in the app's one
shape; a database that cannot be reached is a 503 on field ``database`` that says so.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated, Any

from fastapi import APIRouter, Depends, Header, HTTPException, Request
from fastapi.responses import Response
from pydantic import BaseModel, Field
from sqlalchemy.exc import IntegrityError
from starlette.concurrency import run_in_threadpool

from mechanics.assignments import outcomes
from mechanics.assignments.template import parse_template, parse_template_text, template_hash

from . import report, service
from .db import DatabaseUnavailable
from .pages import router as pages_router
from .service import Refused
from .store import Store
from .tokens import digest

api = APIRouter(prefix="/api/v1/assignments", tags=["assignments"])

ERRORS = {
    401: {"description": "No token, or one this server does not know (field `authorization`)."},
    403: {"description": "A student's token on an instructor route (field `authorization`)."},
    404: {"description": "Unknown template, assignment or part (the field names which)."},
    503: {"description": "The database cannot be reached (field `database`); nothing stored."},
}


def fail(status: int, field: str, message: str) -> HTTPException:
    return HTTPException(status_code=status, detail=[{"field": field, "message": message}])


_store: Store | None = None


def store() -> Store:
    """The process's store (the configured database), opened and migrated on first use."""
    global _store
    if _store is None:
        _store = Store()
    return _store


def reset_store() -> None:
    """Forget the open store (tests that point LAGRANGE_LAB_DATABASE_URL elsewhere)."""
    global _store
    _store = None


def guarded(route: Callable[..., Any]) -> Callable[..., Any]:
    """Refusals and an unreachable database as answers in the one error shape."""

    @functools.wraps(route)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return route(*args, **kwargs)
        except Refused as r:
            raise fail(r.status, r.field, r.message) from None
        except DatabaseUnavailable as exc:
            raise fail(
                503, "database", f"the assignment database is unreachable ({exc}); try again"
            ) from None

    return wrapper


@dataclass(frozen=True)
class Caller:
    role: str
    subject: str


def caller(authorization: Annotated[str | None, Header()] = None) -> Caller:
    # the scheme's name is case-insensitive (RFC 7235 section 2.1): "bearer", "BEARER" too
    scheme, _, token = (authorization or "").strip().partition(" ")
    if scheme.lower() != "bearer" or not token.strip():
        raise fail(401, "authorization", "send 'Authorization: Bearer <token>'")
    try:
        row = store().token(digest(token.strip()))
    except DatabaseUnavailable as exc:
        raise fail(503, "database", f"the assignment database is unreachable ({exc})") from None
    if row is None:
        raise fail(401, "authorization", "unknown or revoked token")
    return Caller(row.role, row.subject)


def instructor(who: Annotated[Caller, Depends(caller)]) -> Caller:
    if who.role != "instructor":
        raise fail(403, "authorization", "an instructor's token is needed for this")
    return who


def student(who: Annotated[Caller, Depends(caller)]) -> Caller:
    if who.role != "student":
        raise fail(403, "authorization", "a student's token is needed: instructors preview")
    return who


def pooled(http: Request) -> service.Run:
    """The engine's jobs in the warm pool, under the check or derive budget."""
    from app.derivations import check_seconds, in_pool

    def run(
        job: Callable[..., Any],
        *args: Any,
        what: str,
        budget: str = "derive",
        affinity: str | None = None,
    ) -> Any:
        seconds = check_seconds() if budget == "check" else None
        field = "answer" if budget == "check" else "template"
        return in_pool(http, job, *args, affinity=affinity, what=what, seconds=seconds, field=field)

    return run


# -- request bodies ---------------------------------------------------------------------------
class TemplateBody(BaseModel):
    """A template as JSON (``template``) or as TOML text (``toml``)."""

    template: dict[str, Any] | None = None
    toml: str | None = Field(default=None, max_length=100_000)
    model_config = {
        "json_schema_extra": {
            "examples": [
                {
                    "template": {
                        "id": "pendulum_T",
                        "title": "The pendulum's kinetic energy",
                        "scene": "simple_pendulum",
                        "retry_penalty": 0.1,
                        "parameters": {"l": {"values": [0.5, 1.0]}},
                        "parts": [{"id": "T", "quantity": "T"}],
                    }
                }
            ]
        }
    }


class DeployBody(BaseModel):
    assignment_id: str = Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_-]{0,39}$")
    count: int = Field(default=10, ge=1, le=service.MAX_DEPLOY)
    seeds: list[Annotated[str, Field(min_length=1, max_length=200)]] = Field(
        default=[],
        max_length=service.MAX_DEPLOY,
        description="Pinned seeds (printed exams), deployed first.",
    )
    model_config = {
        "json_schema_extra": {
            "examples": [{"assignment_id": "week3", "count": 12, "seeds": ["exam-A", "exam-B"]}]
        }
    }


class SubmitBody(BaseModel):
    answer: str = Field(min_length=1, max_length=2000)
    request_id: str | None = Field(
        default=None,
        max_length=100,
        description="Any unique text: a retried request with the same id is not stored twice.",
    )
    model_config = {
        "json_schema_extra": {
            "examples": [{"answer": "m*l^2*theta_dot^2/2", "request_id": "b3f1c2"}]
        }
    }


class StudentTokenBody(BaseModel):
    students: list[Annotated[str, Field(min_length=1, max_length=100)]] = Field(
        min_length=1, max_length=500
    )
    model_config = {"json_schema_extra": {"examples": [{"students": ["s1001", "s1002"]}]}}


# -- instructor routes ---------------------------------------------------------------------------
@api.get("/outcome-codes", summary="The outcome-code table")
def get_codes() -> dict[str, Any]:
    """Every outcome kind (a code is `<T|V|L|Q|eom|accel|p>.<kind>`), what it means, and whether
    it scores the part in full. Public: it holds no key."""
    return {"prefixes": sorted(set(outcomes.PREFIX.values())), "kinds": outcomes.table()}


@api.get("/templates", responses=ERRORS, summary="Templates (shipped and stored)")
@guarded
def get_templates(who: Annotated[Caller, Depends(instructor)]) -> dict[str, Any]:
    from mechanics.assignments.template import shipped_templates

    stored = {t["id"]: t for t in store().templates()}
    out = [
        {"id": t.id, "title": t.title, "sha256": template_hash(t), "shipped": True}
        for t in shipped_templates().values()
        if t.id not in stored
    ]
    out += [
        {
            "id": t["id"],
            "title": t["document"].get("title", ""),
            "sha256": t["sha256"],
            "shipped": False,
        }
        for t in stored.values()
    ]
    return {"templates": sorted(out, key=lambda t: t["id"])}


@api.post("/templates", status_code=201, responses=ERRORS, summary="Store a template")
@guarded
def post_template(body: TemplateBody, who: Annotated[Caller, Depends(instructor)]) -> dict:
    """Validated (its scene, its parts' coordinates) and stored under its id; posting the same
    id again replaces it (assignments already deployed keep the document they were made from)."""
    if (body.template is None) == (body.toml is None):
        raise fail(422, "template", "send either 'template' (JSON) or 'toml' (text)")
    template = (
        parse_template(body.template)
        if body.template is not None
        else parse_template_text(body.toml or "")
    )
    sha = template_hash(template)
    store().put_template(template.id, sha, template.model_dump(mode="json", exclude_defaults=True))
    return {"id": template.id, "sha256": sha}


@api.get("/templates/{template_id}", responses=ERRORS, summary="One template")
@guarded
def get_template(template_id: str, who: Annotated[Caller, Depends(instructor)]) -> dict:
    template = service.find_template(store(), template_id)
    return {
        "sha256": template_hash(template),
        "template": template.model_dump(mode="json", exclude_defaults=True),
    }


@api.post(
    "/templates/{template_id}/deploy",
    status_code=201,
    responses=ERRORS,
    summary="Deploy variants (keys verified)",
)
def post_deploy(
    template_id: str, body: DeployBody, http: Request, who: Annotated[Caller, Depends(instructor)]
) -> dict:
    """Build `count` variants (pinned `seeds` first), verify every key by the second route, and
    store the assignment. The answer is the preview: each variant with its keys, and for one
    that is not deployed, why."""
    run = pooled(http)

    @guarded
    def work() -> dict:
        template = service.find_template(store(), template_id)
        try:
            return service.deploy(
                store(), template, body.assignment_id, body.count, body.seeds, run
            )
        except IntegrityError:
            raise Refused(409, "assignment_id", "that assignment exists already") from None

    return work()


@api.get("/{assignment_id}/preview", responses=ERRORS, summary="Variants with their keys")
@guarded
def get_preview(assignment_id: str, who: Annotated[Caller, Depends(instructor)]) -> dict:
    return service.preview(store(), assignment_id)


@api.post("/{assignment_id}/close", responses=ERRORS, summary="Close (or reopen) it")
@guarded
def post_close(
    assignment_id: str, who: Annotated[Caller, Depends(instructor)], closed: bool = True
) -> dict:
    service.preview(store(), assignment_id)  # 404 for an unknown one
    store().set_closed(assignment_id, closed)
    return {"assignment_id": assignment_id, "closed": closed}


@api.post("/students/tokens", status_code=201, responses=ERRORS, summary="Issue student tokens")
@guarded
def post_student_tokens(
    body: StudentTokenBody, who: Annotated[Caller, Depends(instructor)]
) -> dict:
    """One new token per student id; each is shown once (only its hash is stored)."""
    from .tokens import create

    return {"tokens": {s: create(store(), "student", s) for s in dict.fromkeys(body.students)}}


@api.get("/{assignment_id}/scores", responses=ERRORS, summary="Every student's scores")
@guarded
def get_scores(
    assignment_id: str, http: Request, who: Annotated[Caller, Depends(instructor)]
) -> dict:
    service.regrade_pending(store(), assignment_id, pooled(http), service.PENDING_SECONDS)
    return report.scores(store(), assignment_id)


@api.get("/{assignment_id}/report", responses=ERRORS, summary="The class report (JSON/CSV)")
@guarded
def get_report(
    assignment_id: str,
    http: Request,
    who: Annotated[Caller, Depends(instructor)],
    format: str = "json",
) -> Any:
    """Per part: the score histogram (10 bins over [0, 1]) and each outcome code's count, with
    the share of students who had it. ``?format=csv``: one row per (part, code)."""
    if format not in ("json", "csv"):
        raise fail(422, "format", "json or csv")
    service.regrade_pending(store(), assignment_id, pooled(http), service.PENDING_SECONDS)
    data = report.report(store(), assignment_id)
    if format == "csv":
        return Response(report.report_csv(data), media_type="text/csv; charset=utf-8")
    return data


# -- student routes ----------------------------------------------------------------------------
@api.get("/{assignment_id}/mine", responses=ERRORS, summary="My variant (no key)")
@guarded
def get_mine(assignment_id: str, who: Annotated[Caller, Depends(student)]) -> dict:
    """The caller's own variant: its scene, the parts, attempts left and scores. Never a key."""
    return service.student_view(store(), assignment_id, who.subject)


@api.post(
    "/{assignment_id}/parts/{part_id}/submit",
    responses={
        **ERRORS,
        409: {
            "description": "Closed, every attempt used, or a `request_id` already used for "
            "another part or answer (the field names which)."
        },
        429: {"description": "Too many submissions in a minute (field `answer`)."},
    },
    summary="Submit a part's answer",
)
async def post_submit(
    assignment_id: str,
    part_id: str,
    body: SubmitBody,
    http: Request,
    who: Annotated[Caller, Depends(student)],
) -> dict:
    """The answer is stored first, then judged by the checker and scored: `code` is the outcome
    code, `score` the penalised score of this attempt, `counted` whether it used an attempt
    ("cannot decide" and unreadable answers do not)."""
    run = pooled(http)

    @guarded
    def work() -> dict:
        return service.submit(
            store(), assignment_id, who.subject, part_id, body.answer, body.request_id, run
        )

    return await run_in_threadpool(work)


#: What app/main.py includes: the REST routes and the two pages (app/assignments/pages.py).
router = APIRouter()
router.include_router(api)
router.include_router(pages_router)
