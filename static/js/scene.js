// A scene's page: the derivation step by step, the motion animated, controls, plots, lecture mode.
// Used by /scenes/{id} (a built-in scene) and by the editor (a posted spec).
import { ApiError, getJSON, postJSON, typeset } from "./api.js";
import { Stage } from "./draw.js";
import { plotRun } from "./plots.js";

const METHODS = [
  ["DOP853", "DOP853 (adaptive, order 8)"], ["dop853_fortran", "DOP853 Fortran (fast)"],
  ["RK45", "RK45 (adaptive, order 5)"], ["Radau", "Radau (implicit, stiff)"],
  ["BDF", "BDF (implicit, stiff)"], ["LSODA", "LSODA (auto stiff)"],
  ["rk4", "RK4 (fixed step)"], ["euler", "Euler (fixed step)"],
  ["symplectic_euler", "symplectic Euler (fixed)"], ["implicit_midpoint", "implicit midpoint (fixed)"],
];
const FIXED = new Set(["rk4", "euler", "symplectic_euler", "implicit_midpoint"]);
const $ = (id) => document.getElementById(id);

function fmt(x, digits = 4) {
  if (x === null || x === undefined || Number.isNaN(x)) return "–";
  const a = Math.abs(x);
  return a !== 0 && (a < 1e-3 || a >= 1e5) ? x.toExponential(2) : Number(x.toPrecision(digits)).toString();
}

function range(value, isAngle) {
  if (isAngle) return [-Math.PI, Math.PI];
  const a = Math.abs(value);
  if (a === 0) return [-2, 2];
  return value > 0 ? [0, 3 * a] : [-3 * a, 3 * a];
}

export async function mountScene({ sceneId = null, spec = null }) {
  const view = new SceneView(sceneId, spec);
  await view.start();
  return view;
}

class SceneView {
  constructor(sceneId, spec) {
    this.sceneId = sceneId;
    this.spec = spec;
    this.playing = true;
    this.speed = 1;
    this.time = 0;
    this.revealed = 1;
    this.runCounter = 0;
  }

  target() {
    return this.sceneId ? { scene_id: this.sceneId } : { scene: this.spec };
  }

  async start() {
    if (this.sceneId) this.spec = (await getJSON(`/api/v1/scenes/${this.sceneId}`)).spec;
    const query = new URLSearchParams(location.search);
    this.settings = {
      method: query.get("method") || "DOP853",
      methodB: query.get("method_b") || "rk4",
      tol: query.get("tol") || "1e-9",
      dt: query.get("dt") || "0.001",
      t_end: Number(query.get("t_end")) || 10,
      compare: query.get("compare") === "1",
    };
    this.#integratorPanel();
    this.#playback();
    this.#lecture(query.get("lecture") === "1");
    this.#loop();
    await this.load(this.spec, query);
  }

  async load(spec, query = new URLSearchParams()) {
    // A new spec (the editor re-derives): controls, stages and results start afresh.
    this.spec = spec;
    const units = spec.units || {};
    this.params = { ...spec.parameters };
    this.initial = {};
    for (const q of spec.coordinates) {
      this.initial[q] = (spec.initial || {})[q] ?? 0;
      this.initial[`${q}_dot`] = (spec.initial || {})[`${q}_dot`] ?? 0;
    }
    for (const [k, v] of query) {
      const x = Number(v);
      if (k in this.params && Number.isFinite(x)) this.params[k] = x;
      if (k in this.initial && Number.isFinite(x)) this.initial[k] = x;
    }
    $("scene-summary").textContent = spec.summary || "";
    if (!this.sceneId) $("scene-title").textContent = spec.title || "Your system";
    this.#controls(units);
    this.stageA = new Stage($("canvas"), spec);
    this.stageB = new Stage($("canvas-b"), spec);
    this.result = null;
    this.resultB = null;
    await Promise.all([this.derive(), this.run(), this.equilibria()]);
  }

  // ---------------------------------------------------------------- controls and URL state
  #controls(units) {
    const make = (box, name, value, isAngle, unit, store) => {
      const [lo, hi] = range(value, isAngle);
      const row = document.createElement("div");
      row.className = "control";
      row.innerHTML = `<label for="s-${name}" title="${unit || ""}">${name}</label>
        <input id="s-${name}" type="range" min="${lo}" max="${hi}" step="${(hi - lo) / 400}">
        <input id="n-${name}" type="number" step="any" aria-label="${name}">`;
      box.append(row);
      const slider = row.querySelector('input[type="range"]');
      const number = row.querySelector('input[type="number"]');
      slider.value = value;
      number.value = value;
      const set = (v) => {
        if (!Number.isFinite(v)) return;
        store[name] = v;
        slider.value = v;
        number.value = v;
        this.scheduleRun();
      };
      slider.addEventListener("input", () => set(Number(slider.value)));
      number.addEventListener("change", () => set(Number(number.value)));
    };
    $("params").replaceChildren();
    $("initial").replaceChildren();
    for (const [k, v] of Object.entries(this.params)) make($("params"), k, v, false, units[k], this.params);
    for (const q of this.spec.coordinates) {
      const angle = units[q] === "rad";
      make($("initial"), q, this.initial[q], angle, units[q], this.initial);
      make($("initial"), `${q}_dot`, this.initial[`${q}_dot`], false, "", this.initial);
    }
  }

  setControl(name, value) {
    const store = name in this.params ? this.params : this.initial;
    store[name] = value;
    for (const prefix of ["s-", "n-"]) {
      const el = $(prefix + name);
      if (el) el.value = value;
    }
  }

  #integratorPanel() {
    for (const id of ["method", "method-b"]) {
      $(id).replaceChildren(...METHODS.map(([v, label]) => new Option(label, v)));
    }
    const s = this.settings;
    $("method").value = s.method;
    $("method-b").value = s.methodB;
    $("tol").value = s.tol;
    $("dt").value = s.dt;
    $("t_end").value = s.t_end;
    $("compare").checked = s.compare;
    const sync = () => {
      s.method = $("method").value;
      s.methodB = $("method-b").value;
      s.tol = $("tol").value;
      s.dt = $("dt").value;
      s.t_end = Math.max(0, Math.min(120, Number($("t_end").value) || 10));
      s.compare = $("compare").checked;
      const fixed = FIXED.has(s.method) || (s.compare && FIXED.has(s.methodB));
      const adaptive = !FIXED.has(s.method) || (s.compare && !FIXED.has(s.methodB));
      $("dt-box").hidden = !fixed;
      $("tol-box").hidden = !adaptive;
      $("view-b").hidden = !s.compare;
    };
    sync();
    for (const id of ["method", "method-b", "tol", "dt", "t_end", "compare"]) {
      $(id).addEventListener("change", () => { sync(); this.scheduleRun(); });
    }
  }

  #saveURL() {
    if (!this.params) return; // not loaded yet
    const q = new URLSearchParams();
    for (const [k, v] of Object.entries(this.params)) q.set(k, v);
    for (const [k, v] of Object.entries(this.initial)) q.set(k, v);
    const s = this.settings;
    q.set("method", s.method);
    if (FIXED.has(s.method)) q.set("dt", s.dt); else q.set("tol", s.tol);
    q.set("t_end", s.t_end);
    if (s.compare) { q.set("compare", "1"); q.set("method_b", s.methodB); }
    if (document.body.classList.contains("lecture")) q.set("lecture", "1");
    history.replaceState(null, "", `${location.pathname}?${q}`);
  }

  scheduleRun() {
    clearTimeout(this.timer);
    this.timer = setTimeout(() => { this.run(); this.equilibria(); }, 300);
  }

  // ---------------------------------------------------------------- simulation
  request(method) {
    const s = this.settings;
    const body = {
      ...this.target(), parameters: this.params, initial: this.initial, t_end: s.t_end,
      fps: 60, method,
    };
    if (FIXED.has(method)) body.dt = Number(s.dt);
    else { body.rtol = Number(s.tol); body.atol = Number(s.tol); }
    return body;
  }

  async run() {
    const id = ++this.runCounter;
    this.#saveURL();
    const s = this.settings;
    $("stats").textContent = "simulating…";
    try {
      const runs = [postJSON("/api/v1/simulate", this.request(s.method))];
      if (s.compare) runs.push(postJSON("/api/v1/simulate", this.request(s.methodB)));
      const [a, b] = await Promise.all(runs);
      if (id !== this.runCounter) return; // a newer run superseded this one
      this.result = a;
      this.resultB = b || null;
      this.stageA.setResult(a);
      if (b) this.stageB.setResult(b);
      $("canvas").dataset.lastQ = JSON.stringify(Object.values(a.q).map((v) => v[v.length - 1]));
      this.time = 0;
      this.#stats(a, b);
      plotRun(a, b, [s.method, s.methodB]);
      this.drawFBD();
    } catch (err) {
      if (id !== this.runCounter) return;
      $("stats").textContent = "";
      $("warnings").replaceChildren(Object.assign(document.createElement("li"), {
        textContent: err instanceof ApiError ? err.message : `Simulation failed: ${err}`,
      }));
    }
  }

  #stats(a, b) {
    const box = $("stats");
    box.replaceChildren();
    const show = (r, label) => {
      const st = r.stats;
      const err = st.energy_error ?? st.jacobi_error ?? st.energy_balance_error;
      const what = st.energy_error !== undefined ? "energy error" :
        st.jacobi_error !== undefined ? "Jacobi-integral error" : "energy-balance error";
      const rows = [
        [label, st.method], ["wall time", `${fmt(st.wall_time * 1e3, 3)} ms`], ["steps", st.steps],
        ["RHS evaluations", st.rhs_evaluations], [what, fmt(err, 2)],
      ];
      for (const [k, v] of Object.entries(st.momentum_drift || {})) rows.push([`p_${k} drift`, fmt(v, 2)]);
      for (const [k, v] of rows) {
        const div = document.createElement("div");
        div.className = "row";
        div.innerHTML = `<b>${k}:</b> <span>${v}</span>`;
        box.append(div);
      }
    };
    show(a, b ? "A" : "method");
    if (b) show(b, "B");
    $("caption-a").textContent = b ? `A: ${a.stats.method}` : "";
    $("caption-b").textContent = b ? `B: ${b.stats.method}` : "";
    const warnings = [...a.warnings, ...(b ? b.warnings.map((w) => `B: ${w}`) : [])];
    $("warnings").replaceChildren(...warnings.map((w) => Object.assign(document.createElement("li"), { textContent: w })));
  }

  // ---------------------------------------------------------------- playback
  #playback() {
    $("play").addEventListener("click", () => this.togglePlay());
    $("restart").addEventListener("click", () => { this.time = 0; this.playing = true; $("play").textContent = "Pause"; });
    $("speed").addEventListener("change", () => { this.speed = Number($("speed").value); });
    $("scrub").addEventListener("input", () => {
      if (!this.result) return;
      const t = this.result.t;
      this.time = (Number($("scrub").value) / 1000) * t[t.length - 1];
      this.playing = false;
      $("play").textContent = "Play";
      this.drawFBD();
    });
  }

  togglePlay() {
    this.playing = !this.playing;
    $("play").textContent = this.playing ? "Pause" : "Play";
    if (!this.playing) this.drawFBD();
  }

  #loop() {
    let last = performance.now();
    const tick = (now) => {
      const dt = Math.min(0.1, (now - last) / 1000);
      last = now;
      const r = this.result;
      if (r && r.t.length) {
        const end = r.t[r.t.length - 1];
        if (this.playing) this.time += dt * this.speed;
        if (this.time > end) this.time = end > 0 ? this.time % end : 0;
        const step = r.t.length > 1 ? r.t[1] - r.t[0] : 1;
        const i = Math.min(r.t.length - 1, Math.round(this.time / step));
        this.stageA.draw(i);
        if (this.resultB) this.stageB.draw(Math.min(this.resultB.t.length - 1, i));
        $("clock").textContent = `t = ${this.time.toFixed(2)} s`;
        if (this.playing) $("scrub").value = end > 0 ? Math.round((1000 * this.time) / end) : 0;
      }
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }

  // ---------------------------------------------------------------- derivation
  async derive() {
    const steps = $("steps");
    steps.innerHTML = '<li class="muted">Deriving…</li>';
    try {
      this.derivation = await postJSON("/api/v1/derive", this.target());
    } catch (err) {
      steps.innerHTML = "";
      steps.append(Object.assign(document.createElement("li"), { className: "errors", textContent: err.message }));
      throw err;
    }
    steps.replaceChildren(...this.derivation.steps.map((s) => this.#step(s)));
    this.#applyReveal();
    this.drawFBD();
    await typeset([steps]);
    steps.dataset.typeset = "1";
  }

  #step(step) {
    const li = document.createElement("li");
    li.className = "step";
    li.dataset.step = step.id;
    const h = document.createElement("h3");
    h.textContent = step.title;
    const p = document.createElement("p");
    p.className = "text";
    p.textContent = step.text;
    li.append(h);
    if (step.id === "fbd") {
      const svg = document.createElementNS("http://www.w3.org/2000/svg", "svg");
      svg.setAttribute("class", "fbd");
      svg.setAttribute("width", "260");
      svg.setAttribute("height", "220");
      svg.id = "fbd-svg";
      li.append(svg);
    }
    li.append(p);
    step.latex.forEach((tex, k) => {
      const row = document.createElement("div");
      row.className = "math-line";
      const math = document.createElement("div");
      math.className = "math";
      math.textContent = `\\[${tex}\\]`;
      row.append(math, this.#copy("LaTeX", tex), this.#copy("text", step.plain[k]));
      li.append(row);
    });
    for (const box of this.#yourTurn(step.id)) li.append(box);
    return li;
  }

  #copy(label, text) {
    const b = document.createElement("button");
    b.type = "button";
    b.className = "copy";
    b.textContent = `copy ${label}`;
    b.addEventListener("click", async () => {
      try { await navigator.clipboard.writeText(text); b.textContent = "copied"; } catch { b.textContent = "select"; window.prompt("Copy:", text); }
      setTimeout(() => { b.textContent = `copy ${label}`; }, 1200);
    });
    return b;
  }

  #yourTurn(stepId) {
    const coords = this.spec.coordinates;
    const asks = {
      energy: [["T", null, "T ="], ["V", null, "V ="]],
      forces: coords.map((q) => ["Q", q, `Q_${q} =`]),
      lagrange: [["L", null, "L ="], ...coords.map((q) => ["eom", q, `EoM for ${q}:`])],
      matrix: this.spec.coordinates.length <= 3 ? coords.map((q) => ["accel", q, `${q}_ddot =`]) : [],
    }[stepId] || [];
    return asks.map(([quantity, coordinate, prompt]) => {
      const box = document.createElement("details");
      box.className = "yourturn";
      box.innerHTML = `<summary>Your turn: ${prompt.replace(/[:=]$/, "")}</summary>
        <div class="row"><span>${prompt}</span><input type="text" placeholder="e.g. 1/2 m l^2 theta'^2">
        <button type="button" class="check">Check</button><button type="button" class="reveal">Show answer</button></div>
        <div class="echo"></div><p class="verdict"></p><ul class="feedback"></ul><div class="expected"></div>`;
      const input = box.querySelector("input");
      const ask = async (reveal) => {
        const body = { ...this.target(), quantity, answer: input.value || "0", reveal };
        if (coordinate) body.coordinate = coordinate;
        const verdict = box.querySelector(".verdict");
        try {
          const r = await postJSON("/api/v1/check", body);
          box.querySelector(".echo").textContent = `\\[${r.answer_latex}\\]`;
          verdict.textContent = r.correct ? "✔ Correct" : "✘ Not yet";
          verdict.className = `verdict ${r.correct ? "ok" : "bad"}`;
          box.querySelector(".feedback").replaceChildren(...r.feedback.map((f) => Object.assign(document.createElement("li"), { textContent: f })));
          box.querySelector(".expected").textContent = r.expected_latex ? `\\[${r.expected_latex}\\]` : "";
          await typeset([box]);
        } catch (err) {
          verdict.textContent = err.message;
          verdict.className = "verdict bad";
        }
      };
      box.querySelector(".check").addEventListener("click", () => ask(false));
      box.querySelector(".reveal").addEventListener("click", () => ask(true));
      input.addEventListener("keydown", (e) => { if (e.key === "Enter") ask(false); e.stopPropagation(); });
      return box;
    });
  }

  drawFBD() {
    const svg = $("fbd-svg");
    const r = this.result;
    if (!svg || !r) return;
    const step = r.t.length > 1 ? r.t[1] - r.t[0] : 1;
    const i = Math.min(r.t.length - 1, Math.round(this.time / step));
    const stage = this.stageA;
    const W = 260, H = 220, sx = W / stage.canvas.width, sy = H / stage.canvas.height;
    const parts = [];
    const pos = (name) => { const [x, y] = stage.toScreen(name, i); return [x * sx, y * sy]; };
    for (const [a, b] of stage.links) {
      const [x1, y1] = pos(a), [x2, y2] = pos(b);
      parts.push(`<line x1="${x1}" y1="${y1}" x2="${x2}" y2="${y2}" stroke="#868e96" stroke-width="2"/>`);
    }
    for (const s of this.spec.springs || []) {
      const [x1, y1] = pos(s.a), [x2, y2] = pos(s.b);
      parts.push(`<line x1="${x1}" y1="${y1}" x2="${x2}" y2="${y2}" stroke="#adb5bd" stroke-dasharray="3 3"/>`);
    }
    const colors = { weight: "#2f9e44", spring: "#9c36b5", damper: "#e8590c", force: "#d9480f", torque: "#1971c2" };
    const mags = r.forces.map((f) => Math.hypot(f.x[i], f.y[i]));
    const big = Math.max(...mags, 1e-12);
    r.forces.forEach((f, k) => {
      if (f.kind === "torque" || mags[k] < 1e-9 * big) return;
      const [x, y] = pos(f.on);
      const len = 18 + 42 * mags[k] / big;
      const ux = f.x[i] / mags[k], uy = -f.y[i] / mags[k];
      const x2 = x + ux * len, y2 = y + uy * len;
      const head = `${x2},${y2} ${x2 - 7 * ux + 4 * uy},${y2 - 7 * uy - 4 * ux} ${x2 - 7 * ux - 4 * uy},${y2 - 7 * uy + 4 * ux}`;
      const label = f.label.replace(/\\vec\{(\w)\}_\{\\text\{(\w+)\}\}/, "$1 $2").replace(/[\\{}]/g, "");
      parts.push(`<line x1="${x}" y1="${y}" x2="${x2}" y2="${y2}" stroke="${colors[f.kind]}" stroke-width="2.5"/>
        <polygon points="${head}" fill="${colors[f.kind]}"/>
        <text x="${x2 + 4}" y="${y2 + 4}" font-size="11" fill="${colors[f.kind]}">${label}</text>`);
    });
    for (const b of this.spec.bodies) {
      const [x, y] = pos(b.name);
      parts.push(`<circle cx="${x}" cy="${y}" r="6" fill="#343a40"/>`);
    }
    parts.push(`<text x="6" y="${H - 8}" font-size="10" fill="#5b6575">t = ${r.t[i].toFixed(2)} s</text>`);
    svg.innerHTML = parts.join("");
  }

  // ---------------------------------------------------------------- equilibria
  async equilibria() {
    const box = $("equilibria");
    try {
      const r = await postJSON("/api/v1/equilibria", { ...this.target(), parameters: this.params });
      if (!r.equilibria.length) {
        box.innerHTML = `<p class="muted">${r.warnings[0] || "No equilibrium."}</p>`;
        return;
      }
      const ul = document.createElement("ul");
      for (const e of r.equilibria) {
        const li = document.createElement("li");
        const where = Object.entries(e.q).map(([k, v]) => `${k} = ${fmt(v)}`).join(", ");
        const sym = Object.entries(e.symbolic).map(([k, v]) => `${k} = ${v}`).join(", ");
        li.innerHTML = `<span>${where}</span><span class="tag ${e.stable ? "stable" : "unstable"}">${e.stable ? "stable" : "unstable"}</span>
          ${sym ? `<div class="muted">${sym}${e.exists_when !== "always" ? ` (when ${e.exists_when})` : ""}</div>` : ""}
          ${e.frequencies.length ? `<div class="muted">ω = ${e.frequencies.map((f) => fmt(f)).join(", ")} rad/s</div>` : ""}`;
        const near = document.createElement("button");
        near.type = "button";
        near.textContent = "start near";
        near.addEventListener("click", () => this.startAt(e, null));
        li.append(near);
        e.modes.forEach((mode, k) => {
          const b = document.createElement("button");
          b.type = "button";
          b.textContent = `excite mode ${k + 1}`;
          b.addEventListener("click", () => this.startAt(e, mode));
          li.append(b);
        });
        ul.append(li);
      }
      box.replaceChildren(ul);
    } catch (err) {
      box.innerHTML = `<p class="muted">${err.message}</p>`;
    }
  }

  startAt(eq, mode) {
    const coords = this.spec.coordinates;
    coords.forEach((q, j) => {
      const nudge = mode ? 0.1 * mode[j] : (j === 0 ? 0.05 : 0);
      this.setControl(q, Number((eq.q[q] + nudge).toFixed(6)));
      this.setControl(`${q}_dot`, 0);
    });
    this.run();
  }

  // ---------------------------------------------------------------- lecture mode
  #lecture(on) {
    const toggle = $("lecture-toggle");
    const set = (value) => {
      document.body.classList.toggle("lecture", value);
      if (toggle) toggle.textContent = value ? "Leave lecture mode" : "Lecture mode";
      this.#applyReveal();
      this.#saveURL();
    };
    if (toggle) toggle.addEventListener("click", () => set(!document.body.classList.contains("lecture")));
    set(on);
    document.addEventListener("keydown", (e) => {
      if (e.target.matches("input, textarea, select")) return;
      const lecture = document.body.classList.contains("lecture");
      if (e.key === "p") this.togglePlay();
      else if (e.key === "f") {
        if (document.fullscreenElement) document.exitFullscreen(); else document.documentElement.requestFullscreen?.();
      } else if (lecture && ["ArrowRight", " ", "PageDown"].includes(e.key)) {
        e.preventDefault();
        this.revealed += 1;
        this.#applyReveal();
      } else if (lecture && ["ArrowLeft", "PageUp"].includes(e.key)) {
        e.preventDefault();
        this.revealed = Math.max(1, this.revealed - 1);
        this.#applyReveal();
      }
    });
  }

  #applyReveal() {
    const steps = [...document.querySelectorAll("#steps .step")];
    this.revealed = Math.min(this.revealed, Math.max(1, steps.length));
    steps.forEach((s, k) => s.classList.toggle("hidden", k >= this.revealed));
    const last = steps[this.revealed - 1];
    if (last && document.body.classList.contains("lecture")) last.scrollIntoView({ block: "nearest" });
  }
}
