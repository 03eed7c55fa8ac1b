// "Take it with you": the derivation as LaTeX, the run as a standalone Python script, the
// trajectory as CSV or JSON, the spec as TOML or JSON, and a share link that restores the page
// exactly (/api/v1/export/..., docs/export.md). A built-in scene's files are plain links carrying
// the page's own query (its parameters, initial state, method, tolerance or step, t_end); a
// posted spec's are POSTs whose answer is saved as a file.
import { ApiError, postJSON } from "./api.js";

function el(tag, props = {}, ...children) {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
}

/** What the page's state is, for the API: `getState()` returns {parameters, initial, settings,
 * lecture, lectureStep}; settings as static/js/integrator.js keeps them. */
function runBody(source, state) {
  const s = state.settings || {};
  const fixed = ["rk4", "euler", "symplectic_euler", "implicit_midpoint"].includes(s.method);
  return {
    ...source,
    parameters: state.parameters || {},
    initial: state.initial || {},
    method: s.method || "dop853_c",
    // a link's own atol (integrator.js readSettings) stays what it was, else atol = rtol
    ...(fixed ? { dt: Number(s.dt) } : { rtol: Number(s.tol), atol: Number(s.atol || s.tol) }),
    t_end: Number(s.t_end) || 10,
  };
}

async function download(url, body, filename, status) {
  status.textContent = `Preparing ${filename}…`;
  const r = await fetch(url, {
    method: "POST",
    headers: { "content-type": "application/json" },
    body: JSON.stringify(body),
  });
  if (!r.ok) {
    const detail = (await r.json().catch(() => ({}))).detail ?? r.statusText;
    throw new ApiError(r.status, detail);
  }
  const link = el("a", { href: URL.createObjectURL(await r.blob()), download: filename });
  document.body.append(link);
  link.click();
  link.remove();
  status.textContent = `${filename} saved.`;
}

/** Mount the panel in `container`; `getState()` is read at each click, so the files are those
 * of the page as it is then. */
export function mountExports(container, { sceneId = null, spec = null, getState = () => ({}) } = {}) {
  const source = sceneId ? { scene_id: sceneId } : { scene: spec };
  const status = el("p", { className: "muted", id: "export-status" });
  status.setAttribute("role", "status");
  const list = el("ul", { className: "exports", id: "export-links" });
  const files = [
    ["Derivation (LaTeX)", "derivation.tex", "/api/v1/export/latex", false],
    ["Run as a Python script", "run.py", "/api/v1/export/script", true],
    ["Trajectory (CSV)", "trajectory.csv", "/api/v1/export/trajectory?format=csv", true],
    ["Trajectory (JSON)", "trajectory.json", "/api/v1/export/trajectory?format=json", true],
    ["Spec (TOML)", "spec.toml", "/api/v1/export/spec?format=toml", false],
    ["Spec (JSON)", "spec.json", "/api/v1/export/spec?format=json", false],
  ];
  for (const [label, file, post, withRun] of files) {
    const link = el("a", { textContent: label });
    link.dataset.file = file;
    if (sceneId) {
      // a GET of the page's own query: the browser downloads it like any file
      const base = `/api/v1/export/scenes/${encodeURIComponent(sceneId)}/${file}`;
      const refresh = () => { link.href = withRun ? base + location.search : base; };
      refresh();
      link.addEventListener("focus", refresh);
      link.addEventListener("pointerenter", refresh);
      link.addEventListener("click", refresh);
    } else {
      link.href = "#";
      link.addEventListener("click", (event) => {
        event.preventDefault();
        const body = withRun ? runBody(source, getState() || {}) : source;
        download(post, body, file, status).catch((err) => {
          status.textContent = `Could not export ${file}: ${err.message}`;
        });
      });
    }
    list.append(el("li", {}, link));
  }
  const share = el("button", { type: "button", textContent: "Copy a share link", id: "share" });
  const shared = el("input", { type: "url", readOnly: true, id: "share-url", hidden: true });
  shared.setAttribute("aria-label", "share link");
  share.addEventListener("click", async () => {
    const state = getState() || {};
    const s = state.settings || {};
    const body = {
      ...runBody(source, state),
      compare: Boolean(s.compare),
      ...(s.compare ? { method_b: s.methodB } : {}),
      lecture: Boolean(state.lecture),
      lecture_step: state.lectureStep ?? null,
    };
    if (body.lecture_step === null) delete body.lecture_step;
    try {
      const answer = await postJSON("/api/v1/export/share", body);
      shared.value = location.origin + answer.url;
      shared.hidden = false;
      shared.select();
      await navigator.clipboard?.writeText(shared.value).catch(() => {});
      status.textContent = "Share link ready (copied where the browser allows).";
    } catch (err) {
      status.textContent = `Could not make a share link: ${err.message}`;
    }
  });
  const summary = el("summary", {}, el("h2", { textContent: "Take it with you", id: "h-exports" }));
  const fold = el("details", { className: "fold", open: true }, summary, list, el("p", {}, share, " ", shared), status);
  fold.dataset.phone = "closed"; // folded on a phone, like the other panels below the animation
  if (matchMedia("(max-width: 600px)").matches) fold.open = false; // page.js's phone width
  const root = el("section", { className: "panel exports-panel", id: "exports" }, fold);
  root.setAttribute("aria-labelledby", "h-exports");
  container.append(root);
  return root;
}
