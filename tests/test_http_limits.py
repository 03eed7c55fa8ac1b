"""Limits of an HTTP request that hold however the app is run (issue 24, item 4 and item 6):
``LAGRANGE_LAB_MAX_BODY_BYTES`` sets the body limit."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

POST_SIZES = """
import json
from fastapi.testclient import TestClient
from app.main import app
client = TestClient(app)
out = []
for size in (1500, 2500):
    body = b'{"scene_id": "simple_pendulum", "title": "' + b"x" * (size - 47) + b'"}'
    r = client.post("/api/v1/derive", content=body, headers={"content-type": "application/json"})
    out.append([len(body), r.status_code, r.json()])
print(json.dumps(out))
"""


def test_the_body_limit_is_the_one_the_environment_sets():
    env = {**os.environ, "LAGRANGE_LAB_MAX_BODY_BYTES": "2000", "LAGRANGE_LAB_WARM": "0"}
    done = subprocess.run(
        [sys.executable, "-c", POST_SIZES],
        env=env,
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    (small, big) = json.loads(done.stdout.splitlines()[-1])
    assert small[0] <= 2000 and small[1] == 422  # read (and refused for its extra field)
    assert big[0] > 2000 and big[1] == 413
    assert big[2] == {"detail": [{"field": "body", "message": "request body over 2000 bytes"}]}
