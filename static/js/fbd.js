// The free-body diagram at the current instant: the scene drawn faintly, and on every body each
// force of the run (`forces` of /simulate: weight F_g, spring, damper, applied) as a labelled
// arrow, plus the constraint forces (dashed), named and placed as the derivation's FBD step says
// (`constraint_forces` of its data: a rod's tension F_T, a normal force F_N, static friction F_f at
// a rolling contact, a pin reaction F_pin at the pin), sized by Newton's F_C = m a − ΣF of the run.
// Arrows are to scale: one px-per-newton for the whole diagram (`arrowLengths`), the largest force
// MAX_ARROW px long; only a force too small to see is drawn at MIN_ARROW px, and the legend says so.
// The legend is decided once per run (`runLegend`): it must not change height while the run plays.
import { SceneGeometry } from "./geometry.js";
import { toSVG } from "./render.js";
import { placeLabel, sceneShapes } from "./shapes.js";
import { View } from "./view.js";

export const FORCE_COLORS = {
  weight: "#2f9e44", spring: "#9c36b5", damper: "#e8590c", force: "#1971c2", torque: "#0c8599",
  constraint: "#495057", potential: "#c2255c",
};
const W = 440;
/** Length (px) of the diagram's largest force; every other arrow is shorter in proportion. */
export const MAX_ARROW = 72;
/** A shorter arrow would be all head (10 px): such a force is drawn this long, and named so. */
export const MIN_ARROW = 12;
const analysed = new WeakMap(); // result -> its SceneGeometry: the diagram redraws often

let measurer = null;
/** The width (px) of a label's text as the diagram sets it (italic, semi-bold), measured: an
 * estimate from the character count puts "damper" on top of its neighbour. */
function textWidth(text, px) {
  if (!text) return 0;
  measurer = measurer || document.createElement("canvas").getContext("2d");
  measurer.font = `italic 600 ${px}px system-ui, sans-serif`;
  return measurer.measureText(text).width;
}

/** `\vec{F}_{\text{spring}}` → {text: "F", sub: "spring"}; `\vec{F}_{g,\text{bob}}` → {text: "F",
 * sub: "g,bob"}. */
export function labelParts(latex) {
  const m = latex.match(/^\s*(?:\\vec\{([^}]*)\}|([A-Za-z]+))\s*(?:_(\{(?:[^{}]|\{[^{}]*\})*\}|\w))?/);
  const bare = (x) => x.replace(/\\(?:text|mathrm)\{/g, "").replace(/[\\{}]/g, "");
  if (!m) return { text: bare(latex), sub: "" };
  return { text: bare(m[1] || m[2] || ""), sub: bare(m[3] || "") };
}

/** Arrow lengths (px) for force magnitudes (N): one scale for all, the largest MAX_ARROW long;
 * a force that would be shorter than MIN_ARROW is drawn at MIN_ARROW and marked `short`.
 * Zero (or negligible) forces get length 0: they are not drawn. */
export function arrowLengths(sizes) {
  const biggest = Math.max(...sizes, 1e-12);
  const pxPerNewton = MAX_ARROW / biggest;
  const arrows = sizes.map((size) => {
    if (!(size >= 1e-9 * biggest)) return { length: 0, short: false };
    const length = size * pxPerNewton;
    return length < MIN_ARROW ? { length: MIN_ARROW, short: true } : { length, short: false };
  });
  return { pxPerNewton, arrows };
}

/** Draw into `svg` for sample i; `angles` are the stage's 3-D yaw and pitch; `placed` is the
 * data of the derivation's FBD step (where each constraint force acts and what it is called). */
export function drawFBD(svg, spec, result, parameters, i, angles = {}, placed = null) {
  if (!svg || !result) return;
  let geom = analysed.get(result);
  if (!geom || geom.spec !== spec) {
    geom = new SceneGeometry(spec, result, parameters);
    analysed.set(result, geom);
  }
  i = Math.max(0, Math.min(geom.n - 1, i));
  let H = 330;
  if (!geom.is3D) { // a flat scene gets a flat diagram
    const pts = geom.extent();
    const span = (k) => Math.max(...pts.map((p) => p[k])) - Math.min(...pts.map((p) => p[k]));
    H = Math.round(Math.min(330, Math.max(250, (span(1) / Math.max(span(0), 1e-9)) * (W - 160) + 160)));
  }
  svg.setAttribute("viewBox", `0 0 ${W} ${H}`);
  const view = new View(W, H, geom.is3D);
  if (geom.is3D) Object.assign(view, { yaw: angles.yaw ?? view.yaw, pitch: angles.pitch ?? view.pitch });
  view.fit(geom.extent([i]), 78);
  const px = labelSize(svg);
  const shapes = sceneShapes(geom, view, i, { radius: 8, muted: true, labels: false, axes: false });
  const arrows = arrowsAt(spec, result, parameters, i, placed);
  const kinds = new Set();
  const biggest = Math.max(...arrows.map((a) => a.size), 1e-12);
  const scale = arrowLengths(arrows.map((a) => a.size));
  const lengths = new Map(arrows.map((a, k) => [a, scale.arrows[k]]));
  const short = []; // labels of the forces drawn at the minimum length
  const measured = []; // {label, on, size, length}: what the diagram drew, for tests and readers
  const occupied = [];
  const used = new Set();
  const drawn = []; // [body, direction]: arrows alike in direction are drawn side by side
  const labels = []; // {tip, d, text, sub, color}: placed once all arrows are drawn
  const bodyBoxes = geom.bodies.map((b) => { // what each body covers on the drawing
    const [x, y] = view.project(geom.at(b.name, i));
    const half = bodyHalf(geom, view, b.name);
    return [x - half, y - half, x + half, y + half];
  });
  // labels keep off a body; a wheel's face (drawn faintly, large) may carry them, its centre not
  occupied.push(...bodyBoxes.map((b, k) => {
    if (!geom.wheels?.has(geom.bodies[k].name)) return b;
    const cx = (b[0] + b[2]) / 2, cy = (b[1] + b[3]) / 2;
    return [cx - 12, cy - 12, cx + 12, cy + 12];
  }));
  for (const f of arrows) {
    if (f.size < 1e-9 * biggest || !result.positions[f.on]) continue;
    const p = f.at || geom.at(f.on, i);
    const [x, y] = view.project(p);
    const color = FORCE_COLORS[f.kind] || FORCE_COLORS.force;
    kinds.add(f.kind);
    if (f.kind === "torque") {
      shapes.push(...torqueArc([x, y], Math.sign(f.z) || 1, color));
    } else {
      const d = view.direction(p, [f.x / f.size, f.y / f.size, f.z / f.size]);
      if (!d[0] && !d[1]) continue;
      const { length: len, short: tiny } = lengths.get(f);
      const where = String(p.map((v) => v.toFixed(6)));
      const alike = drawn.filter(([at, e]) => at === where && e[0] * d[0] + e[1] * d[1] > 0.94).length;
      drawn.push([where, d]);
      const side = alike ? (alike % 2 ? 1 : -1) * 8 * Math.ceil(alike / 2) : 0;
      // from the body's edge, not its centre: a short arrow (friction, a push) lay under the body
      // drawn over its foot (issue 26, item 5); slid along its own line, its line of action stays
      // (a force at a contact point, f.at, already starts on the body's surface)
      const centre = geom.P[f.on] ? geom.at(f.on, i) : null;
      const contact = f.at && !(centre && f.at.every((v, k) => Math.abs(v - centre[k]) <= 1e-9 * (1 + Math.abs(v))));
      const own = contact ? null : geom.bodies.findIndex((b) => b.name === f.on);
      const foot = own === null || own < 0 ? [x - d[1] * side, y + d[0] * side]
        : clearOf(bodyBoxes[own], [x - d[1] * side, y + d[0] * side], d, geom.wheels?.has(f.on));
      const tip = [foot[0] + d[0] * len, foot[1] + d[1] * len];
      shapes.push({ t: "arrow", a: foot, b: tip, color, width: 2.5, head: 10, dash: f.dashed ? [5, 3] : undefined });
      // the arrow itself is taken: no label of another force may sit on it
      for (let s = 4; s <= len; s += 6) {
        const px = foot[0] + d[0] * s, py = foot[1] + d[1] * s;
        occupied.push([px - 3, py - 3, px + 3, py + 3]);
      }
      const { text, sub } = f.symbol ? { text: f.symbol[0], sub: f.symbol[1] } : labelParts(f.label);
      measured.push({ label: sub ? `${text}_${sub}` : text, on: f.on, size: f.size, length: len, short: tiny,
        foot: foot.map((v) => Number(v.toFixed(1))), tip: tip.map((v) => Number(v.toFixed(1))) });
      if (tiny && !short.includes(sub ? `${text}_${sub}` : text)) short.push(sub ? `${text}_${sub}` : text);
      const key = `${text}_${sub}@${f.on}`;
      if (used.has(key)) continue;
      used.add(key);
      labels.push({ tip, d, text, sub, color });
    }
  }
  // labels after every arrow is down, each just beyond its arrow's tip where that is free
  for (const { tip, d, text, sub, color } of labels) {
    const before = shapes.length;
    const width = 1.06 * (textWidth(text, px) + textWidth(sub, px * 0.75)) + 3;
    const below = (sub ? 7 : 4) * (px / 13);
    placeLabel(shapes, occupied, tip, 3, text + sub, color, W, H, px, { width, toward: d, below });
    const label = shapes[before];
    Object.assign(label, { text, sub, italic: true, weight: 600 });
  }
  for (const b of geom.bodies) {
    const [x, y] = view.project(geom.at(b.name, i));
    const size = px === 13 ? 11 : px; // in lecture mode as large as the forces' names
    const width = 1.06 * textWidth(b.name, size) + 3;
    placeLabel(shapes, occupied, [x, y], 10, b.name, "#495057", W, H, size, { width, below: 0.3 * size });
  }
  shapes.push({ t: "text", at: [8, H - 8], text: `t = ${result.t[i].toFixed(2)} s`, color: "#6c757d", size: 11 });
  svg.innerHTML = toSVG(shapes);
  svg.dataset.frame = String(i);
  svg.dataset.arrows = String(arrows.filter((a) => a.size >= 1e-9 * biggest).length);
  svg.dataset.scale = JSON.stringify({ px_per_newton: scale.pxPerNewton, arrows: measured });
  svg.dataset.bodies = JSON.stringify(bodyBoxes.map((b, k) => ({ name: geom.bodies[k].name,
    box: b.map((v) => Number(v.toFixed(1))), wheel: Boolean(geom.wheels?.has(geom.bodies[k].name)) })));
  const named = arrows.filter((a) => a.kind === "constraint" && a.size >= 1e-9 * biggest);
  svg.dataset.constraints = JSON.stringify(named.map(({ name, on, at, x, y, z, what }) =>
    ({ name, on, what, at: at || geom.at(on, i), centre: geom.at(on, i), force: [x, y, z] })));
  // the legend's content is the run's, not this instant's (`runLegend`)
  const run = runLegend(spec, result, parameters, placed);
  const legend = new Set(run.kinds);
  legend.constraints = run.constraints;
  legend.short = run.short;
  legend.now = { kinds: [...kinds], short };
  return legend;
}

/** Half the size (px) of the square a body covers on the diagram: its drawn radius (a block is
 * drawn a little wider than a bob), a wheel its rim, and a pixel of margin; at least 12. */
function bodyHalf(geom, view, name) {
  const r = 8 * (geom.size[name] || 1);
  const wheel = geom.wheels?.has(name) ? geom.wheels.get(name) * view.scale : 0;
  return Math.max(12, 1.45 * r + 2, wheel + 2);
}

/** `foot` moved along `d` until it is out of the body's `box` (a wheel: out of its rim, the
 * circle in the box), one pixel beyond; a foot outside stays. */
function clearOf(box, foot, d, round = false) {
  const [x, y] = foot;
  const cx = (box[0] + box[2]) / 2, cy = (box[1] + box[3]) / 2, half = (box[2] - box[0]) / 2;
  let t;
  if (round) { // |foot + t d − c| = half, the larger root
    const ox = x - cx, oy = y - cy, b = ox * d[0] + oy * d[1], c = ox * ox + oy * oy - half * half;
    if (c >= 0) return foot;
    t = -b + Math.sqrt(b * b - c);
  } else {
    if (!(x > box[0] && x < box[2] && y > box[1] && y < box[3])) return foot;
    t = Math.min(...[0, 1].map((k) => (d[k] > 1e-9 ? (box[k + 2] - foot[k]) / d[k]
      : d[k] < -1e-9 ? (box[k] - foot[k]) / d[k] : Infinity)));
  }
  if (!Number.isFinite(t)) return foot;
  return [x + d[0] * (t + 1), y + d[1] * (t + 1)];
}

/** The lecture hall's least label size (CSS px on screen): lecture mode enlarges a drawing's labels
 * to it after the drawing is done, so they are placed at that size here, where overlaps are avoided. */
const LECTURE_LABEL_PX = 24;

/** Font size (svg units) of a force's label: 13, or in lecture mode as large as the hall needs. */
function labelSize(svg) {
  const lecture = typeof document !== "undefined" && document.body?.classList?.contains("lecture");
  const shown = lecture && svg.getBoundingClientRect ? svg.getBoundingClientRect().width : 0;
  if (!shown) return 13;
  return Math.max(13, Math.ceil((LECTURE_LABEL_PX * W * 100) / shown) / 100);
}

/** Every force of sample i as the diagram draws it (constraint forces, potentials' forces too). */
function arrowsAt(spec, result, parameters, i, placed) {
  const arrows = forcesAt(result, i, placed, parameters);
  arrows.push(...potentialForces(spec, result, parameters, i, arrows));
  return arrows;
}

const legends = new WeakMap(); // result -> {placed, parameters, legend}

/** What the legend says for a whole run: the kinds of force drawn at any instant, the constraint
 * forces named, and the forces too small to draw to scale at some instant (over every sample).
 * Decided per instant it came and went as the run played, and the page jumped in height. */
export function runLegend(spec, result, parameters, placed) {
  const known = legends.get(result);
  if (known && known.placed === placed && known.parameters === parameters && known.spec === spec) {
    return known.legend;
  }
  const kinds = new Set(), constraints = new Set(), short = new Map();
  const n = result.t?.length || 0;
  for (let i = 0; i < n; i++) {
    const arrows = arrowsAt(spec, result, parameters, i, placed).filter((a) => result.positions[a.on]);
    const biggest = Math.max(...arrows.map((a) => a.size), 1e-12);
    const scale = arrowLengths(arrows.map((a) => a.size));
    arrows.forEach((f, k) => {
      if (f.size < 1e-9 * biggest) return;
      kinds.add(f.kind);
      if (f.kind === "constraint") constraints.add(f.name);
      if (f.kind === "torque" || !scale.arrows[k].short) return;
      const { text, sub } = f.symbol ? { text: f.symbol[0], sub: f.symbol[1] } : labelParts(f.label);
      short.set(sub ? `${text}_${sub}` : text, [text, sub]);
    });
  }
  const legend = { kinds: [...kinds], constraints: [...constraints], short: [...short.values()] };
  legends.set(result, { placed, parameters, spec, legend });
  return legend;
}

function forcesAt(result, i, placed, parameters) {
  const out = (result.forces || []).map((f) => {
    const x = f.x[i], y = f.y[i], z = f.z[i];
    return { label: f.label, kind: f.kind, on: f.on, x, y, z, size: f.kind === "torque" ? 0 : Math.hypot(x, y, z) };
  });
  return out.concat(constraintForcesAt(result, i, placed, parameters));
}

/** The constraint forces at sample i, each where it acts. Newton's R = m a − ΣF of a body is
 * the sum of its constraint forces; the FBD step says how it splits: the pulls of the rods that
 * hang from the body, then the rest (a rod's tension toward its anchor, a normal force, at a
 * rolling contact F_N across the surface and F_f along it). Without that data (an old derivation)
 * the whole F_C is drawn at the body, named only as a resultant. */
export function constraintForcesAt(result, i, placed, parameters = {}) {
  const R = result.constraint_forces || {};
  const total = (on) => (R[on] ? [R[on].x[i], R[on].y[i], R[on].z[i]] : null);
  const entries = (placed?.bodies || []).flatMap((b) => b.constraint_forces || []);
  if (!placed?.bodies?.some((b) => b.constraint_forces)) {
    return Object.keys(R).map((on) => arrow({ name: "F_C", symbol: ["F", `C,${on}`], on,
      what: `resultant of the constraint forces on ${on}` }, total(on)));
  }
  const vars = { ...parameters, t: result.t[i] };
  for (const [q, v] of Object.entries(result.q || {})) vars[q] = v[i];
  for (const [q, v] of Object.entries(result.q_dot || {})) vars[`${q}_dot`] = v[i];
  const place = (name) => {
    const p = result.positions[name];
    return p ? [p.x[i], p.y[i], p.z[i]] : null;
  };
  const at = (e) => (typeof e.at === "string" ? place(e.at) : e.at.map((c) => evalPlain(c, vars)));
  const toward = (from, to) => unit(sub3(place(to), place(from)));
  const tension = (rodBody) => { // the rod's own tension, read off the body at its far end
    const own = entries.find((e) => e.on === rodBody && e.part === "rest" && e.toward);
    return own ? dot3(rest(rodBody), toward(rodBody, own.toward)) : NaN;
  };
  const pull = (e) => scale3(toward(e.on, e.rod), tension(e.rod));
  const rest = (on) => entries.filter((e) => e.on === on && e.part === "pull")
    .reduce((r, e) => sub3(r, pull(e)), total(on));
  const out = [];
  for (const e of entries) {
    if (!total(e.on)) continue;
    let v;
    if (e.part === "pull") v = pull(e);
    else {
      v = rest(e.on);
      const u = e.along ? e.along.map((c) => evalPlain(c, vars)) : e.toward ? toward(e.on, e.toward) : null;
      if (u) v = scale3(u, dot3(v, u));
    }
    if (v.every(Number.isFinite)) out.push(arrow(e, v, at(e)));
  }
  return out;
}

function arrow(e, [x, y, z], at = null) {
  return { label: e.label || "", symbol: e.symbol, name: e.name, what: e.what, kind: "constraint", on: e.on,
    at: at && at.every(Number.isFinite) ? at : null, x, y, z, size: Math.hypot(x, y, z), dashed: true };
}

const sub3 = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot3 = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const scale3 = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const unit = (a) => scale3(a, 1 / (Math.hypot(...a) || 1));

const FUNCS = { sin: Math.sin, cos: Math.cos, tan: Math.tan, asin: Math.asin, acos: Math.acos,
  atan: Math.atan, atan2: Math.atan2, sinh: Math.sinh, cosh: Math.cosh, tanh: Math.tanh,
  sqrt: Math.sqrt, exp: Math.exp, log: Math.log, Abs: Math.abs, sign: Math.sign,
  cot: (x) => 1 / Math.tan(x), sec: (x) => 1 / Math.cos(x), csc: (x) => 1 / Math.sin(x) };
const CONSTS = { pi: Math.PI, E: Math.E };
const compiled = new Map();

/** The value of a plain-text expression as the engine prints it (`x*cos(alpha) + R**2/2`):
 * numbers, names from `vars`, + − * / ** ^, parentheses and the usual functions; NaN otherwise. */
export function evalPlain(src, vars) {
  if (!compiled.has(src)) compiled.set(src, compile(String(src)));
  const fn = compiled.get(src);
  return fn ? fn(vars) : NaN;
}

function compile(src) {
  const toks = src.match(/\d+\.?\d*(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?|[A-Za-z_]\w*|\*\*|[-+*/^(),]|\S/g) || [];
  let k = 0;
  const fail = () => { throw new Error(`cannot read ${src}`); };
  const eat = (t) => (toks[k] === t ? (k++, true) : false);
  const sum = () => {
    let f = product();
    for (;;) {
      if (eat("+")) { const a = f, b = product(); f = (v) => a(v) + b(v); }
      else if (eat("-")) { const a = f, b = product(); f = (v) => a(v) - b(v); }
      else return f;
    }
  };
  const product = () => {
    let f = unary();
    for (;;) {
      if (eat("*")) { const a = f, b = unary(); f = (v) => a(v) * b(v); }
      else if (eat("/")) { const a = f, b = unary(); f = (v) => a(v) / b(v); }
      else return f;
    }
  };
  const unary = () => {
    if (eat("-")) { const a = unary(); return (v) => -a(v); }
    if (eat("+")) return unary();
    const base = atom();
    if (eat("**") || eat("^")) { const e = unary(); return (v) => base(v) ** e(v); }
    return base;
  };
  const atom = () => {
    const t = toks[k++];
    if (t === undefined) fail();
    if (t === "(") { const f = sum(); if (!eat(")")) fail(); return f; }
    if (/^[\d.]/.test(t)) { const x = Number(t); return () => x; }
    if (!/^[A-Za-z_]/.test(t)) fail();
    if (eat("(")) {
      const fn = FUNCS[t] || fail();
      const args = [sum()];
      while (eat(",")) args.push(sum());
      if (!eat(")")) fail();
      return (v) => fn(...args.map((a) => a(v)));
    }
    if (t in CONSTS) return () => CONSTS[t];
    return (v) => (t in v ? v[t] : NaN);
  };
  try {
    const f = sum();
    return k === toks.length ? f : null;
  } catch {
    return null;
  }
}

/** The force of the scene's potentials on each particle, read off the motion itself:
 * m a (a by central differences of the positions) minus every other force on it. */
function potentialForces(spec, result, parameters, i, known) {
  const potentials = spec.potentials || [];
  const n = result.t.length;
  if (!potentials.length || n < 3) return [];
  const j = Math.max(1, Math.min(n - 2, i));
  const h = result.t[j + 1] - result.t[j];
  const label = `F_{${potentials.map((p) => p.name).join("+")}}`;
  const out = [];
  for (const b of spec.bodies) {
    const P = result.positions[b.name];
    if ((b.kind ?? "particle") !== "particle" || !P) continue; // the schema's default kind
    const m = typeof b.mass === "number" ? b.mass : parameters[b.mass] ?? Number(b.mass);
    if (!Number.isFinite(m)) continue;
    const acc = ["x", "y", "z"].map((c) => (P[c][j + 1] - 2 * P[c][j] + P[c][j - 1]) / (h * h));
    const F = acc.map((a) => m * a);
    for (const f of known) if (f.on === b.name && f.kind !== "torque") { F[0] -= f.x; F[1] -= f.y; F[2] -= f.z; }
    const size = Math.hypot(...F);
    if (size > 1e-3 * m * Math.hypot(...acc) && size > 1e-9) {
      out.push({ label, kind: "potential", on: b.name, x: F[0], y: F[1], z: F[2], size });
    }
  }
  return out;
}

function torqueArc([x, y], sign, color) {
  const pts = [];
  const r = 20;
  for (let k = 0; k <= 24; k++) {
    const a = -sign * (0.3 + (k / 24) * 4.6);
    pts.push([x + r * Math.cos(a), y + r * Math.sin(a)]);
  }
  const end = pts[pts.length - 1], prev = pts[pts.length - 3];
  return [{ t: "poly", pts: pts.slice(0, -1), color, width: 2.2 },
    { t: "arrow", a: prev, b: end, color, width: 2.2, head: 8 }];
}

const escapeHTML = (x) => String(x).replace(/[&<>"']/g, (c) => `&#${c.charCodeAt(0)};`);

/** A symbol as the steps' math sets it: italic letter, upright subscript (`F_T,bob1` → F with
 * subscript T,bob1). The legend is redrawn outside MathJax's reach (it follows the run), so it is
 * HTML, never raw underscores. */
export function symbolHTML(text, sub = "") {
  return `<i>${escapeHTML(text)}</i>${sub ? `<sub>${escapeHTML(sub)}</sub>` : ""}`;
}

// one family, F with a subscript: T is the kinetic energy, N the inertial frame, R a radius
const CONSTRAINT_NAMES = {
  F_T: `${symbolHTML("F", "T")} tension of a rod or rope`, F_N: `${symbolHTML("F", "N")} normal force`,
  F_f: `${symbolHTML("F", "f")} static friction`, F_pin: `${symbolHTML("F", "pin")} pin reaction`,
  F_C: `${symbolHTML("F", "C")} resultant of a body's constraint forces`,
};

/** The legend under the diagram: one swatch per kind of force the run draws, the same at every
 * instant (`runLegend`), its symbols set as math. */
export function fbdLegend(box, kinds) {
  const named = (kinds.constraints || []).map((n) => CONSTRAINT_NAMES[n] || escapeHTML(n)).join(", ");
  const names = {
    weight: `weight ${symbolHTML("F", "g")} = <i>m</i><i>g</i>`, spring: "spring", damper: "damper",
    force: "applied force", torque: "applied torque",
    constraint: `constraint force, dashed${named ? ` (${named})` : ""}`,
    potential: `force of a potential ${symbolHTML("V")}`,
  };
  const short = kinds.short || [];
  const key = [...kinds].sort().join() + named + short.map(([t, s]) => `${t}_${s}`).join();
  if (box.dataset.kinds === key) return;
  box.dataset.kinds = key;
  const scale = document.createElement("span");
  scale.className = "fbd-scale";
  const which = short.map(([t, s]) => symbolHTML(t, s)).join(", ");
  scale.innerHTML = "arrows to scale" + (short.length
    ? ` (except ${which} when too small to draw: then shown at the minimum length)` : "");
  box.replaceChildren(...Object.keys(names).filter((k) => kinds.has(k)).map((k) => {
    const span = document.createElement("span");
    span.className = `swatch ${k}`;
    span.style.setProperty("--c", FORCE_COLORS[k]);
    span.innerHTML = names[k];
    return span;
  }), scale);
}
