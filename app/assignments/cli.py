"""``lagrange-lab token create``: an API token for an instructor (or a student), printed once.

    lagrange-lab token create --name "Dr Ada"                  # an instructor's token
    lagrange-lab token create --role student --name s1001      # a student's

Only the token's sha256 is stored, in the configured database (LAGRANGE_LAB_DATABASE_URL, else
the SQLite file in LAGRANGE_LAB_DATA_DIR): a lost token cannot be shown again, only replaced.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any


def add_token_command(commands: Any) -> None:
    token = commands.add_parser("token", help="create API tokens for the assignment routes")
    actions = token.add_subparsers(dest="action", metavar="ACTION", required=True)
    create = actions.add_parser("create", help="create a token and print it (once)")
    create.add_argument("--name", required=True, help="who it is for (a student: their id)")
    create.add_argument("--role", choices=("instructor", "student"), default="instructor")


def run_token(args: argparse.Namespace) -> int:
    from .db import DatabaseUnavailable
    from .store import Store
    from .tokens import create

    try:
        token = create(Store(), args.role, args.name)
    except (DatabaseUnavailable, ValueError) as exc:
        print(f"lagrange-lab token: {exc}", file=sys.stderr)
        return 1
    print(token)
    print(f"({args.role} token for {args.name}; only its hash is stored)", file=sys.stderr)
    return 0


def add_export_command(commands: Any) -> None:
    export = commands.add_parser("export", help="export an assignment template to a course tool")
    tools = export.add_subparsers(dest="tool", metavar="TOOL", required=True)
    pl = tools.add_parser("prairielearn", help="a PrairieLearn question directory")
    pl.add_argument("template", help="a shipped template's id, or a .toml / .json file")
    pl.add_argument("directory", help="the question directory to write (made if missing)")


def run_export(args: argparse.Namespace) -> int:
    from pathlib import Path

    from mechanics.assignments.prairielearn import export
    from mechanics.assignments.template import parse_template_text, shipped_templates
    from mechanics.spec import SpecError

    source = Path(args.template)
    try:
        if source.is_file():
            fmt = "json" if source.suffix == ".json" else "toml"
            template = parse_template_text(source.read_text(encoding="utf-8"), fmt)
        elif args.template in shipped_templates():
            template = shipped_templates()[args.template]
        else:
            names = ", ".join(sorted(shipped_templates()))
            print(
                f"lagrange-lab export: no file or shipped template {args.template!r} ({names})",
                file=sys.stderr,
            )
            return 2
    except SpecError as exc:
        for e in exc.errors:
            print(f"lagrange-lab export: {e['field']}: {e['message']}", file=sys.stderr)
        return 2
    for path in export(template, Path(args.directory)):
        print(path)
    return 0
