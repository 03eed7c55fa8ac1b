"""A cache disk that cannot write costs speed, never an answer (issue 24, item 2).

Found by an attacker-and-class review: with the cache folder on a full disk, every cache miss was
a 500 (the lock file's write sat outside the error handling) and the empty lock file it left made
the same request wait the store's 60 s lock time once space was freed.

The disk here is real: a 1 MiB tmpfs mounted on the cache folder and filled with a file of zeros.
Where mounting is not permitted (and CI is set) the server-process test falls back to
RLIMIT_FSIZE = 64 bytes in the server's processes: every cache write (an entry, a lock record)
fails with EFBIG, while Python's 4-byte probe of its temporary folder still passes; the old code
answered 500 and left a cut-short lock the same way. The in-process test needs the mount and is
skipped with the reason.
"""

from __future__ import annotations

import json
import logging
import os
import resource
import signal
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from servers import free_port, serving

from mechanics import cache

ROOT = Path(__file__).resolve().parents[2]


class SmallDisk:
    """A 1 MiB tmpfs on ``folder`` (None in ``mounted`` when mount is not permitted)."""

    def __init__(self, folder: Path) -> None:
        self.folder, self.filler = folder, folder / "filler"
        folder.mkdir(parents=True, exist_ok=True)
        done = subprocess.run(
            ["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", str(folder)],
            capture_output=True,
            text=True,
        )
        self.mounted = done.returncode == 0
        self.why_not = done.stderr.strip() or f"mount exited {done.returncode}"

    def fill(self) -> None:
        """Write zeros until the file system says it is full."""
        with open(self.filler, "wb") as f:
            try:
                while True:
                    f.write(b"\0" * 65536)
                    f.flush()
            except OSError as exc:
                assert exc.errno in (28, 27), exc  # ENOSPC (EFBIG: a file-size limit)
        with pytest.raises(OSError):
            (self.folder / "probe").write_bytes(b"x" * 4096)

    def free(self) -> None:
        self.filler.unlink(missing_ok=True)

    def close(self) -> None:
        if self.mounted:
            subprocess.run(["umount", "-l", str(self.folder)], check=False)


@pytest.fixture
def disk(tmp_path: Path) -> Iterator[SmallDisk]:
    d = SmallDisk(tmp_path / "cache")
    yield d
    d.close()


def small_files() -> None:
    """preexec_fn of the fallback: no process of the server can write a file past 64 bytes."""
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # EFBIG instead of a signal (kept over exec)
    resource.setrlimit(resource.RLIMIT_FSIZE, (64, 64))


def post(url: str, path: str, body: dict, timeout: float) -> tuple[int, dict, float]:
    request = urllib.request.Request(
        f"{url}{path}", data=json.dumps(body).encode(), headers={"content-type": "application/json"}
    )
    start = time.monotonic()
    try:
        with urllib.request.urlopen(request, timeout=timeout) as answer:
            return answer.status, json.loads(answer.read()), time.monotonic() - start
    except urllib.error.HTTPError as err:
        return err.code, {"error": err.read().decode(errors="replace")}, time.monotonic() - start


@contextmanager
def server(cache_folder: Path, log: list[str], limit: bool) -> Iterator[str]:
    """A uvicorn server of the app caching in ``cache_folder``; its stderr lines go to ``log``
    (through a pipe: under the fallback's limit it could not write a log file)."""
    port = free_port()
    env = os.environ | {
        cache.ENV_VAR: str(cache_folder),
        "LAGRANGE_LAB_POOL_WORKERS": "1",
        "LAGRANGE_LAB_WARM": "0",  # the request below is the scene's first
    }
    env.pop(cache.REDIS_ENV_VAR, None)
    with serving(
        [sys.executable, "-m", "uvicorn", "app.main:app", "--port", str(port)]
        + ["--host", "127.0.0.1", "--log-level", "warning"],
        port,
        cwd=ROOT,
        env=env,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=small_files if limit else None,
    ) as (url, proc):
        drain = threading.Thread(target=lambda: log.extend(proc.stderr), daemon=True)
        drain.start()
        yield url
    drain.join(timeout=10)


def test_a_server_on_a_full_cache_disk_answers_and_a_freed_disk_does_not_stall(disk):
    """Full: derivations are 200s, logged once per process, no lock file left behind. Freed: a
    fresh server (cold memory) answers the same request at once, and now keeps the entry."""
    ci = os.environ.get("CI", "").lower() in ("1", "true", "yes")
    if not disk.mounted and not ci:
        pytest.skip(f"cannot mount a tmpfs here ({disk.why_not}); CI uses RLIMIT_FSIZE instead")
    if disk.mounted:
        disk.fill()
    log: list[str] = []
    with server(disk.folder, log, limit=not disk.mounted) as url:
        for scene in ("simple_pendulum", "bead_on_hoop", "simple_pendulum"):
            status, body, _ = post(url, "/api/v1/derive", {"scene_id": scene}, timeout=120)
            assert status == 200, body
            assert body["equations"]["eom"]
    logged = "".join(log)
    assert "Traceback" not in logged, logged[-3000:]
    # once per process that met the full disk (the server, and its one pool worker at most)
    assert 1 <= logged.count("cannot write") <= 2, logged[-3000:]
    assert not list(disk.folder.rglob("*.lock")), "a lock file outlived its request"

    disk.free()
    with server(disk.folder, [], limit=False) as url:
        status, body, seconds = post(url, "/api/v1/derive", {"scene_id": "simple_pendulum"}, 30)
    assert status == 200 and body["equations"]["eom"]
    assert seconds < 15, f"the freed disk made the request wait {seconds:.1f} s"
    assert list((disk.folder / "derivation").glob("*.entry")), "entries are kept again"


@pytest.fixture
def full_disk_here(disk: SmallDisk, monkeypatch: pytest.MonkeyPatch) -> Iterator[SmallDisk]:
    """This process caches on the small disk, no Redis, the disk not known bad."""
    if not disk.mounted:
        pytest.skip(f"cannot mount a tmpfs here ({disk.why_not})")
    monkeypatch.setenv(cache.ENV_VAR, str(disk.folder))
    monkeypatch.delenv(cache.REDIS_ENV_VAR, raising=False)
    monkeypatch.setitem(cache._disk_state, "down_until", 0.0)
    monkeypatch.setitem(cache._disk_state, "logged", False)
    monkeypatch.setattr(cache.cache_disk, "RETRY_SECONDS", 0.3)
    cache._memories.clear()
    yield disk


def test_a_full_disk_is_logged_once_and_written_again_once_freed(full_disk_here, caplog):
    """Every miss is computed and answered; one warning for the outage; after the retry time
    the next value is written, and a note says the disk is writable again."""
    full_disk_here.fill()
    with caplog.at_level(logging.WARNING, logger="mechanics.cache"):
        for i in range(5):
            assert cache.get_or_compute("check", {"full": i}, lambda i=i: {"i": i}) == {"i": i}
        assert [r for r in caplog.records if "cannot write" in r.message][1:] == []
        assert cache.get_or_compute("check", {"full": 0}, lambda: {"i": "again"}) == {"i": 0}
        full_disk_here.free()
        time.sleep(0.4)
        assert cache.get_or_compute("check", {"full": 9}, lambda: {"i": 9}) == {"i": 9}
    assert (
        full_disk_here.folder / "check" / f"{cache.key_for('check', {'full': 9})}.entry"
    ).exists()
    assert any("writable again" in r.message for r in caplog.records)
    assert not list(full_disk_here.folder.rglob("*.lock"))
    assert not list(full_disk_here.folder.rglob("*.tmp"))
