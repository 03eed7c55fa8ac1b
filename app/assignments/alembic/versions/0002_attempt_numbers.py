"""One row per counted attempt of a part: a unique index on (assignment, student, part, number).

Two submissions of one part by one student at the same instant (two tabs) both read "one attempt
used" and both wrote attempt 2; with the index the second write fails and is renumbered.

Revision ID: 0002
Revises: 0001
"""

from __future__ import annotations

from alembic import op

revision = "0002"
down_revision = "0001"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_index(
        "uq_submission_attempt",
        "submissions",
        ["assignment_id", "student", "part", "number"],
        unique=True,
    )


def downgrade() -> None:
    op.drop_index("uq_submission_attempt", table_name="submissions")
