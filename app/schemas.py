"""Every request and response body of ``/api/v1``, as pydantic models.

They are the API's contract: FastAPI turns them into the OpenAPI document at ``/docs``, and a change
here is a change for every client. Response models ignore extra keys the engine may add, so the
JSON stays stable until a field is added here on purpose.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, StringConstraints, model_validator
from pydantic_core import PydanticCustomError

from mechanics.spec import SceneSpec

SceneId = Annotated[str, StringConstraints(pattern=r"^[a-z0-9_]{1,64}$")]


class ErrorDetail(BaseModel):
    """One problem with a request: where it is and what is wrong."""

    field: str = Field(
        description="Path of the offending value. Inside a posted scene it is relative to the "
        "scene spec (`bodies[0].position[0]`), as in the spec's own docs; otherwise the request "
        "field (`scene_id`)."
    )
    message: str = Field(examples=["unknown name 'lenght'"])


class ValidationErrors(BaseModel):
    """The body of every 422: all problems found, not only the first."""

    detail: list[ErrorDetail]


class Message(BaseModel):
    """The body of a 404 or 503: one sentence for a person."""

    detail: str


class Health(BaseModel):
    status: str = "ok"
    version: str


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
