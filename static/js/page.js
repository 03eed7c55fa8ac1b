// What every page shares beyond its own module (loaded by base.html): keyboard and screen-reader
// details that no single panel owns.
// - Plot toolbars (plotly's .modebar buttons, a dozen per plot) are left out of the tab order, so
//   Tab goes from the controls to the derivation, not through forty zoom buttons first; the
//   toolbar still answers the mouse.
// - On a phone, folded sections (details.fold[data-phone="closed"]) start closed, so the page is
//   the animation and the derivation until a student opens the rest.
// - A plot in a section just opened is redrawn at its width (plotly cannot measure a closed box).

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

foldForPhones();
watch();
