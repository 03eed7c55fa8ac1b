"""A server killed (SIGKILL, no goodbye) loses no stored submission, and once restarted serves
the same variants and scores (issue 27, "done when"). A real server on SQLite, killed while a
class is submitting, then started again on the same file."""

from __future__ import annotations

import os
import signal
import sys
import threading
from pathlib import Path

import httpx
import pytest
from servers import free_port, serving

from app.assignments import tokens
from app.assignments.db import engine_for, forget_engines
from app.assignments.store import Store

ROOT = Path(__file__).resolve().parents[2]
RIGHT_T = "m*l^2*theta_dot^2/2"


def test_a_killed_server_loses_nothing_and_restarts_with_the_same_variants(tmp_path):
    url = f"sqlite:///{tmp_path / 'assignments.sqlite3'}"
    store = Store(engine_for(url))
    teacher = {"Authorization": f"Bearer {tokens.create(store, 'instructor', 'ada')}"}
    pupils = {f"s{i}": tokens.create(store, "student", f"s{i}") for i in range(6)}
    forget_engines()
    env = {**os.environ, "LAGRANGE_LAB_DATABASE_URL": url, "LAGRANGE_LAB_POOL_WORKERS": "2"}
    command = [sys.executable, "-m", "uvicorn", "app.main:app", "--log-level", "warning"]
    template = {
        "id": "pend",
        "title": "Pendulum",
        "scene": "simple_pendulum",
        "parameters": {"l": {"values": [0.5, 1.0, 2.0]}},
        "parts": [{"id": "T", "quantity": "T"}],
    }
    acknowledged: list[tuple[str, str]] = []
    port = free_port()
    with serving([*command, "--port", str(port)], port, env=env, cwd=ROOT) as (base, proc):
        assert (
            httpx.post(
                f"{base}/api/v1/assignments/templates", json={"template": template}, headers=teacher
            ).status_code
            == 201
        )
        r = httpx.post(
            f"{base}/api/v1/assignments/templates/pend/deploy",
            json={"assignment_id": "w", "count": 3},
            headers=teacher,
            timeout=300,
        )
        assert r.status_code == 201, r.text
        before = {
            s: httpx.get(
                f"{base}/api/v1/assignments/w/mine", headers={"Authorization": f"Bearer {t}"}
            ).json()
            for s, t in pupils.items()
        }

        def student(name: str, token: str) -> None:
            for n, answer in enumerate(("m*l^2*theta_dot^2", RIGHT_T, "2*" + RIGHT_T)):
                try:
                    r = httpx.post(
                        f"{base}/api/v1/assignments/w/parts/T/submit",
                        json={"answer": answer, "request_id": f"r{n}"},
                        headers={"Authorization": f"Bearer {token}"},
                        timeout=30,
                    )
                except httpx.HTTPError:
                    return  # the server is gone
                if r.status_code == 200:
                    acknowledged.append((name, f"r{n}"))

        threads = [threading.Thread(target=student, args=kv) for kv in pupils.items()]
        for t in threads:
            t.start()
        for t in threads[:3]:
            t.join(60)  # half the class done, the other half under way
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
        for t in threads:
            t.join(60)
    with engine_for(url).connect() as c:
        from sqlalchemy import text

        stored = set(c.execute(text("select student, request_id from submissions")).all())
    forget_engines()
    assert set(acknowledged) <= {tuple(s) for s in stored}  # nothing answered was lost
    port = free_port()
    with serving([*command, "--port", str(port)], port, env=env, cwd=ROOT) as (base, _):
        after = {
            s: httpx.get(
                f"{base}/api/v1/assignments/w/mine", headers={"Authorization": f"Bearer {t}"}
            ).json()
            for s, t in pupils.items()
        }
        for s in pupils:
            assert after[s]["seed"] == before[s]["seed"]
            assert after[s]["scene"] == before[s]["scene"]
        scores = httpx.get(
            f"{base}/api/v1/assignments/w/scores", headers=teacher, timeout=120
        ).json()
        done = {row["student"]: row for row in scores["students"]}
        for name, request_id in acknowledged:
            if request_id == "r1":  # the right answer, acknowledged: it counts after the restart
                assert done[name]["parts"]["T"] == pytest.approx(0.9)
        assert all(row["pending"] == 0 for row in scores["students"])  # stored ones were scored
