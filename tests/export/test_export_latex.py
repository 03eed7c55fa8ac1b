"""The derivation as LaTeX: the document compiles with pdflatex, and what a spec's author writes
can only ever print (never run, never read a file).

pdflatex runs as the app's users would run it on a downloaded file, but locked down: no shell
escape, in a temporary folder, kpathsea in paranoid mode (no reading or writing outside it), under
a timeout. Compiling takes 0.2–0.6 s per scene here (measured: atwood 0.31 s, double pendulum
0.59 s, rolling disk 0.41 s, spherical pendulum 0.20 s), so every built-in scene is compiled
under the ``slow`` mark and a representative handful always. Without pdflatex these tests skip,
except under CI, which installs it (.ci/run) and fails without it.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest
import sympy as sp
from fastapi.testclient import TestClient

from app.main import app
from mechanics.export_latex import escape_text, latex_document, prose, safe_math
from mechanics.scenes import load_scene, scene_ids

client = TestClient(app)

PDFLATEX = shutil.which("pdflatex")
IN_CI = os.environ.get("CI", "").lower() in ("1", "true", "yes")

needs_pdflatex = pytest.mark.skipif(
    PDFLATEX is None and not IN_CI,
    reason="pdflatex is not installed (apt-get install texlive-latex-base "
    "texlive-latex-recommended; .ci/run does it)",
)

HOSTILE = (
    r"\input{/etc/passwd} \write18{touch pwned} \immediate\openout1=x \def\x{} "
    r"^^5cinput 50% & $x$ #1 ~ _ { } “quoted” \"q\" é θ ∂ 😀 \end{document}"
)


def compile_tex(tex: str, folder: Path) -> Path:
    """pdflatex on ``tex`` in ``folder``, locked down; returns the PDF (asserting it exists)."""
    if PDFLATEX is None:
        pytest.fail("pdflatex is missing under CI: .ci/run should have installed it")
    (folder / "doc.tex").write_text(tex, encoding="utf-8")
    env = {**os.environ, "openin_any": "p", "openout_any": "p", "shell_escape": "f"}
    done = subprocess.run(
        [PDFLATEX, "-no-shell-escape", "-interaction=nonstopmode", "-halt-on-error", "doc.tex"],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    log = (folder / "doc.log").read_text(errors="replace") if (folder / "doc.log").exists() else ""
    errors = [line for line in log.splitlines() if line.startswith("!")]
    assert done.returncode == 0, f"pdflatex failed: {errors or done.stdout[-2000:]}"
    pdf = folder / "doc.pdf"
    assert pdf.exists() and pdf.read_bytes()[:5] == b"%PDF-" and pdf.stat().st_size > 2000
    return pdf


def latex_of(body: dict) -> str:
    r = client.post("/api/v1/export/latex", json=body)
    assert r.status_code == 200, r.text
    assert r.headers["content-type"].startswith("application/x-tex")
    return r.text


HANDFUL = ["simple_pendulum", "double_pendulum", "rolling_disk", "atwood_machine"]


@needs_pdflatex
@pytest.mark.parametrize("scene_id", HANDFUL)
def test_a_builtin_scene_compiles(scene_id, tmp_path):
    tex = latex_of({"scene_id": scene_id})
    compile_tex(tex, tmp_path)
    # every step of the derivation is a section, in the order the API gives them
    steps = client.post("/api/v1/derive", json={"scene_id": scene_id}).json()["steps"]
    sections = re.findall(r"\\section\{([^}]*)\}", tex)
    assert [escape_text(s["title"]) for s in steps] == sections
    # and every equation line of every step is in it (as math, or escaped as text)
    lines = sum(len(s["latex"]) for s in steps)
    assert tex.count("\\begin{center}\\fiteq{") + tex.count("\\ttfamily\\small") >= lines


@needs_pdflatex
@pytest.mark.slow
@pytest.mark.parametrize("scene_id", sorted(set(scene_ids()) - set(HANDFUL)))
def test_every_other_builtin_scene_compiles(scene_id, tmp_path):
    compile_tex(latex_of({"scene_id": scene_id}), tmp_path)


@needs_pdflatex
def test_get_link_gives_the_same_document(tmp_path):
    r = client.get("/api/v1/export/scenes/simple_pendulum/derivation.tex")
    assert r.status_code == 200
    assert 'filename="simple_pendulum.tex"' in r.headers["content-disposition"]
    assert r.text == latex_of({"scene_id": "simple_pendulum"})


@needs_pdflatex
def test_a_posted_spec_with_a_hostile_title_and_names_compiles_and_only_prints(tmp_path):
    spec = load_scene("double_pendulum")
    spec["title"] = HOSTILE
    spec["summary"] = HOSTILE
    # (a unit like kg\input{/etc/passwd} never gets here: the spec refuses a unit the units
    # grammar cannot read, tests/spec/test_spec_limits.py)
    # underscores in names: sympy prints them inside \text{...}, where _ would stop pdflatex
    spec["bodies"][0]["name"] = "bob_one"
    spec["bodies"][1]["position"]["from"] = "bob_one"
    tex = latex_of({"scene": spec})
    # nothing of the title survives as a control sequence: every backslash of it is escaped
    primitives = re.findall(
        r"\\(input|write|openout|immediate|def|csname|catcode)(?![A-Za-z])", tex
    )
    assert primitives == []
    assert tex.count("\\end{document}") == 1 and tex.count("\\begin{document}") == 1
    assert "^^5c" not in tex
    pdf = compile_tex(tex, tmp_path)
    assert not (tmp_path / "pwned").exists() and not (tmp_path / "x.tex").exists()
    assert pdf.exists()


@pytest.mark.parametrize(
    "latex",
    [
        r"\input{/etc/passwd}",
        r"x \write18{rm -rf /}",
        r"\immediate\openout1=f",
        r"^^5cinput{x}",
        r"\begin{document}",
        r"\end{itemize}",
        r"\csname input\endcsname",
        r"x}",
        r"{x",
        r"a % comment",
        r"a $ b",
        r"#1",
        r"\catcode`\@=11",
        r"\begin {document}",
    ],
)
def test_safe_math_refuses_what_is_not_an_equation(latex):
    assert not safe_math(latex)


def test_safe_math_accepts_sympys_latex():
    """sympy's own printing of the kinds of expressions the engine derives (built here by hand,
    not taken from the engine): fractions, trig, dots, matrices, piecewise."""
    t = sp.Symbol("t")
    theta = sp.Function("theta")(t)
    m, length, g = sp.symbols("m l g", positive=True)
    cases = [
        sp.latex(sp.Rational(1, 2) * m * length**2 * theta.diff(t) ** 2),
        sp.latex(sp.Eq(theta.diff(t, 2), -g / length * sp.sin(theta))),
        sp.latex(sp.Matrix([[m, 0], [0, m * length**2]])),
        sp.latex(sp.Piecewise((1, theta > 0), (0, True))),
        sp.latex(sp.sqrt(sp.Abs(sp.cos(theta) - sp.Symbol("omega")))),
        r"\vec{F}_{g,\text{bob\_1}} = - g m\hat{\jmath}",
        r"\frac{\partial L}{\partial \dot{\theta}} = m l^{2} \dot{\theta}",
        # a scene with a length L writes its Lagrangian as a script L (steps/energy.py)
        r"\mathcal{L} = \frac{L m \dot{\theta}^{2}}{2}",
    ]
    for latex in cases:
        assert safe_math(latex), latex


def test_escaped_text_has_no_control_sequence_but_our_own():
    """After escaping, every backslash starts one of the escapes this module writes."""
    ours = re.compile(
        r"\\(textbackslash\{\}|textasciicircum\{\}|textasciitilde\{\}|textless\{\}"
        r"|textgreater\{\}|textbar\{\}|[{}$&#_%]|ttfamily|ldots\{\}|theta|partial|dot|ddot)"
    )
    escaped = escape_text(HOSTILE + " q̇ θ̈ <|>")
    assert ours.sub("", escaped).count("\\") == 0, escaped
    assert escaped.count("{") == escaped.count("}")


def test_prose_keeps_safe_math_and_escapes_the_rest():
    assert prose(r"moves with $\theta_{1}$, 50%") == r"moves with $\theta_{1}$, 50\%"
    assert prose(r"odd $\input{x}$ math") == (r"odd {\ttfamily \textbackslash{}input\{x\}} math")
    assert prose("one $ sign") == r"one \$ sign"


def test_document_structure_without_compiling():
    """The article has what the issue asks for: the procedure, each step, the values."""
    derivation = {
        "scene": {
            "title": "T & T",
            "coordinates": ["q_1"],
            "parameters": {"k_s": 2.5},
            "initial": {"q_1": 0.1},
        },
        "steps": [
            {"id": "fbd", "title": "Free-body diagram", "text": "x", "latex": ["a"], "labels": []},
            {
                "id": "energy",
                "title": "Energies",
                "text": "T = ½ m v²",
                "latex": [r"T = \frac{1}{2}"],
            },
        ],
        "warnings": ["w_1"],
    }
    tex = latex_document(derivation)
    assert tex.startswith("\\documentclass")
    assert "\\title{T \\& T}" in tex
    assert "\\section*{The procedure}" in tex and tex.count("\\item \\textbf") == 2
    assert "k\\_s & $2.5$" in tex and "q\\_1\\_dot & $0$" in tex
    assert "$\\tfrac{1}{2}$" in tex and "v$^{2}$" in tex
    assert "\\item w\\_1" in tex
