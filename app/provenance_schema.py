"""The ``provenance`` of a derive response, as pydantic models (issue 14.2): where every term of T,
V, Q_j and each equation of motion comes from. The JSON is built by
`mechanics.provenance.provenance_json`; these models document it in the OpenAPI document (the
lead wires `Provenance` into ``DeriveResponse``). Like every response model they ignore extra keys.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

OriginKind = Literal["kinetic", "potential", "generalized force"]


class ProvenanceOrigin(BaseModel):
    """One piece an energy or a generalized force is built from, described once."""

    model_config = ConfigDict(extra="allow")

    kind: OriginKind
    text: str = Field(description="The origin in words: '½ m (e_theta component of v of …)²'.")
    body: str | None = Field(default=None, description="The body it belongs to or acts on.")
    motion: Literal["translational", "rotational"] | None = Field(
        default=None, description="Kinetic origins: ½ m v·v or ½ ω·I·ω."
    )
    frame: str | None = Field(
        default=None,
        description="Kinetic origins: the frame whose unit vectors the components are along "
        "(null for the dot product of two links written in different frames).",
    )
    components: list[dict[str, Any]] | None = Field(
        default=None,
        description="Kinetic origins: the velocity component(s) it comes from. A translational "
        "one names the link (`link`, `from`: the body's position is a chain of links, a body "
        "placed `from` another adds one) and its unit vector (`unit`, `unit_latex`); two "
        "entries without a unit are the dot product of two links' velocities (the cross term "
        "of v·v). A rotational one names body axes (`axis`).",
    )
    source: str | None = Field(
        default=None,
        description="Potential: weight | spring | potential; generalized force: force | damper "
        "| torque.",
    )
    name: str | None = Field(default=None, description="The spring, potential or load's name.")
    coordinate: str | None = Field(
        default=None, description="Generalized forces: the coordinate whose virtual work it is."
    )


class ProvenanceSource(BaseModel):
    """One origin's contribution to a term; a term's contributions add up to it exactly."""

    origin: str = Field(description="Key into `origins` (T1…, V1…, Q<j>.<i>).")
    kind: OriginKind
    body: str | None = None
    piece: Literal["d/dt ∂T/∂q̇", "−∂T/∂q", "∂V/∂q", "Q"] | None = Field(
        default=None,
        description="Equations of motion: the Euler–Lagrange piece it enters through.",
    )
    via: str | None = Field(
        default=None,
        description="Equations of motion: the id of the term of T or V it is differentiated "
        "from (null when that equation was not traced).",
    )
    contribution_latex: str
    contribution_plain: str


class ProvenanceTerm(BaseModel):
    """One term of a displayed equation and the origins it is made of."""

    id: str = Field(
        description="The same expression has the same id in every equation (light it up "
        "wherever it appears)."
    )
    latex: str
    plain: str
    sources: list[ProvenanceSource]


class CancelledPieces(BaseModel):
    """Contributions to a velocity monomial the displayed equation does not have: they cancel."""

    monomial_latex: str
    sources: list[ProvenanceSource]


class TracedEquation(BaseModel):
    """An equation split into terms; the terms add up to the displayed equation exactly."""

    traced: bool = Field(description="False past the size budget (see `reason`).")
    reason: str | None = Field(default=None, description="'too many terms to trace'.")
    terms: list[ProvenanceTerm]
    cancelled: list[CancelledPieces] = []


class EomProvenance(BaseModel):
    """d/dt ∂L/∂q̇_j − ∂L/∂q_j (lhs) = Q_j (rhs), each side traced."""

    lhs: TracedEquation
    rhs: TracedEquation


class ForcingTerms(BaseModel):
    """f_j of M q̈ = f by term ids: Σ `plus` (the EoM's right side) − Σ `minus` (its left-side
    terms free of q̈)."""

    minus: list[str]
    plus: list[str]


class MatrixProvenance(BaseModel):
    """The mass-matrix form by term ids of the equations of motion (null rows: not traced)."""

    M: list[list[list[str]] | None] = Field(
        description="M[j][k]: the ids of EoM j's terms whose sum is M_jk q̈_k."
    )
    f: list[ForcingTerms | None]


class Provenance(BaseModel):
    """Where every term comes from: T, V, Q_j and each equation of motion, term by term."""

    origins: dict[str, ProvenanceOrigin] = Field(
        description="Every origin a source names: per body and velocity component (kinetic), "
        "per conservative force (potential), per load and coordinate (generalized force)."
    )
    T: TracedEquation
    V: TracedEquation
    Q: dict[str, TracedEquation] = Field(description="Q_j per coordinate.")
    eom: dict[str, EomProvenance] = Field(description="Per coordinate.")
    matrix: MatrixProvenance
