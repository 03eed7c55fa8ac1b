// Lecture mode: large type and high contrast for a projector, the derivation revealed one step at a
// time (→, space, PageDown reveal the next; ←, PageUp hide it), p plays or pauses, f full screen.
// A step taller than the screen (a double pendulum's Euler–Lagrange step is three screens) is paged
// through first: the same keys scroll it a screen at a time before the next step is revealed, and
// the counter says when more of it lies below; ← pages back up through it, then hides it and
// shows the step before from its title (just under the sticky header). The counter sits in the sticky header in lecture
// mode, so the room always sees where it is; the page's address keeps the step as the header counts
// it (?step=5 is "step 5 of N", linkedStep), and a link with one opens scrolled to that step.
// The derivation stands beside the animation, so in lecture mode it is moved next to it in the
// page too: the tab order and a screen reader follow what the room sees. Its equations are fitted
// to the narrower column (fit.js).
import { fitEquations, watchEquations } from "./fit.js";

export class Lecture {
  constructor({ list, toggle, counter, onToggle, onPlay, onStep }) {
    this.list = list;
    this.toggle = toggle;
    this.counter = counter;
    this.onToggle = onToggle;
    this.onPlay = onPlay;
    this.onStep = onStep;
    this.revealed = 1;
    this.section = list.closest(".derivation");
    this.home = this.section ? { parent: this.section.parentNode, next: this.section.nextSibling } : null;
    this.counterHome = counter ? { parent: counter.parentNode, next: counter.nextSibling } : null;
    // a step opened from a link is aligned again once the math above it is typeset, unless the
    // reader moved first (settle())
    for (const type of ["keydown", "wheel", "touchstart", "pointerdown"]) {
      window.addEventListener(type, () => { this.linked = false; }, { passive: true, capture: true });
    }
    watchEquations(list);
    if (toggle) toggle.addEventListener("click", () => this.set(!this.on));
    document.addEventListener("keydown", (e) => this.#key(e));
    let queued = false;
    window.addEventListener("scroll", () => {
      if (queued || !this.on) return;
      queued = true;
      requestAnimationFrame(() => { queued = false; this.#count(); });
    }, { passive: true });
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

  /** The derivation right after the animation's column in lecture mode, back home otherwise; the
   * step counter in the sticky header (before the lecture toggle) while in lecture mode: in the
   * derivation's heading it scrolled away at the first key press. */
  #place(on) {
    const header = document.querySelector("body > header");
    if (this.counter && header) {
      if (on && this.counter.parentNode !== header) header.insertBefore(this.counter, this.toggle?.parentNode === header ? this.toggle : null);
      else if (!on && this.counter.parentNode === header) this.counterHome.parent.insertBefore(this.counter, this.counterHome.next);
    }
    const main = this.home && this.home.parent.querySelector(":scope > .col-main");
    if (!main) return;
    if (on && main.nextSibling !== this.section) main.after(this.section);
    else if (!on && this.section.parentNode === this.home.parent && this.section.nextSibling !== this.home.next) {
      this.home.parent.insertBefore(this.section, this.home.next);
    }
  }

  #key(e) {
    if (e.defaultPrevented) return; // taken already (the focused canvas's arrow keys: access.js)
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
      this.forward();
    } else if (this.on && ["ArrowLeft", "PageUp"].includes(e.key)) {
      e.preventDefault();
      this.back();
    }
  }

  /** Key presses one after another, each once the equations it shows are fitted (fit.js breaks
   * a revealed step's wide equations after it is shown, which moves what lies below);
   * `data-lecture-busy` on <html> counts those still to run. */
  #then(action) {
    const root = document.documentElement;
    root.dataset.lectureBusy = String(Number(root.dataset.lectureBusy || 0) + 1);
    this.queue = (this.queue || Promise.resolve()).then(action).catch(() => {}).finally(() => {
      root.dataset.lectureBusy = String(Number(root.dataset.lectureBusy) - 1);
    });
    return this.queue;
  }

  /** The next screen of the current step while it runs on below the screen, else the next step. */
  forward() {
    return this.#then(() => this.#forward());
  }

  back() {
    return this.#then(() => this.#back());
  }

  #forward() {
    const current = this.#current();
    const rest = current?.getBoundingClientRect();
    if (rest && rest.bottom > innerHeight + 2) {
      // the first line cut by the screen's bottom edge goes to the top (so every line shorter
      // than the screen is once seen whole), at most a screen at a time
      const top = this.#headerBottom(), page = this.#page();
      const cut = [...current.querySelectorAll(".math-line, p, h3, figure, summary, tr")]
        .filter(shown).map((b) => b.getBoundingClientRect())
        .find((r) => r.height > 0 && r.bottom > innerHeight + 1 && r.top > top + 1);
      // (a line cut already at the top is taller than the screen: a whole screen of it then)
      const line = parseFloat(getComputedStyle(document.documentElement).fontSize) || 16;
      const by = cut && cut.top - top - 8 > 2 * line ? Math.min(cut.top - top - 8, page) : page;
      window.scrollBy(0, this.#whole(current, Math.min(by, rest.bottom - innerHeight + 16), top, line));
    } else {
      return this.step(+1);
    }
    this.#count();
  }

  /** A scroll `by` adjusted so that no equation (nor title, row, figure) is cut by the header
   * (a page ended with the lower half of an equation under it, student play-test): shortened so
   * the first block under the header starts at its top, or, where that leaves less than two lines
   * of progress (the last screen of a step), lengthened past a block already seen whole on this
   * screen. A block taller than the screen is paged through as it is. */
  #whole(current, by, top, line) {
    const blocks = [...current.querySelectorAll(".math-line, h3, figure, summary, tr, mjx-container[display='true']")]
      .filter(shown).map((b) => b.getBoundingClientRect()).filter((r) => r.height > 0);
    const page = this.#page();
    let at = by;
    for (let k = 0; k < 4; k++) { // a new edge can cut another block: again from there
      const edge = top + at, cut = blocks.filter((r) => r.top < edge - 1 && r.bottom > edge + 12);
      if (!cut.length) break;
      // the outermost block that can start the screen (a broken equation from its first line)
      const back = cut.map((r) => r.top - top - 8).filter((to) => to >= 2 * line && to < at);
      const past = Math.max(...cut.map((r) => r.bottom - top));
      if (back.length) at = Math.min(...back);
      else if (past > at && past <= page) at = past;
      else break;
    }
    return at;
  }

  /** The screen above while the current step began above it, else hide the current step. */
  #back() {
    const rest = this.#current()?.getBoundingClientRect();
    const top = this.#headerBottom();
    if (rest && rest.top < top - 2) window.scrollBy(0, -Math.min(this.#page(), top - rest.top + 8));
    else return this.step(-1);
    this.#count();
  }

  step(delta) {
    this.revealed += delta;
    const shown = this.apply(true);
    this.onStep?.(this.revealed);
    return shown;
  }

  /** Open at step `n` (from 1) of a link, scrolled to it (its title just under the header). */
  open(n) {
    this.revealed = n;
    this.linked = this.on && n > 1;
    return this.apply(this.linked ? "top" : false);
  }

  /** The math above a linked step was typeset (and moved it): bring it back under the header,
   * unless the reader has pressed, scrolled or touched anything since it opened. */
  settle() {
    if (!this.linked || !this.on) return;
    this.linked = false;
    const current = this.#current();
    if (current) window.scrollBy(0, current.getBoundingClientRect().top - this.#headerBottom() - 8);
    this.#count();
  }

  #current() {
    return this.list.querySelectorAll(":scope > .step")[this.revealed - 1] || null;
  }

  /** Below the sticky header: what of the page the room can read. */
  #headerBottom() {
    const header = document.querySelector("body > header");
    return header && getComputedStyle(header).position === "sticky" ? header.getBoundingClientRect().bottom : 0;
  }

  /** A screen, less two lines kept from the last one so the room does not lose its place. */
  #page() {
    const line = parseFloat(getComputedStyle(document.documentElement).fontSize) || 16;
    return Math.max(line * 4, innerHeight - this.#headerBottom() - 3 * line);
  }

  /** "step 6 of 8", and "· more below ↓" while the current step runs on past the screen. */
  #count() {
    const steps = this.list.querySelectorAll(":scope > .step");
    if (!this.counter) return;
    if (!steps.length) { this.counter.textContent = ""; return; }
    const rest = this.on ? this.#current()?.getBoundingClientRect() : null;
    const more = Boolean(rest && rest.bottom > innerHeight + 2);
    this.counter.textContent = `step ${this.revealed} of ${steps.length}${more ? " · more below ↓" : ""}`;
    this.counter.dataset.more = String(more);
  }

  /** Show the first `revealed` steps (all of them outside lecture mode); `scroll` brings the
   * current one (a step just revealed, or the one before, back from it) to its title just under
   * the sticky header unless all of it is on the screen already; "top" always (a linked step).
   * Back from a step: hiding it shortens the page and the browser clamps the scroll, which left
   * the step before with its last line under the header and nothing of it on the screen. */
  apply(scroll = false) {
    const steps = [...this.list.querySelectorAll(":scope > .step")];
    this.revealed = Math.max(1, Math.min(this.revealed, steps.length || 1));
    steps.forEach((s, k) => {
      s.classList.toggle("hidden", this.on && k >= this.revealed);
      s.classList.toggle("current", this.on && k === this.revealed - 1);
    });
    this.list.dataset.revealed = String(this.on ? this.revealed : steps.length);
    const last = steps[this.revealed - 1];
    this.#count();
    return fitEquations(this.list).then(() => { // a step just shown is measured only now
      if (!scroll || !this.on || !last) return;
      const r = last.getBoundingClientRect(), top = this.#headerBottom();
      const whole = r.top >= top && r.bottom <= innerHeight;
      if (scroll === "top" || !whole) window.scrollBy(0, r.top - top - 8);
      this.#count();
    });
  }
}

/** The step (from 1, as the header counts: "step 5 of 8") a link's ?step= opens at, or null.
 * Addresses counted from 0 until November 2026: step=0 (only ever written by them) is the first
 * step, and an older link otherwise opens one step further on (a step more revealed, nothing
 * lost). (A share link's lecture_step counts from 0 in the API; the link adds 1.) */
export function linkedStep(query) {
  const step = query.has("step") ? Number(query.get("step")) : NaN;
  if (!Number.isInteger(step)) return null;
  return Math.max(1, step);
}

/** Not folded away: a closed <details> keeps its contents' last geometry (Chromium lays them out
 * as content-visibility: hidden), so their rectangles say nothing of what is on screen. */
function shown(el) {
  for (let d = el.closest("details"); d; d = d.parentElement?.closest("details")) {
    if (!d.open && !(el.closest("summary")?.parentElement === d)) return false;
  }
  return true;
}
