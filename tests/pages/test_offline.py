"""No asset the app ships points a browser at another host: the pages work offline (the browser
tests also record every off-site request a page makes; this catches what a page has not asked for
yet, such as a library's default URL)."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: Hosts that serve scripts, styles and fonts to pages: what a CDN dependency looks like.
REMOTE = re.compile(r"https?://(cdn|unpkg|cdnjs|fonts\.googleapis|fonts\.gstatic|jsdelivr)[\w.-]*")


def test_no_shipped_asset_names_a_cdn():
    found = []
    for folder in ("static", "templates"):
        for path in (ROOT / folder).rglob("*"):
            if path.is_file() and path.suffix in {".js", ".css", ".html", ".json", ".svg"}:
                text = path.read_text(encoding="utf-8", errors="replace")
                found += [f"{path.relative_to(ROOT)}: {m.group(0)}" for m in REMOTE.finditer(text)]
    assert found == []


def test_plotlys_map_default_is_same_origin():
    """The vendored bundle's topojsonURL default (geo traces' maps) was plotly's CDN."""
    bundle = (ROOT / "static/vendor/plotly-basic/plotly.min.js").read_text(encoding="utf-8")
    assert 'topojsonURL:{valType:"string",noBlank:!0,dflt:"/static/' in bundle
