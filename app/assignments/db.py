"""Where the assignments live: a SQLite file in the data directory by default (so
``lagrange-lab serve`` needs nothing else), PostgreSQL when ``LAGRANGE_LAB_DATABASE_URL`` says so
(several app servers then share it). The schema is brought to the latest Alembic migration when a
database is first opened.

- ``LAGRANGE_LAB_DATABASE_URL``: a SQLAlchemy URL (``postgresql+psycopg://user@host/db``);
- ``LAGRANGE_LAB_DATA_DIR``: the folder of the SQLite file ``assignments.sqlite3`` when no URL
  is given (default ``~/.local/share/lagrange-lab``).
"""

from __future__ import annotations

import os
import threading
from pathlib import Path

from alembic import command
from alembic.config import Config
from sqlalchemy import Engine, create_engine, event
from sqlalchemy.exc import DBAPIError, OperationalError

DATABASE_URL_ENV = "LAGRANGE_LAB_DATABASE_URL"
DATA_DIR_ENV = "LAGRANGE_LAB_DATA_DIR"
MIGRATIONS = Path(__file__).resolve().parent / "alembic"
#: How long a request waits for the database before it is called unreachable.
CONNECT_SECONDS = 5

_engines: dict[str, Engine] = {}
_lock = threading.Lock()


class DatabaseUnavailable(RuntimeError):
    """The database cannot be reached: the web layer answers 503 and says so."""


def data_dir() -> Path:
    raw = os.environ.get(DATA_DIR_ENV)
    return Path(raw).expanduser() if raw else Path.home() / ".local" / "share" / "lagrange-lab"


def database_url() -> str:
    url = os.environ.get(DATABASE_URL_ENV, "").strip()
    if url:
        return url
    folder = data_dir()
    folder.mkdir(parents=True, exist_ok=True)
    return f"sqlite:///{folder / 'assignments.sqlite3'}"


def _sqlite_pragmas(dbapi_connection, _record) -> None:  # noqa: ANN001 (DB-API objects)
    """WAL: readers never wait for the writer; a writer waits (busy_timeout) instead of failing;
    synchronous=FULL: a committed submission survives the server being killed."""
    cursor = dbapi_connection.cursor()
    cursor.execute("PRAGMA journal_mode=WAL")
    cursor.execute("PRAGMA busy_timeout=10000")
    cursor.execute("PRAGMA synchronous=FULL")
    cursor.execute("PRAGMA foreign_keys=ON")
    cursor.close()


def make_engine(url: str) -> Engine:
    if url.startswith("sqlite"):
        engine = create_engine(url, connect_args={"check_same_thread": False, "timeout": 10})
        event.listen(engine, "connect", _sqlite_pragmas)
        return engine
    connect = {"connect_timeout": CONNECT_SECONDS} if url.startswith("postgresql") else {}
    return create_engine(
        url, pool_pre_ping=True, pool_size=10, max_overflow=20, connect_args=connect
    )


def migrate(engine: Engine) -> None:
    """Bring the schema to the newest migration (idempotent)."""
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    with engine.begin() as connection:
        config.attributes["connection"] = connection
        command.upgrade(config, "head")


def engine_for(url: str | None = None) -> Engine:
    """The engine of ``url`` (default: the configured one), migrated once per process; raises
    DatabaseUnavailable when it cannot be reached."""
    url = url or database_url()
    with _lock:
        engine = _engines.get(url)
        if engine is None:
            engine = make_engine(url)
            try:
                migrate(engine)
            except (OperationalError, DBAPIError) as exc:
                engine.dispose()
                raise DatabaseUnavailable(describe(exc)) from None
            _engines[url] = engine
        return engine


def describe(exc: BaseException) -> str:
    """The driver's first line, without the SQL (no data of anyone in an error answer)."""
    text = str(getattr(exc, "orig", exc)).strip().splitlines()
    return text[0][:200] if text else type(exc).__name__


def forget_engines() -> None:
    """Close every engine (tests that start and stop databases)."""
    with _lock:
        for engine in _engines.values():
            engine.dispose()
        _engines.clear()
