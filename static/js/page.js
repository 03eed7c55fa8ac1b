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
      const text = "Greyed: these are the last run's numbers, not the values now set, which the " +
        `server refused (${reason.replace(/^The simulation failed:\s*/, "")}).`;
      const out = note || Object.assign(document.createElement("p"), { className: "stale-note" });
      out.setAttribute("role", "status");
      out.textContent = text;
      if (!note) part.before(out);
    }
  };
  new MutationObserver(mark).observe(canvas, { attributes: true, attributeFilter: ["data-error"] });
  mark();
}

foldForPhones();
watch();
markStale();
