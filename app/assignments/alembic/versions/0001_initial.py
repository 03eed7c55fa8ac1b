"""The first schema of assignments: templates, assignments, variants, enrolments, submissions,
tokens.

Revision ID: 0001
Revises:
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0001"
down_revision = None
branch_labels = None
depends_on = None


def upgrade() -> None:
    when = sa.DateTime(timezone=True)
    op.create_table(
        "templates",
        sa.Column("id", sa.String(24), primary_key=True),
        sa.Column("sha256", sa.String(64), nullable=False),
        sa.Column("document", sa.JSON(), nullable=False),
        sa.Column("created_at", when, nullable=False),
    )
    op.create_table(
        "assignments",
        sa.Column("id", sa.String(40), primary_key=True),
        sa.Column("template_id", sa.String(24), nullable=False),
        sa.Column("template_sha256", sa.String(64), nullable=False),
        sa.Column("template", sa.JSON(), nullable=False),
        sa.Column("closed", sa.Boolean(), nullable=False),
        sa.Column("created_at", when, nullable=False),
    )
    op.create_table(
        "variants",
        sa.Column("id", sa.Integer(), primary_key=True, autoincrement=True),
        sa.Column("assignment_id", sa.String(40), sa.ForeignKey("assignments.id"), nullable=False),
        sa.Column("seed", sa.String(200), nullable=False),
        sa.Column("engine_version", sa.Integer(), nullable=False),
        sa.Column("variant", sa.JSON(), nullable=False),
        sa.Column("keys", sa.JSON(), nullable=False),
        sa.Column("deployable", sa.Boolean(), nullable=False),
        sa.Column("why_not", sa.Text(), nullable=False),
        sa.UniqueConstraint("assignment_id", "seed"),
    )
    op.create_index("ix_variants_assignment_id", "variants", ["assignment_id"])
    op.create_table(
        "enrolments",
        sa.Column("id", sa.Integer(), primary_key=True, autoincrement=True),
        sa.Column("assignment_id", sa.String(40), sa.ForeignKey("assignments.id"), nullable=False),
        sa.Column("student", sa.String(100), nullable=False),
        sa.Column("variant_id", sa.Integer(), sa.ForeignKey("variants.id"), nullable=False),
        sa.UniqueConstraint("assignment_id", "student"),
    )
    op.create_index("ix_enrolments_assignment_id", "enrolments", ["assignment_id"])
    op.create_table(
        "submissions",
        sa.Column("id", sa.Integer(), primary_key=True, autoincrement=True),
        sa.Column("assignment_id", sa.String(40), sa.ForeignKey("assignments.id"), nullable=False),
        sa.Column("student", sa.String(100), nullable=False),
        sa.Column("part", sa.String(24), nullable=False),
        sa.Column("answer", sa.Text(), nullable=False),
        sa.Column("request_id", sa.String(100), nullable=True),
        sa.Column("created_at", when, nullable=False),
        sa.Column("status", sa.String(16), nullable=False),
        sa.Column("code", sa.String(64), nullable=True),
        sa.Column("codes", sa.JSON(), nullable=True),
        sa.Column("decided", sa.Boolean(), nullable=True),
        sa.Column("counted", sa.Boolean(), nullable=True),
        sa.Column("number", sa.Integer(), nullable=True),
        sa.Column("raw", sa.Float(), nullable=True),
        sa.Column("score", sa.Float(), nullable=True),
        sa.Column("feedback", sa.JSON(), nullable=True),
        sa.Column("answer_latex", sa.Text(), nullable=True),
        sa.UniqueConstraint("student", "request_id"),
    )
    op.create_index("ix_submissions_assignment_id", "submissions", ["assignment_id"])
    op.create_index("ix_submissions_student", "submissions", ["student"])
    op.create_index("ix_submissions_created_at", "submissions", ["created_at"])
    op.create_table(
        "tokens",
        sa.Column("id", sa.Integer(), primary_key=True, autoincrement=True),
        sa.Column("sha256", sa.String(64), nullable=False, unique=True),
        sa.Column("role", sa.String(16), nullable=False),
        sa.Column("subject", sa.String(100), nullable=False),
        sa.Column("created_at", when, nullable=False),
        sa.Column("revoked", sa.Boolean(), nullable=False),
    )


def downgrade() -> None:
    for table in ("tokens", "submissions", "enrolments", "variants", "assignments", "templates"):
        op.drop_table(table)
