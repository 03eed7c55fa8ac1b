"""Every environment variable the app reads, in one object, read once (docs/settings.md).

The engine (mechanics/) never imports app/, so the variables it needs (the cache folder, the C
compiler) are still read where they are used, by the same names; they are mirrored here so that
one object, and one page of docs, lists every knob a deployment has.

    from app.settings import settings
    settings.derive_seconds  # 20.0 unless LAGRANGE_LAB_DERIVE_SECONDS says otherwise
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping
from dataclasses import MISSING, dataclass, field, fields
from pathlib import Path

log = logging.getLogger(__name__)

PREFIX = "LAGRANGE_LAB_"


@dataclass(frozen=True)
class Settings:
    """One deployment's configuration; each field is ``LAGRANGE_LAB_<FIELD NAME>``."""

    #: Folder of cached derivations and compiled C libraries (read by mechanics/cache.py).
    cache: Path = Path.home() / ".cache" / "lagrange-lab"
    #: Wall-time budget in seconds of one posted scene's derivation (past it: 503).
    derive_seconds: float = 20.0
    #: Wall-time budget in seconds of checking an answer on a built-in scene (past it: 503).
    check_seconds: float = 5.0
    #: The C compiler for ``dop853_c`` (read by mechanics/native); "none" switches it off,
    #: empty means the first of cc, gcc, clang found.
    cc: str = ""
    #: Size bound in MB of each cache store on disk; the least recently used entries go first
    #: (read by mechanics/cache.py).
    cache_mb: int = 256
    #: Redis URL of the shared cache (several app servers); empty: the local disk only (read by
    #: mechanics/cache.py).
    redis_url: str = ""
    #: Worker processes of ``lagrange-lab serve`` when --workers is not given.
    workers: int = 1
    #: Processes of the warm pool that runs sympy work on user input, per server process
    #: (read by app/derivations.py).
    pool_workers: int = field(default_factory=lambda: max(2, os.cpu_count() or 1))
    #: Pool jobs one client may have running at once; 0 means half the pool (at least 1).
    pool_per_client: int = 0
    #: "1" behind a proxy that sets X-Forwarded-For: the client is the last address in it.
    trust_forwarded: bool = False
    #: Largest request body in bytes; a larger one is refused with 413 as it streams in.
    max_body_bytes: int = 1024 * 1024
    #: Seconds a client has to send a request's headers (app/server.py); then it is closed.
    header_seconds: float = 10.0
    #: Seconds a client has to send a request's whole body once its headers came; then 408.
    body_seconds: float = 30.0
    #: Largest request line and headers in bytes; larger: 431, read no further (app/server.py).
    max_header_bytes: int = 32 * 1024
    #: Connections one client address may hold to one server process; more: 429 and closed.
    #: Not applied with ``trust_forwarded`` (every connection is then the proxy's).
    client_connections: int = 128
    #: "0" switches off making every built-in scene ready when the server starts (derivation,
    #: compiled equations, equilibria; in the background): the first request then pays for it.
    warm: bool = True
    #: SQLAlchemy URL of the assignments' database (several app servers share it, e.g.
    #: postgresql+psycopg://user@host/db); empty: a SQLite file in ``data_dir``
    #: (read by app/assignments/db.py).
    database_url: str = ""
    #: Folder of the assignments' SQLite file when no ``database_url`` is given
    #: (read by app/assignments/db.py).
    data_dir: Path = Path.home() / ".local" / "share" / "lagrange-lab"
    #: Submissions one student may make per minute, over every assignment (counted in the
    #: database; read by app/assignments/service.py).
    submissions_per_minute: int = 30

    @classmethod
    def from_env(cls, environ: Mapping[str, str] | None = None) -> Settings:
        """Read ``environ`` (default os.environ) once; a value that does not parse, or is not
        positive where a count or a duration is meant, is logged and the default kept."""
        environ = os.environ if environ is None else environ
        values: dict[str, object] = {}
        for f in fields(cls):
            raw = environ.get(PREFIX + f.name.upper())
            if raw is None:
                continue
            default = getattr(cls, f.name, None) if f.default_factory is MISSING else None
            kind = type(default) if default is not None else int
            try:
                if kind is bool:
                    value: object = raw.strip() == "1"
                elif issubclass(kind, Path):
                    value = Path(raw).expanduser()
                else:
                    value = kind(raw)
            except ValueError:
                value = None
            numeric = isinstance(value, int | float) and not isinstance(value, bool)
            if value is None or numeric and not 0 < value < float("inf"):
                log.warning("%s%s=%r is not valid; using %r", PREFIX, f.name.upper(), raw, default)
                continue
            values[f.name] = value
        return cls(**values)

    @property
    def per_client(self) -> int:
        """Pool jobs one client may run at once: ``pool_per_client``, else half the pool."""
        return self.pool_per_client or max(1, self.pool_workers // 2)


#: The settings of this process, read when app/ is first imported.
settings = Settings.from_env()
