"""The code stays formatted and lint-clean: ruff is part of the suite, so CI enforces it."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _ruff(*args: str) -> subprocess.CompletedProcess:
    exe = shutil.which("ruff")
    cmd = [exe] if exe else [sys.executable, "-m", "ruff"]
    return subprocess.run([*cmd, *args], cwd=ROOT, capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("args", [("check", "."), ("format", "--check", ".")])
def test_ruff(args):
    result = _ruff(*args)
    assert result.returncode == 0, result.stdout + result.stderr


FORBIDDEN = re.compile(
    r"(?<![\w.])(?:(?:sp|sympy)\.)?(?:eval|exec|sympify|parse_expr)\s*\(|(?:sp|sympy)\.S\s*\("
)


def test_user_text_never_reaches_eval_or_sympify():
    """Only the whitelist parser may turn text into sympy (mechanics/expr.py)."""
    for path in [*ROOT.glob("mechanics/**/*.py"), *ROOT.glob("app/**/*.py")]:
        for n, line in enumerate(path.read_text().splitlines(), 1):
            assert not FORBIDDEN.search(line.split("#")[0]), f"{path.name}:{n}: {line.strip()}"
