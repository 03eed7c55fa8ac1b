"""Real servers for tests that need one: a free loopback port, and a process started on it that is
waited for (its /healthz answers) and always stopped afterwards."""

from __future__ import annotations

import socket
import subprocess
import time
import urllib.request
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextmanager
def serving(
    command: Sequence[Any], port: int, *, what: str = "the server", **popen: Any
) -> Iterator[tuple[str, subprocess.Popen]]:
    """Start ``command`` (which listens on ``port``), yield (its URL, the process) once /healthz
    answers, and stop it afterwards, however the test ends."""
    proc = subprocess.Popen([str(c) if isinstance(c, Path) else c for c in command], **popen)
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 60
    try:
        while True:
            try:
                urllib.request.urlopen(f"{url}/healthz", timeout=1)
                break
            except OSError:
                if time.monotonic() > deadline or proc.poll() is not None:
                    raise RuntimeError(f"{what} did not start") from None
                time.sleep(0.2)
        yield url, proc
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
