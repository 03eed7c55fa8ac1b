// The integrator panel: which method, its tolerance or its step, how long to run, an optional second
// method to compare; and after each run what it cost and how accurate it was (the `stats`).

export const METHODS = [
  ["dop853_c", "DOP853 compiled to C — adaptive, order 8, fastest"],
  ["DOP853", "DOP853 (scipy) — adaptive, order 8"], ["dop853_fortran", "DOP853 (Fortran) — adaptive, order 8"],
  ["RK45", "RK45 — adaptive, order 5"], ["Radau", "Radau — implicit, stiff"],
  ["BDF", "BDF — implicit, stiff"], ["LSODA", "LSODA — switches when stiff"],
  ["rk4", "RK4 — fixed step, order 4"], ["euler", "Euler — fixed step, order 1"],
  // symplectic only where the mass matrix is constant (Cartesian-like coordinates): they step q̇, not p
  ["symplectic_euler", "symplectic Euler — fixed step, symplectic if M is constant"],
  ["implicit_midpoint", "implicit midpoint — fixed step, symplectic if M is constant"],
];
const FIXED = new Set(["rk4", "euler", "symplectic_euler", "implicit_midpoint"]);
export const isFixed = (method) => FIXED.has(method);

const $ = (id) => document.getElementById(id);

/** Give a select the value, adding it as an option first if a shared link brought a new one. */
function choose(select, value) {
  if (![...select.options].some((o) => o.value === value)) select.add(new Option(value, value));
  select.value = value;
}

/** A link's own absolute tolerance (`atol`, a share link's when it differs from rtol), or null
 * when the panel's one tolerance is both: the panel has no atol control, so it is kept as the link
 * gave it, for the runs, the address and the exports, until a tolerance is picked. */
function linkAtol(query, tol) {
  const raw = query.get("atol");
  const x = Number(raw);
  return raw && Number.isFinite(x) && x > 0 && x !== Number(tol) ? raw : null;
}

export function readSettings(query) {
  const tol = query.get("tol") || "1e-9";
  return {
    method: query.get("method") || "dop853_c",
    methodB: query.get("method_b") || "rk4",
    tol,
    atol: linkAtol(query, tol),
    dt: query.get("dt") || "0.01",
    t_end: Math.min(120, Math.max(0.1, Number(query.get("t_end")) || 10)),
    compare: query.get("compare") === "1",
  };
}

/** Wire the panel to `settings` (changed in place); `onChange()` after every user change. */
export function mountIntegrator(settings, onChange) {
  for (const id of ["method", "method-b"]) {
    $(id).replaceChildren(...METHODS.map(([v, label]) => new Option(label, v)));
  }
  choose($("method"), settings.method);
  choose($("method-b"), settings.methodB);
  choose($("tol"), settings.tol);
  choose($("dt"), settings.dt);
  $("t_end").value = settings.t_end;
  $("compare").checked = settings.compare;
  const sync = () => {
    settings.method = $("method").value;
    settings.methodB = $("method-b").value;
    settings.tol = $("tol").value;
    settings.dt = $("dt").value;
    settings.t_end = Math.min(120, Math.max(0.1, Number($("t_end").value) || 10));
    settings.compare = $("compare").checked;
    const both = settings.compare ? [settings.method, settings.methodB] : [settings.method];
    $("dt-box").hidden = !both.some(isFixed);
    $("tol-box").hidden = both.every(isFixed);
    $("method-b").disabled = !settings.compare;
    $("view-b").hidden = !settings.compare;
    document.querySelector(".stage-views").classList.toggle("two", settings.compare);
  };
  sync();
  showAtol(settings);
  $("tol").addEventListener("change", () => { settings.atol = null; showAtol(settings); });
  for (const id of ["method", "method-b", "tol", "dt", "t_end", "compare"]) {
    $(id).addEventListener("change", () => { sync(); onChange(); });
  }
}

/** The tolerance label says what the runs use: "rtol = atol", or rtol here and the link's atol
 * beside it (picking a tolerance makes it both again). */
function showAtol(settings) {
  const box = $("tol-box");
  const words = [...box.childNodes].find((n) => n.nodeType === Node.TEXT_NODE && n.textContent.trim());
  if (words) words.textContent = settings.atol ? "tolerance rtol " : "tolerance rtol = atol ";
  let note = $("atol-note");
  if (!settings.atol) return note?.remove();
  if (!note) {
    note = Object.assign(document.createElement("span"), { id: "atol-note", className: "muted" });
    box.append(note);
  }
  note.textContent = ` atol = ${settings.atol} (from the link)`;
}

export function fmt(x, digits = 4) {
  if (x === null || x === undefined || Number.isNaN(x)) return "–";
  const a = Math.abs(x);
  if (a !== 0 && (a < 1e-3 || a >= 1e5)) return x.toExponential(2);
  return Number(x.toPrecision(digits)).toString();
}

function accuracy(st) {
  if (st.energy_error !== null && st.energy_error !== undefined) return ["energy error |ΔE| / max T", st.energy_error];
  if (st.jacobi_error !== null && st.jacobi_error !== undefined) return ["Jacobi-integral error", st.jacobi_error];
  return ["energy-balance error |ΔE − W_NC| / max T", st.energy_balance_error];
}

/** A run's accuracy as a reader takes it: the number, or, for an error of ½ and more, "blew up at
 * t = … (error 0.98)". The error is the drift |ΔE| (less the work done, where energy is not
 * conserved) over the run's largest T, which a blow-up inflates too: such runs read 0.8 to 1.3,
 * "an error of 1" (issue 26, item 5). The instant is the first sample where the drift reached
 * half the run's largest T (a non-finite energy: where it became so). */
export function accuracyText(r) {
  const [, value] = accuracy(r.stats);
  const plain = fmt(value, 2);
  if (value === null || value === undefined || (Number.isFinite(value) && value < 0.5)) return plain;
  const e = r.energy || {};
  const E = e.E || [], T = e.T || [], W = e.W_nc || [], D = e.W_drive || [];
  const balance = r.stats.energy_error == null && r.stats.jacobi_error == null;
  const scale = Math.max(0, ...T.filter(Number.isFinite).map(Math.abs));
  const stop = r.stats.stop ? `; stopped at t = ${fmt(r.stats.stop.t, 3)} s` : "";
  for (let i = 0; i < E.length; i++) {
    const drift = Math.abs(E[i] - E[0] - (balance ? (W[i] || 0) + (D[i] || 0) : 0));
    if (!Number.isFinite(drift) || (scale > 0 && drift >= 0.5 * scale)) {
      return `blew up at t = ${fmt(r.t[i], 3)} s (error ${plain}${stop})`;
    }
  }
  return `blew up (error ${plain}${stop}; cannot tell when: no energies sampled)`;
}

/** The cost and accuracy readout: one column per run. */
export function showStats(runs) {
  const table = $("stats");
  const rows = [
    ["method", (r) => r.stats.method],
    // the step the server took (fixed-step methods): exactly the dt asked for
    ["step dt", (r) => (r.stats.dt != null ? `${fmt(r.stats.dt)} s` : "adaptive")],
    ["wall time", (r) => `${fmt(r.stats.wall_time * 1e3, 3)} ms`],
    ["steps", (r) => r.stats.steps.toLocaleString("en")],
    ["RHS evaluations", (r) => r.stats.rhs_evaluations.toLocaleString("en")],
    [accuracy(runs[0].stats)[0], accuracyText],
  ];
  for (const k of Object.keys(runs[0].stats.momentum_drift || {})) {
    rows.push([`p_${k} drift`, (r) => fmt((r.stats.momentum_drift || {})[k], 2)]);
  }
  rows.push(["status", (r) => (r.stats.stop ? `stopped at t = ${fmt(r.stats.stop.t, 3)} s` : r.stats.status)]);
  const head = runs.length > 1 ? `<tr><th></th><th>A</th><th>B</th></tr>` : "";
  table.innerHTML = `<thead>${head}</thead><tbody></tbody>`;
  const body = table.querySelector("tbody");
  for (const [label, get] of rows) {
    const tr = document.createElement("tr");
    const th = document.createElement("th");
    th.textContent = label;
    tr.append(th);
    for (const r of runs) {
      const td = document.createElement("td");
      td.textContent = String(get(r));
      if (label === "status" && r.stats.status !== "ok") td.className = "bad";
      if (td.textContent.startsWith("blew up")) td.className = "bad";
      tr.append(td);
    }
    body.append(tr);
  }
  table.dataset.wallTime = String(runs[0].stats.wall_time);
  const warnings = runs.flatMap((r, k) => r.warnings.map((w) => (runs.length > 1 ? `${"AB"[k]}: ${w}` : w)));
  showWarnings(warnings);
}

export function showWarnings(list) {
  $("warnings").replaceChildren(...list.map((w) => Object.assign(document.createElement("li"), { textContent: w })));
}
