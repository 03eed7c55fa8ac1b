"""Shared test setup: the tests never read or write the user's own derivation cache."""

from __future__ import annotations

import os
import shutil
import tempfile

import pytest

_saved: dict[str, str | None] = {}


def pytest_configure(config: pytest.Config) -> None:
    # At configure time, before collection, so even import-time code sees the private folder.
    _saved["LAGRANGE_LAB_CACHE"] = os.environ.get("LAGRANGE_LAB_CACHE")
    os.environ["LAGRANGE_LAB_CACHE"] = tempfile.mkdtemp(prefix="lagrange-lab-cache-")
    # The servers tests start do not warm every scene in the background (2 cores: it would slow
    # every other test); tests/test_warm_up.py switches it on where it is the subject.
    os.environ.setdefault("LAGRANGE_LAB_WARM", "0")


def pytest_unconfigure(config: pytest.Config) -> None:
    shutil.rmtree(os.environ["LAGRANGE_LAB_CACHE"], ignore_errors=True)
    if _saved.get("LAGRANGE_LAB_CACHE") is None:
        os.environ.pop("LAGRANGE_LAB_CACHE", None)
    else:
        os.environ["LAGRANGE_LAB_CACHE"] = _saved["LAGRANGE_LAB_CACHE"]
