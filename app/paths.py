"""Where the page assets live: top-level ``templates/`` and ``static/`` beside the packages.

They are found relative to this checkout (the install is editable, ``pip install -e .``), so a
page author edits a file and reloads, with nothing to rebuild or reinstall.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TEMPLATES_DIR = ROOT / "templates"
STATIC_DIR = ROOT / "static"


def mathjax_dir() -> Path | None:
    """MathJax 3's files from the ``django-static-mathjax`` package (math renders offline), or
    None where that package is not installed."""
    try:
        folder = Path(str(resources.files("mathjax") / "static" / "mathjax"))
    except ModuleNotFoundError:
        return None
    return folder if folder.is_dir() else None
