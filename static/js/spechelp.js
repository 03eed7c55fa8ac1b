// The editor's help: every field of a scene spec with its meaning, units and a one-line example,
// read from the schema the API publishes (GET /openapi.json: the descriptions of mechanics/spec.py's
// models), so the help and the API can never disagree (issue 26, item 4: "the schema link shows
// none"). A description reads "Meaning, units. Example: <json>"; the example is shown as code.

/** The models a spec is built of, in the order a student meets them. */
const ORDER = ["SceneSpec", "Body", "PointSpec", "Frame", "FramePosition", "Inertia", "Gravity", "Spring",
  "Damper", "Force", "Potential", "Stop"];
const TITLES = {
  SceneSpec: "The spec (top level)", Body: "A body (bodies[…])", PointSpec: "A point (points[…])",
  Frame: "A frame (frames[…])", FramePosition: "A position given in a frame", Inertia: "An inertia",
  Gravity: "Gravity", Spring: "A spring (springs[…])", Damper: "A damper (dampers[…])",
  Force: "A force or a torque (forces[…], torques[…])", Potential: "A potential (potentials[…])",
  Stop: "A stop (stops[…])",
};

/** "Meaning. Example: x" → ["Meaning.", "x"]. */
export function splitExample(description) {
  const text = String(description || "");
  const at = text.lastIndexOf("Example: ");
  return at < 0 ? [text.trim(), ""] : [text.slice(0, at).trim(), text.slice(at + 9).trim()];
}

const refName = (ref) => String(ref).split("/").pop();

/** A field's type in words: "list of Body", "text", "number or expression", … */
export function typeText(s) {
  if (!s) return "";
  if (s.$ref) return refName(s.$ref);
  if (s.anyOf) {
    const kinds = [...new Set(s.anyOf.filter((x) => x.type !== "null").map(typeText))];
    const words = kinds.join(" or ");
    return /text or number/.test(words) ? "expression (text) or number" : words;
  }
  if (s.enum) return s.enum.map((v) => JSON.stringify(v)).join(" | ");
  if (s.const !== undefined) return JSON.stringify(s.const);
  if (s.type === "array") return `list of ${typeText(s.items) || "values"}`;
  if (s.type === "object") {
    const value = s.additionalProperties || Object.values(s.patternProperties || {})[0];
    return value ? `map of name → ${typeText(value)}` : "object";
  }
  return { string: "text", number: "number", integer: "number", boolean: "true/false" }[s.type] || s.type || "";
}

function el(tag, props = {}, ...children) {
  const e = Object.assign(document.createElement(tag), props);
  e.append(...children);
  return e;
}

/** One model's fields as a definition list. */
function modelList(name, schema) {
  const required = new Set(schema.required || []);
  const list = el("dl", { className: "field-list" });
  for (const [field, s] of Object.entries(schema.properties || {})) {
    const [meaning, example] = splitExample(s.description);
    const type = typeText(s);
    const dt = el("dt", {}, el("code", { textContent: field }),
      el("span", { className: "field-type", textContent: ` ${type}${required.has(field) ? " · required" : ""}` }));
    const dd = el("dd", {}, meaning || "(no description)");
    if (example) dd.append(el("br"), "Example: ", el("code", { className: "example", textContent: example }));
    dt.id = `field-${name}-${field}`;
    list.append(dt, dd);
  }
  return list;
}

/** Fill `box` with the help, from the app's schema; says so if the schema cannot be read. */
export async function mountSpecHelp(box) {
  let schemas;
  try {
    const r = await fetch("/openapi.json", { headers: { accept: "application/json" } });
    if (!r.ok) throw new Error(`HTTP ${r.status}`);
    schemas = (await r.json()).components?.schemas || {};
  } catch (err) {
    box.replaceChildren(el("p", { className: "muted", textContent: `The field list cannot be loaded (${err.message}).` }));
    return;
  }
  const parts = [el("p", { className: "muted" },
    "Expressions are plain text in the coordinates, the parameters and t: products with *, powers with ** ",
    "(", el("code", { textContent: "m*l**2" }), "), functions such as ", el("code", { textContent: "sin(theta)" }),
    "; a coordinate's rate is ", el("code", { textContent: "theta_dot" }), " in ", el("code", { textContent: "initial" }), ".")];
  for (const name of ORDER) {
    if (!schemas[name]) continue;
    const fold = el("details", { className: "help-model" }, el("summary", { textContent: TITLES[name] || name }));
    if (name === "SceneSpec") fold.open = true;
    fold.dataset.model = name;
    fold.append(modelList(name, schemas[name]));
    parts.push(fold);
  }
  box.replaceChildren(...parts);
  box.dataset.ready = "1";
}
