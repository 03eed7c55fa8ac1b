"""Where the page assets live: the app's templates/ and static/, and the packages that ship files.

In a checkout they are the top-level ``templates/`` and ``static/`` beside the packages, so with the
editable install (``pip install -e .``) a page author edits a file and reloads, with nothing to
rebuild. A wheel carries the same folders as package data of ``app`` (pyproject.toml maps
``app.templates`` and ``app.static`` onto them), so an install outside the checkout finds them
inside the installed package.
"""

from __future__ import annotations

from importlib import resources
from importlib.util import find_spec
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _pages_folder(name: str) -> Path:
    """``app/<name>`` of an installed wheel, else the checkout's top-level ``<name>/``."""
    installed = Path(str(resources.files("app") / name))
    return installed if installed.is_dir() else ROOT / name


TEMPLATES_DIR = _pages_folder("templates")
STATIC_DIR = _pages_folder("static")


def _package_folder(package: str, *parts: str) -> Path | None:
    """A data folder inside an installed package, found without importing the package."""
    spec = find_spec(package)
    if spec is None or not spec.submodule_search_locations:
        return None
    folder = Path(next(iter(spec.submodule_search_locations)), *parts)
    return folder if folder.is_dir() else None


def mathjax_dir() -> Path | None:
    """MathJax 3's files from the ``django-static-mathjax`` package (math renders offline), or
    None where that package is not installed."""
    return _package_folder("mathjax", "static", "mathjax")


def plotly_dir() -> Path | None:
    """The folder of plotly's own ``plotly.min.js`` in the installed ``plotly`` package."""
    return _package_folder("plotly", "package_data")


def api_docs_dir() -> Path | None:
    """Swagger UI's and ReDoc's bundles from the ``fastapi-offline`` package (/docs works
    offline)."""
    return _package_folder("fastapi_offline", "static")
