// A rigid body's own shape, read from its central inertia in its frame: a body that is not pinned
// anywhere (a ladder sliding down a wall, a cylinder rolling inside a cylinder) is drawn as what it
// is, through its centre G and turning with its frame, never as a rod from an invented pivot.
// Nothing here knows the world: geometry.js places the outline, shapes.js draws it.
import { compile } from "./expr.js";

const CIRCLE = 48; // points round a drawn disk

/** The other two axis indices, in order. */
const others = (k) => [0, 1, 2].filter((j) => j !== k);

/**
 * The shape the inertia implies, with its sizes in the body frame, or null when it implies none
 * (products of inertia, a solid body, a value that cannot be read). A moment that vanishes with
 * the other two equal is a slender rod (I = m L²/12 across it); a moment that is the sum of the
 * other two (the perpendicular-axis theorem) is a flat plate: a uniform disk when the two are
 * equal (I = m a²/2 about its axis), else a rectangle (I = m b²/12 about each side's axis).
 */
export function rigidShape(body, parameters) {
  const inertia = body.inertia;
  if (!inertia) return null;
  const value = (x) => {
    const f = compile(x ?? 0);
    return f ? f(parameters) : NaN;
  };
  const m = value(body.mass);
  const d = [inertia.ixx, inertia.iyy, inertia.izz].map(value);
  const products = [inertia.ixy, inertia.iyz, inertia.izx].map(value);
  const big = Math.max(...d);
  if (!(m > 0) || !(big > 0) || ![...d, ...products].every(Number.isFinite)) return null;
  const tol = 1e-6 * big;
  if (products.some((p) => Math.abs(p) > tol)) return null;
  const thin = [0, 1, 2].filter((k) => Math.abs(d[k]) <= tol);
  if (thin.length === 1) {
    const [a, b] = others(thin[0]);
    if (Math.abs(d[a] - d[b]) > tol) return null;
    return { kind: "rod", axis: thin[0], half: Math.sqrt((12 * d[a]) / m) / 2 };
  }
  for (const k of [0, 1, 2]) {
    const [a, b] = others(k);
    if (Math.abs(d[k] - d[a] - d[b]) > tol) continue;
    if (Math.abs(d[a] - d[b]) <= tol) return { kind: "disk", normal: k, radius: Math.sqrt((2 * d[k]) / m) };
    const halves = [0, 0, 0];
    halves[a] = Math.sqrt((12 * d[b]) / m) / 2;
    halves[b] = Math.sqrt((12 * d[a]) / m) / 2;
    return { kind: "plate", normal: k, halves };
  }
  return null;
}

/** The shape's outline as points in the body frame, from G: a rod's two ends, a disk's rim
 * (radius `radius` when given: a rolling disk's, read from its motion), a plate's corners. */
export function outline(shape, radius = null) {
  const at = (pairs) => {
    const p = [0, 0, 0];
    for (const [k, v] of pairs) p[k] = v;
    return p;
  };
  if (shape.kind === "rod") return [at([[shape.axis, -shape.half]]), at([[shape.axis, shape.half]])];
  const [a, b] = others(shape.normal);
  if (shape.kind === "disk") {
    const r = radius ?? shape.radius;
    return Array.from({ length: CIRCLE + 1 }, (_, k) => {
      const angle = (2 * Math.PI * k) / CIRCLE;
      return at([[a, r * Math.cos(angle)], [b, r * Math.sin(angle)]]);
    });
  }
  const [ha, hb] = [shape.halves[a], shape.halves[b]];
  return [[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]].map(([u, v]) => at([[a, u * ha], [b, v * hb]]));
}

/**
 * Where a disk turning about N.z rolls, along its centre's swept path G(q) with its frame's angle
 * φ(q): the instantaneous centre of rotation, G + ẑ × (dG/dq) / (dφ/dq), is the contact point; it
 * rolls when that point stays on the rim (one distance ρ all along, near the inertia's radius).
 * Returns {radius: ρ, contacts, outward} (points from the sweep's origin, and unit vectors from G
 * to each contact), or null when it does not roll (it slides, or the point wanders).
 */
export function rollingContacts(values, place, angle, radius) {
  const contacts = [], outward = [];
  let lo = Infinity, hi = 0;
  for (const v of values) {
    const h = 1e-5 * (1 + Math.abs(v));
    const a = place(v - h), b = place(v + h);
    const dG = [0, 1, 2].map((k) => (b[k] - a[k]) / (2 * h));
    const dphi = (angle(v + h) - angle(v - h)) / (2 * h);
    if (!Number.isFinite(dphi) || Math.abs(dphi) < 1e-9 || Math.abs(dG[2]) > 1e-9 * Math.hypot(...dG)) return null;
    const off = [-dG[1] / dphi, dG[0] / dphi, 0];
    const rho = Math.hypot(...off);
    lo = Math.min(lo, rho);
    hi = Math.max(hi, rho);
    const g = place(v);
    contacts.push([g[0] + off[0], g[1] + off[1], g[2]]);
    outward.push([off[0] / rho, off[1] / rho, 0]);
  }
  if (!contacts.length || !(hi - lo <= 1e-4 * hi) || hi < 0.7 * radius || hi > 1.5 * radius) return null;
  return { radius: hi, contacts, outward };
}

/** The shapes of a rigid body drawn by its own outline (world points `pts` at this sample) through
 * its centre (screen [x, y]): a thick rod, or a tinted disk or plate. */
export function rigidBodyShapes(shape, pts, [x, y], color, muted) {
  const out = [];
  if (shape.kind === "rod") {
    out.push({ t: "line", a: pts[0], b: pts[1], color, width: muted ? 6 : 9, cap: "round", alpha: muted ? 0.5 : 1, piece: "rigid-rod" });
    out.push({ t: "circle", c: [x, y], r: 3.5, fill: "#fff", color: "#343a40", width: 1.5 });
  } else {
    out.push({ t: "poly", pts, fill: color + "22", color, width: 2.5, closed: true, piece: `rigid-${shape.kind}` });
    out.push({ t: "circle", c: [x, y], r: 3, fill: color });
  }
  return out;
}

/** The surface a disk rolls on at screen points `pts` (outward: screen unit vectors away from the
 * disk): a grey line, hatched on the far side. */
export function rollingSurfaceShapes(pts, outward) {
  const out = [{ t: "poly", pts, color: "#868e96", width: 2, piece: "rolling-surface" }];
  let since = Infinity;
  for (let k = 1; k < pts.length; k++) {
    since += Math.hypot(pts[k][0] - pts[k - 1][0], pts[k][1] - pts[k - 1][1]);
    if (since < 10) continue;
    since = 0;
    const [x, y] = pts[k], [nx, ny] = outward[k];
    out.push({ t: "line", a: [x, y], b: [x + nx * 7 - ny * 5, y + ny * 7 + nx * 5], color: "#adb5bd", width: 1 });
  }
  return out;
}

/** A line a rod's end slides on, from screen point a to b, hatched on the side away from the rod
 * (`toRod`: the screen unit vector toward it). */
export function slideLineShapes(a, b, toRod) {
  const out = [{ t: "line", a, b, color: "#868e96", width: 2, piece: "slide-line" }];
  const len = Math.hypot(b[0] - a[0], b[1] - a[1]) || 1, d = [(b[0] - a[0]) / len, (b[1] - a[1]) / len];
  for (let s = 5; s < len; s += 10) {
    const x = a[0] + d[0] * s, y = a[1] + d[1] * s;
    out.push({ t: "line", a: [x, y], b: [x - toRod[0] * 7 - d[0] * 5, y - toRod[1] * 7 - d[1] * 5], color: "#adb5bd", width: 1 });
  }
  return out;
}
