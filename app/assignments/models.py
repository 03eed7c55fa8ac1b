"""The assignment tables (SQLAlchemy 2): templates, assignments (a deployed template), their
variants with verified keys, which variant each student has, submissions with their scores, and
API tokens (stored as sha256 hashes, never in the clear).

The schema is created and changed only by the Alembic migrations in app/assignments/alembic/;
these classes must match them (tests/assignments/test_store_sqlite.py compares the two).
"""

from __future__ import annotations

from datetime import UTC, datetime
from typing import Any

from sqlalchemy import (
    JSON,
    Boolean,
    DateTime,
    Float,
    ForeignKey,
    Index,
    Integer,
    String,
    Text,
    UniqueConstraint,
)
from sqlalchemy.orm import DeclarativeBase, Mapped, mapped_column


def now() -> datetime:
    return datetime.now(UTC)


class Base(DeclarativeBase):
    pass


class TemplateRow(Base):
    __tablename__ = "templates"
    id: Mapped[str] = mapped_column(String(24), primary_key=True)
    sha256: Mapped[str] = mapped_column(String(64))
    document: Mapped[dict[str, Any]] = mapped_column(JSON)
    created_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)


class AssignmentRow(Base):
    __tablename__ = "assignments"
    id: Mapped[str] = mapped_column(String(40), primary_key=True)
    template_id: Mapped[str] = mapped_column(String(24))
    template_sha256: Mapped[str] = mapped_column(String(64))
    template: Mapped[dict[str, Any]] = mapped_column(JSON)  # the document as deployed
    closed: Mapped[bool] = mapped_column(Boolean, default=False)
    created_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)


class VariantRow(Base):
    __tablename__ = "variants"
    __table_args__ = (UniqueConstraint("assignment_id", "seed"),)
    id: Mapped[int] = mapped_column(Integer, primary_key=True, autoincrement=True)
    assignment_id: Mapped[str] = mapped_column(ForeignKey("assignments.id"), index=True)
    seed: Mapped[str] = mapped_column(String(200))
    engine_version: Mapped[int] = mapped_column(Integer)
    variant: Mapped[dict[str, Any]] = mapped_column(JSON)
    keys: Mapped[dict[str, Any]] = mapped_column(JSON)
    deployable: Mapped[bool] = mapped_column(Boolean)
    why_not: Mapped[str] = mapped_column(Text, default="")


class EnrolmentRow(Base):
    __tablename__ = "enrolments"
    __table_args__ = (UniqueConstraint("assignment_id", "student"),)
    id: Mapped[int] = mapped_column(Integer, primary_key=True, autoincrement=True)
    assignment_id: Mapped[str] = mapped_column(ForeignKey("assignments.id"), index=True)
    student: Mapped[str] = mapped_column(String(100))
    variant_id: Mapped[int] = mapped_column(ForeignKey("variants.id"))


class SubmissionRow(Base):
    __tablename__ = "submissions"
    __table_args__ = (
        UniqueConstraint("student", "request_id"),
        # one row per counted attempt: two tabs submitting at once cannot both be attempt 2
        # (migration 0002; NULL, an attempt not counted, may repeat)
        Index("uq_submission_attempt", "assignment_id", "student", "part", "number", unique=True),
    )
    id: Mapped[int] = mapped_column(Integer, primary_key=True, autoincrement=True)
    assignment_id: Mapped[str] = mapped_column(ForeignKey("assignments.id"), index=True)
    student: Mapped[str] = mapped_column(String(100), index=True)
    part: Mapped[str] = mapped_column(String(24))
    answer: Mapped[str] = mapped_column(Text)
    request_id: Mapped[str | None] = mapped_column(String(100), nullable=True)
    created_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now, index=True)
    #: "pending" (stored, not yet scored: a server stopped here regrades it), "graded"
    status: Mapped[str] = mapped_column(String(16), default="pending")
    code: Mapped[str | None] = mapped_column(String(64), nullable=True)
    codes: Mapped[list[str] | None] = mapped_column(JSON, nullable=True)
    decided: Mapped[bool | None] = mapped_column(Boolean, nullable=True)
    counted: Mapped[bool | None] = mapped_column(Boolean, nullable=True)
    number: Mapped[int | None] = mapped_column(Integer, nullable=True)
    raw: Mapped[float | None] = mapped_column(Float, nullable=True)
    score: Mapped[float | None] = mapped_column(Float, nullable=True)
    feedback: Mapped[list[str] | None] = mapped_column(JSON, nullable=True)
    answer_latex: Mapped[str | None] = mapped_column(Text, nullable=True)


class TokenRow(Base):
    __tablename__ = "tokens"
    id: Mapped[int] = mapped_column(Integer, primary_key=True, autoincrement=True)
    sha256: Mapped[str] = mapped_column(String(64), unique=True)
    role: Mapped[str] = mapped_column(String(16))  # "instructor" or "student"
    subject: Mapped[str] = mapped_column(String(100))  # who: a name, or the student's id
    created_at: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=now)
    revoked: Mapped[bool] = mapped_column(Boolean, default=False)
