// A slider and a number box for every parameter and every initial q and q_dot, and the page state
// in the URL query (?m=1.2&theta=0.5&method=rk4&dt=0.01), so a link reproduces a run exactly.

import { nameText } from "./texnames.js";
const SETTINGS = ["method", "method_b", "tol", "atol", "dt", "t_end", "compare", "lecture", "phase"];

/** Units of a quantity that is never 0 nor negative: a mass, a length, a moment of inertia. */
const STRICTLY_POSITIVE = new Set(["kg", "m", "kg*m^2", "kg m^2", "kg·m²"]);

/** Whether a parameter in `unit` must stay above 0 (a mass, a length): its slider then starts at
 * a small positive value, since m = 0 or l = 0 makes every run fail and greys every panel
 * (issue 26, item 5). A number box still takes any value (and the server names what is wrong). */
export function mustBePositive(unit) {
  return STRICTLY_POSITIVE.has(String(unit || "").trim());
}

/** A sensible slider range for a value: [0, 3x] for a positive parameter ([x/100, 3x] for one
 * that must stay above 0: a mass, a length), ±π for an angle. */
export function sliderRange(value, { angle = false, positive = false, strict = false } = {}) {
  let lo, hi;
  const a = Math.abs(value);
  if (angle) [lo, hi] = [-Math.PI, Math.PI];
  else if (strict && value > 0) [lo, hi] = [value / 100, 3 * a];
  else if (positive) [lo, hi] = [0, a > 0 ? 3 * a : 2];
  else if (a === 0) [lo, hi] = [-2, 2];
  else [lo, hi] = [-3 * a, 3 * a];
  return [Math.min(lo, value), Math.max(hi, value)];
}

/** The scene's values, overridden by the query's (unknown names and non-numbers are ignored). */
export function readValues(spec, query) {
  const params = { ...(spec.parameters || {}) };
  const initial = {};
  for (const q of spec.coordinates) {
    initial[q] = (spec.initial || {})[q] ?? 0;
    initial[`${q}_dot`] = (spec.initial || {})[`${q}_dot`] ?? 0;
  }
  for (const [k, v] of query) {
    const x = Number(v);
    if (v === "" || !Number.isFinite(x) || SETTINGS.includes(k)) continue;
    if (k in params) params[k] = x;
    else if (k in initial) initial[k] = x;
  }
  return { params, initial };
}

/** The state as a query string: parameters, initial state, integrator settings (with a link's
 * own atol, integrator.js readSettings), and the editor's share token: the token is the spec a
 * reload of /editor restores, so every rewrite of the address keeps it (editor.js drops it when
 * another spec is derived). */
export function writeQuery({ params, initial, settings, fixed, lecture }) {
  const q = new URLSearchParams();
  for (const [k, v] of Object.entries(params)) q.set(k, String(v));
  for (const [k, v] of Object.entries(initial)) q.set(k, String(v));
  q.set("method", settings.method);
  if (fixed(settings.method) || (settings.compare && fixed(settings.methodB))) q.set("dt", settings.dt);
  if (!fixed(settings.method) || (settings.compare && !fixed(settings.methodB))) {
    q.set("tol", settings.tol);
    if (settings.atol) q.set("atol", settings.atol);
  }
  q.set("t_end", String(settings.t_end));
  if (settings.compare) {
    q.set("compare", "1");
    q.set("method_b", settings.methodB);
  }
  if (lecture) q.set("lecture", "1");
  const here = typeof location === "undefined" ? "" : location.search; // (none in node)
  const token = new URLSearchParams(here).get("share");
  if (token) q.set("share", token);
  return q.toString();
}

/** A value as its number box shows it: 4 significant digits (a slider moves in steps of 1/500 of
 * its range, so more is noise: 0.7853981633974483 reads 0.7854), never fewer than the integer
 * part's digits (1234.5 stays 1235, not 1.235e3), and no trailing zeros. The exact value is what
 * the page keeps and sends; the box's title carries it for anyone who wants every digit. */
export function shownValue(value, digits = 4) {
  const x = Number(value);
  if (!Number.isFinite(x) || x === 0) return String(x);
  const whole = Math.floor(Math.log10(Math.abs(x))) + 1; // digits before the point
  const shown = Number(x.toPrecision(Math.min(21, Math.max(digits, whole))));
  return Math.abs(shown) < 1e-6 ? shown.toExponential() : String(shown);
}

/** Put `value` in a number box rounded for reading; the exact value in its title and data-exact
 * (the page sends the exact value it keeps, never the box's text). */
function showNumber(number, value) {
  number.value = shownValue(value);
  number.dataset.exact = String(value);
  number.title = number.value === String(value) ? "" : `exactly ${value}`;
}

/** Build the rows of sliders; `onChange(name, value)` fires on every move (the caller debounces,
 * or previews live), `onCommit(name, value)` when a value is settled: a slider let go, a number
 * entered. */
export function buildControls(box, rows, onChange, onCommit = () => {}) {
  box.replaceChildren();
  for (const { name, value, unit, angle, positive } of rows) {
    const [lo, hi] = sliderRange(value, { angle, positive, strict: positive && mustBePositive(unit) });
    const row = document.createElement("div");
    row.className = "control";
    row.innerHTML = `<label for="n-${name}"><span class="name"></span> <span class="unit"></span></label>
      <input id="s-${name}" type="range" aria-label="${name} slider">
      <input id="n-${name}" type="number" step="any">`;
    // the symbol (θ̇₁); the name the editor, the answers and the link use (theta1_dot) on hover
    row.querySelector(".name").textContent = nameText(name);
    row.querySelector("label").title = name;
    row.querySelector(".unit").textContent = unit || "";
    const slider = row.querySelector('input[type="range"]');
    const number = row.querySelector('input[type="number"]');
    Object.assign(slider, { min: lo, max: hi, step: (hi - lo) / 500 });
    slider.value = value;
    showNumber(number, value);
    // A slider's own value is min + k·step (−1.79699099785336): below its resolution of 1/500
    // of the range, so the value it sets is the one its box shows (−1.797), and the box, the
    // link and the run agree. Values from elsewhere (a drag, a link) stay exact behind the box.
    const picked = () => Number(shownValue(Number(slider.value)));
    slider.addEventListener("input", () => {
      const v = picked();
      showNumber(number, v);
      onChange(name, v);
    });
    slider.addEventListener("change", () => onCommit(name, picked()));
    number.addEventListener("change", () => {
      const v = Number(number.value);
      if (number.value === "" || !Number.isFinite(v)) return;
      number.dataset.exact = String(v); // typed: exactly what the box says
      number.title = "";
      if (v < Number(slider.min)) slider.min = v;
      if (v > Number(slider.max)) slider.max = v;
      slider.value = v;
      onChange(name, v);
      onCommit(name, v);
    });
    box.append(row);
  }
}

/** Show a value in a control without firing its change (a button set it); said on the document
 * as `control-set` (lecture mode's strip, strip.js, shows it too). */
export function setControl(name, value) {
  document.dispatchEvent(new CustomEvent("control-set", { detail: { name, value } }));
  const slider = document.getElementById(`s-${name}`);
  const number = document.getElementById(`n-${name}`);
  if (number) showNumber(number, value);
  if (slider) {
    if (value < Number(slider.min)) slider.min = value;
    if (value > Number(slider.max)) slider.max = value;
    slider.value = value;
  }
}
