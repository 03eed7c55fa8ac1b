// Thin wrappers over /api/v1: every failure becomes an Error carrying the API's field details.
// The page counts requests in flight on <html data-pending>, so a test (or a person) can tell
// when it has settled.

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

async function call(url, init) {
  pending(+1);
  try {
    const r = await fetch(url, init);
    const body = await r.json().catch(() => ({}));
    if (!r.ok) throw new ApiError(r.status, body.detail ?? r.statusText);
    return body;
  } finally {
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

/** Render the LaTeX inside `elements` with MathJax (pages without it keep the source). MathJax
 * may still be loading (a page can load it async, so it does not hold up the page's script). */
export async function typeset(elements) {
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

function mathJax() {
  const ready = () => (window.MathJax && window.MathJax.startup ? window.MathJax : null);
  if (ready() || !window.MathJax) return Promise.resolve(ready());
  const script = [...document.scripts].find((s) => /mathjax\/.*\.js/.test(s.src));
  if (!script) return Promise.resolve(null);
  return new Promise((resolve) => {
    script.addEventListener("load", () => resolve(ready()), { once: true });
    script.addEventListener("error", () => resolve(null), { once: true });
    setTimeout(() => resolve(ready()), 20000); // never wait forever for the math
  });
}
