// What a student expects from a PhET simulation, beside the animation: live energy bars (T, V, E
// and the work of the non-conservative forces and of the drives, at the sample on screen), a
// stopwatch and a period timer that read the simulation's clock (not the wall clock: at 0.25×
// speed a period still measures what it is; a period only where the coordinate swings steadily,
// else why there is none), gravity presets that move the scene's own gravity
// control the way a user would, and single steps (one measured sample back or forward, buttons and the
// , and . keys while paused). Built from JS next to the stage's canvas; styled inline, so the page's
// stylesheet needs nothing new. Data attributes (data-value, data-t, data-period, ...) let the
// browser tests read what is shown.
import { nameText } from "./texnames.js";

const NS = "http://www.w3.org/2000/svg";
const BARS = [ // key in the run's `energy`, label, colour; the work bars only when the run has any
  ["T", "T", "#1f6feb", false],
  ["V", "V", "#2f9e44", false],
  ["E", "E", "#212529", false],
  ["W_nc", "W_NC", "#e8590c", true],
  ["W_drive", "W_drive", "#9c36b5", true],
];
export const GRAVITY = [["Earth", 9.81], ["Moon", 1.62], ["Mars", 3.71], ["Jupiter", 24.79], ["zero g", 0]];
// the page's colour variables (app.css), so lecture mode's dark theme applies here too
const BOX = "border:1px solid var(--line,#dee2e6);border-radius:6px;padding:6px 8px;background:var(--panel,#fff);min-width:0";
const HEAD = "font-size:12px;font-weight:600;color:var(--muted,#495057);margin:0 0 4px";
const SMALL = "font-size:11px;color:var(--muted,#6c757d);margin:4px 0 0;line-height:1.3";
const BUTTON = "font-size:12px;padding:2px 8px;margin:0 4px 0 0";

const el = (tag, props = {}, style = "") => {
  const e = Object.assign(document.createElement(tag), props);
  if (style) e.style.cssText = style;
  return e;
};
/** `v.toFixed(digits)` without a minus on a number that rounds to zero: a mean of −0.00004 is
 * "0.000", never "-0.000". */
export const fixed = (v, digits) => {
  const s = v.toFixed(digits);
  return /^-0(\.0*)?$/.test(s) ? s.slice(1) : s;
};
// four significant digits, plain up to 10⁵ J (737.3, not 7.37e+2 beside 2.583)
const fmtJ = (v) => (Math.abs(v) >= 1e5 || (Math.abs(v) < 0.01 && v !== 0) ? v.toExponential(2) : v.toPrecision(4));

export class Instruments {
  constructor(stage) {
    this.stage = stage;
    this.result = null;
    this.spec = null;
    this.watch = { running: false, elapsed: 0, last: null };
    this.box = el("div", { className: "instruments", id: "instruments" },
      "display:flex;flex-wrap:wrap;gap:8px;align-items:stretch");
    this.box.setAttribute("aria-label", "instruments");
    // a fold like the page's other sections (app.css .fold), closed at first on a phone, where
    // the animation and the derivation come first
    const fold = el("details", { className: "fold instruments-fold", open: !window.matchMedia("(max-width: 600px)").matches },
      "margin-top:6px");
    const summary = el("summary");
    summary.append(el("h2", { textContent: "Instruments" }, "font-size:1rem"));
    fold.append(summary, this.box);
    const section = stage.canvas.closest("section") || stage.canvas.parentElement;
    const playback = section.querySelector(".playback");
    (playback || section.lastElementChild).after(fold);
    this.#stepButtons(playback);
    this.#energyPanel();
    this.#clocks();
    this.#gravityPanel();
    document.addEventListener("keydown", (e) => this.#key(e));
  }

  // ------------------------------------------------------------------ single step
  #stepButtons(playback) {
    const make = (text, by, title) => {
      const b = el("button", { type: "button", textContent: text, title, className: "step" }, "min-width:2.6em");
      b.dataset.step = String(by);
      b.setAttribute("aria-label", title);
      b.addEventListener("click", () => this.step(by));
      return b;
    };
    this.back = make("◀|", -1, "one sample back (,)");
    this.fwd = make("|▶", 1, "one sample forward (.)");
    const play = playback && playback.querySelector("#play");
    if (play) play.after(this.back, this.fwd);
    else this.box.append(this.back, this.fwd);
  }

  #paused() {
    const play = document.getElementById("play");
    return !play || play.getAttribute("aria-pressed") === "false";
  }

  #key(e) {
    if (e.key !== "," && e.key !== ".") return;
    if (e.target.closest && e.target.closest("input, select, textarea, [contenteditable]")) return;
    if (!this.#paused()) return;
    e.preventDefault();
    this.step(e.key === "." ? 1 : -1);
  }

  /** One sample back or forward: through the page's time slider (it pauses the playback and sets
   * the clock), given the exact time of the sample so a long run is not rounded to 1/1000.
   * A sample the server measured (`sampled` of a run drawn with interpolated frames between its
   * samples, live.js forDisplay): the free-body diagram, drawn from those samples, then shows the
   * instant the canvas and the clock show. */
  step(by) {
    const shown = this.result, scrub = document.getElementById("scrub");
    if (!shown || !scrub || shown.t.length < 2) return;
    const r = shown.sampled || shown;
    const factor = shown.sampled ? (shown.stats?.display_factor || 1) : 1;
    const end = shown.t[shown.t.length - 1];
    // keys pressed faster than frames are drawn step on from the last step, not the stale frame
    const recent = this.stepped && performance.now() - this.stepped.at < 300;
    const at = this.stage.frame / factor; // between two samples on an interpolated frame
    const from = recent ? this.stepped.to : at;
    const next = by > 0 ? Math.floor(from + 1e-9) + by : Math.ceil(from - 1e-9) + by;
    const target = Math.max(0, Math.min(r.t.length - 1, next));
    this.stepped = { to: target, at: performance.now() };
    scrub.step = "any";
    scrub.value = String(end > 0 ? (1000 * r.t[target]) / end : 0);
    scrub.dispatchEvent(new Event("input", { bubbles: true }));
  }

  // ------------------------------------------------------------------ energy bars
  #energyPanel() {
    const box = el("div", { className: "energy-bars" }, `${BOX};flex:1 1 260px`);
    box.append(el("p", { textContent: "Energy (J), now" }, HEAD));
    this.svg = document.createElementNS(NS, "svg");
    this.svg.setAttribute("viewBox", "0 0 300 150");
    this.svg.setAttribute("role", "img");
    this.svg.setAttribute("aria-label", "energy bars");
    this.svg.style.cssText = "width:100%;max-width:22.5rem;height:auto;display:block;background:#fff;border-radius:4px";
    this.caption = el("p", {}, SMALL);
    box.append(this.svg, this.caption);
    this.box.append(box);
    // The bars are drawn in the svg's own pixels (its viewBox as wide as it is shown), so their
    // labels keep their size whether the panel sits beside the animation (a narrow column) or
    // under it: drawn again when its width changes.
    new ResizeObserver(() => {
      const w = Math.round(this.svg.getBoundingClientRect().width);
      if (this.result && w > 0 && Math.abs(w - (this.drawnWidth || 0)) > 1) {
        this.#buildBars();
        this.#updateBars(this.stage.frame);
      }
    }).observe(this.svg);
  }

  #buildBars() {
    const e = this.result.energy || {};
    // a work bar only when the work is more than rounding noise against the energies themselves
    let biggest = 1e-300;
    for (const k of ["T", "V", "E"]) for (const v of e[k] || []) if (Math.abs(v) > biggest) biggest = Math.abs(v);
    const shown = BARS.filter(([k, , , work]) => e[k] && (!work || e[k].some((v) => Math.abs(v) > 1e-9 * biggest)));
    this.series = barSeries(e);
    const datum = this.series.datum;
    const named = (k, name) => (datum && (k === "V" || k === "E") ? `${name}′` : name);
    let lo = 0, hi = 0;
    for (const [k] of shown) for (const v of this.series[k]) if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    if (hi - lo < 1e-12) hi = lo + 1;
    // one viewBox unit per CSS pixel, scaled with the page's root font (lecture mode's 24 px)
    const u = (parseFloat(getComputedStyle(document.documentElement).fontSize) || 16) / 16;
    const shownWidth = Math.round(this.svg.getBoundingClientRect().width);
    this.drawnWidth = shownWidth;
    const W = Math.max(160, shownWidth || 300);
    // lecture mode: every label 24 px (the back of a hall), and the bars on their side, one row
    // each, so a value never shrinks to fit a narrow upright slot
    const lecture = document.documentElement.classList.contains("lecture");
    const small = lecture ? 24 : 9.5 * u, label = lecture ? 24 : 12 * u;
    const parts = [];
    const line = (x1, y1, x2, y2, color) =>
      `<line x1="${x1.toFixed(1)}" y1="${y1.toFixed(1)}" x2="${x2.toFixed(1)}" y2="${y2.toFixed(1)}" stroke="${color}"/>`;
    // A narrow panel (beside the animation) lays the bars on their side, one row each, with
    // their values in a column of their own: upright bars there had slots too narrow for
    // their value labels ("-21.774" over "0.149").
    const across = lecture || W < 17 * 16 * u;
    if (across) {
      // each row: the name and the value on a line, the bar under them across the full width
      const top = 2 * u, barH = 10 * u, rowH = label + barH + 8 * u, pad = 4 * u;
      const bottom = top + shown.length * rowH;
      const H = Math.round(bottom + small + 4 * u);
      this.svg.setAttribute("viewBox", `0 0 ${W} ${H}`);
      const x = (v) => pad + ((v - lo) / (hi - lo)) * (W - 2 * pad);
      const foot = (bottom + small).toFixed(1);
      parts.push(`<text x="${pad}" y="${foot}" font-size="${small}" fill="#5b6575" text-anchor="start">${fmtJ(lo)}</text>`);
      parts.push(`<text x="${(W - pad).toFixed(1)}" y="${foot}" font-size="${small}" fill="#5b6575" text-anchor="end">${fmtJ(hi)}</text>`);
      if (Math.min(x(0) - pad, W - pad - x(0)) > 44 * u) { // clear of both ends' labels
        parts.push(`<text x="${x(0).toFixed(1)}" y="${foot}" font-size="${small}" fill="#5b6575" text-anchor="middle">0</text>`);
      }
      shown.forEach(([k, bare, color], j) => {
        const name = named(k, bare);
        const y = top + j * rowH;
        parts.push(`<text x="${pad}" y="${(y + label).toFixed(1)}" font-size="${label}" fill="${color}" font-style="italic">${name}</text>`);
        parts.push(`<text data-value-of="${k}" x="${(W - pad).toFixed(1)}" y="${(y + label).toFixed(1)}" font-size="${small}" fill="#343a40" text-anchor="end"></text>`);
        // the zero mark of each row's band only: a line down the whole panel crossed the values
        parts.push(line(x(0), y + label + 1.5 * u, x(0), y + label + 4.5 * u + barH, "#868e96"));
        parts.push(`<rect data-key="${k}" x="${x(0).toFixed(1)}" width="0" y="${(y + label + 3 * u).toFixed(1)}" height="${barH.toFixed(1)}" fill="${color}" opacity="0.85"/>`);
      });
      this.axis = { across, x, small };
    } else {
      const H = Math.round(150 * u);
      this.svg.setAttribute("viewBox", `0 0 ${W} ${H}`);
      const top = small + 5 * u, bottom = H - label - 10 * u;
      const left = Math.min(52 * u, W * 0.26), width = W - left - 6;
      const y = (v) => top + ((hi - v) / (hi - lo)) * (bottom - top);
      const slot = width / Math.max(shown.length, 1);
      // a value label ("-1.23e-3": up to 8 characters, ~0.6 em each) fits its bar's slot
      const valueSize = Math.min(small, (0.96 * slot) / (0.6 * 8));
      this.axis = { across, y, small };
      parts.push(line(left, top, left, bottom, "#ced4da"));
      for (const v of [hi, 0, lo]) {
        if (v !== 0 && Math.abs(y(v) - y(0)) < small + 3) continue; // would sit on the 0 label
        parts.push(`<text x="${left - 4}" y="${(y(v) + small / 3).toFixed(1)}" font-size="${small}" fill="#5b6575" text-anchor="end">${fmtJ(v)}</text>`);
      }
      parts.push(line(left, y(0), W - 4, y(0), "#868e96"));
      shown.forEach(([k, bare, color], j) => {
        const name = named(k, bare);
        const x = left + slot * j + slot * 0.2, w = slot * 0.6;
        parts.push(`<rect data-key="${k}" x="${x.toFixed(1)}" width="${w.toFixed(1)}" y="${y(0).toFixed(1)}" height="0" fill="${color}" opacity="0.85"/>`);
        parts.push(`<text data-value-of="${k}" x="${(x + w / 2).toFixed(1)}" y="${small}" font-size="${valueSize.toFixed(1)}" fill="#343a40" text-anchor="middle"></text>`);
        parts.push(`<text x="${(x + w / 2).toFixed(1)}" y="${(H - 6 * u).toFixed(1)}" font-size="${label}" fill="${color}" text-anchor="middle" font-style="italic">${name}</text>`);
      });
    }
    this.svg.innerHTML = parts.join("");
    Object.assign(this.svg.dataset, { lo: String(lo), hi: String(hi) });
    this.rects = Object.fromEntries(shown.map(([k]) => [k, this.svg.querySelector(`rect[data-key="${k}"]`)]));
    this.labels = Object.fromEntries(shown.map(([k]) => [k, this.svg.querySelector(`text[data-value-of="${k}"]`)]));
    const works = shown.filter(([, , , w]) => w).map(([, l]) => l);
    this.caption.textContent = "All bars on one axis, over the whole run. V's zero is arbitrary (where " +
      "the datum is put), so only changes in V and E mean something" +
      (datum ? `; here from V's lowest value in this run, min V = ${fmtJ(datum)} J: V′ = V − min V, ` +
        "E′ = E − min V = T + V′, and every energy bar starts at 0." : ".") +
      (works.length ? ` E − E₀ = ${works.join(" + ")}: the work done on the system.`
        : this.result.stats?.driven ? (this.result.stats.preview ? " A drive can do work here; its bar comes with the server's run."
          : " A drive moves the system here, but it did no measurable work in this run: E stays constant.")
          : " No work is done from outside: E stays constant.");
  }

  #updateBars(i) {
    if (!this.axis) return;
    const e = this.series;
    const { across, small } = this.axis;
    for (const [k, rect] of Object.entries(this.rects)) {
      const v = e[k][i];
      const at = Number.isFinite(v) ? v : 0;
      const label = this.labels[k];
      label.textContent = fmtJ(v);
      rect.dataset.value = String(v);
      if (across) {
        const a = this.axis.x(0), b = this.axis.x(at);
        rect.setAttribute("x", Math.min(a, b).toFixed(2));
        rect.setAttribute("width", Math.abs(b - a).toFixed(2));
        continue;
      }
      const a = this.axis.y(0), b = this.axis.y(at);
      rect.setAttribute("y", Math.min(a, b).toFixed(2));
      rect.setAttribute("height", Math.abs(b - a).toFixed(2));
      label.setAttribute("y", String(Math.max(small, Math.min(a, b) - 3).toFixed(1)));
    }
  }

  // ------------------------------------------------------------------ stopwatch, period timer
  #clocks() {
    const box = el("div", { className: "clocks" }, `${BOX};flex:1 1 200px`);
    box.append(el("p", { textContent: "Stopwatch (simulation time)" }, HEAD));
    this.watchOut = el("output", { id: "stopwatch", textContent: "0.00 s" },
      "font:600 16px ui-monospace,monospace;display:inline-block;min-width:5.5em");
    this.watchBtn = el("button", { type: "button", textContent: "Start" }, BUTTON);
    const reset = el("button", { type: "button", textContent: "Reset" }, BUTTON);
    this.watchBtn.addEventListener("click", () => {
      const t = this.result ? this.result.t[this.stage.frame] : null;
      if (this.watch.running) this.#tick(t); // up to the sample on screen now
      this.watch.running = !this.watch.running;
      this.watch.last = t;
      this.watchBtn.textContent = this.watch.running ? "Stop" : "Start";
      Object.assign(this.watchOut.dataset, { running: this.watch.running ? "1" : "0", [this.watch.running ? "from" : "to"]: String(t) });
      this.#showWatch();
    });
    reset.addEventListener("click", () => {
      this.watch.elapsed = 0;
      this.watch.last = this.result ? this.result.t[this.stage.frame] : null;
      this.#showWatch();
    });
    const row = el("div", {}, "display:flex;align-items:center;gap:4px;flex-wrap:wrap");
    row.append(this.watchOut, this.watchBtn, reset);
    box.append(row);

    box.append(el("p", { textContent: "Period timer" }, `${HEAD};margin-top:8px`));
    this.periodQ = el("select", { ariaLabel: "coordinate to time" }, "font-size:12px");
    this.periodQ.setAttribute("aria-label", "coordinate to time");
    this.periodQ.addEventListener("change", () => { this.#crossings(); this.update(this.stage.frame); });
    this.periodOut = el("output", { id: "period", textContent: "–" }, "font:600 14px ui-monospace,monospace;margin-left:6px");
    const prow = el("div", {}, "display:flex;align-items:center;flex-wrap:wrap");
    prow.append(this.periodQ, this.periodOut);
    this.periodNote = el("p", {}, SMALL);
    box.append(prow, this.periodNote);
    this.box.append(box);
  }

  /** The simulation clock moved to t: a jump back (the run looped, the slider went back) adds
   * nothing. */
  #tick(t) {
    if (this.watch.last !== null && t > this.watch.last) this.watch.elapsed += t - this.watch.last;
    this.watch.last = t;
  }

  #showWatch() {
    this.watchOut.textContent = `${this.watch.elapsed.toFixed(2)} s`;
    this.watchOut.dataset.elapsed = String(this.watch.elapsed);
  }

  /** The chosen coordinate's swings over the whole run (`swings`): a period only where it
   * swings steadily, else the reason there is none. */
  #crossings() {
    const r = this.result, name = this.periodQ.value;
    this.swing = r && r.q && r.q[name] ? swings(r.t, r.q[name]) : null;
  }

  #updatePeriod(i) {
    const out = this.periodOut, sw = this.swing, name = this.periodQ.value;
    delete out.dataset.period;
    out.dataset.state = sw ? sw.kind : "none";
    const small = smallOscillationPeriods();
    const tail = small.length ? ` Small oscillations (equilibria): 2π/ω = ${small.map((p) => `${p.toFixed(3)} s`).join(", ")}.` : "";
    if (!sw) {
      out.textContent = "–";
      this.periodNote.textContent = tail.trim();
      return;
    }
    if (sw.kind !== "steady" && sw.kind !== "once") {
      // the whole run says there is no period: no number at any frame, only why
      out.textContent = "no period";
      this.periodNote.textContent = `${nameText(name)} ${sw.reason}${tail}`;
      return;
    }
    const seen = sw.ups.filter(([k]) => k <= i);
    if (seen.length < 2) {
      out.textContent = "–";
    } else {
      const period = (seen[seen.length - 1][1] - seen[0][1]) / (seen.length - 1);
      // "period", not T: T is the kinetic energy on this page (the bar just above)
      out.textContent = `period ≈ ${period.toFixed(3)} s`;
      out.dataset.period = String(period);
    }
    const n = Math.max(0, seen.length - 1);
    this.periodNote.textContent = `Counts ${nameText(name)} rising through its mean over the run (${fixed(sw.mean, 3)})` +
      `: ${n} full period${n === 1 ? "" : "s"} so far` +
      (sw.kind === "once" ? "; the run holds one swing only, so it is not yet seen to repeat." : ".") + tail;
  }

  // ------------------------------------------------------------------ gravity presets
  #gravityPanel() {
    this.gravityBox = el("div", { className: "gravity-presets" }, `${BOX};flex:1 1 200px`);
    this.box.append(this.gravityBox);
  }

  #buildGravity() {
    const box = this.gravityBox;
    const g = this.spec.gravity;
    const name = g && typeof g.acceleration === "string" && /^[A-Za-z_]\w*$/.test(g.acceleration.trim())
      ? g.acceleration.trim() : null;
    box.replaceChildren(el("p", { textContent: "Gravity" }, HEAD));
    box.hidden = !g;
    if (!g) return;
    if (!name || !document.getElementById(`n-${name}`)) {
      box.append(el("p", { textContent: `g is ${g.acceleration} here, not a parameter: no presets.` }, SMALL));
      return;
    }
    this.gravityName = name;
    const row = el("div", {}, "display:flex;flex-wrap:wrap;gap:4px");
    for (const [planet, value] of GRAVITY) {
      const b = el("button", { type: "button", textContent: `${planet} ${value ? value : ""}`.trim() }, BUTTON);
      b.dataset.g = String(value);
      b.addEventListener("click", () => this.setGravity(value));
      row.append(b);
    }
    box.append(row, el("p", { textContent: `Sets the parameter ${name} (m/s²) and runs again.` }, SMALL));
    this.#markGravity();
  }

  /** Put `value` in the gravity parameter's number box and fire 'input' and 'change' as typing
   * would: the page's own controls then move the slider, update the link and re-run. */
  setGravity(value) {
    const input = document.getElementById(`n-${this.gravityName}`);
    if (!input) return;
    input.value = String(value);
    input.dispatchEvent(new Event("input", { bubbles: true }));
    input.dispatchEvent(new Event("change", { bubbles: true }));
    this.#markGravity();
  }

  #markGravity() {
    const input = document.getElementById(`n-${this.gravityName}`);
    const now = input ? Number(input.value) : NaN;
    for (const b of this.gravityBox.querySelectorAll("button")) {
      const on = Math.abs(Number(b.dataset.g) - now) < 1e-9;
      b.setAttribute("aria-pressed", String(on));
      b.style.fontWeight = on ? "700" : "";
    }
  }

  // ------------------------------------------------------------------ fed by the stage
  setResult(spec, result) {
    const fresh = spec !== this.spec;
    this.spec = spec;
    this.result = result;
    this.#buildBars();
    if (fresh) {
      const keep = this.periodQ.value;
      this.periodQ.replaceChildren(...spec.coordinates.map((q) => new Option(nameText(q), q)));
      if (spec.coordinates.includes(keep)) this.periodQ.value = keep;
      else { // the first coordinate that swings with a period, if any does (φ of a cone orbits)
        const timed = spec.coordinates.find((q) => result.q?.[q] && ["steady", "once"].includes(swings(result.t, result.q[q]).kind));
        if (timed) this.periodQ.value = timed;
      }
      this.#buildGravity();
    } else if (this.gravityName) this.#markGravity();
    this.#crossings();
    this.shownAt = null; // a new run: the period is read again even at the same sample
    this.watch.last = null;
  }

  /** The page's type size changed (lecture mode on or off): the bars drawn again at it. */
  relayout() {
    if (!this.result) return;
    this.#buildBars();
    this.#updateBars(this.stage.frame);
  }

  /** The sample on screen changed (called by the stage every frame it draws). */
  update(i) {
    const r = this.result;
    if (!r || !r.t.length) return;
    const t = r.t[i];
    if (this.watch.running) this.#tick(t);
    this.#showWatch();
    this.#updateBars(i);
    if (i !== this.shownAt) this.#updatePeriod(i);
    this.shownAt = i;
    this.box.dataset.t = String(t);
    this.box.dataset.frame = String(i);
  }
}

/** The small-oscillation periods 2π/ω of the first stable equilibrium the page lists (read from
 * its equilibria panel, whose frequencies may already be typeset by MathJax). */
function smallOscillationPeriods() {
  const li = [...document.querySelectorAll("#equilibria li")].find((x) => x.querySelector(".tag.stable"));
  const freq = li && li.querySelector(".freq");
  if (!freq) return [];
  let text = freq.textContent || "";
  const doc = window.MathJax && window.MathJax.startup && window.MathJax.startup.document;
  if (doc && doc.getMathItemsWithin) {
    try { text = doc.getMathItemsWithin(freq).map((m) => m.math).join(" ") + " " + text; } catch { /* plain text it is */ }
  }
  const m = text.match(/(?:ω|\\omega)\s*=\s*([-\d.eE+,\s]+)/);
  if (!m) return [];
  return m[1].split(",").map(Number).filter((w) => Number.isFinite(w) && w > 0).map((w) => (2 * Math.PI) / w);
}

/** Steady within this fraction: the times between successive rises through the mean may differ
 * by at most 10 % of their average (a damped oscillator's are equal; a driven one's transient, a
 * chaotic or a quasi-periodic motion's differ by 20-50 %). */
const STEADY = 0.1;

/**
 * Whether a coordinate sampled at times t swings back and forth with a period, judged over the
 * whole run: its upward crossings of its mean, interpolated, as [[sample index, time], ...], and
 * - kind "steady": three or more crossings a near-equal time apart: a period;
 * - kind "once": two crossings only: a period, timed over one swing, not seen to repeat;
 * - kind "irregular": the times between crossings differ by more than STEADY: no single period;
 * - kind "monotonic" / "few": it only rises or only falls, or never comes back through its mean
 *   twice: no period (an Atwood machine, a disk rolling down an incline).
 * `reason` says why in words that follow the coordinate's name.
 */
export function swings(t, q) {
  const n = Math.min(t.length, q.length);
  let sum = 0, lo = Infinity, hi = -Infinity;
  for (let k = 0; k < n; k++) { sum += q[k]; lo = Math.min(lo, q[k]); hi = Math.max(hi, q[k]); }
  const mean = sum / Math.max(n, 1);
  const ups = [];
  for (let k = 0; k + 1 < n; k++) {
    if (q[k] < mean && q[k + 1] >= mean) {
      const f = (mean - q[k]) / (q[k + 1] - q[k]);
      ups.push([k + 1, t[k] + f * (t[k + 1] - t[k])]);
    }
  }
  const span = n ? t[n - 1] - t[0] : 0;
  const base = { mean, ups };
  if (ups.length < 2) {
    const eps = 1e-9 * Math.max(hi - lo, Number.MIN_VALUE);
    let rises = true, falls = true;
    for (let k = 0; k + 1 < n; k++) {
      if (q[k + 1] < q[k] - eps) rises = false;
      if (q[k + 1] > q[k] + eps) falls = false;
    }
    if (!(hi > lo)) return { ...base, kind: "monotonic", reason: "stays put over this run: nothing swings, so there is no period." };
    if (rises || falls) {
      return { ...base, kind: "monotonic", reason: `only ${rises ? "rises" : "falls"} over this run (from ${q[0].toPrecision(3)} to ${q[n - 1].toPrecision(3)}): it does not swing back, so there is no period to time.` };
    }
    return { ...base, kind: "few", reason: `turns back, but does not rise through its mean (${fixed(mean, 3)}) twice in this run of ${span.toFixed(2)} s: no full swing to time (if it does swing, its period is longer than the run: raise t_end).` };
  }
  if (ups.length === 2) return { ...base, kind: "once", reason: "" };
  const gaps = ups.slice(1).map(([, b], j) => b - ups[j][1]);
  const avg = gaps.reduce((a, b) => a + b, 0) / gaps.length;
  const least = Math.min(...gaps), most = Math.max(...gaps);
  if (most - least > STEADY * avg) {
    return { ...base, kind: "irregular", reason: `swings, but not with a steady period: the time from one rise through its mean to the next varies from ${least.toFixed(3)} s to ${most.toFixed(3)} s over this run (a transient, beats, or chaos), so no single period is shown.` };
  }
  return { ...base, kind: "steady", reason: "" };
}

/**
 * The energies the bars show, per sample: T, V, E and the works as the run gives them, except that
 * V and E are measured from V's lowest value over the run (`datum`) when V's own zero would
 * crowd the bars: V below 0 somewhere (a pendulum's −mgl cos θ), or its lowest value more than
 * 5 % of the energies that move above 0 (a datum far below the motion). V's zero is a choice of
 * datum, so this changes no difference a student can read (ΔV, ΔE, T + V′ = E′), while every
 * energy bar then starts at 0 and E′ ≥ T, V′: a disk rolling 150 m down an incline showed
 * T = 737 J beside V = −735 J and an E = 2.58 J that was too short to see. Work bars are
 * differences already (W(t) − W(0)) and are kept as they are. `datum` is 0 when nothing moved.
 */
export function barSeries(energy) {
  const V = energy.V || [], T = energy.T || [];
  let vmin = Infinity, vmax = -Infinity, tmax = 0;
  for (const v of V) if (Number.isFinite(v)) { vmin = Math.min(vmin, v); vmax = Math.max(vmax, v); }
  for (const v of T) if (Number.isFinite(v)) tmax = Math.max(tmax, v);
  const moving = tmax + Math.max(0, vmax - vmin);
  const datum = Number.isFinite(vmin) && (vmin < 0 || vmin > 0.05 * moving) ? vmin : 0;
  const out = { ...energy, datum };
  if (datum) {
    out.V = V.map((v) => v - datum);
    if (energy.E) out.E = energy.E.map((v) => v - datum);
  }
  return out;
}
