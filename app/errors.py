"""The one place where errors become HTTP answers, so every error has the same shape.

Errors are values with a field path, raised at the edge (the spec, the expression parser, the
budget) and turned into responses here, 404, 413, 422 and 503 alike:
``{"detail": [{"field": "bodies[0].position[0]", "message": "unknown name 'lenght'"}]}``.
The field of an unknown scene is ``scene_id``, of a body too large ``body``, of a posted scene past
its time budget ``scene``; a path that names no route has ``path``.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Iterable
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException

from mechanics.budget import BudgetExceeded
from mechanics.expr import ExprError
from mechanics.spec import SpecError, field_path

#: pydantic error types that mean "the input is not of this union branch's type at all".
_MISMATCH_SUFFIXES = ("_type", "_parsing")


def register_error_handlers(app: FastAPI) -> None:
    """Install the handlers on ``app`` (called once, by app.main)."""
    app.add_exception_handler(SpecError, spec_error)
    app.add_exception_handler(ExprError, expr_error)
    app.add_exception_handler(BudgetExceeded, budget_exceeded)
    app.add_exception_handler(RequestValidationError, request_invalid)
    app.add_exception_handler(HTTPException, http_error)
    document_errors(app)


def error_body(field: str, message: str) -> dict[str, list[dict[str, str]]]:
    """The one error shape with one problem, for answers built outside these handlers (the
    413 of a body past the limit: ``error_body("body", "request body over 1 MiB")``)."""
    return {"detail": [{"field": field, "message": message}]}


#: An error answer lists at most this many problems, each message at most MAX_MESSAGE characters:
#: a 439 kB request once produced a 2.3 MB error (one problem per item of a list it named).
MAX_PROBLEMS = 40
MAX_MESSAGE = 600


def unprocessable(errors: Iterable[dict[str, str]]) -> JSONResponse:
    """A 422 listing every problem as {field, message} (bounded: `bounded_detail`)."""
    detail = [{"field": e["field"], "message": readable(e["message"])} for e in errors]
    return JSONResponse({"detail": bounded_detail(detail)}, status_code=422)


def bounded_detail(detail: list[dict[str, str]]) -> list[dict[str, str]]:
    """At most `MAX_PROBLEMS` problems, the rest counted in a last one; each field and message
    cut at `MAX_MESSAGE` characters: whatever was sent, the answer stays a few kB."""

    def cut(text: str) -> str:
        return text if len(text) <= MAX_MESSAGE else text[: MAX_MESSAGE - 1] + "…"

    out = [
        {**d, **{k: cut(d[k]) for k in ("field", "message") if isinstance(d.get(k), str)}}
        if isinstance(d, dict)
        else d
        for d in detail[:MAX_PROBLEMS]
    ]
    if len(detail) > MAX_PROBLEMS:
        more = len(detail) - MAX_PROBLEMS
        out.append({"field": "body", "message": f"and {more} more problems, not listed"})
    return out


async def http_error(request: Request, exc: HTTPException) -> JSONResponse:
    """An HTTPException (an unknown scene's 404, a route's 405) in the one shape. A detail
    that is already a list of {field, message} is kept; a sentence gets the field it is about:
    ``scene_id`` for a 404 of a matched route (the only 404 a route raises as a sentence; it
    is told where the ids are listed), ``path`` for a 404/405 of the URL itself, ``scene`` for a
    503, else ``body``. A 404 about anything else is raised as a list naming its field."""
    if exc.status_code == 400 and exc.detail == UNPARSED_BODY:
        return unprocessable([{"field": "body", "message": unreadable_body(exc.__cause__)}])
    if isinstance(exc.detail, list):
        body: dict[str, Any] = {"detail": bounded_detail(exc.detail)}
    else:
        matched = request.scope.get("route") is not None
        message = str(exc.detail)
        if exc.status_code == 404 and matched:
            field = "scene_id"
            message += WHERE_SCENE_IDS
        elif exc.status_code in (404, 405):
            field = "path"
        elif exc.status_code == 503:
            field = "scene"  # the only work refused for load is a posted scene's
        else:
            field = "body"
        body = error_body(field, message)
    return JSONResponse(body, status_code=exc.status_code, headers=exc.headers)


#: FastAPI's 400 for a body its JSON reader raised on with anything but a JSONDecodeError: too
#: deeply nested (RecursionError), an integer past Python's digit limit, bytes that are not UTF-8.
UNPARSED_BODY = "There was an error parsing the body"


def unreadable_body(cause: BaseException | None) -> str:
    """Why the body is not JSON this server reads, for the 422 every other malformed JSON body
    gets (hostile play-test: these were a 400 with FastAPI's sentence, the others a 422)."""
    if isinstance(cause, RecursionError):
        return "invalid JSON: nested too deeply"
    if isinstance(cause, UnicodeDecodeError):
        return "invalid JSON: the body is not UTF-8 text"
    if isinstance(cause, ValueError) and "digits" in str(cause):
        return f"invalid JSON: a number has more than {sys.get_int_max_str_digits()} digits"
    return "invalid JSON: it cannot be read"


#: A UTF-16 surrogate code point: JSON's ``\\ud800`` escape decodes to one when it is not half of
#: a pair, and such a string is not text (it cannot be written as UTF-8: orjson, hashing for the
#: cache and every answer that quotes it failed on it with a 500).
_SURROGATE = re.compile("[\ud800-\udfff]")
LONE_SURROGATE = (
    "holds a lone UTF-16 surrogate ({code}), which is not a character: "
    "send the whole character (both halves of a surrogate pair) or leave it out"
)


async def refuse_lone_surrogates(request: Request) -> None:
    """A JSON body with a lone surrogate in any key or string is a 422 naming the first such
    field, before any route or model sees it (hostile play-test, issue 24: ``{"parameters":
    {"\\ud800": 1}}`` was a 500 on six routes). Installed as the app's one global dependency, it
    runs after FastAPI has read and parsed the body, so the body is neither read nor parsed twice;
    a body without a ``\\ud``/``\\uD`` escape cannot hold one and is not walked."""
    if request.method not in ("POST", "PUT", "PATCH"):
        return
    body = await request.body()
    if b"\\ud" not in body and b"\\uD" not in body:
        return
    try:
        document = await request.json()
    except ValueError:
        return  # not JSON: FastAPI has answered it already, or the route does not read JSON
    found = lone_surrogate_at(document)
    if found is not None:
        path, code = found
        if path[:1] == ["scene"] and len(path) > 1:
            path = path[1:]  # inside a posted scene, fields are the spec's own paths
        field = field_path(path) or "body"
        raise HTTPException(422, [{"field": field, "message": LONE_SURROGATE.format(code=code)}])


def lone_surrogate_at(document: Any) -> tuple[list[Any], str] | None:
    """(path, the surrogate as ``\\udxxx``) of the first key or string in ``document`` that holds
    a lone surrogate, else None; a key is named with its surrogates written as escapes. Walked
    with a stack: a JSON document may nest deeper than Python's recursion limit allows."""
    stack: list[tuple[list[Any], Any]] = [([], document)]
    while stack:
        path, value = stack.pop()
        if isinstance(value, str):
            match = _SURROGATE.search(value)
            if match:
                return path, _escaped(match.group())
        elif isinstance(value, dict):
            for key, item in reversed(value.items()):
                match = _SURROGATE.search(key)
                if match:
                    return [*path, _escaped(key)], _escaped(match.group())
                stack.append(([*path, key], item))
        elif isinstance(value, list):
            stack.extend(([*path, i], item) for i, item in reversed(list(enumerate(value))))
    return None


def _escaped(text: str) -> str:
    return text.encode("utf-8", "backslashreplace").decode("utf-8")


#: Said after an unknown scene_id, whichever route raised it (/derive, /check, live.js, …).
WHERE_SCENE_IDS = " (GET /api/v1/scenes lists the scene ids)"


#: What every /api/v1 operation may answer besides its own, documented on each in OpenAPI.
_SHARED_ERRORS = {
    413: "The request body is over the size limit (field `body`).",
    422: "A field is invalid; every problem is listed with its field.",
}


def document_errors(app: FastAPI) -> None:
    """Add the shared error answers (413 and 422 of any POST) to every API operation in the
    OpenAPI document, in the one error shape, where the route did not document them."""
    generate = app.openapi

    def openapi() -> dict[str, Any]:
        if app.openapi_schema:
            return app.openapi_schema
        schema = generate()
        components = schema.setdefault("components", {}).setdefault("schemas", {})
        if "ValidationErrors" not in components:
            from app.schemas import ValidationErrors

            shape = ValidationErrors.model_json_schema(ref_template="#/components/schemas/{model}")
            components.update(shape.pop("$defs", {}))
            components["ValidationErrors"] = shape
        ref = {"$ref": "#/components/schemas/ValidationErrors"}
        for path, operations in schema.get("paths", {}).items():
            post = operations.get("post") if path.startswith("/api/") else None
            for status, description in _SHARED_ERRORS.items() if post else ():
                post.setdefault("responses", {}).setdefault(
                    str(status),
                    {"description": description, "content": {"application/json": {"schema": ref}}},
                )
        return schema

    app.openapi = openapi  # type: ignore[method-assign]


async def spec_error(request: Request, exc: SpecError) -> JSONResponse:
    return unprocessable(exc.errors)


async def expr_error(request: Request, exc: ExprError) -> JSONResponse:
    return unprocessable([{"field": exc.field, "message": exc.message}])


async def budget_exceeded(request: Request, exc: BudgetExceeded) -> JSONResponse:
    """Time is the server's limit (503: try later, or simplify); size is the scene's (422)."""
    message = f"{exc.kind} budget exceeded: {exc.message}"
    field = getattr(exc, "field", "scene")
    if exc.kind == "time":
        return JSONResponse(error_body(field, message), status_code=503)
    return unprocessable([{"field": field, "message": message}])


async def request_invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
    return unprocessable(request_errors(exc.errors(), exc.body))


def request_errors(errors: Iterable[dict[str, Any]], body: Any) -> list[dict[str, str]]:
    """FastAPI's validation errors as {field, message}, one per problem a person can fix.

    Inside a posted scene the path is relative to the spec (``bodies[0].mass``), the same path the
    engine's own errors carry, so a client maps every error onto the spec it edits alike.
    pydantic reports a value that fails a union (an expression is text or a number; a position is
    a list or a frame position) once per branch; the branches the value's type never fitted are
    dropped when another branch did fit it, and what remains at one field is said in one message.
    """
    walked = []  # (error, path, [(union's loc prefix, this branch rejected the value's type)])
    for error in errors:
        loc, document = _relative(list(error.get("loc", ())), body)
        path, branches = _walk(loc, document)
        mismatch = str(error.get("type", "")).endswith(_MISMATCH_SUFFIXES)
        wrong_at = len(loc) - 1 if mismatch else None
        walked.append((error, path, [(prefix, i == wrong_at) for prefix, i in branches]))
    fitted = {prefix for _, _, branches in walked for prefix, wrong in branches if not wrong}
    out: dict[str, list[str]] = {}
    for error, path, branches in walked:
        if any(wrong and prefix in fitted for prefix, wrong in branches):
            continue
        if error.get("type") == "json_invalid":
            field, message = "body", f"invalid JSON: {(error.get('ctx') or {}).get('error')}"
        else:
            field = field_path(path) or (error.get("ctx") or {}).get("field") or "body"
            message = error.get("msg", "invalid")
        if message not in out.setdefault(field, []):
            out[field].append(message)
    return [{"field": f, "message": _one_message(m)} for f, m in out.items()]


def _relative(loc: list[Any], body: Any) -> tuple[list[Any], Any]:
    """The loc relative to the posted scene (or the request body), and the document it indexes."""
    if loc[:1] in (["path"], ["query"]):
        # a path or query parameter by its own name (`scene_id`, `format`), as the route's
        # other errors about it (an unknown scene_id's 404) name it
        return loc[1:], None
    if loc[:1] != ["body"]:
        return loc, None
    loc = loc[1:]
    if loc[:1] == ["scene"] and len(loc) > 1 and isinstance(body, dict):
        return loc[1:], body.get("scene")
    return loc, body


def _walk(loc: list[Any], document: Any) -> tuple[list[Any], list[tuple[tuple, int]]]:
    """Split a loc into the real path and the union branches it passed through.

    A part is real when it indexes the value found so far in the document (a key of a dict, an
    index of a list) or names a field; a part shaped like a type ('float', 'constrained-str',
    'FramePosition', 'list[...]') that indexes nothing is the label pydantic gives a union branch.
    Returns the path and, per branch, (loc up to the union, index of the label in loc).
    """
    path: list[Any] = []
    branches: list[tuple[tuple, int]] = []
    current = document
    for i, part in enumerate(loc):
        if isinstance(current, dict) and part in current:
            current = current[part]
        elif isinstance(current, list) and isinstance(part, int) and 0 <= part < len(current):
            current = current[part]
        elif isinstance(part, str) and _is_branch_label(part):
            branches.append((tuple(loc[:i]), i))
            continue
        else:
            current = None
        path.append(part)
    return path, branches


def _is_branch_label(part: str) -> bool:
    return part[:1].isupper() or "[" in part or "-" in part or part in {"str", "int", "float"}


def _one_message(messages: list[str]) -> str:
    """Several branches' complaints about one value, as one sentence."""
    prefix = "Input should be "
    if len(messages) > 1 and all(m.startswith(prefix) for m in messages):
        return prefix + " or ".join(m.removeprefix(prefix) for m in messages)
    return "; ".join(messages)


#: pydantic names the model class a value should have been ("Input should be a valid dictionary
#: or instance of SceneSpec"): a Python class name means nothing to whoever sent the request.
_CLASS_NAME = re.compile(r" or instance of \w+")


def readable(message: str) -> str:
    # pydantic prefixes a validator's own words with "Value error, "; the field already says where.
    message = _CLASS_NAME.sub("", message.removeprefix("Value error, "))
    return message.replace("a valid dictionary or object to extract fields from", "a JSON object")
