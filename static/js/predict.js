// "See what your answer predicts": a wrong answer's motion (POST /api/v1/check/predict) drawn as a
// ghost beside the true motion on a small canvas, the moment they part, and the TRUE energy of both
// runs plotted against time. Loaded only when a student asks (derivation.js imports it lazily).
import { getJSON, postJSON, typeset } from "./api.js";
import { readValues } from "./controls.js";
import { SceneGeometry } from "./geometry.js";
import { drawCanvas } from "./render.js";
import { sceneShapes } from "./shapes.js";
import { View } from "./view.js";

const W = 320, H = 220; // the ghosts' canvas, CSS pixels
const PW = 320, PH = 120; // the energy plot
const TRUE_INK = "#868e96", STUDENT_INK = "#d9480f";

const el = (tag, props = {}, ...children) => {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
};
const inlineMath = (text) => text.replace(/\$([^$]+)\$/g, "\\($1\\)");
const specs = new Map();

async function specOf(request) {
  if (request.scene) return request.scene;
  if (!specs.has(request.scene_id)) {
    specs.set(request.scene_id, getJSON(`/api/v1/scenes/${request.scene_id}`).then((r) => r.spec));
  }
  return specs.get(request.scene_id);
}

/** Fill `box` with the prediction of the answer in `request` (a /check body), at the page's
 * current parameters and initial state (the URL keeps them). */
export async function showPrediction(box, request) {
  box.replaceChildren(el("p", { className: "muted", textContent: "Integrating your answer beside the true motion…" }));
  try {
    const spec = await specOf(request);
    const { params, initial } = readValues(spec, new URLSearchParams(location.search));
    const { reveal: _, ...check } = request;
    const r = await postJSON("/api/v1/check/predict", { ...check, parameters: params, initial, t_end: 5 });
    render(box, spec, params, r);
    await typeset([box]);
  } catch (err) {
    box.replaceChildren(el("p", { className: "verdict bad", textContent: inlineMath(err.message) }));
    await typeset([box]);
  }
}

function render(box, spec, params, r) {
  const summary = el("p", { className: "predict-summary", textContent: inlineMath(r.summary) });
  const canvas = el("canvas", { className: "predict-ghosts", role: "img",
    ariaLabel: "the true motion (grey) and your answer's (orange), from the same start" });
  const legend = el("p", { className: "muted predict-legend" });
  legend.append(swatch(TRUE_INK), " true motion  ", swatch(STUDENT_INK), " your answer",
    r.parted_at == null ? "  · they never part visibly" : `  · parted at t = ${r.parted_at.toFixed(2)} s`);
  legend.title = `Parted: ${r.parting_rule}`;
  const replay = el("button", { type: "button", className: "predict-replay", textContent: "replay" });
  const plot = energyPlot(r);
  const figure = el("div", { className: "predict-figure" }, canvas, plot);
  figure.style.cssText = "display:flex;flex-wrap:wrap;gap:.6rem;align-items:flex-start;margin:.4rem 0";
  legend.append("  ", replay);
  box.replaceChildren(summary, figure, legend);
  const play = animate(canvas, spec, params, r, legend);
  replay.addEventListener("click", play);
}

function swatch(color) {
  const s = el("span", { textContent: "●" });
  s.style.color = color;
  return s;
}

/** The two runs as ghosts on one canvas, in real time; returns a function that replays. */
function animate(canvas, spec, params, r, legend) {
  const dpr = window.devicePixelRatio || 1;
  canvas.width = Math.round(W * dpr);
  canvas.height = Math.round(H * dpr);
  canvas.style.cssText = `width:${W}px;max-width:100%;height:auto;aspect-ratio:${W}/${H};` +
    "background:#fbfcfe;border:1px solid #e9ecef;border-radius:6px";
  const ctx = canvas.getContext("2d");
  const truth = new SceneGeometry(spec, r.true, params);
  const student = r.student.t.length ? new SceneGeometry(spec, r.student, params) : null;
  // both runs in view, unless the student's flies off (a blow-up must not shrink the truth to a dot)
  const points = truth.extent();
  const ghost = student ? student.extent().filter((p) => p.every(Number.isFinite)) : [];
  const size = (pts) => Math.max(...[0, 1, 2].map((k) => Math.max(...pts.map((p) => p[k])) - Math.min(...pts.map((p) => p[k]))));
  const both = ghost.length && size([...points, ...ghost]) <= 3 * size(points) ? [...points, ...ghost] : points;
  const view = new View(W, H, truth.is3D).fit(both, 16);
  const last = r.true.t.length - 1;
  const draw = (i) => {
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, W, H);
    drawCanvas(ctx, sceneShapes(truth, view, i, { muted: true, labels: false, radius: 7, trail: 0.6 }));
    if (student) {
      const j = Math.min(i, student.n - 1);
      const shapes = sceneShapes(student, view, j, { labels: false, radius: 7, trail: 0.6, axes: false });
      drawCanvas(ctx, shapes.map((s) => recolor(s)));
    }
    const t = r.true.t[i];
    const label = (text, color, y) => { // a white halo keeps it readable over a body
      ctx.font = "12px system-ui, sans-serif";
      ctx.lineWidth = 3;
      ctx.strokeStyle = "#fff";
      ctx.strokeText(text, 8, y);
      ctx.fillStyle = color;
      ctx.fillText(text, 8, y);
    };
    label(`t = ${t.toFixed(2)} s`, "#495057", 16);
    if (r.parted_at != null && t >= r.parted_at) label("parted", STUDENT_INK, 32);
    canvas.dataset.sample = String(i);
  };
  let frame = 0;
  const play = () => {
    cancelAnimationFrame(frame);
    const start = performance.now();
    const step = (now) => {
      const t = (now - start) / 1000;
      let i = r.true.t.findIndex((x) => x >= t);
      if (i < 0) i = last;
      draw(i);
      if (i < last && canvas.isConnected) frame = requestAnimationFrame(step);
      else canvas.dataset.done = "1";
    };
    frame = requestAnimationFrame(step);
  };
  draw(0);
  play();
  return play;
}

/** The student's ghost in one colour, so two drawings of the same scene can be told apart. */
function recolor(shape) {
  const out = { ...shape };
  if (out.color && out.color !== "transparent") out.color = STUDENT_INK;
  if (out.fill && out.fill !== "none" && out.t !== "text") out.fill = STUDENT_INK;
  out.alpha = (out.alpha ?? 1) * 0.85;
  return out;
}

/** E_true(t) of both runs as a small SVG plot, with the parting time marked. */
function energyPlot(r) {
  const NS = "http://www.w3.org/2000/svg";
  const svg = document.createElementNS(NS, "svg");
  svg.setAttribute("viewBox", `0 0 ${PW} ${PH}`);
  svg.setAttribute("width", PW);
  svg.setAttribute("height", PH);
  svg.setAttribute("class", "predict-energy");
  svg.setAttribute("role", "img");
  svg.setAttribute("aria-label", "the true energy along the true run and along your answer's");
  svg.style.cssText = "max-width:100%;background:#fff;border:1px solid #e9ecef;border-radius:6px";
  const tEnd = Math.max(...r.true.t);
  const truth = r.true.energy.filter(Number.isFinite);
  let lo = Math.min(...truth), hi = Math.max(...truth);
  const scale = r.energy_scale || 1;
  // the student's curve widens the range, but at most to 3 energy scales past the truth's
  for (const e of r.student.energy) {
    if (!Number.isFinite(e)) continue;
    lo = Math.min(lo, Math.max(e, lo - 3 * scale));
    hi = Math.max(hi, Math.min(e, hi + 3 * scale));
  }
  // integration noise (1e-9 of E) is not drawn as spikes: at least 5 % of the motion's energy
  if (hi - lo < 0.05 * scale) {
    const mid = (hi + lo) / 2;
    [lo, hi] = [mid - 0.025 * scale, mid + 0.025 * scale];
  }
  const pad = 0.08 * (hi - lo); // a flat true energy must not hide under the axis
  lo -= pad;
  hi += pad;
  const L = 34, R = 8, T = 8, B = 22;
  const x = (t) => L + (t / tEnd) * (PW - L - R);
  const y = (e) => T + (1 - (Math.min(Math.max(e, lo), hi) - lo) / (hi - lo)) * (PH - T - B);
  const line = (ts, es, color, dash = "") => {
    const pts = ts.map((t, k) => (Number.isFinite(es[k]) ? `${x(t).toFixed(1)},${y(es[k]).toFixed(1)}` : null))
      .filter(Boolean).join(" ");
    const p = document.createElementNS(NS, "polyline");
    p.setAttribute("points", pts);
    p.setAttribute("fill", "none");
    p.setAttribute("stroke", color);
    p.setAttribute("stroke-width", "1.8");
    if (dash) p.setAttribute("stroke-dasharray", dash);
    svg.append(p);
  };
  const text = (tx, ty, s, anchor = "start") => {
    const n = document.createElementNS(NS, "text");
    n.setAttribute("x", tx);
    n.setAttribute("y", ty);
    n.setAttribute("font-size", "10");
    n.setAttribute("fill", "#495057");
    n.setAttribute("text-anchor", anchor);
    n.textContent = s;
    svg.append(n);
  };
  const axis = document.createElementNS(NS, "path");
  axis.setAttribute("d", `M${L},${T} V${PH - B} H${PW - R}`);
  axis.setAttribute("stroke", "#adb5bd");
  axis.setAttribute("fill", "none");
  svg.append(axis);
  if (r.parted_at != null) {
    const m = document.createElementNS(NS, "line");
    m.setAttribute("x1", x(r.parted_at)); m.setAttribute("x2", x(r.parted_at));
    m.setAttribute("y1", T); m.setAttribute("y2", PH - B);
    m.setAttribute("stroke", STUDENT_INK);
    m.setAttribute("stroke-dasharray", "3 3");
    svg.append(m);
  }
  line(r.true.t, r.true.energy, TRUE_INK);
  line(r.student.t, r.student.energy, STUDENT_INK);
  text(L - 3, T + 8, fmt(hi), "end");
  text(L - 3, PH - B, fmt(lo), "end");
  text(PW - R, PH - 6, `t = ${tEnd.toFixed(1)} s`, "end");
  text(L + 4, PH - 6, "true energy E(q, q̇) of each run (J)");
  return svg;
}

function fmt(v) {
  const a = Math.abs(v);
  return a !== 0 && (a < 1e-2 || a >= 1e4) ? v.toExponential(1) : v.toPrecision(3);
}
