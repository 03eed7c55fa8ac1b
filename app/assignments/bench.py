"""``python -m app.assignments.bench``: a scripted class against a real server, on SQLite or
PostgreSQL (issue 27's "done when").

The server is ``python -m app serve`` started as a subprocess on a free loopback port, with its own
data folder (or ``--database-url``). An instructor token is made with ``lagrange-lab token
create``, a shipped template is deployed, and every student (its own loopback source address, as
benchmarks/load.py does) opens their variant and submits every part twice (a wrong answer,
then the key), with think time between. The same class then runs again posting the same answers to
``/api/v1/check`` (no grading, no database): the two p95s side by side. ``--kill-at S`` kills the
server (SIGKILL) S seconds into the graded run and restarts it; students retry a failed submit
with the same ``request_id``. At the end the database is counted: every submission a student sent
is stored exactly once, and graded.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import httpx
from sqlalchemy import create_engine, text

HOST = "127.0.0.1"
TIMEOUT = 60.0
TARGET_P95_MS = 300.0


def free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind((HOST, 0))
        return s.getsockname()[1]


def start(port: int, env: dict[str, str], log: Path) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "app", "serve", "--host", HOST, "--port", str(port)]
    proc = subprocess.Popen(cmd, env=env, stdout=log.open("ab"), stderr=subprocess.STDOUT)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        try:
            if httpx.get(f"http://{HOST}:{port}/healthz", timeout=1).status_code == 200:
                return proc
        except httpx.HTTPError:
            time.sleep(0.3)
    proc.kill()
    raise RuntimeError(f"the server did not start (see {log})")


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))] if ordered else float("nan")


def wrong_of(key: str, quantity: str) -> str:
    """A wrong answer made from the key: twice it (an equation: with a stray + 1)."""
    if quantity == "eom":
        lhs, rhs = key.split("=")
        return f"{lhs} + 1 = {rhs}"
    return f"2*({key})"


class Class:
    def __init__(self, base: str, teacher: str, assignment: str, preview: dict, think: float):
        self.base, self.teacher, self.assignment, self.think = base, teacher, assignment, think
        self.keys = {v["seed"]: {k["part"]: k["plain"] for k in v["keys"]} for v in preview}
        self.graded: list[float] = []
        self.checked: list[float] = []
        self.sent: set[tuple[str, str]] = set()  # (student, request_id) acknowledged or retried
        self.errors: list[str] = []

    async def student(self, i: int, token: str, grade: bool, rng: random.Random) -> None:
        address = f"127.0.{1 + i // 250}.{1 + i % 250}"
        transport = httpx.AsyncHTTPTransport(local_address=address)
        headers = {"Authorization": f"Bearer {token}"}
        async with httpx.AsyncClient(
            base_url=self.base, transport=transport, timeout=TIMEOUT, headers=headers
        ) as http:
            await asyncio.sleep(rng.uniform(0, self.think * 4))  # the class arrives over time
            mine = await self._retry(http, "GET", f"/api/v1/assignments/{self.assignment}/mine")
            mine = mine.json()
            keys = self.keys[mine["seed"]]
            for part in mine["parts"]:
                for n, answer in enumerate(
                    (wrong_of(keys[part["id"]], part["quantity"]), keys[part["id"]])
                ):
                    await asyncio.sleep(rng.uniform(0.5, 1.5) * self.think)
                    if grade:
                        request_id = f"{part['id']}-{n}"
                        self.sent.add((f"s{i}", request_id))
                        url = f"/api/v1/assignments/{self.assignment}/parts/{part['id']}/submit"
                        body = {"answer": answer, "request_id": request_id}
                        start = time.perf_counter()
                        await self._retry(http, "POST", url, body)
                        self.graded.append(time.perf_counter() - start)
                    else:
                        body = {
                            "scene": mine["scene"],
                            "quantity": part["quantity"],
                            "coordinate": part.get("coordinate"),
                            "answer": answer,
                        }
                        start = time.perf_counter()
                        await self._retry(http, "POST", "/api/v1/check", body)
                        self.checked.append(time.perf_counter() - start)

    async def _retry(
        self, http: httpx.AsyncClient, method: str, url: str, body: Any = None
    ) -> httpx.Response:
        """A request until it is answered (a killed server is restarting: wait and send again)."""
        for _ in range(120):
            try:
                r = await http.request(method, url, json=body)
                if r.status_code < 500:
                    if r.status_code >= 400:
                        self.errors.append(f"{method} {url}: {r.status_code} {r.text[:200]}")
                    return r
            except httpx.HTTPError:
                pass
            await asyncio.sleep(1.0)
        raise RuntimeError(f"{method} {url}: never answered")


def warm(base: str, preview: list[dict]) -> None:
    """Each variant's derivation made once in every pool worker before either run is timed, by
    checking each key a few times (the pool sends one spec to the same worker when it can)."""
    for v in preview:
        spec = v["variant"]["spec"]
        for part, key in zip(v["variant"]["parts"], v["keys"], strict=True):
            body = {
                "scene": spec,
                "quantity": part["quantity"],
                "coordinate": part.get("coordinate"),
                "answer": key["plain"],
            }
            for _ in range(3):
                httpx.post(f"{base}/api/v1/check", json=body, timeout=120)


def count(url: str, assignment: str) -> dict[str, int]:
    engine = create_engine(url)
    with engine.connect() as c:
        q = "select count(*) from submissions where assignment_id = :a"
        rows = c.execute(text(q), {"a": assignment}).scalar()
        graded = c.execute(text(q + " and status = 'graded'"), {"a": assignment}).scalar()
        dup = c.execute(
            text(
                "select count(*) from (select student, request_id from submissions where "
                "assignment_id = :a group by student, request_id having count(*) > 1) d"
            ),
            {"a": assignment},
        ).scalar()
    engine.dispose()
    return {"rows": int(rows), "graded": int(graded), "duplicated": int(dup)}


async def run_class(cls: Class, tokens: dict[str, str], grade: bool, seed: int) -> None:
    rng = random.Random(seed)
    await asyncio.gather(
        *(cls.student(int(s[1:]), t, grade, random.Random(rng.random())) for s, t in tokens.items())
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m app.assignments.bench")
    parser.add_argument("--students", type=int, default=200)
    parser.add_argument("--think", type=float, default=3.0, help="mean seconds between steps")
    parser.add_argument("--template", default="pendulum_energies")
    parser.add_argument("--variants", type=int, default=8)
    parser.add_argument("--database-url", default="", help="default: SQLite in a temp folder")
    parser.add_argument("--kill-at", type=float, default=0.0, help="SIGKILL the server then")
    args = parser.parse_args(argv)
    folder = Path(tempfile.mkdtemp(prefix="lagrange-lab-bench-"))
    env = {
        **os.environ,
        "LAGRANGE_LAB_DATA_DIR": str(folder),
        "LAGRANGE_LAB_WARM": "0",
        "LAGRANGE_LAB_SUBMISSIONS_PER_MINUTE": "1000",
    }
    if args.database_url:
        env["LAGRANGE_LAB_DATABASE_URL"] = args.database_url
    url = args.database_url or f"sqlite:///{folder / 'assignments.sqlite3'}"
    port = free_port()
    base = f"http://{HOST}:{port}"
    log = folder / "server.log"
    server = start(port, env, log)
    try:
        teacher = subprocess.run(
            [sys.executable, "-m", "app", "token", "create", "--name", "bench"],
            env=env,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        head = {"Authorization": f"Bearer {teacher}"}
        assignment = f"bench{int(time.time())}"
        r = httpx.post(
            f"{base}/api/v1/assignments/templates/{args.template}/deploy",
            json={"assignment_id": assignment, "count": args.variants},
            headers=head,
            timeout=600,
        )
        r.raise_for_status()
        preview = [v for v in r.json()["variants"] if v["deployable"]]
        names = [f"s{i}" for i in range(args.students)]
        tokens = httpx.post(
            f"{base}/api/v1/assignments/students/tokens",
            json={"students": names},
            headers=head,
            timeout=120,
        ).json()["tokens"]
        cls = Class(base, teacher, assignment, preview, args.think)
        warm(base, preview)

        async def graded_run() -> None:
            task = asyncio.create_task(run_class(cls, tokens, True, 1))
            if args.kill_at > 0:
                nonlocal server
                await asyncio.sleep(args.kill_at)
                server.send_signal(signal.SIGKILL)
                server.wait()
                server = await asyncio.to_thread(start, port, env, log)
            await task

        t0 = time.monotonic()
        asyncio.run(graded_run())
        graded_seconds = time.monotonic() - t0
        before = count(url, assignment)
        scores = httpx.get(
            f"{base}/api/v1/assignments/{assignment}/scores", headers=head, timeout=600
        ).json()
        after = count(url, assignment)
        t0 = time.monotonic()
        asyncio.run(run_class(cls, tokens, False, 1))
        check_seconds = time.monotonic() - t0
    finally:
        server.send_signal(signal.SIGTERM)
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()
    result = {
        "students": args.students,
        "database": url.split(":", 1)[0],
        "killed_at": args.kill_at or None,
        "submissions_sent": len(cls.sent),
        "stored_after_run": before,
        "stored_after_scores": after,
        "lost": len(cls.sent) - after["rows"],
        "mean_total": round(sum(s["total"] for s in scores["students"]) / len(names), 4),
        "submit_p50_ms": round(1000 * percentile(cls.graded, 0.5), 1),
        "submit_p95_ms": round(1000 * percentile(cls.graded, 0.95), 1),
        "check_p50_ms": round(1000 * percentile(cls.checked, 0.5), 1),
        "check_p95_ms": round(1000 * percentile(cls.checked, 0.95), 1),
        "graded_run_s": round(graded_seconds, 1),
        "check_run_s": round(check_seconds, 1),
        "client_errors": cls.errors[:5],
    }
    print(json.dumps(result, indent=2))
    ok = result["lost"] == 0 and after["duplicated"] == 0 and after["graded"] == after["rows"]
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
