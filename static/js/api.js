// Thin wrappers over /api/v1: every failure becomes an Error carrying the API's field details.

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

export async function getJSON(url) {
  const r = await fetch(url);
  const body = await r.json().catch(() => ({}));
  if (!r.ok) throw new ApiError(r.status, body.detail ?? r.statusText);
  return body;
}

export async function postJSON(url, payload, { signal } = {}) {
  const r = await fetch(url, {
    method: "POST",
    headers: { "content-type": "application/json" },
    body: JSON.stringify(payload),
    signal,
  });
  const body = await r.json().catch(() => ({}));
  if (!r.ok) throw new ApiError(r.status, body.detail ?? r.statusText);
  return body;
}

export async function typeset(elements) {
  // MathJax renders the LaTeX in place; pages without it simply show the source.
  if (!window.MathJax) return;
  await window.MathJax.startup.promise;
  await window.MathJax.typesetPromise(elements);
}
