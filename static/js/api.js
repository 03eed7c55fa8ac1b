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

/** Render the LaTeX inside `elements` with MathJax (pages without it keep the source). */
export async function typeset(elements) {
  const mj = window.MathJax;
  if (!mj || !mj.startup) return;
  await mj.startup.promise;
  mj.typesetClear?.(elements);
  await mj.typesetPromise(elements);
}
