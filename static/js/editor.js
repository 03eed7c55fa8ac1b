// The spec editor: write or paste a scene spec, derive it, see errors next to their fields,
// then simulate and animate it like a built-in scene.
import { ApiError, getJSON, postJSON } from "./api.js";
import { mountScene } from "./scene.js";

const $ = (id) => document.getElementById(id);
let view = null;

export async function mountEditor() {
  const query = new URLSearchParams(location.search);
  const start = query.get("from") || "simple_pendulum";
  $("template").value = start;
  await load(start);
  $("load-template").addEventListener("click", () => load($("template").value));
  $("derive").addEventListener("click", derive);
}

async function load(id) {
  const { spec } = await getJSON(`/api/v1/scenes/${id}`);
  $("spec").value = JSON.stringify(spec, null, 2);
  $("spec-errors").replaceChildren();
  $("spec").classList.remove("has-error");
}

function showErrors(items) {
  $("spec").classList.toggle("has-error", items.length > 0);
  $("spec-errors").replaceChildren(...items.map(({ field, message }) => {
    const li = document.createElement("li");
    li.dataset.field = field;
    li.innerHTML = "<code></code>: <span></span>";
    li.querySelector("code").textContent = field || "spec";
    li.querySelector("span").textContent = message;
    return li;
  }));
  const first = items[0];
  if (first) highlight(first.field);
}

function highlight(field) {
  // Select the line of the JSON that holds the last named key of the field path.
  const key = (field.match(/([A-Za-z_]\w*)(?:\[\d+\])*$/) || [])[1];
  if (!key) return;
  const text = $("spec").value;
  const at = text.indexOf(`"${key}"`);
  if (at >= 0) $("spec").setSelectionRange(at, text.indexOf("\n", at));
}

async function derive() {
  let spec;
  try {
    spec = JSON.parse($("spec").value);
  } catch (err) {
    showErrors([{ field: "JSON", message: err.message }]);
    return;
  }
  $("editor-status").textContent = "deriving…";
  try {
    await postJSON("/api/v1/derive", { scene: spec });
  } catch (err) {
    $("editor-status").textContent = "";
    showErrors(err instanceof ApiError && Array.isArray(err.detail) ? err.detail : [{ field: "", message: err.message }]);
    return;
  }
  showErrors([]);
  $("editor-status").textContent = "derived";
  $("result").hidden = false;
  if (view) await view.load(spec);
  else view = await mountScene({ spec });
}
