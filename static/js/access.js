// The animation without a mouse and without sight (WCAG 2.2 AA; issue 26, item 6).
// - The canvas is a tab stop with a visible focus ring. On it: arrow keys move the chosen body
//   (as a drag does: dropped from rest, the server's run follows), `b` chooses the next body,
//   Shift + arrows turn a 3-D view (a drag elsewhere does it with the mouse: 2.5.7), space or
//   Enter plays and pauses (p does anywhere: 2.2.2). The keys are taken before lecture mode's
//   (→ would reveal the next step), only while the canvas has the focus.
// - The hint (how to drag, the keys, "camera follows the motion") is a line under the canvas,
//   never drawn over the motion (a 3-D hint covered a third of a 374×247 canvas in lecture mode);
//   in lecture mode it goes once the canvas was used.
// - An aria-live region says the scene in words: each body's position, the energies and the
//   clock; on pause, on a step and on a keyboard move, never every frame.
import { nameText } from "./texnames.js";
import { fmt } from "./integrator.js";

const $ = (id) => document.getElementById(id);
/** Screen pixels a key press moves a body (Alt: finer). */
const NUDGE_PX = 8;
/** Radians a Shift + arrow press turns a 3-D view. */
const TURN = 0.12;
/** The description waits this long after the last pause or step (a held key, a scrubbed slider). */
const SAY_MS = 250;

export class SceneAccess {
  constructor(sceneView) {
    this.sv = sceneView;
    this.canvas = $("canvas");
    this.chosen = null;
    this.canvas.tabIndex = 0;
    this.hint = Object.assign(document.createElement("p"), { id: "canvas-hint", className: "canvas-hint muted" });
    this.canvas.closest("figure")?.append(this.hint);
    this.region = Object.assign(document.createElement("p"), { id: "scene-description", className: "sr-only" });
    this.region.setAttribute("aria-live", "polite");
    this.region.setAttribute("role", "status");
    this.hint.after(this.region);
    this.canvas.setAttribute("aria-describedby", "canvas-hint");
    this.canvas.addEventListener("keydown", (e) => this.#key(e));
    for (const type of ["pointerdown", "keydown"]) {
      this.canvas.addEventListener(type, () => this.hint.classList.add("used"), { passive: true });
    }
    new MutationObserver(() => this.#hint()).observe(this.canvas, { attributes: true, attributeFilter: ["data-hint", "data-view"] });
    this.#hint();
  }

  /** The line under the canvas: what the drawing used to write over itself, and the keys. */
  #hint() {
    const drawn = this.canvas.dataset.hint || "";
    const movable = this.#bodies().length > 0;
    const keys = [movable ? "arrow keys move a body (b picks which)" : "",
      this.canvas.dataset.view === "3d" ? "Shift + arrows turn the view" : "", "space plays or pauses"].filter(Boolean);
    const text = `On the focused canvas: ${keys.join(", ")}.`;
    if (this.hint.textContent === `${drawn ? `${drawn}. ` : ""}${text}`) return;
    // lecture mode shows the drag's words only (the keys are for whoever sits at the keyboard)
    this.hint.replaceChildren(
      Object.assign(document.createElement("span"), { className: "hint-drag", textContent: drawn ? `${drawn}. ` : "" }),
      Object.assign(document.createElement("span"), { className: "hint-keys", textContent: text }));
  }

  /** The bodies a key can move: drawn, and moved by some coordinate. */
  #bodies() {
    const { live, stageA, spec } = this.sv;
    if (!live || !stageA?.geom || !spec) return [];
    return (spec.bodies || []).map((b) => b.name)
      .filter((n) => live.meta.points.includes(n) && !stageA.geom.fixed.has(n) && stageA.geom.P[n]);
  }

  #key(e) {
    if (e.ctrlKey || e.metaKey) return;
    const sv = this.sv;
    const arrows = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1] };
    if (e.key === " " || e.key === "Enter") {
      e.preventDefault();
      sv.togglePlay();
      return;
    }
    if (e.key === "b" || e.key === "B") {
      e.preventDefault();
      const all = this.#bodies();
      if (!all.length) return;
      this.chosen = all[(all.indexOf(this.chosen) + 1) % all.length];
      sv.drag.hovered = this.chosen;
      this.say(`${this.chosen} chosen: arrow keys move it.`);
      return;
    }
    const step = arrows[e.key];
    if (!step) return;
    e.preventDefault(); // not the page's scroll, nor lecture mode's next step
    const st = sv.stageA;
    if (e.shiftKey && st.geom?.is3D) {
      st.yaw += step[0] * TURN;
      st.pitch = Math.max(-1.45, Math.min(1.45, st.pitch + step[1] * TURN));
      if (st.view) Object.assign(st.view, { yaw: st.yaw, pitch: st.pitch });
      st.draw(st.frame);
      this.canvas.dataset.turned = String(Number(this.canvas.dataset.turned || 0) + 1);
      return;
    }
    const all = this.#bodies();
    if (!all.length) return;
    if (!all.includes(this.chosen)) this.chosen = all[all.length - 1]; // the outermost, as a hand takes
    const px = e.altKey ? 1 : NUDGE_PX;
    if (sv.playing) sv.togglePlay();
    if (sv.drag.nudge(this.chosen, step[0] * px, step[1] * px)) {
      sv.drag.hovered = this.chosen;
      this.later();
    }
  }

  /** The description, SAY_MS after the last call. */
  later() {
    clearTimeout(this.timer);
    this.timer = setTimeout(() => this.describe(true), SAY_MS);
  }

  describe(now = false) {
    if (!now) return this.later();
    const text = this.text();
    if (text) this.say(text);
  }

  say(text) {
    // the same words again are announced again only if the region changes: a space resets it
    this.region.textContent = this.region.textContent === text ? `${text} ` : text;
  }

  /** "Paused at t = 1.23 s. bob1 at x = 0.5 m, y = −0.8 m; … Energies: T = …, V = …, E = … J." */
  text() {
    const { shown, stageA, playing } = this.sv;
    const g = stageA?.geom;
    if (!shown || !g) return "";
    const i = stageA.frame;
    const t = shown.t[Math.min(i, shown.t.length - 1)];
    const where = g.bodies.map((b) => {
      const [x, y, z] = g.at(b.name, i);
      const parts = [`x = ${fmt(x, 3)} m`, `y = ${fmt(y, 3)} m`];
      if (g.is3D) parts.push(`z = ${fmt(z, 3)} m`);
      return `${b.name} at ${parts.join(", ")}`;
    });
    const coords = (this.sv.spec?.coordinates || []).map((q) => {
      const v = shown.q?.[q]?.[i];
      return Number.isFinite(v) ? `${nameText(q)} = ${fmt(v, 4)}` : null;
    }).filter(Boolean);
    const e = shown.energy || {};
    const energy = ["T", "V", "E"].filter((k) => Number.isFinite(e[k]?.[i])).map((k) => `${k} = ${fmt(e[k][i], 3)} J`);
    const state = playing ? "Playing" : "Paused";
    const kind = shown.stats?.preview ? " (preview)" : "";
    return `${state} at t = ${Number(t).toFixed(2)} s${kind}. ${where.join("; ")}.`
      + (coords.length ? ` Coordinates: ${coords.join(", ")}.` : "")
      + (energy.length ? ` Energies: ${energy.join(", ")}.` : "");
  }
}
