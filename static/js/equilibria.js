// Equilibria of the scene at the current parameters (POST /api/v1/equilibria): where, whether
// stable, the small-oscillation frequencies, and buttons that start the motion near one.
import { postJSON, typeset } from "./api.js";
import { inline, inlineMath, nameTex } from "./texnames.js";
import { SceneGeometry } from "./geometry.js";
import { fmt } from "./integrator.js";
import { toSVG } from "./render.js";
import { sceneShapes } from "./shapes.js";
import { View } from "./view.js";

const W = 150, H = 100;

/** The badge's class per kind: marginal (neutral, undecided) has its own slate, not the
 * unstable pink it wore before (a family of neutral equilibria read as a warning). */
const KIND_CLASS = {
  "stable": "stable", "asymptotically stable": "stable", "gyroscopically stable": "stable",
  "marginal": "neutral", "unstable": "unstable",
};
/** The neutral badge's colours, set here because the page's stylesheet has no rule for it:
 * slate #3b4a63 on #e8edf5 is 7.6:1 (AA needs 4.5:1 for its small type). */
const NEUTRAL = { color: "#3b4a63", background: "#e8edf5" };

/** The first time the panel says $\mathbf K$ (or $\mathbf C$), what it is: the reasons speak
 * of them as known, bold as the derivation's matrix step writes its matrices (a cart's mass M
 * is not the mass matrix).
 * The gloss follows the reason: K is the Hessian of V only where a potential stands behind it
 * (not under a follower load, and of the effective potential where a frame turns); C's
 * symmetric part is damping and its antisymmetric part gyroscopic, whatever their source (the
 * reason names it: Coriolis only where a frame turns, else forces that do no work). */
const GLOSSES = [
  ["$\\mathbf K$", (text) => (/not symmetric/.test(text)
    ? "the stiffness matrix $\\mathbf K$ (the restoring force per unit displacement, not the Hessian of any potential)"
    : /effective potential/.test(text)
      ? "the stiffness matrix $\\mathbf K$ (the Hessian of the effective potential)"
      : "the stiffness matrix $\\mathbf K = \\partial^2 V/\\partial q^2$")],
  ["$\\mathbf C$", () => "$\\mathbf C$ (the velocity matrix: its symmetric part damping, its antisymmetric part gyroscopic)"],
];

/** `text` with the first unglossed bold K or C explained in place; `said` keeps what was. */
function glossed(text, said) {
  for (const [symbol, gloss] of GLOSSES) {
    if (said.has(symbol) || !text.includes(symbol)) continue;
    said.add(symbol);
    const words = gloss(text);
    text = text.replace(symbol, () => words);
  }
  return text;
}

/** Modes that repeat an earlier shape (a degenerate pair at a pole) start the same motion. */
function sameShape(a, b) {
  return a.length === b.length && a.every((x, i) => Math.abs(x - b[i]) < 1e-9);
}

/** Each stability kind (the response's `kind`) in words. */
const KIND_WORDS = {
  "stable": "Stable: the potential has a minimum here",
  "asymptotically stable": "Asymptotically stable: damping makes every small motion die out",
  "gyroscopically stable": "Gyroscopically stable: not a minimum of the potential, but gyroscopic terms (forces that do no work, or Coriolis where a frame turns) keep small motions bounded (any damping would undo it)",
  "marginal": "Marginal: neutral (no force pulls it back along some direction) or undecided by the linear test",
  "unstable": "Unstable: a small displacement grows",
};

/** A small drawing of the system resting at q (one zero-length run gives the positions). */
async function sketch(svg, target, parameters, spec, q) {
  try {
    const initial = Object.fromEntries(Object.entries(q).flatMap(([k, v]) => [[k, v], [`${k}_dot`, 0]]));
    const run = await postJSON("/api/v1/simulate", { ...target, parameters, initial, t_end: 0,
      check_sensitivity: false });
    const geom = new SceneGeometry(spec, run);
    const view = new View(W, H, geom.is3D).fit(geom.extent(), geom.is3D ? 8 : 14);
    svg.innerHTML = toSVG(sceneShapes(geom, view, 0, { radius: 6, path: false, axes: false }));
    svg.dataset.ready = "1";
  } catch {
    svg.remove();
  }
}

/** Fill `box`; `startAt(q, mode)` is called by the buttons (mode: a normal-mode shape or null). */
export async function showEquilibria(box, target, parameters, startAt, spec = null) {
  try {
    const r = await postJSON("/api/v1/equilibria", { ...target, parameters });
    // every warning shown (a capped list, dry friction, a drive), its math ($…$) rendered
    const notes = (r.warnings.length || r.equilibria.length ? r.warnings : ["No equilibrium at these parameters."])
      .map((w) => Object.assign(document.createElement("p"), {
        className: "muted eq-warning", textContent: inlineMath(w),
      }));
    if (!r.equilibria.length) {
      box.replaceChildren(...notes);
      await typeset(notes);
      return;
    }
    const ul = document.createElement("ul");
    const said = new Set();
    for (const e of r.equilibria) {
      const li = document.createElement("li");
      // in the scene's coordinate order; a free coordinate is 'any φ', as the steps say it
      const names = (spec?.coordinates || []).filter((k) => k in e.q);
      const order = names.length === Object.keys(e.q).length ? names : Object.keys(e.q);
      const where = order.map((k) => (e.free.includes(k)
        ? `any ${inline(nameTex(k))}` : inline(`${nameTex(k)} = ${fmt(e.q[k])}`))).join(", ");
      // the closed form as math (symbolic_latex); the plain `symbolic` only to tell whether it
      // says more than the numbers do (θ = 0 needs no second line)
      const latex = e.symbolic_latex || {};
      const numeric = Object.entries(e.q).map(([k, v]) => `${k} = ${fmt(v)}`).join(", ");
      const plain = Object.entries(e.symbolic).map(([k, v]) => `${k} = ${v}`).join(", ");
      const closed = plain && plain !== numeric
        ? Object.entries(e.symbolic).map(([k, v]) => inline(`${nameTex(k)} = ${latex[k] ?? v}`)).join(", ")
        : "";
      const kind = e.kind || (e.stable ? "stable" : "unstable");
      li.innerHTML = `<div><span class="where"></span> <span class="tag"></span></div>
        <div class="muted closed"></div><div class="muted freq"></div><div class="muted why"></div><div class="buttons"></div>`;
      li.querySelector(".where").textContent = where;
      const tag = li.querySelector(".tag");
      const badge = KIND_CLASS[kind] || (e.stable ? "stable" : "unstable");
      tag.classList.add(badge);
      if (badge === "neutral") Object.assign(tag.style, NEUTRAL);
      tag.textContent = kind;
      tag.title = KIND_WORDS[kind] || "";
      // the reason says why in full; the kind's own gloss would say half of it twice
      if (e.reason) {
        // its math ($…$) typeset with the rest of the list, as the derivation's steps are
        li.querySelector(".why").textContent = inlineMath(glossed(`${kind[0].toUpperCase()}${kind.slice(1)}: ${e.reason}.`, said));
      }
      if (spec) {
        const svg = document.createElementNS("http://www.w3.org/2000/svg", "svg");
        svg.setAttribute("class", "eq-sketch");
        svg.setAttribute("viewBox", `0 0 ${W} ${H}`);
        svg.setAttribute("width", W);
        svg.setAttribute("height", H);
        li.prepend(svg);
        sketch(svg, target, parameters, spec, e.q);
      }
      // "always", or "numeric" (found by the search at these values: no condition is known)
      const known = e.exists_when !== "always" && e.exists_when !== "numeric";
      const condition = e.exists_when_latex || (known ? e.exists_when : "");
      const exists = condition ? ` (exists when ${e.exists_when_latex ? inline(condition) : condition})` : "";
      li.querySelector(".closed").textContent = closed + exists;
      if (e.frequencies.length) {
        li.querySelector(".freq").textContent = `${inline(`\\omega = ${e.frequencies.map((f) => fmt(f)).join(", ")}`)} rad/s`;
      }
      const buttons = li.querySelector(".buttons");
      const button = (text, mode) => {
        const b = Object.assign(document.createElement("button"), { type: "button", textContent: text });
        b.addEventListener("click", () => startAt(e.q, mode));
        buttons.append(b);
      };
      button("start near", null);
      // A whirling mode (coordinates out of phase) is not a displacement pattern to start from.
      e.modes.forEach((mode, k) => {
        const phases = (e.mode_phases || [])[k] || [];
        const repeat = e.modes.slice(0, k).some((other) => sameShape(other, mode));
        if (!repeat && phases.every((p) => Math.abs(p) < 1e-9)) button(`excite mode ${k + 1}`, mode);
      });
      ul.append(li);
    }
    box.replaceChildren(ul, ...notes);
    await typeset([ul, ...notes]);
  } catch (err) {
    box.replaceChildren(Object.assign(document.createElement("p"), { className: "muted", textContent: err.message }));
  }
}
