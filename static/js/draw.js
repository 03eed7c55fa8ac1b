// Draws a simulated trajectory: bodies, rods, springs (zigzag), dampers, supports and a fading
// trail. Planar scenes in the x–y plane; 3-D ones in a perspective view rotated by dragging.

const COLORS = ["#1f6feb", "#d9480f", "#2f9e44", "#9c36b5", "#e8590c", "#0c8599"];

export function bodyAnchor(body) {
  const p = body.position;
  return p && !Array.isArray(p) && p.from ? p.from : "O";
}

export class Stage {
  constructor(canvas, spec) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d");
    this.spec = spec;
    this.yaw = 0.6;
    this.pitch = 0.35;
    this.result = null;
    this.frame = 0;
    this.canvas.addEventListener("pointerdown", (e) => this.#drag(e));
  }

  setResult(result) {
    this.result = result;
    const P = result.positions;
    const names = Object.keys(P);
    this.is3D = this.spec.bodies.some((b) => P[b.name] && P[b.name].z.some((z) => Math.abs(z) > 1e-9));
    this.links = [];
    for (const b of this.spec.bodies) {
      const a = bodyAnchor(b);
      if (!P[a] || !P[b.name]) continue;
      const d = P[b.name].x.map((_, i) => Math.hypot(
        P[b.name].x[i] - P[a].x[i], P[b.name].y[i] - P[a].y[i], P[b.name].z[i] - P[a].z[i]));
      const mean = d.reduce((s, v) => s + v, 0) / d.length;
      const spread = Math.max(...d) - Math.min(...d);
      if (mean > 1e-9 && spread <= 1e-6 * mean) this.links.push([a, b.name]);
    }
    this.#fit(names);
  }

  #project(x, y, z) {
    if (!this.is3D) return [x, y, 0];
    const cy = Math.cos(this.yaw), sy = Math.sin(this.yaw);
    const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    const x1 = cy * x + sy * z, z1 = -sy * x + cy * z;
    const y2 = cp * y - sp * z1, z2 = sp * y + cp * z1;
    return [x1, y2, z2];
  }

  #fit(names) {
    const P = this.result.positions;
    let lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
    for (const n of names) {
      for (let i = 0; i < P[n].x.length; i += Math.max(1, Math.floor(P[n].x.length / 400))) {
        const [u, v] = this.#project(P[n].x[i], P[n].y[i], P[n].z[i]);
        lo = [Math.min(lo[0], u), Math.min(lo[1], v)];
        hi = [Math.max(hi[0], u), Math.max(hi[1], v)];
      }
    }
    const w = this.canvas.width, h = this.canvas.height;
    const span = Math.max(hi[0] - lo[0], hi[1] - lo[1], 1e-9);
    this.scale = 0.8 * Math.min(w, h) / span;
    if (!isFinite(this.scale)) this.scale = 1;
    this.center = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2];
  }

  toScreen(name, i) {
    const p = this.result.positions[name];
    const [u, v, depth] = this.#project(p.x[i], p.y[i], p.z[i]);
    const persp = this.is3D ? 1 / (1 + 0.15 * depth * this.scale / this.canvas.height) : 1;
    return [
      this.canvas.width / 2 + (u - this.center[0]) * this.scale * persp,
      this.canvas.height / 2 - (v - this.center[1]) * this.scale * persp,
    ];
  }

  draw(i) {
    if (!this.result) return;
    const n = this.result.t.length;
    this.frame = Math.max(0, Math.min(n - 1, i));
    const { ctx, canvas } = this;
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    if (this.is3D) this.#axes();
    this.#trails();
    for (const s of this.spec.springs || []) this.#spring(s.a, s.b);
    for (const d of this.spec.dampers || []) this.#damper(d.a, d.b);
    ctx.lineWidth = 3;
    ctx.strokeStyle = "#495057";
    for (const [a, b] of this.links) this.#line(a, b);
    for (const p of this.spec.points || []) this.#support(p.name);
    this.#support("O");
    this.spec.bodies.forEach((b, k) => this.#body(b, COLORS[k % COLORS.length]));
    canvas.dataset.frame = String(this.frame);
  }

  #line(a, b) {
    const [x1, y1] = this.toScreen(a, this.frame), [x2, y2] = this.toScreen(b, this.frame);
    this.ctx.beginPath(); this.ctx.moveTo(x1, y1); this.ctx.lineTo(x2, y2); this.ctx.stroke();
  }

  #support(name) {
    if (!this.result.positions[name]) return;
    const [x, y] = this.toScreen(name, this.frame);
    const c = this.ctx;
    c.fillStyle = "#343a40";
    c.beginPath(); c.moveTo(x, y); c.lineTo(x - 7, y - 11); c.lineTo(x + 7, y - 11); c.closePath();
    c.fill();
  }

  #spring(a, b) {
    const [x1, y1] = this.toScreen(a, this.frame), [x2, y2] = this.toScreen(b, this.frame);
    const dx = x2 - x1, dy = y2 - y1, len = Math.hypot(dx, dy) || 1;
    const nx = -dy / len, ny = dx / len, coils = 10, amp = 7;
    const c = this.ctx;
    c.strokeStyle = "#868e96"; c.lineWidth = 2; c.beginPath(); c.moveTo(x1, y1);
    for (let k = 1; k < 2 * coils; k++) {
      const f = k / (2 * coils), side = k % 2 ? amp : -amp;
      c.lineTo(x1 + dx * f + nx * side, y1 + dy * f + ny * side);
    }
    c.lineTo(x2, y2); c.stroke();
  }

  #damper(a, b) {
    const c = this.ctx;
    c.save(); c.setLineDash([4, 4]); c.strokeStyle = "#adb5bd"; c.lineWidth = 2;
    const [x1, y1] = this.toScreen(a, this.frame), [x2, y2] = this.toScreen(b, this.frame);
    c.beginPath(); c.moveTo(x1, y1 + 12); c.lineTo(x2, y2 + 12); c.stroke(); c.restore();
  }

  #body(b, color) {
    const c = this.ctx;
    const [x, y] = this.toScreen(b.name, this.frame);
    const frames = this.result.frames || {};
    if (b.kind === "rigid_body" && frames[b.frame]) {
      const f = frames[b.frame][this.frame];
      const anchor = bodyAnchor(b);
      const linked = this.links.some(([a, n]) => n === b.name && a === anchor);
      if (linked) { // a rod pivoted at its anchor: draw it through the centre to the far end
        const [ax, ay] = this.toScreen(anchor, this.frame);
        c.strokeStyle = color; c.lineWidth = 8; c.lineCap = "round";
        c.beginPath(); c.moveTo(ax, ay); c.lineTo(2 * x - ax, 2 * y - ay); c.stroke();
        c.lineCap = "butt";
      } else { // a wheel: a disk with a spoke along the body's x axis
        const r = 18;
        c.fillStyle = color + "33"; c.strokeStyle = color; c.lineWidth = 3;
        c.beginPath(); c.arc(x, y, r, 0, 2 * Math.PI); c.fill(); c.stroke();
        c.beginPath(); c.moveTo(x, y); c.lineTo(x + r * f[0], y - r * f[1]); c.stroke();
      }
    } else {
      c.fillStyle = color;
      c.beginPath(); c.arc(x, y, 10, 0, 2 * Math.PI); c.fill();
    }
    c.fillStyle = "#212529"; c.font = "12px system-ui"; c.fillText(b.name, x + 13, y - 10);
  }

  #trails() {
    const c = this.ctx, t = this.result.t;
    const span = Math.min(this.frame, Math.round(1.5 / Math.max(t[1] - t[0], 1e-9)));
    this.spec.bodies.forEach((b, k) => {
      c.strokeStyle = COLORS[k % COLORS.length]; c.lineWidth = 2;
      for (let i = this.frame - span + 1; i <= this.frame; i++) {
        if (i < 1) continue;
        c.globalAlpha = 0.6 * (1 - (this.frame - i) / span);
        const [x1, y1] = this.toScreen(b.name, i - 1), [x2, y2] = this.toScreen(b.name, i);
        c.beginPath(); c.moveTo(x1, y1); c.lineTo(x2, y2); c.stroke();
      }
      c.globalAlpha = 1;
    });
  }

  #axes() {
    const c = this.ctx, len = 0.25 * Math.min(this.canvas.width, this.canvas.height) / this.scale;
    const o = this.#project(0, 0, 0);
    [["x", [len, 0, 0], "#e03131"], ["y", [0, len, 0], "#2f9e44"], ["z", [0, 0, len], "#1971c2"]]
      .forEach(([label, v, color]) => {
        const p = this.#project(...v);
        const X = (u) => this.canvas.width / 2 + (u - this.center[0]) * this.scale;
        const Y = (u) => this.canvas.height / 2 - (u - this.center[1]) * this.scale;
        c.strokeStyle = color; c.lineWidth = 1; c.beginPath();
        c.moveTo(X(o[0]), Y(o[1])); c.lineTo(X(p[0]), Y(p[1])); c.stroke();
        c.fillStyle = color; c.fillText(label, X(p[0]) + 3, Y(p[1]));
      });
  }

  #drag(e) {
    if (!this.is3D) return;
    const x0 = e.clientX, y0 = e.clientY, yaw0 = this.yaw, pitch0 = this.pitch;
    const move = (m) => {
      this.yaw = yaw0 + (m.clientX - x0) * 0.01;
      this.pitch = Math.max(-1.4, Math.min(1.4, pitch0 + (m.clientY - y0) * 0.01));
      this.draw(this.frame);
    };
    const up = () => { window.removeEventListener("pointermove", move); window.removeEventListener("pointerup", up); };
    window.addEventListener("pointermove", move);
    window.addEventListener("pointerup", up);
  }
}
