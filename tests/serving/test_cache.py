"""The cache (mechanics/cache.py) on the local disk: keys, verification on read, single flight in
threads and across processes, locks that do not outlive their process, a bounded folder, Redis
going away — and compiled libraries that are verified before they are loaded (mechanics/native).

Redis itself, and two app servers sharing it, are in test_redis.py.
"""

from __future__ import annotations

import json
import logging
import math
import os
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from servers import free_port

from mechanics import cache, derive, native
from mechanics.scenes import load_scene

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def fresh_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty cache folder (and so a cold memory tier), no Redis."""
    monkeypatch.setenv(cache.ENV_VAR, str(tmp_path))
    monkeypatch.delenv(cache.REDIS_ENV_VAR, raising=False)
    monkeypatch.setitem(cache._redis_state, "down_until", 0.0)
    monkeypatch.setitem(cache._redis_state, "logged", False)
    monkeypatch.setitem(cache._disk_state, "down_until", 0.0)
    monkeypatch.setitem(cache._disk_state, "logged", False)
    return tmp_path


def entry_path(store: str, parts: object) -> Path:
    return cache.cache_dir() / store / f"{cache.key_for(store, parts)}.entry"


def forget_memory() -> None:
    """What a fresh process (another worker) sees: only the disk."""
    cache._memories.clear()


class Counting:
    """A computation that counts its calls."""

    def __init__(self, value: object, seconds: float = 0.0, error: Exception | None = None):
        self.value, self.seconds, self.error, self.calls = value, seconds, error, 0
        self.lock = threading.Lock()

    def __call__(self) -> object:
        with self.lock:
            self.calls += 1
        time.sleep(self.seconds)
        if self.error is not None:
            raise self.error
        return self.value


# --- keys -------------------------------------------------------------------------------------


def test_a_key_is_the_canonical_json_of_store_engine_and_parts(monkeypatch):
    a = cache.key_for("equilibria", {"spec": {"m": 1, "l": 2}, "parameters": {"g": 9.81}})
    b = cache.key_for("equilibria", {"parameters": {"g": 9.81}, "spec": {"l": 2, "m": 1}})
    assert a == b and len(a) == 64
    assert a != cache.key_for("newton", {"spec": {"m": 1, "l": 2}, "parameters": {"g": 9.81}})
    assert a != cache.key_for("equilibria", {"spec": {"m": 1, "l": 2}, "parameters": {"g": 9.8}})
    monkeypatch.setattr(cache, "ENGINE_VERSION", "another")
    assert a != cache.key_for("equilibria", {"spec": {"m": 1, "l": 2}, "parameters": {"g": 9.81}})


def test_an_unknown_store_is_a_programming_error():
    with pytest.raises(ValueError, match="no cache store 'derivations'"):
        cache.get_or_compute("derivations", {}, dict)


def test_a_value_is_computed_once_then_read_from_disk_by_another_process():
    compute = Counting({"omega": [1.5, 2.5], "stable": True})
    first = cache.get_or_compute("equilibria", {"spec": 1}, compute)
    forget_memory()
    second = cache.get_or_compute("equilibria", {"spec": 1}, compute)
    assert first == second == {"omega": [1.5, 2.5], "stable": True}
    assert compute.calls == 1 and cache.stats()["equilibria"]["hit"] >= 1


def test_a_computed_value_is_what_a_reader_gets():
    """A miss answers what a hit would: the value as read back from its JSON (tuples are lists)."""
    value = cache.get_or_compute("newton", {"spec": 2}, lambda: {"forces": (1, 2)})
    assert value == {"forces": [1, 2]}


def test_a_value_that_is_not_json_is_returned_but_not_stored():
    value = cache.get_or_compute("newton", {"spec": 3}, lambda: {"x": math.nan})
    assert math.isnan(value["x"])
    assert not entry_path("newton", {"spec": 3}).exists()


# --- verified on read: every case of the module docstring's list --------------------------------


def good_entry(store: str, parts: object, value: object) -> bytes:
    cache.get_or_compute(store, parts, lambda: value)
    forget_memory()
    return entry_path(store, parts).read_bytes()


def tampered(kind: str) -> bytes:
    """A bad entry for the ``newton`` store, key {"spec": 7}, of the given kind."""
    parts, stale = {"spec": 7}, {"tension": "stale"}
    data = good_entry("newton", parts, stale)
    head, _, payload = data.partition(b"\n")
    header = json.loads(head)
    if kind == "bare value, the old format":
        return json.dumps(stale).encode()
    if kind == "old engine":
        return json.dumps(header | {"engine": "0"}).encode() + b"\n" + payload
    if kind == "another key":
        other = good_entry("newton", {"spec": 8}, stale)  # a real entry, filed under a wrong name
        return other
    if kind == "another store":
        return good_entry("equilibria", parts, stale)
    if kind == "truncated":
        return data[: len(data) - 5]
    if kind == "altered, same length":
        return head + b"\n" + payload.replace(b"stale", b"stali")
    if kind == "altered, length and hash updated":  # passes the hash: the validator catches it
        body = json.dumps({"wrong": "shape"}).encode()
        header |= {"bytes": len(body), "sha256": __import__("hashlib").sha256(body).hexdigest()}
        return json.dumps(header).encode() + b"\n" + body
    if kind == "not json":
        return b"\x00\xffgarbage"
    if kind == "empty":
        return b""
    raise AssertionError(kind)


KINDS = [
    "bare value, the old format",
    "old engine",
    "another key",
    "another store",
    "truncated",
    "altered, same length",
    "altered, length and hash updated",
    "not json",
    "empty",
]


@pytest.mark.parametrize("kind", KINDS)
def test_a_bad_entry_is_recomputed_and_replaced_never_served(kind, caplog):
    bad = tampered(kind)
    path = entry_path("newton", {"spec": 7})
    path.write_bytes(bad)
    forget_memory()
    fresh = Counting({"tension": "fresh"})

    def shaped(value: object) -> bool:
        return isinstance(value, dict) and "tension" in value

    with caplog.at_level(logging.WARNING, logger="mechanics.cache"):
        assert cache.get_or_compute("newton", {"spec": 7}, fresh, shaped) == {"tension": "fresh"}
    assert fresh.calls == 1
    assert any("ignoring newton entry" in r.message for r in caplog.records)
    forget_memory()
    assert cache.get("newton", {"spec": 7}, shaped) == {"tension": "fresh"}  # replaced


@pytest.mark.parametrize("validate", [lambda v: False, lambda v: v["missing"]])
def test_a_value_its_validator_refuses_or_trips_over_is_recomputed(validate):
    good_entry("check", {"answer": "x"}, {"correct": True})
    compute = Counting({"correct": False})
    assert cache.get_or_compute("check", {"answer": "x"}, compute, validate) == {"correct": False}
    assert compute.calls == 1


def test_a_tampered_derivation_is_recomputed_and_a_posted_copy_shares_the_entry():
    """The derivation store end to end: derive_scene's entry damaged on disk is not served; the
    same spec posted (keys in another order) is the same entry, not another computation."""
    answer = derive.derive_scene("simple_pendulum")
    assert derive.is_derivation_json(answer)
    path = cache.cache_dir() / "derivation"
    (entry,) = path.glob("*.entry")
    data = entry.read_bytes()
    entry.write_bytes(data.replace(b'"accelerations"', b'"acceleration5"'))  # same length
    forget_memory()
    again = derive.derive_scene("simple_pendulum")
    assert again == answer and cache.stats()["derivation"]["invalid"] >= 1
    forget_memory()
    raw = json.loads(json.dumps(load_scene("simple_pendulum")))
    posted = dict(reversed(list(raw.items())))
    before = cache.stats()["derivation"].get("computed", 0)
    assert derive.derive_cached(posted, compute=lambda: pytest.fail("derived again")) == answer
    assert cache.stats()["derivation"].get("computed", 0) == before


@pytest.mark.parametrize(
    "value",
    [
        {"answer": 42},
        {"scene": {}, "steps": [], "equations": {}, "latex": {}, "warnings": [], "seconds": 0},
        [1, 2, 3],
        "not an object",
    ],
)
def test_a_derivation_entry_of_the_wrong_shape_is_recomputed(value):
    """An entry whose header and hash are right (written by a buggy engine of this version) but
    whose value is not a derivation: is_derivation_json refuses it, the scene is derived again."""
    parts = derive.scene_key("simple_pendulum")
    cache.get_or_compute("derivation", parts, lambda: value)  # stored: no validator given
    forget_memory()
    answer = derive.derive_scene("simple_pendulum")
    assert answer != value and derive.is_derivation_json(answer)
    assert answer["equations"]["accelerations"] is not None


# --- single flight ----------------------------------------------------------------------------


def run_threads(n: int, target) -> list:
    results: list = [None] * n

    def one(i: int) -> None:
        try:
            results[i] = target()
        except Exception as exc:  # noqa: BLE001 — the test looks at what each thread got
            results[i] = exc

    threads = [threading.Thread(target=one, args=(i,)) for i in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    return results


def test_identical_concurrent_requests_in_a_process_wait_for_one_computation():
    compute = Counting({"value": 1}, seconds=0.3)
    results = run_threads(8, lambda: cache.get_or_compute("derivation", {"s": 1}, compute))
    assert compute.calls == 1
    assert results == [{"value": 1}] * 8


def test_a_computation_that_raises_reaches_every_waiter_and_leaves_no_lock():
    compute = Counting(None, seconds=0.3, error=RuntimeError("sympy gave up"))
    results = run_threads(4, lambda: cache.get_or_compute("derivation", {"s": 2}, compute))
    assert compute.calls == 1
    assert all(isinstance(r, RuntimeError) and "sympy gave up" in str(r) for r in results)
    assert not list((cache.cache_dir() / "derivation").glob("*.lock"))
    assert cache.get_or_compute("derivation", {"s": 2}, lambda: {"ok": 1}) == {"ok": 1}


WORKER = """
import json, os, sys, time
from mechanics import cache
parts, log, seconds, fail = json.loads(sys.argv[1]), sys.argv[2], float(sys.argv[3]), sys.argv[4]
def compute():
    with open(log, "a") as f:
        f.write(f"{os.getpid()}\\n")
    time.sleep(seconds)
    if fail == "1":
        raise RuntimeError("failed on purpose")
    return {"by": os.getpid()}
try:
    print(json.dumps(cache.get_or_compute("equilibria", parts, compute)))
except RuntimeError as exc:
    print(json.dumps({"error": str(exc)}))
"""


def worker(parts: object, log: Path, seconds: float, fail: bool = False) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-c", WORKER, json.dumps(parts), str(log), str(seconds), "01"[fail]],
        cwd=ROOT,
        env=os.environ.copy(),
        stdout=subprocess.PIPE,
        text=True,
    )


def wait_for(predicate, seconds: float = 20.0) -> None:
    deadline = time.monotonic() + seconds
    while not predicate():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.02)


def test_identical_requests_in_several_processes_wait_for_one_computation(tmp_path):
    log = tmp_path / "computations.log"
    procs = [worker({"p": 1}, log, 1.0) for _ in range(4)]
    answers = [json.loads(p.communicate(timeout=60)[0]) for p in procs]
    assert len(log.read_text().split()) == 1
    assert len({a["by"] for a in answers}) == 1


def test_a_lock_whose_process_was_killed_does_not_stall_anyone(tmp_path):
    log = tmp_path / "computations.log"
    holder = worker({"p": 2}, log, 300.0)
    lock = entry_path("equilibria", {"p": 2}).with_suffix(".lock")
    wait_for(lambda: log.exists() and lock.exists())
    holder.kill()  # kill -9 mid-computation: the lock file stays behind
    holder.wait()
    assert lock.exists()
    start = time.monotonic()
    assert cache.get_or_compute("equilibria", {"p": 2}, lambda: {"by": "me"}) == {"by": "me"}
    assert time.monotonic() - start < 2.0  # its process is gone: stale at once
    assert not lock.exists()


def test_a_lock_past_its_time_is_broken(monkeypatch):
    """A lock from another host (its process cannot be asked) expires with its store's time."""
    lock = entry_path("check", {"p": 3}).with_suffix(".lock")
    lock.parent.mkdir(parents=True)
    lock.write_text(json.dumps({"token": "t", "host": "elsewhere", "pid": 1}))
    old = time.time() - cache.STORES["check"].lock_seconds - 1
    os.utime(lock, (old, old))
    assert cache.get_or_compute("check", {"p": 3}, lambda: {"ok": 1}) == {"ok": 1}


def test_when_the_computer_in_another_process_fails_the_waiter_computes(tmp_path):
    log = tmp_path / "computations.log"
    failing = worker({"p": 4}, log, 0.5, fail=True)
    wait_for(log.exists)
    compute = Counting({"by": "me"})
    assert cache.get_or_compute("equilibria", {"p": 4}, compute) == {"by": "me"}
    assert compute.calls == 1
    assert json.loads(failing.communicate(timeout=30)[0]) == {"error": "failed on purpose"}


# --- a bounded folder, Redis away ---------------------------------------------------------------


def test_the_disk_store_stays_bounded(monkeypatch):
    monkeypatch.setenv(cache.SIZE_ENV_VAR, "0.01")  # ~10 kB
    monkeypatch.setattr(cache.DiskBackend, "PRUNE_EVERY", 1)
    for i in range(40):
        cache.get_or_compute("check", {"i": i}, lambda i=i: {"feedback": "x" * 1000, "i": i})
    folder = cache.cache_dir() / "check"
    total = sum(f.stat().st_size for f in folder.glob("*.entry"))
    assert 0 < total <= 0.01 * 1024 * 1024 + 1200
    forget_memory()
    assert cache.get("check", {"i": 39}) == {"feedback": "x" * 1000, "i": 39}  # newest kept


def test_without_redis_values_are_computed_and_kept_on_disk_logged_once(monkeypatch, caplog):
    monkeypatch.setenv(cache.REDIS_ENV_VAR, f"redis://127.0.0.1:{free_port()}/0")
    monkeypatch.setattr(cache.cache_redis, "RETRY_SECONDS", 0.0)  # try Redis on every call
    with caplog.at_level(logging.WARNING, logger="mechanics.cache"):
        for i in range(3):
            assert cache.get_or_compute("newton", {"i": i}, lambda i=i: {"i": i}) == {"i": i}
    assert len([r for r in caplog.records if "Redis is unreachable" in r.message]) == 1
    assert entry_path("newton", {"i": 2}).exists()
    assert cache.shared_computations("newton") is None


# --- compiled libraries: verified before they are loaded ---------------------------------------


@pytest.fixture
def libraries(monkeypatch):
    """Two right-hand sides (q̈ = -q, q̈ = -5q) compiled into the fresh cache; their files."""
    if native.compiler() is None:
        pytest.skip("no C compiler")
    native._rhs_library.cache_clear()
    args = list(sp.symbols("t_ q_0 u_0"))
    sources = [native.rhs_source(args, 1, sp.S.Zero, accelerations=[-k * args[1]]) for k in (1, 5)]
    for src in sources:
        native.compile_rhs(src, [], 3)
    native._rhs_library.cache_clear()
    files = [next((cache.cache_dir() / "native").glob(f"rhs-{_digest(s)}.so")) for s in sources]
    yield sources, files
    native._rhs_library.cache_clear()


def _digest(source: str) -> str:
    import hashlib
    import platform

    parts = [source, " ".join(native.FLAGS), platform.machine(), platform.system()]
    return hashlib.sha256("\0".join(parts).encode()).hexdigest()[:24]


def builds(monkeypatch) -> list:
    runs: list = []
    real = subprocess.run
    monkeypatch.setattr(subprocess, "run", lambda *a, **k: runs.append(a) or real(*a, **k))
    return runs


def accelerations(sources: list[str]) -> list[float]:
    y = np.array([1.0, 0.0, 0.0])
    return [float(native.compile_rhs(src, [], 3)(0.0, y)[1]) for src in sources]


def test_a_verified_library_is_loaded_without_compiling(libraries, monkeypatch):
    sources, _ = libraries
    runs = builds(monkeypatch)
    assert accelerations(sources) == [-1.0, -5.0] and runs == []


def test_a_truncated_library_is_rebuilt_never_loaded(libraries, monkeypatch):
    sources, files = libraries
    files[0].write_bytes(files[0].read_bytes()[:1000])
    runs = builds(monkeypatch)
    assert accelerations(sources) == [-1.0, -5.0] and len(runs) == 1
    native._rhs_library.cache_clear()
    assert accelerations(sources) == [-1.0, -5.0] and len(runs) == 1  # the rebuilt one is good


@pytest.mark.parametrize("with_records", [False, True])
def test_swapped_libraries_are_rebuilt_never_run_as_the_other_scene(
    libraries, monkeypatch, with_records
):
    """Swapping the .so files (and, the second time, their records too) must not make q̈ = -q run
    q̈ = -5q: the record's source hash or library hash no longer matches."""
    sources, files = libraries
    pairs = [files] + ([[f.with_suffix(".json") for f in files]] if with_records else [])
    for a, b in pairs:
        tmp = a.with_suffix(".swap")
        shutil.move(a, tmp)
        shutil.move(b, a)
        shutil.move(tmp, b)
    runs = builds(monkeypatch)
    assert accelerations(sources) == [-1.0, -5.0] and len(runs) == 2


def test_a_library_without_its_record_is_rebuilt(libraries, monkeypatch):
    sources, files = libraries
    files[1].with_suffix(".json").unlink()
    runs = builds(monkeypatch)
    assert accelerations(sources) == [-1.0, -5.0] and len(runs) == 1


# --- C source from outside the process would be checked before it is compiled (none is shared) --


def test_every_generated_source_passes_the_check_of_a_shared_source():
    from mechanics.numeric import compiled_scene
    from mechanics.scenes import scene_ids

    for scene_id in scene_ids():
        assert native.is_generated_source(compiled_scene(scene_id).native_source), scene_id
    args = list(sp.symbols("t_ q_0 q_1 u_0 u_1 k"))
    q0, q1, k = args[1], args[2], args[5]
    mass = [2 + sp.cos(q1), 1, 1, 3]  # M q̈ = f, solved in C: the source carries lab_solve
    source = native.rhs_source(args, 2, sp.S.Zero, mass=mass, forcing=[-k * q0, -k * q1])
    assert "lab_solve" in source and native.is_generated_source(source)


@pytest.mark.parametrize(
    ("find", "replace"),
    [
        ("    return 0;\n}", '    return 0;\n}\nint evil(void) { return system("x"); }'),
        ("#include <math.h>", "#include <stdlib.h>"),
        ("    dy[0] = y[1];", '    dy[0] = y[1]; system("rm -rf /");'),
        ("    dy[0] = y[1];", "    dy[0] = system(0);"),
        ("    dy[0] = y[1];", "    dy[0] = y[1] /* hidden */;"),
        ("    dy[0] = y[1];", "#define sin system\n    dy[0] = y[1];"),
        ("/* lab: dim 3 params 0 */", "/* lab: dim 3 params 9 */ int x;"),
    ],
)
def test_a_source_that_is_not_generated_is_refused(find, replace):
    args = list(sp.symbols("t_ q_0 u_0"))
    source = native.rhs_source(args, 1, sp.S.Zero, accelerations=[-sp.sin(args[1])])
    assert native.is_generated_source(source) and find in source
    assert not native.is_generated_source(source.replace(find, replace, 1))


@pytest.mark.parametrize(
    "body",
    [
        b"",  # a writer that died (or whose disk filled) between creating the file and writing it
        b'{"token": "half',  # cut short
        json.dumps({"token": "t", "host": "elsewhere", "pid": 1, "until": 1.0}).encode(),
    ],
    ids=["empty", "cut short", "past its deadline"],
)
def test_a_stale_lock_is_recognised_at_once(body, monkeypatch):
    """Issue 24 (item 2): an empty lock file made the same request wait the store's whole lock
    time. A lock that names no owner, or whose own deadline has passed, is broken at once."""
    monkeypatch.setitem(cache.STORES, "check", cache.Store("check", ttl_seconds=60, lock_seconds=5))
    lock = entry_path("check", {"stale": 1}).with_suffix(".lock")
    lock.parent.mkdir(parents=True, exist_ok=True)
    lock.write_bytes(body)
    start = time.monotonic()
    assert cache.get_or_compute("check", {"stale": 1}, lambda: {"ok": 1}) == {"ok": 1}
    assert time.monotonic() - start < 1.5
    assert not lock.exists()


SHARE = """
import json, sys
import mechanics
from mechanics import cache
assert mechanics.__file__.startswith(sys.argv[1]), mechanics.__file__
print(json.dumps(cache.get_or_compute("newton", {"spec": "deployed"}, lambda: {"by": sys.argv[2]})))
"""


def test_deployments_with_the_same_version_but_different_code_share_no_entry(tmp_path):
    """Issue 24 (item 6): two servers with the same ENGINE_VERSION but different engine code read
    each other's entries. Three copies of the engine share one cache folder: a copy identical to
    the first reads its entry, a copy with one changed source computes its own."""
    copies = {}
    for name in ("first", "same", "changed"):
        copies[name] = tmp_path / name
        shutil.copytree(
            ROOT / "mechanics",
            copies[name] / "mechanics",
            ignore=shutil.ignore_patterns("__pycache__"),
        )
    with open(copies["changed"] / "mechanics" / "equilibria.py", "a") as f:
        f.write("\n# a deployment with one more line of engine code\n")

    def run(name: str) -> dict:
        done = subprocess.run(
            [sys.executable, "-c", SHARE, str(copies[name]), name],
            cwd=copies[name],
            env=os.environ | {cache.ENV_VAR: str(tmp_path / "shared-cache")},
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert done.returncode == 0, done.stderr[-2000:]
        return json.loads(done.stdout)

    assert run("first") == {"by": "first"}
    assert run("same") == {"by": "first"}  # the same code: the entry is shared
    assert run("changed") == {"by": "changed"}  # other code: never the first one's entry
