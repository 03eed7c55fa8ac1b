"""Alembic's environment: the connection is handed in by app/assignments/db.py (migrate), so
the migrations run on whatever database the app uses, SQLite or PostgreSQL, with no alembic.ini."""

from __future__ import annotations

from alembic import context

from app.assignments.models import Base

connection = context.config.attributes["connection"]
context.configure(
    connection=connection,
    target_metadata=Base.metadata,
    render_as_batch=connection.dialect.name == "sqlite",  # SQLite alters tables by copying
)
with context.begin_transaction():
    context.run_migrations()
