"""The teaching pages: the catalog, a scene's page, and the spec editor (HTML; data via /api/v1)."""

from __future__ import annotations

from pathlib import Path

from fastapi import APIRouter, Request
from fastapi.responses import FileResponse, HTMLResponse
from fastapi.templating import Jinja2Templates

from app.paths import TEMPLATES_DIR, mathjax_dir
from mechanics.scenes import list_scenes, scene_ids

router = APIRouter(include_in_schema=False)
templates = Jinja2Templates(directory=str(TEMPLATES_DIR))


def _plotly_js() -> Path:
    import plotly

    return Path(plotly.__file__).parent / "package_data" / "plotly.min.js"


@router.get("/static/vendor/plotly.min.js")
def plotly_js() -> FileResponse:
    """plotly's own bundle from the installed package: no CDN, cached by the browser."""
    return FileResponse(
        _plotly_js(),
        media_type="text/javascript",
        headers={"Cache-Control": "public, max-age=86400"},
    )


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
    return _page(
        request, "scene.html", scene_id=scene_id, title=entry["title"], summary=entry["summary"]
    )


@router.get("/editor", response_class=HTMLResponse)
def editor(request: Request) -> HTMLResponse:
    return _page(request, "editor.html", scene_ids=scene_ids())
