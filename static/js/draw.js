// The animation canvas: the scene at one sample with a fading trail, sharp on any screen (device
// pixel ratio), planar scenes in the x–y plane, 3-D ones in a perspective view turned by dragging.
// A run that travels far (a disk rolling down a long slope) gets a camera that pans with it at one
// fixed scale, never zooming out. The stages of one page that show the same spec (compare mode:
// two methods side by side) share one scale, fitted to the union of their runs, so equal
// distances look equal. The page's first stage carries the instruments (instruments.js). In a
// 3-D view a drag turns the camera, unless it starts on a body (livedrag.js moves that body).
import { SceneGeometry } from "./geometry.js";
import { Instruments } from "./instruments.js";
import { drawCanvas } from "./render.js";
import { sceneShapes } from "./shapes.js";
import { View } from "./view.js";

const ASPECT = 0.66; // height / width, for 3-D scenes and tall planar ones
const PAD = { "2d": 34, "3d": 18 };
const FOLLOWED_PX = 60; // the least size (px) of a body a following camera shows
const KEEP_MARGIN = 12; // px: a run kept in a dragged view keeps its bodies (radius ~11) on the canvas
const stages = new Set(); // every stage on the page: the ones showing the same spec share a scale

export class Stage {
  /** opts.instruments: mount the energy bars, stopwatch, ... under this canvas (default: the
   * page's first stage does). */
  constructor(canvas, opts = {}) {
    this.canvas = canvas;
    const instruments = opts.instruments ?? stages.size === 0;
    stages.add(this);
    this.instruments = instruments ? new Instruments(this) : null;
    this.ctx = canvas.getContext("2d");
    this.geom = null;
    this.frame = 0;
    this.yaw = 0.55;
    this.pitch = 0.4;
    /** (pointerdown event) => true when the pointer takes a body (livedrag.js), which a 3-D
     * view's drag then moves instead of turning the camera. */
    this.grabs = null;
    /** () => whether bodies can be dragged here (the note on a 3-D canvas says so). */
    this.placeable = () => false;
    this.canvas.addEventListener("pointerdown", (e) => this.#drag(e));
    new ResizeObserver(() => this.#resize()).observe(canvas);
    this.#resize();
  }

  #resize() {
    const w = Math.max(200, Math.round(this.canvas.clientWidth || 640));
    const h = Math.round(w * (this.aspect || ASPECT));
    const dpr = window.devicePixelRatio || 1;
    // on-screen pixels per canvas pixel: below 1 where the canvas is shown shrunk to fit a short
    // screen's height (lecture mode's max-height, object-fit: contain); read here, not per frame
    const shownH = this.canvas.clientHeight;
    this.shownScale = shownH && h ? Math.min(1, shownH / h) : 1;
    if (this.canvas.width === Math.round(w * dpr) && this.cssW === w && this.cssH === h) return;
    this.cssW = w;
    this.cssH = h;
    this.canvas.width = Math.round(w * dpr);
    this.canvas.height = Math.round(h * dpr);
    this.canvas.style.aspectRatio = `${w} / ${h}`;
    this.dpr = dpr;
    if (this.geom) { this.#fit(this.#peers()); this.draw(this.frame); }
  }

  setResult(spec, result, parameters) {
    this.geom = new SceneGeometry(spec, result, parameters);
    this.canvas.dataset.view = this.geom.is3D ? "3d" : "2d";
    if (this.instruments) this.instruments.setResult(spec, result);
    const peers = this.#peers();
    for (const s of peers) s.#layout(peers);
  }

  /** The shown stages (this one included) drawing the same spec: they share one scale. */
  #peers() {
    if (!this.geom) return [this];
    const shown = (s) => s === this || !s.canvas.closest("[hidden]");
    return [...stages].filter((s) => s.geom && s.geom.spec === this.geom.spec && s.geom.is3D === this.geom.is3D && shown(s));
  }

  #layout(peers) {
    // A flat scene (a block on a floor) gets a flatter canvas, not a tall empty one.
    let aspect = ASPECT;
    if (!this.geom.is3D) {
      const pts = peers.flatMap((s) => s.geom.extent());
      const span = (k) => Math.max(...pts.map((p) => p[k])) - Math.min(...pts.map((p) => p[k]));
      aspect = Math.min(ASPECT, Math.max(0.42, span(1) / Math.max(span(0), 1e-9) + 0.2));
    }
    if (aspect !== this.aspect) {
      this.aspect = aspect;
      this.cssW = 0; // force a resize
      this.#resize();
    }
    this.#fit(peers);
  }

  #firstSecond() {
    const t = this.geom.result.t;
    const idx = [];
    for (let i = 0; i < t.length && t[i] - t[0] <= 1.0; i++) idx.push(i);
    return idx;
  }

  /** One scale for the peers: the union of their runs fits; or, when the motion travels far
   * compared with its first second, a fixed closer scale that pans with the bodies. */
  #fit(peers = [this]) {
    const g = this.geom;
    const pad = PAD[g.is3D ? "3d" : "2d"];
    const box = (w, h) => new View(w, h, g.is3D);
    // the smallest canvas of the peers decides, so the same scale fits every one of them
    const w = Math.min(...peers.map((s) => s.cssW || this.cssW)), h = Math.min(...peers.map((s) => s.cssH || this.cssH));
    const all = box(w, h).fit(peers.flatMap((s) => s.geom.extent()), pad);
    this.view = new View(this.cssW, this.cssH, g.is3D);
    Object.assign(this.view, { yaw: this.yaw, pitch: this.pitch });
    this.view.fit(g.extent(), pad);
    this.view.scale = all.scale;
    if (peers.length > 1) this.view.center = all.center;
    this.follow = false;
    if (!g.is3D) {
      const early = box(w, h).fit(peers.flatMap((s) => s.geom.extent(s.#firstSecond(), false)), pad);
      // Travels far compared with its first second: follow it at one scale instead of
      // shrinking it to a dot; the scale keeps a few of the system's own sizes in view.
      if (early.scale > 6 * all.scale) {
        this.follow = true;
        const size = Math.max(...peers.map((s) => s.geom.bodySize()));
        const readable = size > 0 ? (Math.min(w, h) - 2 * pad) / (4 * size) : early.scale;
        // the first second in view, but on a narrow canvas (instruments beside it) never at the
        // cost of the body itself: at least FOLLOWED_PX across, as long as 4 of it still fit
        const legible = size > 0 ? Math.min(readable, FOLLOWED_PX / size) : 0;
        this.view.scale = Math.max(all.scale, Math.min(early.scale, readable), legible);
      }
    }
    this.canvas.dataset.scale = this.view.scale.toPrecision(6);
  }

  /** Show the run in `view` (the one a body was dragged in) instead of the fitted one, so the
   * world does not move, nor the scale jump, under the user's hand. `force` (during a drag)
   * keeps it whatever the run; otherwise only when the whole run fits in it (a body dragged
   * far out needs the wider view) — a following camera keeps the scale and follows. Returns
   * whether the view was kept. */
  keep(view, force = false) {
    const g = this.geom;
    if (!g || !view || view.is3D !== g.is3D) return false;
    if (!force && this.follow) {
      this.view.scale = view.scale;
      this.canvas.dataset.scale = view.scale.toPrecision(6);
      return true;
    }
    if (!force && !view.contains(g.extent(), KEEP_MARGIN)) return false;
    if (view.w !== this.cssW || view.h !== this.cssH) { // a new layout changed the canvas' shape
      if (view.w !== this.cssW) return false; // the page was resized meanwhile: fitted anew
      this.aspect = view.h / view.w;
      this.cssW = 0;
      this.#resize();
    }
    Object.assign(view, { yaw: this.yaw, pitch: this.pitch });
    this.view = view;
    this.follow = false;
    this.canvas.dataset.scale = view.scale.toPrecision(6);
    return true;
  }

  draw(i) {
    const g = this.geom;
    if (!g) return;
    this.frame = Math.max(0, Math.min(g.n - 1, i));
    if (this.follow) this.view.center = g.focus(this.frame);
    const { ctx, canvas } = this;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    // lecture mode: labels (a body's name, a spring's, the scale bar's "50 cm", which is drawn a
    // pixel smaller) at least 24 px on the screen, read from the back of a hall; bodies keep
    // their size
    const lecture = document.body.classList.contains("lecture");
    const font = lecture ? Math.ceil(25 / (this.shownScale || 1)) : 12;
    const shapes = sceneShapes(g, this.view, this.frame, {
      radius: lecture ? 16 : 11, trail: g.is3D ? 3 : 1.5, scaleBar: true, font,
    });
    const turn = this.placeable() ? ["drag a body to place it,", "drag elsewhere to turn the view"] : ["drag to turn the view"];
    const note = g.is3D ? turn : this.follow ? ["camera follows the motion"] : [];
    // the hint is a line under the canvas (access.js), never drawn over the motion: a 3-D one
    // covered a third of a 374×247 canvas in lecture mode (issue 26, item 2)
    const hint = note.join(" ");
    if (canvas.dataset.hint !== hint) canvas.dataset.hint = hint;
    drawCanvas(ctx, shapes);
    canvas.dataset.frame = String(this.frame);
    const v = this.view; // the camera, for tests that check where things are drawn
    canvas.dataset.camera = JSON.stringify({ w: v.w, h: v.h, scale: v.scale, center: v.center, yaw: v.yaw, pitch: v.pitch, camera: v.camera, is3D: v.is3D });
    canvas.dataset.pieces = [...new Set(shapes.map((s) => s.piece).filter(Boolean))].sort().join(" ");
    if (this.instruments) this.instruments.update(this.frame);
  }

  #drag(e) {
    if (!this.geom || !this.geom.is3D || this.grabs?.(e)) return;
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

