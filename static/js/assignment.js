// A student's assignment page: their own variant (never its keys), each part with an answer box,
// the checker's feedback, attempts left and the score.

import { postJSON, typeset } from "./api.js";
import { renderSteps } from "./derivation.js";
import { api, askToken, el, forgetToken, inlineMath, say } from "./assignment_common.js";

const root = document.getElementById("parts");
const id = root.dataset.assignment;
const base = `/api/v1/assignments/${encodeURIComponent(id)}`;
const WHAT = { T: "T", V: "V", L: "L", Q: "Q", eom: "the equation of motion", accel: "the acceleration", momentum: "the momentum",
  equilibrium: "the equilibrium", frequency: "the small-oscillation angular frequency ω" };

function attemptsText(part) {
  const left = part.attempts_left === null ? "unlimited attempts" : `${part.attempts_left} attempt(s) left`;
  return `Score ${part.score.toFixed(2)} · ${part.attempts_used} used · ${left}`;
}

function feedbackList(list, lines) {
  list.replaceChildren(...lines.map((line) => el("li", inlineMath(line))));
  typeset([list]);
}

function renderPart(part) {
  const box = el("section", "", { class: "panel assignment-part", id: `part-${part.id}` });
  const asked = part.coordinate ? `${WHAT[part.quantity]} for ${part.coordinate}` : WHAT[part.quantity];
  box.append(el("h2", `Part ${part.id}: ${asked}`));
  if (part.prompt) box.append(el("p", part.prompt));
  const form = el("form", "", { class: "assignment-answer" });
  const input = el("input", "", { id: `answer-${part.id}`, autocomplete: "off", spellcheck: "false" });
  const label = el("label", `Your answer (plain text, e.g. m*l^2*theta_dot^2/2)`, { for: input.id });
  const button = el("button", "Submit", { type: "submit", class: "primary" });
  form.append(label, input, button);
  const line = el("p", attemptsText(part), { class: "muted", id: `score-${part.id}` });
  const list = el("ul", "", { class: "feedback", "aria-live": "polite" });
  box.append(form, line, list);
  if (part.last) {
    input.value = part.last.answer;
    feedbackList(list, [`${part.last.code} (last answer)`, ...part.last.feedback]);
  }
  if (part.attempts_left === 0) button.disabled = true;
  form.addEventListener("submit", async (event) => {
    event.preventDefault();
    if (!input.value.trim()) return;
    button.disabled = true;
    try {
      const done = await api(`${base}/parts/${encodeURIComponent(part.id)}/submit`, {
        method: "POST", body: { answer: input.value, request_id: crypto.randomUUID?.() },
      });
      const counted = done.counted ? `attempt ${done.attempt}: score ${done.score.toFixed(2)}` : "no attempt used";
      feedbackList(list, [`${done.code} (${counted})`, ...done.feedback]);
      await update();
    } catch (error) {
      feedbackList(list, [error.message]);
      button.disabled = false;
    }
  });
  return box;
}

let derivation = null;
let shownKey = "";

/** The derivation's steps this student may see now (the server says which: all in practice,
 * in a graded assignment only those that give away no part still open). */
async function showDerivation(mine) {
  const panel = document.getElementById("derivation-panel");
  const key = mine.steps_shown.join(",");
  if (key === shownKey) return;
  shownKey = key;
  derivation ||= await postJSON("/api/v1/derive", { scene: mine.scene });
  const steps = derivation.steps.filter((s) => mine.steps_shown.includes(s.id) && s.id !== "fbd");
  const hidden = derivation.steps.length - steps.length - 1;
  document.getElementById("derivation-note").textContent = hidden > 0
    ? `${hidden} step(s) stay hidden until the parts they would give away are done (right, or out of attempts).`
    : "";
  renderSteps(document.getElementById("steps"), { ...derivation, steps }, {
    target: () => ({ scene: mine.scene }), coordinates: mine.scene.coordinates,
  });
  panel.hidden = false;
  typeset([panel]);
}

async function refresh() {
  const mine = await api(`${base}/mine`);
  document.getElementById("title").textContent = mine.title;
  document.getElementById("scene-summary").textContent = `${mine.scene.title}: ${mine.scene.summary || ""}`;
  const given = document.getElementById("given");
  const units = mine.scene.units || {};
  given.replaceChildren(...Object.entries(mine.parameters).flatMap(([name, value]) => [
    el("dt", name), el("dd", `${value}${units[name] ? ` ${units[name]}` : ""}`),
  ]));
  document.getElementById("total").textContent = mine.score.toFixed(2);
  document.getElementById("variant").hidden = false;
  root.replaceChildren(...mine.parts.map(renderPart));
  if (mine.closed) say("This assignment is closed: answers are no longer taken.");
  await showDerivation(mine);
}

/** After a submission: the scores and attempts left, without redrawing the parts. */
async function update() {
  const mine = await api(`${base}/mine`);
  document.getElementById("total").textContent = mine.score.toFixed(2);
  await showDerivation(mine);
  for (const part of mine.parts) {
    document.getElementById(`score-${part.id}`).textContent = attemptsText(part);
    document.querySelector(`#part-${part.id} button`).disabled = part.attempts_left === 0 || mine.closed;
  }
}

async function main() {
  await askToken();
  try {
    await refresh();
    say("");
  } catch (error) {
    if (error.status === 401) forgetToken();
    say(error.message, true);
  }
}

main();
