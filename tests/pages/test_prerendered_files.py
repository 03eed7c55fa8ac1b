"""The prerendered math (static/math/<scene>.json, made by ``python -m app.prerender``) covers every
built-in derivation as the engine writes it now.

A formula missing from its file is typeset live, so a stale file is never wrong, only slow; but
slow is what issue 13 was about, so a derivation's text changing without the files being made
again fails here, naming the command. Whether each stored formula is what MathJax renders now
is checked in a browser (tests/browser/test_prerendered_math.py).
"""

from __future__ import annotations

import json
import re

import pytest

from app.derivations import scene_json
from app.paths import STATIC_DIR
from mechanics.scenes import scene_ids

#: `$…$` in a step's prose, as static/js/texnames.js inlineMath reads it
INLINE = re.compile(r"\$([^$]+)\$")
REMAKE = "run `python -m app.prerender` (Chromium) and commit static/math/"


def formulas(scene_id: str) -> set[str]:
    """The keys the page looks up for the scene's steps: each display line (D) and each `$…$` of
    the prose (I)."""
    derivation = json.loads(scene_json(scene_id))
    keys = set()
    for step in derivation["steps"]:
        keys |= {"D" + tex for tex in step["latex"]}
        keys |= {"I" + tex for tex in INLINE.findall(step["text"])}
    return keys


@pytest.mark.parametrize("scene_id", sorted(scene_ids()))
def test_every_formula_of_a_built_in_derivation_is_prerendered(scene_id):
    path = STATIC_DIR / "math" / f"{scene_id}.json"
    assert path.is_file(), f"no prerendered math for {scene_id}: {REMAKE}"
    data = json.loads(path.read_text(encoding="utf-8"))
    needed = formulas(scene_id)
    assert len(needed) > 5  # a derivation has at least T, V, L and the equations of motion
    # a key is D or I, the font size in px, "|", the TeX: each formula at some size at least
    have = {key[0] + key.partition("|")[2] for key in data["math"]}
    missing = sorted(needed - have)
    assert not missing, f"{len(missing)} formulas of {scene_id} changed: {REMAKE}\n{missing[:5]}"


@pytest.mark.parametrize("scene_id", sorted(scene_ids()))
def test_a_prerendered_file_is_mathjax_output_with_its_glyphs_and_styles(scene_id):
    data = json.loads((STATIC_DIR / "math" / f"{scene_id}.json").read_text(encoding="utf-8"))
    assert re.fullmatch(r"3\.\d+\.\d+", data["mathjax"])
    assert "mjx-assistive-mml" in data["css"]  # the rule that keeps the spoken MathML unseen
    glyphs = set(re.findall(r'<path id="([^"]+)"', data["defs"]))
    assert sorted(set(data["math"].values())) == list(range(len(data["html"])))
    for key, i in data["math"].items():
        html = data["html"][i]
        assert re.match(r"[DI]\d+(\.\d+)?\|", key), key
        assert html.startswith('<mjx-container class="MathJax" jax="SVG"')
        assert ('display="true"' in html) == (key[0] == "D")
        assert "ctxtmenu" not in html.lower()  # no menu is attached to it yet
        assert "<script" not in html.lower()
        # every glyph a formula draws is defined in the file's own glyph cache
        used = set(re.findall(r'xlink:href="#([^"]+)"', html))
        assert used <= glyphs, (key, sorted(used - glyphs)[:3])
