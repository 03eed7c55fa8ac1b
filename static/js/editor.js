// The spec editor: write or paste a scene spec, derive it, see each error beside the line of the
// field it names (the API's field paths, found in the text), then simulate and animate it like a
// built-in scene with the same modules.
import { ApiError, getJSON, postJSON } from "./api.js";
import { lineOf, locate } from "./jsonpath.js";
import { mountScene } from "./scene.js";

const $ = (id) => document.getElementById(id);
const LINE = 20; // px, as in app.css (.code textarea line-height)
let view = null;
let marks = [];
let shared = null; // the spec a share link brought, reloadable from the "Start from" list
let sharedToken = null; // its token, kept in the address while that spec is the one derived

export async function mountEditor() {
  const query = new URLSearchParams(location.search);
  const start = query.get("from") || "simple_pendulum";
  if ([...$("template").options].some((o) => o.value === start)) $("template").value = start;
  const area = $("spec");
  area.addEventListener("input", () => { numberLines(); });
  area.addEventListener("scroll", syncScroll);
  area.addEventListener("keydown", (e) => {
    e.stopPropagation(); // typing is not a lecture-mode shortcut
    if (e.key === "Enter" && (e.ctrlKey || e.metaKey)) { e.preventDefault(); derive(); }
  });
  $("load-template").addEventListener("click", () => {
    const id = $("template").value;
    if (id === SHARED && shared) showSpec(shared);
    else load(id);
  });
  $("derive").addEventListener("click", derive);
  const token = query.get("share");
  if (token && (await openShared(token))) return;
  await load(start);
}

/** A share link of one's own spec (/s/{token} lands here with ?share=token): the spec in the
 * editor, the page's state (values, integrator, lecture step) in the query the scene view reads,
 * then derived and run as the sharer saw it. The token stays in the address, so a reload (or the
 * address copied) brings back this spec, not a template; an address that already holds a state
 * beside the token is the page's own after a reload (values moved since), and is kept. False
 * (with the reason shown) if the link is bad. */
async function openShared(token) {
  let state;
  try {
    state = await getJSON(`/api/v1/export/share/${encodeURIComponent(token)}`);
  } catch (err) {
    showErrors([{ field: "share", message: `This share link cannot be opened: ${err.message}` }]);
    return false;
  }
  if (!state.scene) return false;
  sharedToken = token;
  // (the page writes `method` into every address it keeps: then this is a reload)
  if (!new URLSearchParams(location.search).has("method")) {
    history.replaceState(null, "", `${location.pathname}?${sharedQuery(state, token)}`);
  }
  shared = state.scene;
  showSpec(shared);
  await Promise.all([derive(), showOrigin(shared)]);
  return true;
}

/** The query the scene view reads for a shared state (controls.js writeQuery's keys), with the
 * token. */
function sharedQuery(state, token) {
  const q = new URLSearchParams();
  for (const [k, v] of Object.entries({ ...state.parameters, ...state.initial })) q.set(k, String(v));
  q.set("method", state.method || "dop853_c");
  if (state.dt != null) q.set("dt", String(state.dt));
  if (state.rtol != null) q.set("tol", String(state.rtol));
  if (state.atol != null && state.atol !== state.rtol) q.set("atol", String(state.atol));
  if (state.t_end != null) q.set("t_end", String(state.t_end));
  if (state.compare) q.set("compare", "1");
  if (state.method_b) q.set("method_b", state.method_b);
  if (state.lecture) q.set("lecture", "1");
  if (state.lecture_step != null) q.set("step", String(state.lecture_step + 1)); // the page counts from 1
  if (state.phase) q.set("phase", state.phase);
  q.set("share", token);
  return q;
}

const SHARED = ""; // the value of the "shared spec" entry of the "Start from" list

function showSpec(spec) {
  $("spec").value = JSON.stringify(spec, null, 2);
  numberLines();
}

/** The built-in scene a spec came from: the one with its title (a share link carries the spec,
 * not where it started), or null. */
export function originOf(spec, scenes) {
  const title = spec && typeof spec.title === "string" ? spec.title.trim() : "";
  const found = title && scenes.find((s) => s.title.trim() === title);
  return found ? found.id : null;
}

/** After a share link: the "Start from" list names the scene the spec came from, or a
 * "shared spec" entry (which Load brings back) when it came from none. */
async function showOrigin(spec) {
  const select = $("template");
  let id = null;
  try {
    id = originOf(spec, await getJSON("/api/v1/scenes"));
  } catch {
    id = null; // the list cannot be read: say "shared spec" rather than a wrong scene
  }
  select.querySelector("option[data-shared]")?.remove();
  const known = id !== null && [...select.options].some((o) => o.value === id);
  if (!known) {
    const entry = new Option("shared spec", SHARED, true, true);
    entry.dataset.shared = "1";
    select.prepend(entry);
  }
  select.value = known ? id : SHARED;
  select.dataset.origin = known ? id : "shared";
}

async function load(id) {
  const { spec } = await getJSON(`/api/v1/scenes/${id}`);
  $("spec").value = JSON.stringify(spec, null, 2);
  showErrors([]);
  $("errors-empty").textContent = "None found yet: press “Derive and simulate”.";
}

function numberLines() {
  const n = $("spec").value.split("\n").length;
  const gutter = $("gutter");
  if (gutter.childElementCount !== n) {
    gutter.replaceChildren(...Array.from({ length: n }, (_, k) => Object.assign(document.createElement("div"), { textContent: k + 1 })));
  }
  const bad = new Set(marks.flatMap((m) => m.lines));
  [...gutter.children].forEach((d, k) => d.classList.toggle("error", bad.has(k + 1)));
  syncScroll();
}

function syncScroll() {
  const area = $("spec");
  $("gutter").scrollTop = area.scrollTop;
  const inner = $("line-marks").firstElementChild;
  if (inner) inner.style.transform = `translate(${-area.scrollLeft}px, ${-area.scrollTop}px)`;
}

/** Where a field is in the text: its lines (at most six) and its first character. */
function place(field) {
  const text = $("spec").value;
  const at = locate(text, field);
  if (!at) return { lines: [1], start: 0, end: 0 };
  const first = lineOf(text, at.start), last = Math.min(lineOf(text, at.end), first + 5);
  return { lines: Array.from({ length: last - first + 1 }, (_, k) => first + k), start: at.start, end: at.end };
}

function showErrors(items) {
  marks = items.map((e) => ({ ...e, ...place(e.field) }));
  $("code").classList.toggle("has-error", marks.length > 0);
  $("errors-empty").hidden = marks.length > 0;
  $("errors-empty").textContent = "No problems: derived.";
  $("spec-errors").replaceChildren(...marks.map((m) => {
    const li = document.createElement("li");
    li.dataset.field = m.field;
    li.innerHTML = '<code></code>: <span class="message"></span><span class="where"></span>';
    li.querySelector("code").textContent = m.field || "spec";
    li.querySelector(".message").textContent = m.message;
    li.querySelector(".where").textContent = `line ${m.lines[0]}`;
    li.title = "show it in the spec";
    li.addEventListener("click", () => reveal(m));
    return li;
  }));
  const inner = document.createElement("div");
  inner.className = "inner";
  inner.append(...marks.flatMap((m) => m.lines.map((line, k) => {
    const div = document.createElement("div");
    div.className = "mark";
    div.style.top = `${10 + (line - 1) * LINE}px`;
    div.dataset.field = m.field;
    if (k === 0) div.title = `${m.field}: ${m.message}`;
    return div;
  })));
  $("line-marks").replaceChildren(inner);
  codeNote();
  numberLines();
  if (marks.length) reveal(marks[0], false);
}

/** The first problem in a line of its own right under the code, never over it: a note drawn at
 * a line's end covered the code after it once the text scrolled sideways, and ran off a phone's
 * screen (issue 26, item 4). The marked lines and the gutter show where; the Problems list all. */
function codeNote() {
  const note = $("code-note");
  if (!note) return;
  note.hidden = marks.length === 0;
  if (!marks.length) { note.replaceChildren(); return; }
  const m = marks[0];
  const go = Object.assign(document.createElement("button"), { type: "button", className: "small", textContent: `line ${m.lines[0]}` });
  go.addEventListener("click", () => reveal(m));
  const more = marks.length > 1 ? ` (and ${marks.length - 1} more under Problems)` : "";
  note.replaceChildren(go, " ", Object.assign(document.createElement("code"), { textContent: m.field || "spec" }),
    `: ${m.message}${more}`);
}

function reveal(m, focus = true) {
  const area = $("spec");
  area.scrollTop = Math.max(0, (m.lines[0] - 4) * LINE);
  if (focus) {
    area.focus({ preventScroll: true });
    area.setSelectionRange(m.start, m.end);
    area.scrollTop = Math.max(0, (m.lines[0] - 4) * LINE);
  }
  syncScroll();
}

function jsonError(err) {
  const text = $("spec").value;
  const m = err.message.match(/position (\d+)/) || [];
  const lc = err.message.match(/line (\d+) column (\d+)/);
  const line = lc ? Number(lc[1]) : m[1] ? lineOf(text, Number(m[1])) : 1;
  return { field: "JSON", message: err.message, line };
}

async function derive() {
  let spec;
  try {
    spec = JSON.parse($("spec").value);
  } catch (err) {
    const e = jsonError(err);
    showErrors([{ field: e.field, message: e.message }]);
    marks[0].lines = [e.line];
    $("spec-errors").querySelector(".where").textContent = `line ${e.line}`;
    $("line-marks").querySelector(".mark").style.top = `${10 + (e.line - 1) * LINE}px`;
    codeNote();
    numberLines();
    return;
  }
  $("editor-status").textContent = "deriving…";
  $("derive").disabled = true;
  let derivation;
  try {
    derivation = await postJSON("/api/v1/derive", { scene: spec });
  } catch (err) {
    $("editor-status").textContent = "";
    $("result").hidden = true;
    const detail = err instanceof ApiError && Array.isArray(err.detail)
      ? err.detail.map((d) => ({ ...d, field: d.field.replace(/^scene(\.|$)/, "") }))
      : [{ field: "", message: err.message }];
    showErrors(detail);
    return;
  } finally {
    $("derive").disabled = false;
  }
  showErrors([]);
  keepToken(spec);
  $("editor-status").textContent = `derived in ${(derivation.seconds ?? 0).toFixed(2)} s`;
  $("result").hidden = false;
  if (view) await view.load(spec, new URLSearchParams(), derivation);
  else view = await mountScene({ spec, derivation });
}

/** The share token stays in the address while the shared spec is the one derived (a reload
 * restores it); another spec derived drops it, and a reload brings back the template. */
function keepToken(spec) {
  if (!sharedToken) return;
  const q = new URLSearchParams(location.search);
  if (JSON.stringify(spec) === JSON.stringify(shared)) q.set("share", sharedToken);
  else q.delete("share");
  history.replaceState(null, "", `${location.pathname}?${q}${location.hash}`);
}
