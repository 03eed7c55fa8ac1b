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
