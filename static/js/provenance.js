// Where every term comes from (issue 14.2): under T, V, each Q_j and each equation of motion, a
// "where each term comes from" table built from the derive response's `provenance` (see
// docs/provenance.md): each term as math, its origins in words (which body, which velocity
// component in which frame, which force's virtual work), the Euler–Lagrange piece it enters
// through and its contribution. Hover, focus or click a term and the same term lights up in every
// table where it appears, with the terms of T or V it was differentiated from and the terms made
// from it. Tables, not \class{} inside the displayed equations: the lines stay exactly as the
// derivation prints them (and as copied), and the tables work with or without MathJax.
import { typeset } from "./api.js";
import { dottedTex, nameTex } from "./texnames.js";

const el = (tag, props = {}, ...children) => {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
};
const math = (tex) => `\\(${tex}\\)`;

/** The Euler–Lagrange piece of a source, in the coordinate's own notation. */
function pieceTex(piece, q) {
  switch (piece) {
    case "d/dt ∂T/∂q̇": return `\\frac{d}{dt}\\frac{\\partial T}{\\partial ${dottedTex(q, 1)}}`;
    case "−∂T/∂q": return `-\\frac{\\partial T}{\\partial ${nameTex(q)}}`;
    case "∂V/∂q": return `+\\frac{\\partial V}{\\partial ${nameTex(q)}}`;
    case "Q": return `Q_{${nameTex(q)}}^{NC}`;
    default: return "";
  }
}

/** An origin in words, its unit vectors as math (ê_θ, not e_theta). */
function originWords(origin) {
  if (!origin) return "";
  let text = origin.text || "";
  for (const c of origin.components || []) {
    if (c.unit && c.unit_latex) text = text.replace(`${c.unit} component`, `${math(c.unit_latex)} component`);
  }
  return text;
}

function sourceCells(source, origins, q) {
  const piece = q && source.piece ? math(pieceTex(source.piece, q)) : "";
  return [
    el("td", { className: "pv-origin", textContent: originWords(origins[source.origin]) }),
    el("td", { className: "pv-piece", textContent: piece }),
    el("td", { className: "pv-part", textContent: math(source.contribution_latex) }),
  ];
}

/** The derivation's lines a source stands on, as [step id, line label] (derivation.js labels):
 * the body's velocity and T, the spring's or potential's V, the load's Q_j, and the pieces of the
 * Euler–Lagrange equation it passes through. */
function linesOf(source, origins, q) {
  const o = origins[source.origin] || {};
  const out = [];
  if (o.kind === "kinetic") {
    const links = new Set((o.components || []).map((c) => c.link).filter(Boolean));
    if (o.motion === "rotational") out.push(["kinematics", `angular velocity of ${o.body}`]);
    else for (const link of links.size ? links : [o.body]) out.push(["kinematics", `v of ${link}`]);
    out.push(["kinematics", `v of ${o.body}`], ["energy", `T_${o.body}`], ["energy", "T"]);
  } else if (o.kind === "potential") {
    out.push(["energy", `V_${o.name}`], ["energy", "V"]);
  } else if (o.kind === "generalized force") {
    out.push(["forces", `Q_${o.coordinate}`]);
  }
  if (q && source.piece === "d/dt ∂T/∂q̇") out.push(["lagrange", `dL/d${q}_dot`], ["lagrange", `d/dt dL/d${q}_dot`]);
  if (q && (source.piece === "−∂T/∂q" || source.piece === "∂V/∂q")) out.push(["lagrange", `dL/d${q}`]);
  if (q) out.push(["lagrange", `EoM ${q}`]);
  return out;
}

/** One table: a <tbody> per term (its id, the ids it came through), a row per source. */
function table(eq, origins, q, side) {
  if (!eq || !eq.traced) {
    return el("p", { className: "muted pv-untraced", textContent: eq?.reason || "not traced" });
  }
  if (!eq.terms.length && !eq.cancelled.length) {
    return el("p", { className: "muted", textContent: side ? `${side}: 0` : "0 (nothing contributes)" });
  }
  const t = el("table", { className: "pv-table" });
  if (side) t.append(el("caption", { textContent: side }));
  t.append(el("thead", {}, el("tr", {},
    el("th", { scope: "col", textContent: "term" }),
    el("th", { scope: "col", textContent: "comes from" }),
    el("th", { scope: "col", textContent: q ? "through" : "" }),
    el("th", { scope: "col", textContent: "contribution" }))));
  for (const term of eq.terms) {
    const body = el("tbody", { className: "pv-term", tabIndex: 0 });
    body.dataset.term = term.id;
    body.dataset.via = [...new Set(term.sources.map((s) => s.via).filter(Boolean))].join(" ");
    body.title = `${term.plain}: click to keep it lit`;
    const lines = term.sources.flatMap((source) => linesOf(source, origins, q));
    body.dataset.lines = JSON.stringify([...new Map(lines.map((l) => [l.join("\u0000"), l])).values()]);
    term.sources.forEach((source, k) => {
      const row = el("tr");
      if (k === 0) {
        row.append(el("td", { className: "pv-term-math", rowSpan: term.sources.length, textContent: math(term.latex) }));
      }
      row.append(...sourceCells(source, origins, q));
      body.append(row);
    });
    t.append(body);
  }
  for (const gone of eq.cancelled) {
    const body = el("tbody", { className: "pv-cancelled" });
    gone.sources.forEach((source, k) => {
      const row = el("tr");
      if (k === 0) {
        row.append(el("td", {
          className: "pv-term-math muted", rowSpan: gone.sources.length,
          textContent: `${math(gone.monomial_latex)} terms cancel`,
        }));
      }
      row.append(...sourceCells(source, origins, q));
      body.append(row);
    });
    t.append(body);
  }
  // wide math (lecture mode's big type) scrolls inside its box, never the page
  return el("div", { className: "pv-scroll" }, t);
}

/** M and f entry by entry: each entry is the sum of the equation-of-motion terms it lists (by
 * id: hovering an entry lights them, hovering one of them lights the entries it is part of). */
function matrixTables(provenance) {
  const byId = new Map();
  for (const eom of Object.values(provenance.eom || {})) {
    for (const side of [eom.lhs, eom.rhs]) for (const t of side?.terms || []) byId.set(t.id, t);
  }
  const names = Object.keys(provenance.eom || {});
  const sum = (ids, sign = 1) => ids.map((id, k) => {
    const tex = byId.get(id)?.latex ?? "?";
    return (sign < 0 ? "- " : k ? "+ " : "") + (sign < 0 ? String.raw`\left(${tex}\right)` : tex);
  }).join(" ");
  const entry = (label, ids, terms) => {
    const body = el("tbody", { className: "pv-term", tabIndex: 0 });
    body.dataset.term = `matrix:${label}`;
    body.dataset.via = ids.join(" ");
    body.title = "the equation-of-motion terms this entry is made of: click to keep them lit";
    body.append(el("tr", {},
      el("td", { className: "pv-term-math", textContent: math(label) }),
      el("td", { textContent: terms ? math(terms) : "0" })));
    return body;
  };
  const head = (what) => el("thead", {}, el("tr", {},
    el("th", { scope: "col", textContent: "entry" }), el("th", { scope: "col", textContent: what })));
  const M = el("table", { className: "pv-table" }, head("the terms of the equation of motion it collects"));
  const f = el("table", { className: "pv-table" }, head("right side minus the left side's terms free of q̈"));
  (provenance.matrix?.M || []).forEach((row, j) => {
    if (!row) return;
    row.forEach((ids, k) => {
      if (ids.length) {
        const qk = dottedTex(names[k], 2);
        M.append(entry(`M_{${j + 1}${k + 1}}\,${qk}`, ids, sum(ids)));
      }
    });
  });
  (provenance.matrix?.f || []).forEach((parts, j) => {
    if (!parts) return;
    const tex = [sum(parts.plus), sum(parts.minus, -1)].filter(Boolean).join(" ");
    f.append(entry(`f_{${j + 1}}`, [...parts.plus, ...parts.minus], tex));
  });
  return [el("div", { className: "pv-scroll" }, M), el("div", { className: "pv-scroll" }, f)];
}

function panel(title, parts) {
  const box = el("details", { className: "pv-panel" });
  box.append(el("summary", { textContent: `Where each term of ${title} comes from` }), ...parts);
  return box;
}

/** The line of a step with this label (derivation.js keeps it in data-label). */
function lineOf(container, stepId, label) {
  const step = container.querySelector(`li[data-step="${stepId}"]`);
  if (!step) return null;
  const row = [...step.querySelectorAll(".math-line")]
    .find((r) => r.dataset.label === label);
  return row || null;
}

/** Light a term everywhere: the same id (.pv-lit), the terms it came through (.pv-from), the
 * terms derived from it (.pv-into) and the derivation's lines its origins stand on (.pv-line). */
function light(container, body, on) {
  for (const row of container.querySelectorAll(".math-line.pv-line")) row.classList.remove("pv-line");
  if (on) {
    for (const [stepId, label] of JSON.parse(body.dataset.lines || "[]")) {
      lineOf(container, stepId, label)?.classList.add("pv-line");
    }
  }
  const id = body.dataset.term;
  const vias = (body.dataset.via || "").split(" ").filter(Boolean);
  for (const other of container.querySelectorAll("tbody.pv-term")) {
    const same = other.dataset.term === id;
    const from = vias.includes(other.dataset.term);
    const into = (other.dataset.via || "").split(" ").includes(id);
    other.classList.toggle("pv-lit", on && same);
    other.classList.toggle("pv-from", on && from && !same);
    other.classList.toggle("pv-into", on && into && !same);
  }
}

function wire(container) {
  if (container.dataset.provenanceWired) return;
  container.dataset.provenanceWired = "1";
  let pinned = null;
  const termOf = (e) => e.target.closest?.("tbody.pv-term");
  const show = (body) => light(container, body, true);
  const restore = () => {
    if (pinned && pinned.isConnected) show(pinned);
    else for (const b of container.querySelectorAll("tbody.pv-term")) light(container, b, false);
  };
  container.addEventListener("mouseover", (e) => { const b = termOf(e); if (b) show(b); });
  container.addEventListener("mouseout", (e) => { if (termOf(e)) restore(); });
  container.addEventListener("focusin", (e) => { const b = termOf(e); if (b) show(b); });
  container.addEventListener("focusout", (e) => { if (termOf(e)) restore(); });
  const toggle = (b) => {
    pinned = pinned === b ? null : b;
    for (const x of container.querySelectorAll("tbody.pv-pinned")) x.classList.remove("pv-pinned");
    if (pinned) pinned.classList.add("pv-pinned");
    restore();
  };
  container.addEventListener("click", (e) => { const b = termOf(e); if (b) toggle(b); });
  container.addEventListener("keydown", (e) => {
    const b = termOf(e);
    if (b && (e.key === "Enter" || e.key === " ")) { e.preventDefault(); e.stopPropagation(); toggle(b); }
  });
}

const STYLE = `
.pv-panel { margin: .15rem 0 .5rem 1rem; font-size: .9rem; min-width: 0; max-width: 100%; }
.pv-scroll { overflow-x: auto; max-width: 100%; }
.pv-panel > summary { cursor: pointer; color: var(--muted, #5b6575); font-size: .82rem; }
.pv-table { border-collapse: collapse; margin: .3rem 0; width: 100%; }
.pv-table caption { text-align: left; font-size: .8rem; color: var(--muted, #5b6575); }
.pv-table th { text-align: left; font-weight: 600; font-size: .75rem; color: var(--muted, #5b6575);
  border-bottom: 1px solid var(--line, #dde2e9); padding: .1rem .4rem; }
.pv-table td { padding: .15rem .4rem; vertical-align: middle; border-bottom: 1px solid var(--line, #dde2e9); }
.pv-table .pv-origin { font-size: .82rem; }
.pv-term { cursor: pointer; outline-offset: -2px; }
.pv-term.pv-lit { background: rgba(255, 214, 0, .30); }
.pv-term.pv-from { background: rgba(26, 99, 214, .14); }
.pv-term.pv-into { background: rgba(26, 127, 55, .14); }
.pv-term.pv-pinned { box-shadow: inset 3px 0 0 var(--accent, #1a63d6); }
.pv-untraced { font-size: .82rem; }
html.lecture .pv-panel, html.lecture .pv-panel :is(summary, caption, th, td, .pv-origin, .pv-untraced) {
  font-size: 1rem; } /* legible from the back of the hall: 24 px like the rest of lecture mode */
.math-line.pv-line { background: rgba(255, 214, 0, .18); box-shadow: inset 3px 0 0 rgba(214, 160, 0, .9); }
@media (max-width: 640px) { .pv-panel { margin-left: 0; } .pv-table .pv-origin { font-size: .78rem; }
  .pv-table, .pv-table tbody, .pv-table tr { display: block; } .pv-table thead { display: none; }
  .pv-table td { display: inline-block; border: 0; } .pv-table tbody { border-bottom: 1px solid var(--line, #dde2e9); } }
`;

function injectStyle() {
  if (document.getElementById("provenance-style")) return;
  document.head.append(el("style", { id: "provenance-style", textContent: STYLE }));
}

/**
 * Add the "where each term comes from" tables to a rendered derivation.
 * @param {HTMLElement} container the steps list derivation.js rendered (#steps)
 * @param {object} provenance the derive response's `provenance`
 * @returns {Promise<HTMLElement[]>} the panels added (typeset)
 */
export async function traceTerms(container, provenance) {
  if (!container || !provenance) return [];
  injectStyle();
  for (const old of container.querySelectorAll(".pv-panel")) old.remove();
  const origins = provenance.origins || {};
  const added = [];
  const place = (stepId, label, title, parts) => {
    const line = lineOf(container, stepId, label);
    if (!line) return;
    const box = panel(title, parts);
    line.after(box);
    added.push(box);
  };
  place("energy", "T", math("T"), [table(provenance.T, origins, null, "")]);
  place("energy", "V", math("V"), [table(provenance.V, origins, null, "")]);
  for (const [q, eq] of Object.entries(provenance.Q || {})) {
    // Q_j^{NC} as the forces step writes it: the weight and the springs are in V, not here
    place("forces", `Q_${q}`, math(`Q_{${nameTex(q)}}^{NC}`), [table(eq, origins, q, "")]);
  }
  for (const [q, eom] of Object.entries(provenance.eom || {})) {
    const d = dottedTex(q, 1);
    const n = nameTex(q);
    place("lagrange", `EoM ${q}`, `the equation of motion for ${math(n)}`, [
      table(eom.lhs, origins, q, `left side ${math(`\\frac{d}{dt}\\frac{\\partial L}{\\partial ${d}} - \\frac{\\partial L}{\\partial ${n}}`)}`),
      table(eom.rhs, origins, q, `right side ${math(`Q_{${n}}^{NC}`)} (non-conservative forces)`),
    ]);
  }
  if (provenance.matrix) {
    const [M, f] = matrixTables(provenance);
    place("matrix", "M", math("\\mathbf{M}"), [M]);
    place("matrix", "f", math("\\mathbf{f}"), [f]);
  }
  wire(container);
  await typeset(added);
  return added;
}
