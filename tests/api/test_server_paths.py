"""What a client reads names none of the server's folders (issue 24, item 6: a run's warning
quoted the C compiler's command line, with the absolute path of the server's cache)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from mechanics.native import NativeUnavailable

ROOT = Path(__file__).resolve().parents[2]

RUN = """
import json
from fastapi.testclient import TestClient
from app.main import app
r = TestClient(app).post(
    "/api/v1/simulate", json={"scene_id": "simple_pendulum", "t_end": 1, "method": "dop853_c"}
)
print(json.dumps(r.json()))
"""


def test_a_failed_compile_is_told_without_the_servers_paths(tmp_path):
    cc = tmp_path / "cc"
    cc.write_text('#!/bin/sh\necho "cc: cannot build: $*" >&2\nexit 1\n')
    cc.chmod(0o755)
    cache = tmp_path / "server-cache-folder"
    env = {
        **os.environ,
        "LAGRANGE_LAB_CACHE": str(cache),
        "LAGRANGE_LAB_CC": str(cc),
        "LAGRANGE_LAB_WARM": "0",
    }
    done = subprocess.run(
        [sys.executable, "-c", RUN], env=env, cwd=ROOT, capture_output=True, text=True, timeout=300
    )
    answer = json.loads(done.stdout.splitlines()[-1])
    text = json.dumps(answer["warnings"])
    assert "compiler failed" in text  # the reason is still told
    assert "server-cache-folder" not in text and str(tmp_path) not in text
    assert "out.so" in text  # file names stay: they say what failed


def test_a_reason_keeps_its_words_and_loses_its_folders():
    reason = "[Errno 28] No space left on device: '/root/.cache/lagrange-lab/native/x.so'"
    assert str(NativeUnavailable(reason)) == "[Errno 28] No space left on device: 'x.so'"
    assert str(NativeUnavailable("m/s and 1/2 stay")) == "m/s and 1/2 stay"
