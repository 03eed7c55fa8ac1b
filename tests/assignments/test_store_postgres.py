"""The assignment store on a real PostgreSQL (Debian's server, started here on a free loopback
port): the database several app servers share. Skipped with a reason where the server is not
installed; under CI (CI=true) that is a failure instead."""

from __future__ import annotations

import os

import pytest
from servers import free_port

from app.assignments.db import forget_engines

from .postgres_server import binaries, postgres
from .store_cases import *  # noqa: F403  (the cases every database must pass)

IN_CI = os.environ.get("CI", "").lower() == "true"

if binaries() is None:
    if IN_CI:
        raise RuntimeError("PostgreSQL is missing under CI: .ci/run should have installed it")
    pytest.skip(
        "Debian's postgresql is not installed (apt-get install postgresql)", allow_module_level=True
    )


@pytest.fixture(scope="session")
def server():
    with postgres() as url:
        yield url


@pytest.fixture
def url(server):
    """The server's database, emptied before each test."""
    import sqlalchemy as sa

    engine = sa.create_engine(server)
    with engine.begin() as c:
        c.execute(sa.text("DROP SCHEMA public CASCADE; CREATE SCHEMA public"))
    engine.dispose()
    forget_engines()
    yield server
    forget_engines()


@pytest.fixture
def unreachable_url():
    return f"postgresql+psycopg://postgres@127.0.0.1:{free_port()}/lagrange"
