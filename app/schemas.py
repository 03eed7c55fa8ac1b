"""Every request and response body of ``/api/v1``, as pydantic models.

They are the API's contract: FastAPI turns them into the OpenAPI document at ``/docs``, and a change
here is a change for every client. Response models ignore extra keys the engine may add, so the
JSON stays stable until a field is added here on purpose.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, StringConstraints, model_validator
from pydantic_core import PydanticCustomError

from app.provenance_schema import Provenance
from mechanics.check import QUANTITIES
from mechanics.integrators import METHODS
from mechanics.spec import SceneSpec

SceneId = Annotated[str, StringConstraints(pattern=r"^[a-z0-9_]{1,64}$")]
#: The registry's names and the checkable quantities, as enums in the OpenAPI document; an unknown
#: value is a 422 naming the field, like every other bad value.
MethodName = Literal[tuple(METHODS)]  # type: ignore[valid-type]
Quantity = Literal[QUANTITIES]  # type: ignore[valid-type]
#: A number a request may carry: NaN and ±Infinity (which Python's JSON reader accepts) are a 422
#: "Input should be a finite number" on their field, said before any range the field has. Strict:
#: JSON true is not 1 and "3" is not 3 (``"t_end": true`` ran as a 1 s run).
Finite = Annotated[float, Field(strict=True, allow_inf_nan=False)]


class ErrorDetail(BaseModel):
    """One problem with a request: where it is and what is wrong."""

    field: str = Field(
        description="Path of the offending value. Inside a posted scene it is relative to the "
        "scene spec (`bodies[0].position[0]`), as in the spec's own docs; otherwise the request "
        "field (`scene_id`)."
    )
    message: str = Field(examples=["unknown name 'lenght'"])


class ValidationErrors(BaseModel):
    """The body of every error the API answers (404, 413, 422, 503): all problems found, not
    only the first, each with the field it is about (`scene_id` for an unknown scene, `body` for
    a body too large, `scene` for a posted scene past its budget)."""

    detail: list[ErrorDetail]


#: The same shape under the name the 404 and 503 responses were documented with.
Message = ValidationErrors


class WarmUp(BaseModel):
    """How far this server process is in making every built-in scene ready (app/derivations.py)."""

    done: int = Field(description="Built-in scenes made ready so far.")
    of: int = Field(description="Built-in scenes to make ready (0: warming is off).")
    seconds: float | None = Field(description="How long it took, once all are ready.")


class Health(BaseModel):
    status: str = "ok"
    version: str
    warm: WarmUp | None = Field(default=None, description="The start-up warming of this process.")


class SceneSummary(BaseModel):
    """A menu entry for one built-in scene."""

    id: SceneId
    title: str
    summary: str
    coordinates: list[str]


class SceneDetail(BaseModel):
    """A built-in scene's spec: the very document a client may edit and POST to /derive."""

    id: SceneId
    spec: SceneSpec


class DeriveRequest(BaseModel):
    """Derive the equations of motion of a built-in scene (`scene_id`) or of a posted `scene`."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={"examples": [{"scene_id": "simple_pendulum"}]},
    )

    scene_id: SceneId | None = Field(default=None, description="A built-in scene's id.")
    scene: SceneSpec | None = Field(
        default=None, description="A scene spec of your own (derived under a time budget)."
    )

    @model_validator(mode="after")
    def _exactly_one(self) -> DeriveRequest:
        # The error carries the field it is about (ctx), since a model-level error has no loc.
        if self.scene_id is not None and self.scene is not None:
            raise PydanticCustomError(
                "exactly_one",
                "send either scene_id or scene, not both",
                {"field": "scene"},
            )
        if self.scene_id is None and self.scene is None:
            raise PydanticCustomError(
                "exactly_one",
                "send scene_id (a built-in scene) or scene (a spec of your own)",
                {"field": "scene_id"},
            )
        return self


class Step(BaseModel):
    """One step of the derivation as the notes present it: prose, then its equations."""

    id: str
    title: str
    text: str
    latex: list[str] = Field(description="The step's equations, one LaTeX string per line.")
    plain: list[str] = Field(description="The same lines in plain text (`m*l**2*theta_ddot`).")
    labels: list[str] = Field(default=[], description="A short label per line.")
    data: dict[str, Any] = Field(default={}, description="Step-specific data for the page.")


class Conserved(BaseModel):
    """A conserved quantity: energy, or the momentum of a cyclic coordinate."""

    name: str
    coordinate: str | None = Field(description="The cyclic coordinate, or null (energy).")
    expression: str


class Equations(BaseModel):
    """The results of a derivation, all in one notation (plain text or LaTeX)."""

    T: str = Field(description="Kinetic energy.")
    V: str = Field(description="Potential energy.")
    L: str = Field(description="Lagrangian T - V.")
    generalized_forces: dict[str, str] = Field(description="Q_j per coordinate (non-conservative).")
    eom: dict[str, str] = Field(description="Equation of motion per coordinate, `lhs = rhs`.")
    mass_matrix: list[list[str]] = Field(description="M(q) of M(q) q'' = f(q, q', t).")
    forcing: list[str] = Field(description="f(q, q', t) of M(q) q'' = f(q, q', t).")
    accelerations: dict[str, str] | None = Field(
        description="q'' solved per coordinate, or null where solving was out of budget."
    )
    conserved: list[Conserved]


class DeriveResponse(BaseModel):
    """A whole derivation: the scene, its steps, and the equations in two notations."""

    scene: dict[str, Any] = Field(description="The scene spec that was derived (see SceneSpec).")
    steps: list[Step]
    equations: Equations = Field(description="Results in plain text.")
    latex: Equations = Field(description="The same results in LaTeX.")
    warnings: list[str] = Field(description="What the engine could not simplify, and similar.")
    seconds: float | None = Field(
        default=None, description="How long the derivation took when it was computed."
    )
    provenance: Provenance | None = Field(
        default=None,
        description="Where every term of T, V, Q_j and each equation of motion comes from: "
        "which body, velocity component, force or piece of Lagrange's equations "
        "(docs/provenance.md).",
    )


class SimulateRequest(DeriveRequest):
    """Simulate a scene: which one, its parameters and initial state, and how to integrate."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={
            "examples": [
                {
                    "scene_id": "double_pendulum",
                    "t_end": 20,
                    "fps": 60,
                    "method": "dop853_c",
                    "rtol": 1e-10,
                    "atol": 1e-10,
                },
                {"scene_id": "simple_pendulum", "method": "rk4", "dt": 0.01},
            ]
        },
    )

    parameters: dict[str, Finite] = Field(default={}, description="Overrides of the defaults.")
    initial: dict[str, Finite] = Field(
        default={}, description="Initial q and q_dot (`theta`, `theta_dot`); default the scene's."
    )
    t_end: Finite = Field(default=10.0, description="Seconds of motion (≤ 1000).")
    fps: Finite = Field(
        default=60.0,
        description="Output samples per second (> 0), as many as t_end × fps + 1 ≤ 20001 "
        "samples allow: 100 samples over 1 ms is fps = 1e5. A fixed-step run samples every "
        "whole number of its steps nearest 1/fps instead (stats.sample_interval).",
    )
    method: MethodName = Field(  # type: ignore[valid-type]
        default="dop853_c",
        description="Default dop853_c: DOP853's steps in C (scipy's DOP853 where C cannot run; "
        "stats.method names the one that ran). euler, symplectic_euler, rk4, implicit_midpoint "
        "(fixed step: give dt), or "
        "RK45, DOP853, dop853_c, dop853_fortran, Radau, BDF, LSODA (adaptive: rtol, atol); "
        "`GET /api/v1/methods` lists each with its order and properties.",
    )
    rtol: Finite = Field(default=1e-9, description="Relative tolerance (adaptive methods).")
    atol: Finite = Field(default=1e-9, description="Absolute tolerance (adaptive methods).")
    dt: Finite | None = Field(
        default=None,
        description="Step (fixed-step methods), ≤ t_end: the run takes exactly this step, and "
        "samples every whole number of steps near 1/fps (`t` holds the times).",
    )
    check_sensitivity: bool = Field(
        default=True,
        description="Re-run at a 1000× looser tolerance and warn if the motion is sensitive.",
    )
    constraint_forces: bool = Field(
        default=False,
        description="Also return the constraint force on each body (and a rod's tension).",
    )


class MethodOut(BaseModel):
    """One integration method: what a student needs to pick it knowingly."""

    name: str = Field(description="The value for `method`.")
    label: str
    kind: str = Field(description="fixed (give dt) or adaptive (give rtol, atol).")
    order: int = Field(description="Order of accuracy (the maximum, for variable-order methods).")
    symplectic: bool
    implicit: bool
    description: str
    available: bool = Field(description="False when it would run as another method here.")
    note: str = Field(default="", description="Why it is not available, and what runs instead.")


class StopOut(BaseModel):
    """Where a run ended because its model stops holding there."""

    name: str
    t: float = Field(description="When, located by event detection to the run's tolerance.")
    message: str


class SimulateStats(BaseModel):
    """What the run cost and how accurate it was."""

    model_config = ConfigDict(extra="allow")

    method: str = Field(description="The method that ran (method_requested: the one asked for).")
    steps: int
    rhs_evaluations: int
    jacobian_evaluations: int
    wall_time: float = Field(description="Seconds spent integrating.")
    samples: int
    sample_interval: float | None = Field(
        default=None,
        description="Seconds between two samples: 1/fps for adaptive methods; for fixed-step "
        "ones a whole number of steps dt near 1/fps (null with a single sample).",
    )
    dt: float | None = Field(
        default=None,
        description="The step a fixed-step method took: exactly the dt asked for (the samples "
        "are whole steps apart). Absent for adaptive methods.",
    )
    status: str = Field(description="ok, or stopped (see warnings).")
    driven: bool = Field(
        default=False,
        description="True when something drives the system (moving constraints, a spinning "
        "frame, a time-dependent potential): its work is energy.W_drive.",
    )
    stop: StopOut | None = Field(
        default=None,
        description="The stop condition that ended the run (the spec's `stops`, a spring "
        "reaching its anchor, a positive coordinate reaching 0), located to the run's tolerance.",
    )
    energy_error: float | None = Field(
        default=None, description="max |E(t) - E0| / max |T(t)|, when energy is conserved."
    )
    jacobi_error: float | None = Field(
        default=None, description="The same for the Jacobi integral (moving constraints)."
    )
    energy_balance_error: float | None = Field(
        default=None,
        description="max |E(t) − E0 − W_NC(t) − W_drive(t)| / max |T(t)|, when forces or "
        "drives do work.",
    )
    momentum_drift: dict[str, float] = Field(
        description="Relative drift of each conserved momentum p_j."
    )


class SimulateResponse(BaseModel):
    """A trajectory sampled at the requested rate, its energies, positions and diagnostics."""

    t: list[float]
    q: dict[str, list[float]]
    q_dot: dict[str, list[float]]
    energy: dict[str, list[float]] = Field(
        description="T, V, E, W_nc (work of the non-conservative forces since t = 0) and "
        "W_drive (work of whatever drives the constraints or the potential in time: "
        "ΔT + ΔV = W_nc + W_drive) along the run."
    )
    positions: dict[str, dict[str, list[float]]] = Field(
        description="x, y, z in N of every body and point, for drawing."
    )
    frames: dict[str, list[list[float]]] = Field(
        description="Per sample, the N components of a frame's x, y, z unit vectors (9 numbers)."
    )
    stats: SimulateStats
    warnings: list[str]
    work: dict[str, dict[str, list[float]]] = Field(
        description="Cumulative work since t = 0 of each conservative force (−ΔV of its part) "
        "and each non-conservative one (∫F·v dt), keyed 'kind:name'."
    )
    forces: list[dict[str, Any]] = Field(
        description="Every applied force on every body along the run: label (LaTeX), kind "
        "(weight, spring, damper, force, torque), on, and x, y, z in N — the free-body diagram."
    )
    constraint_forces: dict[str, dict[str, list[float]]] | None = Field(
        default=None, description="With constraint_forces: true — R in N (x, y, z), tension."
    )


class CheckRequest(DeriveRequest):
    """A student's answer for one quantity of a scene's derivation."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={
            "examples": [
                {"scene_id": "simple_pendulum", "quantity": "T", "answer": "1/2 m l^2 theta'^2"},
                {
                    "scene_id": "cart_pendulum",
                    "quantity": "eom",
                    "coordinate": "theta",
                    "answer": "l theta_ddot + cos(theta) x_ddot + g sin(theta) = 0",
                    "reveal": True,
                },
            ]
        },
    )

    quantity: Quantity = Field(  # type: ignore[valid-type]
        description="T, V, L, Q, eom, accel or momentum."
    )
    coordinate: str | None = Field(
        default=None, description="The coordinate, for Q, eom, accel and momentum."
    )
    answer: Annotated[str, StringConstraints(max_length=2000)] = Field(
        description="Plain text; also theta', thetadot, dtheta, ^ for powers, implicit "
        "multiplication (2 m l^2) and Greek letters (θ)."
    )
    reveal: bool = Field(default=False, description="Also return the derived answer.")


class CheckResponse(BaseModel):
    """The verdict and feedback that points at the error."""

    correct: bool
    confirmed: bool = Field(
        default=True,
        description="False when the answer equals the derived result at every state sampled but "
        "sympy could not prove it: `correct` is then false without the answer being shown wrong.",
    )
    feedback: list[str] = Field(
        description="Sentences that point at the error; their math is inline LaTeX between "
        "dollar signs (`Sign error in the $\\frac{g}{l} \\sin\\theta$ term.`), never code."
    )
    answer_latex: str = Field(
        description="What the answer was read as, in LaTeX (an equation of motion as lhs = rhs)."
    )
    expected_latex: str | None = Field(default=None, description="Only with reveal: true.")


class PredictRequest(CheckRequest):
    """A student's answer, to be integrated beside the true motion from the same state."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={
            "examples": [
                {
                    "scene_id": "simple_pendulum",
                    "quantity": "eom",
                    "coordinate": "theta",
                    "answer": "theta'' - g/l sin(theta) = 0",
                },
                {"scene_id": "double_pendulum", "quantity": "T", "answer": "...", "t_end": 3},
            ]
        },
    )

    parameters: dict[str, Finite] = Field(default={}, description="Overrides of the defaults.")
    initial: dict[str, Finite] = Field(
        default={}, description="Overrides of the initial state (q and q_dot by name)."
    )
    t_end: Finite = Field(default=5.0, gt=0, le=10, description="Seconds to integrate (≤ 10).")


class PredictedRun(BaseModel):
    """One model's motion: sampled at 60 per second (≤ 601 samples) until t_end or a stop."""

    t: list[float]
    q: dict[str, list[float | None]]
    q_dot: dict[str, list[float | None]]
    energy: list[float | None] = Field(
        description="The TRUE energy E = T + V (the derivation's) along this run."
    )
    positions: dict[str, dict[str, list[float | None]]] = Field(
        description="x, y, z in N of every body and point, as in /simulate."
    )
    frames: dict[str, list[list[float | None]]] = Field(
        description="Per sample, a frame's x, y, z axes in N (9 numbers), as in /simulate."
    )
    reached: float = Field(description="How far in time the stepping got.")
    blew_up_at: float | None = Field(
        default=None,
        description="When the run stopped because it blew up (|q| or |q̇| > 1e6, not finite, "
        "or q̈ undetermined): a result, not an error.",
    )
    stopped_because: str | None = Field(default=None, description="Why it stopped early.")


class PredictResponse(BaseModel):
    """What the answer predicts: its motion beside the true one, when they part, and the
    energy the student's model gains or loses, measured with the true E."""

    correct: bool
    feedback: list[str] = Field(description="The check's feedback (math as $…$).")
    answer_latex: str
    true: PredictedRun = Field(description="The derivation's motion.")
    student: PredictedRun = Field(description="The answer's motion, from the same state.")
    parted_at: float | None = Field(
        description="When the two motions first part visibly (parting_rule); null if never."
    )
    parting_rule: str = Field(description="What 'part visibly' means for this scene.")
    energy_change: float = Field(
        description="ΔE of the student's run minus ΔE of the true run (both with the true E) "
        "up to energy_until, over energy_scale: > 0 the answer creates energy, < 0 destroys it."
    )
    energy_change_max: float = Field(description="The largest |difference| along the way.")
    energy_scale: float = Field(
        description="The motion's energy: the true run's largest kinetic energy (else |E(0)|)."
    )
    energy_until: float = Field(description="The last time both energies are known.")
    blamed: str | None = Field(description="The feedback line that names the error, if any.")
    summary: str = Field(description="One sentence for the student (math as $…$).")


class EquilibriaRequest(DeriveRequest):
    """Find the equilibria of a scene at the given parameter values."""

    model_config = ConfigDict(
        extra="forbid",
        json_schema_extra={"examples": [{"scene_id": "bead_on_hoop", "parameters": {"Omega": 6}}]},
    )

    parameters: dict[str, Finite] = Field(default={}, description="Overrides of the defaults.")


class Equilibrium(BaseModel):
    """One equilibrium: where, in closed form when possible, when it exists, and how it moves."""

    q: dict[str, float] = Field(
        description="Coordinates at the given parameters; angles in (−π, π]."
    )
    symbolic: dict[str, str] = Field(
        description="Closed form per coordinate, where sympy found it."
    )
    symbolic_latex: dict[str, str] = Field(
        default={}, description="The same closed forms in LaTeX, for display."
    )
    free: list[str] = Field(description="Coordinates absent from the conditions (any value).")
    exists_when: str = Field(description="Condition for existence, e.g. |g/(Omega**2*R)| <= 1.")
    exists_when_latex: str = Field(
        default="", description="The same condition in LaTeX; empty when it always exists."
    )
    found_by: str = Field(
        description="closed form / closed form, confirmed numerically / numeric search."
    )
    stable: bool = Field(
        description="True for the kinds stable, asymptotically stable, gyroscopically stable."
    )
    kind: str = Field(
        description="What the eigenvalues of M δq̈ + C δq̇ + K δq = 0 decide: stable, "
        "asymptotically stable, gyroscopically stable, marginal or unstable.",
        json_schema_extra={
            "enum": [
                "stable",
                "asymptotically stable",
                "gyroscopically stable",
                "marginal",
                "unstable",
            ]
        },
    )
    reason: str = Field(description="Why, in words: the eigenvalues and K that decided.")
    eigenvalues: list[list[float]] = Field(
        description="[Re λ, Im λ] of the first-order linearized system, δq ∝ e^(λt)."
    )
    frequencies: list[float] = Field(
        description="Small-oscillation ω = Im λ in rad/s, ascending (none when unstable)."
    )
    modes: list[list[float]] = Field(
        description="Normal mode shapes (max |·| = 1), one per frequency; amplitudes when the "
        "mode whirls (see mode_phases)."
    )
    mode_phases: list[list[float]] = Field(
        description="Phase of each coordinate in each mode, rad (all 0: a standing pattern)."
    )


class EquilibriaResponse(BaseModel):
    steps: list[Step]
    equilibria: list[Equilibrium]
    warnings: list[str]


class ConstraintForceOut(BaseModel):
    """The force a constraint supplies to one body, with q̈ from the equations of motion."""

    body: str
    name: str = Field(
        description="As the free-body diagram names it: F_T (a rod's or rope's tension), F_N "
        "(a normal force), F_pin (a pin reaction) when it is one force there, else F_C, the "
        "resultant of the several the diagram draws."
    )
    frame: str = Field(description="The frame its components are written in.")
    unit_vectors: list[str]
    components: list[str]
    latex: str
    tension_toward: str | None = Field(
        description="The point it hangs from by a rod or string of fixed length, if any."
    )
    tension: str | None = Field(description="The pull toward that point (negative: a push).")


class DiagramForceOut(BaseModel):
    """One force of the free-body diagram on one body, by the name the diagram gives it."""

    body: str = Field(description="The body it acts on.")
    name: str = Field(
        description="F_g (weight), F_<spring> (a spring's pull), F_<name> or M_<name> (a "
        "force, damper or torque of the scene, by its name), and for constraint forces F_T "
        "(tension of a rod or rope), F_N (normal force), F_f (static friction), F_pin (pin "
        "reaction) or F_C (a constraint force with no narrower name)."
    )
    kind: str = Field(
        description="weight, spring, force, damper or torque (applied), or constraint."
    )
    latex: str = Field(description="Its label as the diagram and the steps typeset it.")
    what: str | None = Field(
        description="A constraint force in words, as the diagram says it (which rod pulls, "
        "on what); null for an applied force."
    )


class NewtonResponse(BaseModel):
    """Σ F = m a (and Σ M = dH/dt) beside Lagrange: steps, constraint forces, agreement."""

    steps: list[Step]
    constraint_forces: list[ConstraintForceOut]
    forces: list[DiagramForceOut] = Field(
        description="Every force the free-body diagram draws, body by body (a scene "
        "potential's force enters through V and is not drawn)."
    )
    equations: dict[str, str] = Field(description="Newton's equations projected on each δq_j.")
    agrees_with_lagrange: bool
    constraint_forces_unknown: str | None = Field(
        default=None,
        description="Why `constraint_forces` is empty (a potential given as V(q) fixes only "
        "its virtual work, not its force across the constraints); null when they are given.",
    )
