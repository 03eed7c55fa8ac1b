// The work–precision panel (POST /api/v1/precision): pick methods and a step or tolerance range,
// Run, and see error against wall time and against RHS evaluations, energy error against RHS
// evaluations (log–log), each method's fitted order beside its textbook order, and optionally
// symplectic Euler beside RK4 over up to 1000 periods: the bounded energy error against the drift
// where the motion is conservative, autonomous and M is constant, and why not elsewhere (the API
// says it in words: `not_symplectic`, `long_run_declined`, `warnings`).
//
//   import { mountPrecision } from "./precision.js";
//   mountPrecision(container, { sceneId, getState: () => ({ parameters, initial }) });
//
// The panel builds its own DOM inside `container` (no template needed); `spec` instead of
// `sceneId` runs a posted scene (in the server's pool).
import { getJSON, postJSON } from "./api.js";
import { loadPlotly } from "./lazy.js";
import { CONFIG } from "./plots.js";

const DEFAULT_METHODS = ["euler", "rk4", "DOP853"];
const COLORS = ["#1c7ed6", "#d9480f", "#2b8a3e", "#862e9c", "#e67700", "#0b7285"];
const STYLE = `
.precision { margin-top: 1rem; }
.precision fieldset { border: 1px solid var(--line, #dee2e6); border-radius: 6px; margin: .4rem 0; padding: .4rem .6rem; }
.precision .methods { display: flex; flex-wrap: wrap; gap: .2rem 1rem; }
.precision .ranges { display: flex; flex-wrap: wrap; gap: .4rem 1.2rem; align-items: end; }
.precision .ranges label { display: flex; flex-direction: column; font-size: .85rem; }
.precision .ranges input { width: 7rem; }
.precision .plots { display: grid; grid-template-columns: repeat(auto-fit, minmax(280px, 1fr)); gap: .6rem; }
.precision .plot { min-height: 300px; }
.precision table { border-collapse: collapse; margin: .6rem 0; font-size: .9rem; }
.precision th, .precision td { border-bottom: 1px solid var(--line, #dee2e6); padding: .2rem .6rem; text-align: right; }
.precision th:first-child, .precision td:first-child { text-align: left; }
.precision .status { min-height: 1.2em; }
.precision .table-scroll { overflow-x: auto; }
.precision h3 { font-size: 1rem; margin: .8rem 0 .3rem; }
.precision .error { color: #c92a2a; }
.precision tr.has-left-out td { border-bottom: 0; }
.precision tr.left-out td { text-align: left; font-size: .85rem; color: var(--muted, #5b6575); padding-top: 0; }
.precision tr.left-out ul { margin: 0; padding-left: 1.2rem; }
.precision tr.not-symplectic td { text-align: left; font-size: .85rem; color: var(--muted, #5b6575); padding-top: 0; }
.precision .warnings p { margin: .3rem 0; padding: .3rem .6rem; border-left: 3px solid #e67700; }
.precision table { width: 100%; max-width: 60rem; }
@media (max-width: 600px) { .precision th, .precision td { padding: .2rem .25rem; } .precision table { font-size: .82rem; } }
`;

function el(tag, props = {}, ...children) {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children.filter((c) => c !== null && c !== undefined));
  return node;
}

/** n numbers from a to b, evenly spaced on a log axis (a and b included). */
export function logRange(a, b, n) {
  if (n <= 1) return [a];
  const la = Math.log10(a), lb = Math.log10(b);
  return Array.from({ length: n }, (_, i) => Number((10 ** (la + ((lb - la) * i) / (n - 1))).toPrecision(3)));
}

const num = (x, digits = 3) => (x === null || x === undefined ? "–" : Math.abs(x) >= 1e-2 && Math.abs(x) < 1e4 ? Number(x.toPrecision(digits)).toString() : x.toExponential(digits - 1));

/**
 * Why each point of a method is not in its fit, as lines for the table: the API gives every
 * left-out point its reason (`excluded`); points with the same reason are named together
 * ("h = 0.05, 0.02 s: not converging yet (…)"), and a point with no error to draw (a run that
 * stopped, a state that blew up) says it is not on the plots either. With fewer than two points
 * left there is no fitted order, and the last line says so.
 */
/** A step as a plain decimal (0.0119), a tolerance as a power of ten (1e-5, 3.16e-7). */
const settingText = (x, fixed) => (fixed ? String(Number(x.toPrecision(3))) : Number(x.toPrecision(3)).toExponential());

export function leftOutLines(m) {
  const fixed = m.kind === "fixed";
  const groups = new Map();
  for (const p of m.points) {
    if (!p.excluded) continue;
    const reason = p.error === null || p.error === undefined || !(p.error > 0)
      ? `${p.excluded}; not on the plots (no error to draw)` : p.excluded;
    if (!groups.has(reason)) groups.set(reason, []);
    groups.get(reason).push(settingText(p.setting, fixed));
  }
  const lines = [...groups].map(([reason, settings]) =>
    `left out: ${fixed ? "h" : "tol"} = ${settings.join(", ")}${fixed ? " s" : ""} — ${reason}`);
  if (lines.length && m.points_in_fit < 2) {
    lines.push(`no fitted order: ${m.points_in_fit === 0 ? "no point is" : "only one point is"} left to fit a slope to (try smaller ${fixed ? "steps" : "tolerances"} or a shorter t_end)`);
  }
  return lines;
}

function logLayout(title, x, y, ink) {
  return {
    font: { color: ink }, // the page's text colour: lecture mode's dark theme too
    title: { text: title, font: { size: 14 }, x: 0.02, xanchor: "left" },
    margin: { l: 62, r: 14, t: 40, b: 52 },
    legend: { orientation: "h", yref: "container", yanchor: "bottom", y: 0, x: 0, font: { size: 11 } }, // under the axis title (plots.js)
    paper_bgcolor: "rgba(0,0,0,0)", plot_bgcolor: "rgba(0,0,0,0)",
    xaxis: { type: "log", title: { text: x }, exponentformat: "power", automargin: true },
    yaxis: { type: "log", title: { text: y }, exponentformat: "power" },
  };
}

/** Mount the panel; returns { run() } (Run clicked from code), and the panel's root element. */
export function mountPrecision(container, { sceneId = null, spec = null, getState = () => ({}) } = {}) {
  if (!document.getElementById("precision-style")) {
    document.head.append(el("style", { id: "precision-style", textContent: STYLE }));
  }
  const root = el("section", { className: "precision panel", id: "precision" });
  root.setAttribute("aria-labelledby", "h-precision");
  const methodsBox = el("div", { className: "methods" });
  const stepFrom = el("input", { type: "number", value: "0.02", step: "any", min: "0", id: "precision-step-from" });
  const stepTo = el("input", { type: "number", value: "0.0025", step: "any", min: "0", id: "precision-step-to" });
  const tolFrom = el("input", { type: "number", value: "1e-5", step: "any", min: "0", id: "precision-tol-from" });
  const tolTo = el("input", { type: "number", value: "1e-10", step: "any", min: "0", id: "precision-tol-to" });
  const count = el("input", { type: "number", value: "5", min: "2", max: "8", step: "1", id: "precision-count" });
  const tEnd = el("input", { type: "number", value: "10", min: "0", max: "100", step: "any", id: "precision-t-end" });
  const longRun = el("input", { type: "checkbox", id: "precision-long-run" });
  const runButton = el("button", { type: "button", textContent: "Run", id: "precision-run" });
  const status = el("p", { className: "status muted", id: "precision-status" });
  status.setAttribute("role", "status");
  const plots = el("div", { className: "plots" },
    el("div", { className: "plot", id: "precision-plot-time" }),
    el("div", { className: "plot", id: "precision-plot-evals" }),
    el("div", { className: "plot", id: "precision-plot-energy" }));
  const table = el("table", { id: "precision-orders" });
  const longBox = el("div", { id: "precision-long" });
  const warningsBox = el("div", { className: "warnings", id: "precision-warnings" });
  const label = (text, input) => el("label", {}, text, input);
  root.append(
    el("h2", { id: "h-precision", textContent: "Work–precision" }),
    el("p", { className: "muted", textContent: "Each method at several steps (fixed-step methods) or tolerances (adaptive ones), against a DOP853 reference at 1e-13: what the accuracy costs, and each method's order measured from the points." }),
    el("fieldset", {}, el("legend", { textContent: "Methods (up to 6)" }), methodsBox),
    el("fieldset", {}, el("legend", { textContent: "Range" }),
      el("div", { className: "ranges" },
        label("step from (s)", stepFrom), label("step to (s)", stepTo),
        label("tolerance from", tolFrom), label("tolerance to", tolTo),
        label("points", count), label("t_end (s)", tEnd),
        el("label", { className: "inline" }, longRun, " long run: symplectic Euler vs RK4, up to 1000 periods"),
        runButton)),
    status, warningsBox, plots, el("div", { className: "table-scroll" }, table), longBox);
  container.append(root);

  getJSON("/api/v1/methods").then((methods) => {
    for (const m of methods) {
      const box = el("input", { type: "checkbox", value: m.name, checked: DEFAULT_METHODS.includes(m.name) });
      box.dataset.kind = m.kind;
      methodsBox.append(el("label", { title: m.description }, box, ` ${m.label} (order ${m.order})`));
    }
    methodsBox.dataset.ready = "1";
  }).catch((err) => { status.textContent = `Methods unavailable: ${err.message}`; });

  async function run() {
    const chosen = [...methodsBox.querySelectorAll("input:checked")].map((b) => b.value);
    const n = Math.max(2, Math.min(8, Math.round(Number(count.value) || 5)));
    const state = getState() || {};
    const body = {
      ...(sceneId ? { scene_id: sceneId } : { scene: spec }),
      parameters: state.parameters || {},
      initial: state.initial || {},
      methods: chosen,
      steps: logRange(Number(stepFrom.value), Number(stepTo.value), n),
      tolerances: logRange(Number(tolFrom.value), Number(tolTo.value), n),
      t_end: Number(tEnd.value),
      long_run: longRun.checked,
    };
    runButton.disabled = true;
    status.className = "status muted";
    status.textContent = "Running…";
    root.dataset.state = "running";
    warningsBox.replaceChildren();
    try {
      const result = await postJSON("/api/v1/precision", body);
      showTable(result);
      warningsBox.replaceChildren(...(result.warnings || []).map((w) => el("p", { textContent: w })));
      const ends = result.stopped ? ` The motion ends at t = ${num(result.stopped.t)} s (${result.stopped.message}): every run is compared up to there.` : "";
      status.textContent = `Done in ${num(result.seconds)} s${result.cut ? " — the time budget ran out: later points were cut short" : ""}.${ends}`;
      await loadPlotly().then(() => draw(result)).catch(() => {});
      root.dataset.state = "done";
    } catch (err) {
      status.className = "status error";
      status.textContent = err.message;
      root.dataset.state = "error";
    } finally {
      runButton.disabled = false;
    }
  }

  function showTable(result) {
    const heads = ["method", "order", "fitted order", "points in fit", "fitted against"];
    table.replaceChildren(
      el("caption", { textContent: "Measured order: least-squares slope of log error against log h (fixed step), or minus the slope against log RHS evaluations (adaptive). A point left out of a fit is named under its method, with the reason." }),
      el("tr", {}, ...heads.map((h) => el("th", { scope: "col", textContent: h }))),
      ...result.methods.flatMap((m) => {
        const row = el("tr", {},
          el("td", { textContent: m.label }),
          el("td", { textContent: String(m.order) }),
          el("td", { className: "fitted", textContent: m.fitted_order === null ? "–" : m.fitted_order.toFixed(2) }),
          el("td", { textContent: `${m.points_in_fit} of ${m.points.length}` }),
          el("td", { textContent: m.fitted_against }));
        row.dataset.method = m.method;
        const rows = [row];
        if (m.not_symplectic) { // a method symplectic where M is constant, but not on this motion
          row.className = "has-left-out";
          const note = el("tr", { className: "not-symplectic" },
            el("td", { colSpan: heads.length, textContent: `not symplectic here: ${m.not_symplectic}.` }));
          note.dataset.noteOf = m.method;
          rows.push(note);
        }
        const lines = leftOutLines(m);
        if (!lines.length) return rows;
        row.className = "has-left-out";
        const cell = el("td", { colSpan: heads.length },
          el("ul", {}, ...lines.map((text) => el("li", { textContent: text }))));
        const why = el("tr", { className: "left-out" }, cell);
        why.dataset.leftOutOf = m.method; // not data-method: that names the rows of orders
        return [...rows, why];
      }));
    if (!result.long_run) {
      longBox.replaceChildren(...(result.long_run_declined
        ? [el("h3", { textContent: "Long run" }), el("p", { textContent: result.long_run_declined })] : []));
      return;
    }
    const lr = result.long_run;
    const line = (name) => {
      const r = lr.runs[name];
      const env = r.energy_error;
      return `${name === "rk4" ? "RK4" : "symplectic Euler"}: energy error ${num(env[0])} after the first ${lr.periods / 100} periods, ${num(env[env.length - 1])} at the end${r.status === "ok" ? "" : ` (cut: ${r.message})`}`;
    };
    longBox.replaceChildren(
      el("h3", { textContent: `Long run: ${lr.periods} periods at h = ${num(lr.h)} s (period ${num(lr.period)} s, from ${lr.period_from})` }),
      el("p", { textContent: `${line("symplectic_euler")}; ${line("rk4")}.` }),
      // the claim only where it holds (the API's one rule), and why not elsewhere
      el("p", { className: "muted", textContent: lr.symplectic_here
        ? "This motion is conservative and autonomous with a constant mass matrix: symplectic Euler "
          + "conserves a modified energy exactly, so its energy error stays bounded, while RK4's drifts one way."
        : `No bounded energy error is to be expected here: ${lr.not_symplectic}.` }),
      el("div", { className: "plot", id: "precision-plot-long" }));
  }

  function draw(result) {
    const P = window.Plotly;
    const ink = getComputedStyle(root).color;
    const traces = (x, y) => result.methods.map((m, i) => {
      const pts = m.points.filter((p) => p[y] > 0 && p[x] > 0);
      return {
        x: pts.map((p) => p[x]), y: pts.map((p) => p[y]), name: m.method, mode: "lines+markers",
        line: { color: COLORS[i % COLORS.length] },
        marker: { symbol: pts.map((p) => (p.excluded ? "circle-open" : "circle")), size: 8 },
        text: pts.map((p) => `${m.kind === "fixed" ? "h" : "tol"} = ${num(p.setting)}${p.excluded ? ` (left out: ${p.excluded})` : ""}`),
      };
    });
    P.react("precision-plot-time", traces("wall_time", "error"), logLayout("error against wall time", "wall time (s)", "max |y − y_ref|", ink), CONFIG);
    P.react("precision-plot-evals", traces("rhs_evaluations", "error"), logLayout("error against RHS evaluations", "RHS evaluations", "max |y − y_ref|", ink), CONFIG);
    P.react("precision-plot-energy", traces("rhs_evaluations", "energy_error"), logLayout("energy error against RHS evaluations", "RHS evaluations", "|ΔE| / max T", ink), CONFIG);
    if (result.long_run) {
      const lr = result.long_run;
      const data = Object.entries(lr.runs).map(([name, r], i) => ({
        x: r.t, y: r.energy_error, name: name === "rk4" ? "RK4" : "symplectic Euler", mode: "lines",
        line: { color: COLORS[(i + 3) % COLORS.length] },
      }));
      const layout = logLayout("energy error over the long run (largest in each window)", "t (s)", "|ΔE| / max T", ink);
      layout.xaxis.type = "linear";
      P.react("precision-plot-long", data, layout, CONFIG);
    }
  }

  runButton.addEventListener("click", run);
  return { root, run };
}
