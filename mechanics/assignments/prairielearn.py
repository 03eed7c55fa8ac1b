"""``lagrange-lab export prairielearn TEMPLATE DIR``: a PrairieLearn question from a template.

The directory holds ``info.json``, ``question.html`` (a ``pl-string-input`` per part) and
``server.py``, whose ``generate(data)`` builds the variant from ``data["variant_seed"]`` (the same
variant as Lagrange Lab's for that seed) and refuses one whose keys the second route cannot
verify, and whose ``grade(data)`` fills ``data["partial_scores"]`` with the checker's scores and
feedback (a graded template's: only the outcome's description, since the checker's words name
the key). An answer that does not parse, or that the checker cannot decide, is a format error:
PrairieLearn then neither grades it nor counts it. The question imports this engine as a library
(``pip install lagrange-lab`` in the course's Python image); it needs no network.
"""

from __future__ import annotations

import html
import json
import uuid
from pathlib import Path

from .template import Template, template_hash

#: A fixed namespace: the same template id always gets the same question uuid.
NAMESPACE = uuid.UUID("6f1c9f0e-2b7d-4d0a-9a8e-27a55157a127")
WHAT = {
    "T": "the kinetic energy T",
    "V": "the potential energy V",
    "L": "the Lagrangian L",
    "Q": "the generalized force Q",
    "eom": "the equation of motion",
    "accel": "the acceleration",
    "momentum": "the generalized momentum",
    "equilibrium": "the equilibrium",
    "frequency": "the small-oscillation angular frequency ω",
}

SERVER = '''"""PrairieLearn question code for the Lagrange Lab template {template_id!r}
(sha256 {sha}).

Written by `lagrange-lab export prairielearn`; do not edit: export again instead.
"""

from mechanics.assignments.prairielearn_runtime import generate_question, grade_question

TEMPLATE = {template}


def generate(data):
    generate_question(TEMPLATE, data)


def grade(data):
    grade_question(TEMPLATE, data)
'''


def question_html(template: Template) -> str:
    parts = []
    for p in template.parts:
        asked = WHAT[p.quantity] + (f" for {p.coordinate}" if p.coordinate else "")
        prompt = html.escape(p.prompt or f"Give {asked}.")
        parts.append(
            f"<p>Part {html.escape(p.id)}: {prompt}</p>\n"
            f'<pl-string-input answers-name="{html.escape(p.id)}" label="{html.escape(p.id)} ="'
            f' size="60" remove-spaces="false" placeholder="plain text, e.g. m*l^2*theta_dot^2/2">'
            f"</pl-string-input>"
        )
    head = (
        "<pl-question-panel>\n<p>{{params.title}}</p>\n<p>{{params.summary}}</p>\n"
        "<p>Given: {{params.given}}</p>\n</pl-question-panel>\n"
    )
    return head + "\n".join(parts) + "\n"


def export(template: Template, folder: Path) -> list[Path]:
    """Write the question into ``folder`` (made if missing); the paths written."""
    folder.mkdir(parents=True, exist_ok=True)
    document = template.model_dump(mode="json", exclude_defaults=True)
    info = {
        "uuid": str(uuid.uuid5(NAMESPACE, template.id)),
        "title": template.title,
        "topic": "Lagrangian mechanics",
        "tags": ["lagrange-lab", template.id],
        "type": "v3",
    }
    written = {
        "info.json": json.dumps(info, indent=2) + "\n",
        "question.html": question_html(template),
        "server.py": SERVER.format(
            template_id=template.id, sha=template_hash(template), template=repr(document)
        ),
    }
    paths = []
    for name, text in written.items():
        path = folder / name
        path.write_text(text, encoding="utf-8")
        paths.append(path)
    return paths
