// Work and energy between two times (notes II.B, III): each force's W_1→2, ΔT, ΔV and the check
// W^NC = ΔT + ΔV — with, for a driven system (a spinning hoop, a moving support, a time-dependent
// potential), the work of the drive W_drive (`energy.W_drive` and `stats.driven` of /simulate):
// W^NC + W_drive = ΔT + ΔV — as a table and a stacked plot; and the constraint forces along the run — the
// result Newton's method gives and Lagrange's hides (a pendulum's tension, where a string would
// go slack).

import { atRoundingLevel, CONFIG, energyScale } from "./plots.js";

const $ = (id) => document.getElementById(id);

function fmt(x) {
  const a = Math.abs(x);
  return a !== 0 && (a < 1e-3 || a >= 1e5) ? x.toExponential(3) : x.toFixed(4);
}

/** What a load is called in the spec, and its kind in words: "drive (applied force)", not
 * "force drive" (which reads as an instruction). */
const KINDS = { spring: "spring", potential: "potential", damper: "damper", force: "applied force",
  torque: "applied torque" };

function label(key) {
  const [kind, rest] = key.split(":");
  const name = rest.split("@")[0];
  if (kind === "weight") return `weight of ${name}`;
  if (!(kind in KINDS)) return key;
  // a spring named "spring" (or "spring 1") is not "spring (spring)": its name says its kind
  return name.toLowerCase().startsWith(kind) ? name : `${name} (${KINDS[kind]})`;
}

function index(t, time) {
  let i = 0;
  while (i < t.length - 1 && t[i + 1] <= time + 1e-12) i += 1;
  return i;
}

export function showWork(run, { lecture = false } = {}) {
  if (!run || !run.work) return;
  const t = run.t, end = t[t.length - 1];
  const t1box = $("work-t1"), t2box = $("work-t2");
  // rounded up, so a run that ends between two hundredths (at a stop) is taken to its end
  const last = (Math.ceil(end * 100 - 1e-9) / 100).toFixed(2);
  if (t2box.value === "" || Number(t2box.value) > Number(last)) t2box.value = last;
  const i = index(t, Math.max(0, Number(t1box.value) || 0));
  const j = index(t, Math.min(end, Number(t2box.value)));
  const rows = [];
  let wc = 0, wnc = 0;
  for (const [k, w] of Object.entries(run.work.conservative)) { rows.push([label(k), w[j] - w[i], "conservative"]); wc += w[j] - w[i]; }
  for (const [k, w] of Object.entries(run.work.non_conservative)) { rows.push([label(k), w[j] - w[i], "non-conservative"]); wnc += w[j] - w[i]; }
  const e = run.energy;
  const dT = e.T[j] - e.T[i], dV = e.V[j] - e.V[i];
  const html = [`<tr><th>force</th><th>kind</th><th>W<sub>1→2</sub> (J)</th></tr>`];
  for (const [name, w, kind] of rows) html.push(`<tr><td>${name}</td><td>${kind}</td><td>${fmt(w)}</td></tr>`);
  html.push(`<tr class="sum"><td>ΔT</td><td></td><td>${fmt(dT)}</td></tr>`);
  html.push(`<tr class="sum"><td>ΔV = −W<sup>C</sup></td><td></td><td>${fmt(dV)}</td></tr>`);
  html.push(`<tr class="sum"><td>W<sup>NC</sup></td><td></td><td>${fmt(wnc)}</td></tr>`);
  const driven = Boolean(run.stats?.driven) && Array.isArray(e.W_drive);
  const wdrive = driven ? e.W_drive[j] - e.W_drive[i] : 0;
  if (driven) html.push(`<tr class="sum drive"><td>W<sub>drive</sub>: work of the drive</td><td>driving agent</td><td>${fmt(wdrive)}</td></tr>`);
  const gap = wnc + wdrive - (dT + dV);
  const scale = Math.max(Math.abs(dT), Math.abs(dV), Math.abs(wnc), Math.abs(wdrive), 1e-300);
  const ok = Math.abs(gap) <= 1e-5 * scale;
  const lhs = driven ? "W<sup>NC</sup> + W<sub>drive</sub>" : "W<sup>NC</sup>";
  const verdict = ok ? "✔ balanced"
    : `✘ not balanced: ${lhs} ≠ ΔT + ΔV${driven ? "" : " (work missing from the table?)"}`;
  html.push(`<tr class="check ${ok ? "pass" : "fail"}"><td>${lhs} − (ΔT + ΔV)</td><td>${verdict}</td><td>${fmt(gap)}</td></tr>`);
  const table = $("work-table");
  table.innerHTML = html.join("");
  table.dataset.gap = String(gap / scale);
  table.dataset.balanced = ok ? "1" : "0";
  table.dataset.driven = driven ? "1" : "0";
  cueScrolling(table);
  if (typeof window.Plotly === "undefined") return;
  const ink = lecture ? "#f1f3f5" : "#1d2430";
  const base = { margin: { l: 60, r: 12, t: lecture ? 60 : 48, b: lecture ? 64 : 52 }, paper_bgcolor: "rgba(0,0,0,0)",
    plot_bgcolor: "rgba(0,0,0,0)", font: { color: ink, size: lecture ? 20 : 12 },
    // the legend at the figure's foot (container coordinates): plotly then makes room for it
    // under the axis title, which a legend placed below the plot area (paper y < 0) would cover
    legend: { orientation: "h", yref: "container", yanchor: "bottom", y: 0, x: 0 } };
  // titles of one short line: plotly clips a title longer than its plot, and a second line too
  const title = (text) => ({ text, font: { size: lecture ? 22 : 14 }, x: 0.02, xanchor: "left" });
  const top = () => base.margin;
  const span = t.slice(i, j + 1);
  const traces = Object.entries(run.work.non_conservative).map(([k, w]) => ({
    x: span, y: w.slice(i, j + 1).map((v) => v - w[i]), name: `W ${label(k)}`, stackgroup: "nc", mode: "none" }));
  if (driven) traces.push({ x: span, y: e.W_drive.slice(i, j + 1).map((v) => v - e.W_drive[i]), name: "W drive", stackgroup: "nc", mode: "none" });
  traces.push({ x: span, y: span.map((_, k) => e.T[i + k] - e.T[i] + e.V[i + k] - e.V[i]), name: "ΔT + ΔV",
    mode: "lines", line: { color: ink, width: 2, dash: "dot" } });
  // A conservative scene: no force does work and ΔT + ΔV is zero up to rounding and integration
  // error. Plotted as it is, the axis would zoom to nJ and show noise; it is drawn flat at 0 on an
  // axis of the scene's energy scale, saying so and how large the largest value was.
  const energy = energyScale(e);
  const rounding = traces.every((tr) => atRoundingLevel(tr.y, energy));
  const yaxis = { title: { text: "J" }, zeroline: true };
  const annotations = [];
  if (rounding) {
    const largest = Math.max(...traces.flatMap((tr) => tr.y.map(Math.abs)));
    for (const tr of traces) tr.y = tr.y.map(() => 0);
    const r = Math.max(energy, 1e-12) * 0.1;
    Object.assign(yaxis, { range: [-r, r], autorange: false });
    annotations.push({ text: `W<sup>NC</sup> = ΔT + ΔV = 0 within rounding<br>(largest |value| ${largest.toExponential(1)} J)`, showarrow: false,
      xref: "paper", yref: "paper", x: 0.5, y: 0.62, font: { size: lecture ? 22 : 14, color: ink } });
  }
  $("plot-work").dataset.rounding = rounding ? "1" : "0";
  const workTitle = driven ? "W of forces and drive (stacked), ΔT + ΔV"
    : traces.length > 1 ? "W of non-conservative forces (stacked), ΔT + ΔV" : "W<sup>NC</sup> and ΔT + ΔV";
  window.Plotly.react("plot-work", traces, { ...base, margin: top(workTitle), title: title(workTitle), annotations,
    xaxis: { title: { text: "t (s)" }, automargin: true }, yaxis }, CONFIG);
  // A body on a string or rod has a tension (which a string cannot make negative); any other
  // constraint (a block on an incline, a bead on a hoop) a reaction of magnitude |F_C| (the FBD's name).
  const forces = run.constraint_forces || {};
  const ctraces = Object.entries(forces).map(([body, f]) => f.tension
    ? { x: t, y: f.tension, name: `tension on ${body}`, mode: "lines" }
    : { x: t, y: f.x.map((x, k) => Math.hypot(x, f.y[k], f.z[k])), name: `|F<sub>C</sub>| on ${body}`, mode: "lines" });
  const tension = Object.values(forces).some((f) => f.tension);
  // none at all: a potential V(q) left them unknown (the run's warnings and the FBD say why)
  const constraintTitle = !ctraces.length
    ? "constraint forces: not computed (see the warnings)"
    : tension
      ? "constraint forces (tension < 0: a string goes slack)"
      : "constraint forces |F<sub>C</sub>| along the run";
  $("plot-constraint").dataset.tension = tension ? "1" : "0";
  window.Plotly.react("plot-constraint", ctraces, { ...base, margin: top(constraintTitle), title: title(constraintTitle),
    xaxis: { title: { text: "t (s)" }, automargin: true }, yaxis: { title: { text: "N" }, zeroline: true } }, CONFIG);
}

/** The table's box scrolls sideways when the table is wider (a phone in lecture mode): say so
 * under it, and again whenever the box changes width. */
function cueScrolling(table) {
  const box = table.closest(".table-scroll");
  if (!box) return;
  const mark = () => box.classList.toggle("scrolls", box.scrollWidth > box.clientWidth + 1);
  mark();
  if (!box.dataset.watched) {
    box.dataset.watched = "1";
    new ResizeObserver(mark).observe(box);
  }
}

export function watchWorkInputs(onChange) {
  for (const id of ["work-t1", "work-t2"]) $(id).addEventListener("change", onChange);
}
