"""A page's state (the scene or its spec, the sliders, the integrator, the lecture step) as a token
that fits in a URL: canonical JSON, zlib-compressed, base64url without padding, behind a version
letter. Nothing is stored on the server, so a link works on any server of the deployment, survives
restarts, and cannot be used to fill the server's disk.

Decoding is strict because the token is someone else's input: its length is bounded before
anything else, the decompressed size is bounded while decompressing (a zlib bomb stops at the
limit), the JSON must be an object of finite numbers (``NaN``/``Infinity`` are refused), and the
caller validates the object against its schema. Every failure is a `ShareError` naming what is
wrong, which the web layer answers as a 422 on the field ``token``. A state that fits the schema
must still fit its scene (`state_problems`): a built-in scene that exists, values and a phase
coordinate the scene has, and no value named like a setting of the page's query string (a
parameter ``t_end`` would write a second ``t_end`` into the link the page opens).

Floats survive exactly: JSON writes them with ``repr``, the shortest text that reads back as the
same double.

A state that fits its scene must also be one the page it opens can run: `run_problems` asks the
checks /simulate makes before it integrates (a mass or length that leaves no inertia, a state
past a declared stop, a value that overflows, a coordinate declared positive at 0) of the run the
page makes (`page_run`), so a link is refused with /simulate's own field and reason instead of
opening on an error (hostile play-test: a share of m = 0 was a 200 that /simulate then refused).
"""

from __future__ import annotations

import base64
import binascii
import json
import re
import zlib
from collections.abc import Mapping
from typing import Any

from mechanics.scenes import load_scene, scene_ids
from mechanics.simulate import SimulationRequest
from mechanics.spec import SpecError

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

#: Keys of a scene page's query string that are the page's own settings, not values of the
#: scene (static/js/controls.js writeQuery and scene.js): a scene value under one of these names
#: could not be told apart from the setting in a link.
PAGE_SETTINGS = frozenset(
    {"method", "method_b", "tol", "atol", "dt", "t_end", "compare", "lecture"}
    | {"phase", "step", "from", "fps", "share"}
)


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
    if inflate.unused_data:  # one state, one token: trailing bytes would be new cache keys
        raise ShareError("not a share token: it goes on after its compressed data")
    # said in words about the token, not Python's ('Expecting value: line 1 column 6 (char 5)',
    # 'maximum recursion depth exceeded while decoding a JSON array from a unicode string')
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise ShareError("the token's state is not valid JSON (it is not UTF-8 text)") from None
    try:
        state = json.loads(text, parse_constant=_no_constant)
    except json.JSONDecodeError as exc:
        where = (
            "breaks off"
            if exc.pos >= len(text.rstrip())
            else f"goes wrong at character {exc.pos + 1}"
        )
        raise ShareError(f"the token's state is not valid JSON (it {where})") from None
    except RecursionError:  # [[[[…
        raise ShareError("the token's state is not valid JSON (it is nested too deeply)") from None
    except ValueError as exc:  # NaN, Infinity (_no_constant's words)
        raise ShareError(f"the token's state is not valid JSON ({exc})") from None
    if not isinstance(state, dict):
        raise ShareError("the token's state is not a JSON object")
    return state


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a number JSON allows")


def state_problems(state: Mapping[str, Any]) -> list[dict[str, str]]:
    """What a schema-valid state names that its scene does not have, as {field, message}
    (fields relative to the state: ``scene_id``, ``parameters.t_end``, ``phase``); empty when
    the state fits its scene.

    ``state`` is the state as JSON: ``scene_id`` (a built-in scene) or ``scene`` (a posted spec,
    whose own names are checked), ``parameters`` and ``initial`` by name, ``phase``.
    """
    scene_id = state.get("scene_id")
    if scene_id is not None:
        if scene_id not in scene_ids():
            return [
                {
                    "field": "scene_id",
                    # the words of app/errors.py's 404 for an unknown scene_id
                    "message": f"unknown scene '{scene_id}' (GET /api/v1/scenes lists the "
                    "scene ids)",
                }
            ]
        spec: Mapping[str, Any] = load_scene(scene_id)
        whose = f"the scene '{scene_id}'"
    else:
        spec = state.get("scene") or {}
        whose = "the posted scene"
    parameters = set(spec.get("parameters") or {})
    coordinates = list(spec.get("coordinates") or [])
    values = set(coordinates) | {f"{q}_dot" for q in coordinates}
    problems = []
    for where, given, known, kind in (
        ("parameters", state.get("parameters") or {}, parameters, "parameter"),
        ("initial", state.get("initial") or {}, values, "coordinate or velocity"),
    ):
        for name in given:
            if name in known and (scene_id is None or name not in PAGE_SETTINGS):
                continue
            if name in PAGE_SETTINGS:
                message = f"'{name}' is a setting of the page, not a {kind} of {whose}"
                if name in _STATE_KEYS:
                    message += f": give it as the state's own '{name}'"
            else:
                message = f"{whose} has no {kind} '{name}'; it has {_listed(known)}"
            problems.append({"field": f"{where}.{name}", "message": message})
    phase = state.get("phase")
    if phase is not None and phase not in coordinates:
        problems.append(
            {
                "field": "phase",
                "message": f"{whose} has no coordinate '{phase}'; it has {_listed(coordinates)}",
            }
        )
    return problems


#: The settings a state carries under the same name as the page's query key.
_STATE_KEYS = frozenset({"method", "method_b", "dt", "t_end", "compare", "lecture", "phase"})


def _listed(names: Any) -> str:
    names = sorted(names)
    return ", ".join(names) if names else "none"


# ------------------------------------------------------------------------------ the run

#: The run a scene page makes of a state (static/js/scene.js SERVER_FPS, integrator.js
#: readSettings): 30 samples per second from the server, a step of 0.01 s for a fixed-step method
#: and rtol = atol = 1e-9 for an adaptive one unless the state gives them.
PAGE_FPS = 30.0
PAGE_DT = 0.01
PAGE_TOL = 1e-9
#: The page's range of t_end (static/js/integrator.js clamps to it): a state outside it would not
#: open as it was shared.
PAGE_T_END = (0.1, 120.0)


def page_run(state: Mapping[str, Any]) -> SimulationRequest:
    """The /simulate request the page opened from ``state`` (JSON, as a token carries it) makes
    for its first method."""
    from mechanics.integrators import METHODS

    method = state.get("method") or "dop853_c"
    fixed = method in METHODS and METHODS[method].kind == "fixed"
    rtol = state.get("rtol")
    rtol = PAGE_TOL if rtol is None else rtol
    atol = state.get("atol")
    return SimulationRequest(
        parameters=dict(state.get("parameters") or {}),
        initial=dict(state.get("initial") or {}),
        t_end=float(state.get("t_end", 10.0)),
        fps=PAGE_FPS,
        method=method,
        rtol=rtol,
        atol=rtol if atol is None else atol,
        dt=(state.get("dt") or PAGE_DT) if fixed else None,
        check_sensitivity=False,
    )


def run_problems(
    scene_id: str | None, spec_key: str | None, request: SimulationRequest
) -> list[dict[str, str]]:
    """What /simulate refuses of ``request`` before integrating, as {field, message} (its own
    words and fields), or [] when it would run. A built-in scene by id, a posted spec by its
    canonical JSON (mechanics.jobs.spec_key); the same compiled scene the run uses, so this costs
    what the run's own checks cost once the scene is compiled (a pool job for a posted spec).

    A state past a spring's anchor is run by /simulate on the variant derived for that side: it
    is checked there too, as the run does (mechanics.simulate.simulate's loop)."""
    import json

    from mechanics import simulate as run
    from mechanics.numeric import compiled_scene, compiled_spec
    from mechanics.stops import refuse_passed_stops

    spec = json.loads(spec_key) if spec_key is not None else None
    branches: dict[int, int] = {}
    try:
        for _ in range(run.MAX_BRANCH_FLIPS):
            key = tuple(sorted(branches.items()))
            c = compiled_scene(scene_id, key) if scene_id is not None else compiled_spec(spec, key)
            try:
                params, y0 = run.check_request(c, request)
            except run._OtherBranch as other:  # the run's own retry, on the other variant
                branches = {**c.derivation.model.branches, **other.flips}
                continue
            refuse_passed_stops(c, params, y0)
            return []
    except SpecError as exc:
        return list(exc.errors)
    return [{"field": "initial", "message": "no derivation matches this state"}]
