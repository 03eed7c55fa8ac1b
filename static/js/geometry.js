// What a scene looks like, read from its spec and one simulated run: which bodies hang on rods,
// which slide along a straight track (a floor, an incline), which hang on a rope from a pulley,
// which ride a spinning hoop or a cone, how big a rolling wheel is, where the supports are.
// Nothing here is scene-specific: every drawing decision is inferred from the data.

export const COLORS = ["#1f6feb", "#d9480f", "#2f9e44", "#9c36b5", "#e8590c", "#0c8599"];
const REL = 1e-6; // relative tolerance for "constant" along a run

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

/** A number for a mass given as a parameter name or a numeral; 1 when it is an expression. */
function massValue(mass, parameters) {
  if (typeof mass === "number") return mass;
  if (mass in parameters) return parameters[mass];
  const x = Number(mass);
  return Number.isFinite(x) ? x : 1;
}

export class SceneGeometry {
  constructor(spec, result, parameters = spec.parameters || {}) {
    this.spec = spec;
    this.result = result;
    this.P = result.positions;
    this.n = result.t.length;
    this.bodies = spec.bodies.filter((b) => this.P[b.name]);
    const g = spec.gravity ? [...spec.gravity.direction, 0].slice(0, 3) : null;
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
    for (const b of this.bodies) this.#analyze(b);
    this.supports = this.#supports();
  }

  at(name, i) {
    const p = this.P[name];
    return [p.x[i], p.y[i], p.z[i]];
  }

  height(point) {
    return -dot(point, this.down);
  }

  #isFixed(name) {
    const p = this.P[name];
    return ["x", "y", "z"].every((c) => {
      const v = p[c], v0 = v[0];
      return v.every((x) => Math.abs(x - v0) <= 1e-12 * (1 + Math.abs(v0)));
    });
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
        const axisIndex = spec && spec.parent === "N" ? "xyz".indexOf(spec.axis) : -1;
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
      if (constant) {
        this.links.push([anchor, name]);
        return;
      }
    }
    this.#track(body, idx);
  }

  #track(body, idx) {
    if (idx.length < 3) return;
    const name = body.name;
    const p0 = this.at(name, idx[0]);
    let far = p0, reach = 0;
    for (const i of idx) {
      const d = norm(sub(this.at(name, i), p0));
      if (d > reach) { reach = d; far = this.at(name, i); }
    }
    if (reach < 1e-9) return;
    const dir = unit(sub(far, p0));
    const s = idx.map((i) => dot(sub(this.at(name, i), p0), dir));
    const off = Math.max(...idx.map((i, k) => norm(sub(sub(this.at(name, i), p0), mul(dir, s[k])))));
    if (off > REL * reach) return; // not a straight line
    if (this.hasGravity && Math.abs(dot(dir, this.down)) > Math.cos(0.17)) {
      this.#rope(name); // straight up and down: on a rope, never on a vertical "floor"
      return;
    }
    this.tracks.push({ body: name, origin: p0, dir, lo: Math.min(...s), hi: Math.max(...s) });
    if (body.kind === "rigid_body" && body.frame && this.result.frames[body.frame]) {
      // Rolling: the turn angle follows the distance travelled, s = R * angle.
      const F = this.result.frames[body.frame];
      const ang = [];
      for (const i of idx) {
        let a = Math.atan2(F[i][1], F[i][0]);
        if (ang.length) a += 2 * Math.PI * Math.round((ang[ang.length - 1] - a) / (2 * Math.PI));
        ang.push(a);
      }
      const turned = ang[ang.length - 1] - ang[0];
      if (Math.abs(turned) > 1e-6) this.wheels.set(name, Math.abs((s[s.length - 1] - s[0]) / turned));
    }
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

  /** World points the view must fit: every position along the run and the drawn extras. */
  extent(frames = null) {
    const idx = frames || this.#samples();
    const pts = [];
    for (const name of Object.keys(this.P)) for (const i of idx) pts.push(this.at(name, i));
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
    for (const c of this.cones) {
      const apex = this.at(c.anchor, 0);
      const h = c.length * Math.cos(c.halfAngle), r = c.length * Math.sin(c.halfAngle);
      const rim = [0, 0, 0];
      rim[c.axisIndex] = c.sign * h;
      around(add(apex, rim), r);
    }
    for (const [a, b] of this.links) {
      if (this.bodies.find((x) => x.name === b)?.kind !== "rigid_body") continue;
      for (const i of idx) pts.push(sub(mul(this.at(b, i), 2), this.at(a, i))); // the rod's far end
    }
    return pts;
  }
}
