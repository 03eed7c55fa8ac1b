"""``/api/v1/export/...``: take a scene with you — its derivation as LaTeX, a run as a standalone
Python script, a trajectory as CSV or JSON, the spec as TOML or JSON, and the page's state as a
link.

Each export exists as a POST taking the body of the matching API call (``/derive``'s for the
derivation and the spec, ``/simulate``'s for a run), for built-in scenes and posted specs alike,
and as a GET for built-in scenes taking the scene page's own query string (``?m=2&theta=1.2&
method=rk4&dt=0.01&t_end=5``), so the page links to them as they are. Work on a posted spec runs
where the API's other work on it runs: sympy in the worker pool under its time budget, a
simulation through /simulate's own path; a built-in scene's through the in-process gate.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Collection, Mapping
from typing import Annotated, Any, Literal
from urllib.parse import urlencode

import orjson
from fastapi import APIRouter, HTTPException, Query, Request, Response
from fastapi.responses import RedirectResponse
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ValidationError
from starlette.concurrency import run_in_threadpool

from app import derivations, share_links
from app.errors import readable
from app.routes.scenes import unknown_scene
from app.routes.simulate import simulation_answer
from app.schemas import (
    DeriveRequest,
    Finite,
    MethodName,
    SceneId,
    SimulateRequest,
    ValidationErrors,
)
from mechanics.budget import BudgetExceeded
from mechanics.export_formats import (
    json_text,
    spec_toml,
    stats_lines,
    trajectory_columns,
    trajectory_csv,
)
from mechanics.export_share import (
    PAGE_SETTINGS,
    PAGE_T_END,
    ShareError,
    decode_state,
    encode_state,
    page_run,
    run_problems,
    state_problems,
)
from mechanics.integrators import METHODS
from mechanics.scenes import load_scene, scene_ids
from mechanics.spec import IDENT, MAX_COORDINATES, MAX_PARAMETERS, SpecError

#: One router for the exports under /api/v1/export and the share link /s/{token} (a page URL),
#: so the app includes it once.
router = APIRouter(tags=["export"])
API = "/api/v1/export"

_ERRORS: dict[int | str, dict[str, Any]] = {
    404: {"model": ValidationErrors, "description": "Unknown scene_id."},
    422: {"model": ValidationErrors, "description": "A field is invalid (named in the answer)."},
    503: {"model": ValidationErrors, "description": "The work ran past its time budget."},
}
TEX = "application/x-tex"
PYTHON = "text/x-python; charset=utf-8"
CSV = "text/csv; charset=utf-8"
TOML = "application/toml; charset=utf-8"
#: Longest a page query string may be for the GET exports (characters): a scene has at most
#: 40 parameters and 12 initial values, each well under 60 characters.
MAX_QUERY = 4096


def _named(pattern: str, what: str) -> AfterValidator:
    """A name checked against ``pattern`` and refused in words ("a name is a letter, then ..."),
    not pydantic's "String should match pattern '^[A-Za-z]...'" (hostile play-test)."""
    rule = re.compile(pattern)

    def check(name: str) -> str:
        if not rule.match(name):
            raise ValueError(f"{name[:40]!r} is not a name: {what}")
        return name

    return AfterValidator(check)


Name = Annotated[str, _named(IDENT, "a letter, then letters, digits or _ (24 at most)")]
StateName = Annotated[
    str,
    _named(r"^[A-Za-z][A-Za-z0-9_]{0,27}$", "a letter, then letters, digits or _ (28 at most)"),
]


def _download(content: str | bytes, media_type: str, filename: str) -> Response:
    """An attachment: the browser saves it under ``filename`` instead of showing it."""
    return Response(
        content=content,
        media_type=media_type,
        headers={"Content-Disposition": f'attachment; filename="{filename}"'},
    )


def _file_stem(request: DeriveRequest) -> str:
    return request.scene_id or "scene"


def _only_query(http: Request, allowed: Collection[str], reads: str) -> None:
    """A 422 naming every query key this export does not read (hostile play-test: a misspelt
    key was ignored, and the file came back as if it had been read). ``reads`` says what it
    reads, for the message."""
    unknown = [k for k in dict.fromkeys(http.query_params.keys()) if k not in allowed]
    if unknown:
        raise HTTPException(
            422,
            [{"field": k, "message": f"unknown query parameter '{k}': {reads}"} for k in unknown],
        )


# --------------------------------------------------------------------------------- LaTeX


@router.post(
    API + "/latex",
    response_class=Response,
    responses={200: {"content": {TEX: {}}, "description": "A LaTeX article."}, **_ERRORS},
    summary="The derivation as a LaTeX document",
)
async def post_latex(request: DeriveRequest, http: Request) -> Response:
    """The whole derivation as a LaTeX article that compiles with `pdflatex` (no shell escape
    needed): the notes' procedure, every step with its prose and equations, the values, and the
    free-body diagram drawn at the initial state. Text from a posted spec is escaped: it prints,
    it never runs."""
    _only_query(http, (), "this export reads its JSON body only")
    return _download(await _latex(request, http), TEX, f"{_file_stem(request)}.tex")


@router.get(
    API + "/scenes/{scene_id}/derivation.tex",
    response_class=Response,
    responses={200: {"content": {TEX: {}}, "description": "A LaTeX article."}, **_ERRORS},
    summary="A built-in scene's derivation as LaTeX",
)
async def get_latex(scene_id: SceneId, http: Request) -> Response:
    """The same document as `POST /api/v1/export/latex` with `{"scene_id": ...}`."""
    _only_query(http, (), "the derivation is symbolic and takes no query parameters")
    request = DeriveRequest(scene_id=scene_id)
    return _download(await _latex(request, http), TEX, f"{scene_id}.tex")


async def _latex(request: DeriveRequest, http: Request) -> str:
    from mechanics.export_latex import document_of

    if request.scene_id is not None:
        _known(request.scene_id)
        return await derivations.in_process(
            http, document_of, request.scene_id, None, what="LaTeX export"
        )
    key = await run_in_threadpool(derivations.posted_key, request.scene)
    return await run_in_threadpool(
        derivations.in_pool,
        http,
        document_of,
        None,
        key,
        affinity=key,
        what="writing this scene's derivation as LaTeX",
    )


def _known(scene_id: str) -> None:
    if scene_id not in scene_ids():
        raise unknown_scene(scene_id)


# --------------------------------------------------------------------------------- script


@router.post(
    API + "/script",
    response_class=Response,
    responses={200: {"content": {"text/x-python": {}}, "description": "A script."}, **_ERRORS},
    summary="A run as a standalone Python script",
)
async def post_script(request: SimulateRequest, http: Request) -> Response:
    """A Python script (numpy and scipy only) that reproduces this `/simulate` request: the
    scene's equations of motion as code, its parameters, initial state, method, tolerances (or
    step) and sample times. `python run.py --json out.json` writes t, q and q_dot. It
    integrates the same state with the same right-hand side, so it agrees with the API's run to
    the run's tolerance. (Stop conditions are listed in it, not applied.)"""
    _only_query(http, (), "this export reads its JSON body only")
    return _download(await _script(request, http), PYTHON, f"{_file_stem(request)}_run.py")


def _in_page_terms(exc: SpecError, query: Any) -> SpecError:
    """A GET export's refusal in the page query's names: its ``tol`` is /simulate's rtol and
    atol at once, so a tolerance out of range is said once, on ``tol`` (on ``atol`` when the
    query gives that key itself)."""
    names = {"rtol": "tol", "atol": "atol" if "atol" in query else "tol"}
    out: list[dict[str, str]] = []
    for error in exc.errors:
        error = {**error, "field": names.get(error["field"], error["field"])}
        if not any(o["field"] == error["field"] for o in out):
            out.append(error)
    return SpecError(out)


@router.get(
    API + "/scenes/{scene_id}/run.py",
    response_class=Response,
    responses={200: {"content": {"text/x-python": {}}, "description": "A script."}, **_ERRORS},
    summary="A built-in scene's run as a Python script (page query string)",
)
async def get_script(scene_id: SceneId, http: Request) -> Response:
    """`POST /api/v1/export/script` for a built-in scene, with the scene page's query string
    (parameter and initial values by name, `method`, `tol`, `dt`, `t_end`)."""
    request = _page_request(scene_id, http)
    try:
        script = await _script(request, http)
    except SpecError as exc:
        raise _in_page_terms(exc, http.query_params) from None
    return _download(script, PYTHON, f"{scene_id}_run.py")


async def _script(request: SimulateRequest, http: Request) -> str:
    """The script of a run /simulate makes: the run itself first, so a request /simulate refuses
    (g = 1e308 overflows in the first step, found only by stepping) is refused here with the
    same 422, not written as a script that crashes (hostile play-test). A built-in scene's run
    is kept (app/memo.py): the trajectory of the same query costs nothing after it."""
    from mechanics.export_script import run_script
    from mechanics.simulate import SimulationRequest

    await simulation_answer(request, http, gzip_ok=False)
    options = SimulationRequest(
        **request.model_dump(include=set(SimulationRequest.__dataclass_fields__))
    )
    if request.scene_id is not None:
        _known(request.scene_id)
        origin = f"Lagrange Lab, built-in scene {request.scene_id}"
        return await derivations.in_process(
            http, run_script, request.scene_id, None, options, origin, what="script export"
        )
    key = await run_in_threadpool(derivations.posted_key, request.scene)
    return await run_in_threadpool(
        derivations.in_pool,
        http,
        run_script,
        None,
        key,
        options,
        "Lagrange Lab, a posted scene",
        affinity=key,
        what="writing this run as a script",
    )


# ----------------------------------------------------------------------------- trajectory

TrajectoryFormat = Literal["csv", "json"]


@router.post(
    API + "/trajectory",
    response_class=Response,
    responses={
        200: {"content": {"text/csv": {}, "application/json": {}}, "description": "The run."},
        **_ERRORS,
    },
    summary="A run's trajectory as CSV or JSON, with its stats",
)
async def post_trajectory(
    request: SimulateRequest,
    http: Request,
    format: Annotated[TrajectoryFormat, Query(description="csv or json")] = "csv",
) -> Response:
    """Runs the `/simulate` request and answers its trajectory as a file: t, each q and q̇,
    T, V, E, W_nc and W_drive per sample, headed by name and unit; the run's stats and warnings
    as `#` comment lines (CSV) or fields (JSON)."""
    _only_query(http, ("format",), "this export reads format (csv or json) only")
    return await _trajectory(request, http, format)


@router.get(
    API + "/scenes/{scene_id}/trajectory.{format}",
    response_class=Response,
    responses={
        200: {"content": {"text/csv": {}, "application/json": {}}, "description": "The run."},
        **_ERRORS,
    },
    summary="A built-in scene's trajectory as CSV or JSON (page query string)",
)
async def get_trajectory(scene_id: SceneId, format: TrajectoryFormat, http: Request) -> Response:
    """`POST /api/v1/export/trajectory` for a built-in scene, with the page's query string."""
    try:
        return await _trajectory(_page_request(scene_id, http), http, format)
    except SpecError as exc:
        raise _in_page_terms(exc, http.query_params) from None


async def _trajectory(request: SimulateRequest, http: Request, format: str) -> Response:
    if request.scene_id is not None:
        _known(request.scene_id)
        spec: dict[str, Any] = load_scene(request.scene_id)
    else:
        spec = request.scene.model_dump(mode="json", by_alias=True)
    answer = await simulation_answer(request, http, gzip_ok=False)
    run = orjson.loads(answer.body)
    units = spec.get("units") or {}
    stem = _file_stem(request)
    described = {
        "scene": request.scene_id or spec.get("title"),
        "method": request.method,
        **({"dt": request.dt} if METHODS[request.method].kind == "fixed" else {}),
        **(
            {"rtol": request.rtol, "atol": request.atol}
            if METHODS[request.method].kind == "adaptive"
            else {}
        ),
        "t_end": request.t_end,
        "fps": request.fps,
        "parameters": {**spec.get("parameters", {}), **request.parameters},
        "initial": _initial_of(spec, request.initial),
    }
    if format == "json":
        body = {
            "request": described,
            "columns": [{"name": n, "unit": u} for n, u in trajectory_columns(run, units)],
            **{k: run[k] for k in ("t", "q", "q_dot", "energy", "stats", "warnings")},
        }
        return _download(orjson.dumps(body), "application/json", f"{stem}_trajectory.json")
    comments = [f"Lagrange Lab trajectory of {described['scene']}"]
    comments += [f"{k}: {json_text(v)}" for k, v in described.items()]
    comments += stats_lines(run["stats"]) + [f"warning: {w}" for w in run["warnings"]]
    return _download(trajectory_csv(run, units, comments), CSV, f"{stem}_trajectory.csv")


def _initial_of(spec: dict[str, Any], overrides: dict[str, float]) -> dict[str, float]:
    initial = spec.get("initial") or {}
    out = {}
    for q in spec.get("coordinates") or []:
        for key in (q, f"{q}_dot"):
            out[key] = overrides.get(key, initial.get(key, 0.0))
    return out


# ----------------------------------------------------------------------------------- spec

SpecFormat = Literal["toml", "json"]


@router.post(
    API + "/spec",
    response_class=Response,
    responses={
        200: {"content": {"application/toml": {}, "application/json": {}}, "description": "."},
        **_ERRORS,
    },
    summary="A scene's spec as TOML or JSON",
)
async def post_spec(
    request: DeriveRequest,
    http: Request,
    format: Annotated[SpecFormat, Query(description="toml or json")] = "toml",
) -> Response:
    """The spec of a built-in scene (as written in its file) or a posted one (as its schema read
    it, defaults left out; names and physics are checked by /derive, so a draft can be saved),
    as TOML (`tomllib` reads it back equal) or JSON: ready to edit and post to `/api/v1/derive`."""
    _only_query(http, ("format",), "this export reads format (toml or json) only")
    if request.scene_id is not None:
        return _spec_file(_builtin_spec(request.scene_id), format, request.scene_id)
    spec = request.scene.model_dump(mode="json", by_alias=True, exclude_unset=True)
    return _spec_file(spec, format, "scene")


@router.get(
    API + "/scenes/{scene_id}/spec.{format}",
    response_class=Response,
    responses={
        200: {"content": {"application/toml": {}, "application/json": {}}, "description": "."},
        **_ERRORS,
    },
    summary="A built-in scene's spec as TOML or JSON",
)
def get_spec(scene_id: SceneId, format: SpecFormat, http: Request) -> Response:
    """The same as `POST /api/v1/export/spec` with `{"scene_id": ...}`."""
    _only_query(http, (), "the spec is the scene's file and takes no query parameters")
    return _spec_file(_builtin_spec(scene_id), format, scene_id)


def _builtin_spec(scene_id: str) -> dict[str, Any]:
    try:
        return load_scene(scene_id)
    except KeyError:
        raise unknown_scene(scene_id) from None


def _spec_file(spec: dict[str, Any], format: str, stem: str) -> Response:
    if format == "toml":
        return _download(spec_toml(spec), TOML, f"{stem}.toml")
    text = json.dumps(spec, indent=2, ensure_ascii=False) + "\n"
    return _download(text, "application/json", f"{stem}.json")


# ---------------------------------------------------------------------------------- share


class ShareState(DeriveRequest):
    """What a scene's page shows, to restore exactly from a link: the scene (a built-in one's id
    or a posted spec), the sliders, the integrator, the time span and the lecture step."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={
            "examples": [
                {
                    "scene_id": "double_pendulum",
                    "parameters": {"m2": 2.0},
                    "initial": {"theta1": 1.2},
                    "method": "rk4",
                    "dt": 0.005,
                    "t_end": 15,
                    "lecture": True,
                    "lecture_step": 4,
                }
            ]
        },
    )

    parameters: Annotated[dict[Name, Finite], Field(max_length=MAX_PARAMETERS)] = {}
    initial: Annotated[dict[StateName, Finite], Field(max_length=2 * MAX_COORDINATES)] = {}
    method: MethodName = "dop853_c"  # type: ignore[valid-type]
    rtol: Finite | None = Field(default=None, ge=1e-14, le=0.1)
    atol: Finite | None = Field(default=None, ge=1e-16, le=1.0)
    dt: Finite | None = Field(default=None, gt=0, le=1000)
    t_end: Finite = Field(
        default=10.0,
        ge=PAGE_T_END[0],
        le=PAGE_T_END[1],
        description="Seconds of motion, in the page's range (its t_end box clamps to it).",
    )
    compare: bool = False
    method_b: MethodName | None = None  # type: ignore[valid-type]
    lecture: bool = False
    lecture_step: int | None = Field(default=None, ge=0, le=63, description="0 = the first step.")
    phase: Name | None = Field(default=None, description="The coordinate of the phase plot.")


class ShareLink(BaseModel):
    token: str = Field(description="The state, compressed (zlib + base64url); nothing is stored.")
    url: str = Field(description="The link to share: /s/{token} opens the page in this state.")
    api: str = Field(description="GET it for the state as JSON.")


@router.post(
    API + "/share",
    response_model=ShareLink,
    responses={422: _ERRORS[422], 503: _ERRORS[503]},
    summary="A link that restores a page's state",
)
async def post_share(state: ShareState, http: Request) -> ShareLink:
    """The state compressed into a URL: the link carries the scene (a posted spec too), the
    parameters, initial state, method, tolerances or step, t_end and lecture step, with every
    number exact. Nothing is stored on the server, so it works on any server, forever. A state
    the page it opens could not run (m = 0, a state past a stop) is refused with /simulate's own
    field and reason."""
    _only_query(http, (), "this link is made from its JSON body only")
    document = state.model_dump(mode="json", by_alias=True, exclude_unset=True)
    problems = state_problems(document)
    if any(p["field"] == "scene_id" for p in problems):
        raise unknown_scene(document["scene_id"])  # the 404 of every other unknown scene_id
    if problems:
        raise HTTPException(422, problems)
    await _runnable(state, document, http, prefix="")
    try:
        token = encode_state(document)
    except (ShareError, ValueError) as exc:
        raise HTTPException(422, [{"field": "scene", "message": str(exc)}]) from None
    return ShareLink(token=token, url=f"/s/{token}", api=f"/api/v1/export/share/{token}")


@router.get(
    API + "/share/{token}",
    response_model=ShareState,
    response_model_exclude_unset=True,
    responses={422: _ERRORS[422]},
    summary="The state a share link carries",
)
async def get_share(token: str, http: Request) -> ShareState:
    """The state of `/s/{token}`, as JSON (what the page restores). A token this app did not
    write, or whose run /simulate would refuse, answers 422 naming what is wrong with it."""
    _only_query(http, (), "a share token carries the whole state")
    return await _decoded(token, http)


@router.get(
    "/s/{token}",
    response_class=RedirectResponse,
    status_code=303,
    responses={422: _ERRORS[422]},
    summary="Open a shared link",
)
async def open_share(token: str, http: Request) -> RedirectResponse:
    """Redirects to the page in the shared state: a built-in scene's page with its query
    string (`step` is the lecture step), or, for a posted spec, the editor with `?share=token`
    (the editor reads the state from `/api/v1/export/share/{token}`). A query string added to
    the link on its way (a chat app's tracking key) is not the state and is left out."""
    state = await _decoded(token, http)
    if state.scene_id is None:
        return RedirectResponse(f"/editor?{urlencode({'share': token})}", status_code=303)
    return RedirectResponse(f"/scenes/{state.scene_id}?{page_query(state)}", status_code=303)


async def _decoded(token: str, http: Request) -> ShareState:
    """The state of a link, checked once per link and kept (app/share_links.py)."""
    return await share_links.memo.get(token, lambda: _decode_and_check(token, http))


async def _decode_and_check(token: str, http: Request) -> ShareState | share_links.Undecided:
    try:
        document = decode_state(token)
        state = ShareState.model_validate(document)
    except ShareError as exc:
        raise HTTPException(422, [{"field": "token", "message": str(exc)}]) from None
    except ValidationError as exc:
        problems = [{"field": _token_field(e), "message": readable(e["msg"])} for e in exc.errors()]
        raise HTTPException(422, problems) from None
    # a hand-made token may name a scene or values the scene does not have: said here, not by
    # the page it would open
    document = state.model_dump(mode="json", by_alias=True, exclude_unset=True)
    problems = state_problems(document)
    if problems:
        raise HTTPException(
            422, [{"field": f"token.{p['field']}", "message": p["message"]} for p in problems]
        )
    seconds = share_links.link_seconds(token, derivations.derive_seconds())
    try:
        await _runnable(state, document, http, prefix="token.", seconds=seconds)
    except BudgetExceeded as exc:
        if exc.kind != "time":
            raise
        return share_links.Undecided(state)  # cannot decide in time: the page's run will say
    return state


async def _runnable(
    state: ShareState,
    document: Mapping[str, Any],
    http: Request,
    prefix: str,
    seconds: float | None = None,
) -> None:
    """A 422 with /simulate's own fields and reasons when the run the page makes of this state
    would be refused (mechanics.export_share.run_problems): a built-in scene's checks in this
    process, a posted spec's in the pool, where its other work runs, under the same budget."""
    request = page_run(document)
    if state.scene_id is not None:
        problems = await derivations.in_process(
            http, run_problems, state.scene_id, None, request, what="checking the shared run"
        )
    else:
        key = await run_in_threadpool(derivations.posted_key, state.scene)
        problems = await run_in_threadpool(
            derivations.in_pool,
            http,
            run_problems,
            None,
            key,
            request,
            affinity=key,
            what="checking the shared run",
            seconds=seconds,
        )
    if problems:
        raise HTTPException(
            422, [{"field": prefix + p["field"], "message": p["message"]} for p in problems]
        )


def _token_field(error: Any) -> str:
    """``token.<path>`` of a schema error in a token's state; a model-level error (scene_id and
    scene both, or neither) has no path, and its context names the field."""
    path = [str(p) for p in error["loc"]] or [(error.get("ctx") or {}).get("field") or ""]
    return ".".join(["token", *path]).rstrip(".")


def page_query(state: ShareState) -> str:
    """The scene page's query string for ``state`` (static/js/controls.js writeQuery's keys;
    numbers written with repr, which the page reads back as the same doubles)."""
    query: list[tuple[str, str]] = []
    query += [(k, repr(v)) for k, v in state.parameters.items()]
    query += [(k, repr(v)) for k, v in state.initial.items()]
    query.append(("method", state.method))
    if state.dt is not None:
        query.append(("dt", repr(state.dt)))
    if state.rtol is not None:
        query.append(("tol", repr(state.rtol)))
    if state.atol is not None and state.atol != state.rtol:
        query.append(("atol", repr(state.atol)))
    query.append(("t_end", repr(state.t_end)))
    if state.compare:
        query.append(("compare", "1"))
    if state.method_b is not None:
        query.append(("method_b", state.method_b))
    if state.lecture:
        query.append(("lecture", "1"))
    if state.lecture_step is not None:
        query.append(("step", str(state.lecture_step + 1)))  # the page counts from 1
    if state.phase is not None:
        query.append(("phase", state.phase))
    return urlencode(query)


# ------------------------------------------------------------------------ page query string


def _page_request(scene_id: str, http: Request) -> SimulateRequest:
    """The /simulate request a scene page's query string describes (see static/js/controls.js
    writeQuery): values by name, ``method``, ``tol`` (rtol and atol), ``dt``, ``t_end``. The
    page's other settings (``lecture``, ``phase``, ``compare``, ...) are the page's and are
    passed over; a key that names nothing in the scene nor the page, or a value that is not a
    finite decimal number, is a 422 naming it (a key given twice is refused before any route,
    app/middleware.py OneValuePerKey)."""
    _known(scene_id)
    if len(http.url.query) > MAX_QUERY:
        raise HTTPException(422, [{"field": "query", "message": f"over {MAX_QUERY} characters"}])
    spec = load_scene(scene_id)
    names_p = set(spec.get("parameters") or {})
    names_i = {n for q in spec["coordinates"] for n in (q, f"{q}_dot")}
    query = http.query_params
    errors: list[dict[str, str]] = []
    for key in dict.fromkeys(query.keys()):
        if key not in names_p | names_i | PAGE_SETTINGS:
            errors.append(
                {
                    "field": key,
                    "message": f"unknown query parameter '{key}': the scene '{scene_id}' has "
                    f"no value of that name (parameters: {_names(names_p)}; initial state: "
                    f"{_names(names_i)}) and the page no setting of it "
                    f"({_names(PAGE_SETTINGS)})",
                }
            )
    if errors:
        raise HTTPException(422, errors)

    def number(key: str) -> float | None:
        raw = query.get(key)
        if raw is None or raw == "":
            return None
        # a decimal number as the page writes one; Python's float() also reads '1_0' (as 10),
        # 'infinity' and ' 1 ', which the page's Number() does not read the same way
        value = float(raw) if _DECIMAL.match(raw) else math.nan
        if not math.isfinite(value):
            if not any(e["field"] == key for e in errors):  # tol is read twice
                digits = "" if raw.isascii() else " (written with the digits 0-9)"
                errors.append(
                    {"field": key, "message": f"must be a finite number{digits}, not {raw[:40]!r}"}
                )
            return None
        return value

    fields: dict[str, Any] = {"scene_id": scene_id, "parameters": {}, "initial": {}}
    for key in query:
        if key in names_p and (v := number(key)) is not None:
            fields["parameters"][key] = v
        elif key in names_i and (v := number(key)) is not None:
            fields["initial"][key] = v
    method = query.get("method") or "dop853_c"
    if method not in METHODS:
        errors.append(
            {"field": "method", "message": f"unknown method; one of {', '.join(METHODS)}"}
        )
    fields["method"] = method
    for key, target in (("tol", "rtol"), ("tol", "atol"), ("atol", "atol"), ("t_end", "t_end")):
        if (v := number(key)) is not None:
            fields[target] = v
    if method in METHODS and METHODS[method].kind == "fixed":
        dt = number("dt")
        fields["dt"] = 0.01 if dt is None else dt  # the page's default step
    if (v := number("fps")) is not None:
        fields["fps"] = v
    if errors:
        raise HTTPException(422, errors)
    try:
        return SimulateRequest.model_validate(fields)
    except ValidationError as exc:
        problems = [
            {"field": ".".join(str(p) for p in e["loc"]) or "query", "message": e["msg"]}
            for e in exc.errors()
        ]
        raise HTTPException(422, problems) from None


#: A decimal number: what the page writes (String of a double, repr on the server).
#: ASCII digits only: Python's \d and float() also read '１' (a fullwidth 1) and '١' (an
#: Arabic-Indic 1), which the page's Number() reads as NaN (hostile play-test).
_DECIMAL = re.compile(r"^[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?$", re.ASCII)


def _names(names: Collection[str]) -> str:
    return ", ".join(sorted(names)) or "none"
