"""The canvas's scale bar ("1 m") never covers a body (lecture-mode play-test: at 25 px, the
Atwood machine's label sat on the lower block). shapes.js runs in node on a real run."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.scenes import load_scene, scene_ids

ROOT = Path(__file__).resolve().parent.parent
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
const view = new View(d.w, d.h, g.is3D).fit(g.extent(), 24);
const font = 25;
const frames = [];
for (let i = 0; i < g.n; i += 4) {
  const shapes = sceneShapes(g, view, i, { radius: 16, trail: 0, scaleBar: true, font });
  const bar = shapes.find((s) => s.t === "text" && / c?m$/.test(s.text) && s.size === font - 1);
  const bodies = g.bodies.map((b) =>
    [b.name, ...view.project(g.at(b.name, i)).slice(0, 2), 16 * g.size[b.name]]);
  frames.push({ i, bar: bar ?? null, bodies });
}
console.log(JSON.stringify({ frames, w: view.w, h: view.h, is3D: g.is3D }));
"""


def draw(scene_id: str, w: int, h: int) -> dict:
    r = client.post("/api/v1/simulate", json={"scene_id": scene_id, "t_end": 1, "fps": 20})
    assert r.status_code == 200, r.text
    data = json.dumps({"spec": load_scene(scene_id), "result": r.json(), "w": w, "h": h})
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
    d = draw(scene_id, *size)
    for frame in d["frames"]:  # every 4th frame of the first second: the bodies move
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
