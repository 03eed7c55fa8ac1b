"""The assignment store on SQLite, the embedded default (a file in the data directory)."""

from __future__ import annotations

import pytest

from app.assignments.db import database_url, forget_engines

from .store_cases import *  # noqa: F403  (the cases every database must pass)


@pytest.fixture
def url(tmp_path):
    yield f"sqlite:///{tmp_path / 'assignments.sqlite3'}"
    forget_engines()


@pytest.fixture
def unreachable_url(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    return f"sqlite:///{blocker / 'assignments.sqlite3'}"  # a path under a file


def test_the_default_is_a_file_in_the_data_dir(tmp_path, monkeypatch):
    monkeypatch.delenv("LAGRANGE_LAB_DATABASE_URL", raising=False)
    monkeypatch.setenv("LAGRANGE_LAB_DATA_DIR", str(tmp_path / "data"))
    assert database_url() == f"sqlite:///{tmp_path / 'data' / 'assignments.sqlite3'}"
    assert (tmp_path / "data").is_dir()


def test_lagrange_lab_token_create_prints_a_token_stored_only_hashed(tmp_path):
    import subprocess
    import sys

    from app.assignments import tokens
    from app.assignments.db import engine_for
    from app.assignments.store import Store

    env = {"PATH": "", "LAGRANGE_LAB_DATA_DIR": str(tmp_path), "HOME": str(tmp_path)}
    out = subprocess.run(
        [sys.executable, "-m", "app", "token", "create", "--name", "Dr Ada"],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    token = out.stdout.strip()
    assert token.startswith("llab_") and "only its hash is stored" in out.stderr
    database = tmp_path / "assignments.sqlite3"
    for file in tmp_path.glob("assignments.sqlite3*"):  # the database and its WAL
        assert token.encode() not in file.read_bytes()
    row = Store(engine_for(f"sqlite:///{database}")).token(tokens.digest(token))
    assert (row.role, row.subject) == ("instructor", "Dr Ada")
    bad = subprocess.run(
        [sys.executable, "-m", "app", "token", "create", "--name", "x", "--role", "admin"],
        capture_output=True,
        text=True,
        env=env,
    )
    assert bad.returncode == 2 and "invalid choice" in bad.stderr
