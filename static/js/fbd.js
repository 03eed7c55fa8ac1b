// The free-body diagram at the current instant: the scene drawn faintly, and on every body each
// force of the run (`forces` of /simulate: weight, spring, damper, applied) as a labelled arrow to
// scale, plus the constraint forces (dashed) the rods, tracks and hoops supply.
import { SceneGeometry } from "./geometry.js";
import { toSVG } from "./render.js";
import { placeLabel, sceneShapes } from "./shapes.js";
import { View } from "./view.js";

export const FORCE_COLORS = {
  weight: "#2f9e44", spring: "#9c36b5", damper: "#e8590c", force: "#1971c2", torque: "#0c8599",
  constraint: "#495057", potential: "#c2255c",
};
const W = 440;
const analysed = new WeakMap(); // result -> its SceneGeometry: the diagram redraws often

/** `\vec{F}_{\text{spring}}` → {text: "F", sub: "spring"}. */
export function labelParts(latex) {
  const m = latex.match(/^\s*(?:\\vec\{([^}]*)\}|([A-Za-z]+))\s*(?:_\{?(?:\\text\{|\\mathrm\{)?([^{}]*)\}?\}?)?/);
  if (!m) return { text: latex.replace(/[\\{}]/g, ""), sub: "" };
  return { text: (m[1] || m[2] || "").replace(/[\\{}]/g, ""), sub: (m[3] || "").replace(/[\\{}]/g, "") };
}

/** Draw into `svg` for sample i; `angles` are the stage's 3-D yaw and pitch. */
export function drawFBD(svg, spec, result, parameters, i, angles = {}) {
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
  const shapes = sceneShapes(geom, view, i, { radius: 8, muted: true, labels: false, axes: false });
  const arrows = forcesAt(result, i);
  arrows.push(...potentialForces(spec, result, parameters, i, arrows));
  const kinds = new Set();
  const biggest = Math.max(...arrows.map((a) => a.size), 1e-12);
  const occupied = [];
  const used = new Set();
  const drawn = []; // [body, direction]: arrows alike in direction are drawn side by side
  for (const b of geom.bodies) {
    const [x, y] = view.project(geom.at(b.name, i));
    occupied.push([x - 12, y - 12, x + 12, y + 12]);
  }
  for (const f of arrows) {
    if (f.size < 1e-9 * biggest || !result.positions[f.on]) continue;
    const p = geom.at(f.on, i);
    const [x, y] = view.project(p);
    const color = FORCE_COLORS[f.kind] || FORCE_COLORS.force;
    kinds.add(f.kind);
    if (f.kind === "torque") {
      shapes.push(...torqueArc([x, y], Math.sign(f.z) || 1, color));
    } else {
      const d = view.direction(p, [f.x / f.size, f.y / f.size, f.z / f.size]);
      if (!d[0] && !d[1]) continue;
      const len = 22 + 50 * (f.size / biggest);
      const alike = drawn.filter(([on, e]) => on === f.on && e[0] * d[0] + e[1] * d[1] > 0.94).length;
      drawn.push([f.on, d]);
      const side = alike ? (alike % 2 ? 1 : -1) * 8 * Math.ceil(alike / 2) : 0;
      const foot = [x - d[1] * side, y + d[0] * side];
      const tip = [foot[0] + d[0] * len, foot[1] + d[1] * len];
      shapes.push({ t: "arrow", a: foot, b: tip, color, width: 2.5, head: 10, dash: f.dashed ? [5, 3] : undefined });
      const { text, sub } = labelParts(f.label);
      const key = `${text}_${sub}`;
      if (used.has(key)) continue;
      used.add(key);
      const before = shapes.length;
      placeLabel(shapes, occupied, tip, 3, text + sub, color, W, H, 13);
      const label = shapes[before];
      Object.assign(label, { text, sub, italic: true, weight: 600 });
    }
  }
  for (const b of geom.bodies) {
    const [x, y] = view.project(geom.at(b.name, i));
    placeLabel(shapes, occupied, [x, y], 10, b.name, "#495057", W, H, 11);
  }
  shapes.push({ t: "text", at: [8, H - 8], text: `t = ${result.t[i].toFixed(2)} s`, color: "#6c757d", size: 11 });
  svg.innerHTML = toSVG(shapes);
  svg.dataset.frame = String(i);
  svg.dataset.arrows = String(arrows.filter((a) => a.size >= 1e-9 * biggest).length);
  return kinds;
}

function forcesAt(result, i) {
  const out = (result.forces || []).map((f) => {
    const x = f.x[i], y = f.y[i], z = f.z[i];
    return { label: f.label, kind: f.kind, on: f.on, x, y, z, size: f.kind === "torque" ? 0 : Math.hypot(x, y, z) };
  });
  for (const [on, r] of Object.entries(result.constraint_forces || {})) {
    const x = r.x[i], y = r.y[i], z = r.z[i];
    const rod = r.tension !== undefined;
    out.push({ label: rod ? `T_{${on}}` : `R_{${on}}`, kind: "constraint", on, x, y, z, size: Math.hypot(x, y, z), dashed: true });
  }
  return out;
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
    if (b.kind !== "particle" || !P) continue;
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

/** The legend under the diagram: one swatch per kind of force drawn. */
export function fbdLegend(box, kinds) {
  const names = { weight: "weight", spring: "spring", damper: "damper", force: "applied force", torque: "applied torque",
    constraint: "constraint force (rod tension T, reaction R)", potential: "force of a potential V" };
  const key = [...kinds].sort().join();
  if (box.dataset.kinds === key) return;
  box.dataset.kinds = key;
  box.replaceChildren(...Object.keys(names).filter((k) => kinds.has(k)).map((k) => {
    const span = document.createElement("span");
    span.className = `swatch ${k}`;
    span.style.setProperty("--c", FORCE_COLORS[k]);
    span.textContent = names[k];
    return span;
  }));
}
