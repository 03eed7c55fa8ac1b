"""The canvas's scale bar ("1 m") never covers a body (lecture-mode play-test: at 25 px, the
Atwood machine's label sat on the lower block; round 2: on the lecture canvas the lower block
reached the corner chosen at the start only at t = 0.89 s). shapes.js runs in node on a real run."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.scenes import load_scene, scene_ids

ROOT = Path(__file__).resolve().parents[2]
NODE = shutil.which("node")
client = TestClient(app)

#: The shapes of frame 0 at a 1024×768 lecture canvas's size, with lecture-size labels; then
#: the scale bar's label box and each body's disc on the screen.
DRAW = """
import { readFileSync } from "node:fs";
const root = process.argv[1];
const { SceneGeometry } = await import(root + "/static/js/geometry.js");
const { View } = await import(root + "/static/js/view.js");
const { sceneShapes } = await import(root + "/static/js/shapes.js");
const d = JSON.parse(readFileSync(0, "utf8"));
const g = new SceneGeometry(d.spec, d.result);
const view = new View(d.w, d.h, g.is3D).fit(g.extent(), d.pad);
const font = 25;
const frames = [];
for (let i = 0; i < g.n; i += d.every) {
  const shapes = sceneShapes(g, view, i, { radius: 16, trail: 0, scaleBar: true, font });
  const bar = shapes.find((s) => s.t === "text" && / c?m$/.test(s.text) && s.size === font - 1);
  const bodies = g.bodies.map((b) =>
    [b.name, ...view.project(g.at(b.name, i)).slice(0, 2), 16 * g.size[b.name]]);
  const line = shapes.find((s) => s.t === "poly" && s.color === "#868e96" && s.pts.length === 4);
  frames.push({ i, bar: bar ?? null, left: line ? line.pts[0][0] : null, bodies });
}
console.log(JSON.stringify({ frames, w: view.w, h: view.h, is3D: g.is3D }));
"""


def draw(
    scene_id: str, w: int, h: int, *, t_end: float = 1, fps: int = 20, pad: int = 24, every: int = 4
) -> dict:
    """Frames 0, every, 2·every, … of a run drawn on a w×h canvas fitted with `pad` px."""
    run = {"scene_id": scene_id, "t_end": t_end, "fps": fps}
    r = client.post("/api/v1/simulate", json=run)
    assert r.status_code == 200, r.text
    data = json.dumps(
        {
            "spec": load_scene(scene_id),
            "result": r.json(),
            "w": w,
            "h": h,
            "pad": pad,
            "every": every,
        }
    )
    out = subprocess.run(
        [NODE, "--input-type=module", "-e", DRAW, str(ROOT)],
        input=data,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


@pytest.mark.skipif(NODE is None, reason="node is not installed")
@pytest.mark.parametrize("scene_id", scene_ids())
@pytest.mark.parametrize("size", [(470, 360), (1000, 520)])
def test_the_scale_bar_label_covers_no_body(scene_id, size):
    assert_clear(draw(scene_id, *size))


#: The animation's canvas in lecture mode (measured in Chromium: 372×246 at 1024×768, 481×317 at
#: 1280×720), fitted with the page's 34 px (draw.js PAD), and the page's default run (10 s, 30
#: samples a second).
LECTURE_CANVASES = [(372, 246), (481, 317)]


@pytest.mark.skipif(NODE is None, reason="node is not installed")
@pytest.mark.parametrize("scene_id", scene_ids())
@pytest.mark.parametrize("size", LECTURE_CANVASES)
def test_the_scale_bar_keeps_one_corner_clear_of_every_body_for_a_whole_lecture_run(scene_id, size):
    d = draw(scene_id, *size, t_end=10, fps=30, pad=34, every=1)
    assert_clear(d)
    if d["is3D"]:
        return
    # one place for the run: it does not jump from frame to frame, unless no place it took was
    # free for the whole run (a chaotic double pendulum's bob sweeps a small canvas)
    places = {(f["left"], tuple(f["bar"]["at"]), f["bar"]["text"]) for f in d["frames"]}
    if len(places) > 1:
        for left, at, text in places:  # the bar and its label
            box = (left, *label_box(at, 24, text)[1:])
            assert any(covers(box, f["bodies"]) for f in d["frames"]), at
    if scene_id == "atwood_machine":  # the play-test's case: a place is free all the run
        assert len(places) == 1


def label_box(at, size, text) -> tuple:
    """The label's box: 0.6 em per character wide, an em tall above its baseline."""
    x, y = at
    return (x, y - size, x + 0.6 * size * len(text), y + 3)


def covers(box, bodies) -> bool:
    """Whether a body's disc (a block is drawn in it) reaches into `box`."""
    return any(
        not (box[2] < bx - r or box[0] > bx + r or box[3] < by - r or box[1] > by + r)
        for _, bx, by, r in bodies
    )


def assert_clear(d: dict) -> None:
    for frame in d["frames"]:  # the bodies move
        bar = frame["bar"]
        if d["is3D"]:
            assert bar is None  # a perspective view has no one scale
            continue
        assert bar is not None
        x, y = bar["at"]
        # the label's box: 0.6 em per character wide, an em tall above its baseline
        box = (x, y - bar["size"], x + 0.6 * bar["size"] * len(bar["text"]), y + 3)
        assert 0 <= box[0] and box[2] <= d["w"] and 0 <= box[1] and box[3] <= d["h"]
        for name, bx, by, r in frame["bodies"]:  # r: the body's disc (a block is drawn in it)
            clear = box[2] < bx - r or box[0] > bx + r or box[3] < by - r or box[1] > by + r
            assert clear, (frame["i"], name, (bx, by), bar)
