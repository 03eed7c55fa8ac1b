"""API tokens: an instructor's (from ``lagrange-lab token create``) or a student's (issued by an
instructor). Only the sha256 of a token is stored: 32 random bytes need no slow hash, since no
dictionary can guess them, and a leaked table then holds nothing that logs anyone in."""

from __future__ import annotations

import hashlib
import secrets

from .store import Store

ROLES = ("instructor", "student")
PREFIX = "llab_"


def digest(token: str) -> str:
    return hashlib.sha256(token.encode()).hexdigest()


def create(store: Store, role: str, subject: str) -> str:
    """A new token for ``subject`` in ``role``; the token itself is returned once, never stored."""
    if role not in ROLES:
        raise ValueError(f"role must be one of {', '.join(ROLES)}")
    if not subject or len(subject) > 100:
        raise ValueError("a subject (the instructor's name or the student's id) of 1-100 chars")
    token = PREFIX + secrets.token_urlsafe(32)
    store.add_token(digest(token), role, subject)
    return token
