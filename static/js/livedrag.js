// Dragging a body on the canvas to set where the motion starts (and, with Shift held or the
// "drag sets velocity" toggle, how fast it starts). The pointer is mapped to world coordinates by
// inverting the stage's view; the coordinates that put the dragged body there come from the scene's
// own position functions (live.js: damped Gauss–Newton), so a double pendulum's lower bob moves
// both angles and a bead stays on its hoop. Nothing is asked of the server while dragging: the
// live preview redraws each animation frame; the server's run is asked for on release, and the
// motion plays from the new start in the view it was dragged in (no jump of scale).
// In a 3-D view a drag that starts on a body moves it on the plane through it parallel to the
// screen (drag3d.js); one that starts elsewhere turns the camera (draw.js).
import { placeOnScreen, velocityOnScreen, movers } from "./drag3d.js";
import { unproject } from "./live.js";

const PICK_PX = 30; // how near the pointer must be to a body to grab it
const VELOCITY_SECONDS = 1; // the arrow's tip is where the body would be after 1 s at that speed

const $ = (id) => document.getElementById(id);

export class BodyDrag {
  constructor(sceneView) {
    this.sv = sceneView;
    this.canvas = $("canvas");
    this.drag = null;
    this.kept = null; // {view, changes}: the view of the last drag, kept while nothing else changed
    this.hovered = null;
    this.velocityMode = false;
    const stage = sceneView.stageA;
    stage.grabs = (e) => e.button <= 0 && Boolean(this.#usable() && this.#grab(this.#local(e)));
    stage.placeable = () => Boolean(this.#usable());
    this.canvas.addEventListener("pointerdown", (e) => this.#down(e));
    this.canvas.addEventListener("pointermove", (e) => this.#hover(e));
    this.canvas.addEventListener("pointerleave", () => { if (!this.drag) this.#highlight(null); });
    this.#toggle();
  }

  /** A body is being moved: the animation holds its start (until the pointer moves after the
   * press, the motion goes on, so a click on a body changes nothing). */
  get active() {
    return Boolean(this.drag?.moved);
  }

  /** The button beside the playback controls that makes a drag set the velocity instead. */
  #toggle() {
    const bar = document.querySelector(".playback");
    if (!bar || $("drag-mode")) return;
    const b = Object.assign(document.createElement("button"), { id: "drag-mode", type: "button" });
    b.title = "drag a body on the canvas to set where it starts, from rest (its velocities become 0); Shift-drag (or this toggle) sets its velocity";
    const sync = () => {
      b.textContent = this.velocityMode ? "drag sets: velocity" : "drag sets: position, at rest";
      b.setAttribute("aria-pressed", String(this.velocityMode));
    };
    b.addEventListener("click", () => { this.velocityMode = !this.velocityMode; sync(); });
    sync();
    bar.append(b);
  }

  #usable() {
    const { live, shown, stageA } = this.sv;
    return live && shown && stageA.geom && stageA.view;
  }

  /** Pointer position in the canvas's CSS pixels (the view's units). */
  #local(e) {
    const r = this.canvas.getBoundingClientRect();
    const st = this.sv.stageA;
    return [(e.clientX - r.left) * (st.cssW / r.width), (e.clientY - r.top) * (st.cssH / r.height)];
  }

  /** The movable body drawn nearest the pointer (within PICK_PX), or null. */
  #pick(at) {
    const { stageA, spec, live } = this.sv;
    const i = stageA.frame;
    let best = null, bestD = PICK_PX;
    for (const b of spec.bodies || []) {
      if (!live.meta.points.includes(b.name) || stageA.geom.fixed.has(b.name)) continue;
      const s = stageA.view.project(stageA.geom.at(b.name, i));
      const d = Math.hypot(s[0] - at[0], s[1] - at[1]);
      if (d < bestD) { best = b.name; bestD = d; }
    }
    return best;
  }

  /** The body a press at `at` takes: the one drawn nearest (within PICK_PX) that some
   * coordinate moves; null when the press is for the camera. */
  #grab(at) {
    const body = this.#pick(at);
    if (!body) return null;
    const { live, initial, params } = this.sv;
    return movers(live, body, this.#drawnState(live.state(initial)), live.paramVector(params)).length ? body : null;
  }

  #hover(e) {
    if (this.drag || !this.#usable()) return;
    if (e.buttons) { this.#highlight(null); return; } // the camera is being turned
    this.#highlight(this.#pick(this.#local(e)));
  }

  /** The grab cursor and a ring around the body a press would take. */
  #highlight(body) {
    this.hovered = body;
    this.canvas.style.cursor = body ? "grab" : "";
  }

  /** The state the run on the canvas passes through at its drawn frame: its q, and q̇ = 0 (a
   * position drag drops the body from rest) or, with `rates`, the run's own q̇ there (a velocity
   * drag then changes only the rates that move the body taken; the others go on as they were). */
  #drawnState(fallback, { rates = false } = {}) {
    const { shown, live, stageA } = this.sv;
    const y = Float64Array.from(fallback);
    live.meta.coordinates.forEach((q, j) => {
      const v = shown.q?.[q]?.[stageA.frame];
      if (Number.isFinite(v)) y[j] = v;
      const w = shown.q_dot?.[q]?.[stageA.frame];
      y[live.n + j] = rates && Number.isFinite(w) ? w : 0;
    });
    return y;
  }

  /** State y with `body` moved to where it is drawn (`seen`, on the screen): the new start is at
   * t = 0, and where a constraint moves with time (a spinning hoop) the same q put it elsewhere
   * then; elsewhere it is there already and nothing changes. */
  #placedAsSeen(body, seen, y, p, positive) {
    const { live, stageA } = this.sv;
    const view = stageA.view;
    if (view.is3D) return placeOnScreen(live, body, view, seen, seen[2], y, p, { positive });
    const here = live.places(y, p)[body];
    return live.reach(body, unproject(view, seen[0], seen[1], here[2]), y, p);
  }

  #down(e) {
    if (!this.#usable() || e.button > 0) return;
    const at = this.#local(e);
    const body = this.#grab(at);
    if (!body) return;
    e.preventDefault();
    e.stopImmediatePropagation();
    const sv = this.sv;
    const live = sv.live;
    const st = sv.stageA;
    this.canvas.setPointerCapture?.(e.pointerId);
    this.canvas.style.cursor = "grabbing";
    const velocity = this.velocityMode || e.shiftKey;
    // Both kinds of drag start from the instant on the screen, the body taken where it is seen
    // (which keeps a double pendulum's elbow or a bob's side of its sphere): a position drag
    // moves it from there, a velocity drag gives it a velocity there. (A velocity drag once
    // started from the scene's start: the body jumped away from under the pointer, and out of
    // a following camera's view.)
    const p = live.paramVector(sv.params);
    const seen = st.view.project(st.geom.at(body, st.frame)); // where the body was taken
    const positive = (sv.spec.positive_coordinates || []).map((q) => live.meta.coordinates.indexOf(q)).filter((j) => j >= 0);
    const drawn = this.#drawnState(live.state(sv.initial), { rates: velocity });
    const y = velocity ? this.#placedAsSeen(body, seen, drawn, p, positive) : drawn;
    this.drag = { body, velocity, at, press: at, view: st.view, y, p, moved: false, seen, positive };
    const move = (m) => {
      this.drag.at = this.#local(m);
      this.drag.moved = true;
      this.#apply();
    };
    const up = () => {
      this.canvas.removeEventListener("pointermove", move);
      this.canvas.removeEventListener("pointerup", up);
      this.canvas.removeEventListener("pointercancel", up);
      const d = this.drag;
      this.drag = null;
      this.#highlight(null);
      if (!d.moved) return; // a click on a body changes nothing
      this.kept = { view: d.view, changes: sv.changes };
      sv.time = 0;
      if (!sv.playing) sv.togglePlay(); // it swings from where it was let go
      sv.schedule(0); // the server's run of the new start
    };
    this.canvas.addEventListener("pointermove", move);
    this.canvas.addEventListener("pointerup", up);
    this.canvas.addEventListener("pointercancel", up);
  }

  /** The keyboard's drag (access.js, WCAG 2.5.7): `body` moved by (dx, dy) screen pixels, dropped
   * from rest, as a pointer drag would move it; the server's run of the new start follows. The
   * first press starts from where the body is drawn; presses after it from the start they set
   * (the animation is paused meanwhile, so the body stays where the keys put it). */
  nudge(body, dx, dy) {
    if (!this.#usable()) return false;
    const sv = this.sv, live = sv.live, st = sv.stageA;
    const p = live.paramVector(sv.params);
    const positive = (sv.spec.positive_coordinates || []).map((q) => live.meta.coordinates.indexOf(q)).filter((j) => j >= 0);
    const again = this.keyed && this.keyed.changes === sv.changes;
    let y = again ? live.state(sv.initial) : this.#drawnState(live.state(sv.initial));
    for (let j = 0; j < live.n; j++) y[live.n + j] = 0;
    const view = again ? this.keyed.view : st.view;
    const seen = view.project(live.places(y, p)[body]);
    const to = [seen[0] + dx, seen[1] + dy];
    if (view.is3D) y = placeOnScreen(live, body, view, to, seen[2], y, p, { positive });
    else y = live.reach(body, unproject(view, to[0], to[1], live.places(y, p)[body][2]), y, p);
    for (let j = 0; j < live.n; j++) y[live.n + j] = 0;
    const values = {};
    const w = wrapped(live, y, p);
    live.meta.coordinates.forEach((q, j) => { values[q] = w[j]; values[`${q}_dot`] = 0; });
    sv.time = 0;
    sv.setInitial(values);
    this.keyed = { changes: sv.changes, view };
    this.kept = { view, changes: sv.changes };
    sv.schedule(400); // the server's run once the keys rest
    return true;
  }

  /** Where the velocity arrow's tip is on the screen: the start's place moved as far as the
   * pointer moved since the press (the body may have been taken while it swung elsewhere). */
  #tip(d, from) {
    return [from[0] + d.at[0] - d.press[0], from[1] + d.at[1] - d.press[1]];
  }

  /** The state the pointer asks for, into the controls and the preview. */
  #apply() {
    const d = this.drag;
    const live = this.sv.live;
    const here = live.places(d.y, d.p)[d.body];
    if (d.velocity) {
      const from = d.view.project(here);
      const [tx, ty] = this.#tip(d, from);
      const target = d.view.is3D ? d.view.unproject(tx, ty, from[2]) : unproject(d.view, tx, ty, here[2]);
      const v = [0, 1, 2].map((k) => (target[k] - here[k]) / VELOCITY_SECONDS);
      if (d.view.is3D) d.y = velocityOnScreen(live, d.body, d.view, v, d.y, d.p);
      else d.y = live.velocityFor(d.body, [v[0], v[1], 0], d.y, d.p);
    } else { // the body follows the pointer, as far from it as where it was taken
      const to = [d.seen[0] + d.at[0] - d.press[0], d.seen[1] + d.at[1] - d.press[1]];
      if (d.view.is3D) d.y = placeOnScreen(live, d.body, d.view, to, d.seen[2], d.y, d.p, { positive: d.positive });
      else d.y = live.reach(d.body, unproject(d.view, to[0], to[1], here[2]), d.y, d.p);
      for (let j = 0; j < live.n; j++) d.y[live.n + j] = 0; // dropped from rest
    }
    const values = {};
    const y = wrapped(live, d.y, d.p);
    live.meta.coordinates.forEach((q, j) => {
      values[q] = y[j];
      values[`${q}_dot`] = y[live.n + j];
    });
    this.sv.setInitial(values);
  }

  /** Called whenever a new run is put on the canvas: keep the view the drag started in (a refit
   * would move the world under the pointer), and after the drag, while nothing else changed,
   * for the runs of the new start (the preview's last frame, the server's run) if they fit. */
  freeze() {
    const st = this.sv.stageA;
    if (this.drag) {
      st.keep(this.drag.view, true);
      return;
    }
    if (!this.kept) return;
    if (this.kept.changes !== this.sv.changes || !st.keep(this.kept.view)) this.kept = null;
  }

  /** Drawn over the stage each frame: the velocity arrow while one is dragged, and (for tests and
   * tools) where each point is on screen while the motion stands still. */
  overlay() {
    const st = this.sv.stageA;
    if (!st.geom || !st.view) return;
    if (this.drag || !this.sv.playing) {
      const pts = {};
      for (const name of Object.keys(st.geom.P)) {
        const s = st.view.project(st.geom.at(name, st.frame));
        pts[name] = [Number(s[0].toFixed(2)), Number(s[1].toFixed(2))];
      }
      this.canvas.dataset.screen = JSON.stringify(pts);
    }
    const d = this.drag;
    const ring = d ? d.body : this.hovered;
    if (ring && st.geom.P[ring] && this.#usable()) {
      const [x, y] = st.view.project(st.geom.at(ring, st.frame));
      const ctx = st.ctx;
      ctx.save();
      ctx.strokeStyle = "#f08c00";
      ctx.lineWidth = 2;
      ctx.setLineDash([4, 3]);
      ctx.beginPath();
      ctx.arc(x, y, PICK_PX * 0.6, 0, 2 * Math.PI);
      ctx.stroke();
      ctx.restore();
    }
    if (!d || !d.velocity) return;
    const from = st.view.project(st.geom.at(d.body, 0));
    const ctx = st.ctx;
    const [x0, y0] = from, [x1, y1] = this.#tip(d, from);
    const len = Math.hypot(x1 - x0, y1 - y0);
    if (len < 2) return;
    const ux = (x1 - x0) / len, uy = (y1 - y0) / len;
    ctx.save();
    ctx.strokeStyle = ctx.fillStyle = "#d9480f";
    ctx.lineWidth = 2.5;
    ctx.beginPath();
    ctx.moveTo(x0, y0);
    ctx.lineTo(x1 - 8 * ux, y1 - 8 * uy);
    ctx.stroke();
    ctx.beginPath();
    ctx.moveTo(x1, y1);
    ctx.lineTo(x1 - 11 * ux - 5 * uy, y1 - 11 * uy + 5 * ux);
    ctx.lineTo(x1 - 11 * ux + 5 * uy, y1 - 11 * uy - 5 * ux);
    ctx.closePath();
    ctx.fill();
    ctx.font = "12px system-ui, sans-serif";
    const label = "v (tip: where it is after 1 s)";
    const w = ctx.measureText(label).width; // beside the tip, slid inside the canvas
    // past the tip, away from the shaft: below it for an arrow pointing down, else above
    const below = (y1 > y0 && y1 + 20 < st.cssH) || y1 < 24;
    const lx = Math.max(4, Math.min(x1 + 6, st.cssW - 4 - w)), ly = below ? y1 + 20 : y1 - 8;
    ctx.fillStyle = "rgba(255,255,255,0.85)";
    ctx.fillRect(lx - 2, ly - 12, w + 4, 16);
    ctx.fillStyle = "#d9480f";
    ctx.fillText(label, lx, ly);
    ctx.restore();
  }
}

/** The state with each angle brought into (−π, π] where that changes no position: the solver
 * may wind an angle round (φ = 11.43 after a few turns of a drag), which pinned its slider at
 * the end of its range. A coordinate whose turns move something (a disk's roll angle) stays. */
function wrapped(live, y, p) {
  const out = Float64Array.from(y);
  const before = live.places(y, p);
  for (let j = 0; j < live.n; j++) {
    const turns = Math.round(out[j] / (2 * Math.PI));
    if (turns === 0) continue;
    const trial = Float64Array.from(out);
    trial[j] -= 2 * Math.PI * turns;
    const after = live.places(trial, p);
    const same = Object.keys(before).every((k) => before[k].every((x, i) => Math.abs(x - after[k][i]) <= 1e-9 * (1 + Math.abs(x))));
    if (same) out[j] = trial[j];
  }
  return out;
}
