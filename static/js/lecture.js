// Lecture mode: large type and high contrast for a projector, the derivation revealed one step at a
// time (→, space, PageDown reveal the next; ←, PageUp hide it), p plays or pauses, f full screen.
// The derivation stands beside the animation, so in lecture mode it is moved next to it in the
// page too: the tab order and a screen reader follow what the room sees. Its equations are fitted
// to the narrower column (fit.js).
import { fitEquations, watchEquations } from "./fit.js";

export class Lecture {
  constructor({ list, toggle, counter, onToggle, onPlay }) {
    this.list = list;
    this.toggle = toggle;
    this.counter = counter;
    this.onToggle = onToggle;
    this.onPlay = onPlay;
    this.revealed = 1;
    this.section = list.closest(".derivation");
    this.home = this.section ? { parent: this.section.parentNode, next: this.section.nextSibling } : null;
    watchEquations(list);
    if (toggle) toggle.addEventListener("click", () => this.set(!this.on));
    document.addEventListener("keydown", (e) => this.#key(e));
  }

  get on() {
    return document.body.classList.contains("lecture");
  }

  set(on) {
    document.body.classList.toggle("lecture", on);
    document.documentElement.classList.toggle("lecture", on); // rem units follow the big type
    this.#place(on);
    if (this.toggle) {
      this.toggle.textContent = on ? "Leave lecture mode" : "Lecture mode";
      this.toggle.setAttribute("aria-pressed", String(on));
    }
    this.apply();
    this.onToggle?.(on);
  }

  /** The derivation right after the animation's column in lecture mode, back home otherwise. */
  #place(on) {
    const main = this.home && this.home.parent.querySelector(":scope > .col-main");
    if (!main) return;
    if (on && main.nextSibling !== this.section) main.after(this.section);
    else if (!on && this.section.parentNode === this.home.parent && this.section.nextSibling !== this.home.next) {
      this.home.parent.insertBefore(this.section, this.home.next);
    }
  }

  #key(e) {
    const t = e.target;
    if (t instanceof Element && t.closest("input, textarea, select, [contenteditable]")) return;
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    if (e.key === "p") {
      this.onPlay?.();
    } else if (e.key === "f") {
      if (document.fullscreenElement) document.exitFullscreen();
      else document.documentElement.requestFullscreen?.().catch(() => {});
    } else if (this.on && ["ArrowRight", " ", "PageDown"].includes(e.key)) {
      e.preventDefault();
      this.step(+1);
    } else if (this.on && ["ArrowLeft", "PageUp"].includes(e.key)) {
      e.preventDefault();
      this.step(-1);
    }
  }

  step(delta) {
    this.revealed += delta;
    this.apply(true);
  }

  /** Show the first `revealed` steps (all of them outside lecture mode). */
  apply(scroll = false) {
    const steps = [...this.list.querySelectorAll(":scope > .step")];
    this.revealed = Math.max(1, Math.min(this.revealed, steps.length || 1));
    steps.forEach((s, k) => {
      s.classList.toggle("hidden", this.on && k >= this.revealed);
      s.classList.toggle("current", this.on && k === this.revealed - 1);
    });
    this.list.dataset.revealed = String(this.on ? this.revealed : steps.length);
    if (this.counter) this.counter.textContent = steps.length ? `step ${this.revealed} of ${steps.length}` : "";
    const last = steps[this.revealed - 1];
    if (scroll && this.on && last) last.scrollIntoView({ block: "nearest", behavior: "smooth" });
    fitEquations(this.list); // a step just shown is measured only now
  }
}
