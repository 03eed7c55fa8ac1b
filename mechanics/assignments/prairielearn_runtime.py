"""What an exported PrairieLearn question's ``server.py`` calls (mechanics/assignments/
prairielearn.py writes it): the variant from PrairieLearn's seed, and grading by the checker.

PrairieLearn's ``data`` holds ``params`` (shown to the student: never a key),
``correct_answers`` (shown only in the answer panel), ``submitted_answers``, and, for grading,
``partial_scores``, ``format_errors``, ``score`` and ``feedback``.
"""

from __future__ import annotations

from typing import Any

from . import grading, outcomes
from .keys import variant_keys
from .template import parse_template
from .variants import Variant, build_variant


def generate_question(template_document: dict[str, Any], data: dict[str, Any]) -> None:
    """Build the variant of ``data["variant_seed"]``; a variant whose keys are not verified is
    refused (PrairieLearn reports the error and no student sees it)."""
    template = parse_template(template_document)
    variant = build_variant(template, data["variant_seed"])
    keys = variant_keys(variant)
    if not keys.deployable:
        raise ValueError(f"variant {variant.seed} is not deployable: {keys.why_not}")
    spec = variant.spec
    units = spec.get("units", {})
    given = ", ".join(
        f"{name} = {value:g}{(' ' + units[name]) if name in units else ''}"
        for name, value in variant.parameters.items()
    )
    data["params"]["title"] = spec.get("title", template.title)
    data["params"]["summary"] = spec.get("summary", "")
    data["params"]["given"] = given or "the symbols of the scene"
    data["params"]["variant"] = variant.to_json()
    for key in keys.keys:
        data["correct_answers"][key.part] = key.plain


def grade_question(template_document: dict[str, Any], data: dict[str, Any]) -> None:
    """Each part judged by the checker: its score (partial credit by outcome code) and its
    feedback in ``partial_scores``; unreadable or undecidable answers are format errors."""
    variant = Variant.from_json(data["params"]["variant"])
    # graded: PrairieLearn shows the feedback after every try, and the checker's words name the
    # key ("Missing term ..."): only the outcome's description, as the app gives an open part
    graded = template_document.get("mode", "graded") == "graded"
    total = weights = 0.0
    for part in variant.parts:
        name = part["id"]
        answer = str(data["submitted_answers"].get(name, "") or "")
        weights += part["weight"]
        if not answer.strip():
            data["format_errors"][name] = "No answer given."
            data["partial_scores"].pop(name, None)  # the element's own exact-match grade
            continue
        judged = grading.judge(variant, part, answer)
        feedback = list(judged.feedback)
        if graded and judged.code.split(".", 1)[1] not in outcomes.CREDIT:
            feedback = outcomes.open_feedback(judged.code, feedback, note=False)
        if not judged.decided:
            data["format_errors"][name] = " ".join(feedback)
            data["partial_scores"].pop(name, None)
            continue
        kind = judged.code.split(".", 1)[1]
        score = 1.0 if kind in outcomes.CREDIT else float(part["partial"].get(judged.code, 0.0))
        data["partial_scores"][name] = {
            "score": score,
            "weight": part["weight"],
            "feedback": f"{judged.code}: " + " ".join(feedback),
        }
        total += part["weight"] * score
    data["score"] = total / weights if weights else 0.0
