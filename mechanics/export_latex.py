"""A scene's whole derivation as a LaTeX article that compiles with plain pdflatex.

Every step as the page shows it (its prose, then its equations with their labels), the notes'
procedure as an outline, the parameters and initial state, and the free-body diagram drawn at the
initial state with LaTeX's own ``picture`` environment (no TikZ: Debian's texlive-latex-base and
-recommended are enough, 40 MB instead of 120).

What reaches the document from a posted spec is someone else's text, and TeX is a programming
language (``\\input{/etc/passwd}``, ``\\write18{...}``). So:

- free text (the title, the summary, names, the steps' prose) goes through `escape_text`: every
  special character is escaped and every character outside ASCII is mapped to LaTeX or shown as
  its code point, so it can only ever print;
- mathematics (the steps' equations, the ``$...$`` in their prose, force labels) is the engine's
  sympy output; it is kept only when `safe_math` accepts it: balanced braces, no ``%``, ``#``,
  ``$`` or ``^^``, and only control words from a whitelist (Greek letters, ``\\frac``, ``\\left``,
  ...). Anything else is printed as escaped text instead, never interpreted.

The document needs amsmath, amssymb, graphicx, geometry and lmodern (texlive-latex-base and
texlive-latex-recommended).
"""

from __future__ import annotations

import math
import re
import unicodedata
from collections.abc import Iterable, Mapping
from typing import Any

_SPECIAL = {
    "\\": r"\textbackslash{}",
    "{": r"\{",
    "}": r"\}",
    "$": r"\$",
    "&": r"\&",
    "#": r"\#",
    "^": r"\textasciicircum{}",
    "_": r"\_",
    "%": r"\%",
    "~": r"\textasciitilde{}",
    "<": r"\textless{}",
    ">": r"\textgreater{}",
    "|": r"\textbar{}",
}

_GREEK = {
    "α": "alpha", "β": "beta", "γ": "gamma", "δ": "delta", "ε": "epsilon", "ζ": "zeta",
    "η": "eta", "θ": "theta", "ι": "iota", "κ": "kappa", "λ": "lambda", "μ": "mu", "ν": "nu",
    "ξ": "xi", "π": "pi", "ρ": "rho", "σ": "sigma", "τ": "tau", "υ": "upsilon", "φ": "phi",
    "χ": "chi", "ψ": "psi", "ω": "omega", "ϕ": "varphi", "ϑ": "vartheta", "Γ": "Gamma",
    "Δ": "Delta", "Θ": "Theta", "Λ": "Lambda", "Ξ": "Xi", "Π": "Pi", "Σ": "Sigma",
    "Υ": "Upsilon", "Φ": "Phi", "Ψ": "Psi", "Ω": "Omega",
}  # fmt: skip
_SYMBOLS = {
    "²": "^{2}", "³": "^{3}", "¹": "^{1}", "·": r"\cdot", "½": r"\tfrac{1}{2}", "×": r"\times",
    "ℓ": r"\ell", "∂": r"\partial", "−": "-", "≤": r"\leq", "≥": r"\geq", "≠": r"\neq",
    "≈": r"\approx", "→": r"\to", "←": r"\leftarrow", "⇒": r"\Rightarrow", "∞": r"\infty",
    "∫": r"\int", "∑": r"\sum", "√": r"\surd", "±": r"\pm", "∈": r"\in", "°": r"^{\circ}",
    "′": "'", "₀": "_{0}", "₁": "_{1}", "₂": "_{2}", "₃": "_{3}", "ᵢ": "_{i}", "ⱼ": "_{j}",
    "ₖ": "_{k}", "⁻": "^{-}", "∇": r"\nabla", "⋅": r"\cdot", "∝": r"\propto",
}  # fmt: skip
_TEXT_SYMBOLS = {
    "–": "--", "—": "---", "‘": "`", "’": "'", "“": "``", "”": "''", "…": r"\ldots{}",
    "\u00a0": "~", "•": r"\textbullet{}", "«": r"\guillemotleft{}", "»": r"\guillemotright{}",
}  # fmt: skip
#: Combining marks the engine writes after a letter (q̇, q̈) and their LaTeX accents.
_ACCENTS = {"\u0307": r"\dot", "\u0308": r"\ddot", "\u0302": r"\hat", "\u0304": r"\bar"}

#: Control words an equation may use: what sympy prints for the engine's expressions.
MATH_WORDS = frozenset(
    set(_GREEK.values())
    | {"varepsilon", "varrho", "varsigma", "ell", "imath", "jmath", "hbar", "infty", "partial"}
    | {"sin", "cos", "tan", "cot", "sec", "csc", "arcsin", "arccos", "arctan", "sinh", "cosh"}
    | {"tanh", "coth", "log", "ln", "exp", "sqrt", "frac", "dfrac", "tfrac", "left", "right"}
    | {"begin", "end", "text", "mathrm", "mathbf", "mathit", "operatorname", "boldsymbol"}
    | {"hat", "vec", "dot", "ddot", "bar", "tilde", "sum", "prod", "int", "quad", "qquad"}
    | {"times", "cdot", "cdots", "ldots", "pm", "mp", "leq", "geq", "neq", "approx", "equiv"}
    | {"lt", "gt", "le", "ge", "to", "mapsto", "circ", "displaystyle", "limits", "nabla"}
    | {"lvert", "rvert", "lVert", "rVert", "langle", "rangle", "lfloor", "rfloor", "lceil"}
    | {"rceil", "max", "min", "sgn", "mod", "operatorname", "Re", "Im", "in", "propto"}
    | {"Rightarrow", "leftarrow", "surd", "det"}
    | {"mathcal"}  # 𝓛, 𝒯, 𝒱, 𝓔, 𝒬: the energies when a parameter has their letter
)
#: Environments an equation may open (sympy's matrices, piecewise's cases).
MATH_ENVIRONMENTS = frozenset({"matrix", "pmatrix", "bmatrix", "smallmatrix", "cases", "array"})
_MATH_TOKEN = re.compile(r"\\([A-Za-z]+|.)|(.)", re.S)
_MAX_MATH = 60_000


def escape_text(text: str) -> str:
    """Free text as LaTeX that can only print: specials escaped, Greek letters and mathematical
    symbols as math, Latin-1 letters as they are (T1 fonts have them), anything else as its code
    point ``[U+1F600]`` (pdflatex has no glyph for it; an unknown character would stop it)."""
    out: list[str] = []
    chars = unicodedata.normalize("NFC", text)
    i = 0
    while i < len(chars):
        ch = chars[i]
        following = chars[i + 1] if i + 1 < len(chars) else ""
        if following in _ACCENTS:  # q̇ stays decomposed under NFC when no precomposed form exists
            base = ch if ch.isascii() and ch.isalpha() else _math_char(ch)
            if base is not None:
                out.append(f"${_ACCENTS[following]}{{{base}}}$")
                i += 2
                continue
        out.append(_text_char(ch))
        i += 1
    return "".join(out)


def _math_char(ch: str) -> str | None:
    if ch in _GREEK:
        return "\\" + _GREEK[ch]
    return _SYMBOLS.get(ch)


def _text_char(ch: str) -> str:
    if ch in _SPECIAL:
        return _SPECIAL[ch]
    if ch in ("\n", "\r", "\t"):
        return " "
    if 0x20 <= ord(ch) < 0x7F:
        return ch
    math_form = _math_char(ch)
    if math_form is not None:
        return f"${math_form}$"
    if ch in _TEXT_SYMBOLS:
        return _TEXT_SYMBOLS[ch]
    if 0xC0 <= ord(ch) <= 0xFF and ch not in "×÷":  # Latin-1 letters: inputenc + T1 print them
        return ch
    if unicodedata.category(ch) in ("Mn", "Cc", "Cf"):  # a stray combining mark or control
        return ""
    return "{\\ttfamily[U+" + f"{ord(ch):04X}" + "]}"


def safe_math(latex: str) -> bool:
    """Is ``latex`` (the inside of a math display) made of whitelisted control words and
    harmless characters, with balanced braces? (``\\\\`` and ``&`` are fine: matrix rows.)"""
    if len(latex) > _MAX_MATH or "^^" in latex:
        return False
    environments = re.findall(r"\\(?:begin|end)(?![A-Za-z])(\{[A-Za-z]*\})?", latex)
    if not all(name[1:-1] in MATH_ENVIRONMENTS for name in environments):
        return False
    depth = 0
    for match in _MATH_TOKEN.finditer(latex):
        word, ch = match.group(1), match.group(2)
        if word is not None:
            if word.isalpha() and word not in MATH_WORDS:
                return False
            if not word.isalpha() and word not in ",;:! \\{}|_%&#$^":
                return False  # spacing, escaped specials and row breaks only
            continue
        if ch in "%#$" or not (ch.isascii() and (ch.isprintable() or ch == "\n")):
            return False
        depth += {"{": 1, "}": -1}.get(ch, 0)
        if depth < 0:
            return False
    return depth == 0


_TEXT_ARGUMENT = re.compile(r"\\text\{([^{}]*)\}")
_BARE_UNDERSCORE = re.compile(r"(?<!\\)_")


def _text_underscores(latex: str) -> str:
    """``\\text{bob_1}`` -> ``\\text{bob\\_1}``: sympy prints a name inside \\text as it is,
    and an underscore there is a math subscript in text mode, which stops pdflatex."""

    def escaped(match: re.Match) -> str:
        return "\\text{" + _BARE_UNDERSCORE.sub(r"\\_", match.group(1)) + "}"

    return _TEXT_ARGUMENT.sub(escaped, latex)


def math_or_text(latex: str) -> str:
    """``$...$`` of ``latex`` when it is safe, else the same characters escaped as text."""
    latex = _text_underscores(latex)
    return f"${latex}$" if safe_math(latex) else r"{\ttfamily " + escape_text(latex) + "}"


def prose(text: str) -> str:
    """The engine's prose: text with ``$...$`` math; each math part kept only if safe."""
    parts = text.split("$")
    if len(parts) % 2 == 0:  # an unpaired $: treat all of it as text
        return escape_text(text)
    out = []
    for k, part in enumerate(parts):
        out.append(math_or_text(part) if k % 2 else escape_text(part))
    return "".join(out)


def _display(latex: str) -> str:
    latex = _text_underscores(latex)
    if safe_math(latex):
        return "\\begin{center}\\fiteq{" + latex + "}\\end{center}\n"
    return "\\begin{center}{\\ttfamily\\small " + escape_text(latex) + "}\\end{center}\n"


# ------------------------------------------------------------------------- free-body diagram

#: Longest side of the drawing (cm) and length of a force arrow (cm).
FIGURE_CM = 7.0
ARROW_CM = 1.3
_DOT_STEP_CM = 0.02


def _segment(x1: float, y1: float, x2: float, y2: float, dot: float = 0.05) -> str:
    """A straight line drawn as a dense row of dots (\\multiput of \\circle*): plain LaTeX's
    \\line takes only a few slopes, and TikZ or pict2e would need another 80 MB of TeX Live."""
    length = math.hypot(x2 - x1, y2 - y1)
    count = max(1, math.ceil(length / _DOT_STEP_CM))
    dx, dy = (x2 - x1) / count, (y2 - y1) / count
    return (
        f"\\multiput({x1:.4f},{y1:.4f})({dx:.5f},{dy:.5f}){{{count + 1}}}{{\\circle*{{{dot}}}}}\n"
    )


def _arrow(x: float, y: float, ux: float, uy: float, length: float, dot: float = 0.05) -> str:
    tip = (x + ux * length, y + uy * length)
    out = _segment(x, y, *tip, dot)
    for angle in (2.7, -2.7):  # the two barbs of the head, 155° back from the direction
        bx = ux * math.cos(angle) - uy * math.sin(angle)
        by = ux * math.sin(angle) + uy * math.cos(angle)
        out += _segment(*tip, tip[0] + 0.22 * bx, tip[1] + 0.22 * by, dot)
    return out


def fbd_picture(
    places: Mapping[str, tuple[float, float, float]],
    bodies: Iterable[str],
    forces: Iterable[tuple[str, str, tuple[float, float, float]]],
    links: Iterable[tuple[str, str]],
) -> str:
    """The free-body diagram at one state, projected on the x–y plane: O, every body as a dot
    with its name, each rod or string as a line (``links``: (body, point) pairs), and each
    applied force as an arrow of fixed length in its direction with its LaTeX label.

    ``places``: x, y, z of every point and body (m); ``forces``: (label, on, vector (N))."""
    places = dict(places)
    places.setdefault("O", (0.0, 0.0, 0.0))
    xs = [p[0] for p in places.values()]
    ys = [p[1] for p in places.values()]
    if not all(math.isfinite(v) for v in xs + ys):
        return ""
    span = max(max(xs) - min(xs), max(ys) - min(ys), 1e-9)
    scale = FIGURE_CM / span
    pad = ARROW_CM + 0.8
    x0, y0 = min(xs) * scale - pad, min(ys) * scale - pad
    width = (max(xs) - min(xs)) * scale + 2 * pad
    height = (max(ys) - min(ys)) * scale + 2 * pad

    def at(name: str) -> tuple[float, float]:
        p = places[name]
        return p[0] * scale, p[1] * scale

    out = ["\\setlength{\\unitlength}{1cm}\n"]
    out.append(f"\\begin{{picture}}({width:.3f},{height:.3f})({x0:.3f},{y0:.3f})\n")
    ox, oy = at("O")
    out.append(f"\\put({ox:.4f},{oy:.4f}){{\\circle{{0.18}}}}\n")
    out.append(f"\\put({ox + 0.15:.4f},{oy + 0.1:.4f}){{$O$}}\n")
    for body, point in links:
        if body in places and point in places:
            out.append(_segment(*at(point), *at(body), dot=0.04))
    for body in bodies:
        if body in places:
            x, y = at(body)
            out.append(f"\\put({x:.4f},{y:.4f}){{\\circle*{{0.22}}}}\n")
            out.append(
                f"\\put({x - 0.2:.4f},{y + 0.18:.4f}){{\\makebox(0,0)[rb]"
                f"{{\\small {escape_text(body)}}}}}\n"
            )
    for label, on, vector in forces:
        if on not in places:
            continue
        fx, fy = vector[0], vector[1]
        size = math.hypot(fx, fy)
        if not (math.isfinite(size) and size > 1e-12 * max(1.0, abs(vector[2]))):
            continue  # along z (out of the drawing) or zero at this state
        x, y = at(on)
        ux, uy = fx / size, fy / size
        out.append(_arrow(x, y, ux, uy, ARROW_CM))
        lx, ly = x + ux * (ARROW_CM + 0.35), y + uy * (ARROW_CM + 0.35)
        out.append(f"\\put({lx:.4f},{ly:.4f}){{\\makebox(0,0){{{math_or_text(label)}}}}}\n")
    out.append("\\end{picture}\n")
    return "".join(out)


# ---------------------------------------------------------------------------- the document

#: The notes' procedure, by step id: why each step comes where it does.
PROCEDURE = {
    "fbd": "Draw every force on every body; decide which are conservative (they enter through V) "
    "and which do work otherwise (they enter through the generalized forces).",
    "coordinates": "Count the degrees of freedom and choose generalized coordinates that absorb "
    "the holonomic constraints.",
    "kinematics": "Write each position in the coordinates and differentiate for the velocities.",
    "energy": "Kinetic energy T from the velocities, potential energy V from the heights, "
    "springs and potentials.",
    "forces": "Generalized forces Q_j of the non-conservative forces, by virtual work.",
    "lagrange": "Form L = T - V and apply Lagrange's equations to each coordinate.",
    "matrix": "Collect the equations as M(q) q'' = f(q, q', t) and solve for the accelerations.",
    "conserved": "Read off the conserved quantities: energy (or the Jacobi integral) and the "
    "momenta of cyclic coordinates.",
}

_PREAMBLE = r"""\documentclass[11pt]{article}
\usepackage[utf8]{inputenc}
\usepackage[T1]{fontenc}
\usepackage{lmodern}
\usepackage{amsmath,amssymb}
\usepackage{graphicx}
\usepackage[margin=2.2cm]{geometry}
\allowdisplaybreaks
\setlength{\parindent}{0pt}
\setlength{\parskip}{0.5em}
% An equation wider than the line is scaled down to fit it (a solved q'' can be long).
\newsavebox{\labeqbox}
\newcommand{\fiteq}[1]{\sbox{\labeqbox}{$\displaystyle #1$}%
  \ifdim\wd\labeqbox>\linewidth\resizebox{\linewidth}{!}{\usebox{\labeqbox}}%
  \else\usebox{\labeqbox}\fi}
"""


def _number(value: Any) -> str:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return escape_text(str(value))
    return f"${float(value):.6g}$".replace("e", r"\mathrm{e}")


def _values_table(scene: Mapping[str, Any]) -> str:
    units = scene.get("units") or {}
    rows = []
    for name, value in (scene.get("parameters") or {}).items():
        rows.append((name, value, units.get(name, "")))
    initial = scene.get("initial") or {}
    for q in scene.get("coordinates") or []:
        for key in (q, f"{q}_dot"):
            unit = units.get(q, "")
            if key != q and unit:
                unit = f"{unit}/s"
            rows.append((key, initial.get(key, 0.0), unit))
    if not rows:
        return ""
    body = "".join(
        f"{escape_text(name)} & {_number(value)} & {escape_text(unit)}\\\\\n"
        for name, value, unit in rows
    )
    return (
        "\\begin{center}\\begin{tabular}{lll}\n\\hline\nName & Value & Unit\\\\\n\\hline\n"
        + body
        + "\\hline\n\\end{tabular}\\end{center}\n"
    )


def latex_document(derivation: Mapping[str, Any], picture: str = "", source: str = "") -> str:
    """The article: title, summary, the values, the procedure, each step, the warnings.

    ``derivation`` is the JSON of POST /api/v1/derive; ``picture`` a `fbd_picture` (or "");
    ``source`` says where the scene came from (a built-in scene's id), printed as text."""
    scene = derivation.get("scene") or {}
    title = str(scene.get("title") or "Your system")
    out = [_PREAMBLE]
    out.append(f"\\title{{{escape_text(title)}}}\n\\author{{Lagrange Lab}}\n\\date{{}}\n")
    out.append("\\begin{document}\n\\maketitle\n")
    if scene.get("summary"):
        out.append(f"{escape_text(str(scene['summary']))}\n\n")
    if source:
        out.append(f"\\textit{{Scene:}} {escape_text(source)}.\n\n")
    coordinates = ", ".join(escape_text(str(q)) for q in scene.get("coordinates") or [])
    out.append(f"\\textit{{Generalized coordinates:}} {coordinates}.\n\n")
    out.append(_values_table(scene))
    steps = derivation.get("steps") or []
    out.append("\\section*{The procedure}\n\\begin{enumerate}\n")
    for step in steps:
        why = PROCEDURE.get(step.get("id", ""), "")
        out.append(f"\\item \\textbf{{{escape_text(step.get('title', ''))}}}. {escape_text(why)}\n")
    out.append("\\end{enumerate}\n")
    for step in steps:
        out.append(f"\\section{{{escape_text(step.get('title', ''))}}}\n")
        out.append(prose(step.get("text", "")) + "\n\n")
        if step.get("id") == "fbd" and picture:
            out.append("\\begin{center}\n" + picture + "\\end{center}\n")
            out.append(
                "\\begin{center}\\small The scene at its initial state, seen along $z$: "
                "each applied force as an arrow of fixed length in its direction.\\end{center}\n"
            )
        labels = step.get("labels") or []
        for k, line in enumerate(step.get("latex") or []):
            if k < len(labels) and labels[k]:
                out.append(f"\\textit{{{escape_text(labels[k])}}}\n")
            out.append(_display(line))
    warnings = derivation.get("warnings") or []
    if warnings:
        out.append("\\section*{Warnings}\n\\begin{itemize}\n")
        out += [f"\\item {prose(w)}\n" for w in warnings]
        out.append("\\end{itemize}\n")
    out.append("\\end{document}\n")
    return "".join(out)


# --------------------------------------------------------------------- from a compiled scene


def scene_picture(compiled: Any, fbd_data: Mapping[str, Any]) -> str:
    """The free-body diagram of a compiled scene (mechanics.numeric.CompiledScene) at its
    initial state with its default parameters; "" if it cannot be evaluated there."""
    import numpy as np

    from mechanics.numeric import evaluate

    spec = compiled.derivation.model.spec
    n = compiled.n
    initial = spec.initial
    q = np.array([[float(initial.get(c, 0.0))] for c in compiled.coordinates]).reshape(n, 1)
    qd = np.array([[float(initial.get(f"{c}_dot", 0.0))] for c in compiled.coordinates])
    qd = qd.reshape(n, 1)
    params = [float(spec.parameters[k]) for k in compiled.parameters]
    t = np.zeros(1)
    try:
        places = {
            name: tuple(float(v[0]) for v in evaluate(fn, t, q, qd, params))
            for name, fn in compiled.places.items()
        }
        forces = [
            (label, on, tuple(float(v[0]) for v in evaluate(fn, t, q, qd, params)))
            for label, _kind, on, fn in compiled.forces
        ]
    except (ArithmeticError, ValueError, TypeError):
        return ""
    links = []
    for entry in fbd_data.get("bodies") or []:
        for force in entry.get("constraint_forces") or []:
            if force.get("toward"):
                links.append((entry.get("body"), force["toward"]))
    bodies = [entry.get("body") for entry in fbd_data.get("bodies") or []]
    return fbd_picture(places, bodies, forces, links)


def document_of(scene_id: str | None, key: str | None) -> str:
    """The article of a built-in scene (by id) or of a posted spec (by its canonical JSON
    ``key``): a pool job for posted specs, since it compiles the scene with sympy."""
    import json

    from mechanics.derive import derivation_of_spec, derive_scene
    from mechanics.numeric import compiled_scene, compiled_spec

    if scene_id is not None:
        derivation = derive_scene(scene_id)
        compiled = compiled_scene(scene_id)
        source = f"built-in scene {scene_id}"
    else:
        derivation = derivation_of_spec(key).to_json()
        compiled = compiled_spec(json.loads(key))
        source = ""
    fbd = next((s for s in derivation["steps"] if s.get("id") == "fbd"), {})
    picture = scene_picture(compiled, fbd.get("data") or {})
    return latex_document(derivation, picture, source)
