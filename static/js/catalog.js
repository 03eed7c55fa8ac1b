// The catalog's small drawings: each scene at its initial configuration.
import { postJSON } from "./api.js";
import { Stage } from "./draw.js";

export async function drawThumbnails() {
  for (const canvas of document.querySelectorAll("canvas[data-thumb]")) {
    const id = canvas.dataset.thumb;
    try {
      const [{ spec }, run] = await Promise.all([
        fetch(`/api/v1/scenes/${id}`).then((r) => r.json()),
        postJSON("/api/v1/simulate", { scene_id: id, t_end: 1.5, fps: 20, check_sensitivity: false }),
      ]);
      const stage = new Stage(canvas, spec);
      stage.setResult(run);
      stage.draw(run.t.length - 1);
      canvas.dataset.ready = "1";
    } catch (err) {
      canvas.dataset.ready = "error";
    }
  }
}
