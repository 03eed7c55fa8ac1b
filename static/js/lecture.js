// Lecture mode: large type and high contrast for a projector, the derivation revealed one step at a
// time (→, space, PageDown reveal the next; ←, PageUp hide it), p plays or pauses, f full screen.

export class Lecture {
  constructor({ list, toggle, counter, onToggle, onPlay }) {
    this.list = list;
    this.toggle = toggle;
    this.counter = counter;
    this.onToggle = onToggle;
    this.onPlay = onPlay;
    this.revealed = 1;
    if (toggle) toggle.addEventListener("click", () => this.set(!this.on));
    document.addEventListener("keydown", (e) => this.#key(e));
  }

  get on() {
    return document.body.classList.contains("lecture");
  }

  set(on) {
    document.body.classList.toggle("lecture", on);
    if (this.toggle) {
      this.toggle.textContent = on ? "Leave lecture mode" : "Lecture mode";
      this.toggle.setAttribute("aria-pressed", String(on));
    }
    this.apply();
    this.onToggle?.(on);
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
  }
}
