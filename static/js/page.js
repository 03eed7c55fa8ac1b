// What every page shares beyond its own module (loaded by base.html): keyboard and screen-reader
// details that no single panel owns.
// - Plot toolbars (plotly's .modebar buttons, a dozen per plot) are left out of the tab order, so
//   Tab goes from the controls to the derivation, not through forty zoom buttons first; the
//   toolbar still answers the mouse.
// - On a phone, folded sections (details.fold[data-phone="closed"]) start closed, so the page is
//   the animation and the derivation until a student opens the rest.
// - A plot in a section just opened is redrawn at its width (plotly cannot measure a closed box).
// - A run the server refuses (m = 0, a state past a stop) leaves the last good run's numbers in
//   the statistics, the instruments, the plots and the work table: they are greyed and say so,
//   with the reason, until a run goes through (`#canvas[data-error]`, set and cleared by scene.js).
// - A "Your turn" box, once opened, hides the lines of its step that are its answer (T, V, Q_j,
//   L, an equation of motion and the lines that work it out, q̈), until the student checks a
//   correct answer, presses "Show answer" or the step's own "show" button, or closes the box: the
//   derived expression just above it gave the exercise away (student play-test).

const PHONE = "(max-width: 600px)";

function tidy(root) {
  if (!(root instanceof Element)) return;
  for (const b of root.querySelectorAll(".modebar-btn:not([tabindex])")) b.setAttribute("tabindex", "-1");
}

function watch() {
  tidy(document.body);
  new MutationObserver((changes) => {
    for (const c of changes) for (const n of c.addedNodes) if (n.nodeType === 1) tidy(n.parentElement || n);
  }).observe(document.body, { childList: true, subtree: true });
}

function foldForPhones() {
  if (!window.matchMedia(PHONE).matches) return;
  for (const d of document.querySelectorAll('details.fold[data-phone="closed"]')) d.open = false;
}

document.addEventListener("toggle", (e) => {
  const d = e.target;
  if (!(d instanceof HTMLDetailsElement) || !d.open || !window.Plotly) return;
  for (const p of d.querySelectorAll(".js-plotly-plot")) window.Plotly.Plots.resize(p);
}, true);

/** What a refused run leaves behind: the panels that still show the last good run. */
const STALE = ["#stats", "#instruments", ".plots .plot-grid", "#work-panel .work-grid"];

function markStale() {
  const canvas = document.getElementById("canvas");
  if (!canvas) return;
  const mark = () => {
    const reason = canvas.dataset.error;
    for (const selector of STALE) {
      const part = document.querySelector(selector);
      if (!part) continue;
      const note = part.previousElementSibling?.classList.contains("stale-note") ? part.previousElementSibling : null;
      part.classList.toggle("stale", Boolean(reason));
      if (!reason) {
        note?.remove();
        delete part.dataset.stale;
        continue;
      }
      part.dataset.stale = reason;
      const why = reason.replace(/^The simulation failed:\s*/, "");
      const what = canvas.dataset.errorFrom === "page"
        ? `the page failed to show the run for (${why})` : `the server refused (${why})`;
      const text = canvas.dataset.hadRun === "0"
        ? `Greyed: no run has been shown yet; the values now set are ones ${what}.`
        : `Greyed: these are the last run's numbers, not the values now set, which ${what}.`;
      const out = note || Object.assign(document.createElement("p"), { className: "stale-note" });
      out.setAttribute("role", "status");
      out.textContent = text;
      if (!note) part.before(out);
    }
  };
  new MutationObserver(mark).observe(canvas, { attributes: true, attributeFilter: ["data-error"] });
  mark();
}

// ------------------------------------------------------------------ "Your turn" withholds its answer

/** The labels (derivation.js's data-label, the step's `labels`) of the lines that answer the k-th
 * "Your turn" box of a step: the boxes come in derivation.js yourTurn's order (energy: T, V;
 * forces: Q_j per coordinate; lagrange: L, then the equation of motion per coordinate; matrix: q̈
 * per coordinate), and the coordinates in the order of the step's own labels. */
export function answerLabels(stepId, k, labels) {
  const nth = (pattern, j) => labels.filter((l) => pattern.test(l))[j];
  if (stepId === "energy") return labels.filter((l) => (k === 0 ? /^T(_|$)/ : k === 1 ? /^V(_|$)/ : /^$/).test(l));
  if (stepId === "forces") return [nth(/^Q_/, k)].filter(Boolean);
  if (stepId === "matrix") return [nth(/_ddot$/, k)].filter(Boolean);
  if (stepId === "lagrange") {
    if (k === 0) return labels.filter((l) => l === "L");
    const eom = nth(/^EoM /, k - 1);
    if (!eom) return [];
    const q = eom.slice(4);
    return [eom, `dL/d${q}_dot`, `d/dt dL/d${q}_dot`, `dL/d${q}`].filter((l) => labels.includes(l));
  }
  return [];
}

const labelOf = (line) => line.dataset.label || "";

/** Hide, in one step, the answers of its open and not yet revealed boxes; show the rest. */
function withhold(step) {
  const boxes = [...step.querySelectorAll(":scope > .yourturn")];
  const lines = [...step.querySelectorAll(".math-line")];
  const labels = lines.map(labelOf);
  const hidden = new Set();
  boxes.forEach((box, k) => {
    if (box.open && !box.dataset.revealed) for (const l of answerLabels(step.dataset.step, k, labels)) hidden.add(l);
  });
  lines.forEach((line, j) => line.classList.toggle("withheld", hidden.has(labels[j])));
  let note = step.querySelector(".withheld-note");
  if (!hidden.size) {
    note?.remove();
    return;
  }
  if (!note) {
    note = Object.assign(document.createElement("p"), { className: "withheld-note" });
    const show = Object.assign(document.createElement("button"), { type: "button", className: "small", textContent: "show it" });
    show.addEventListener("click", () => {
      for (const box of boxes) if (box.open) box.dataset.revealed = "shown";
      withhold(step);
    });
    note.append("Part of this step is hidden while you try “Your turn” below. ", show);
  }
  const first = lines.find((line) => line.classList.contains("withheld"));
  if (note.nextElementSibling !== first) first.before(note);
}

function withholdAnswers() {
  document.addEventListener("toggle", (e) => {
    const box = e.target;
    if (!(box instanceof HTMLDetailsElement) || !box.classList.contains("yourturn")) return;
    const step = box.closest(".step");
    if (!step) return;
    const result = box.querySelector(".result");
    if (result && !box.dataset.watched) {
      box.dataset.watched = "1";
      // a checked answer that is correct has earned the derivation (data-checked is set once the
      // answer is settled and typeset)
      new MutationObserver(() => {
        if (box.querySelector(".verdict.ok")) {
          box.dataset.revealed = "correct";
          withhold(step);
        }
      }).observe(result, { attributes: true, attributeFilter: ["data-checked"] });
    }
    withhold(step);
  }, true);
  document.addEventListener("click", (e) => {
    const reveal = e.target instanceof Element && e.target.closest(".yourturn .reveal");
    if (!reveal) return;
    const box = reveal.closest(".yourturn");
    box.dataset.revealed = "asked";
    withhold(box.closest(".step"));
  }, true);
}

foldForPhones();
watch();
markStale();
withholdAnswers();
