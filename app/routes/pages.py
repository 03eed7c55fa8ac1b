"""The teaching pages: the catalog, a scene's page, the spec editor, and the API docs (HTML; data
via /api/v1). Every page answers ``HEAD`` too (app/middleware.py)."""

from __future__ import annotations

from typing import Any

import jinja2
from fastapi import APIRouter, Request
from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html
from fastapi.responses import HTMLResponse
from fastapi.templating import Jinja2Templates

from app.paths import TEMPLATES_DIR, mathjax_dir
from mechanics.scenes import list_scenes, scene_ids

router = APIRouter(include_in_schema=False)


def _page_context(request: Request) -> dict[str, Any]:
    """What every template may use besides its own variables: the CSP nonce of this response
    (app/middleware.py) for inline scripts."""
    return {"csp_nonce": getattr(request.state, "csp_nonce", "")}


@jinja2.pass_context
def asset(context: jinja2.runtime.Context, path: str) -> str:
    """``{{ asset("js/scene.js") }}``: the file's versioned URL, cached by the browser for a year
    (app/assets.py)."""
    return context["request"].app.state.assets.url(path)


templates = Jinja2Templates(directory=str(TEMPLATES_DIR), context_processors=[_page_context])
templates.env.globals["asset"] = asset


def _page(request: Request, name: str, **context) -> HTMLResponse:
    return templates.TemplateResponse(
        request, name, {"mathjax": mathjax_dir() is not None, **context}
    )


@router.get("/", response_class=HTMLResponse)
def catalog(request: Request) -> HTMLResponse:
    return _page(request, "catalog.html", scenes=list_scenes())


@router.get("/scenes/{scene_id}", response_class=HTMLResponse)
def scene_page(request: Request, scene_id: str) -> HTMLResponse:
    if scene_id not in scene_ids():
        return templates.TemplateResponse(
            request, "404.html", {"what": f"There is no scene '{scene_id}'."}, status_code=404
        )
    entry = next(s for s in list_scenes() if s["id"] == scene_id)
    page = _page(
        request, "scene.html", scene_id=scene_id, title=entry["title"], summary=entry["summary"]
    )
    # The page's script asks for these first; the browser fetches them while it is still
    # parsing MathJax and the modules, and the script's fetch() finds them waiting.
    page.headers["Link"] = ", ".join(
        f"<{url}>; rel=preload; as=fetch; crossorigin"
        for url in (f"/api/v1/scenes/{scene_id}", f"/api/v1/scenes/{scene_id}/live")
    )
    return page


@router.get("/editor", response_class=HTMLResponse)
def editor(request: Request) -> HTMLResponse:
    return _page(request, "editor.html", scene_ids=scene_ids())


@router.get("/docs", response_class=HTMLResponse)
def swagger_ui(request: Request) -> HTMLResponse:
    """Swagger UI from the ``fastapi-offline`` package's files, served by this app: no CDN."""
    url = request.app.state.assets.url
    page = get_swagger_ui_html(
        openapi_url=request.app.openapi_url,
        title=f"{request.app.title} — API",
        swagger_js_url=url("api-docs/swagger-ui-bundle.js"),
        swagger_css_url=url("api-docs/swagger-ui.css"),
        swagger_favicon_url=url("api-docs/favicon.png"),
        oauth2_redirect_url=None,
    )
    return _with_nonce(page, request)


@router.get("/redoc", response_class=HTMLResponse)
def redoc(request: Request) -> HTMLResponse:
    """ReDoc from the ``fastapi-offline`` package's files, without Google's fonts."""
    url = request.app.state.assets.url
    page = get_redoc_html(
        openapi_url=request.app.openapi_url,
        title=f"{request.app.title} — API",
        redoc_js_url=url("api-docs/redoc.standalone.js"),
        redoc_favicon_url=url("api-docs/favicon.png"),
        with_google_fonts=False,
    )
    return _with_nonce(page, request)


def _with_nonce(page: HTMLResponse, request: Request) -> HTMLResponse:
    """FastAPI's docs page with this response's CSP nonce on its inline script."""
    nonce = _page_context(request)["csp_nonce"]
    body = bytes(page.body).replace(b"<script>", f'<script nonce="{nonce}">'.encode())
    return HTMLResponse(body)
