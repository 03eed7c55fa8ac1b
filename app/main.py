"""The FastAPI application: the routers of ``/api/v1``, the error handlers, the static files.

``uvicorn app.main:app`` (or ``lagrange-lab serve``) serves it; routes stay thin and every error
becomes its HTTP answer in app/errors.py.
"""

from __future__ import annotations

from fastapi import Depends, FastAPI, Request
from starlette.middleware.gzip import GZipMiddleware
from starlette.types import ASGIApp

from app import __version__
from app.assets import Assets, content_version, package_version
from app.assignments.routes import router as assignments_router
from app.derivations import pool_lifespan
from app.errors import refuse_lone_surrogates, register_error_handlers
from app.middleware import BodyLimit, HeadAsGet, OneValuePerKey, RequestDeadline, SecurityHeaders
from app.paths import STATIC_DIR, api_docs_dir, mathjax_dir, plotly_dir
from app.responses import ORJSONResponse
from app.routes import (
    check,
    derive,
    equilibria,
    export,
    newton,
    pages,
    precision,
    scenes,
    simulate,
)
from app.schemas import Health, WarmUp
from app.server import install_connection_guard
from app.settings import settings

#: A request body past this is refused unread: no honest scene comes near it
#: (``LAGRANGE_LAB_MAX_BODY_BYTES``, 1 MiB by default).
MAX_BODY_BYTES = settings.max_body_bytes
#: Smaller answers gain too little from gzip to be worth it. What passes through here is dynamic
#: (the static bundles are compressed once, app/assets.py): a double pendulum's 193 kB run
#: compresses to 76.7 kB in 1.5 ms at level 1 against 73.5 kB in 7.2 ms at level 6, and under a
#: class's load the server's CPU is the scarce thing.
GZIP_MIN_BYTES = 1024
GZIP_LEVEL = 1


class LagrangeLab(FastAPI):
    """FastAPI whose outermost layers are the security headers and HEAD: they reach every
    answer, the 500s that Starlette's error middleware sends included."""

    def build_middleware_stack(self) -> ASGIApp:
        limited = RequestDeadline(
            super().build_middleware_stack(),
            body_seconds=settings.body_seconds,
            max_header_bytes=settings.max_header_bytes,
        )
        return SecurityHeaders(HeadAsGet(limited))


# Header deadline, header size and connections per client in uvicorn's protocols, however the
# app is served (lagrange-lab serve, python -m uvicorn app.main:app, gunicorn's UvicornWorker).
install_connection_guard()

app = LagrangeLab(
    lifespan=pool_lifespan,  # the worker pool starts warm before the first request
    title="Lagrange Lab",
    version=__version__,
    summary="Step-by-step Lagrangian mechanics: from a scene to its equations of motion.",
    docs_url=None,  # served by app/routes/pages.py with Swagger UI's files from this app
    redoc_url=None,
    # a lone surrogate anywhere in a JSON body: a 422 naming its field, before any route runs
    dependencies=[Depends(refuse_lone_surrogates)],
)
app.include_router(scenes.router)
app.include_router(derive.router)
app.include_router(simulate.router)
app.include_router(check.router)
app.include_router(equilibria.router)
app.include_router(newton.router)
app.include_router(export.router)
app.include_router(precision.router)
app.include_router(assignments_router)
app.include_router(pages.router)
register_error_handlers(app)

app.add_middleware(OneValuePerKey)  # an API query key given twice: a 422 before any route runs
app.add_middleware(GZipMiddleware, minimum_size=GZIP_MIN_BYTES, compresslevel=GZIP_LEVEL)
app.add_middleware(BodyLimit, max_bytes=MAX_BODY_BYTES)


async def internal_error(request: Request, exc: Exception) -> ORJSONResponse:
    """An unexpected failure in the same shape as every other error (the traceback is logged)."""
    return ORJSONResponse({"detail": "internal server error"}, status_code=500)


app.add_exception_handler(Exception, internal_error)

# Static files under versioned URLs (app/assets.py); the packages' folders are mounted before
# /static, which would otherwise shadow them. Pages name files with asset("js/scene.js").
assets = Assets()
for _prefix, _folder, _version in [
    ("/static/mathjax", mathjax_dir(), package_version("django-static-mathjax")),
    ("/static/vendor", plotly_dir(), package_version("plotly")),
    ("/static/api-docs", api_docs_dir(), package_version("fastapi-offline")),
    ("/static", STATIC_DIR, content_version(STATIC_DIR)),
]:
    if _folder is not None:
        app.mount(_prefix, assets.add(_prefix, _folder, _version))
app.state.assets = assets


@app.get("/healthz", response_model=Health, tags=["health"])
def healthz() -> Health:
    """Liveness for load balancers and CI: answers without touching the engine."""
    from app.derivations import warm_state

    return Health(version=__version__, warm=WarmUp(**warm_state))
