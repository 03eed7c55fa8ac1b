// The catalog's drawings: each scene at its initial configuration (SVG), with a faint line showing
// where its first second of motion takes it. One request brings every scene's spec and short run
// (GET /api/v1/scenes/catalog), instead of two per scene.
//
// On a server still warming up (just started: every scene's derivation and first runs being
// made), that one answer waits until the runs are made, which can be many seconds. Meanwhile
// each card shows a placeholder that says the drawing is coming, and a line above the cards
// shows how far the server is (GET /healthz's `warm`: {done, of}), polled until the drawings come.
import { track } from "./api.js";
import { SceneGeometry } from "./geometry.js";
import { toSVG } from "./render.js";
import { sceneShapes } from "./shapes.js";
import { View } from "./view.js";

const W = 240, H = 150;
const POLL_MS = 800; // how often /healthz is asked while the drawings are not there
const TRIES = 3; // the catalog is asked again after a failure (a restart, a dropped connection)

function drawOne(svg, entry) {
  try {
    if (!entry || !entry.run) throw new Error("no run");
    const geom = new SceneGeometry(entry.spec, entry.run);
    const view = new View(W, H, geom.is3D).fit(geom.extent(), geom.is3D ? 10 : 22);
    svg.innerHTML = toSVG(sceneShapes(geom, view, 0, { radius: 7, path: true, axes: false }));
    svg.dataset.ready = "1";
  } catch (err) {
    svg.dataset.ready = "error";
    svg.innerHTML = `<text x="${W / 2}" y="${H / 2}" text-anchor="middle" fill="#5b6575" font-size="12">no drawing</text>`;
  }
  svg.removeAttribute("aria-busy");
}

/** The card's placeholder while its drawing is coming: a faint pendulum-like sketch that pulses
 * (app.css .thumb-wait; still under prefers-reduced-motion) and a line of text. */
function placeholder(svg) {
  svg.dataset.ready = "waiting";
  svg.setAttribute("aria-busy", "true");
  svg.innerHTML = `<g class="thumb-wait">
    <line x1="${W / 2 - 18}" y1="34" x2="${W / 2 + 18}" y2="34" stroke="#adb5bd" stroke-width="2"/>
    <line x1="${W / 2}" y1="34" x2="${W / 2 + 22}" y2="86" stroke="#adb5bd" stroke-width="2"/>
    <circle cx="${W / 2 + 22}" cy="86" r="8" fill="#ced4da"/></g>
    <text x="${W / 2}" y="124" text-anchor="middle" fill="#5b6575" font-size="12">preparing the drawing…</text>`;
}

/** The line above the cards: what is being waited for, with a progress bar of the warm-up. */
function progressLine() {
  const line = document.createElement("p");
  line.id = "catalog-progress";
  line.className = "catalog-progress muted";
  line.setAttribute("role", "status");
  const text = document.createElement("span");
  text.textContent = "Preparing the drawings…";
  const bar = document.createElement("progress");
  bar.setAttribute("aria-label", "server warm-up");
  line.append(text, " ", bar); // no value yet: an indeterminate bar until /healthz answers
  return { line, text, bar };
}

/** How the progress line reads for /healthz's `warm` ({done, of} or absent). */
export function warmText(warm) {
  if (!warm || !warm.of) return "Preparing the drawings…";
  if (warm.done >= warm.of) return "Drawing the scenes…";
  return `The server is getting the scenes ready (${warm.done} of ${warm.of}); the drawings follow.`;
}

/** The catalog's answer, fetched without api.js's "Loading…" badge: the line above the cards says
 * what is awaited, and the badge, fixed to the window's corner, floated over the last card of the
 * row there (student play-test, 1400 px). Still counted on <html data-pending>. */
async function fetchCatalog() {
  const r = await fetch("/api/v1/scenes/catalog");
  if (!r.ok) throw new Error(`catalog: ${r.status}`);
  return r.json();
}

async function catalogEntries() {
  for (let k = 1; ; k++) {
    try {
      return await track(fetchCatalog());
    } catch (err) {
      if (k >= TRIES) return [];
      await new Promise((resolve) => setTimeout(resolve, 1000 * k));
    }
  }
}

export async function drawThumbnails() {
  const svgs = [...document.querySelectorAll("svg[data-thumb]")];
  svgs.forEach(placeholder);
  const cards = document.getElementById("catalog");
  const progress = progressLine();
  let done = false;
  // shown only if the answer takes a moment: a warm server's drawings come before anyone reads it
  const shown = setTimeout(() => { if (!done && cards) cards.before(progress.line); }, 300);
  const poll = async () => {
    while (!done) {
      try {
        const r = await fetch("/healthz", { cache: "no-store" });
        const { warm } = await r.json();
        if (done) break;
        progress.text.textContent = warmText(warm);
        if (warm && warm.of) Object.assign(progress.bar, { max: warm.of, value: warm.done });
      } catch {
        // the server is restarting: keep the indeterminate bar, ask again
      }
      await new Promise((resolve) => setTimeout(resolve, POLL_MS));
    }
  };
  poll();
  const entries = await catalogEntries();
  done = true;
  clearTimeout(shown);
  progress.line.remove();
  const byId = new Map(entries.map((e) => [e.id, e]));
  for (const svg of svgs) drawOne(svg, byId.get(svg.dataset.thumb));
}
