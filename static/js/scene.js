// A scene's page: the derivation step by step, the motion animated, the controls, the integrator,
// the plots, the free-body diagram and lecture mode. Used by /scenes/{id} (a built-in scene) and by
// the editor (a posted spec): one class, fed either a scene id or a spec.
import { getJSON, postJSON, typeset } from "./api.js";
import { buildControls, readValues, setControl, writeQuery } from "./controls.js";
import { renderSteps } from "./derivation.js";
import { Stage } from "./draw.js";
import { showEquilibria } from "./equilibria.js";
import { drawFBD, fbdLegend } from "./fbd.js";
import { isFixed, mountIntegrator, readSettings, showStats, showWarnings } from "./integrator.js";
import { Lecture } from "./lecture.js";
import { plotRun, plotlyReady } from "./plots.js";
import { showWork, watchWorkInputs } from "./work.js";

const $ = (id) => document.getElementById(id);

export async function mountScene({ sceneId = null, spec = null, derivation = null }) {
  const view = new SceneView(sceneId);
  await view.start(spec, derivation);
  return view;
}

class SceneView {
  constructor(sceneId) {
    this.sceneId = sceneId;
    this.playing = true;
    this.speed = 1;
    this.time = 0;
    this.runs = 0;
    this.result = null;
    this.resultB = null;
  }

  target() {
    return this.sceneId ? { scene_id: this.sceneId } : { scene: this.spec };
  }

  async start(spec, derivation) {
    if (this.sceneId) spec = (await getJSON(`/api/v1/scenes/${this.sceneId}`)).spec;
    const query = new URLSearchParams(location.search);
    this.settings = readSettings(query);
    this.phase = query.get("phase");
    mountIntegrator(this.settings, () => this.schedule());
    this.stageA = new Stage($("canvas"));
    this.stageB = new Stage($("canvas-b"));
    this.#playback();
    this.lecture = new Lecture({
      list: $("steps"), toggle: $("lecture-toggle"), counter: $("step-counter"),
      onToggle: () => { this.#saveURL(); this.#plot(); }, onPlay: () => this.togglePlay(),
    });
    this.lecture.set(query.get("lecture") === "1");
    watchWorkInputs(() => this.#plot());
    $("phase-q").addEventListener("change", () => { this.phase = $("phase-q").value; this.#saveURL(); this.#plot(); });
    $("reset").addEventListener("click", () => this.#reset());
    this.#loop();
    await this.load(spec, query, derivation);
  }

  /** A new spec (first load, or the editor re-derived): controls and results start afresh. */
  async load(spec, query = new URLSearchParams(), derivation = null) {
    this.spec = spec;
    const { params, initial } = readValues(spec, query);
    this.params = params;
    this.initial = initial;
    $("scene-summary").textContent = spec.summary || "";
    if (!this.sceneId) $("scene-title").textContent = spec.title || "Your system";
    this.#controls();
    $("phase-q").replaceChildren(...spec.coordinates.map((q) => new Option(q, q)));
    if (spec.coordinates.includes(this.phase)) $("phase-q").value = this.phase;
    this.result = null;
    this.resultB = null;
    await Promise.all([this.derive(derivation), this.run(), this.equilibria()]);
  }

  // ------------------------------------------------------------------ controls and URL state
  #controls() {
    const units = this.spec.units || {};
    const positive = new Set(this.spec.positive_coordinates || []);
    const changed = (store) => (name, value) => { store[name] = value; this.schedule(); };
    buildControls($("params"), Object.entries(this.params).map(([name, value]) => ({
      name, value, unit: units[name], positive: value > 0,
    })), changed(this.params));
    const rows = [];
    for (const q of this.spec.coordinates) {
      rows.push({ name: q, value: this.initial[q], unit: units[q], angle: units[q] === "rad", positive: positive.has(q) });
      rows.push({ name: `${q}_dot`, value: this.initial[`${q}_dot`], unit: units[q] ? `${units[q]}/s` : "" });
    }
    buildControls($("initial"), rows, changed(this.initial));
  }

  #reset() {
    const fresh = readValues(this.spec, new URLSearchParams());
    for (const [k, v] of Object.entries({ ...fresh.params, ...fresh.initial })) setControl(k, v);
    Object.assign(this.params, fresh.params);
    Object.assign(this.initial, fresh.initial);
    this.schedule(0);
  }

  #saveURL() {
    if (!this.params) return;
    const q = new URLSearchParams(writeQuery({
      params: this.params, initial: this.initial, settings: this.settings, fixed: isFixed,
      lecture: this.lecture.on,
    }));
    if (this.phase && this.phase !== this.spec.coordinates[0]) q.set("phase", this.phase);
    if (!this.sceneId) {
      const from = new URLSearchParams(location.search).get("from");
      if (from) q.set("from", from);
    }
    history.replaceState(null, "", `${location.pathname}?${q}`);
  }

  /** Re-run after the user stops moving a control for `ms` milliseconds. */
  schedule(ms = 300) {
    this.#saveURL();
    clearTimeout(this.timer);
    this.timer = setTimeout(() => {
      this.run();
      this.equilibria();
    }, ms);
  }

  // ------------------------------------------------------------------ simulation
  request(method, extra = {}) {
    const s = this.settings;
    const body = { ...this.target(), parameters: this.params, initial: this.initial, t_end: s.t_end, fps: 60, method, ...extra };
    if (isFixed(method)) body.dt = Number(s.dt);
    else { body.rtol = Number(s.tol); body.atol = Number(s.tol); }
    return body;
  }

  async run() {
    const id = ++this.runs;
    this.#saveURL();
    const s = this.settings;
    $("stats").classList.add("busy");
    document.body.dataset.running = "1";
    try {
      const runs = [postJSON("/api/v1/simulate", this.request(s.method, { constraint_forces: true }))];
      if (s.compare) runs.push(postJSON("/api/v1/simulate", this.request(s.methodB, { check_sensitivity: false })));
      const [a, b] = await Promise.all(runs);
      if (id !== this.runs) return; // a newer run superseded this one
      this.result = a;
      this.resultB = b || null;
      this.stageA.setResult(this.spec, a, this.params);
      if (b) this.stageB.setResult(this.spec, b, this.params);
      this.time = Math.min(this.time, a.t[a.t.length - 1]);
      showStats(b ? [a, b] : [a]);
      $("caption-a").textContent = b ? `A: ${a.stats.method}` : "";
      $("caption-b").textContent = b ? `B: ${b.stats.method}` : "";
      const last = Object.values(a.q).map((v) => v[v.length - 1]);
      $("canvas").dataset.lastQ = JSON.stringify(last);
      $("canvas").dataset.run = String(id);
      showStop([a, b]);
      this.#plot();
      this.fbd(true);
    } catch (err) {
      if (id !== this.runs) return;
      showWarnings([`The simulation failed: ${err.message}`]);
      $("canvas").dataset.error = err.message;
    } finally {
      if (id === this.runs) {
        $("stats").classList.remove("busy");
        delete document.body.dataset.running;
      }
    }
  }

  #plot() {
    if (!this.result) return;
    if (!plotlyReady()) { window.addEventListener("load", () => this.#plot(), { once: true }); return; }
    const s = this.settings;
    plotRun({ a: this.result, b: this.resultB, labels: [s.method, s.methodB], spec: this.spec,
      phase: $("phase-q").value, lecture: this.lecture.on });
    showWork(this.result, { lecture: this.lecture.on });
  }

  // ------------------------------------------------------------------ playback
  #playback() {
    $("play").addEventListener("click", () => this.togglePlay());
    $("restart").addEventListener("click", () => { this.time = 0; this.#setPlaying(true); });
    $("speed").addEventListener("change", () => { this.speed = Number($("speed").value); });
    $("scrub").addEventListener("input", () => {
      if (!this.result) return;
      const t = this.result.t;
      this.time = (Number($("scrub").value) / 1000) * t[t.length - 1];
      this.#setPlaying(false);
    });
  }

  #setPlaying(on) {
    this.playing = on;
    $("play").textContent = on ? "❚❚ Pause" : "▶ Play";
    $("play").setAttribute("aria-pressed", String(on));
    if (!on) this.fbd(true);
  }

  togglePlay() {
    const r = this.result;
    if (!this.playing && r && stopOf(r) && this.time >= r.t[r.t.length - 1]) this.time = 0; // replay
    this.#setPlaying(!this.playing);
  }

  frameIndex(r = this.result) {
    const step = r.t.length > 1 ? r.t[1] - r.t[0] : 1;
    return Math.min(r.t.length - 1, Math.round(this.time / step));
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
        if (this.time >= end && stopOf(r)) { // a stop ended the run: hold its last frame
          this.time = end;
          if (this.playing) { this.#setPlaying(false); $("scrub").value = 1000; }
        } else if (this.time > end) this.time = end > 0 ? this.time % end : 0;
        this.stageA.draw(this.frameIndex());
        if (this.resultB) this.stageB.draw(this.frameIndex(this.resultB));
        $("clock").textContent = `t = ${this.time.toFixed(2)} s`;
        if (this.playing) $("scrub").value = end > 0 ? Math.round((1000 * this.time) / end) : 0;
        if (this.playing) this.fbd();
      }
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }

  /** Redraw the free-body diagram (while playing, a few times a second). */
  fbd(now = false) {
    const t = performance.now();
    if (!now && t - (this.fbdAt || 0) < 150) return;
    this.fbdAt = t;
    if (!this.result || !$("fbd-svg")) return;
    const placed = this.derivation?.steps?.find((s) => s.id === "fbd")?.data;
    const kinds = drawFBD($("fbd-svg"), this.spec, this.result, this.params, this.frameIndex(),
      { yaw: this.stageA.yaw, pitch: this.stageA.pitch }, placed);
    fbdLegend($("fbd-legend"), kinds);
  }

  // ------------------------------------------------------------------ derivation, equilibria
  async derive(given = null) {
    const steps = $("steps");
    delete steps.dataset.typeset;
    steps.innerHTML = '<li class="muted">Deriving the equations of motion…</li>';
    try {
      this.derivation = given || await postJSON("/api/v1/derive", this.target());
    } catch (err) {
      steps.replaceChildren(Object.assign(document.createElement("li"), { className: "errors", textContent: err.message }));
      return;
    }
    renderSteps(steps, this.derivation, { target: () => this.target(), coordinates: this.spec.coordinates });
    showWarningsBelow(this.derivation.warnings);
    this.lecture.apply();
    if (this.result) this.fbd(true);
    await typeset([steps]);
    steps.dataset.typeset = "1";
  }

  async equilibria() {
    await showEquilibria($("equilibria"), this.target(), this.params, (q, mode) => this.startAt(q, mode), this.spec);
  }

  startAt(q0, mode) {
    this.spec.coordinates.forEach((q, j) => {
      const nudge = mode ? 0.1 * mode[j] : (j === 0 ? 0.05 : 0);
      const v = Number((q0[q] + nudge).toFixed(6));
      this.initial[q] = v;
      this.initial[`${q}_dot`] = 0;
      setControl(q, v);
      setControl(`${q}_dot`, 0);
    });
    this.time = 0;
    this.schedule(0);
  }
}

/** `stats.stop` of a run a declared stop condition ended: {name, t, message}. */
function stopOf(run) {
  return run?.stats?.stop || null;
}

/** The banner by the animation when a stop condition ended a run (A, and B in compare mode). */
function showStop(runs) {
  const box = $("stop-banner");
  const lines = runs.filter(Boolean).map((r, k) => {
    const stop = stopOf(r);
    if (!stop) return null;
    const who = runs.filter(Boolean).length > 1 ? `${"AB"[k]}: ` : "";
    return `${who}Stopped at t = ${Number(stop.t).toFixed(2)} s: ${stop.message}`;
  }).filter(Boolean);
  box.textContent = lines.join(" · ");
  box.hidden = !lines.length;
  if (lines.length) $("canvas").dataset.stopped = String(stopOf(runs[0])?.t ?? "");
  else delete $("canvas").dataset.stopped;
}

function showWarningsBelow(list) {
  const box = $("derive-warnings");
  if (box) box.replaceChildren(...(list || []).map((w) => Object.assign(document.createElement("li"), { textContent: w })));
}
