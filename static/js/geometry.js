// What a scene looks like, read from its spec and one simulated run: which bodies hang on rods,
// which slide along a straight track (a floor, an incline), which hang on a rope from a pulley,
// which ride a spinning hoop or a cone or a wire of any shape (swept from the spec's position at
// the run's parameters), how big a rolling wheel is, where the supports are (fixed points only).
// A rigid body hangs on a rod only when it is pinned (the anchor is a point of the body); else it
// is drawn by its own shape and frame (rigid.js), on the surface it rolls on when it rolls.
// Nothing here is scene-specific: every drawing decision is inferred from the data.
import { compile } from "./expr.js";
import { outline, rigidShape, rollingContacts } from "./rigid.js";

export const COLORS = ["#1f6feb", "#d9480f", "#2f9e44", "#9c36b5", "#e8590c", "#0c8599"];
const REL = 1e-6; // relative tolerance for "constant" along a run
const SWEEP = 121; // points along a swept wire
const DOWN = [0, -1, 0]; // gravity's direction when a spec gives none (spec.py Gravity.direction)
// spec -> {q: [lo, hi]}: the range each coordinate covered in the last full run, so a one-sample
// run (an equilibrium sketch) of the same spec sweeps its wire over the same stretch.
const lastRanges = new WeakMap();

export const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
export const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
export const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
export const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
export const norm = (a) => Math.hypot(a[0], a[1], a[2]);
export const unit = (a) => mul(a, 1 / (norm(a) || 1));
export const cross = (a, b) => [
  a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];

/** The point a body is placed from (`position.from`), else the origin O. */
export function bodyAnchor(body) {
  const p = body.position;
  return p && !Array.isArray(p) && p.from ? p.from : "O";
}

function positionFrame(body) {
  const p = body.position;
  return p && !Array.isArray(p) && p.frame && p.frame !== "N" ? p.frame : null;
}

/** The components, frame (null for N) and anchor of a body's or point's position. */
function positionParts(position) {
  if (Array.isArray(position)) return { components: position, frame: null, anchor: "O" };
  if (!position) return null;
  return { components: position.components || [], frame: position.frame && position.frame !== "N" ? position.frame : null,
    anchor: position.from || "O" };
}

/** A number for a mass given as a parameter name or a numeral; 1 when it is an expression. */
function massValue(mass, parameters) {
  if (typeof mass === "number") return mass;
  if (mass in parameters) return parameters[mass];
  const x = Number(mass);
  return Number.isFinite(x) ? x : 1;
}

/**
 * The positions to draw. A run shown at more frames than it was sampled at (live.js forDisplay:
 * `sampled`, `stats.display_factor`) has its in-between points on the straight chord between two
 * samples, so a trail drawn through them bends only at the samples, 30 times a second: kinks a
 * fast bob shows plainly. Here the in-between points lie on a cubic through the samples (Hermite,
 * each sample's tangent the central difference of its neighbours in time), so the trail and the
 * motion are smooth (the ends' tangents from a parabola through three samples); the points at
 * the samples are the measured ones.
 */
function smoothPositions(result) {
  const base = result.sampled, factor = result.stats?.display_factor;
  if (!base?.positions || !(factor > 1) || base.t.length < 3) return result.positions;
  const t = base.t, n = t.length;
  if ((n - 1) * factor + 1 !== result.t.length) return result.positions; // not forDisplay's shape
  // the slope at a of the parabola through (a, b, c): the ends' tangents, as good as the middle's
  const end = (v, a, b, c) => v[a] * (2 * t[a] - t[b] - t[c]) / ((t[a] - t[b]) * (t[a] - t[c]))
    + v[b] * (t[a] - t[c]) / ((t[b] - t[a]) * (t[b] - t[c])) + v[c] * (t[a] - t[b]) / ((t[c] - t[a]) * (t[c] - t[b]));
  const curve = (v) => {
    const slope = (i) => (i === 0 ? end(v, 0, 1, 2) : i === n - 1 ? end(v, n - 1, n - 2, n - 3)
      : (v[i + 1] - v[i - 1]) / (t[i + 1] - t[i - 1]));
    const out = new Array(result.t.length);
    let m0 = slope(0);
    for (let i = 0; i < n - 1; i++) {
      const h = t[i + 1] - t[i], m1 = slope(i + 1);
      out[i * factor] = v[i];
      for (let k = 1; k < factor; k++) {
        const f = k / factor, f2 = f * f, f3 = f2 * f;
        out[i * factor + k] = (2 * f3 - 3 * f2 + 1) * v[i] + (f3 - 2 * f2 + f) * h * m0
          + (3 * f2 - 2 * f3) * v[i + 1] + (f3 - f2) * h * m1;
      }
      m0 = m1;
    }
    out[(n - 1) * factor] = v[n - 1];
    return out;
  };
  const same = (v) => v.every((x) => x === v[0]); // a fixed point stays exactly where it is
  return Object.fromEntries(Object.entries(base.positions).map(([name, p]) => [name,
    same(p.x) && same(p.y) && same(p.z) ? result.positions[name]
      : { x: curve(p.x), y: curve(p.y), z: curve(p.z) }]));
}

export class SceneGeometry {
  constructor(spec, result, parameters = spec.parameters || {}) {
    this.spec = spec;
    this.result = result;
    this.P = smoothPositions(result);
    this.n = result.t.length;
    this.bodies = spec.bodies.filter((b) => this.P[b.name]);
    this.parameters = parameters;
    this.coordinates = new Set(spec.coordinates || []);
    // a valid spec may leave out the direction (the schema's default: down -y); the page must
    // read it as the server does, not fail on it
    const g = spec.gravity ? [...(spec.gravity.direction ?? DOWN), 0].slice(0, 3) : null;
    this.down = g ? unit(g) : [0, -1, 0];
    this.hasGravity = Boolean(g);
    this.is3D = this.bodies.some((b) => this.P[b.name].z.some((z) => Math.abs(z) > 1e-9));
    this.color = Object.fromEntries(this.bodies.map((b, k) => [b.name, COLORS[k % COLORS.length]]));
    const masses = this.bodies.map((b) => Math.abs(massValue(b.mass, parameters)) || 1);
    const heaviest = Math.max(...masses);
    this.size = Object.fromEntries(this.bodies.map((b, k) =>
      [b.name, Math.max(0.65, Math.cbrt(masses[k] / heaviest))]));
    this.fixed = new Set(Object.keys(this.P).filter((name) => this.#isFixed(name)));
    this.links = []; // [anchor, body]: a rod (or rope) of constant length
    this.hoops = []; // {body, anchor, frame, axes: [i, j], radius}
    this.cones = []; // {anchor, frame, axisIndex, halfAngle, length}
    this.tracks = []; // {body, origin, dir, lo, hi}: the straight line a body slides along
    this.ropes = []; // {body, point}: a vertical rope up to a fixed point's height
    this.pulleys = new Map(); // point -> radius
    this.wheels = new Map(); // rigid body -> radius (world units), inferred from rolling
    this.wires = []; // {body, anchor, frame, q, local: [[x, y, z]...] in the frame, from the anchor}
    this.surfaces = []; // {body, anchor, frame, lines: [local points...]}: a mesh of two sweeps
    this.rolls = []; // {body, contacts, outward}: the curve a disk rolls on (world points)
    this.shapes = new Map(); // rigid body -> its shape by its inertia (rigid.js), in its frame
    for (const b of this.bodies) {
      const shape = b.kind === "rigid_body" && b.frame && result.frames?.[b.frame] ? rigidShape(b, parameters) : null;
      if (shape) this.shapes.set(b.name, shape);
    }
    this.ranges = this.#ranges();
    for (const b of this.bodies) this.#analyze(b);
    // a wire or hoop turning about an axis in the picture's plane needs depth to be seen
    const spinsInPlane = (frame) => {
      const f = (spec.frames || []).find((x) => x.name === frame);
      return f && f.axis !== "z" && this.frameSpins(frame);
    };
    if ([...this.wires, ...this.hoops].some((w) => spinsInPlane(w.frame))) this.is3D = true;
    this.supports = this.#supports();
    this.slides = this.#slides(); // {body, origin, dir, lo, hi, away}: a line a rod's end slides on
  }

  at(name, i) {
    const p = this.P[name];
    return [p.x[i], p.y[i], p.z[i]];
  }

  height(point) {
    return -dot(point, this.down);
  }

  /** Fixed: constant along the run and, by its spec, depending on no coordinate and not on t (a
   * one-sample run, an equilibrium sketch, cannot tell a resting body from a support). */
  #isFixed(name) {
    const p = this.P[name];
    if (!this.#staticBySpec(name, 0)) return false;
    return ["x", "y", "z"].every((c) => {
      const v = p[c], v0 = v[0];
      return v.every((x) => Math.abs(x - v0) <= 1e-12 * (1 + Math.abs(v0)));
    });
  }

  /** The names a frame's orientation depends on (its angle's and its parents'); null when an
   * angle cannot be read. */
  frameNames(frame, depth = 0) {
    if (!frame || frame === "N" || depth > 20) return new Set();
    const f = (this.spec.frames || []).find((x) => x.name === frame);
    if (!f) return new Set();
    const angle = compile(f.angle), up = this.frameNames(f.parent, depth + 1);
    return angle && up ? new Set([...angle.names, ...up]) : null;
  }

  /** Whether a frame turns (its angle, or a parent's, depends on a coordinate or on t). */
  frameMoves(frame) {
    const names = this.frameNames(frame);
    return !names || [...names].some((n) => n === "t" || this.coordinates.has(n));
  }

  /** Whether a frame is driven round by the clock alone (a spinning hoop, not a coordinate). */
  frameSpins(frame) {
    const names = this.frameNames(frame);
    return Boolean(names) && names.has("t") && ![...names].some((n) => this.coordinates.has(n));
  }

  #staticBySpec(name, depth) {
    if (name === "O" || depth > 20) return true;
    const item = [...(this.spec.points || []), ...this.spec.bodies].find((x) => x.name === name);
    if (!item) return true; // not described: the samples decide
    const parts = positionParts(item.position);
    if (!parts) return true;
    const comps = parts.components.map(compile);
    if (comps.some((c) => !c)) return true;
    const varies = comps.some((c) => [...c.names].some((n) => n === "t" || this.coordinates.has(n)));
    const allZero = comps.every((c) => !c.names.size && c({}) === 0);
    if (varies || (!allZero && this.frameMoves(parts.frame))) return false;
    return this.#staticBySpec(parts.anchor, depth + 1);
  }

  /** Each coordinate's range over this run; a run too short to show one borrows the last full
   * run's of the same spec. */
  #ranges() {
    const out = {};
    const q = this.result.q || {};
    for (const [name, v] of Object.entries(q)) {
      if (v.length) out[name] = [Math.min(...v), Math.max(...v)];
    }
    if (this.n >= 3) lastRanges.set(this.spec, out);
    else {
      const before = lastRanges.get(this.spec) || {};
      for (const [name, r] of Object.entries(before)) {
        if (out[name] && out[name][0] >= r[0] - 1e-9 && out[name][1] <= r[1] + 1e-9) out[name] = r;
      }
    }
    return out;
  }

  /** The frame's axes at sample i as three rows (identity for N). */
  axesAt(frame, i) {
    if (!frame) return [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
    const F = this.result.frames[frame][i];
    return [F.slice(0, 3), F.slice(3, 6), F.slice(6, 9)];
  }

  /** A wire's (or any frame-fixed curve's) points in the world at sample i. */
  wireAt(w, i) {
    const A = this.axesAt(w.frame, i), o = this.at(w.anchor, i);
    return w.local.map((p) => add(o, add(mul(A[0], p[0]), add(mul(A[1], p[1]), mul(A[2], p[2])))));
  }

  /**
   * The curve a body is held to, when its position (in its frame, from its anchor) depends on a
   * single coordinate and not on t: the positions as that coordinate sweeps its range with
   * everything else as at sample 0. A full turn for a coordinate seen only inside sin, cos, ...;
   * else the range the run covered and a quarter more each way. Null when the spec's expressions
   * do not reproduce the run's position at sample 0 (then nothing is drawn rather than a guess).
   */
  #sweep(body) {
    const f = this.#positionFunction(body);
    if (!f || f.qs.length !== 1) return null;
    const q = f.qs[0], [lo, hi] = f.range(q);
    const pts = [], values = [];
    for (let k = 0; k < SWEEP; k++) {
      const v = lo + ((hi - lo) * k) / (SWEEP - 1), p = f.local({ [q]: v });
      if (p.every(Number.isFinite)) { pts.push(p); values.push(v); }
    }
    if (pts.length < 2) return null;
    return { body: body.name, anchor: f.parts.anchor, frame: f.parts.frame, q, local: pts, closed: f.periodic(q),
      values, place: (v) => f.local({ [q]: v }) };
  }

  /** The spec's position of a body as local (frame, from anchor) points of its coordinates, when
   * it reproduces the run at sample 0 and no frame turns with a coordinate; else null. */
  #positionFunction(body) {
    const parts = positionParts(body.position);
    if (!parts || !this.P[parts.anchor]) return null;
    if (parts.frame && !(this.result.frames || {})[parts.frame]) return null;
    const turns = this.frameNames(parts.frame);
    if (!turns || [...turns].some((n) => this.coordinates.has(n))) return null;
    const comps = parts.components.map(compile);
    if (comps.some((c) => !c)) return null;
    while (comps.length < 3) comps.push(compile(0));
    const used = new Set(comps.flatMap((c) => [...c.names]));
    if (used.has("t")) return null;
    const env = { ...this.parameters, t: this.result.t[0] };
    for (const [name, v] of Object.entries(this.result.q || {})) env[name] = v[0];
    const local = (values) => comps.map((c) => c({ ...env, ...values }));
    const A = this.axesAt(parts.frame, 0), o = this.at(parts.anchor, 0), l0 = local({});
    const here = add(o, add(mul(A[0], l0[0]), add(mul(A[1], l0[1]), mul(A[2], l0[2]))));
    const there = this.at(body.name, 0);
    if (!(norm(sub(here, there)) <= 1e-6 * (1 + norm(there)))) return null;
    const qs = [...used].filter((n) => this.coordinates.has(n));
    const periodic = (q) => comps.every((c) => !c.names.has(q) || c.periodic.has(q));
    const range = (q) => {
      if (periodic(q)) return [env[q] - Math.PI, env[q] + Math.PI];
      const [lo, hi] = this.ranges[q] || [env[q], env[q]];
      if (hi - lo > 1e-9) return [lo - 0.25 * (hi - lo), hi + 0.25 * (hi - lo)];
      const reach = Math.max(1, Math.abs(env[q])); // at rest: a unit either way, for a start
      return [env[q] - reach, env[q] + reach];
    };
    return { parts, qs, local, periodic, range };
  }

  /**
   * The surface a body is held to, when its position depends on two coordinates and not on t (a
   * bead in a bowl): a mesh of the curves along which one coordinate changes and the other is
   * held, over the ranges the run covered. Not drawn when it is the picture's own plane.
   */
  #surface(body) {
    const f = this.#positionFunction(body);
    if (!f || f.qs.length !== 2 || !this.is3D) return;
    const [a, b] = f.qs, ra = f.range(a), rb = f.range(b);
    const LINES = 9, POINTS = 41;
    const at = (r, k, n) => r[0] + ((r[1] - r[0]) * k) / (n - 1);
    const lines = [];
    for (let j = 0; j < LINES; j++) {
      const one = [], other = [];
      for (let k = 0; k < POINTS; k++) {
        one.push(f.local({ [a]: at(ra, k, POINTS), [b]: at(rb, j, LINES) }));
        other.push(f.local({ [a]: at(ra, j, LINES), [b]: at(rb, k, POINTS) }));
      }
      for (const line of [one, other]) {
        const ok = line.filter((p) => p.every(Number.isFinite));
        if (ok.length > 1) lines.push(ok);
      }
    }
    if (!lines.length) return;
    this.surfaces.push({ body: body.name, anchor: f.parts.anchor, frame: f.parts.frame, lines });
  }

  /** One sample shows no motion: what holds the body is read from its swept curve instead. */
  #fromSweep(body, w) {
    const d = w.local.map(norm);
    const mean = d.reduce((s, v) => s + v, 0) / d.length;
    const constant = mean > 1e-9 && Math.max(...d) - Math.min(...d) <= REL * mean;
    // a rigid body not pinned at the anchor: its centre's circle is no rod (and no wire)
    if (constant && !this.#pinned(body, w.anchor)) {
      this.#rolling(body, w);
      return;
    }
    if (constant) {
      const flat = [0, 1, 2].find((k) => w.local.every((p) => Math.abs(p[k]) <= REL * mean));
      if (this.frameSpins(w.frame) && flat !== undefined) {
        this.hoops.push({ body: w.body, anchor: w.anchor, frame: w.frame,
          axes: [0, 1, 2].filter((k) => k !== flat), radius: mean });
      } else this.links.push([w.anchor, w.body]);
      return;
    }
    const first = w.local[0], last = w.local[w.local.length - 1];
    const reach = norm(sub(last, first));
    const dir = unit(sub(last, first));
    const straight = reach > 1e-9 && w.local.every((p) => {
      const r = sub(p, first);
      return norm(sub(r, mul(dir, dot(r, dir)))) <= REL * reach;
    });
    if (straight && !this.frameMoves(w.frame)) {
      const world = this.wireAt(w, 0), here = this.at(w.body, 0);
      const dirW = unit(sub(world[world.length - 1], world[0]));
      if (this.hasGravity && Math.abs(dot(dirW, this.down)) > Math.cos(0.17) && this.#rope(w.body)) return;
      const s = world.map((p) => dot(sub(p, here), dirW));
      const span = Math.max(...s) - Math.min(...s);
      this.tracks.push({ body: w.body, origin: here, dir: dirW, lo: -0.2 * span, hi: 0.2 * span });
      return;
    }
    if (body.kind === "rigid_body" && this.#rolling(body, w)) return;
    this.wires.push(w);
  }

  /**
   * Whether a body turns about its anchor as about a pin: a particle at a constant distance is
   * on a rod; a rigid body only when the anchor is a point of it. Its spec can say so (placed in
   * its own frame from the anchor by constants: a physical pendulum); else the run must show the
   * anchor fixed in the body's frame, seen from G, while the body moves (a one-sample sketch
   * shows no motion: unsure, so no pin, and the body is drawn by its shape, not on a rod).
   */
  #pinned(body, anchor) {
    if (body.kind !== "rigid_body") return true;
    const parts = positionParts(body.position);
    if (parts && body.frame && parts.frame === body.frame && parts.anchor === anchor) {
      const comps = parts.components.map(compile);
      if (comps.every((c) => c && ![...c.names].some((n) => n === "t" || this.coordinates.has(n)))) return true;
    }
    const run = this.result.sampled?.frames?.[body.frame] && this.result.sampled.positions?.[anchor]
      ? this.result.sampled : this.result;
    const F = run.frames?.[body.frame], G = run.positions?.[body.name], A = run.positions?.[anchor];
    if (!F || !G || !A || run.t.length < 3) return false;
    const world = run.t.map((_, i) => [A.x[i] - G.x[i], A.y[i] - G.y[i], A.z[i] - G.z[i]]);
    const local = world.map((r, i) => [0, 1, 2].map((k) => dot(r, F[i].slice(3 * k, 3 * k + 3))));
    const size = Math.max(...world.map(norm), 1e-12);
    const moves = world.some((r) => norm(sub(r, world[0])) > 1e-6 * size);
    return moves && local.every((r) => norm(sub(r, local[0])) <= 1e-4 * size);
  }

  /** A disk turning about N.z whose contact point stays on its rim along its centre's swept path
   * (rigid.js rollingContacts): its radius from the motion, and the surface it rolls on. */
  #rolling(body, w) {
    const shape = this.shapes.get(body.name), frame = (this.spec.frames || []).find((f) => f.name === body.frame);
    if (shape?.kind !== "disk" || shape.normal !== 2 || this.is3D || w.frame || !this.fixed.has(w.anchor)) return false;
    if (!frame || (frame.parent ?? "N") !== "N" || frame.axis !== "z") return false;
    const angleOf = compile(frame.angle);
    if (!angleOf || angleOf.names.has("t")) return false;
    const env = { ...this.parameters };
    for (const [name, v] of Object.entries(this.result.q || {})) env[name] = v[0];
    const angle = (v) => angleOf({ ...env, [w.q]: v });
    const F0 = this.result.frames[body.frame][0], turn = angle(env[w.q]) - Math.atan2(F0[1], F0[0]);
    if (!(Math.abs(turn - 2 * Math.PI * Math.round(turn / (2 * Math.PI))) < 1e-6)) return false;
    const roll = rollingContacts(w.values, w.place, angle, shape.radius);
    if (!roll) return false;
    const o = this.at(w.anchor, 0);
    this.wheels.set(body.name, roll.radius);
    this.rolls.push({ body: body.name, contacts: roll.contacts.map((p) => add(o, p)), outward: roll.outward });
    return true;
  }

  /** The straight lines the ends of a turning, unpinned rod slide along (a ladder's wall and
   * floor), read from the measured samples; `away` points from the line to the rod's side. */
  #slides() {
    const out = [], linked = new Set(this.links.map(([, b]) => b));
    for (const [name, shape] of this.shapes) {
      const body = this.bodies.find((b) => b.name === name);
      const run = this.result.sampled?.frames?.[body.frame] ? this.result.sampled : this.result;
      const F = run.frames[body.frame], G = run.positions[name];
      if (shape.kind !== "rod" || linked.has(name) || !G || run.t.length < 3) continue;
      const axis = (i) => F[i].slice(3 * shape.axis, 3 * shape.axis + 3);
      if (!F.some((_, i) => norm(cross(axis(i), axis(0))) > 0.05)) continue; // it must turn
      for (const sign of [-1, 1]) {
        const ends = run.t.map((_, i) => add([G.x[i], G.y[i], G.z[i]], mul(axis(i), sign * shape.half)));
        const reach = Math.max(...ends.map((p) => norm(sub(p, ends[0]))));
        if (reach < 1e-3 * shape.half) continue;
        const dir = unit(sub(ends.find((p) => norm(sub(p, ends[0])) === reach), ends[0]));
        const s = ends.map((p) => dot(sub(p, ends[0]), dir));
        if (ends.some((p, i) => norm(sub(sub(p, ends[0]), mul(dir, s[i]))) > 1e-4 * reach)) continue;
        const g = sub([G.x[0], G.y[0], G.z[0]], ends[0]), across = sub(g, mul(dir, dot(g, dir)));
        if (norm(across) < 1e-9) continue;
        const margin = shape.half / 2;
        out.push({ body: name, origin: ends[0], dir, lo: Math.min(...s) - margin, hi: Math.max(...s) + margin,
          away: unit(across) });
      }
    }
    return out;
  }

  /** A rigid body's outline (rigid.js) in the world at sample i: through G, in its frame. */
  outlineAt(name, i) {
    const shape = this.shapes.get(name), body = this.bodies.find((b) => b.name === name);
    const A = this.axesAt(body.frame, i), g = this.at(name, i);
    return outline(shape, this.wheels.get(name) ?? null)
      .map((p) => add(g, add(mul(A[0], p[0]), add(mul(A[1], p[1]), mul(A[2], p[2])))));
  }

  /** The body's position relative to `anchor`, in the axes of `frame`, at sample i. */
  #relIn(frame, body, anchor, i) {
    const r = sub(this.at(body, i), this.at(anchor, i));
    const f = this.result.frames[frame][i];
    return [dot(r, f.slice(0, 3)), dot(r, f.slice(3, 6)), dot(r, f.slice(6, 9))];
  }

  #samples() {
    const step = Math.max(1, Math.floor(this.n / 300));
    const out = [];
    for (let i = 0; i < this.n; i += step) out.push(i);
    if (out[out.length - 1] !== this.n - 1) out.push(this.n - 1);
    return out;
  }

  #analyze(body) {
    const name = body.name;
    const wire = this.#sweep(body);
    if (wire && this.n < 3) {
      this.#fromSweep(body, wire);
      return;
    }
    const anchor = bodyAnchor(body);
    const idx = this.#samples();
    const frame = positionFrame(body);
    const moving = frame && this.result.frames[frame] && this.P[anchor];
    if (this.P[anchor]) {
      const d = idx.map((i) => norm(sub(this.at(name, i), this.at(anchor, i))));
      const mean = d.reduce((s, v) => s + v, 0) / d.length;
      const constant = mean > 1e-9 && Math.max(...d) - Math.min(...d) <= REL * mean;
      if (moving) {
        const rel = idx.map((i) => this.#relIn(frame, name, anchor, i));
        const still = [0, 1, 2].every((k) => rel.every((r) => Math.abs(r[k] - rel[0][k]) <= REL * (mean || 1)));
        const flat = [0, 1, 2].find((k) => rel.every((r) => Math.abs(r[k]) <= REL * (mean || 1)));
        if (constant && !still && flat !== undefined) {
          this.hoops.push({ body: name, anchor, frame, axes: [0, 1, 2].filter((k) => k !== flat), radius: mean });
          return;
        }
        const spec = (this.spec.frames || []).find((f) => f.name === frame);
        // (a frame that names no parent turns in N: the schema's default)
        const axisIndex = spec && (spec.parent ?? "N") === "N" ? "xyz".indexOf(spec.axis) : -1;
        const radial = rel.every((r) => norm(cross(unit(r), unit(rel[rel.length - 1]))) <= 1e-6);
        if (!constant && !still && axisIndex >= 0 && radial) {
          const r = rel[rel.length - 1];
          const along = r[axisIndex];
          const across = Math.hypot(...r.filter((_, k) => k !== axisIndex));
          if (across > 1e-9 && Math.abs(along) > 1e-9) {
            const length = 1.25 * Math.max(...rel.map(norm));
            this.cones.push({ anchor, frame, axisIndex, sign: Math.sign(along),
              halfAngle: Math.atan2(across, Math.abs(along)), length });
            return;
          }
        }
      }
      if (constant && this.#pinned(body, anchor)) {
        this.links.push([anchor, name]);
        return;
      }
    }
    if (this.#track(body, idx)) return;
    if (wire) this.#fromSweep(body, wire);
    else this.#surface(body);
  }

  /** A straight line in the world (a floor, an incline, a rope): true when it is one. */
  #track(body, idx) {
    if (idx.length < 3) return false;
    const name = body.name;
    const p0 = this.at(name, idx[0]);
    let far = p0, reach = 0;
    for (const i of idx) {
      const d = norm(sub(this.at(name, i), p0));
      if (d > reach) { reach = d; far = this.at(name, i); }
    }
    if (reach < 1e-9) return false; // at rest: the spec's sweep, if any, decides
    const dir = unit(sub(far, p0));
    const s = idx.map((i) => dot(sub(this.at(name, i), p0), dir));
    const off = Math.max(...idx.map((i, k) => norm(sub(sub(this.at(name, i), p0), mul(dir, s[k])))));
    if (off > REL * reach) return false; // not a straight line
    if (this.hasGravity && Math.abs(dot(dir, this.down)) > Math.cos(0.17)) {
      this.#rope(name); // straight up and down: on a rope, never on a vertical "floor"
      return true;
    }
    this.tracks.push({ body: name, origin: p0, dir, lo: Math.min(...s), hi: Math.max(...s) });
    if (body.kind === "rigid_body" && body.frame && this.result.frames[body.frame]) {
      // Rolling: the turn angle follows the distance travelled, s = R * angle. A turn between two
      // samples is only known modulo a full turn, so a wheel that speeds up past half a turn a
      // sample (a disk 5 s down a slope, 30 samples/s) would look slower, i.e. bigger: the
      // radius is read over the stretch from the start where each sample turns < a quarter turn.
      // Read from the measured samples (a run drawn between them has its frames interpolated
      // along the shorter arc, which would hide the aliasing).
      const run = this.result.sampled?.frames?.[body.frame] ? this.result.sampled : this.result;
      const F = run.frames[body.frame], P = run.positions[name];
      const angle = (i) => Math.atan2(F[i][1], F[i][0]);
      const place = (i) => [P.x[i], P.y[i], P.z[i]];
      let turned = 0, travelled = 0;
      for (let i = 1; i < run.t.length; i++) {
        let step = angle(i) - angle(i - 1);
        step -= 2 * Math.PI * Math.round(step / (2 * Math.PI));
        if (Math.abs(step) > Math.PI / 2) break;
        turned += step;
        travelled += dot(sub(place(i), place(i - 1)), dir);
      }
      if (Math.abs(turned) > 1e-6) this.wheels.set(name, Math.abs(travelled / turned));
    }
    return true;
  }

  #rope(name) {
    // A body moving straight up and down below a fixed named point hangs from it by a rope.
    const here = this.at(name, 0);
    const top = this.height(here);
    let best = null, bestGap = Infinity;
    for (const p of this.spec.points || []) {
      if (!this.fixed.has(p.name)) continue;
      const q = this.at(p.name, 0);
      if (this.height(q) <= top) continue;
      const across = sub(sub(here, q), mul(this.down, dot(sub(here, q), this.down)));
      if (norm(across) < bestGap) { best = p.name; bestGap = norm(across); }
    }
    if (!best) return false;
    this.ropes.push({ body: name, point: best });
    this.pulleys.set(best, Math.max(this.pulleys.get(best) || 0, bestGap));
    return true;
  }

  /** Fixed points things hang from or are tied to, with the mean direction of what they hold. */
  #supports() {
    const held = new Map();
    const hold = (p, other) => {
      if (!this.fixed.has(p) || !this.P[other]) return;
      if (!held.has(p)) held.set(p, []);
      held.get(p).push(other);
    };
    for (const [a, b] of this.links) hold(a, b);
    for (const s of [...(this.spec.springs || []), ...(this.spec.dampers || [])]) {
      hold(s.a, s.b);
      hold(s.b, s.a);
    }
    const out = [];
    const idx = this.#samples();
    for (const [p, others] of held) {
      let d = [0, 0, 0];
      for (const o of others) for (const i of idx) d = add(d, unit(sub(this.at(o, i), this.at(p, i))));
      out.push({ point: p, dir: this.#snap(norm(d) > 1e-9 ? unit(d) : this.down) });
    }
    return out;
  }

  /** A support faces straight down when what it holds hangs roughly below it, else the
   * nearest axis: a ceiling or a wall, not a tilted plate. */
  #snap(d) {
    if (this.hasGravity && dot(d, this.down) > Math.cos(1.05)) return this.down;
    const k = [0, 1, 2].reduce((best, j) => (Math.abs(d[j]) > Math.abs(d[best]) ? j : best), 0);
    const out = [0, 0, 0];
    out[k] = Math.sign(d[k]);
    return out;
  }

  /** Named fixed points nothing is attached to (a sun, a pulley): drawn as labelled markers. */
  markers() {
    const used = new Set([...this.supports.map((s) => s.point), ...this.pulleys.keys()]);
    return (this.spec.points || []).map((p) => p.name)
      .filter((n) => this.P[n] && !used.has(n));
  }

  /** The size of the system itself (a wheel's diameter, a rod's length, a hoop's): a camera
   * that follows the motion keeps a few of these in view. 0 when nothing has a size. */
  bodySize() {
    const sizes = [0];
    for (const r of this.wheels.values()) sizes.push(2 * r);
    for (const r of this.pulleys.values()) sizes.push(2 * r);
    for (const h of this.hoops) sizes.push(2 * h.radius);
    for (const [a, b] of this.links) sizes.push(norm(sub(this.at(a, 0), this.at(b, 0))));
    for (const name of this.shapes.keys()) {
      if (this.links.some(([, b]) => b === name)) continue; // a pinned rod's length is its link's
      const pts = this.outlineAt(name, 0);
      sizes.push(Math.max(...pts.map((p) => norm(sub(p, pts[0])))));
    }
    return Math.max(...sizes);
  }

  /** Where a following camera looks at sample i: the middle of the bodies. */
  focus(i) {
    const pts = this.bodies.map((b) => this.at(b.name, i));
    return mul(pts.reduce(add, [0, 0, 0]), 1 / (pts.length || 1));
  }

  /** The named points something is drawn at: the bodies, what they hang from or turn about,
   * spring ends, the spec's own points. The origin O alone, with nothing there, is not one (a
   * disk far down its slope is not shrunk to keep O in view). */
  #drawnPoints() {
    const names = new Set([...this.bodies.map((b) => b.name), ...(this.spec.points || []).map((p) => p.name)]);
    for (const [a] of this.links) names.add(a);
    for (const s of [...(this.spec.springs || []), ...(this.spec.dampers || [])]) names.add(s.a).add(s.b);
    for (const x of [...this.hoops, ...this.cones, ...this.wires, ...this.surfaces]) names.add(x.anchor);
    return names;
  }

  /** World points the view must fit: every position along the run and the drawn extras (the
   * wires and surfaces, swept over the whole run's range, only with `sweeps`). */
  extent(frames = null, sweeps = true) {
    const idx = frames || this.#samples();
    const pts = [];
    const shown = this.#drawnPoints();
    for (const name of Object.keys(this.P)) {
      if (shown.has(name)) for (const i of idx) pts.push(this.at(name, i));
    }
    const around = (c, r) => {
      for (let k = 0; k < 3; k++) {
        const e = [0, 0, 0];
        e[k] = r;
        pts.push(add(c, e), sub(c, e));
      }
    };
    for (const [p, r] of this.pulleys) around(this.at(p, 0), r);
    for (const [b, r] of this.wheels) for (const i of idx) around(this.at(b, i), r);
    for (const h of this.hoops) around(this.at(h.anchor, 0), h.radius);
    const every = Math.max(1, Math.floor(idx.length / 40));
    for (const sf of sweeps ? this.surfaces : []) {
      for (const line of sf.lines) for (const p of this.wireAt({ ...sf, local: line.filter((_, j) => j % 8 === 0) }, idx[0])) pts.push(p);
    }
    for (const w of sweeps ? this.wires : []) {
      for (let k = 0; k < idx.length; k += every) {
        const world = this.wireAt(w, idx[k]);
        for (let j = 0; j < world.length; j += 6) pts.push(world[j]);
      }
    }
    for (const c of this.cones) {
      const apex = this.at(c.anchor, 0);
      const h = c.length * Math.cos(c.halfAngle), r = c.length * Math.sin(c.halfAngle);
      const rim = [0, 0, 0];
      rim[c.axisIndex] = c.sign * h;
      around(add(apex, rim), r);
    }
    for (const r of this.rolls) pts.push(...r.contacts);
    for (const w of this.slides) pts.push(add(w.origin, mul(w.dir, w.lo)), add(w.origin, mul(w.dir, w.hi)));
    const linked = new Set(this.links.map(([, b]) => b));
    for (const name of this.shapes.keys()) {
      if (!linked.has(name)) for (const i of idx) pts.push(...this.outlineAt(name, i));
    }
    for (const [a, b] of this.links) {
      if (this.bodies.find((x) => x.name === b)?.kind !== "rigid_body") continue;
      for (const i of idx) pts.push(sub(mul(this.at(b, i), 2), this.at(a, i))); // the rod's far end
    }
    return pts;
  }
}
