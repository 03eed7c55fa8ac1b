"""A scene's spec as TOML, a run's trajectory as CSV: the files a student takes away.

TOML is written here, not by a library: the standard library reads TOML (tomllib) but does not
write it, and a spec's shape is small (scalars, lists, tables, arrays of tables). Every float is
written with ``repr`` (the shortest text that reads back as the same double), so
``tomllib.loads(spec_toml(spec)) == spec`` holds exactly, and every string is a TOML basic string
with its quotes, backslashes and control characters escaped.

    >>> print(spec_toml({"title": 'A "quoted" pendulum', "parameters": {"l": 0.1}}))
    title = "A \\"quoted\\" pendulum"
    parameters = { l = 0.1 }
    <BLANKLINE>
"""

from __future__ import annotations

import io
import json
import math
import re
from collections.abc import Iterable, Mapping
from typing import Any

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")
_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f"}
_ESCAPES["\r"] = "\\r"
#: Every character str.splitlines() breaks a line at: a CSV reader, an editor or pandas may too.
LINE_BREAKS = frozenset("\n\r\v\f\x1c\x1d\x1e\x85\u2028\u2029")


class TomlError(ValueError):
    """A value TOML cannot hold (None inside a list, a type that is not data)."""


def toml_string(text: str) -> str:
    """A TOML basic string: quotes, backslashes and control characters escaped, the rest as is."""
    out = []
    for ch in text:
        if ch in _ESCAPES:
            out.append(_ESCAPES[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def toml_key(key: str) -> str:
    return key if _BARE_KEY.match(key) else toml_string(key)


def toml_value(value: Any) -> str:
    """One value inline: arrays as [...], tables as { ... }."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return toml_string(value)
    if isinstance(value, Mapping):
        items = [f"{toml_key(k)} = {toml_value(v)}" for k, v in value.items() if v is not None]
        return "{ " + ", ".join(items) + " }" if items else "{}"
    if isinstance(value, list | tuple):
        if any(v is None for v in value):
            raise TomlError("TOML has no null: a list holds None")
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise TomlError(f"TOML cannot hold a {type(value).__name__}")


def spec_toml(spec: Mapping[str, Any]) -> str:
    """The spec as a TOML document: top-level keys first, then each list of tables (bodies,
    springs, ...) as ``[[name]]`` sections; nested tables inside them are written inline."""
    head, sections = [], []
    for key, value in spec.items():
        if value is None:
            continue
        if _is_table_array(value):
            for table in value:
                lines = [f"{toml_key(k)} = {toml_value(v)}" for k, v in table.items()]
                sections.append(f"\n[[{toml_key(key)}]]\n" + "".join(f"{x}\n" for x in lines))
        else:
            head.append(f"{toml_key(key)} = {toml_value(value)}\n")
    return "".join(head) + "".join(sections)


def _is_table_array(value: Any) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, Mapping) for v in value)


# ---------------------------------------------------------------------------- trajectory as CSV

ENERGY_COLUMNS = ("T", "V", "E", "W_nc", "W_drive")


def trajectory_columns(run: Mapping[str, Any], units: Mapping[str, str]) -> list[tuple[str, str]]:
    """(column, unit) in order: t, each q, each q̇, the energies. A coordinate's unit is the
    scene's (``units``); energies are in J when the scene declares units at all (SI), else ""."""
    columns = [("t", "s")]
    for q in run["q"]:
        columns.append((q, units.get(q, "")))
    for q in run["q_dot"]:
        unit = units.get(q, "")
        columns.append(
            (f"{q}_dot", f"{unit}/s" if unit and unit != "1" else ("1/s" if unit else ""))
        )
    energy = "J" if units else ""
    columns += [(name, energy) for name in ENERGY_COLUMNS if name in run.get("energy", {})]
    return columns


def _series(run: Mapping[str, Any], column: str) -> list[Any]:
    if column == "t":
        return run["t"]
    if column in run["q"]:
        return run["q"][column]
    if column.endswith("_dot") and column[:-4] in run["q_dot"]:
        return run["q_dot"][column[:-4]]
    return run["energy"][column]


def trajectory_csv(
    run: Mapping[str, Any], units: Mapping[str, str], comments: Iterable[str] = ()
) -> str:
    """The run as CSV: ``#`` comment lines (what was run, its stats: pandas' ``comment="#"``
    skips them), a header ``name [unit]``, one row per sample. Numbers are written
    with ``repr`` (they read back as the same doubles); a missing value (null) as ``nan``."""
    columns = trajectory_columns(run, units)
    out = io.StringIO()
    for line in comments:
        out.write("# " + defused(one_line(line)) + "\n")
    out.write(",".join(_header_cell(name, unit) for name, unit in columns) + "\n")
    series = [_series(run, name) for name, _ in columns]
    for row in zip(*series, strict=True):
        out.write(",".join("nan" if v is None else repr(float(v)) for v in row) + "\n")
    return out.getvalue()


def json_text(value: Any) -> str:
    """``value`` as JSON on one line that reads back equal: U+0085, U+2028 and U+2029, which
    JSON keeps raw and str.splitlines() breaks at, written as \\u escapes (the others are
    control characters, which JSON escapes itself)."""
    text = json.dumps(value, ensure_ascii=False)
    return "".join(f"\\u{ord(ch):04x}" if ch in LINE_BREAKS else ch for ch in text)


def one_line(text: str) -> str:
    """``text`` with each line break (`LINE_BREAKS`, U+2028 and U+0085 too) as a space: a comment
    that a title or a stop message split would start a data row in the middle of the header."""
    return "".join(" " if ch in LINE_BREAKS else ch for ch in text)


#: What makes a spreadsheet (Excel, LibreOffice, Google Sheets) read a cell as a formula: a title
#: or a stop message is someone's text, and ``x,=HYPERLINK("http://…")`` in it would be a cell
#: that runs when the CSV is opened (OWASP "CSV injection").
#: What starts a formula, fullwidth forms included (a spreadsheet may fold them to ASCII).
FORMULA_START = frozenset("=+-@\t\r＝＋－＠")
#: What a spreadsheet may split a line's cells at: a comma, or a semicolon (the separator of most
#: European locales, and one LibreOffice guesses). A tab starts a formula instead (OWASP), so a
#: cell after a tab is defused as one.
_CELL_BREAK = re.compile(r"([,;])")
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?|[+-]?(inf|nan)", re.IGNORECASE)


def defused(text: str) -> str:
    """``text`` with each of its cells that a spreadsheet would run as a formula prefixed with
    ``'`` (the spreadsheets' own mark for "this is text"); a number such as -1.5 is left as it is,
    and so is every other cell. Cells are cut at every separator a spreadsheet may use (comma or
    semicolon), since the reader's locale picks it. A cell's leading spaces and opening quote
    are looked through: ``"=1+1"`` is the cell =1+1 to a CSV reader."""
    return "".join(_defused_cell(part) for part in _CELL_BREAK.split(text))


def _defused_cell(cell: str) -> str:
    start = len(cell) - len(cell.lstrip(' "'))
    rest = cell[start:]
    if rest[:1] in FORMULA_START and not _NUMBER.fullmatch(rest.strip().strip('"')):
        return cell[:start] + "'" + rest
    return cell


def stats_lines(stats: Mapping[str, Any], prefix: str = "stats.") -> list[str]:
    """A run's stats flattened as ``key: value`` lines (nested dicts with dotted keys)."""
    lines = []
    for key, value in stats.items():
        if isinstance(value, Mapping):
            lines += stats_lines(value, f"{prefix}{key}.")
        else:
            lines.append(f"{prefix}{key}: {value}")
    return lines


def _header_cell(name: str, unit: str) -> str:
    """``name [unit]`` as one CSV cell whatever the unit says: a spec's unit is someone's text,
    and a line break, a comma, a quote or a '#' in it would add rows, split columns or hide the
    rest of the header from a reader that skips '#' comments. Those characters are replaced."""
    cell = f"{name} [{unit}]" if unit else name
    return "".join(" " if ch in '\t,"#' or ord(ch) < 32 else ch for ch in one_line(cell))
