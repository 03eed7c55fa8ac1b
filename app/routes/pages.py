"""The teaching pages: the catalog, a scene's page, the spec editor, and the API docs (HTML; data
via /api/v1). Every page answers ``HEAD`` too (app/middleware.py)."""

from __future__ import annotations

import logging
import re
from collections.abc import Callable
from typing import Any, TypeVar

import anyio
import anyio.to_thread
import jinja2
import orjson
from fastapi import APIRouter, Request
from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html
from fastapi.responses import HTMLResponse
from fastapi.templating import Jinja2Templates

from app import derivations
from app.paths import STATIC_DIR, TEMPLATES_DIR, mathjax_dir
from mechanics.scenes import list_scenes, scene_ids

router = APIRouter(include_in_schema=False)
log = logging.getLogger(__name__)
T = TypeVar("T")

#: How long a scene page waits for its derivation and for its live equations when this process
#: does not have them yet (before the warm-up reached the scene); ready, each takes a few ms.
READY_WAIT_SECONDS = 0.2


def _page_context(request: Request) -> dict[str, Any]:
    """What every template may use besides its own variables: the CSP nonce of this response
    (app/middleware.py) for inline scripts."""
    return {"csp_nonce": getattr(request.state, "csp_nonce", "")}


@jinja2.pass_context
def asset(context: jinja2.runtime.Context, path: str) -> str:
    """``{{ asset("js/scene.js") }}``: the file's versioned URL, cached by the browser for a year
    (app/assets.py)."""
    return context["request"].app.state.assets.url(path)


@jinja2.pass_context
def module_preloads(context: jinja2.runtime.Context, entry: str) -> list[str]:
    """``{% for url in module_preloads("js/scene.js") %}``: the versioned URLs of everything a
    page's entry module imports statically, for ``<link rel="modulepreload">`` (the entry itself
    is named by the page's own script, which the browser reads at once when it is in the head)."""
    return context["request"].app.state.assets.module_urls(entry)[1:]


def inline_json(data: bytes) -> str:
    """JSON bytes made safe inside ``<script type="application/json">``: no ``</script>`` or
    ``<!--`` can close or confuse the element (``<``, ``>``, ``&`` become JSON escapes, which
    are only ever inside strings, so the JSON means the same)."""
    text = data.decode()
    for char, escape in (("<", "\\u003c"), (">", "\\u003e"), ("&", "\\u0026")):
        text = text.replace(char, escape)
    return text


_LOWER = "alpha beta gamma delta epsilon zeta eta theta iota kappa lambda mu nu xi pi rho sigma tau"
_GREEK = dict(
    zip((_LOWER + " upsilon phi chi psi omega").split(), "αβγδεζηθικλμνξπρστυφχψω", strict=True)
)
_GREEK |= dict(
    zip("Gamma Delta Theta Lambda Xi Pi Sigma Phi Psi Omega".split(), "ΓΔΘΛΞΠΣΦΨΩ", strict=True)
)
_NAME = re.compile(r"([A-Za-z]+?)_?(\d*)")


def symbol(name: str) -> str:
    """A coordinate's or parameter's name as a symbol where nothing typesets it (a catalog card):
    theta1 -> θ₁, Omega -> Ω; any other name (x_cart) stays what the editor calls it. The same
    rule as static/js/texnames.js nameText."""
    m = _NAME.fullmatch(name)
    if not m:
        return name
    stem, digits = m.groups()
    base = _GREEK.get(stem) or (stem if len(stem) == 1 else None)
    if base is None:
        return name
    return base + digits.translate(str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉"))


templates = Jinja2Templates(directory=str(TEMPLATES_DIR), context_processors=[_page_context])
templates.env.globals["asset"] = asset
templates.env.filters["symbol"] = symbol
templates.env.globals["module_preloads"] = module_preloads


def _page(request: Request, name: str, **context) -> HTMLResponse:
    return templates.TemplateResponse(
        request, name, {"mathjax": mathjax_dir() is not None, **context}
    )


@router.get("/", response_class=HTMLResponse)
def catalog(request: Request) -> HTMLResponse:
    return _page(request, "catalog.html", scenes=list_scenes(), entry_module="js/catalog.js")


@router.get("/scenes/{scene_id}", response_class=HTMLResponse)
async def scene_page(request: Request, scene_id: str) -> HTMLResponse:
    """A scene's page, carrying in its HTML what its script would otherwise ask for first: the
    spec, the derivation (built-in ones are derived at server start, app/derivations.py) and the
    live equations' slots, with the live module named for preloading. Each saves a round trip
    that the derivation and the first moving frame used to wait for; whichever is not ready yet
    is left out, and the script asks the API for it as before."""
    if scene_id not in scene_ids():
        return templates.TemplateResponse(
            request, "404.html", {"what": f"There is no scene '{scene_id}'."}, status_code=404
        )
    entry = next(s for s in list_scenes() if s["id"] == scene_id)
    derivation, live, module = await _inline_parts(scene_id)
    return _page(
        request,
        "scene.html",
        scene_id=scene_id,
        title=entry["title"],
        summary=entry["summary"],
        entry_module="js/scene.js",
        inline_spec=inline_json(_spec_json(scene_id)),
        inline_derivation=derivation,
        inline_live=live,
        live_module=module,
        prerendered_math=_prerendered_math(request, scene_id),
    )


def _prerendered_math(request: Request, scene_id: str) -> str | None:
    """The URL of the scene's derivation typeset ahead of time (``python -m app.prerender``), if
    the package has it: the page puts those equations up as they are instead of typesetting them
    (static/js/prerendered.js). Cached a year like every asset; a derivation changed since
    misses in it and is typeset live."""
    if mathjax_dir() is None or not (STATIC_DIR / "math" / f"{scene_id}.json").is_file():
        return None
    return request.app.state.assets.url(f"math/{scene_id}.json")


def _spec_json(scene_id: str) -> bytes:
    """The scene's spec exactly as ``GET /api/v1/scenes/{id}`` answers it."""
    from app.routes.scenes import get_scene

    return orjson.dumps(
        get_scene(scene_id).model_dump(mode="json", exclude_unset=True, by_alias=True)
    )


#: What each scene's page carries, once this process has it all: (derivation, live) as inline
#: JSON, and the live module's URL.
_inline: dict[str, tuple[str, str | None, str | None]] = {}


async def _if_ready(job: Callable[[str], T], scene_id: str) -> T | None:
    """``job(scene_id)`` if it is done within `READY_WAIT_SECONDS` (a built-in scene's work is
    done once per process, at server start, and then remembered), else None: the page is sent
    without it while the job goes on in its thread, and the page's script asks the API."""
    try:
        with anyio.fail_after(READY_WAIT_SECONDS):
            return await anyio.to_thread.run_sync(job, scene_id, abandon_on_cancel=True)
    except TimeoutError:
        return None


async def _inline_parts(scene_id: str) -> tuple[str | None, str | None, str | None]:
    """The derivation's JSON exactly as ``POST /api/v1/derive`` answers it and what
    ``GET /api/v1/scenes/{id}/live`` answers, each None if not ready (or no live preview).
    Kept once both are had: a page view then costs a lookup, not a thread."""
    if scene_id in _inline:
        return _inline[scene_id]
    body = await _if_ready(derivations.scene_json, scene_id)
    derivation = inline_json(body) if body is not None else None
    live, complete = await _live_if_ready(scene_id)
    live_json = inline_json(orjson.dumps(live)) if live else None
    parts = (derivation, live_json, live["module"] if live else None)
    if derivation is not None and complete:
        _inline[scene_id] = parts
    return parts


async def _live_if_ready(scene_id: str) -> tuple[dict[str, Any] | None, bool]:
    """What ``GET /api/v1/scenes/{id}/live`` answers, if ready; and whether that is final (the
    scene has no live equations, or they are here)."""
    from mechanics.jscode import JsUnavailable, scene_live_module

    try:
        live = await _if_ready(scene_live_module, scene_id)
    except JsUnavailable as exc:
        log.info("no live preview for %s: %s", scene_id, exc)
        return None, True
    if live is None:
        return None, False
    return {
        "module": f"/api/v1/scenes/{scene_id}/live.js?v={live.digest}",
        **live.slots(),
    }, True


@router.get("/editor", response_class=HTMLResponse)
def editor(request: Request) -> HTMLResponse:
    return _page(request, "editor.html", scene_ids=scene_ids(), entry_module="js/editor.js")


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
