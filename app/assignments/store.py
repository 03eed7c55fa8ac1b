"""Every read and write of the assignment tables, in one class; nothing else opens a session.

Each method is one short transaction. A database that cannot be reached (or drops the
connection) raises `DatabaseUnavailable`, which the routes answer as a 503 saying so; a method
that fails leaves nothing half-written (its transaction is rolled back).
"""

from __future__ import annotations

import functools
import hashlib
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from datetime import UTC, datetime, timedelta
from typing import Any, TypeVar

from sqlalchemy import Engine, func, select
from sqlalchemy.exc import DBAPIError, IntegrityError, OperationalError
from sqlalchemy.orm import Session

from mechanics.assignments import outcomes
from mechanics.assignments.grading import Attempt, Judged

from .db import DatabaseUnavailable, describe, engine_for
from .models import (
    AssignmentRow,
    EnrolmentRow,
    SubmissionRow,
    TemplateRow,
    TokenRow,
    VariantRow,
)

F = TypeVar("F", bound=Callable[..., Any])


def _reachable(method: F) -> F:
    """A lost database becomes DatabaseUnavailable (the transaction is already rolled back)."""

    @functools.wraps(method)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return method(*args, **kwargs)
        except IntegrityError:
            raise
        except (OperationalError, DBAPIError) as exc:
            raise DatabaseUnavailable(describe(exc)) from None

    return wrapper  # type: ignore[return-value]


def student_choice(assignment_id: str, student: str, count: int) -> int:
    """Which of ``count`` deployed variants a student gets: sha256 of (assignment, student)."""
    digest = hashlib.sha256(f"{assignment_id}\x00{student}".encode()).digest()
    return int.from_bytes(digest[:8], "big") % count


def attempt_of(row: SubmissionRow) -> Attempt:
    kind = (row.code or "").split(".", 1)[-1]
    judged = Judged(
        row.code or "",
        list(row.codes or []),
        bool(row.decided),
        kind in outcomes.CREDIT,
        list(row.feedback or []),
        row.answer_latex or "",
    )
    return Attempt(row.answer, judged, bool(row.counted), row.number, row.raw, row.score)


class Store:
    def __init__(self, engine: Engine | None = None) -> None:
        self.engine = engine or engine_for()
        #: Variants never change once stored: kept by id after their first read.
        self._variants: dict[int, VariantRow] = {}

    @contextmanager
    def session(self) -> Iterator[Session]:
        with Session(self.engine, expire_on_commit=False) as session, session.begin():
            yield session

    # -- templates ---------------------------------------------------------------------------
    @_reachable
    def put_template(self, template_id: str, sha256: str, document: dict[str, Any]) -> None:
        with self.session() as s:
            row = s.get(TemplateRow, template_id)
            if row is None:
                s.add(TemplateRow(id=template_id, sha256=sha256, document=document))
            else:
                row.sha256, row.document = sha256, document

    @_reachable
    def template(self, template_id: str) -> dict[str, Any] | None:
        with self.session() as s:
            row = s.get(TemplateRow, template_id)
            return None if row is None else row.document

    @_reachable
    def templates(self) -> list[dict[str, Any]]:
        with self.session() as s:
            rows = s.scalars(select(TemplateRow).order_by(TemplateRow.id))
            return [{"id": r.id, "sha256": r.sha256, "document": r.document} for r in rows]

    # -- assignments and variants ---------------------------------------------------------------
    @_reachable
    def create_assignment(
        self, assignment_id: str, template: dict[str, Any], sha256: str, variants: list[dict]
    ) -> None:
        """The assignment and all its variants at once, or nothing (a duplicate id raises
        IntegrityError)."""
        with self.session() as s:
            s.add(
                AssignmentRow(
                    id=assignment_id,
                    template_id=template["id"],
                    template_sha256=sha256,
                    template=template,
                )
            )
            s.flush()
            for v in variants:
                s.add(VariantRow(assignment_id=assignment_id, **v))

    @_reachable
    def assignment(self, assignment_id: str) -> AssignmentRow | None:
        with self.session() as s:
            return s.get(AssignmentRow, assignment_id)

    @_reachable
    def set_closed(self, assignment_id: str, closed: bool) -> None:
        with self.session() as s:
            row = s.get(AssignmentRow, assignment_id)
            if row is not None:
                row.closed = closed

    @_reachable
    def variants(self, assignment_id: str) -> list[VariantRow]:
        with self.session() as s:
            query = select(VariantRow).where(VariantRow.assignment_id == assignment_id)
            return list(s.scalars(query.order_by(VariantRow.id)))

    @_reachable
    def variant_of(self, assignment_id: str, student: str) -> VariantRow | None:
        """The student's variant: the one recorded for them, else one of the deployable
        variants chosen by `student_choice` and recorded (so it never changes afterwards)."""
        for _ in range(2):  # a second server may record it at the same moment: read theirs
            with self.session() as s:
                enrolled = s.scalar(
                    select(EnrolmentRow).where(
                        EnrolmentRow.assignment_id == assignment_id,
                        EnrolmentRow.student == student,
                    )
                )
                if enrolled is not None:
                    return self._variant(s, enrolled.variant_id)
            deployable = [v for v in self.variants(assignment_id) if v.deployable]
            if not deployable:
                return None
            chosen = deployable[student_choice(assignment_id, student, len(deployable))]
            try:
                with self.session() as s:
                    s.add(
                        EnrolmentRow(
                            assignment_id=assignment_id, student=student, variant_id=chosen.id
                        )
                    )
                return chosen
            except IntegrityError:
                continue
        return None

    def _variant(self, s: Session, variant_id: int) -> VariantRow | None:
        row = self._variants.get(variant_id)
        if row is None:
            row = s.get(VariantRow, variant_id)
            if row is not None:
                self._variants[variant_id] = row
        return row

    @_reachable
    def submit_context(
        self, assignment_id: str, student: str, part: str, seconds: float
    ) -> tuple[AssignmentRow | None, VariantRow | None, list[SubmissionRow], int]:
        """What a submission needs, read in one transaction: the assignment, the student's
        variant (None if not yet chosen), their graded attempts at the part, and how many
        submissions they made in the last ``seconds``."""
        since = datetime.now(UTC) - timedelta(seconds=seconds)
        with self.session() as s:
            assignment = s.get(AssignmentRow, assignment_id)
            enrolled = s.scalar(
                select(EnrolmentRow.variant_id).where(
                    EnrolmentRow.assignment_id == assignment_id, EnrolmentRow.student == student
                )
            )
            variant = None if enrolled is None else self._variant(s, enrolled)
            attempts = s.scalars(
                select(SubmissionRow)
                .where(
                    SubmissionRow.assignment_id == assignment_id,
                    SubmissionRow.student == student,
                    SubmissionRow.part == part,
                    SubmissionRow.status == "graded",
                )
                .order_by(SubmissionRow.id)
            )
            attempts = list(attempts)
            recent = s.scalar(
                select(func.count(SubmissionRow.id)).where(
                    SubmissionRow.student == student, SubmissionRow.created_at >= since
                )
            )
            return assignment, variant, attempts, int(recent or 0)

    # -- submissions ---------------------------------------------------------------------------
    @_reachable
    def recent_submissions(self, student: str, seconds: float) -> int:
        since = datetime.now(UTC) - timedelta(seconds=seconds)
        with self.session() as s:
            query = select(func.count(SubmissionRow.id)).where(
                SubmissionRow.student == student, SubmissionRow.created_at >= since
            )
            return int(s.scalar(query) or 0)

    @_reachable
    def attempts(self, assignment_id: str, student: str, part: str | None = None) -> list[Any]:
        """The student's graded submissions (of one part), oldest first."""
        with self.session() as s:
            query = select(SubmissionRow).where(
                SubmissionRow.assignment_id == assignment_id,
                SubmissionRow.student == student,
                SubmissionRow.status == "graded",
            )
            if part is not None:
                query = query.where(SubmissionRow.part == part)
            return list(s.scalars(query.order_by(SubmissionRow.id)))

    @_reachable
    def store_pending(
        self, assignment_id: str, student: str, part: str, answer: str, request_id: str | None
    ) -> tuple[SubmissionRow, bool]:
        """Store the answer before it is judged; (row, False) if this request_id was stored
        already (a retried request is not a second submission)."""
        if request_id is not None:
            with self.session() as s:
                old = s.scalar(
                    select(SubmissionRow).where(
                        SubmissionRow.student == student, SubmissionRow.request_id == request_id
                    )
                )
                if old is not None:
                    return old, False
        row = SubmissionRow(
            assignment_id=assignment_id,
            student=student,
            part=part,
            answer=answer,
            request_id=request_id,
            status="pending",
        )
        try:
            with self.session() as s:
                s.add(row)
        except IntegrityError:  # the same request_id, stored by a parallel request
            with self.session() as s:
                old = s.scalar(
                    select(SubmissionRow).where(
                        SubmissionRow.student == student, SubmissionRow.request_id == request_id
                    )
                )
                return old, False  # type: ignore[return-value]
        return row, True

    @_reachable
    def finish(self, submission_id: int, attempt: Attempt) -> SubmissionRow:
        with self.session() as s:
            row = s.get(SubmissionRow, submission_id)
            assert row is not None
            j = attempt.judged
            row.status = "graded"
            row.code, row.codes, row.decided = j.code, list(j.codes), j.decided
            row.counted, row.number = attempt.counted, attempt.number
            row.raw, row.score = attempt.raw, attempt.score
            row.feedback, row.answer_latex = list(j.feedback), j.answer_latex
            return row

    @_reachable
    def pending(
        self, assignment_id: str | None = None, before: datetime | None = None
    ) -> list[SubmissionRow]:
        """Stored answers not yet scored (stored before ``before``, if given)."""
        before = before or datetime.now(UTC)
        with self.session() as s:
            query = select(SubmissionRow).where(
                SubmissionRow.status == "pending", SubmissionRow.created_at <= before
            )
            if assignment_id is not None:
                query = query.where(SubmissionRow.assignment_id == assignment_id)
            return list(s.scalars(query.order_by(SubmissionRow.id)))

    @_reachable
    def submissions(self, assignment_id: str) -> list[SubmissionRow]:
        with self.session() as s:
            query = select(SubmissionRow).where(SubmissionRow.assignment_id == assignment_id)
            return list(s.scalars(query.order_by(SubmissionRow.id)))

    @_reachable
    def enrolments(self, assignment_id: str) -> list[EnrolmentRow]:
        with self.session() as s:
            query = select(EnrolmentRow).where(EnrolmentRow.assignment_id == assignment_id)
            return list(s.scalars(query.order_by(EnrolmentRow.student)))

    # -- tokens --------------------------------------------------------------------------------
    @_reachable
    def add_token(self, sha256: str, role: str, subject: str) -> None:
        with self.session() as s:
            s.add(TokenRow(sha256=sha256, role=role, subject=subject))

    @_reachable
    def token(self, sha256: str) -> TokenRow | None:
        with self.session() as s:
            row = s.scalar(select(TokenRow).where(TokenRow.sha256 == sha256))
            return None if row is None or row.revoked else row
