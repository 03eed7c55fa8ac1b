"""A page's state (the scene or its spec, the sliders, the integrator, the lecture step) as a token
that fits in a URL: canonical JSON, zlib-compressed, base64url without padding, behind a version
letter. Nothing is stored on the server, so a link works on any server of the deployment, survives
restarts, and cannot be used to fill the server's disk.

Decoding is strict because the token is someone else's input: its length is bounded before
anything else, the decompressed size is bounded while decompressing (a zlib bomb stops at the
limit), the JSON must be an object of finite numbers (``NaN``/``Infinity`` are refused), and the
caller validates the object against its schema. Every failure is a `ShareError` naming what is
wrong, which the web layer answers as a 422 on the field ``token``.

Floats survive exactly: JSON writes them with ``repr``, the shortest text that reads back as the
same double.
"""

from __future__ import annotations

import base64
import binascii
import json
import re
import zlib
from typing import Any

#: The format of a token: the letter it starts with. A new format gets a new letter, and old
#: links still decode.
VERSION = "z"
#: Longest token accepted (characters). A built-in scene's state is ~150; a posted spec of the
#: largest honest size compresses to a few kB. Browsers and proxies handle URLs of 16 kB.
MAX_TOKEN = 12_000
#: Longest JSON a token may decompress to (bytes): the spec's own limits keep honest ones far
#: below (a request body is at most 1 MiB, a spec of the maximum size is ~100 kB).
MAX_JSON = 256 * 1024

_TOKEN = re.compile(r"^[A-Za-z0-9_-]+$")


class ShareError(ValueError):
    """A token that is not a state this app wrote: the message says what is wrong with it."""


def encode_state(state: dict[str, Any]) -> str:
    """The token of ``state`` (a JSON object of finite numbers, strings, lists, objects)."""
    text = json.dumps(state, sort_keys=True, separators=(",", ":"), allow_nan=False)
    raw = zlib.compress(text.encode(), 9)
    token = VERSION + base64.urlsafe_b64encode(raw).decode().rstrip("=")
    if len(token) > MAX_TOKEN:
        raise ShareError(
            f"the state compresses to {len(token)} characters, over the {MAX_TOKEN} a link may "
            "carry: shorten the spec (fewer bodies, shorter expressions and text)"
        )
    return token


def decode_state(token: str) -> dict[str, Any]:
    """The object a token carries; ShareError for anything that is not one `encode_state` made."""
    if len(token) > MAX_TOKEN:
        raise ShareError(f"a token is at most {MAX_TOKEN} characters (this one has {len(token)})")
    if not token.startswith(VERSION) or not _TOKEN.match(token):
        raise ShareError("not a share token: it starts with 'z' followed by base64url characters")
    body = token[len(VERSION) :]
    try:
        raw = base64.urlsafe_b64decode(body + "=" * (-len(body) % 4))
    except (binascii.Error, ValueError):
        raise ShareError("not a share token: its base64url is damaged (cut short?)") from None
    inflate = zlib.decompressobj()
    try:
        data = inflate.decompress(raw, MAX_JSON)
    except zlib.error:
        raise ShareError("not a share token: its compressed data is damaged") from None
    if inflate.unconsumed_tail:
        raise ShareError(f"the token's state is larger than {MAX_JSON} bytes")
    if not inflate.eof:
        raise ShareError("not a share token: its compressed data is cut short")
    try:
        state = json.loads(data.decode("utf-8"), parse_constant=_no_constant)
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:  # [[[[…: nesting too deep
        raise ShareError(f"the token's state is not valid JSON ({exc})") from None
    if not isinstance(state, dict):
        raise ShareError("the token's state is not a JSON object")
    return state


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a number JSON allows")
