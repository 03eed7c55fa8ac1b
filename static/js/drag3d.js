// Dragging a body in a 3-D view: the coordinates that put it under the pointer, and the rates that
// give it a velocity drawn on the screen. A pointer says two things (where on the screen), a 3-D
// place needs three: the third is the depth the body was grabbed at, i.e. the pointer names a
// point on the plane through the body parallel to the screen (View.unproject). The coordinates
// come from a damped Gauss–Newton (Levenberg–Marquardt) on the scene's own position functions
// (live.js places), like live.js reach does for the plane, but with the residual measured on the
// screen: a body whose constraint cannot reach that plane point (a bob on its sphere, a particle
// on its cone, a bead on its hoop) goes where it is drawn nearest the pointer, its depth a
// tie-breaker weighted DEPTH_WEIGHT of the screen's pixels, so it stays on the branch it was on.
// Nothing is asked of the server: a few dozen position evaluations per pointer move.
import { solveSmall } from "./live.js";

/** How much a pixel of depth change counts against a pixel on the screen. */
const DEPTH_WEIGHT = 0.03;
const ITERATIONS = 40;
/** Coordinates held positive (the spec's positive_coordinates) stay at least this far from 0. */
const FLOOR = 1e-6;

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

/** The body's screen place and weighted depth (pixels) at state y: the residual's pieces. */
function screenOf(live, body, view, y, p, t) {
  const s = view.project(live.places(y, p, t)[body]);
  return [s[0], s[1], DEPTH_WEIGHT * view.scale * s[2]];
}


/** Columns ∂f/∂q_j (central differences) of f(state) → 3-vector; the coordinates whose column
 * is not zero are the ones that move the body. */
function columns(f, y, n) {
  const cols = [];
  for (let j = 0; j < n; j++) {
    const eps = 1e-6 * Math.max(1, Math.abs(y[j]));
    const a = Float64Array.from(y), b = Float64Array.from(y);
    a[j] += eps; b[j] -= eps;
    const fa = f(a), fb = f(b);
    cols.push([0, 1, 2].map((k) => (fa[k] - fb[k]) / (2 * eps)));
  }
  return cols;
}

/** Least squares (JᵀJ + λ·diag) δ = Jᵀ r over the given coordinates; null when singular. */
function normalStep(J, r, free, lambda) {
  const m = free.length;
  const A = Array.from({ length: m }, () => new Float64Array(m));
  const g = new Float64Array(m);
  let scale = 0;
  free.forEach((a, i) => {
    free.forEach((b, j) => { A[i][j] = dot(J[a], J[b]); });
    g[i] = dot(J[a], r);
    scale = Math.max(scale, A[i][i]);
  });
  for (let i = 0; i < m; i++) A[i][i] += lambda * (A[i][i] + 1e-9 * scale) + 1e-12;
  return solveSmall(A, g);
}

/** The coordinates (by index) that move `body` at state y: a drag changes only these. */
export function movers(live, body, y, p) {
  const J = columns((x) => live.places(x, p)[body], y, live.n);
  return J.map((c, j) => (Math.hypot(...c) > 1e-9 ? j : -1)).filter((j) => j >= 0);
}

/**
 * The state (q̇ unchanged) that draws `body` at screen point `at` = [x, y] (the view's CSS
 * pixels) on the plane at `depth` (View.project's third value), or, when its constraint cannot
 * reach that point, as near it on the screen as it can go. Starts from state y and moves only
 * the coordinates that move the body; those listed in `positive` (indices) stay > 0.
 */
export function placeOnScreen(live, body, view, at, depth, y, p, { positive = [] } = {}) {
  const x = Float64Array.from(y);
  const target = [at[0], at[1], DEPTH_WEIGHT * view.scale * depth];
  const f = (state) => screenOf(live, body, view, state, p, 0);
  const cost = (s) => (s[0] - target[0]) ** 2 + (s[1] - target[1]) ** 2 + (s[2] - target[2]) ** 2;
  const keep = new Set(positive);
  let now = f(x), lambda = 1e-3;
  for (let iter = 0; iter < ITERATIONS && cost(now) > 1e-8; iter++) {
    const J = columns(f, x, live.n);
    const free = J.map((c, j) => (Math.hypot(...c) > 1e-9 ? j : -1)).filter((j) => j >= 0);
    if (!free.length) break;
    const r = [0, 1, 2].map((k) => target[k] - now[k]);
    let accepted = false;
    for (let tries = 0; tries < 10 && !accepted; tries++) {
      const delta = normalStep(J, r, free, lambda);
      if (!delta) { lambda *= 10; continue; }
      const trial = Float64Array.from(x);
      free.forEach((j, i) => {
        trial[j] += delta[i];
        if (keep.has(j) && !(trial[j] > FLOOR)) trial[j] = Math.max(FLOOR, x[j] / 2);
      });
      const then = f(trial);
      if (cost(then) < cost(now)) {
        x.set(trial);
        now = then;
        lambda = Math.max(1e-7, lambda / 4);
        accepted = true;
      } else lambda *= 8;
    }
    if (!accepted) break; // nearest reachable: no step makes it nearer
  }
  return x;
}

/**
 * The state whose q̇ gives `body` the velocity `v` (world units per second) as seen on the
 * screen: least squares on v's components along the screen's right and up, the component toward
 * the viewer weighted DEPTH_WEIGHT (a constraint decides it); q unchanged. The velocity a moving
 * constraint gives by itself (a spinning hoop: ∂r/∂t) counts, so the arrow is the body's velocity.
 */
export function velocityOnScreen(live, body, view, v, y, p) {
  const x = Float64Array.from(y);
  const [ex, ey, ez] = view.axes();
  const inCamera = (w) => [dot(w, ex), dot(w, ey), DEPTH_WEIGHT * dot(w, ez)];
  const n = live.n;
  const at = (state, t = 0) => live.places(state, p, t)[body];
  const J = columns((state) => inCamera(at(state)), x, n);
  const free = J.map((c, j) => (Math.hypot(...c) > 1e-9 ? j : -1)).filter((j) => j >= 0);
  if (!free.length) return x;
  const h = 1e-6;
  const a = at(x, h), b = at(x, -h);
  const drift = inCamera([0, 1, 2].map((k) => (a[k] - b[k]) / (2 * h)));
  const want = inCamera(v).map((c, k) => c - drift[k]);
  const qd = normalStep(J, want, free, 0);
  if (qd) free.forEach((j, i) => { x[n + j] = qd[i]; });
  return x;
}
