"""The ``lagrange-lab`` command: ``lagrange-lab serve`` starts the web app with uvicorn.

One command a newcomer can remember; everything else (host, port, workers) has a sane default for
a laptop, and production runs the same command with ``--host 0.0.0.0 --workers N``.
"""

from __future__ import annotations

import argparse
import os
from functools import partial

import uvicorn

from app.assignments.cli import add_export_command, add_token_command, run_export, run_token
from app.server import HEADER_TIMEOUT, HeaderDeadlineProtocol, install_connection_guard


def build_parser() -> argparse.ArgumentParser:
    """The argument parser, separate from main() so tests and docs can inspect it."""
    parser = argparse.ArgumentParser(
        prog="lagrange-lab", description="Lagrange Lab: analytical mechanics, step by step."
    )
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    add_token_command(commands)  # lagrange-lab token create (app/assignments/cli.py)
    add_export_command(commands)  # lagrange-lab export prairielearn TEMPLATE DIR
    serve = commands.add_parser("serve", help="start the web app (http://127.0.0.1:8000)")
    serve.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1)")
    serve.add_argument("--port", type=int, default=8000, help="port to bind (default 8000)")
    serve.add_argument("--workers", type=int, default=1, help="worker processes (default 1)")
    serve.add_argument("--reload", action="store_true", help="restart when a source file changes")
    serve.add_argument(
        "--pool-workers",
        type=int,
        default=None,
        help="warm processes per worker for sympy work on user input "
        "(default: cores / workers, at least 2)",
    )
    serve.add_argument(
        "--timeout-keep-alive",
        type=float,
        default=5,
        help="close an idle kept-alive connection after this many seconds (default 5)",
    )
    serve.add_argument(
        "--timeout-headers",
        type=float,
        default=HEADER_TIMEOUT,
        help="close a connection whose request headers take longer than this "
        f"(default {HEADER_TIMEOUT:g} s)",
    )
    return parser


def pool_workers(requested: int | None, workers: int) -> None:
    """Size each server process's pool (app/derivations.py) through its environment variable,
    which uvicorn's worker processes inherit: as asked, else the cores shared among the workers,
    at least 2 (so one busy client never holds them all), unless the variable is already set."""
    if requested is not None:
        os.environ["LAGRANGE_LAB_POOL_WORKERS"] = str(requested)
    else:
        share = max(2, (os.cpu_count() or 1) // workers)
        os.environ.setdefault("LAGRANGE_LAB_POOL_WORKERS", str(share))


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script and of ``python -m app``; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command == "token":
        return run_token(args)
    if args.command == "export":
        return run_export(args)
    if args.command != "serve":
        parser.print_help()
        return 2
    if args.workers < 1:
        parser.error("--workers must be at least 1")
    if args.reload and args.workers > 1:
        parser.error("--reload runs a single worker; drop --workers")
    if args.pool_workers is not None and args.pool_workers < 1:
        parser.error("--pool-workers must be at least 1")
    pool_workers(args.pool_workers, args.workers)
    install_connection_guard()  # app.main installs it too, in every worker it is imported in
    uvicorn.run(
        "app.main:app",
        host=args.host,
        port=args.port,
        workers=args.workers,
        reload=args.reload,
        http=partial(HeaderDeadlineProtocol, header_timeout=args.timeout_headers),
        timeout_keep_alive=args.timeout_keep_alive,
    )
    return 0
