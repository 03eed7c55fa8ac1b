// The catalog's drawings: each scene at its initial configuration (SVG), with a faint line showing
// where its first second of motion takes it.
import { getJSON, postJSON } from "./api.js";
import { SceneGeometry } from "./geometry.js";
import { toSVG } from "./render.js";
import { sceneShapes } from "./shapes.js";
import { View } from "./view.js";

const W = 240, H = 150;

async function drawOne(svg) {
  const id = svg.dataset.thumb;
  try {
    const [{ spec }, run] = await Promise.all([
      getJSON(`/api/v1/scenes/${id}`),
      postJSON("/api/v1/simulate", { scene_id: id, t_end: 1, fps: 30, check_sensitivity: false }),
    ]);
    const geom = new SceneGeometry(spec, run);
    const view = new View(W, H, geom.is3D).fit(geom.extent(), geom.is3D ? 10 : 22);
    svg.innerHTML = toSVG(sceneShapes(geom, view, 0, { radius: 7, path: true, axes: false }));
    svg.dataset.ready = "1";
  } catch (err) {
    svg.dataset.ready = "error";
    svg.innerHTML = `<text x="${W / 2}" y="${H / 2}" text-anchor="middle" fill="#868e96" font-size="12">no drawing</text>`;
  }
}

export async function drawThumbnails() {
  const queue = [...document.querySelectorAll("svg[data-thumb]")];
  const worker = async () => { while (queue.length) await drawOne(queue.shift()); };
  await Promise.all([worker(), worker(), worker()]);
}
