// The live preview: the scene's equations stepped in the browser, so the motion follows a slider
// while it moves and a body dragged on the canvas swings from where it is dropped, with no server
// round trip. The equations are the server's own, printed as JavaScript from the derivation
// (mechanics/jscode.py, GET /api/v1/scenes/{id}/live); the stepping is a fixed-step RK4 here, so
// what it shows is a preview: the server's run (the measured one, with its method and tolerance)
// replaces it when the slider is let go, and only the server's run feeds the integrator panel,
// the plots and compare mode.
import { getJSON, postJSON } from "./api.js";

/** Substeps of RK4 per output sample at 60 fps: h = 1/600 s keeps a pendulum's preview within
 * ~1e-6 of the reference over 10 s, and costs a few ms. */
const SUBSTEPS = 10;
/** Past this many RK4 steps a preview is coarser rather than slower (a long t_end). */
const MAX_STEPS = 60000;
export const PREVIEW_LABEL = "live preview (browser RK4)";

export class LiveModel {
  /** The scene's module and its slots' names; null when the server has none for it. `meta`:
   * the slots' names the page already carries (templates/scene.html), which saves asking /live;
   * its module is then preloaded by the page too. */
  static async load(sceneId, meta = null) {
    meta ||= await getJSON(`/api/v1/scenes/${encodeURIComponent(sceneId)}/live`);
    const mod = await import(meta.module);
    return new LiveModel(meta, mod);
  }

  /** The same for a spec of one's own (the editor): printed by the server's worker pool. */
  static async forSpec(spec) {
    const meta = await postJSON("/api/v1/scenes/live", { scene: spec });
    const mod = await import(meta.module);
    return new LiveModel(meta, mod);
  }

  constructor(meta, mod) {
    this.meta = meta;
    this.mod = mod;
    this.n = mod.dims.n;
    this.dim = 2 * this.n + mod.dims.extras;
  }

  /** Parameters in slot order from the page's {name: value}. */
  paramVector(params) {
    return Float64Array.from(this.meta.parameters, (k) => Number(params[k]));
  }

  /** y0 = [q, q̇, 0…] from the page's {q: value, q_dot: value}. */
  state(initial) {
    const y = new Float64Array(this.dim);
    this.meta.coordinates.forEach((q, i) => {
      y[i] = Number(initial[q]) || 0;
      y[this.n + i] = Number(initial[`${q}_dot`]) || 0;
    });
    return y;
  }

  /** Every point's position at state y: {name: [x, y, z]}. */
  places(y, p, t = 0) {
    const out = new Float64Array(3 * this.meta.points.length);
    this.mod.places(t, y, p, out);
    return Object.fromEntries(this.meta.points.map((k, i) => [k, [out[3 * i], out[3 * i + 1], out[3 * i + 2]]]));
  }

  /**
   * A run in the server's shape (t, q, q_dot, positions, frames, energy, stats), stepped by RK4
   * from `initial` with `params`, sampled at `fps` up to `tEnd`. It ends early, and says so,
   * when the state stops being finite or the mass matrix turns singular.
   */
  run({ params, initial, tEnd, fps = 60 }) {
    const started = performance.now();
    const { n, dim, mod, meta } = this;
    const p = this.paramVector(params);
    const samples = Math.max(2, Math.floor(tEnd * fps + 1e-9) + 1);
    const dtOut = 1 / fps;
    const sub = Math.max(1, Math.min(SUBSTEPS, Math.floor(MAX_STEPS / samples)));
    const h = dtOut / sub;
    let y = this.state(initial);
    const k1 = new Float64Array(dim), k2 = new Float64Array(dim), k3 = new Float64Array(dim), k4 = new Float64Array(dim);
    const tmp = new Float64Array(dim);
    const ys = [Float64Array.from(y)], ts = [0];
    let t = 0, status = "ok", evaluations = 0, stop = null;
    const f = (time, state, out) => { evaluations++; return mod.rhs(time, state, p, out); };
    const watch = new StopWatch(this, p);
    stop = watch.atStart(y);
    if (stop) status = "stopped";
    outer: for (let s = 1; s < samples && !stop; s++) {
      for (let j = 0; j < sub; j++) {
        let bad = f(t, y, k1);
        for (let i = 0; i < dim; i++) tmp[i] = y[i] + 0.5 * h * k1[i];
        bad |= f(t + 0.5 * h, tmp, k2);
        for (let i = 0; i < dim; i++) tmp[i] = y[i] + 0.5 * h * k2[i];
        bad |= f(t + 0.5 * h, tmp, k3);
        for (let i = 0; i < dim; i++) tmp[i] = y[i] + h * k3[i];
        bad |= f(t + h, tmp, k4);
        const next = new Float64Array(dim);
        let finite = true;
        for (let i = 0; i < dim; i++) {
          next[i] = y[i] + (h / 6) * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
          if (!Number.isFinite(next[i])) finite = false;
        }
        if (bad || !finite) { status = bad ? "singular" : "diverged"; break outer; }
        const tNext = (s - 1) * dtOut + (j + 1) * h;
        stop = watch.step(t, tNext, next);
        y = next;
        t = tNext;
        if (stop) { // the preview ends where the model stops holding, as the server's run does
          status = "stopped";
          ys.push(Float64Array.from(y));
          ts.push(stop.t);
          break outer;
        }
      }
      t = s * dtOut;
      ys.push(Float64Array.from(y));
      ts.push(t);
    }
    return this.#shape(ys, ts, p, { status, evaluations, steps: Math.max(0, ts.length - 1) * sub, h, started, stop });
  }

  #shape(ys, t, p, { status, evaluations, steps, h, started, stop }) {
    const { n, mod, meta } = this;
    const count = ys.length;
    const q = {}, qd = {};
    meta.coordinates.forEach((name, i) => {
      q[name] = ys.map((y) => y[i]);
      qd[name] = ys.map((y) => y[n + i]);
    });
    const positions = Object.fromEntries(meta.points.map((k) => [k, { x: new Array(count), y: new Array(count), z: new Array(count) }]));
    const frames = Object.fromEntries(meta.frames.map((k) => [k, new Array(count)]));
    const place = new Float64Array(3 * meta.points.length), axes = new Float64Array(9 * meta.frames.length);
    const e = new Float64Array(2);
    const T = new Array(count), V = new Array(count), E = new Array(count), Wnc = new Array(count);
    for (let s = 0; s < count; s++) {
      mod.places(t[s], ys[s], p, place);
      meta.points.forEach((k, i) => {
        positions[k].x[s] = place[3 * i]; positions[k].y[s] = place[3 * i + 1]; positions[k].z[s] = place[3 * i + 2];
      });
      if (meta.frames.length) {
        mod.axes(t[s], ys[s], p, axes);
        meta.frames.forEach((k, i) => { frames[k][s] = Array.from(axes.subarray(9 * i, 9 * i + 9)); });
      }
      mod.energy(t[s], ys[s], p, e);
      T[s] = e[0]; V[s] = e[1]; E[s] = e[0] + e[1]; Wnc[s] = ys[s][2 * n];
    }
    return {
      t, q, q_dot: qd, positions, frames,
      energy: { T, V, E, W_nc: Wnc, W_drive: new Array(count).fill(0) },
      stats: {
        method: PREVIEW_LABEL, preview: true, status, steps, rhs_evaluations: evaluations, step: h,
        wall_time: (performance.now() - started) / 1000, samples: count, ...(stop ? { stop } : {}),
      },
      warnings: status === "ok" || status === "stopped" ? [] : [`The live preview stopped early (${status}).`],
    };
  }

  /** ∂(place of `body`)/∂q_j for every coordinate j, by central differences: 3 × n. */
  jacobian(body, y, p) {
    const cols = [];
    for (let j = 0; j < this.n; j++) {
      const eps = 1e-6 * Math.max(1, Math.abs(y[j]));
      const a = Float64Array.from(y), b = Float64Array.from(y);
      a[j] += eps; b[j] -= eps;
      const ra = this.places(a, p)[body], rb = this.places(b, p)[body];
      cols.push([0, 1, 2].map((k) => (ra[k] - rb[k]) / (2 * eps)));
    }
    return cols; // cols[j][k] = ∂r_k/∂q_j
  }

  /**
   * The coordinates that put `body` nearest to `target` (world x, y; z kept), starting from the
   * state `y`: damped Gauss–Newton on |r(q) − target|² over the coordinates that move the body
   * (the others stay put). Returns a new state vector with q̇ unchanged.
   */
  reach(body, target, y, p, { planar = true } = {}) {
    const x = Float64Array.from(y);
    const axes = planar ? [0, 1] : [0, 1, 2];
    for (let iter = 0; iter < 20; iter++) {
      const r = this.places(x, p)[body];
      const J = this.jacobian(body, x, p);
      const free = J.map((c, j) => (Math.hypot(...axes.map((k) => c[k])) > 1e-9 ? j : -1)).filter((j) => j >= 0);
      if (!free.length) break;
      const res = axes.map((k) => target[k] - r[k]);
      if (Math.hypot(...res) < 1e-10) break;
      // Normal equations (JᵀJ + λI) δ = Jᵀ res over the free coordinates (λ keeps a reach past
      // the body's range, or a singular pose, from jumping).
      const m = free.length;
      const A = Array.from({ length: m }, () => new Float64Array(m));
      const g = new Float64Array(m);
      let scale = 0;
      free.forEach((a, i) => {
        free.forEach((b, j) => { A[i][j] = axes.reduce((s, k) => s + J[a][k] * J[b][k], 0); });
        g[i] = axes.reduce((s, k) => s + J[a][k] * res[k], 0);
        scale = Math.max(scale, A[i][i]);
      });
      for (let i = 0; i < m; i++) A[i][i] += 1e-9 * scale + 1e-12;
      const delta = solveSmall(A, g);
      if (!delta) break;
      let step = 1;
      const before = Math.hypot(...res);
      for (let tries = 0; tries < 12; tries++) {
        const trial = Float64Array.from(x);
        free.forEach((j, i) => { trial[j] += step * delta[i]; });
        const rt = this.places(trial, p)[body];
        if (Math.hypot(...axes.map((k) => target[k] - rt[k])) <= before) {
          x.set(trial);
          break;
        }
        step /= 2;
      }
      if (step < 1e-3) break;
    }
    return x;
  }

  /** q̇ that gives `body` the velocity `v` (least squares over the coordinates that move it). */
  velocityFor(body, v, y, p, { planar = true } = {}) {
    const x = Float64Array.from(y);
    const axes = planar ? [0, 1] : [0, 1, 2];
    const J = this.jacobian(body, x, p);
    const free = J.map((c, j) => (Math.hypot(...axes.map((k) => c[k])) > 1e-9 ? j : -1)).filter((j) => j >= 0);
    const m = free.length;
    if (!m) return x;
    const A = Array.from({ length: m }, () => new Float64Array(m));
    const g = new Float64Array(m);
    let scale = 0;
    free.forEach((a, i) => {
      free.forEach((b, j) => { A[i][j] = axes.reduce((s, k) => s + J[a][k] * J[b][k], 0); });
      g[i] = axes.reduce((s, k) => s + J[a][k] * v[k], 0);
      scale = Math.max(scale, A[i][i]);
    });
    for (let i = 0; i < m; i++) A[i][i] += 1e-9 * scale + 1e-12;
    const qd = solveSmall(A, g);
    if (qd) free.forEach((j, i) => { x[this.n + j] = qd[i]; });
    return x;
  }
}

/**
 * The scene's stop conditions watched after every RK4 step (mechanics/stops.py's rule, without
 * its event location: the preview ends at the step where a value crosses 0, its time placed by
 * the secant). A stop applies where its guard is not < 0; a value turning undefined stops too.
 */
class StopWatch {
  constructor(model, p) {
    this.model = model;
    this.p = p;
    this.count = model.mod.dims.stops || 0;
    this.before = new Float64Array(2 * this.count);
    this.now = new Float64Array(2 * this.count);
  }

  #info(k, t) {
    const s = this.model.meta.stops[k] || { name: `stop ${k}`, message: "a stop condition" };
    return { name: s.name, message: s.message, t };
  }

  /** A 'falls' stop already at or past 0 ends the preview at t = 0 (the server refuses or
   * stops such a start, and says which). */
  atStart(y) {
    if (!this.count) return null;
    this.model.mod.stops(0, y, this.p, this.before);
    for (let k = 0; k < this.count; k++) {
      const v = this.before[2 * k], guard = this.before[2 * k + 1];
      const falls = (this.model.meta.stops[k] || {}).crossing !== "any";
      if (falls && !(v > 0) && !(guard < 0)) return this.#info(k, 0);
    }
    return null;
  }

  step(t0, t1, y) {
    if (!this.count) return null;
    this.model.mod.stops(t1, y, this.p, this.now);
    let hit = null;
    for (let k = 0; k < this.count && !hit; k++) {
      const before = this.before[2 * k], now = this.now[2 * k], guard = this.now[2 * k + 1];
      const applies = !(guard < 0);
      const falls = (this.model.meta.stops[k] || {}).crossing !== "any";
      const crossed = Number.isNaN(now) ? !Number.isNaN(before)
        : falls ? before > 0 && now <= 0 && applies
          : Math.sign(before) !== Math.sign(now) && before !== 0 && applies;
      if (crossed) {
        const at = Number.isFinite(before - now) && before !== now ? t1 - (now * (t1 - t0)) / (now - before) : t1;
        hit = this.#info(k, Math.min(t1, Math.max(t0, at)));
      }
    }
    this.before.set(this.now);
    return hit;
  }
}

/** Gaussian elimination with partial pivoting on a small dense system; null when singular. */
export function solveSmall(A, b) {
  const n = b.length;
  const a = A.map((row) => Float64Array.from(row));
  const x = Float64Array.from(b);
  for (let c = 0; c < n; c++) {
    let piv = c;
    for (let r = c + 1; r < n; r++) if (Math.abs(a[r][c]) > Math.abs(a[piv][c])) piv = r;
    if (!(Math.abs(a[piv][c]) > 0)) return null;
    [a[c], a[piv]] = [a[piv], a[c]];
    [x[c], x[piv]] = [x[piv], x[c]];
    for (let r = c + 1; r < n; r++) {
      const m = a[r][c] / a[c][c];
      for (let j = c; j < n; j++) a[r][j] -= m * a[c][j];
      x[r] -= m * x[c];
    }
  }
  for (let r = n - 1; r >= 0; r--) {
    let s = x[r];
    for (let j = r + 1; j < n; j++) s -= a[r][j] * x[j];
    x[r] = s / a[r][r];
  }
  return x;
}

/** Screen (CSS pixels on the canvas) to world, for a planar view: the inverse of View.project. */
export function unproject(view, sx, sy, z = 0) {
  return [view.center[0] + (sx - view.w / 2) / view.scale, view.center[1] - (sy - view.h / 2) / view.scale, z];
}

/**
 * A server run sampled at `fps` shown at `factor` × fps: between two samples, points on the line
 * between them (positions, energies, coordinates; each frame axis renormalised). The server is
 * asked for half the samples (half the bytes a visit costs, ~107 → 54 kB gzipped for a double
 * pendulum over 10 s) and the animation still moves every display frame at 60 fps. What is drawn
 * between samples is an interpolation of the measured run, said so under the canvas; the plots,
 * the panel and the work table use the samples themselves.
 */
export function forDisplay(run, factor = 2) {
  const t = run.t, n = t.length;
  if (!run || n < 2 || factor <= 1) return run;
  const idx = []; // [i, fraction] for every displayed sample
  for (let i = 0; i < n - 1; i++) for (let k = 0; k < factor; k++) idx.push([i, k / factor]);
  idx.push([n - 1, 0]);
  const lerp = (arr) => idx.map(([i, f]) => (f === 0 ? arr[i] : arr[i] + f * (arr[i + 1] - arr[i])));
  const each = (obj, fn) => Object.fromEntries(Object.entries(obj || {}).map(([k, v]) => [k, fn(v)]));
  const axes = (rows) => idx.map(([i, f]) => {
    if (f === 0) return rows[i];
    const m = rows[i].map((v, j) => v + f * (rows[i + 1][j] - v));
    for (let a = 0; a < 9; a += 3) {
      const len = Math.hypot(m[a], m[a + 1], m[a + 2]) || 1;
      m[a] /= len; m[a + 1] /= len; m[a + 2] /= len;
    }
    return m;
  });
  return {
    ...run,
    t: lerp(t),
    q: each(run.q, lerp),
    q_dot: each(run.q_dot, lerp),
    positions: each(run.positions, (p) => ({ x: lerp(p.x), y: lerp(p.y), z: lerp(p.z) })),
    frames: each(run.frames, axes),
    energy: each(run.energy, (e) => (Array.isArray(e) ? lerp(e) : e)),
    stats: { ...run.stats, display_factor: factor },
    sampled: run, // the run as measured
  };
}
