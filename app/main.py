"""The FastAPI application: the routers of ``/api/v1``, the error handlers, the static files.

``uvicorn app.main:app`` (or ``lagrange-lab serve``) serves it; routes stay thin and every error
becomes its HTTP answer in app/errors.py.
"""

from __future__ import annotations

from typing import Any

from fastapi import FastAPI, Request
from fastapi.responses import JSONResponse
from fastapi.staticfiles import StaticFiles

from app import __version__
from app.errors import register_error_handlers
from app.paths import STATIC_DIR, mathjax_dir
from app.routes import check, derive, equilibria, newton, pages, scenes, simulate
from app.schemas import Health

#: A request body past this is refused unread: no honest scene comes near it.
MAX_BODY_BYTES = 1024 * 1024

app = FastAPI(
    title="Lagrange Lab",
    version=__version__,
    summary="Step-by-step Lagrangian mechanics: from a scene to its equations of motion.",
    docs_url="/docs",
)
app.include_router(scenes.router)
app.include_router(derive.router)
app.include_router(simulate.router)
app.include_router(check.router)
app.include_router(equilibria.router)
app.include_router(newton.router)
app.include_router(pages.router)
register_error_handlers(app)

_mathjax = mathjax_dir()
if _mathjax is not None:  # mounted before /static, which would otherwise shadow it
    app.mount("/static/mathjax", StaticFiles(directory=_mathjax), name="mathjax")
app.mount("/static", StaticFiles(directory=STATIC_DIR, check_dir=False), name="static")


@app.get("/healthz", response_model=Health, tags=["health"])
def healthz() -> Health:
    """Liveness for load balancers and CI: answers without touching the engine."""
    return Health(version=__version__)


@app.middleware("http")
async def refuse_huge_bodies(request: Request, call_next: Any) -> Any:
    """Refuse a body over MAX_BODY_BYTES by its Content-Length, before reading it into memory."""
    length = request.headers.get("content-length", "")
    if length.isdigit() and int(length) > MAX_BODY_BYTES:
        return JSONResponse({"detail": "request body over 1 MiB"}, status_code=413)
    return await call_next(request)
