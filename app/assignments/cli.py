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
