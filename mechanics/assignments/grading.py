"""Grading a part: the checker's verdict (mechanics.check.check) as a score in [0, 1], an
outcome code, and the attempt bookkeeping of STACK-like course tools.

- A decided answer uses an attempt: its score is ``raw × max(0, 1 − penalty × (n − 1))`` for the
  n-th attempt, ``raw`` 1 for a correct answer, else the template's partial credit for its outcome
  code (0 unless the template says otherwise).
- The part's score is the best penalised score of its attempts (a worse later answer costs
  nothing already earned).
- An answer the checker cannot decide (past its budget, or neither proved nor refuted) and one that
  does not parse use no attempt and score nothing: "cannot decide, because ...", never a guess.
- The same answer typed again is not a new attempt: the earlier result is returned.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

from mechanics.budget import BudgetExceeded
from mechanics.cache import ENGINE_VERSION
from mechanics.check import check
from mechanics.derive import derivation_of_spec
from mechanics.expr import ExprError

from . import oscillations, outcomes
from .variants import Variant


@dataclass(frozen=True)
class Judged:
    """What the checker said about one answer, before any attempt bookkeeping."""

    code: str
    codes: list[str]
    decided: bool
    correct: bool
    feedback: list[str]
    answer_latex: str = ""

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class Attempt:
    answer: str
    judged: Judged
    counted: bool  # used an attempt
    number: int | None  # which attempt (1-based) if counted
    raw: float | None
    score: float | None  # after the retry penalty

    def to_json(self) -> dict[str, Any]:
        return {**asdict(self), "judged": self.judged.to_json()}


@dataclass
class Policy:
    """A part's grading rules, from its template."""

    retry_penalty: float = 0.1
    max_attempts: int = 0  # 0: unlimited
    partial: dict[str, float] = field(default_factory=dict)


class AttemptsExhausted(ValueError):
    """Every attempt of the part is used: the answer is refused, not judged."""


def judge_job(
    spec_text: str, quantity: str, coordinate: str | None, answer: str, options: tuple = ()
) -> dict:
    """The checker's verdict as JSON, in a pool worker (picklable, module level): the web layer
    runs it under the check budget. An equilibrium or a frequency is judged by oscillations.py."""
    d = derivation_of_spec(spec_text)
    if quantity in oscillations.QUANTITIES:
        return oscillations.judge(d, {"quantity": quantity, **dict(options)}, answer)
    return check(d, quantity, answer, coordinate).to_json(reveal=False)


Runner = Callable[..., dict]


def _local(
    spec_text: str, quantity: str, coordinate: str | None, answer: str, options: tuple = ()
) -> dict:
    return judge_job(spec_text, quantity, coordinate, answer, options)


def options_of(part: dict[str, Any]) -> tuple:
    """What an equilibrium or frequency part adds to its quantity, as a hashable tuple."""
    return tuple((k, part[k]) for k in ("near", "mode") if part.get(k) is not None)


def judge(variant: Variant, part: dict[str, Any], answer: str, run: Runner = _local) -> Judged:
    """One answer to one part of a variant, judged (``run`` is where the checker runs: here, or
    a budgeted pool worker that raises BudgetExceeded)."""
    quantity = part["quantity"]
    try:
        verdict = run(
            variant.spec_text(), quantity, part.get("coordinate"), answer, options_of(part)
        )
    except ExprError as exc:
        code = outcomes.code(quantity, outcomes.UNREADABLE)
        return Judged(code, [code], False, False, [f"{exc.message}"])
    except BudgetExceeded as exc:
        code = outcomes.code(quantity, outcomes.CANNOT_DECIDE)
        line = f"Cannot decide, because the checker ran past its budget ({exc.message})."
        return Judged(code, [code], False, False, [line])
    code, codes = outcomes.outcome(quantity, verdict["correct"], verdict["feedback"])
    decided = verdict.get("confirmed", True) and not code.endswith(".cannot_decide")
    feedback = list(verdict["feedback"])
    if not decided:
        code = outcomes.code(quantity, outcomes.CANNOT_DECIDE)
        feedback.insert(0, "Cannot decide, because no proof could settle it; no attempt used.")
    return Judged(code, codes, decided, bool(verdict["correct"]), feedback, verdict["answer_latex"])


def key_still_holds(
    variant: Variant, part: dict[str, Any], stored_key: str, run: Runner = _local
) -> bool:
    """Does this engine judge the key stored with the variant correct? A variant made by another
    engine version is regraded only if so (else its parts cannot be decided)."""
    if variant.engine_version == ENGINE_VERSION:
        return True
    try:
        verdict = run(
            variant.spec_text(),
            part["quantity"],
            part.get("coordinate"),
            stored_key,
            options_of(part),
        )
    except (ExprError, BudgetExceeded):
        return False
    return bool(verdict["correct"])


def raw_score(judged: Judged, policy: Policy) -> float:
    kind = judged.code.split(".", 1)[1]
    if kind in outcomes.CREDIT:
        return 1.0
    return float(policy.partial.get(judged.code, 0.0))


def record(previous: list[Attempt], answer: str, judged: Judged, policy: Policy) -> Attempt:
    """The attempt ``answer`` makes after ``previous`` (raises AttemptsExhausted when none is
    left; an undecided or unreadable answer uses none)."""
    typed = answer.strip()
    for earlier in previous:
        if earlier.counted and earlier.answer.strip() == typed:
            return earlier
    if not judged.decided:
        return Attempt(answer, judged, False, None, None, None)
    used = sum(1 for a in previous if a.counted)
    if policy.max_attempts and used >= policy.max_attempts:
        raise AttemptsExhausted(f"all {policy.max_attempts} attempts of this part are used")
    n = used + 1
    raw = raw_score(judged, policy)
    score = round(raw * max(0.0, 1.0 - policy.retry_penalty * (n - 1)), 6)
    return Attempt(answer, judged, True, n, raw, score)


def part_score(attempts: list[Attempt]) -> float:
    """The best penalised score over the part's attempts (0 with none)."""
    return max((a.score for a in attempts if a.score is not None), default=0.0)


def attempts_left(attempts: list[Attempt], policy: Policy) -> int | None:
    """None: unlimited."""
    if not policy.max_attempts:
        return None
    return max(0, policy.max_attempts - sum(1 for a in attempts if a.counted))


def total_score(parts: list[dict[str, Any]], scores: dict[str, float]) -> float:
    """The weighted mean of the parts' scores, in [0, 1]."""
    weight = sum(p["weight"] for p in parts)
    return sum(p["weight"] * scores.get(p["id"], 0.0) for p in parts) / weight
