"""A seeded, bounded fuzzer over every /api/v1 endpoint: no input makes the server answer 5xx.

Requests carry the values that broke it before (1e±308, 0, −0, subnormals, l = 1e155, k = 1e-300,
Ω = 1e308), huge and tiny t_end, fps and dt, every method, random parameter and initial-state
overrides, strings where numbers go, deep nesting, NaN literals, unknown keys. Every answer must
be a 200 with strict JSON (no NaN), the documented 503 budget refusal, or a 4xx in the one error
shape naming a field; /healthz answers afterwards. The default run is a few hundred requests
(about half a minute); the slow run a few thousand.
"""

from __future__ import annotations

import json
import random
from collections import Counter
from typing import Any

import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics import simulate as simulate_module
from mechanics.check import QUANTITIES
from mechanics.integrators import METHODS
from mechanics.scenes import load_scene, scene_ids

#: Values a double can hold that are far from a scene's comfortable range.
EXTREMES = [
    0.0,
    -0.0,
    5e-324,
    -5e-324,
    2.2250738585072014e-308,
    1e-308,
    1e-300,
    1e-155,
    1e-30,
    1e-9,
    0.5,
    1.0,
    -1.0,
    3.0,
    1e9,
    1e30,
    1e155,
    -1e155,
    1e300,
    1e308,
    -1e308,
    1.7976931348623157e308,
]
#: What goes where a number belongs in a malformed request.
NOT_NUMBERS = ["1e400", "abc", "", "1/0", None, True, [], {}, [1.0], {"x": 1}, 10**400]
T_ENDS = [0.0, -0.0, 5e-324, 1e-300, 1e-3, 0.02, 0.3, 1.0, 1000.0, 1000.000001, 1e308, -1.0]
FPS = [5e-324, 1e-300, 0.5, 1.0, 60.0, 240.0, 241.0, 1e5, 1e300, 1e308, 0.0, -60.0]
STEPS = [5e-324, 1e-300, 1e-9, 1e-3, 0.01, 0.5, 1e3, 1e308, 0.0, -0.01]
TOLERANCES = [1e-16, 1e-14, 1e-9, 1e-3, 0.1, 1.0, 0.0, 5e-324, 1e308]
ANSWERS = [
    "1/2 m l^2 theta'^2",
    "m g l cos(theta)",
    "0",
    "theta_ddot",
    "",
    "((",
    "x y z",
    "1e308^2",
]
POSTED = {
    "title": "Pendulum",
    "coordinates": ["theta"],
    "parameters": {"m": 1.0, "l": 1.0, "g": 9.81},
    "bodies": [{"name": "bob", "mass": "m", "position": ["l*sin(theta)", "-l*cos(theta)", 0]}],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
}

#: Seconds one run may integrate in the fuzzer: the answers' status is under test, not accuracy.
WALL_TIME = 0.3


@pytest.fixture(scope="module")
def client():
    with TestClient(app, raise_server_exceptions=False) as c:
        yield c


@pytest.fixture
def short_runs(monkeypatch):
    monkeypatch.setattr(simulate_module, "MAX_WALL_TIME", WALL_TIME)


def number(rng: random.Random) -> float:
    """An extreme value half the time, else any double by its order of magnitude."""
    if rng.random() < 0.5:
        return rng.choice(EXTREMES)
    return rng.choice([-1, 1]) * 10 ** rng.uniform(-307, 307)


def overrides(rng: random.Random, names: list[str], bad: float) -> dict[str, Any]:
    """A random subset of names with random values; now and then an unknown name or a string."""
    out: dict[str, Any] = {k: number(rng) for k in names if rng.random() < 0.4}
    if rng.random() < bad:
        out[rng.choice(names + ["nonexistent"])] = rng.choice(NOT_NUMBERS)
    return out


def nested(depth: int) -> Any:
    value: Any = 1.0
    for i in range(depth):
        value = [value] if i % 2 else {"a": value}
    return value


class Fuzzer:
    """Draws one request at a time: (method, path, json body or raw text)."""

    def __init__(self, seed: int, posted_budget: int) -> None:
        self.rng = random.Random(seed)
        self.scenes = sorted(scene_ids())
        self.specs = {s: load_scene(s) for s in self.scenes}
        self.posted_left = posted_budget

    def scene(self) -> tuple[str, dict]:
        scene_id = self.rng.choice(self.scenes)
        return scene_id, self.specs[scene_id]

    def simulate(self) -> dict[str, Any]:
        """A run that would pass but for a few extreme fields: every field is drawn from its
        extremes now and then, parameters and initial values more often."""
        rng = self.rng
        scene_id, spec = self.scene()
        states = list(spec["coordinates"]) + [f"{q}_dot" for q in spec["coordinates"]]
        method = rng.choice([*METHODS, *METHODS, *METHODS, "lsoda", "RK23", ""])
        fixed = method in METHODS and METHODS[method].kind == "fixed"

        def pick(extremes: list[float], sane: float) -> float:
            return rng.choice(extremes) if rng.random() < 0.25 else sane

        body: dict[str, Any] = {
            "scene_id": scene_id,
            "method": method,
            "parameters": overrides(rng, list(spec.get("parameters", {})), 0.05),
            "initial": overrides(rng, states, 0.05) if rng.random() < 0.4 else {},
            "t_end": pick(T_ENDS, rng.uniform(0, 0.5)),
            "fps": pick(FPS, 60.0),
            "check_sensitivity": rng.random() < 0.3,
            "constraint_forces": rng.random() < 0.2,
        }
        if fixed or rng.random() < 0.1:
            body["dt"] = pick(STEPS, 0.01)
        if rng.random() < 0.3:
            body["rtol"], body["atol"] = pick(TOLERANCES, 1e-6), pick(TOLERANCES, 1e-8)
        return body

    def equilibria(self) -> dict[str, Any]:
        scene_id, spec = self.scene()
        return {
            "scene_id": scene_id,
            "parameters": overrides(self.rng, list(spec.get("parameters", {})), 0.1),
        }

    def check(self) -> dict[str, Any]:
        rng = self.rng
        scene_id, spec = self.scene()
        return {
            "scene_id": scene_id,
            "quantity": rng.choice([*QUANTITIES, "H", "t", ""]),
            "coordinate": rng.choice([None, *spec["coordinates"], "nope"]),
            "answer": rng.choice(ANSWERS),
            "reveal": rng.random() < 0.5,
        }

    def posted(self) -> tuple[str, dict[str, Any]]:
        """A posted pendulum with extreme parameter defaults (each costs a derivation)."""
        rng = self.rng
        self.posted_left -= 1
        spec = json.loads(json.dumps(POSTED))
        spec["parameters"] = {k: number(rng) for k in spec["parameters"]}
        path = rng.choice(["/api/v1/simulate", "/api/v1/equilibria", "/api/v1/derive"])
        body: dict[str, Any] = {"scene": spec}
        if path == "/api/v1/simulate":
            body |= {"t_end": rng.choice([0.0, 0.1, 1.0]), "method": rng.choice(list(METHODS))}
            body |= {"dt": 0.01, "check_sensitivity": False}
        return path, body

    def malformed(self) -> tuple[str, Any]:
        """Strings where numbers go, deep nesting, unknown keys, NaN literals, not JSON at all."""
        rng = self.rng
        path = rng.choice(
            ["/api/v1/simulate", "/api/v1/equilibria", "/api/v1/check", "/api/v1/derive"]
        )
        kind = rng.randrange(7)
        if kind == 0:
            key = rng.choice(["t_end", "fps", "dt", "rtol", "atol", "method", "scene_id"])
            return path, {"scene_id": "simple_pendulum", key: rng.choice(NOT_NUMBERS)}
        if kind == 1:
            return path, {"scene_id": "simple_pendulum", "parameters": nested(rng.randrange(50))}
        if kind == 2:
            literal = rng.choice(["NaN", "Infinity", "-Infinity", "1e999", "-1e999"])
            key = rng.choice(["t_end", "fps", "parameters", "initial"])
            value = literal if key in ("t_end", "fps") else f'{{"m": {literal}}}'
            return path, f'{{"scene_id": "simple_pendulum", "{key}": {value}}}'
        if kind == 3:
            return path, rng.choice(['{"scene_id": ', "[]", "null", "1e308", '"x"', "{}" * 3])
        if kind == 4:
            return path, {"scene_id": "simple_pendulum", "surprise": nested(rng.randrange(30))}
        if kind == 5:
            spec = json.loads(json.dumps(POSTED))
            spec["bodies"][0]["mass"] = rng.choice(NOT_NUMBERS + [nested(20)])
            return path, {"scene": spec}
        return path, {"scene_id": rng.choice(["no_such_scene", "../etc", "", "A" * 65, 7])}

    def request(self) -> tuple[str, str, Any]:
        roll = self.rng.random()
        if roll < 0.40:
            return "POST", "/api/v1/simulate", self.simulate()
        if roll < 0.58:
            return "POST", "/api/v1/equilibria", self.equilibria()
        if roll < 0.68:
            return "POST", "/api/v1/check", self.check()
        if roll < 0.72:
            return "POST", "/api/v1/newton", {"scene_id": self.rng.choice(self.scenes[:6])}
        if roll < 0.75:
            return "POST", "/api/v1/derive", {"scene_id": self.rng.choice(self.scenes)}
        if roll < 0.78:
            scene_id = self.rng.choice([*self.scenes, "nope", "..%2Fx", "%00", "A" * 200])
            return "GET", f"/api/v1/scenes/{scene_id}", None
        if roll < 0.80:
            return "GET", self.rng.choice(["/api/v1/scenes", "/api/v1/methods"]), None
        if roll < 0.84 and self.posted_left > 0:
            return "POST", *self.posted()
        return "POST", *self.malformed()


def _strict(constant: str) -> Any:
    raise ValueError(f"{constant} in a JSON answer")


def send(client: TestClient, method: str, path: str, body: Any):
    if method == "GET":
        return client.get(path)
    if isinstance(body, str):
        return client.post(path, content=body, headers={"content-type": "application/json"})
    return client.post(path, json=body)


def assert_answer(response, method: str, path: str, body: Any) -> None:
    """200 with strict JSON, the documented 503, or a 4xx in the one error shape."""
    where = f"{method} {path} {body!r:.600} -> {response.status_code} {response.text[:400]}"
    status = response.status_code
    assert status < 500 or status == 503, where
    payload = json.loads(response.text, parse_constant=_strict)
    if status == 200:
        return
    detail = payload["detail"]
    assert isinstance(detail, list) and detail, where
    for problem in detail:
        assert set(problem) == {"field", "message"}, where
        assert isinstance(problem["field"], str) and problem["field"], where
        assert isinstance(problem["message"], str) and problem["message"], where


def fuzz(client: TestClient, seed: int, count: int, posted: int) -> Counter:
    fuzzer, seen = Fuzzer(seed, posted), Counter()
    for _ in range(count):
        method, path, body = fuzzer.request()
        response = send(client, method, path, body)
        assert_answer(response, method, path, body)
        seen[(path.rsplit("/", 1)[0] if method == "GET" else path, response.status_code)] += 1
    assert client.get("/healthz").status_code == 200
    return seen


def test_the_cases_fuzzing_found_answer_422_naming_the_field_or_a_flagged_result(client):
    for path, body in [
        ("/api/v1/simulate", {"scene_id": "simple_pendulum", "method": "LSODA"}),
        ("/api/v1/simulate", {"scene_id": "simple_pendulum", "parameters": {"l": 1e155}}),
        ("/api/v1/equilibria", {"scene_id": "bead_on_hoop", "parameters": {"Omega": 1e308}}),
        ("/api/v1/simulate", {"scene_id": "elastic_pendulum", "parameters": {"k": 1e-300}}),
        ("/api/v1/equilibria", {"scene_id": "elastic_pendulum", "parameters": {"k": 1e-300}}),
    ]:
        response = client.post(path, json=body)
        assert_answer(response, "POST", path, body)
    huge = client.post(
        "/api/v1/simulate", json={"scene_id": "simple_pendulum", "parameters": {"l": 1e155}}
    )
    assert [d["field"] for d in huge.json()["detail"]] == ["parameters.l"]


def test_a_few_hundred_fuzzed_requests_answer_no_5xx(client, short_runs):
    seen = fuzz(client, seed=12, count=300, posted=6)
    assert sum(seen.values()) == 300
    assert any(status == 200 for _, status in seen)  # the fuzzer also reaches the engine
    print(sorted(seen.items()))


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_thousands_of_fuzzed_requests_answer_no_5xx(client, short_runs, seed):
    fuzz(client, seed=seed, count=1000, posted=10)
