// World (x, y, z in N) to screen pixels: the x–y plane for planar scenes, a perspective view for
// 3-D ones (yaw and pitch change when the user drags); and back (unproject), for dragging a body.

export class View {
  constructor(width, height, is3D = false) {
    this.w = width;
    this.h = height;
    this.is3D = is3D;
    this.yaw = 0.55;
    this.pitch = 0.4;
    this.scale = 1;
    this.center = [0, 0, 0];
    this.camera = 1;
  }

  /** Fit the points (world) in the view with `pad` pixels to spare on every side. */
  fit(points, pad = 24) {
    if (!points.length) return this;
    const lo = [0, 1, 2].map((k) => Math.min(...points.map((p) => p[k])));
    const hi = [0, 1, 2].map((k) => Math.max(...points.map((p) => p[k])));
    this.center = lo.map((v, k) => (v + hi[k]) / 2);
    const room = [Math.max(this.w - 2 * pad, 10), Math.max(this.h - 2 * pad, 10)];
    if (this.is3D) {
      // A bounding sphere: the scale stays put while the user turns the view.
      const radius = Math.max(...points.map((p) => Math.hypot(
        p[0] - this.center[0], p[1] - this.center[1], p[2] - this.center[2])), 1e-9);
      this.camera = 3.5 * radius;
      this.scale = Math.min(...room) / 2 / (1.4 * radius);
    } else {
      const span = [Math.max(hi[0] - lo[0], 1e-9), Math.max(hi[1] - lo[1], 1e-9)];
      this.scale = Math.min(room[0] / span[0], room[1] / span[1]);
      if (span[0] < 1e-6 && span[1] < 1e-6) this.scale = Math.min(...room) / 2;
    }
    return this;
  }

  /** Whether every point is drawn inside the canvas, `margin` pixels from its edges (a 3-D
   * view: as the camera looks now). */
  contains(points, margin = 0) {
    return points.every((p) => {
      const [x, y] = this.project(p);
      return x >= margin && x <= this.w - margin && y >= margin && y <= this.h - margin;
    });
  }

  /** Screen [x, y], the depth toward the viewer, and the perspective factor. */
  project(p) {
    let x = p[0] - this.center[0], y = p[1] - this.center[1], z = p[2] - this.center[2];
    let f = 1;
    if (this.is3D) {
      const cy = Math.cos(this.yaw), sy = Math.sin(this.yaw);
      const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
      const x1 = cy * x + sy * z, z1 = -sy * x + cy * z;
      const y2 = cp * y - sp * z1, z2 = sp * y + cp * z1;
      f = this.camera / (this.camera - z2);
      x = x1; y = y2; z = z2;
    }
    return [this.w / 2 + x * this.scale * f, this.h / 2 - y * this.scale * f, z, f];
  }

  /** The camera's axes in world coordinates: screen right, screen up, and toward the viewer
   * (project's depth is the component along the third). A planar view's are x, y, z. */
  axes() {
    if (!this.is3D) return [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
    const cy = Math.cos(this.yaw), sy = Math.sin(this.yaw);
    const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    return [[cy, 0, sy], [sp * sy, cp, -sp * cy], [-cp * sy, sp, cp * cy]];
  }

  /** The inverse of project: the world point drawn at screen (sx, sy) on the plane parallel to
   * the screen at `depth` (project's third value). A dragged body is moved in that plane. */
  unproject(sx, sy, depth = 0) {
    const f = this.is3D ? this.camera / (this.camera - depth) : 1;
    const x = (sx - this.w / 2) / (this.scale * f), y = -(sy - this.h / 2) / (this.scale * f);
    const [ex, ey, ez] = this.axes();
    return [0, 1, 2].map((k) => this.center[k] + x * ex[k] + y * ey[k] + depth * ez[k]);
  }

  /** The screen direction (unit, pixels) of a world direction d at world point p. */
  direction(p, d, eps = 1e-3) {
    const a = this.project(p);
    const b = this.project([p[0] + d[0] * eps, p[1] + d[1] * eps, p[2] + d[2] * eps]);
    const dx = b[0] - a[0], dy = b[1] - a[1], len = Math.hypot(dx, dy);
    return len > 1e-12 ? [dx / len, dy / len] : [0, 0];
  }
}
