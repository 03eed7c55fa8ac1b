// The derivation, step by step: each step's title, its sentence, its equations (LaTeX rendered by
// MathJax) with buttons to copy a line as LaTeX or as plain text, and "your turn" boxes that check
// an answer typed in plain notation (POST /api/v1/check).
import { postJSON, typeset } from "./api.js";
import { dottedTex, inline, inlineMath, labelText, nameTex } from "./texnames.js";

const el = (tag, props = {}, ...children) => {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
};


export function renderSteps(list, derivation, { target, coordinates }) {
  list.replaceChildren(...derivation.steps.map((step, k) => renderStep(step, k, target, coordinates)));
}

function renderStep(step, k, target, coordinates) {
  const li = el("li", { className: "step" });
  li.dataset.step = step.id;
  li.append(el("h3", {}, el("span", { className: "num", textContent: `${k + 1}` }), step.title));
  const body = el("div", { className: "step-body" });
  const words = el("div", { className: "step-words" });
  words.append(el("p", { className: "text" }, ...prose(step.text)));
  if (step.id === "fbd") {
    const figure = el("figure", { className: "fbd" });
    figure.innerHTML = `<svg id="fbd-svg" role="img" aria-label="free-body diagram"></svg>
      <figcaption><span id="fbd-legend" class="legend"></span>
      <span class="muted">Drawn at the animation's current instant: pause or scrub to study one.</span></figcaption>`;
    body.append(figure);
    for (const note of step.data?.constraints || []) words.append(el("p", { className: "note" }, ...prose(note)));
  }
  step.latex.forEach((tex, j) => words.append(mathLine(tex, step.plain[j] ?? "", step.labels?.[j] ?? "", coordinates)));
  body.prepend(words);
  li.append(body);
  for (const box of yourTurn(step.id, target, coordinates)) li.append(box);
  return li;
}

/**
 * A sentence with `$…$` math as text and nodes for MathJax, each math with the punctuation right
 * after it in a span that does not wrap: the line broke between "$\\mathbf f(q,\\dot q,t)$" and
 * its "." (a full stop alone at the start of a line, at 1024×768 in lecture mode).
 */
export function prose(text) {
  return String(text).split(/(\$[^$]+\$[.,;:!?)]*)/).filter(Boolean).map((part) =>
    part.startsWith("$") ? el("span", { className: "math-nowrap", textContent: inlineMath(part) }) : part);
}

/** One display equation with its tools; the engine's label (what provenance.js and page.js look
 * lines up by) in data-label, and shown as symbols: "dL/dtheta_dot" reads ∂L/∂θ̇. */
function mathLine(tex, plain, label, coordinates = []) {
  const row = el("div", { className: "math-line" });
  row.dataset.label = label;
  const math = el("div", { className: "math", textContent: `\\[${tex}\\]` });
  math.dataset.latex = tex;
  const tools = el("div", { className: "line-tools" });
  if (label) tools.append(el("span", { className: "line-label", textContent: labelText(label, coordinates), title: label }));
  tools.append(copyButton("LaTeX", tex), copyButton("text", plain));
  row.append(math, tools);
  return row;
}

function copyButton(what, text) {
  const b = el("button", { type: "button", className: "copy", textContent: `copy ${what}`, title: text });
  b.dataset.copy = what;
  b.addEventListener("click", async () => {
    try {
      await navigator.clipboard.writeText(text);
      b.textContent = "copied ✓";
    } catch {
      window.prompt(`Copy the ${what}:`, text); // no clipboard (plain http on another host)
    }
    setTimeout(() => { b.textContent = `copy ${what}`; }, 1200);
  });
  return b;
}

function yourTurn(stepId, target, coordinates) {
  // prompts as math: Q_θ, θ̈₁, not Q_theta, theta1_ddot
  const asks = {
    energy: [["T", null, `${inline("T")} =`], ["V", null, `${inline("V")} =`]],
    // Q_j^{NC}, as the forces step writes it: only the non-conservative part is asked (gravity
    // and springs are in V); "Q_x" led students following the notes' eq. 31 to add the weight
    forces: coordinates.map((q) => ["Q", q, `${inline(`Q_{${nameTex(q)}}^{NC}`)} =`]),
    lagrange: [["L", null, `${inline("L")} =`],
      ...coordinates.map((q) => ["eom", q, `equation of motion for ${inline(nameTex(q))}:`])],
    matrix: coordinates.length <= 3 ? coordinates.map((q) => ["accel", q, `${inline(dottedTex(q, 2))} =`]) : [],
  }[stepId] || [];
  return asks.map(([quantity, coordinate, prompt]) => {
    const box = el("details", { className: "yourturn" });
    box.innerHTML = `<summary></summary>
      <div class="row"><span class="prompt"></span><input type="text" placeholder="e.g. 1/2 m l^2 theta'^2"
      aria-label="your answer"><button type="button" class="check">Check</button>
      <button type="button" class="reveal">Show answer</button></div>
      <div class="result" aria-live="polite" aria-atomic="true"><div class="echo"></div>
      <p class="verdict"></p><ul class="feedback"></ul><div class="expected"></div></div>
      <div class="predict"></div>`;
    box.querySelector("summary").textContent = `Your turn: ${prompt.replace(/\s*[:=]$/, "")}`;
    // The prompt inside the box is typeset when the box is first opened, not with its step:
    // nobody sees it before, and the double pendulum has nine (issue 13: every step typeset
    // within 1.0 s). Until then MathJax skips it (its ignore class) and its source is out of sight.
    const promptEl = box.querySelector(".prompt");
    promptEl.textContent = prompt;
    promptEl.classList.add("mathjax_ignore");
    promptEl.style.visibility = "hidden";
    box.addEventListener("toggle", async () => {
      if (!box.open || !promptEl.classList.contains("mathjax_ignore")) return;
      promptEl.classList.remove("mathjax_ignore");
      await typeset([promptEl]);
      promptEl.style.visibility = "";
    });
    const input = box.querySelector("input");
    const result = box.querySelector(".result");
    const verdict = box.querySelector(".verdict");
    // the box narrows (a phone turned, lecture mode's column): which math scrolls is asked again
    new ResizeObserver(() => markWide(result)).observe(result);
    let asked = 0; // only the latest check may fill the box: a slow earlier answer never lands on it
    const ask = async (reveal) => {
      // an empty box is no answer: never sent as "0" (which is Q^NC of every conservative scene,
      // so doing nothing was "✔ Correct"); a 0 typed on purpose is checked like any answer
      if (!reveal && !input.value.trim()) {
        ++asked; // a check still on its way must not land on the box after this
        for (const part of [".echo", ".expected"]) box.querySelector(part).textContent = "";
        box.querySelector(".feedback").replaceChildren();
        offerPrediction(box.querySelector(".predict"), null);
        verdict.className = "verdict empty";
        verdict.textContent = "Type an answer first.";
        result.dataset.checked = String(asked);
        input.focus();
        return;
      }
      const mine = ++asked;
      // "Show answer" on an empty box: the API wants an answer, so a 0 is sent, but no verdict
      // on that 0 is shown (it was "✔ Correct" where the answer is 0), only the derived answer
      const unanswered = !input.value.trim();
      const body = { ...target(), quantity, answer: unanswered ? "0" : input.value, reveal };
      if (coordinate) body.coordinate = coordinate;
      try {
        const r = await postJSON("/api/v1/check", body);
        if (mine !== asked) return;
        if (unanswered) {
          box.querySelector(".echo").textContent = "";
          verdict.textContent = "The derived answer:";
          verdict.className = "verdict";
          box.querySelector(".feedback").replaceChildren();
          box.querySelector(".expected").textContent = r.expected_latex ? `\\[${r.expected_latex}\\]` : "";
          offerPrediction(box.querySelector(".predict"), null);
          await typeset([result]);
          markWide(result);
          result.dataset.checked = String(mine);
          return;
        }
        box.querySelector(".echo").textContent = `read as \\(\\displaystyle ${r.answer_latex}\\)`;
        // equal at every state sampled but not proved: neither right nor wrong is claimed
        const open = !r.correct && r.confirmed === false;
        verdict.textContent = r.correct ? "✔ Correct" : open ? "? Not confirmed" : "✘ Not yet";
        verdict.className = `verdict ${r.correct ? "ok" : open ? "open" : "bad"}`;
        // each feedback sentence carries its math as $…$ (LaTeX), rendered by MathJax
        // in display size: a fraction in a sentence is otherwise 8 px high (student play-test)
        const shown = (f) => inlineMath(f).replace(/\\\(/g, "\\(\\displaystyle ");
        box.querySelector(".feedback").replaceChildren(...r.feedback.map((f) => el("li", { textContent: shown(f) })));
        box.querySelector(".expected").textContent = r.expected_latex ? `\\[${r.expected_latex}\\]` : "";
        offerPrediction(box.querySelector(".predict"), r.correct ? null : body);
        await typeset([result]);
        markWide(result);
        result.dataset.checked = String(mine); // settled and typeset (tests wait on it)
      } catch (err) {
        if (mine !== asked) return;
        // an answer that could not be read replaces the previous answer's result, never sits
        // beside it (a stale "✔ Correct" under a new parse error)
        for (const part of [".echo", ".expected"]) box.querySelector(part).textContent = "";
        box.querySelector(".feedback").replaceChildren();
        offerPrediction(box.querySelector(".predict"), null);
        showError(verdict, err.message, body.answer);
        result.dataset.checked = String(mine);
      }
    };
    box.querySelector(".check").addEventListener("click", () => ask(false));
    box.querySelector(".reveal").addEventListener("click", () => ask(true));
    input.addEventListener("keydown", (e) => {
      e.stopPropagation(); // typing is not a lecture-mode shortcut
      if (e.key === "Enter") ask(false);
    });
    return box;
  });
}

/** The math of a result wider than its box scrolls inside it (app.css: a 390 px phone's "read as"
 * of a double pendulum's T ran to 509 px and the whole page scrolled sideways); `scrolls` marks
 * which, for the fade and the "scroll →" under it. */
function markWide(result) {
  for (const math of result.querySelectorAll("mjx-container")) {
    math.classList.remove("scrolls"); // measured at its own width (inline math has no scrollWidth)
    const box = math.closest(".echo, li, .expected") || result;
    const style = getComputedStyle(box);
    const right = box.getBoundingClientRect().right - parseFloat(style.paddingRight) - parseFloat(style.borderRightWidth);
    const wide = math.scrollWidth > math.clientWidth + 1 || math.getBoundingClientRect().right > right + 1;
    math.classList.toggle("scrolls", wide);
  }
}

/**
 * A refusal of /check read for a student: a plain sentence and the place it points at in the text
 * as typed. The server says `answer: syntax error: the expression ends with '+', a term is missing
 * after it (at character 20: …theta'^2 ⟨here⟩+)`: the field and "syntax error" are jargon, and
 * for a missing term its position is the operator's while what is wrong comes after it. So:
 * `{ sentence: "Can't read your answer: a term is missing after '+' at the end.", text, at }`
 * with `text` the whole answer (when the server's excerpt is found in it at its position, else
 * the excerpt) and `at` the index in `text` where the marker goes: after the operator for a
 * missing term (whichever of the two places the server points at), else where it points.
 * `at` is null when the message points nowhere.
 */
export function readRefusal(message, typed = "") {
  const raw = String(message).replace(/^answer:\s*/, "");
  const m = /^(.*) \(at character (\d+): (.*)⟨here⟩(.*)\)$/s.exec(raw);
  const what = (m ? m[1] : raw).replace(/^syntax error:?\s*/i, "");
  const say = (plain) => `Can't read your answer: ${plain || "something does not fit here"}${/[.!?]$/.test(plain) ? "" : "."}`;
  if (!m) return { sentence: say(what), text: typed, at: null };
  let [, , char, before, after] = m;
  if (before.startsWith("…")) before = before.slice(1);
  if (after.endsWith("…")) after = after.slice(0, -1);
  let text = `${before}${after}`, at = before.length;
  const index = Number(char) - 1;
  // the excerpt was trimmed (strip) by the server: find it in the answer at its position
  const lead = typed.slice(0, index);
  if (typed && lead.trimEnd().endsWith(before.trim()) && typed.slice(index).trimStart().startsWith(after.trim())) {
    text = typed;
    at = index;
  }
  // a missing term: the marker goes after the operator it is missing after, not before it, and
  // the sentence names the operator where it is (character n counts from 1, as the server does)
  const atEnd = /^the expression ends with '(.+)', a term is missing after it$/s.exec(what)
    || /^a term is missing after '(.+)' at the end$/s.exec(what);
  const op = (/a term is missing after '(.+?)'/.exec(what) || atEnd || [])[1];
  if (op) {
    const rest = text.slice(at);
    const skip = rest.length - rest.trimStart().length;
    if (rest.trimStart().startsWith(op)) at += skip + op.length;
    const where = text.slice(0, at).endsWith(op) ? ` at character ${at - op.length + 1 + (text === typed ? 0 : index - before.length)}` : "";
    at = Math.max(0, Math.min(at, text.length));
    const plain = atEnd ? `it ends with a '${op}'${where ? ` (${where.trim()})` : ""} and no term after it`
      : `a term is missing after the '${op}'${where}`;
    return { sentence: say(plain), text, at };
  }
  const plain = `${what || "something does not fit here"} (at character ${char})`;
  return { sentence: say(plain), text, at: Math.max(0, Math.min(at, text.length)) };
}

/** A refusal from the parser: a plain sentence, then the answer as typed with a ▸ where the
 * problem is (`theta +▸` for a term missing after the '+'). */
function showError(verdict, message, typed) {
  verdict.className = "verdict bad";
  const { sentence, text, at } = readRefusal(message, typed);
  const words = el("span", { className: "refusal", textContent: inlineMath(sentence) });
  if (at === null) {
    verdict.replaceChildren(words);
  } else {
    // the typed text stays text (never math, whatever it holds); the message's own math renders
    const code = el("code", { className: "typed" }, text.slice(0, at),
      el("mark", { textContent: "▸", title: `character ${at + 1}` }), text.slice(at));
    verdict.replaceChildren(words, " ", code);
  }
  typeset([words]);
}

/** Quantities whose wrong answer is a model of its own that can be integrated (predict.js). */
const PREDICTS = new Set(["eom", "accel", "T", "V", "L", "Q"]);

/** After a wrong answer, a button that integrates it beside the true motion; cleared otherwise. */
function offerPrediction(area, request) {
  area.replaceChildren();
  if (!request || !PREDICTS.has(request.quantity)) return;
  const button = el("button", { type: "button", className: "predict-open", textContent: "See what your answer predicts" });
  const out = el("div", { className: "predict-out" });
  button.addEventListener("click", async () => {
    button.disabled = true;
    const { showPrediction } = await import("./predict.js");
    await showPrediction(out, request);
    button.disabled = false;
  });
  area.append(button, out);
}
