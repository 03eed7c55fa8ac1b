// A scene's page: the derivation step by step, the motion animated, the controls, the integrator,
// the plots, the free-body diagram and lecture mode. Used by /scenes/{id} (a built-in scene) and by
// the editor (a posted spec): one class, fed either a scene id or a spec.
//
// A built-in scene also gets its equations as JavaScript (live.js): the animation then starts from
// a preview stepped in the browser before the server's run arrives, follows a slider while it
// moves, and lets a body be dragged to its starting place. The preview is labelled as such until
// the server's run (the measured one, which the integrator panel, plots and compare mode show)
// replaces it; the server is asked when a slider is let go.
import {
  ApiError, busy, getJSON, holdMathJax, postJSON, prerenderedMath, releaseMathJax, track, typeset,
} from "./api.js";
import { keepAnchor } from "./anchor.js";
import { buildControls, readValues, setControl, writeQuery } from "./controls.js";
import { renderSteps } from "./derivation.js";
import { nameText } from "./texnames.js";
import { Stage } from "./draw.js";
import { showEquilibria } from "./equilibria.js";
import { fitEquations } from "./fit.js";
import { drawFBD, fbdLegend } from "./fbd.js";
import { fmt, isFixed, mountIntegrator, readSettings, showStats, showWarnings } from "./integrator.js";
import { Lecture, linkedStep } from "./lecture.js";
import { LiveModel, PREVIEW_LABEL, forDisplay } from "./live.js";
import { BodyDrag } from "./livedrag.js";
import { loadPlotly } from "./lazy.js";
import { plotRun, plotlyReady } from "./plots.js";
import { LectureStrip } from "./strip.js";
import { SceneAccess } from "./access.js";
import { showWork, watchWorkInputs } from "./work.js";

const $ = (id) => document.getElementById(id);
/** Samples per second asked of the server, and how many times that the animation draws (the
 * frames between two samples are interpolated: live.js forDisplay). */
const SERVER_FPS = 30;
const DISPLAY_FACTOR = 2;
/** The derivation's math waits for the canvas to move, at most this long (ms). */
const MATH_WAIT_MS = 600;
/** The first plots wait for the math, at most this long (ms). */
const PLOTS_WAIT_MS = 3000;
/** The prerendered math (one file, fetched with the page) is waited for at most this long (ms). */
const PRERENDERED_WAIT_MS = 1500;

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
    this.result = null; // the server's run: what the panel, the plots and the FBD show
    this.resultB = null;
    this.shownB = null;
    this.shown = null; // what canvas A draws: the server's run or the live preview
    this.live = null;
    this.changes = 0; // every change of a value, so a server run can tell it is behind
    this.previews = 0;
  }

  target() {
    return this.sceneId ? { scene_id: this.sceneId } : { scene: this.spec };
  }

  async start(spec, derivation) {
    // Everything a built-in scene needs is asked for at once: the spec, the derivation and the
    // live equations do not wait for each other. The page usually carries them already
    // (templates/scene.html): then nothing waits for a round trip.
    keepAnchor(); // a link to #h-derivation stays there while the page fills in above it
    const inline = this.sceneId ? inlineData() : {};
    let derived = derivation;
    this.motion = settleOnce(); // resolved once the canvas moves, or is known not to soon
    this.mathDone = settleOnce(); // resolved once the derivation is typeset (or failed)
    holdMathJax(this.motion);
    // a built-in derivation's math, typeset ahead of time (prerendered.js), fetched meanwhile
    const ready = document.querySelector("link[data-prerendered-math]");
    this.prerendered = ready ? prerenderedMath(ready.href) : Promise.resolve(false);
    if (this.sceneId) {
      derived = derivation || inline.derivation || postJSON("/api/v1/derive", this.target());
      derived.catch?.(() => {}); // shown by derive(); not an unhandled rejection meanwhile
      LiveModel.load(this.sceneId, inline.live)
        .then((live) => { // a preview only while the server's run is not there yet
          this.live = live;
          $("canvas").dataset.live = "ready";
          if (!this.result) this.preview();
        })
        .catch((err) => {
          $("canvas").dataset.live = `unavailable: ${err.message}`;
          this.motion.resolve(); // no preview coming: the math need not wait for one
        });
    } else {
      this.motion.resolve();
    }
    const specP = this.sceneId ? (inline.spec || getJSON(`/api/v1/scenes/${this.sceneId}`)) : null;
    const query = new URLSearchParams(location.search);
    this.settings = readSettings(query);
    this.phase = query.get("phase");
    mountIntegrator(this.settings, () => this.schedule());
    this.stageA = new Stage($("canvas"), { instruments: true });
    this.stageB = new Stage($("canvas-b"), { instruments: false });
    this.badge = liveBadge();
    this.#waiting("Computing the motion…");
    this.#syncPlay();
    this.#playback();
    this.strip = new LectureStrip({ play: $("play") }); // lecture mode's controls by the step
    this.lecture = new Lecture({
      list: $("steps"), toggle: $("lecture-toggle"), counter: $("step-counter"),
      onToggle: (on) => {
        this.strip.set(on);
        this.#saveURL(); this.#plot(); this.#label(this.shown);
        this.stageA.instruments?.relayout(); // the bars' labels at the lecture size, or back
        this.fbd(true); // and the diagram's
      },
      onPlay: () => this.togglePlay(),
      onStep: () => this.#saveURL(), // the address bar keeps the step the room is at
    });
    // a link's lecture step (as the header counts it, from 1), revealed once the steps are there
    this.wantedSteps = linkedStep(query);
    this.lecture.set(query.get("lecture") === "1");
    watchWorkInputs(() => this.#plot());
    $("phase-q").addEventListener("change", () => { this.phase = $("phase-q").value; this.#saveURL(); this.#plot(); });
    $("reset").addEventListener("click", () => this.#reset());
    this.drag = new BodyDrag(this);
    this.access = new SceneAccess(this); // keys on the canvas, the scene in words (access.js)
    this.#loop();
    for (const id of ["plot-q", "plot-phase", "plot-energy"]) {
      if ($(id) && !$(id).childElementCount) {
        $(id).append(Object.assign(document.createElement("p"), {
          className: "muted plot-wait", textContent: "Plotted when the server's run arrives…" }));
      }
    }
    if (specP) spec = (await specP).spec;
    // The math is typeset once the motion is on screen (typesetting holds the main thread), but
    // never later than MATH_WAIT_MS after the page's script started.
    setTimeout(() => this.motion.resolve(), MATH_WAIT_MS);
    setTimeout(() => this.mathDone.resolve(), PLOTS_WAIT_MS);
    await this.load(spec, query, derived);
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
    $("phase-q").replaceChildren(...spec.coordinates.map((q) => new Option(nameText(q), q)));
    if (spec.coordinates.includes(this.phase)) $("phase-q").value = this.phase;
    this.result = null;
    this.resultB = null;
    this.shownB = null;
    this.shown = null;
    if (!this.sceneId) this.live = null;
    this.preview();
    await Promise.all([this.derive(derivation), this.run(), this.equilibria()]);
    if (!this.sceneId && this.spec === spec) {
      // A spec of one's own: its equations printed for it, once its other jobs are done (the
      // pool runs one job per client at a time; its worker has the spec compiled by now).
      try {
        const live = await LiveModel.forSpec(spec);
        if (this.spec === spec) { this.live = live; $("canvas").dataset.live = "ready"; }
      } catch (err) {
        $("canvas").dataset.live = `unavailable: ${err.message}`;
      }
    }
  }

  // ------------------------------------------------------------------ controls and URL state
  #controls() {
    const units = this.spec.units || {};
    const positive = new Set(this.spec.positive_coordinates || []);
    // Every move shows at once in the live preview; the server runs when the slider is let go
    // (without live equations, 300 ms after the last move, as before).
    const changed = (store) => (name, value) => {
      store[name] = value;
      this.changes++;
      if (this.live) { this.preview(); this.#saveURL(); } else this.schedule();
    };
    const commit = () => { if (this.live) this.schedule(0); };
    buildControls($("params"), Object.entries(this.params).map(([name, value]) => ({
      name, value, unit: units[name], positive: value > 0,
    })), changed(this.params), commit);
    const rows = [];
    for (const q of this.spec.coordinates) {
      rows.push({ name: q, value: this.initial[q], unit: units[q], angle: units[q] === "rad", positive: positive.has(q) });
      rows.push({ name: `${q}_dot`, value: this.initial[`${q}_dot`], unit: units[q] ? `${units[q]}/s` : "" });
    }
    buildControls($("initial"), rows, changed(this.initial), commit);
    this.strip?.build();
  }

  /** New initial values from a drag on the canvas: controls, URL and the live preview follow. */
  setInitial(values) {
    for (const [k, v] of Object.entries(values)) {
      const x = Number(v.toFixed(6));
      this.initial[k] = x;
      setControl(k, x);
    }
    this.changes++;
    this.preview();
    this.#saveURL();
  }

  #reset() {
    const fresh = readValues(this.spec, new URLSearchParams());
    for (const [k, v] of Object.entries({ ...fresh.params, ...fresh.initial })) setControl(k, v);
    Object.assign(this.params, fresh.params);
    Object.assign(this.initial, fresh.initial);
    this.changes++;
    this.preview();
    this.schedule(0);
  }

  #saveURL() {
    if (!this.params) return;
    const q = new URLSearchParams(writeQuery({
      params: this.params, initial: this.initial, settings: this.settings, fixed: isFixed,
      lecture: this.lecture.on,
    }));
    if (this.phase && this.phase !== this.spec.coordinates[0]) q.set("phase", this.phase);
    // (a link's step is kept while the derivation it waits for is on its way)
    if (this.lecture.on) q.set("step", String(this.wantedSteps || this.lecture.revealed));
    if (!this.sceneId) {
      const from = new URLSearchParams(location.search).get("from");
      if (from) q.set("from", from);
    }
    // (the #fragment stays: a link to the derivation keeps its place)
    history.replaceState(null, "", `${location.pathname}?${q}${location.hash}`);
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
    const body = { ...this.target(), parameters: this.params, initial: this.initial, t_end: s.t_end, fps: SERVER_FPS, method, ...extra };
    if (isFixed(method)) body.dt = Number(s.dt);
    else { body.rtol = Number(s.tol); body.atol = Number(s.atol || s.tol); } // a link's own atol kept
    return body;
  }

  async run() {
    const id = ++this.runs;
    const changes = this.changes;
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
      delete $("canvas").dataset.error;
      // A value moved since this run was asked for: the preview on the canvas is newer; the
      // panel and the plots take the server's run, the canvas waits for the next one.
      if (changes === this.changes || !this.live) this.#show(forDisplay(a, DISPLAY_FACTOR), "server", changes);
      else this.#label(this.shown); // the preview stays: its line now says the run is in
      this.shownB = b ? forDisplay(b, DISPLAY_FACTOR) : null;
      if (b) this.stageB.setResult(this.spec, this.shownB, this.params);
      showStats(b ? [a, b] : [a]);
      $("caption-a").textContent = b ? `A: ${a.stats.method}` : "";
      $("caption-b").textContent = b ? `B: ${b.stats.method}` : "";
      const last = Object.values(a.q).map((v) => v[v.length - 1]);
      $("canvas").dataset.lastQ = JSON.stringify(last);
      $("canvas").dataset.run = String(id);
      showStop([a, b]);
      if (!this.playing) this.#toSample(); // a new run's samples may lie elsewhere (another dt)
      this.fbd(true);
      // The plots after the motion's next frame is painted: plotly's first drawing takes a few
      // hundred ms of the main thread, which the animation should not wait behind.
      // The first time, after the derivation's math too: the plots lie below the fold, their
      // library and first drawing take ~0.4 s of main thread, and the math is what a student
      // reads first.
      track(this.mathDone
        .then(() => new Promise((resolve) => requestAnimationFrame(() => setTimeout(resolve, 0))))
        .then(() => this.#plot()));
    } catch (err) {
      if (id !== this.runs) return;
      showWarnings([`The simulation failed: ${err.message}`]);
      // what the greyed panels say (page.js): whether numbers of an earlier run are on them, and
      // whether the server refused the values or the page failed to show its answer
      $("canvas").dataset.errorFrom = err instanceof ApiError ? "server" : "page";
      $("canvas").dataset.hadRun = this.result ? "1" : "0";
      $("canvas").dataset.error = err.message;
      if (this.shown && this.shown.stats.preview) { // never leave a preview of a refused state
        this.shown = null;
        this.#waiting("No motion: the server refused this state (see the warnings).");
        this.#label(null);
      }
      this.#syncPlay(); // nothing on the canvas: 'no run', not '… computing' for ever
    } finally {
      if (id === this.runs) {
        $("stats").classList.remove("busy");
        delete document.body.dataset.running;
      }
    }
  }

  // ------------------------------------------------------------------ the live preview
  /** Recompute the preview at the next animation frame (a burst of slider events costs one). */
  preview() {
    if (this.live && this.spec) this.previewDue = true;
  }

  #computePreview() {
    this.previewDue = false;
    // The server's run of these very values is on the canvas already (it came in between the
    // preview being asked for and this frame): it stays, and its line says so.
    if (this.shown && !this.shown.stats.preview && this.shownChanges === this.changes) return;
    let run;
    try {
      run = this.live.run({ params: this.params, initial: this.initial, tEnd: this.settings.t_end, fps: 60 });
    } catch (err) {
      $("canvas").dataset.live = `failed: ${err.message}`;
      this.live = null;
      return;
    }
    this.previews++;
    this.#show(run, "live", this.changes);
  }

  /** Put a run on canvas A: the server's, or the live preview (labelled as one), of the values
   * as they were at change number `changes`. */
  #show(run, source, changes) {
    this.shown = run;
    this.shownChanges = changes;
    this.stageA.setResult(this.spec, run, this.params);
    this.drag?.freeze();
    const end = run.t[run.t.length - 1];
    this.time = Math.min(this.time, end);
    const c = $("canvas");
    c.dataset.source = source;
    if (source === "live") {
      c.dataset.previews = String(this.previews);
      if (run.stats.stop) c.dataset.previewStop = String(run.stats.stop.t);
      else delete c.dataset.previewStop;
    }
    this.#label(run);
    this.stageA.draw(this.frameIndex());
    this.#syncPlay();
  }

  #label(run) {
    const b = this.badge;
    if (!run) { b.hidden = true; return; }
    b.hidden = false;
    const st = run.stats;
    if (st.preview) {
      b.dataset.kind = "preview";
      b.textContent = `${PREVIEW_LABEL}, h = ${(st.step * 1000).toPrecision(2)} ms — a preview: `
        + (this.result ? "the server's run follows when you let go" : "the server's run is on its way");
      if (st.stop) b.textContent += ` · stops at t = ${st.stop.t.toFixed(2)} s: ${st.stop.message}`;
      else if (st.status !== "ok") b.textContent += ` (stopped early: ${st.status})`;
      Object.assign(b.style, { background: "#fff3bf", color: "#5c3c00", borderColor: "#f59f00" });
    } else {
      b.dataset.kind = "server";
      const s = this.settings;
      // the step the server took (stats.dt) and the samples it sent: a fixed step samples every
      // whole number of steps near 1/fps, so its rate is not always SERVER_FPS
      const how = isFixed(st.method) ? `dt = ${st.dt ?? s.dt} s` : (s.atol ? `rtol = ${s.tol}, atol = ${s.atol}` : `rtol = atol = ${s.tol}`);
      const rate = st.sample_interval ? 1 / st.sample_interval : SERVER_FPS;
      const drawn = st.display_factor > 1 ? `; ${fmt(rate, 3)} samples/s, drawn at ${fmt(rate * st.display_factor, 3)} by interpolation` : "";
      // in lecture mode (24 px type beside a narrow canvas) the short form: the full one pushed
      // the play controls off a 1280×720 projector; the full one stays in its tooltip
      b.textContent = document.body.classList.contains("lecture")
        ? `server run (${st.method})` : `server run (${st.method}, ${how}${drawn})`;
      b.title = `server run (${st.method}, ${how}${drawn})`;
      Object.assign(b.style, { background: "transparent", color: "inherit", borderColor: "transparent" });
    }
  }

  /** Say on the canvas itself what is coming, so it is never blank while the page works. */
  #waiting(text) {
    const c = $("canvas");
    const ctx = c.getContext("2d");
    const dpr = window.devicePixelRatio || 1;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, c.width, c.height);
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = "#868e96";
    ctx.font = "14px system-ui, sans-serif";
    ctx.textAlign = "center";
    ctx.fillText(text, c.width / dpr / 2, c.height / dpr / 2);
    ctx.textAlign = "start";
    c.dataset.waiting = text;
    this.waitSize = [c.width, c.height];
  }

  #plot() {
    if (!this.result) return;
    if (!plotlyReady()) { // plotly is loaded once the motion is on screen (lazy.js)
      return loadPlotly().then(() => this.#plot(), () => {});
    }
    document.querySelectorAll(".plot-wait").forEach((el) => el.remove());
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
      if (!this.shown) return;
      const t = this.shown.t;
      this.time = (Number($("scrub").value) / 1000) * t[t.length - 1];
      this.#setPlaying(false);
    });
  }

  #setPlaying(on) {
    this.playing = on;
    if (!on) this.#toSample();
    this.#syncPlay();
    if (!on) this.fbd(true);
    if (!on) this.access?.describe(); // paused: the scene said in words, once
  }

  /** Paused (or scrubbed, or stepped): the clock goes to the nearest sample the server measured.
   * The canvas draws frames interpolated between samples (forDisplay), the free-body diagram
   * only the samples (its forces are the run's): held between two, the diagram said
   * t = 2.30 s under a clock at 2.28 s. On a sample, clock, canvas and diagram are one instant. */
  #toSample() {
    const r = this.result;
    if (!r || r.t.length < 2 || !this.shown || this.shown.stats.preview) return;
    this.time = r.t[this.frameIndex(r)];
    $("clock").textContent = `t = ${this.time.toFixed(2)} s`;
  }

  /** 'Pause' only while something moves on the canvas: before the first run it says so. */
  #syncPlay() {
    const ready = Boolean(this.shown);
    const refused = !ready && $("canvas").dataset.error !== undefined;
    $("play").textContent = refused ? "no run" : !ready ? "… computing" : this.playing ? "❚❚ Pause" : "▶ Play";
    $("play").setAttribute("aria-pressed", String(this.playing && ready));
  }

  togglePlay() {
    const r = this.shown;
    if (!this.playing && r && stopOf(r) && this.time >= r.t[r.t.length - 1]) this.time = 0; // replay
    this.#setPlaying(!this.playing);
  }

  frameIndex(r = this.shown) {
    const step = r.t.length > 1 ? r.t[1] - r.t[0] : 1;
    return Math.min(r.t.length - 1, Math.round(this.time / step));
  }

  #loop() {
    let last = performance.now();
    const tick = (now) => {
      const dt = Math.min(0.1, (now - last) / 1000);
      last = now;
      if (this.previewDue && this.live) this.#computePreview();
      const r = this.shown;
      if (r && r.t.length) {
        const end = r.t[r.t.length - 1];
        const held = this.drag.active;
        if (this.playing && !held) this.time += dt * this.speed;
        if (held) this.time = 0;
        if (this.time >= end && stopOf(r)) { // a stop ended the run: hold its last frame
          this.time = end;
          if (this.playing) { this.#setPlaying(false); $("scrub").value = 1000; }
        } else if (this.time > end) this.time = end > 0 ? this.time % end : 0;
        const frame = this.frameIndex();
        this.stageA.draw(frame);
        if (this.motion.pending) { // a third different frame drawn: the canvas has moved
          this.framesSeen ||= new Set();
          this.framesSeen.add(frame);
          if (this.framesSeen.size >= 3) this.motion.resolve();
        }
        this.drag.overlay();
        if (this.shownB) this.stageB.draw(this.frameIndex(this.shownB));
        $("clock").textContent = `t = ${this.time.toFixed(2)} s`;
        if (this.playing) $("scrub").value = end > 0 ? Math.round((1000 * this.time) / end) : 0;
        if (this.playing) this.fbd();
      } else {
        const c = $("canvas"); // the message again whenever the canvas was sized (which clears it)
        if (c.dataset.waiting && (c.width !== this.waitSize?.[0] || c.height !== this.waitSize?.[1])) {
          this.#waiting(c.dataset.waiting);
        }
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
    if (!this.shown || this.shown.stats.preview) return; // of the server's run, not a preview
    const placed = this.derivation?.steps?.find((s) => s.id === "fbd")?.data;
    const kinds = drawFBD($("fbd-svg"), this.spec, this.result, this.params, this.frameIndex(this.result),
      { yaw: this.stageA.yaw, pitch: this.stageA.pitch }, placed);
    fbdLegend($("fbd-legend"), kinds);
    if (this.lecture.on) legibleLabels($("fbd-svg"), LECTURE_LABEL_PX);
  }

  // ------------------------------------------------------------------ derivation, equilibria
  async derive(given = null) {
    const steps = $("steps");
    delete steps.dataset.typeset;
    steps.innerHTML = '<li class="muted">Deriving the equations of motion…</li>';
    try {
      this.derivation = given ? await given : await postJSON("/api/v1/derive", this.target());
    } catch (err) {
      steps.replaceChildren(Object.assign(document.createElement("li"), { className: "errors", textContent: err.message }));
      this.mathDone.resolve();
      return;
    }
    renderSteps(steps, this.derivation, { target: () => this.target(), coordinates: this.spec.coordinates });
    showWarningsBelow(this.derivation.warnings);
    if (this.wantedSteps) { // a link's step: opened there, scrolled to it
      this.lecture.open(this.wantedSteps);
      this.wantedSteps = null;
    } else this.lecture.apply();
    // the address says the step shown: a link's step=99 past the last one is clamped to it (as a
    // step=-3 or step=abc is read as the first), so a copied address opens where the room is
    this.#saveURL();
    if (this.result) this.fbd(true);
    // One step at a time with a frame between: typesetting the whole derivation at once holds the
    // main thread for half a second, during which the animation could not start or move.
    // Until its turn, a step's LaTeX source is kept out of sight (its place kept, no jump).
    const items = [...steps.children];
    const raw = (item, hide) => item.querySelectorAll(".math, .text, .note").forEach((el) => {
      el.style.visibility = hide ? "hidden" : "";
    });
    if (window.MathJax) items.forEach((item) => raw(item, true));
    const done = busy("Typesetting the equations…");
    const view = watchInView(items);
    try {
      // which steps are in view, and the ready-made math (unless its file is slow to come: then
      // MathJax typesets it all), waited for together
      const [, madeAhead] = await Promise.all([view.ready, Promise.race([this.prerendered,
        new Promise((resolve) => setTimeout(() => resolve(false), PRERENDERED_WAIT_MS))])]);
      // A derivation out of sight that MathJax must typeset waits for the animation to move (it
      // would hold the main thread for half a second); ready-made math costs only its insertion,
      // and an out-of-sight step is not even laid out (content-visibility), so it goes in at once
      // (a formula it lacks still waits: MathJax itself is held until the motion). One in view
      // (lecture mode, a link to it) is what the reader came for, so it starts at once.
      if (items.some((item) => view.has(item))) releaseMathJax();
      else if (!madeAhead) await this.motion;
      const left = new Set(items);
      const pace = typesetPace(madeAhead);
      while (left.size) {
        // the steps in view first (again after each batch: the reader may have scrolled), then
        // the rest in order; a hidden step (lecture mode) is typeset too, ready when revealed
        const order = [...items.filter((i) => left.has(i) && view.has(i)),
          ...items.filter((i) => left.has(i) && !view.has(i))];
        const batch = pace.take(order);
        batch.forEach((item) => left.delete(item));
        const started = performance.now();
        await typeset(batch);
        pace.learn(batch, performance.now() - started);
        batch.forEach((item) => {
          raw(item, false);
          item.dataset.typeset = "1";
        });
        if (!left.size) break; // the last one: nothing more waits for a frame
        // a frame between two batches: the animation's is drawn, and the observer reports where
        // the steps are now that this batch changed their heights (else the next batch is
        // chosen by the old positions: the steps above a reader at the end came before the
        // ones on screen); at most 50 ms, for a tab in the background that draws no frames
        await new Promise((resolve) => {
          const timer = setTimeout(resolve, 50);
          requestAnimationFrame(() => setTimeout(() => { clearTimeout(timer); resolve(); }, 0));
        });
      }
    } finally {
      view.stop();
      done();
      this.mathDone.resolve();
    }
    steps.dataset.typeset = "1";
    if (this.derivation.provenance) { // where each term comes from: tables under each equation
      const { traceTerms } = await import("./provenance.js");
      await traceTerms(steps, this.derivation.provenance);
    }
    // the typeset math (and its tables) above a linked step moved it: back under the header
    fitEquations(steps).then(() => this.lecture.settle());
    this.#mountExtras();
  }

  /** The panels that read the page's state when asked: work–precision and exports, once. */
  #mountExtras() {
    if (this.extras) return;
    this.extras = true;
    const main = document.querySelector("main");
    const source = { sceneId: this.sceneId, spec: this.sceneId ? null : this.spec };
    const state = () => ({
      parameters: this.params, initial: this.initial, settings: this.settings,
      lecture: this.lecture.on, lectureStep: this.lecture.on ? this.lecture.revealed - 1 : null,
    });
    // Work–precision runs a dozen integrations when asked: folded, and loaded on first opening
    const fold = Object.assign(document.createElement("section"), { className: "panel", id: "precision-panel" });
    fold.innerHTML = '<details class="fold"><summary><h2 id="h-precision-fold">Work–precision: '
      + "what accuracy costs, for this scene</h2></summary></details>";
    fold.setAttribute("aria-labelledby", "h-precision-fold");
    main.append(fold);
    const details = fold.firstElementChild;
    details.addEventListener("toggle", () => {
      if (!details.open || details.dataset.mounted) return;
      details.dataset.mounted = "1";
      import("./precision.js").then(({ mountPrecision }) => {
        mountPrecision(details, { ...source, getState: state });
        details.querySelector("#h-precision")?.remove(); // the fold's summary is its heading
        const inner = details.querySelector("#precision");
        inner?.classList.remove("panel");
        inner?.setAttribute("aria-labelledby", "h-precision-fold");
      });
    });
    import("./exports.js").then(({ mountExports }) => mountExports(main, { ...source, getState: state }));
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
    this.changes++;
    this.preview();
    this.schedule(0);
  }
}

/** Lecture mode's least size of a label in a drawing (CSS px): read from the back of a hall. */
const LECTURE_LABEL_PX = 24;

/** The labels of an svg drawn in its own units (the free-body diagram: 11 units, 13 px on a
 * 1024×768 projector) brought up to `px` CSS pixels on the screen, their subscripts in proportion. */
function legibleLabels(svg, px) {
  const box = svg?.viewBox?.baseVal;
  const shown = svg?.getBoundingClientRect().width;
  if (!box || !box.width || !shown) return;
  const k = shown / box.width; // screen px per svg unit
  for (const text of svg.querySelectorAll("text")) {
    const size = parseFloat(text.getAttribute("font-size")) || 12;
    if (size * k >= px) continue;
    const by = px / (size * k);
    text.style.fontSize = `${(size * by).toFixed(2)}px`;
    for (const span of text.querySelectorAll("tspan[font-size]")) {
      span.style.fontSize = `${(parseFloat(span.getAttribute("font-size")) * by).toFixed(2)}px`;
    }
  }
}

/** The spec, the live equations' slots and the derivation the page carries in its HTML
 * (templates/scene.html), each as a resolved promise; a part the page does not carry is absent. */
function inlineData() {
  const read = (id) => {
    const el = document.getElementById(id);
    if (!el) return undefined;
    try {
      return JSON.parse(el.textContent);
    } catch {
      return undefined; // the script asks the API instead
    }
  };
  const spec = read("scene-spec"), live = read("scene-live"), derivation = read("scene-derivation");
  return {
    spec: spec && Promise.resolve(spec),
    live: live || null,
    derivation: derivation && Promise.resolve(derivation),
  };
}

/** How many steps to typeset in one go. Each MathJax call measures the page's layout once: on a
 * loaded machine the double pendulum's steps in one call took about a quarter less time than one
 * call per step (on a quiet one the difference was within the noise), but one call for everything
 * holds the main thread (and the animation) for a quarter of a second. So steps are grouped to
 * about BATCH_MS of work each, at the pace this machine was seen to typeset. */
const BATCH_MS = 50;

function typesetPace(madeAhead) {
  const size = (item) => item.textContent.length || 1; // the LaTeX source: a proxy for the work
  // unknown until the first step was typeset; ready-made math is only inserted (the double
  // pendulum's seven steps took 40 ms in all, measured in the page): one batch, which learns
  // the pace in case the file lacked some formulas and MathJax typesets them live
  let msPerChar = madeAhead ? 0 : null;
  return {
    take(order) {
      if (msPerChar === null) return order.slice(0, 1);
      const batch = [];
      let cost = 0;
      for (const item of order) {
        cost += size(item) * msPerChar;
        if (batch.length && cost > BATCH_MS) break;
        batch.push(item);
      }
      return batch;
    },
    learn(batch, ms) {
      const rate = ms / batch.reduce((n, item) => n + size(item), 0);
      msPerChar = msPerChar === null ? rate : (msPerChar + rate) / 2;
    },
  };
}

/** Which of `elements` are in (or just below) the viewport now, kept up to date as the reader
 * scrolls or lecture mode reveals a step; `ready` settles once each has been looked at once. */
function watchInView(elements) {
  const seen = new Set();
  let first;
  const ready = new Promise((resolve) => { first = resolve; });
  if (!("IntersectionObserver" in window) || !elements.length) {
    return { ready: Promise.resolve(), has: () => false, stop: () => {} };
  }
  const observer = new IntersectionObserver((entries) => {
    for (const e of entries) {
      if (e.isIntersecting) seen.add(e.target);
      else seen.delete(e.target);
    }
    first();
  }, { rootMargin: "0px 0px 25% 0px" });
  elements.forEach((el) => observer.observe(el));
  return { ready, has: (el) => seen.has(el), stop: () => observer.disconnect() };
}

/** A promise resolved by whoever gets there first; `pending` until then. */
function settleOnce() {
  let resolve;
  const p = new Promise((r) => { resolve = r; });
  p.pending = true;
  p.resolve = () => { p.pending = false; resolve(); };
  return p;
}

/** The line under the animation that says what it shows: a live preview or the server's run. */
function liveBadge() {
  let b = $("live-badge");
  if (b) return b;
  b = Object.assign(document.createElement("p"), { id: "live-badge", hidden: true });
  b.setAttribute("role", "status");
  Object.assign(b.style, { margin: "0.3rem 0", padding: "0.15rem 0.5rem", border: "1px solid transparent",
    borderRadius: "4px", fontSize: "0.85rem" });
  const views = document.querySelector(".stage-views");
  views.after(b);
  return b;
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
