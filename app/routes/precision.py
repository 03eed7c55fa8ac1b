"""``/api/v1/precision``: the work–precision diagram of the scene on screen, and measured orders.

Built-in scenes run in this process through the fair gate (trusted equations, like /simulate);
posted specs run in the pool, under the derivation's budget plus the runs' own. Answers are kept
by their canonical request (app/memo.py): the runs are deterministic, so a class asking for the
same diagram computes it once. A run cut by the time budget is that request's answer only.
"""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, Request, Response
from pydantic import BaseModel, ConfigDict, Field
from starlette.concurrency import run_in_threadpool

from app.derivations import derive_seconds, in_pool, in_process, posted_key
from app.memo import AnswerMemo
from app.responses import dumps
from app.routes.scenes import unknown_scene
from app.schemas import DeriveRequest, Finite, Message, MethodName, ValidationErrors
from mechanics.scenes import scene_ids

router = APIRouter(prefix="/api/v1", tags=["precision"])

answers = AnswerMemo(max_entries=128, max_bytes=16 * 1024 * 1024)

#: Seconds for all the runs of one request, the long run's included (every answer < 5 s).
SECONDS = 4.5


class PrecisionIn(DeriveRequest):
    """Which scene, at which parameters and start, and which methods at which settings."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={
            "examples": [
                {
                    "scene_id": "simple_pendulum",
                    "methods": ["euler", "rk4", "DOP853"],
                    "steps": [0.01, 0.005, 0.0025, 0.00125],
                    "tolerances": [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10],
                    "t_end": 10,
                    "long_run": True,
                }
            ]
        },
    )

    parameters: dict[str, Finite] = Field(default={}, description="Overrides of the defaults.")
    initial: dict[str, Finite] = Field(default={}, description="Initial q and q_dot.")
    methods: list[MethodName] = Field(  # type: ignore[valid-type]
        default=["euler", "rk4", "DOP853"],
        min_length=1,
        max_length=6,
        description="Up to 6 methods of `GET /api/v1/methods`, each once.",
    )
    steps: list[Finite] | None = Field(
        default=None,
        max_length=8,
        description="Steps (s) for the fixed-step methods, up to 8, each ≤ t_end; default "
        "t_end/100 … t_end/3200. At most 200000 steps a run.",
    )
    tolerances: list[Finite] | None = Field(
        default=None,
        max_length=8,
        description="rtol = atol for the adaptive methods, up to 8 in [1e-12, 0.01]; default "
        "1e-4 … 1e-10.",
    )
    t_end: Finite = Field(default=10.0, description="Seconds of motion (0.001 … 100).")
    long_run: bool = Field(
        default=False,
        description="Also symplectic Euler against RK4 at one step over up to 1000 periods (as "
        "many as fit in the request's time): not past a stop, nor of a motion with no period.",
    )


class PointOut(BaseModel):
    setting: float = Field(description="The step or the tolerance asked for.")
    h: float | None = Field(description="The step taken (fixed-step methods), ≤ the one asked.")
    wall_time: float
    rhs_evaluations: int
    steps: int
    error: float | None = Field(description="max |y − y_ref| over the samples, q and q̇.")
    energy_error: float | None = Field(description="max |E − E0| / max T (or the balance).")
    status: str
    excluded: str | None = Field(description="Why the point is left out of the fit, or null.")


class MethodPoints(BaseModel):
    method: str
    label: str
    kind: str
    order: int = Field(description="The method's order (the registry's).")
    symplectic: bool = Field(
        description="Symplectic on this motion, its energy error bound to stay bounded: a "
        "symplectic method stepping (q, q̇) is only on a conservative motion (no damper, friction "
        "or drive doing work) with L free of t, a constant mass matrix and forces of q alone."
    )
    not_symplectic: str | None = Field(
        default=None,
        description="For a method symplectic where those hold (symplectic_euler, "
        "implicit_midpoint): why it is not on this motion, in words; null otherwise.",
    )
    fitted_order: float | None = Field(
        description="Least-squares slope of log error against log h (fixed step), or minus the "
        "slope against log RHS evaluations (adaptive); null with < 2 points in the fit."
    )
    fitted_against: str
    points_in_fit: int
    points: list[PointOut]


class LongRunOut(BaseModel):
    symplectic_here: bool = Field(
        description="Whether symplectic Euler keeps its energy error bounded here: only on a "
        "conservative motion (no damper, friction or drive doing work) with L free of t, a "
        "constant mass matrix (it steps q̇, not p) and forces of q alone."
    )
    not_symplectic: str | None = Field(
        default=None, description="Why symplectic_here is false, in words; null when true."
    )
    period: float
    period_from: str
    periods: int = Field(description="Periods run: up to 1000, as many as fit in the time.")
    h: float
    runs: dict[str, dict[str, Any]] = Field(
        description="Per method: t and the largest energy error in each window, status, cost."
    )


class PrecisionOut(BaseModel):
    t_end: float
    reference: dict[str, Any]
    error_scale: float = Field(description="1 + max |y_ref|: the fit's floor and ceiling scale.")
    methods: list[MethodPoints]
    seconds: float
    cut: bool = Field(description="True when the time budget ran out (later points stopped).")
    scene_parameters: dict[str, float]
    long_run: LongRunOut | None
    long_run_declined: str | None = Field(
        default=None,
        description="Why a long run asked for was not run (the motion ends at a stop, or has no "
        "period), in words; null otherwise.",
    )
    warnings: list[str] = Field(
        default=[],
        description="What the numbers cannot say: a comparison past the motion's "
        "predictability horizon (chaos), where the errors measure the system, not the methods.",
    )
    stopped: dict[str, Any] | None = Field(
        default=None,
        description="Where the motion ends at a declared stop before t_end ({t, message}): "
        "every run is compared up to there, and t_end is that time.",
    )


def _options(body: PrecisionIn) -> Any:
    from mechanics.precision import PrecisionRequest

    return PrecisionRequest(
        methods=list(body.methods),
        parameters=body.parameters,
        initial=body.initial,
        t_end=body.t_end,
        steps=body.steps,
        tolerances=body.tolerances,
        long_run=body.long_run,
    )


def _encoded(result: dict) -> tuple[bytes, bool]:
    """The validated JSON, and whether it may be shared (not cut short by the budget)."""
    cut = result["cut"] or any(
        r["status"] != "ok" for r in ((result.get("long_run") or {}).get("runs") or {}).values()
    )
    return PrecisionOut.model_validate(result).model_dump_json().encode(), not cut


@router.post(
    "/precision",
    response_model=PrecisionOut,
    responses={
        404: {"model": Message, "description": "Unknown scene_id."},
        422: {"model": ValidationErrors, "description": "A field is invalid or out of bounds."},
        503: {"model": Message, "description": "Past the time budget, or the server is busy."},
    },
    summary="Work–precision diagram and measured orders",
)
async def post_precision(body: PrecisionIn, http: Request) -> Response:
    """Each method at each step or tolerance: wall time and RHS evaluations against the error
    (against DOP853 at 1e-13) and the energy error, with each method's order fitted from the
    points in the asymptotic range; optionally symplectic Euler against RK4 over up to 1000
    periods."""
    from mechanics.precision import check_precision_request, precision, precision_job

    options = _options(body)
    check_precision_request(options)  # a 422 before any queue
    key = dumps(body.model_dump(mode="json", exclude_unset=False), sort=True).decode()
    if body.scene_id is not None:
        if body.scene_id not in scene_ids():
            raise unknown_scene(body.scene_id)

        def run() -> tuple[bytes, bool]:
            return _encoded(precision(body.scene_id, None, options, SECONDS))

        async def compute() -> tuple[bytes, bool]:
            return await in_process(http, run, what="work–precision run")

    else:
        spec_key = await run_in_threadpool(posted_key, body.scene)

        def run() -> tuple[bytes, bool]:
            result = in_pool(
                http,
                precision_job,
                spec_key,
                options,
                SECONDS,
                affinity=spec_key,
                what="the work–precision runs of this scene",
                # the derivation's own budget, then the runs' (the long run's included), and
                # building the scene's C for the reference
                seconds=derive_seconds() + SECONDS + 5.0,
            )
            return _encoded(result)

        async def compute() -> tuple[bytes, bool]:
            return await run_in_threadpool(run)

    return Response(await answers.get_or_compute(key, compute), media_type="application/json")
