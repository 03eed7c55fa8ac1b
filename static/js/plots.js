// q(t), the phase portrait of one coordinate (q_j against q̇_j), and the energies T, V, E (and the
// work W_NC of non-conservative forces) against time, with plotly served by the app (no CDN).
// In compare mode the energy plot shows both runs' energy error instead. Coordinates are named as
// the page writes them (θ̇₁, not theta1_dot: texnames.js), and lecture mode's type is 24 px.
import { nameText } from "./texnames.js";

// No "share to Plotly Cloud" (plotly.js 4 offers it by default: an upload off the machine), no logo,
// no selection tools (nothing here uses a selection). The toolbar's buttons are kept out of the
// tab order by page.js.
export const CONFIG = {
  responsive: true, displaylogo: false, showSendToCloud: false, showEditInChartStudio: false,
  modeBarButtonsToRemove: ["sendChartToCloud", "sendDataToCloud", "select2d", "lasso2d"],
};

/**
 * Work or energy changes that are all at the level of rounding and integration error next to the
 * scene's energies (|w| ≤ 1e-7 × scale: a conservative run at the default tolerance drifts by
 * ~5e-9 of its energy) are not plotted as they are: plotly would stretch the axis to nJ or pJ and
 * draw the noise as a signal.
 */
export const NEGLIGIBLE = 1e-7;
export const atRoundingLevel = (values, scale) =>
  values.every((v) => !Number.isFinite(v) || Math.abs(v) <= NEGLIGIBLE * Math.max(scale, 1e-300));
export const energyScale = (energy) =>
  Math.max(...["T", "V", "E"].flatMap((k) => (energy[k] || []).map((v) => Math.abs(v) || 0)), 0);

export function layout(title, x, y, lecture) {
  const ink = lecture ? "#f1f3f5" : "#1d2430";
  const grid = lecture ? "#333" : "#e9ecef";
  return {
    // a title is kept short enough for a plot a third of the page wide, and a second line (<br>)
    // gets room (automargin) instead of being clipped. The legend sits at the figure's foot in
    // container coordinates: plotly then adds its height (two rows on a phone) to the bottom
    // margin under the axis title; placed below the plot area (paper y < 0) it covered the title.
    title: { text: title, font: { size: lecture ? 26 : 14 }, automargin: true, x: 0.02, xanchor: "left" },
    margin: { l: lecture ? 76 : 62, r: 14, t: lecture ? 60 : 44, b: lecture ? 70 : 52 },
    legend: { orientation: "h", yref: "container", yanchor: "bottom", y: 0, x: 0, font: { size: lecture ? 24 : 11 } },
    font: { size: lecture ? 24 : 12, color: ink },
    paper_bgcolor: "rgba(0,0,0,0)",
    plot_bgcolor: "rgba(0,0,0,0)",
    xaxis: { title: { text: x }, gridcolor: grid, zerolinecolor: grid, automargin: true },
    yaxis: { title: { text: y }, gridcolor: grid, zerolinecolor: grid, exponentformat: "power", automargin: true },
  };
}

export const plotlyReady = () => typeof window.Plotly !== "undefined";

function unitOf(units, q) {
  return units && units[q] ? ` (${units[q]})` : "";
}

/** Draw the three plots for run `a` (and `b` when comparing). */
export function plotRun({ a, b, labels, spec, phase, lecture }) {
  if (!plotlyReady()) return;
  const P = window.Plotly;
  const names = Object.keys(a.q);
  const units = spec.units || {};
  const t = a.t;
  const same = new Set(names.map((n) => units[n] || "")).size === 1;
  const yq = same && units[names[0]] ? `q (${units[names[0]]})` : "q";
  P.react("plot-q", names.map((n) => ({ x: t, y: a.q[n], name: nameText(n), mode: "lines", line: { width: 2 } })),
    layout("coordinates q(t)", "t (s)", yq, lecture), CONFIG);
  const q = names.includes(phase) ? phase : names[0];
  const traces = [{ x: a.q[q], y: a.q_dot[q], name: b ? `A: ${labels[0]}` : nameText(q), mode: "lines", line: { width: 1.8 } }];
  if (b) traces.push({ x: b.q[q], y: b.q_dot[q], name: `B: ${labels[1]}`, mode: "lines", line: { width: 1.4, dash: "dot" } });
  traces.push({ x: [a.q[q][0]], y: [a.q_dot[q][0]], name: "start", mode: "markers", marker: { size: 9, color: "#d9480f" } });
  const uq = units[q];
  P.react("plot-phase", traces,
    layout(`phase portrait of ${nameText(q)}`, `${nameText(q)}${unitOf(units, q)}`,
      `${nameText(`${q}_dot`)}${uq ? ` (${uq}/s)` : ""}`, lecture), CONFIG);
  const e = a.energy;
  let energy;
  let title = "energy";
  if (b) {
    const err = (r) => {
      const maxT = Math.max(...r.energy.T.map(Math.abs), 1e-300);
      return r.energy.E.map((v, i) => (v - r.energy.E[0] - r.energy.W_nc[i]) / maxT);
    };
    energy = [{ x: t, y: err(a), name: `A: ${labels[0]}`, mode: "lines" }, { x: b.t, y: err(b), name: `B: ${labels[1]}`, mode: "lines" }];
    title = "energy error (E − E₀ − W_NC) / max T";
  } else {
    energy = [
      { x: t, y: e.T, name: "T", mode: "lines" },
      { x: t, y: e.V, name: "V", mode: "lines" },
      { x: t, y: e.E, name: "E = T + V", mode: "lines", line: { width: 3 } },
    ];
    if (!atRoundingLevel(e.W_nc, energyScale(e))) {
      energy.push({ x: t, y: e.W_nc, name: "W_NC", mode: "lines", line: { dash: "dot" } });
    }
  }
  P.react("plot-energy", energy, layout(title, "t (s)", b ? "relative error" : "J", lecture), CONFIG);
}
