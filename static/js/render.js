// Two ways to draw the primitives of shapes.js: on a 2-D canvas (the animation) and as SVG markup
// (the catalog drawings and the free-body diagram).

function arrowHead(a, b, size) {
  const dx = b[0] - a[0], dy = b[1] - a[1], len = Math.hypot(dx, dy) || 1;
  const ux = dx / len, uy = dy / len, w = size * 0.55;
  return [[b[0], b[1]], [b[0] - ux * size + uy * w, b[1] - uy * size - ux * w],
    [b[0] - ux * size - uy * w, b[1] - uy * size + ux * w]];
}

/** Draw the primitives on a canvas context (in CSS pixels: the caller sets the DPR transform). */
export function drawCanvas(ctx, shapes) {
  for (const s of shapes) {
    ctx.save();
    ctx.globalAlpha = s.alpha ?? 1;
    ctx.lineWidth = s.width ?? 1;
    ctx.lineCap = s.cap || "butt";
    ctx.lineJoin = "round";
    ctx.setLineDash(s.dash || []);
    if (s.color) ctx.strokeStyle = s.color;
    if (s.fill) ctx.fillStyle = s.fill;
    if (s.t === "line" || s.t === "arrow") {
      const b = s.t === "arrow" ? shorten(s.a, s.b, (s.head ?? 9) * 0.8) : s.b;
      ctx.beginPath(); ctx.moveTo(s.a[0], s.a[1]); ctx.lineTo(b[0], b[1]); ctx.stroke();
      if (s.t === "arrow") {
        ctx.setLineDash([]);
        ctx.fillStyle = s.color;
        fillPoly(ctx, arrowHead(s.a, s.b, s.head ?? 9));
      }
    } else if (s.t === "poly") {
      ctx.beginPath();
      s.pts.forEach(([x, y], k) => (k ? ctx.lineTo(x, y) : ctx.moveTo(x, y)));
      if (s.closed) ctx.closePath();
      if (s.fill) ctx.fill();
      if (s.color) ctx.stroke();
    } else if (s.t === "circle") {
      ctx.beginPath(); ctx.arc(s.c[0], s.c[1], Math.max(0.5, s.r), 0, 2 * Math.PI);
      if (s.fill) ctx.fill();
      if (s.color) ctx.stroke();
    } else if (s.t === "text") {
      drawText(ctx, s);
    }
    ctx.restore();
  }
}

function shorten(a, b, by) {
  const dx = b[0] - a[0], dy = b[1] - a[1], len = Math.hypot(dx, dy) || 1;
  return [b[0] - (dx / len) * Math.min(by, len), b[1] - (dy / len) * Math.min(by, len)];
}

function fillPoly(ctx, pts) {
  ctx.beginPath();
  pts.forEach(([x, y], k) => (k ? ctx.lineTo(x, y) : ctx.moveTo(x, y)));
  ctx.closePath();
  ctx.fill();
}

function drawText(ctx, s) {
  const size = s.size ?? 12;
  const font = (px) => `${s.italic ? "italic " : ""}${s.weight || 500} ${px}px system-ui, sans-serif`;
  ctx.font = font(size);
  const main = ctx.measureText(s.text).width;
  ctx.font = font(size * 0.75);
  const subw = s.sub ? ctx.measureText(s.sub).width : 0;
  let x = s.at[0];
  if (s.align === "center") x -= (main + subw) / 2;
  if (s.halo) {
    ctx.fillStyle = "rgba(255,255,255,0.8)";
    ctx.fillRect(x - 2, s.at[1] - size + 1, main + subw + 4, size + 3);
  }
  ctx.fillStyle = s.color || "#212529";
  ctx.font = font(size);
  ctx.fillText(s.text, x, s.at[1]);
  if (s.sub) {
    ctx.font = font(size * 0.75);
    ctx.fillText(s.sub, x + main + 1, s.at[1] + size * 0.3);
  }
}

const esc = (t) => String(t).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]);
const num = (x) => (Math.round(x * 10) / 10).toString();
const pts = (list) => list.map(([x, y]) => `${num(x)},${num(y)}`).join(" ");

/** SVG markup (the inside of an <svg>) for the primitives. */
export function toSVG(shapes) {
  return shapes.map((s) => {
    const stroke = s.color ? ` stroke="${s.color}" stroke-width="${s.width ?? 1}"` : "";
    const fill = ` fill="${s.fill || "none"}"`;
    const extra = `${s.piece ? ` data-piece="${s.piece}"` : ""}${s.alpha !== undefined ? ` opacity="${s.alpha.toFixed(2)}"` : ""}${s.dash ? ` stroke-dasharray="${s.dash.join(" ")}"` : ""}${s.cap ? ` stroke-linecap="${s.cap}"` : ""}`;
    if (s.t === "line") {
      return `<line x1="${num(s.a[0])}" y1="${num(s.a[1])}" x2="${num(s.b[0])}" y2="${num(s.b[1])}"${stroke}${extra}/>`;
    }
    if (s.t === "arrow") {
      const b = shorten(s.a, s.b, (s.head ?? 9) * 0.8);
      return `<g${extra}><line x1="${num(s.a[0])}" y1="${num(s.a[1])}" x2="${num(b[0])}" y2="${num(b[1])}"${stroke}/>` +
        `<polygon points="${pts(arrowHead(s.a, s.b, s.head ?? 9))}" fill="${s.color}"/></g>`;
    }
    if (s.t === "poly") {
      const tag = s.closed ? "polygon" : "polyline";
      return `<${tag} points="${pts(s.pts)}"${stroke}${fill}${extra} stroke-linejoin="round"/>`;
    }
    if (s.t === "circle") {
      return `<circle cx="${num(s.c[0])}" cy="${num(s.c[1])}" r="${num(Math.max(0.5, s.r))}"${stroke}${fill}${extra}/>`;
    }
    if (s.t === "text") {
      const size = s.size ?? 12;
      const anchor = s.align === "center" ? ' text-anchor="middle"' : "";
      const halo = s.halo ? ' paint-order="stroke" stroke="#fff" stroke-width="3" stroke-linejoin="round"' : "";
      const sub = s.sub ? `<tspan font-size="${num(size * 0.75)}" dy="${num(size * 0.3)}">${esc(s.sub)}</tspan>` : "";
      return `<text x="${num(s.at[0])}" y="${num(s.at[1])}" font-size="${size}" fill="${s.color || "#212529"}"${anchor}${halo}${s.italic ? ' font-style="italic"' : ""} font-weight="${s.weight || 500}">${esc(s.text)}${sub}</text>`;
    }
    return "";
  }).join("");
}
