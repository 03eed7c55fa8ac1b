"""The assignment pages (HTML; data via /api/v1/assignments with the reader's own token):
``/assignments/{id}`` for a student, ``/assignments`` for an instructor. The token is typed once
(or given in the link's fragment, ``#token=...``, which never reaches a server log) and kept in the
tab's sessionStorage."""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import HTMLResponse

router = APIRouter(include_in_schema=False)


def _page(request: Request, name: str, **context: object) -> HTMLResponse:
    from app.paths import mathjax_dir
    from app.routes.pages import templates

    context = {"mathjax": mathjax_dir() is not None, **context}
    return templates.TemplateResponse(request, name, context)


@router.get("/assignments", response_class=HTMLResponse)
def instructor_page(request: Request) -> HTMLResponse:
    return _page(request, "assignment_admin.html", entry_module="js/assignment_admin.js")


@router.get("/assignments/{assignment_id}", response_class=HTMLResponse)
def student_page(request: Request, assignment_id: str) -> HTMLResponse:
    return _page(
        request, "assignment.html", entry_module="js/assignment.js", assignment_id=assignment_id
    )
