// Lecture mode's control strip: play/pause and the scene's parameters, each a small slider and a
// number box, right under the animation in its sticky column, so the instructor changes l₂ beside
// the step being read instead of scrolling ~1300 px down to the Parameters panel (issue 26,
// item 2). The strip holds no state of its own: each of its inputs drives the panel's own control
// (the same `input` / `change` events, so the live preview, the server's run and the address
// follow exactly as from the panel), and it shows what the panel shows (controls.js announces
// every value set from elsewhere: a drag, a reset, a link, an equilibrium's start).
import { nameText } from "./texnames.js";
import { shownValue } from "./controls.js";

const $ = (id) => document.getElementById(id);

export class LectureStrip {
  /** `play` is the page's play/pause button (mirrored, never duplicated in behaviour). */
  constructor({ play }) {
    this.play = play;
    this.box = Object.assign(document.createElement("div"), { id: "lecture-strip", className: "lecture-strip" });
    this.box.setAttribute("role", "group");
    this.box.setAttribute("aria-label", "lecture controls: play and the parameters");
    this.box.hidden = true;
    document.querySelector(".stage-views")?.after(this.box);
    // the panel's values set by a drag, a reset, a link: shown here too
    document.addEventListener("control-set", (e) => this.#show(e.detail.name, e.detail.value));
    for (const id of ["params"]) {
      $(id)?.addEventListener("input", (e) => this.#mirror(e.target));
      $(id)?.addEventListener("change", (e) => this.#mirror(e.target));
    }
    new MutationObserver(() => this.#syncPlay()).observe(play, { childList: true, characterData: true, subtree: true, attributes: true });
  }

  /** Build the strip for the panel's current parameters (after controls.js built them). */
  build() {
    this.box.replaceChildren();
    const button = Object.assign(document.createElement("button"), { type: "button", id: "strip-play" });
    button.addEventListener("click", () => this.play.click());
    this.button = button;
    const rows = document.createElement("div");
    rows.className = "strip-params";
    for (const row of document.querySelectorAll("#params .control")) {
      const slider = row.querySelector('input[type="range"]');
      const number = row.querySelector('input[type="number"]');
      const name = slider.id.slice(2);
      const item = document.createElement("div");
      item.className = "strip-param";
      const label = Object.assign(document.createElement("label"), { htmlFor: `strip-n-${name}`, title: name });
      label.textContent = nameText(name);
      // m/s^2 as m/s², N*s/m as N·s/m: read from the back of the room
      const unit = row.querySelector(".unit")?.textContent.replace(/\^2/g, "²").replace(/\^3/g, "³").replace(/\*/g, "·");
      if (unit) label.append(Object.assign(document.createElement("span"), { className: "unit", textContent: ` ${unit}` }));
      const s = Object.assign(document.createElement("input"), { type: "range", id: `strip-s-${name}` });
      Object.assign(s, { min: slider.min, max: slider.max, step: slider.step, value: slider.value });
      s.setAttribute("aria-label", `${name} slider`);
      const n = Object.assign(document.createElement("input"), { type: "number", id: `strip-n-${name}`, step: "any" });
      n.value = number.value;
      // each move drives the panel's own control, as if it had been moved there
      s.addEventListener("input", () => { slider.value = s.value; slider.dispatchEvent(new Event("input", { bubbles: true })); });
      s.addEventListener("change", () => { slider.value = s.value; slider.dispatchEvent(new Event("change", { bubbles: true })); });
      n.addEventListener("change", () => { number.value = n.value; number.dispatchEvent(new Event("change", { bubbles: true })); });
      item.append(label, s, n);
      rows.append(item);
    }
    this.box.append(button, rows);
    this.#syncPlay();
  }

  /** Shown in lecture mode only (the panel is at hand otherwise). */
  set(on) {
    this.box.hidden = !on;
  }

  #mirror(input) {
    const name = input?.id?.slice(2);
    const slider = $(`s-${name}`), number = $(`n-${name}`);
    if (!slider || !number) return;
    const s = $(`strip-s-${name}`), n = $(`strip-n-${name}`);
    if (!s || !n) return;
    Object.assign(s, { min: slider.min, max: slider.max });
    if (document.activeElement !== s) s.value = slider.value;
    if (document.activeElement !== n) n.value = number.value;
  }

  #show(name, value) {
    const s = $(`strip-s-${name}`), n = $(`strip-n-${name}`);
    if (!s || !n) return;
    if (value < Number(s.min)) s.min = value;
    if (value > Number(s.max)) s.max = value;
    s.value = value;
    n.value = shownValue(value);
  }

  #syncPlay() {
    if (!this.button) return;
    this.button.textContent = this.play.textContent;
    this.button.setAttribute("aria-pressed", this.play.getAttribute("aria-pressed") || "false");
    this.button.title = "play / pause (p)";
  }
}
