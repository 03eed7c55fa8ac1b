// Thin wrappers over /api/v1: every failure becomes an Error carrying the API's field details.
// The page counts requests in flight on <html data-pending>, so a test (or a person) can tell
// when it has settled; whatever takes longer than SLOW_MS (a request, the math being typeset)
// shows a progress bar at the top of the page, saying what it waits for (`busy`).

import { applyPrerendered, usePrerendered } from "./prerendered.js";

export class ApiError extends Error {
  constructor(status, detail) {
    const text = Array.isArray(detail)
      ? detail.map((d) => `${d.field}: ${d.message}`).join("; ")
      : String(detail);
    super(text);
    this.status = status;
    this.detail = detail;
  }
}

function pending(delta) {
  const root = document.documentElement;
  root.dataset.pending = String(Number(root.dataset.pending || 0) + delta);
}

/** Past this many ms, work the page waits for shows the progress bar (a person notices a wait
 * of a third of a second; shorter ones would only flicker). */
export const SLOW_MS = 300;
const slow = new Map(); // what is slow now → how many of it

/**
 * Mark the start of work the page waits for; call the returned function when it is done. If it
 * is still going after SLOW_MS, the progress bar shows (with `what`) until every slow thing is
 * done.
 */
export function busy(what = "Loading…") {
  let late = false, over = false;
  const timer = setTimeout(() => {
    if (over) return;
    late = true;
    slow.set(what, (slow.get(what) || 0) + 1);
    showProgress();
  }, SLOW_MS);
  return () => {
    if (over) return;
    over = true;
    clearTimeout(timer);
    if (!late) return;
    const n = (slow.get(what) || 1) - 1;
    if (n > 0) slow.set(what, n);
    else slow.delete(what);
    showProgress();
  };
}

const WAITS = [ // what a request is for, in words, by its path
  [/\/simulate$/, "Computing the motion…"], [/\/derive$/, "Deriving the equations…"],
  [/\/equilibria$/, "Finding equilibria…"], [/\/check$/, "Checking your answer…"],
  [/\/live$/, "Loading the live equations…"],
];

function waitFor(url) {
  const path = String(url).split("?")[0];
  return (WAITS.find(([re]) => re.test(path)) || [null, "Loading…"])[1];
}

/** The bar at the top of the page (built here, so every page has it without a template of its
 * own): an indeterminate progressbar, the things waited for in words in the bottom corner. */
function showProgress() {
  const root = document.documentElement;
  let bar = document.getElementById("progress");
  if (!slow.size) {
    delete root.dataset.slow;
    if (bar) bar.hidden = true;
    return;
  }
  if (!bar) {
    bar = document.createElement("div");
    bar.id = "progress";
    bar.setAttribute("role", "progressbar");
    bar.setAttribute("aria-label", "working");
    Object.assign(bar.style, { position: "fixed", top: "0", left: "0", right: "0", zIndex: "1000",
      pointerEvents: "none" });
    const stripe = document.createElement("div");
    Object.assign(stripe.style, { height: "3px", background:
      "linear-gradient(90deg, transparent 0%, #1c7ed6 35%, #1c7ed6 65%, transparent 100%)",
    backgroundSize: "50% 100%", backgroundRepeat: "no-repeat" });
    stripe.animate?.([{ backgroundPosition: "-50% 0" }, { backgroundPosition: "150% 0" }],
      { duration: 1100, iterations: Infinity });
    const words = document.createElement("span");
    words.className = "progress-words";
    // at the bottom corner: at the top it would cover the top bar's buttons
    Object.assign(words.style, { position: "fixed", bottom: "8px", right: "8px", padding: "0.1rem 0.5rem",
      font: "0.8rem system-ui, sans-serif", background: "#e7f5ff", color: "#1864ab",
      border: "1px solid #a5d8ff", borderRadius: "4px" });
    bar.append(stripe, words);
    document.body.append(bar);
  }
  const words = [...slow.keys()].join(" · ");
  bar.querySelector(".progress-words").textContent = words;
  bar.setAttribute("aria-valuetext", words);
  bar.hidden = false;
  root.dataset.slow = words;
}

/** Count `promise` on <html data-pending> until it settles (work the page has not finished,
 * such as plots waiting for their library); returns it. */
export function track(promise) {
  pending(+1);
  return Promise.resolve(promise).finally(() => pending(-1));
}

async function call(url, init) {
  pending(+1);
  const done = busy(waitFor(url));
  try {
    const r = await fetch(url, init);
    const body = await r.json().catch(() => ({}));
    if (!r.ok) throw new ApiError(r.status, body.detail ?? r.statusText);
    return body;
  } finally {
    done();
    pending(-1);
  }
}

export function getJSON(url) {
  return call(url);
}

export function postJSON(url, payload, { signal } = {}) {
  return call(url, {
    method: "POST",
    headers: { "content-type": "application/json" },
    body: JSON.stringify(payload),
    signal,
  });
}

/** Render the LaTeX inside `elements` with MathJax (pages without it keep the source): from the
 * prerendered math where it has the formula (a built-in derivation, static/js/prerendered.js),
 * else live. MathJax may still be loading (a page can load it async, so it does not hold up the
 * page's script). */
export async function typeset(elements) {
  const left = applyPrerendered(elements);
  if (left.length) await typesetLive(left);
}

/** Use the prerendered math at `url` for the derivation's steps (see prerendered.js). */
export function prerenderedMath(url) {
  return usePrerendered(url, typesetLive);
}

async function typesetLive(elements) {
  let mj = await mathJax();
  if (!mj) return;
  await mj.startup.promise;
  // Loaded before the page was parsed, MathJax defines typesetPromise only once its startup has
  // run on the page: wait for it (a few frames) rather than fail.
  for (let i = 0; i < 400 && typeof window.MathJax.typesetPromise !== "function"; i++) {
    await new Promise((resolve) => setTimeout(resolve, 50));
  }
  mj = window.MathJax;
  if (typeof mj.typesetPromise !== "function") return;
  await mj.startup.promise;
  mj.typesetClear?.(elements);
  await mj.typesetPromise(elements);
}

let mathHold = Promise.resolve();
let releaseHold = () => {};

/** Run MathJax's bundle only once `promise` settles (a scene page: once its animation moves),
 * whoever asks to typeset before then — or once `releaseMathJax` is called, whichever is first. */
export function holdMathJax(promise) {
  mathHold = new Promise((resolve) => {
    releaseHold = resolve;
    Promise.resolve(promise).catch(() => {}).then(resolve);
  });
}

/** Math a reader is looking at now (a derivation in view: lecture mode, a link to it) is worth
 * more than the first frames' smoothness: stop holding MathJax back. */
export function releaseMathJax() {
  releaseHold();
}

/** MathJax once it has run: a page names its bundle in a <link rel="preload" data-mathjax>
 * (templates/mathjax.html), fetched with the page and run here on the first typeset (and not
 * before `holdMathJax`'s promise), so its ~0.1 s of script does not hold up what the page shows
 * first. */
async function mathJax() {
  // (before it runs, window.MathJax is the page's configuration, which has a `startup` too)
  const ready = () => (window.MathJax?.version && window.MathJax.startup ? window.MathJax : null);
  if (ready() || !window.MathJax) return ready();
  let script = [...document.scripts].find((s) => /mathjax\/.*\.js/.test(s.src));
  const link = document.querySelector("link[data-mathjax]");
  if (!script && !link) return null;
  if (!script) await mathHold;
  script ||= [...document.scripts].find((s) => /mathjax\/.*\.js/.test(s.src)); // asked meanwhile
  return new Promise((resolve) => {
    if (ready()) { resolve(ready()); return; }
    if (!script) {
      script = Object.assign(document.createElement("script"), { src: link.href, async: true });
      document.head.append(script);
    }
    script.addEventListener("load", () => resolve(ready()), { once: true });
    script.addEventListener("error", () => resolve(null), { once: true });
    setTimeout(() => resolve(ready()), 20000); // never wait forever for the math
  });
}
