"""The house keeps its shape: the engine's stages import only the stages above them, modules and
functions stay small, and test files are named after what they test (issue 25, and
../shared/ARCHITECTURE.md).

The pipeline is `spec ← model ← derivation ← numerics ← {simulation, equilibria, answers} ←
assignments ← export ← serving`, one package of mechanics/ per stage. What breaks a rule today
is listed in `ALLOWED_*` below, one line each: the lists only shrink. A new module, function or
import that breaks a rule fails here with the rule it breaks.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
ENGINE = ROOT / "mechanics"

#: The stages from the top of the pipeline down; a stage may import only itself and those before.
ORDER = (
    "spec",
    "model",
    "derivation",
    "numerics",
    "run",
    "assignments",
    "export",
    "serving",
    "api",
)
#: simulation, equilibria and answers are siblings below numerics: none imports another.
SIBLINGS = {"simulation": "run", "equilibria": "run", "answers": "run"}

#: Every engine module lives in the package of its stage (mechanics/<stage>/...), but the facade.
STAGES = {*ORDER, *SIBLINGS} - {"run"}


# fmt: off
#: Engine modules that import the app (none may).
ALLOWED_APP_IMPORTS: set[str] = set()
#: Imports against the pipeline's direction today (importer -> imported), to be removed by the cut.
ALLOWED_UPWARD: set[tuple[str, str]] = {
    ("assignments.grading", "budget"),
    ("assignments.grading", "cache"),
    ("assignments.variants", "cache"),
    ("derive", "cache"),
    ("native", "cache"),
}
#: Modules over 600 lines today.
ALLOWED_LONG_MODULES: set[str] = {
    "check",
    "equilibria",
    "expr",
    "model",
    "precision",
    "predict",
    "provenance",
    "simulate",
    "steps.fbd",
}
#: Functions over 80 lines today ("module:function").
ALLOWED_LONG_FUNCTIONS: set[str] = {
    "answers:read_answer",
    "answers:to_convention_mapped",
    "check:_eom",
    "divergence:classify_divergence",
    "equilibria:_cartesian_linearization",
    "equilibria:_classify",
    "equilibria:equilibria",
    "integrators:integrate",
    "jscode:live_module",
    "model:build_model",
    "numeric:compile_derivation",
    "precision:work_precision",
    "predict:predict",
    "provenance:kinetic_origins",
    "simulate:_accuracy_warning",
    "simulate:simulate_compiled",
    "spec_names:check_names",
    "steps.conserved:conserved_quantities",
    "steps.fbd:_sliding_ends",
    "steps.fbd:constraint_forces",
    "steps.fbd:free_body_diagram",
}
#: Classes over 400 lines today ("module:Class").
ALLOWED_LONG_CLASSES: set[str] = {
    "check:_Judge",
}
#: Modules over 400 lines today whose docstring does not yet say why.
ALLOWED_UNEXPLAINED: set[str] = {
    "answers",
    "divergence",
    "export_latex",
    "integrators",
    "native",
    "numeric",
    "pool",
    "spec",
    "steps.conserved",
    "stops",
}
#: Test files still named after a review round.
ALLOWED_ROUND_NAMES: set[str] = set()
# fmt: on

ROUND_NAME = re.compile(r"([0-9]|trust|round|leftover|polish)")


def _modules() -> dict[str, Path]:
    """Every engine module by its dotted name below `mechanics` ("steps.fbd", "cache", ...)."""
    found = {}
    for path in sorted(ENGINE.rglob("*.py")):
        parts = path.relative_to(ENGINE).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if parts:
            found[".".join(parts)] = path
    return found


def _stage(name: str) -> str | None:
    first = name.split(".")[0]
    return first if first in STAGES else None


def _imported(path: Path, name: str) -> set[str]:
    """The engine modules `path` imports, at the top or lazily inside a function."""
    tree = ast.parse(path.read_text())
    package = name.split(".")[:-1] if path.name != "__init__.py" else name.split(".")
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("mechanics.")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - node.level + 1]
                target = ".".join([*base, node.module] if node.module else base)
                out.add("mechanics." + target if target else "mechanics")
            elif node.module and node.module.startswith("mechanics"):
                out.add(node.module)
                out |= {f"{node.module}.{a.name}" for a in node.names}
    modules = _modules()
    return {m.removeprefix("mechanics.") for m in out if m.removeprefix("mechanics.") in modules}


def _rank(stage: str) -> int:
    return ORDER.index(SIBLINGS.get(stage, stage))


def _upward_imports() -> set[tuple[str, str]]:
    bad = set()
    for name, path in _modules().items():
        mine = _stage(name)
        if mine is None:
            continue
        for other in _imported(path, name):
            theirs = _stage(other)
            if theirs is None or theirs == mine:
                continue
            upward = _rank(theirs) > _rank(mine)
            sideways = theirs in SIBLINGS and mine in SIBLINGS
            if upward or sideways:
                bad.add((name, other))
    return bad


def test_every_engine_module_has_a_stage():
    """A new module says where it belongs: in the package of its stage."""
    assert [name for name in _modules() if _stage(name) is None] == []


def _imports_app(path: Path) -> bool:
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            names = [node.module or ""]
        else:
            continue
        if any(n == "app" or n.startswith("app.") for n in names):
            return True
    return False


def test_the_engine_never_imports_the_app():
    found = {str(p.relative_to(ROOT)) for p in ENGINE.rglob("*.py") if _imports_app(p)}
    assert sorted(found - ALLOWED_APP_IMPORTS) == [], "mechanics/ must never import app/"
    assert sorted(ALLOWED_APP_IMPORTS - found) == [], "fixed: remove from ALLOWED_APP_IMPORTS"


def test_stages_import_only_the_stages_above_them():
    found = _upward_imports()
    assert sorted(found - ALLOWED_UPWARD) == [], "imports against the pipeline's direction"
    assert sorted(ALLOWED_UPWARD - found) == [], "fixed: remove these from ALLOWED_UPWARD"


def _lines(node: ast.AST) -> int:
    return node.end_lineno - node.lineno + 1


def _sizes() -> tuple[set[str], set[str], set[str]]:
    long_modules, long_functions, long_classes = set(), set(), set()
    for name, path in _modules().items():
        text = path.read_text()
        if len(text.splitlines()) > 600:
            long_modules.add(name)
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and _lines(node) > 80:
                long_functions.add(f"{name}:{node.name}")
            elif isinstance(node, ast.ClassDef) and _lines(node) > 400:
                long_classes.add(f"{name}:{node.name}")
    return long_modules, long_functions, long_classes


@pytest.mark.parametrize(
    ("kind", "index", "allowed"),
    [
        ("module over 600 lines", 0, ALLOWED_LONG_MODULES),
        ("function over 80 lines", 1, ALLOWED_LONG_FUNCTIONS),
        ("class over 400 lines", 2, ALLOWED_LONG_CLASSES),
    ],
)
def test_engine_pieces_stay_small(kind, index, allowed):
    found = _sizes()[index]
    assert sorted(found - allowed) == [], f"new {kind}: split it by what it answers"
    assert sorted(allowed - found) == [], f"no longer a {kind}: remove it from the allow-list"


def test_a_module_over_400_lines_says_why():
    """ARCHITECTURE.md: over 400 lines only with a one-line reason in the module's docstring (one
    that says how many "lines" and why)."""
    silent = set()
    for name, path in _modules().items():
        text = path.read_text()
        if 400 < len(text.splitlines()) and name not in ALLOWED_LONG_MODULES:
            doc = ast.get_docstring(ast.parse(text)) or ""
            if "lines" not in doc.lower():
                silent.add(name)
    assert sorted(silent - ALLOWED_UNEXPLAINED) == [], "say in the docstring why it is so long"
    assert sorted(ALLOWED_UNEXPLAINED - silent) == [], "explained: remove from the allow-list"


def test_test_files_are_named_after_a_concept():
    """No digits, 'trust', 'round', 'leftovers' or 'polish' in a test file's name (2d/3d and a11y
    are concepts); the round that found a bug goes in the test's docstring."""
    named = set()
    for path in (ROOT / "tests").rglob("test_*.py"):
        stem = re.sub(r"a11y|[23]d", "", path.stem.removeprefix("test_"))
        if ROUND_NAME.search(stem):
            named.add(str(path.relative_to(ROOT)))
    assert sorted(named - ALLOWED_ROUND_NAMES) == [], "name the test file after its concept"
    assert sorted(ALLOWED_ROUND_NAMES - named) == [], "renamed: remove from ALLOWED_ROUND_NAMES"
