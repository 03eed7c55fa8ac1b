"""What the assignment routes do, without HTTP: deploy, a student's view, submit, scores, report.

The engine's work (building and verifying variants, judging answers) goes through ``run``, a
callable the routes bind to the warm pool under its budgets (tests may bind it to this process).
Every answer is stored before it is judged (status "pending"), and scored in a second short
transaction: a server killed in between leaves the answer stored, and `regrade_pending` scores it
when asked (the routes call it for the assignment before reading scores).
"""

from __future__ import annotations

import hashlib
import os
import threading
from collections import OrderedDict, defaultdict
from collections.abc import Callable
from datetime import UTC, datetime, timedelta
from typing import Any

from sqlalchemy.exc import IntegrityError

from mechanics.assignments import grading, outcomes
from mechanics.assignments.grading import AttemptsExhausted, Policy
from mechanics.assignments.keys import deploy_job
from mechanics.assignments.template import Template, parse_template, template_hash
from mechanics.assignments.variants import Variant, deploy_seeds
from mechanics.cache import ENGINE_VERSION
from mechanics.spec import SpecError

from .store import Store, attempt_of

#: Submissions one student may make per minute, over every assignment and server (counted in
#: the database, so a second server or a restart does not reset it).
RATE_ENV = "LAGRANGE_LAB_SUBMISSIONS_PER_MINUTE"
DEFAULT_RATE = 30
MAX_DEPLOY = 50
#: A submission whose attempt number another one took at the same moment is renumbered this often.
RENUMBER_TRIES = 5
#: The scores and the report judge answers left pending this long (past any check's budget, so
#: not one a live request is still judging).
PENDING_SECONDS = 30.0
STARTED = datetime.now(UTC)

Run = Callable[..., Any]  # run(job, *args, what=..., budget="check"|"derive", affinity=...)


class Refused(Exception):
    """A request the rules refuse: ``status`` (404, 409, 429, ...) with one field and message."""

    def __init__(self, status: int, field: str, message: str) -> None:
        super().__init__(message)
        self.status, self.field, self.message = status, field, message


def submissions_per_minute() -> int:
    raw = os.environ.get(RATE_ENV, "")
    return int(raw) if raw.strip().isdigit() and int(raw) > 0 else DEFAULT_RATE


def local_run(job: Callable[..., Any], *args: Any, **_: Any) -> Any:
    """Run a job in this process (the CLI, tests): no budget."""
    return job(*args)


def find_template(store: Store, template_id: str) -> Template:
    """A stored template, else a shipped one; Refused(404) if neither."""
    from mechanics.assignments.template import shipped_templates

    document = store.template(template_id)
    if document is not None:
        return parse_template(document)
    shipped = shipped_templates().get(template_id)
    if shipped is None:
        raise Refused(404, "template_id", f"no template '{template_id}'")
    return shipped


def deploy(
    store: Store,
    template: Template,
    assignment_id: str,
    count: int,
    pinned: list[str],
    run: Run = local_run,
) -> dict[str, Any]:
    """Build ``count`` variants (pinned seeds first), verify every key, store the assignment.
    A variant whose keys are not all verified is stored as not deployable, with the reason,
    and no student ever gets it."""
    if store.assignment(assignment_id) is not None:
        raise Refused(409, "assignment_id", f"assignment '{assignment_id}' exists already")
    if not 1 <= count <= MAX_DEPLOY or len(pinned) > count:
        raise Refused(422, "count", f"between 1 and {MAX_DEPLOY}, and at least the pinned seeds")
    document = template.model_dump(mode="json", exclude_defaults=True)
    rows = []
    for seed in deploy_seeds(count, pinned):
        try:
            built = run(deploy_job, document, seed, what="verifying a variant's keys")
        except SpecError as exc:  # a switch that breaks the scene: not deployable, say why
            why = "; ".join(f"{e['field']}: {e['message']}" for e in exc.errors)
            rows.append(_undeployable(template, seed, f"the variant's scene is invalid: {why}"))
            continue
        except Exception as exc:  # past the budget, a lost worker: never deployed
            rows.append(_undeployable(template, seed, f"its keys could not be verified: {exc}"))
            continue
        keys = built["keys"]
        rows.append(
            {
                "seed": seed,
                "engine_version": built["variant"]["engine_version"],
                "variant": built["variant"],
                "keys": keys,
                "deployable": keys["deployable"],
                "why_not": keys["why_not"],
            }
        )
    store.create_assignment(assignment_id, document, template_hash(template), rows)
    return preview(store, assignment_id)


def _undeployable(template: Template, seed: str, why: str) -> dict[str, Any]:
    from mechanics.cache import ENGINE_VERSION

    return {
        "seed": seed,
        "engine_version": ENGINE_VERSION,
        "variant": {"seed": seed, "template_id": template.id},
        "keys": {"deployable": False, "why_not": why, "parts": []},
        "deployable": False,
        "why_not": why,
    }


def assignment_row(store: Store, assignment_id: str) -> Any:
    row = store.assignment(assignment_id)
    if row is None:
        raise Refused(404, "assignment_id", f"no assignment '{assignment_id}'")
    return row


def preview(store: Store, assignment_id: str) -> dict[str, Any]:
    """For instructors: every variant with its keys and whether it is deployed (and why not)."""
    row = assignment_row(store, assignment_id)
    return {
        "assignment_id": row.id,
        "template_id": row.template_id,
        "template_sha256": row.template_sha256,
        "closed": row.closed,
        "variants": [
            {
                "seed": v.seed,
                "engine_version": v.engine_version,
                "deployable": v.deployable,
                "why_not": v.why_not,
                "parameters": v.variant.get("parameters", {}),
                "switches": v.variant.get("switches", {}),
                "keys": v.keys.get("parts", []),
                "variant": v.variant,
            }
            for v in store.variants(assignment_id)
        ],
    }


def _policy(template: dict[str, Any], part: dict[str, Any]) -> Policy:
    return Policy(
        retry_penalty=template.get("retry_penalty", 0.1),
        max_attempts=template.get("max_attempts", 0),
        partial=dict(part.get("partial", {})),
    )


#: The derivation's steps (mechanics/derive.py STEPS) and the parts each would give away: in a
#: graded assignment a step is shown once every part it gives away is done (right, or no attempt
#: left: shown after one wrong attempt, the key would make the retry free), or the assignment is
#: closed; in practice, every step at once.
STEP_GIVES = {
    "fbd": set(),
    "coordinates": set(),
    "kinematics": {"T", "L", "momentum"},
    "energy": {"T", "V", "L", "momentum", "equilibrium", "frequency"},
    "forces": {"Q", "eom", "accel"},
    "lagrange": {"eom", "accel", "equilibrium", "frequency"},
    "matrix": {"T", "eom", "accel", "frequency"},
    "conserved": {"T", "V", "L", "momentum"},
}


def shown_steps(mode: str, closed: bool, parts: list[dict[str, Any]]) -> list[str]:
    """The derivation steps a student may see now (see STEP_GIVES)."""
    if mode == "practice" or closed:
        return list(STEP_GIVES)
    open_quantities = {p["quantity"] for p in parts if not p["solved"] and p["attempts_left"] != 0}
    return [step for step, gives in STEP_GIVES.items() if not gives & open_quantities]


def student_view(store: Store, assignment_id: str, student: str) -> dict[str, Any]:
    """A student's own variant, without any key: the scene, the parts, attempts and scores."""
    row = assignment_row(store, assignment_id)
    chosen = store.variant_of(assignment_id, student)
    if chosen is None:
        raise Refused(409, "assignment_id", "this assignment has no deployable variant")
    variant = chosen.variant
    done = defaultdict(list)
    for sub in store.attempts(assignment_id, student):
        done[sub.part].append(sub)
    parts, scores = [], {}
    for part in variant["parts"]:
        attempts = [attempt_of(s) for s in done[part["id"]]]
        policy = _policy(row.template, part)
        scores[part["id"]] = grading.part_score(attempts)
        last = done[part["id"]][-1] if done[part["id"]] else None
        closed = part_closed(row.template, row.closed, attempts, policy)
        parts.append(
            {
                "id": part["id"],
                "quantity": part["quantity"],
                "coordinate": part.get("coordinate"),
                "weight": part["weight"],
                "prompt": part.get("prompt", ""),
                "attempts_used": sum(1 for a in attempts if a.counted),
                "attempts_left": grading.attempts_left(attempts, policy),
                "solved": any(a.counted and a.raw == 1.0 for a in attempts),
                "score": scores[part["id"]],
                "last": None if last is None else _submission_json(last, closed),
            }
        )
    return {
        "assignment_id": row.id,
        "title": row.template.get("title", ""),
        "mode": row.template.get("mode", "graded"),
        "closed": row.closed,
        "seed": chosen.seed,
        "scene": variant["spec"],
        "parameters": variant["parameters"],
        "parts": parts,
        "score": grading.total_score(variant["parts"], scores),
        "steps_shown": shown_steps(row.template.get("mode", "graded"), row.closed, parts),
    }


def part_closed(template: dict[str, Any], closed: bool, attempts: list, policy: Policy) -> bool:
    """Whether a student may see the checker's full feedback on a part: in practice mode always;
    in graded mode once the part is closed (answered right, out of attempts, or the assignment
    closed). While it is open the feedback would give the key away ("Missing term 5 l² θ̇²/4"
    is the key itself), and a retry would then be free."""
    if template.get("mode", "graded") == "practice" or closed:
        return True
    if any(a.counted and a.raw == 1.0 for a in attempts):
        return True
    return grading.attempts_left(attempts, policy) == 0


def _submission_json(row: Any, full: bool = True) -> dict[str, Any]:
    feedback = list(row.feedback or [])
    if not full:
        feedback = outcomes.open_feedback(row.code or "", feedback)
    return {
        "submission_id": row.id,
        "part": row.part,
        "answer": row.answer,
        "status": row.status,
        "code": row.code,
        "decided": row.decided,
        "counted": row.counted,
        "attempt": row.number,
        "score": row.score,
        "feedback": feedback,
        "answer_latex": row.answer_latex or "",
    }


def submit(
    store: Store,
    assignment_id: str,
    student: str,
    part_id: str,
    answer: str,
    request_id: str | None = None,
    run: Run = local_run,
) -> dict[str, Any]:
    """Store the answer, then judge it and store its score; the stored row's JSON."""
    row, chosen, done, recent = store.submit_context(assignment_id, student, part_id, 60)
    if row is None:
        raise Refused(404, "assignment_id", f"no assignment '{assignment_id}'")
    if row.closed:
        raise Refused(409, "assignment_id", "this assignment is closed")
    if chosen is None:
        chosen = store.variant_of(assignment_id, student)
    if chosen is None:
        raise Refused(409, "assignment_id", "this assignment has no deployable variant")
    part = next((p for p in chosen.variant["parts"] if p["id"] == part_id), None)
    if part is None:
        raise Refused(404, "part_id", f"no part '{part_id}' in this assignment")
    policy = _policy(row.template, part)
    previous = [attempt_of(s) for s in done]
    left = grading.attempts_left(previous, policy)
    if left == 0 and not any(a.answer.strip() == answer.strip() for a in previous):
        raise Refused(409, "answer", f"all {policy.max_attempts} attempts of this part are used")
    limit = submissions_per_minute()
    if recent >= limit:
        raise Refused(429, "answer", f"more than {limit} submissions in a minute; wait a little")
    stored, new = store.store_pending(assignment_id, student, part_id, answer, request_id)
    if not new and (stored.assignment_id, stored.part, stored.answer) != (
        assignment_id,
        part_id,
        answer,
    ):
        raise Refused(
            409,
            "request_id",
            f"request_id '{request_id}' was already used for another submission "
            f"(part '{stored.part}' of assignment '{stored.assignment_id}'); send a new one",
        )
    if new or stored.status != "graded":
        stored = _grade(store, stored, chosen, part, policy, previous, run)
    attempts = [attempt_of(s) for s in store.attempts(assignment_id, student, part_id)]
    return _submission_json(stored, part_closed(row.template, row.closed, attempts, policy))


#: Verdicts already reached, by (scene, quantity, coordinate, answer): a class types the same
#: answers, and a verdict is a pure function of them (the engine's version is fixed per process).
_verdicts: OrderedDict[tuple, dict] = OrderedDict()
_verdicts_lock = threading.Lock()
MAX_VERDICTS = 4096


def _remembered(key: tuple, compute: Callable[[], dict]) -> dict:
    with _verdicts_lock:
        if key in _verdicts:
            _verdicts.move_to_end(key)
            return _verdicts[key]
    verdict = compute()  # an exception (past the budget) is not remembered
    with _verdicts_lock:
        _verdicts[key] = verdict
        while len(_verdicts) > MAX_VERDICTS:
            _verdicts.popitem(last=False)
    return verdict


def forget_verdicts() -> None:
    """Empty the verdict memo (tests that count how often the checker runs)."""
    with _verdicts_lock:
        _verdicts.clear()


def _grade(store, stored, chosen, part, policy, previous, run) -> Any:  # noqa: ANN001
    variant = Variant.from_json(chosen.variant)

    def budgeted(spec_text, quantity, coordinate, answer, options=()):  # noqa: ANN001, ANN202
        digest = hashlib.sha256(spec_text.encode()).hexdigest()
        key = (digest, quantity, coordinate, answer, options)
        return _remembered(
            key, lambda: judge_in_pool(spec_text, quantity, coordinate, answer, options)
        )

    def judge_in_pool(spec_text, quantity, coordinate, answer, options):  # noqa: ANN001, ANN202
        return run(
            grading.judge_job,
            spec_text,
            quantity,
            coordinate,
            answer,
            options,
            what="checking this answer",
            budget="check",
            affinity=spec_text,
        )

    judged = grading.judge(variant, part, stored.answer, run=budgeted)
    if variant.engine_version != ENGINE_VERSION and judged.decided:
        keys = {k["part"]: k["plain"] for k in chosen.keys.get("parts", [])}
        if not grading.key_still_holds(variant, part, keys.get(part["id"], ""), run=budgeted):
            code = outcomes.code(part["quantity"], outcomes.CANNOT_DECIDE)
            line = (
                f"Cannot decide, because this engine (version {ENGINE_VERSION}) no longer agrees "
                f"with the key this variant was made with (version {variant.engine_version}): "
                "no attempt used; the instructor must redeploy."
            )
            judged = grading.Judged(code, [code], False, False, [line])
    for _ in range(RENUMBER_TRIES):
        try:
            attempt = grading.record(previous, stored.answer, judged, policy)
        except AttemptsExhausted:
            attempt = grading.Attempt(stored.answer, judged, False, None, None, None)
        if attempt.counted and any(p.number == attempt.number for p in previous):
            # the same answer again: the earlier attempt stands, this row uses none (storing its
            # number twice broke the one-row-per-attempt index: a 409 after every renumbering)
            attempt = grading.Attempt(stored.answer, judged, False, None, None, None)
        try:
            return store.finish(stored.id, attempt)
        except IntegrityError:  # another submission of this part took that attempt number
            previous = [
                attempt_of(s)
                for s in store.attempts(stored.assignment_id, stored.student, part["id"])
            ]
    raise Refused(409, "answer", "another submission of this part is being scored; send it again")


def regrade_pending(
    store: Store, assignment_id: str, run: Run = local_run, older_than: float = 0.0
) -> int:
    """Score every answer stored but not scored (its server stopped in between): those stored
    before this process started, or at least ``older_than`` seconds ago (a younger one is most
    likely being judged by the request that stored it); how many."""
    row = assignment_row(store, assignment_id)
    count = 0
    before = max(datetime.now(UTC) - timedelta(seconds=older_than), STARTED)
    for sub in store.pending(assignment_id, before):
        chosen = store.variant_of(assignment_id, sub.student)
        part = next((p for p in chosen.variant["parts"] if p["id"] == sub.part), None)
        if part is None:
            continue
        previous = [attempt_of(s) for s in store.attempts(assignment_id, sub.student, sub.part)]
        _grade(store, sub, chosen, part, _policy(row.template, part), previous, run)
        count += 1
    return count
