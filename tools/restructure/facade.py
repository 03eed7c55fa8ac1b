"""Write mechanics/api.py from what app/ imports of the engine, and point app/ at it.

The app reaches the engine through one facade (ARCHITECTURE.md rule 1), plus mechanics.serving.
Run from the repository root after engine_packages.py. A test that monkeypatches an engine
module's constant the app reads (MAX_WALL_TIME) must then patch mechanics.api's name too."""

from __future__ import annotations

import ast
import subprocess
from collections import defaultdict
from pathlib import Path

ROOT = Path.cwd()
SKIP = ("mechanics.serving", "mechanics.api")

HEADER = '''"""The engine as the app sees it: one facade, so app/ depends on what the engine
offers, not on where each piece lives (ARCHITECTURE.md, rule 1). app/ imports from here and from
mechanics.serving only; tests/test_layers.py holds that.

Grouped by stage: the spec and its scenes, the derivation, numerics, runs, equilibria, answers,
exports and assignments. A name is added here when the app needs it.
"""

'''


def _engine_imports(tree: ast.AST):
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            mod = node.module
            if mod.startswith("mechanics.") and not mod.startswith(SKIP):
                yield node


def collect() -> dict[str, set[tuple[str, str | None]]]:
    wanted: dict[str, set] = defaultdict(set)
    for path in sorted((ROOT / "app").rglob("*.py")):
        for node in _engine_imports(ast.parse(path.read_text())):
            for alias in node.names:
                wanted[node.module].add(alias.name)
    return wanted


def write_api(wanted) -> list[str]:
    seen: dict[str, str] = {}
    lines = [HEADER, "from __future__ import annotations", ""]
    exported = []
    for module in sorted(wanted):
        names = sorted(wanted[module])
        for n in names:
            if n in seen and seen[n] != module:
                raise SystemExit(f"{n} from both {seen[n]} and {module}: alias it by hand")
            seen[n] = module
        lines.append(f"from {module} import {', '.join(names)}")
        exported += names
    lines += ["", "__all__ = [", *[f'    "{n}",' for n in sorted(set(exported))], "]", ""]
    (ROOT / "mechanics" / "api.py").write_text("\n".join(lines))
    return exported


def point_app_at_api() -> None:
    for path in sorted((ROOT / "app").rglob("*.py")):
        source = path.read_text()
        tree = ast.parse(source)
        nodes = sorted(_engine_imports(tree), key=lambda n: n.lineno, reverse=True)
        if not nodes:
            continue
        lines = source.splitlines(keepends=True)
        for node in nodes:
            first, last = node.lineno - 1, node.end_lineno - 1
            indent = lines[first][: len(lines[first]) - len(lines[first].lstrip())]
            names = ", ".join(
                a.name if a.asname is None else f"{a.name} as {a.asname}" for a in node.names
            )
            tail = lines[last][node.end_col_offset :]
            lines[first : last + 1] = [f"{indent}from mechanics.api import {names}{tail}"]
        path.write_text("".join(lines))


if __name__ == "__main__":
    exported = write_api(collect())
    point_app_at_api()
    subprocess.run(["git", "add", "mechanics/api.py"], cwd=ROOT, check=True)
    subprocess.run(["ruff", "check", "--fix", "-q", "app", "mechanics/api.py"], cwd=ROOT)
    subprocess.run(["ruff", "format", "-q", "app", "mechanics/api.py"], cwd=ROOT)
    print(f"mechanics/api.py exports {len(set(exported))} names")
