// The animation canvas: the scene at one sample with a fading trail, sharp on any screen (device
// pixel ratio), planar scenes in the x–y plane, 3-D ones in a perspective view turned by dragging.
// A run that travels far (an Atwood machine, a block down a slope) gets a camera that pulls back.
import { SceneGeometry } from "./geometry.js";
import { drawCanvas } from "./render.js";
import { sceneShapes } from "./shapes.js";
import { View } from "./view.js";

const ASPECT = 0.66; // height / width, for 3-D scenes and tall planar ones

export class Stage {
  constructor(canvas) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d");
    this.geom = null;
    this.frame = 0;
    this.yaw = 0.55;
    this.pitch = 0.4;
    this.canvas.addEventListener("pointerdown", (e) => this.#drag(e));
    new ResizeObserver(() => this.#resize()).observe(canvas);
    this.#resize();
  }

  #resize() {
    const w = Math.max(200, Math.round(this.canvas.clientWidth || 640));
    const h = Math.round(w * (this.aspect || ASPECT));
    const dpr = window.devicePixelRatio || 1;
    if (this.canvas.width === Math.round(w * dpr) && this.cssW === w && this.cssH === h) return;
    this.cssW = w;
    this.cssH = h;
    this.canvas.width = Math.round(w * dpr);
    this.canvas.height = Math.round(h * dpr);
    this.canvas.style.aspectRatio = `${w} / ${h}`;
    this.dpr = dpr;
    if (this.geom) { this.#fit(); this.draw(this.frame); }
  }

  setResult(spec, result, parameters) {
    this.geom = new SceneGeometry(spec, result, parameters);
    this.canvas.dataset.view = this.geom.is3D ? "3d" : "2d";
    // A flat scene (a block on a floor) gets a flatter canvas, not a tall empty one.
    let aspect = ASPECT;
    if (!this.geom.is3D) {
      const pts = this.geom.extent();
      const span = (k) => Math.max(...pts.map((p) => p[k])) - Math.min(...pts.map((p) => p[k]));
      aspect = Math.min(ASPECT, Math.max(0.42, span(1) / Math.max(span(0), 1e-9) + 0.2));
    }
    if (aspect !== this.aspect) {
      this.aspect = aspect;
      this.cssW = 0; // force a resize
      this.#resize();
    }
    this.#fit();
  }

  #firstSecond() {
    const t = this.geom.result.t;
    const idx = [];
    for (let i = 0; i < t.length && t[i] - t[0] <= 1.0; i++) idx.push(i);
    return idx;
  }

  #fit() {
    const g = this.geom;
    this.view = new View(this.cssW, this.cssH, g.is3D);
    this.view.yaw = this.yaw;
    this.view.pitch = this.pitch;
    const pad = g.is3D ? 18 : 34;
    this.view.fit(g.extent(), pad);
    this.follow = false;
    if (!g.is3D) {
      const early = new View(this.cssW, this.cssH).fit(g.extent(this.#firstSecond()), pad);
      // Travels far compared with its first second: follow it instead of shrinking it to a dot.
      if (early.scale > 6 * this.view.scale) {
        this.follow = true;
        this.closest = early.scale;
      }
    }
  }

  draw(i) {
    const g = this.geom;
    if (!g) return;
    this.frame = Math.max(0, Math.min(g.n - 1, i));
    if (this.follow) {
      this.view.fit(g.extent([this.frame]), 34);
      this.view.scale = Math.min(this.view.scale, this.closest);
    }
    const { ctx, canvas } = this;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    const font = document.body.classList.contains("lecture") ? 17 : 12;
    const shapes = sceneShapes(g, this.view, this.frame, {
      radius: font - 1, trail: g.is3D ? 3 : 1.5, scaleBar: true, font,
    });
    const note = g.is3D ? "drag to turn the view" : this.follow ? "camera follows the motion" : "";
    if (note) shapes.push({ t: "text", at: [10, 8 + font], text: note, color: "#868e96", size: font });
    drawCanvas(ctx, shapes);
    canvas.dataset.frame = String(this.frame);
  }

  #drag(e) {
    if (!this.geom || !this.geom.is3D) return;
    e.preventDefault();
    const x0 = e.clientX, y0 = e.clientY, yaw0 = this.yaw, pitch0 = this.pitch;
    const move = (m) => {
      this.yaw = yaw0 + (m.clientX - x0) * 0.01;
      this.pitch = Math.max(-1.45, Math.min(1.45, pitch0 + (m.clientY - y0) * 0.01));
      this.view.yaw = this.yaw;
      this.view.pitch = this.pitch;
      this.draw(this.frame);
    };
    const up = () => {
      window.removeEventListener("pointermove", move);
      window.removeEventListener("pointerup", up);
    };
    window.addEventListener("pointermove", move);
    window.addEventListener("pointerup", up);
  }
}
