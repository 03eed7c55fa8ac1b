"""``/api/v1/simulate``: integrate a scene's equations of motion with the method the user picks."""

from __future__ import annotations

import math
import time
from functools import partial

from fastapi import APIRouter, Request, Response
from starlette.concurrency import run_in_threadpool

from app.derivations import in_pool, in_process, posted_key, server_timing
from app.memo import AnswerMemo
from app.responses import ORJSONResponse, dumps
from app.routes.scenes import unknown_scene
from app.schemas import Message, MethodOut, SimulateRequest, SimulateResponse, ValidationErrors
from mechanics.scenes import scene_ids

router = APIRouter(prefix="/api/v1", tags=["simulate"])

#: A built-in scene's runs are deterministic and the same for everyone: a class opening a scene
#: at its defaults computes its run once (app/memo.py).
built_in_runs = AnswerMemo()


@router.post(
    "/simulate",
    response_model=SimulateResponse,  # documents the body; the route sends it pre-serialised
    responses={
        404: {"model": Message, "description": "Unknown scene_id."},
        422: {"model": ValidationErrors, "description": "A field is invalid or out of bounds."},
        503: {
            "model": Message,
            "description": "A posted scene ran past its time budget, or the run could not start "
            "in time (the server is busy, or this client already has a run going).",
        },
    },
    summary="Simulate a scene",
)
async def post_simulate(request: SimulateRequest, http: Request) -> Response:
    """Integrate, then report the trajectory with its cost (steps, RHS evaluations, wall time)
    and accuracy (energy error or energy balance, momentum drift), and warnings in plain words.

    A built-in scene runs in this process once the fair gate lets it start (app/derivations.py:
    a few runs at once, one per client, the others waiting without holding a thread); a posted
    one runs in the pool.
    """
    return await simulation_answer(request, http, gzip_ok=True)


async def simulation_answer(request: SimulateRequest, http: Request, *, gzip_ok: bool) -> Response:
    """The answer of POST /simulate; ``gzip_ok``: a repeated built-in run may go out gzipped
    (once compressed, app/memo.py). Another route that reads the body passes False."""
    from mechanics.simulate import SimulationRequest, simulate

    options = SimulationRequest(
        **request.model_dump(include=set(SimulationRequest.__dataclass_fields__))
    )
    if request.scene_id is not None:
        if request.scene_id not in scene_ids():
            raise unknown_scene(request.scene_id)
        run = partial(simulate, request.scene_id, None, options)

        timing: dict[str, float] = {}

        def encoded() -> tuple[bytes, bool]:
            t0 = time.perf_counter()
            result = run()
            timing["run"] = time.perf_counter() - t0
            return dumps(result), _not_load_dependent(result)

        async def compute() -> tuple[bytes, bool]:
            return await in_process(http, encoded, what="simulation", timing=timing)

        key = dumps(request.model_dump(mode="json"), sort=True).decode()
        misses = built_in_runs.misses
        body = await built_in_runs.get_or_compute(key, compute)
        shared = built_in_runs.misses == misses  # found (or waited for), not computed here
        times = {"memo": 0.0} if shared else timing
        if gzip_ok and shared and "gzip" in http.headers.get("accept-encoding", ""):
            headers = {"content-encoding": "gzip", "vary": "Accept-Encoding"}
            gz = await run_in_threadpool(built_in_runs.gzipped, key, body)
            return Response(
                gz, media_type="application/json", headers=headers | server_timing(times)
            )
        return Response(body, media_type="application/json", headers=server_timing(times))
    from mechanics.jobs import simulation

    key = await run_in_threadpool(posted_key, request.scene)
    run = partial(
        in_pool, http, simulation, key, options, affinity=key, what="simulating this scene"
    )
    return await run_in_threadpool(lambda: _answer(run()))


def _not_load_dependent(result: dict) -> bool:
    """A run far from its wall-time budget is the scene's answer, the same on any server and
    at any load; one cut short (or near enough that its check re-run may have been) is only
    this request's, and is not kept for others."""
    from mechanics.simulate import MAX_WALL_TIME

    quick = result["stats"]["wall_time"] < 0.25 * MAX_WALL_TIME
    return quick and not any("of wall time" in w for w in result["warnings"])


def _answer(result: dict) -> Response:
    """The JSON answer, encoded where the run ran (a thread), not in the event loop."""
    return ORJSONResponse(result)  # NaN/inf become null, as _finite did


@router.get("/methods", response_model=list[MethodOut], summary="List the integration methods")
def get_methods() -> list[MethodOut]:
    """The registry, in the order the pages offer it; `available` is false for ``dop853_c`` on a
    server without a C compiler (it then runs scipy's DOP853, the same steps, more slowly)."""
    from mechanics import native
    from mechanics.integrators import METHODS

    why = native.available()
    return [
        MethodOut(
            **vars(m),
            available=not (m.name == "dop853_c" and why),
            note=f"runs scipy's DOP853 here: {why}" if m.name == "dop853_c" and why else "",
        )
        for m in METHODS.values()
    ]


def _finite(value):
    """JSON has no NaN/inf: a non-finite number (an overflowing energy) becomes null."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value
