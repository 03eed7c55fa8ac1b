// A scene at one sample, as flat screen primitives (lines, polygons, circles, arrows, text) that
// render.js draws on a canvas or writes as SVG: the animation, the catalog drawings and the
// free-body diagram all come from here.
import { add, dot, mul, sub } from "./geometry.js";
import { rigidBodyShapes, rollingSurfaceShapes, slideLineShapes } from "./rigid.js";

const INK = "#343a40";
const GROUND = "#868e96";

/** The scene's pieces at sample i. opts: radius (px of the heaviest body), trail (s), path,
 * muted (grey pieces, for the free-body diagram), labels, scaleBar. */
export function sceneShapes(geom, view, i, opts = {}) {
  const o = { radius: 11, trail: 0, path: false, muted: false, labels: true, scaleBar: false, font: 12, ...opts };
  const out = [];
  const P = (name) => view.project(geom.at(name, i));
  const xy = (p) => { const s = view.project(p); return [s[0], s[1]]; };
  const tint = (name) => (o.muted ? "#495057" : geom.color[name]);
  const rad = (name) => o.radius * (geom.size[name] || 1);
  const sliding = new Map(geom.tracks.map((t) => [t.body, t]));
  for (const r of geom.ropes) sliding.set(r.body, { origin: geom.at(r.body, 0), dir: geom.down });

  if (geom.is3D && o.axes !== false) floorAndAxes(geom, view, out);
  grounds(geom, view, rad, out);
  for (const h of geom.hoops) hoop(geom, view, h, i, out);
  for (const r of geom.rolls) {
    const pts = r.contacts.map((p) => view.project(p).slice(0, 2));
    out.push(...rollingSurfaceShapes(pts, r.contacts.map((p, k) => view.direction(p, r.outward[k]))));
  }
  for (const w of geom.slides) {
    const a = view.project(add(w.origin, mul(w.dir, w.lo))).slice(0, 2), b = view.project(add(w.origin, mul(w.dir, w.hi))).slice(0, 2);
    out.push(...slideLineShapes(a, b, view.direction(w.origin, w.away)));
  }
  for (const sf of geom.surfaces) {
    for (const line of sf.lines) {
      const pts = geom.wireAt({ ...sf, local: line }, i).map((p) => view.project(p).slice(0, 2));
      out.push({ t: "poly", pts, color: "#ced4da", width: 1, alpha: 0.9, piece: "surface" });
    }
    spinAround(geom, view, { ...sf, local: sf.lines.flat() }, i, out);
  }
  for (const w of geom.wires) wire(geom, view, w, i, out);
  for (const c of geom.cones) cone(geom, view, c, i, out);
  const occupied = []; // screen boxes a label must not cover: pulleys, bodies, labels placed
  for (const [p, r] of geom.pulleys) {
    const [cx, cy] = P(p);
    const R = r * view.scale;
    out.push({ t: "circle", c: [cx, cy], r: R, color: INK, width: 2, fill: "#f1f3f5" });
    occupied.push([cx - R, cy - R, cx + R, cy + R]);
    out.push({ t: "circle", c: [cx, cy], r: 3, fill: INK });
  }
  for (const r of geom.ropes) {
    const b = geom.at(r.body, i);
    const top = add(b, mul(geom.down, -(geom.height(geom.at(r.point, i)) - geom.height(b))));
    out.push({ t: "line", a: xy(b), b: xy(top), color: "#5c4b37", width: 1.6 });
  }
  if (o.path) for (const b of geom.bodies) path(geom, view, b.name, 0, geom.n - 1, tint(b.name), 0.35, out);
  if (o.trail > 0 && geom.n > 1) {
    const dt = geom.result.t[1] - geom.result.t[0] || 1;
    const span = Math.min(i, Math.round(o.trail / dt));
    for (const b of geom.bodies) fadingTrail(geom, view, b.name, i, span, tint(b.name), out);
  }
  const pairs = new Map();
  const offsetFor = (a, b) => {
    const key = [a, b].sort().join("|");
    const k = pairs.get(key) || 0;
    pairs.set(key, k + 1);
    return k;
  };
  const doubled = new Set([...(geom.spec.springs || []), ...(geom.spec.dampers || [])]
    .map((s) => [s.a, s.b].sort().join("|")).filter((k, n, all) => all.indexOf(k) !== n));
  const elements = []; // [label, middle (px), half-width]: named after the pieces are drawn
  for (const [list, kind, draw, strength] of [[geom.spec.springs, "spring", spring, "k"], [geom.spec.dampers, "damper", damper, "c"]]) {
    for (const s of list || []) {
      if (!geom.P[s.a] || !geom.P[s.b]) continue;
      const two = doubled.has([s.a, s.b].sort().join("|"));
      const shift = two ? (offsetFor(s.a, s.b) ? 1 : -1) * 0.7 * o.radius : 0;
      const amp = two ? 0.45 * o.radius : 6;
      const a = P(s.a), b = P(s.b);
      draw(a, b, shift, amp, o.muted ? "#adb5bd" : "#6c757d", out);
      out[out.length - 1].piece = kind;
      const len = Math.hypot(b[0] - a[0], b[1] - a[1]) || 1;
      const mid = [(a[0] + b[0]) / 2 - ((b[1] - a[1]) / len) * shift, (a[1] + b[1]) / 2 + ((b[0] - a[0]) / len) * shift];
      const name = s.name || (typeof s[strength] === "string" && /^\w+$/.test(s[strength]) ? s[strength] : kind);
      elements.push([name, mid, amp, [-(b[1] - a[1]) / len, (b[0] - a[0]) / len], Math.sign(shift)]);
    }
  }
  for (const [a, b] of geom.links) {
    out.push({ t: "line", a: P(a), b: P(b), color: o.muted ? "#adb5bd" : "#495057", width: 3, cap: "round" });
  }
  for (const s of geom.supports) support(geom, view, s, i, out);
  for (const name of geom.markers()) {
    const [x, y] = P(name);
    out.push({ t: "circle", c: [x, y], r: 6, fill: "#f59f00", color: "#b36b00", width: 1.5 });
    out.push({ t: "text", at: [x + 9, y - 8], text: name, color: "#6c5200", size: o.font, halo: true });
  }
  for (const b of geom.bodies) body(geom, view, b, i, tint(b.name), rad(b.name), sliding.get(b.name), o, out, occupied);
  // the scale bar's corner before the names: they keep clear of it, as it keeps clear of the bodies
  const bar = o.scaleBar && !geom.is3D ? scaleBar(geom, view, i, o, occupied, rad, sliding) : [];
  if (o.labels) {
    const w = view.w, h = view.h;
    for (const b of geom.bodies) {
      const [x, y] = P(b.name);
      const r = Math.max(rad(b.name), geom.wheels.has(b.name) ? geom.wheels.get(b.name) * view.scale : 0);
      placeLabel(out, occupied, [x, y], r, b.name, o.muted ? INK : "#212529", w, h, o.font);
    }
    // springs and dampers by name, clear of the bodies, their names and each other
    // (a spring and a damper side by side are each named on their outer side)
    const size = o.font - 1;
    for (const [, [x, y], amp] of elements) occupied.push([x - amp - 2, y - amp - 2, x + amp + 2, y + amp + 2]);
    for (const [name, mid, amp, n, side] of elements) {
      if (!side) { placeLabel(out, occupied, mid, amp + 2, name, "#6c757d", w, h, size, { optional: true }); continue; }
      const reach = amp + 3 + size * (0.5 + 0.5 * Math.abs(n[0]));
      const c = [mid[0] + n[0] * side * reach, mid[1] + n[1] * side * reach];
      const tw = 0.6 * size * name.length;
      const box = [c[0] - tw / 2, c[1] - size / 2, c[0] + tw / 2, c[1] + size / 2];
      if (occupied.some((o) => box[0] < o[2] && box[2] > o[0] && box[1] < o[3] && box[3] > o[1])) continue;
      if (box[0] < 0 || box[2] > w || box[1] < 0 || box[3] > h) continue;
      out.push({ t: "text", at: [c[0], c[1] + 0.35 * size], text: name, color: "#6c757d", size, halo: true, align: "center" });
      occupied.push(box);
    }
  }
  out.push(...bar);
  return out;
}

function path(geom, view, name, from, to, color, alpha, out) {
  const pts = [];
  const step = Math.max(1, Math.floor((to - from) / 400));
  for (let k = from; k <= to; k += step) pts.push(view.project(geom.at(name, k)).slice(0, 2));
  if (pts.length > 1) out.push({ t: "poly", pts, color, width: 1.5, alpha });
}

function fadingTrail(geom, view, name, i, span, color, out) {
  if (span < 2) return;
  const buckets = 8;
  for (let k = 0; k < buckets; k++) {
    const a = i - span + Math.floor((k * span) / buckets);
    const b = i - span + Math.floor(((k + 1) * span) / buckets);
    const pts = [];
    for (let j = Math.max(0, a); j <= b; j++) pts.push(view.project(geom.at(name, j)).slice(0, 2));
    if (pts.length > 1) out.push({ t: "poly", pts, color, width: 2, alpha: 0.07 + (0.55 * (k + 1)) / buckets });
  }
}

/** Clip the segment a–b to the rectangle [x0, x1] × [y0, y1] (Liang–Barsky); null if outside. */
function clip(a, b, x0, y0, x1, y1) {
  let t0 = 0, t1 = 1;
  const dx = b[0] - a[0], dy = b[1] - a[1];
  for (const [p, q] of [[-dx, a[0] - x0], [dx, x1 - a[0]], [-dy, a[1] - y0], [dy, y1 - a[1]]]) {
    if (p === 0) { if (q < 0) return null; continue; }
    const r = q / p;
    if (p < 0) { if (r > t1) return null; if (r > t0) t0 = r; } else { if (r < t0) return null; if (r < t1) t1 = r; }
  }
  return [[a[0] + t0 * dx, a[1] + t0 * dy], [a[0] + t1 * dx, a[1] + t1 * dy]];
}

/** The floor or incline a body slides along: a line below it, hatched on the far side. */
function grounds(geom, view, rad, out) {
  for (const tr of geom.tracks) {
    if (geom.is3D) continue;
    const wheel = geom.wheels.get(tr.body);
    const rigid = geom.bodies.find((b) => b.name === tr.body).kind === "rigid_body";
    const gap = wheel ? wheel * view.scale : rad(tr.body) * (rigid ? 1.6 : 1.4);
    const margin = 0.5 + 0.15 * (tr.hi - tr.lo);
    const a0 = add(tr.origin, mul(tr.dir, tr.lo - margin));
    const b0 = add(tr.origin, mul(tr.dir, tr.hi + margin));
    const [ax, ay] = view.project(a0), [bx, by] = view.project(b0);
    const len = Math.hypot(bx - ax, by - ay) || 1;
    const d = [(bx - ax) / len, (by - ay) / len];
    let n = [-d[1], d[0]];
    const g = view.direction(tr.origin, geom.down);
    if (n[0] * g[0] + n[1] * g[1] < 0 || (!geom.hasGravity && n[1] < 0)) n = [-n[0], -n[1]];
    const seg = clip([ax + n[0] * gap, ay + n[1] * gap], [bx + n[0] * gap, by + n[1] * gap],
      -20, -20, view.w + 20, view.h + 20);
    if (!seg) continue;
    const [p, q] = seg;
    out.push({ t: "line", a: p, b: q, color: GROUND, width: 2 });
    const L = Math.hypot(q[0] - p[0], q[1] - p[1]);
    // hatches anchored to the world origin, so they scroll when the camera moves
    const zero = view.project([0, 0, 0]);
    const phase = (((p[0] - zero[0]) * d[0] + (p[1] - zero[1]) * d[1]) % 10 + 10) % 10;
    for (let s = 10 - phase; s < L; s += 10) {
      const x = p[0] + d[0] * s, y = p[1] + d[1] * s;
      out.push({ t: "line", a: [x, y], b: [x + n[0] * 7 - d[0] * 5, y + n[1] * 7 - d[1] * 5], color: "#adb5bd", width: 1 });
    }
  }
}

function floorAndAxes(geom, view, out) {
  const c = view.center;
  const key = c.join();
  if (!geom.floor || geom.floor.key !== key) { // once per run and view, not once per frame
    const pts = geom.extent();
    geom.floor = { key, lowest: Math.min(...pts.map((p) => p[1])),
      r: 0.9 * Math.max(...pts.map((p) => Math.hypot(p[0] - c[0], p[2] - c[2])), 0.1) };
  }
  const { lowest, r } = geom.floor;
  if (geom.hasGravity && geom.down[1] > -0.99) return; // a floor only under gravity along −y
  const y = lowest - 0.05 * r;
  for (let k = -3; k <= 3; k++) {
    const s = (k / 3) * r;
    out.push({ t: "line", a: view.project([c[0] + s, y, c[2] - r]), b: view.project([c[0] + s, y, c[2] + r]), color: "#e1e5eb", width: 1 });
    out.push({ t: "line", a: view.project([c[0] - r, y, c[2] + s]), b: view.project([c[0] + r, y, c[2] + s]), color: "#e1e5eb", width: 1 });
  }
  const o = view.project([0, 0, 0]);
  const len = 0.35 * r;
  [["x", [len, 0, 0], "#e03131"], ["y", [0, len, 0], "#2f9e44"], ["z", [0, 0, len], "#1971c2"]]
    .forEach(([label, v, color]) => {
      const p = view.project(v);
      out.push({ t: "arrow", a: o, b: p, color, width: 1.2, head: 6 });
      out.push({ t: "text", at: [p[0] + 4, p[1] - 3], text: label, color, size: 12 });
    });
}

function circle3(view, center, e1, e2, radius, n = 72) {
  const pts = [];
  for (let k = 0; k <= n; k++) {
    const a = (2 * Math.PI * k) / n;
    pts.push(view.project(add(center, add(mul(e1, radius * Math.cos(a)), mul(e2, radius * Math.sin(a))))).slice(0, 2));
  }
  return pts;
}

function hoop(geom, view, h, i, out) {
  const F = geom.result.frames[h.frame][i];
  const axis = (k) => F.slice(3 * k, 3 * k + 3);
  const c = geom.at(h.anchor, i);
  out.push({ t: "poly", pts: circle3(view, c, axis(h.axes[0]), axis(h.axes[1]), h.radius), color: "#868e96", width: 3, alpha: 0.9, piece: "hoop" });
  out.push({ t: "circle", c: view.project(c).slice(0, 2), r: 3, fill: "#868e96" });
  const spin = spinAxis(geom, h.frame);
  if (spin !== null) spinMarks(geom, view, h.frame, spin, c, -1.25 * h.radius, 1.35 * h.radius, 0.25 * h.radius, i, out);
}

/** The curve a bead rides on (swept from its position function), turning with its frame. */
function wire(geom, view, w, i, out) {
  const world = geom.wireAt(w, i);
  const pts = world.map((p) => view.project(p).slice(0, 2));
  out.push({ t: "poly", pts, color: "#868e96", width: 3, alpha: 0.9, cap: "round", closed: w.closed, piece: "wire" });
  spinAround(geom, view, w, i, out);
}

/** The spin axis of the frame a wire or surface turns with, through its anchor, as long as the
 * curve reaches along it (and a bit more). */
function spinAround(geom, view, w, i, out) {
  const axis = spinAxis(geom, w.frame);
  if (axis === null) return;
  const along = w.local.map((p) => p[axis]);
  const lo = Math.min(0, ...along), hi = Math.max(0, ...along);
  const size = Math.max(hi - lo, ...w.local.map((p) => Math.hypot(...p.filter((_, k) => k !== axis))), 1e-6);
  spinMarks(geom, view, w.frame, axis, geom.at(w.anchor, i), lo - 0.15 * size, hi + 0.25 * size, 0.15 * size, i, out);
}

/** The index (0, 1, 2) of the axis a frame turns about, when it turns; else null. */
function spinAxis(geom, frame) {
  if (!frame || !geom.frameSpins(frame) || !(geom.result.frames || {})[frame]) return null;
  const spec = (geom.spec.frames || []).find((f) => f.name === frame);
  const k = spec ? "xyz".indexOf(spec.axis) : -1;
  return k >= 0 ? k : null;
}

/** A frame's spin axis (dashed, from lo to hi along it through `origin`) and an arrow around
 * it near the top that turns the way the frame turns. */
function spinMarks(geom, view, frame, axis, origin, lo, hi, r, i, out) {
  const A = geom.axesAt(frame, i);
  const e = A[axis], e1 = A[(axis + 1) % 3], e2 = A[(axis + 2) % 3];
  out.push({ t: "line", a: view.project(add(origin, mul(e, lo))), b: view.project(add(origin, mul(e, hi))),
    color: "#adb5bd", width: 1.5, dash: [6, 4], piece: "axis" });
  let sense = 1;
  if (geom.n > 1) { // which way the frame turns: e1 moves toward e2 or away
    const j = i + 1 < geom.n ? i + 1 : i - 1;
    const B = geom.axesAt(frame, j);
    sense = Math.sign(dot(sub(B[(axis + 1) % 3], e1), e2) * (j > i ? 1 : -1)) || 1;
  }
  const c = add(origin, mul(e, hi - 0.4 * r));
  const arc = [];
  for (let k = 0; k <= 24; k++) {
    const a = sense * (0.25 + (1.4 * Math.PI * k) / 24);
    arc.push(view.project(add(c, add(mul(e1, r * Math.cos(a)), mul(e2, r * Math.sin(a))))).slice(0, 2));
  }
  out.push({ t: "poly", pts: arc.slice(0, -1), color: "#868e96", width: 1.5, piece: "spin" });
  out.push({ t: "arrow", a: arc[arc.length - 3], b: arc[arc.length - 1], color: "#868e96", width: 1.5, head: 7 });
}

function cone(geom, view, c, i, out) {
  const apex = geom.at(c.anchor, i);
  const axis = [0, 0, 0]; axis[c.axisIndex] = c.sign;
  const e1 = [0, 0, 0]; e1[(c.axisIndex + 1) % 3] = 1;
  const e2 = [0, 0, 0]; e2[(c.axisIndex + 2) % 3] = 1;
  const h = c.length * Math.cos(c.halfAngle), r = c.length * Math.sin(c.halfAngle);
  const rim = add(apex, mul(axis, h));
  out.push({ t: "poly", pts: circle3(view, rim, e1, e2, r), color: "#adb5bd", width: 1.5 });
  out.push({ t: "poly", pts: circle3(view, add(apex, mul(axis, h / 2)), e1, e2, r / 2), color: "#dee2e6", width: 1 });
  for (let k = 0; k < 12; k++) {
    const a = (2 * Math.PI * k) / 12;
    const end = add(rim, add(mul(e1, r * Math.cos(a)), mul(e2, r * Math.sin(a))));
    out.push({ t: "line", a: view.project(apex), b: view.project(end), color: "#dee2e6", width: 1 });
  }
  out.push({ t: "line", a: view.project(apex), b: view.project(add(apex, mul(axis, 1.15 * h))), color: "#adb5bd", width: 1, dash: [6, 4] });
}

function spring(a, b, shift, amp, color, out) {
  const dx = b[0] - a[0], dy = b[1] - a[1], len = Math.hypot(dx, dy) || 1;
  const nx = -dy / len, ny = dx / len;
  const s = [a[0] + nx * shift, a[1] + ny * shift], e = [b[0] + nx * shift, b[1] + ny * shift];
  const coils = 9, lead = Math.min(10, 0.12 * len);
  const pts = [[a[0], a[1]], s, [s[0] + (dx / len) * lead, s[1] + (dy / len) * lead]];
  const inner = len - 2 * lead;
  for (let k = 1; k < 2 * coils; k++) {
    const f = (lead + (inner * k) / (2 * coils)) / len, side = k % 2 ? amp : -amp;
    pts.push([s[0] + dx * f + nx * side, s[1] + dy * f + ny * side]);
  }
  pts.push([e[0] - (dx / len) * lead, e[1] - (dy / len) * lead], e, [b[0], b[1]]);
  out.push({ t: "poly", pts, color, width: 1.8 });
}

function damper(a, b, shift, w, color, out) {
  // A dashpot: a rod from a into an open cylinder, a piston rod out to b.
  const dx = b[0] - a[0], dy = b[1] - a[1], len = Math.hypot(dx, dy) || 1;
  const ux = dx / len, uy = dy / len, nx = -uy, ny = ux;
  const at = (f, side = 0) => [a[0] + nx * shift + dx * f + nx * side, a[1] + ny * shift + dy * f + ny * side];
  const c0 = Math.max(0.2, 0.5 - 2.2 * w / len), c1 = Math.min(0.8, 0.5 + 2.2 * w / len);
  out.push({ t: "poly", pts: [[a[0], a[1]], at(0), at(c0)], color, width: 1.8 });
  out.push({ t: "poly", pts: [at(c1, w), at(c0, w), at(c0, -w), at(c1, -w)], color, width: 1.8 });
  const piston = (c0 + c1) / 2;
  out.push({ t: "line", a: at(piston, 0.7 * w), b: at(piston, -0.7 * w), color, width: 2.5 });
  out.push({ t: "poly", pts: [at(piston), at(1), [b[0], b[1]]], color, width: 1.8 });
}

function support(geom, view, s, i, out) {
  // A fixed wall or ceiling across the direction of what it holds, hatched behind; a hinge pin.
  const [x, y] = view.project(geom.at(s.point, i));
  const d = view.direction(geom.at(s.point, i), s.dir);
  if (!d[0] && !d[1]) return;
  const n = [-d[1], d[0]], half = 20;
  out.push({ t: "line", a: [x - n[0] * half, y - n[1] * half], b: [x + n[0] * half, y + n[1] * half], color: INK, width: 2.5, piece: "support" });
  for (let k = -half + 4; k <= half; k += 6) {
    const px = x + n[0] * k, py = y + n[1] * k;
    out.push({ t: "line", a: [px, py], b: [px - d[0] * 7 - n[0] * 5, py - d[1] * 7 - n[1] * 5], color: "#868e96", width: 1 });
  }
  if (geom.links.some(([a]) => a === s.point)) {
    out.push({ t: "circle", c: [x, y], r: 4, fill: "#fff", color: INK, width: 2 });
  }
}

function body(geom, view, b, i, color, r, track, o, out, occupied) {
  const c = geom.at(b.name, i);
  const [x, y] = view.project(c);
  const frames = geom.result.frames || {};
  if (b.kind === "rigid_body") {
    const link = geom.links.find(([, n]) => n === b.name);
    if (link) { // a rod pivoted at its anchor: drawn from the pivot through its centre to the far end
      const [ax, ay] = view.project(geom.at(link[0], i));
      out.push({ t: "line", a: [ax, ay], b: [2 * x - ax, 2 * y - ay], color, width: o.muted ? 6 : 9, cap: "round", alpha: o.muted ? 0.5 : 1 });
      out.push({ t: "circle", c: [x, y], r: 3.5, fill: "#fff", color: INK, width: 1.5 });
      occupied.push([x - 6, y - 6, x + 6, y + 6]);
      return;
    }
    const shape = geom.shapes.get(b.name);
    if (shape && (shape.kind !== "disk" || !geom.wheels.has(b.name))) { // its own outline, through G
      out.push(...rigidBodyShapes(shape, geom.outlineAt(b.name, i).map((p) => view.project(p).slice(0, 2)), [x, y], color, o.muted));
      occupied.push([x - 6, y - 6, x + 6, y + 6]);
      return;
    }
    const R = geom.wheels.has(b.name) ? geom.wheels.get(b.name) * view.scale : 1.6 * r;
    out.push({ t: "circle", c: [x, y], r: R, fill: color + "22", color, width: 2.5 });
    if (frames[b.frame]) {
      const F = frames[b.frame][i];
      for (const k of [0, 1]) {
        const e = view.direction(c, F.slice(3 * k, 3 * k + 3));
        out.push({ t: "line", a: [x - e[0] * R, y - e[1] * R], b: [x + e[0] * R, y + e[1] * R], color, width: 1.5, alpha: 0.8 });
      }
    }
    out.push({ t: "circle", c: [x, y], r: 3, fill: color });
    occupied.push([x - R, y - R, x + R, y + R]);
    return;
  }
  if (track && !geom.is3D) { // a block sliding along its track, sitting on it
    const d = view.direction(track.origin, track.dir);
    let n = [-d[1], d[0]];
    const g = view.direction(c, geom.down);
    if (n[0] * g[0] + n[1] * g[1] < 0 || (!geom.hasGravity && n[1] < 0)) n = [-n[0], -n[1]];
    const s = 1.4 * r;
    const pts = [[-1, -1], [1, -1], [1, 1], [-1, 1]].map(([u, v]) => [x + d[0] * u * s + n[0] * v * s, y + d[1] * u * s + n[1] * v * s]);
    out.push({ t: "poly", pts, fill: color, color: o.muted ? INK : shade(color), width: 1.5, closed: true });
  } else {
    const f = view.project(c)[3];
    out.push({ t: "circle", c: [x, y], r: r * Math.min(1.3, Math.max(0.7, f)), fill: color, color: o.muted ? INK : shade(color), width: 1.5 });
  }
  const half = track && !geom.is3D ? 1.4 * r : r;
  occupied.push([x - half, y - half, x + half, y + half]);
}

function shade(hex) {
  const v = parseInt(hex.slice(1), 16);
  const c = [(v >> 16) & 255, (v >> 8) & 255, v & 255].map((x) => Math.round(x * 0.7));
  return `rgb(${c.join(",")})`;
}

/**
 * Put a label beside a point where it overlaps nothing placed before (or the first try).
 * opts: `optional` (a spring's name: left out when there is no free spot), `width` (px, when
 * known better than from the character count), `toward` (a unit screen direction, an arrow's:
 * first try the spot just beyond its tip).
 */
export function placeLabel(out, occupied, [x, y], r, text, color, w, h, size = 12, opts = {}) {
  // the box a rendered label takes: its ascent above the baseline, `below` under it (the
  // descent, and a subscript's drop when there is one)
  const tw = opts.width ?? 0.6 * size * text.length, th = size, below = opts.below ?? 3;
  const g = r + 4;
  const tries = [[g, -g], [g, g + th * 0.6], [-g - tw, -g], [-g - tw, g + th * 0.6], [-tw / 2, -g - 4], [-tw / 2, g + th]];
  if (opts.toward) {
    const [dx, dy] = opts.toward;
    tries.unshift([dx * (g + tw / 2) - tw / 2, dy * (g + (th + below) / 2) + th / 2]);
  }
  // then farther out, in eight directions, before giving up on a free spot
  for (let k = 1; k <= 5; k++) {
    for (let a = 0; a < 8; a++) {
      const ux = Math.cos((a * Math.PI) / 4), uy = -Math.sin((a * Math.PI) / 4);
      const cx = x + ux * (g + 9 * k + (tw / 2) * Math.abs(ux)), cy = y + uy * (g + 9 * k + (th / 2) * Math.abs(uy));
      tries.push([cx - tw / 2 - x, cy + th / 2 - y]);
    }
  }
  let pick = null;
  for (const [dx, dy] of tries) {
    const box = [x + dx, y + dy - th, x + dx + tw, y + dy + below];
    if (box[0] < 0 || box[2] > w || box[1] < 0 || box[3] > h) continue;
    if (occupied.some((o) => box[0] < o[2] && box[2] > o[0] && box[1] < o[3] && box[3] > o[1])) continue;
    pick = box;
    break;
  }
  if (!pick && opts.optional) return;
  if (!pick) {
    const left = Math.min(Math.max(0, x + g), w - tw), top = Math.min(Math.max(0, y - g - th), h - th - below);
    pick = [left, top, left + tw, top + th + below];
  }
  occupied.push(pick);
  out.push({ t: "text", at: [pick[0], pick[3] - below], text, color, size, halo: true });
}

/** Where the scale bar goes, per run and view: geom -> Map(view -> [length index, corner index]). */
const BAR_PLACES = new WeakMap();

/** The bar's lengths on the screen, longest first: a shorter one where the long one would cover a
 * body (a chaotic double pendulum's bob reaches every corner of a lecture canvas). */
const BAR_PX = [110, 60, 35];

/**
 * A bar of a round length in a corner: the bottom-left one, or the first corner (then the middle
 * of the left or right edge) where neither the bar nor its label covers a body (at lecture size
 * the label is 25 px) at any instant of the run, chosen once per run and view so it never jumps;
 * a shorter bar where no place is free for a long one; where none is free for the whole run, a
 * place clear of the bodies at each frame. Chosen per frame, the corner free at the first frame was covered later (the Atwood
 * machine's lower block sat on "1 m" at t = 0.89 s on a lecture canvas). A camera that follows
 * the motion moves every body on the screen from frame to frame: there the corner is chosen per
 * frame, clear of what is drawn now. Returns the shapes.
 */
function scaleBar(geom, view, i, o, occupied, rad, sliding) {
  const size = o.font - 1;
  const layouts = BAR_PX.map((target) => barLayout(view, size, target));
  // a camera that follows the motion looks at the bodies' middle at every frame (draw.js)
  const following = String(view.center) === String(geom.focus(i));
  const overlaps = (b, c) => b[0] < c[2] && b[2] > c[0] && b[1] < c[3] && b[3] > c[1];
  const nowFree = () => { // clear of what is drawn at this frame: the longest bar that has a place
    for (const [n, { boxes }] of layouts.entries()) {
      const k = boxes.slice(0, following ? -1 : undefined).findIndex((b) => !occupied.some((c) => overlaps(b, c)));
      if (k >= 0) return [n, k];
    }
    return [0, 0];
  };
  const [n, k] = (following ? null : runPlace(geom, view, o, layouts.map((l) => l.boxes), rad, sliding)) || nowFree();
  const { px, label, boxes } = layouts[n];
  const box = boxes[k];
  occupied.push(box);
  const x = box[0], y = box[3] - 4;
  return [
    { t: "poly", pts: [[x, y - 5], [x, y], [x + px, y], [x + px, y - 5]], color: "#868e96", width: 1.5 },
    { t: "text", at: [x + px + 6, y + 1], text: label, color: "#6c757d", size },
  ];
}

/** A bar of a round length near `target` px: its length, label, and its box in each corner, the
 * top-left one last (a following camera's note is written there: scaleBar never takes it then). */
function barLayout(view, size, target) {
  const metres = target / view.scale;
  const p = 10 ** Math.floor(Math.log10(metres));
  const nice = [1, 2, 5, 10].map((k) => k * p).filter((v) => v <= metres).pop() || p;
  const px = nice * view.scale;
  const label = nice >= 1 ? `${nice} m` : nice >= 0.01 ? `${Math.round(nice * 100)} cm` : `${nice} m`;
  const width = px + 6 + 0.6 * size * label.length;
  const middle = (view.h + size) / 2;
  const corners = [[14, view.h - 14], [view.w - 14 - width, view.h - 14], [view.w - 14 - width, 14 + size],
    [14, middle], [view.w - 14 - width, middle], [14, 14 + size]];
  return { px, label, boxes: corners.map(([x, y]) => [x, y - Math.max(size, 5), x + width, y + 4]) };
}

/** [length, corner]: the first bar length with a corner no body covers at any sample of the run
 * (each body as drawn: its disc, a sliding block's 1.4× half-width, a wheel's rim; the pulleys),
 * and its first such corner; null when every place is covered at some sample. */
function runPlace(geom, view, o, layouts, rad, sliding) {
  let views = BAR_PLACES.get(geom);
  if (!views) BAR_PLACES.set(geom, (views = new Map()));
  const key = [view.w, view.h, view.scale, view.center, o.radius, o.font].join("|");
  if (views.has(key)) return views.get(key);
  const boxes = layouts.flat();
  const hits = boxes.map(() => 0);
  const overlaps = (b, c) => b[0] < c[2] && b[2] > c[0] && b[1] < c[3] && b[3] > c[1];
  for (const [p, r] of geom.pulleys) {
    const [cx, cy] = view.project(geom.at(p, 0));
    const R = r * view.scale;
    boxes.forEach((b, k) => { if (overlaps(b, [cx - R, cy - R, cx + R, cy + R])) hits[k] = Infinity; });
  }
  const halves = geom.bodies.map((b) => {
    const r = rad(b.name);
    const wheel = geom.wheels.has(b.name) ? geom.wheels.get(b.name) * view.scale : 0;
    return [b.name, Math.max(sliding.has(b.name) ? 1.4 * r : r, wheel)];
  });
  for (let i = 0; i < geom.n; i++) {
    for (const [name, half] of halves) {
      const [x, y] = view.project(geom.at(name, i));
      boxes.forEach((b, k) => { if (overlaps(b, [x - half, y - half, x + half, y + half])) hits[k] += 1; });
    }
  }
  const per = layouts[0].length;
  const k = hits.indexOf(0);
  // covered somewhere whatever the length and place (a chaotic bob sweeps a small canvas): a
  // place per frame, clear of the bodies where they are now
  const choice = k < 0 ? null : [Math.floor(k / per), k % per];
  views.set(key, choice);
  return choice;
}
