// The catalog's drawings: each scene at its initial configuration (SVG), with a faint line showing
// where its first second of motion takes it. One request brings every scene's spec and short run
// (GET /api/v1/scenes/catalog), instead of two per scene.
import { getJSON } from "./api.js";
import { SceneGeometry } from "./geometry.js";
import { toSVG } from "./render.js";
import { sceneShapes } from "./shapes.js";
import { View } from "./view.js";

const W = 240, H = 150;

function drawOne(svg, entry) {
  try {
    if (!entry || !entry.run) throw new Error("no run");
    const geom = new SceneGeometry(entry.spec, entry.run);
    const view = new View(W, H, geom.is3D).fit(geom.extent(), geom.is3D ? 10 : 22);
    svg.innerHTML = toSVG(sceneShapes(geom, view, 0, { radius: 7, path: true, axes: false }));
    svg.dataset.ready = "1";
  } catch (err) {
    svg.dataset.ready = "error";
    svg.innerHTML = `<text x="${W / 2}" y="${H / 2}" text-anchor="middle" fill="#868e96" font-size="12">no drawing</text>`;
  }
}

export async function drawThumbnails() {
  const svgs = [...document.querySelectorAll("svg[data-thumb]")];
  let entries = [];
  try {
    entries = await getJSON("/api/v1/scenes/catalog");
  } catch (err) {
    entries = [];
  }
  const byId = new Map(entries.map((e) => [e.id, e]));
  for (const svg of svgs) drawOne(svg, byId.get(svg.dataset.thumb));
}
