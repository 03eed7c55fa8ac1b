// Wide equations fit their box: a projector at 1024×768 or a phone has no room for a double
// pendulum's θ̈₁ on one line. An equation wider than its box is, in order,
//   1. broken at the + and − of its longest side into a few aligned lines; a matrix (M, f) is
//      written entry by entry, a long fraction as num/den with num and den on lines of their own;
//   2. scaled down, not below MIN_SCALE (smaller would not be read from the back of a hall);
//   3. left to scroll inside its own box, which then carries the class `scrolls` (a fade at the
//      right edge and a "scroll →" cue, see app.css), never making the page wider.
// The LaTeX the engine sent stays in `data-latex` (the copy buttons use it): a box wide enough
// again gets the original line back.
import { typeset } from "./api.js";

const MIN_SCALE = 0.72;

/** Top-level positions of `chars` in `tex`: outside {…}, \left…\right and environments. */
function topLevel(tex, chars) {
  const found = [];
  let depth = 0;
  for (let i = 0; i < tex.length; i++) {
    const c = tex[i];
    if (c === "\\" && tex[i + 1] === "\\") { // a row break \\ of a matrix or an aligned block
      if (depth === 0 && chars.includes("\\")) found.push(i);
      i += 1;
      continue;
    }
    if (c === "\\") {
      const m = /^\\(left|right|begin|end)\b/.exec(tex.slice(i));
      if (m) depth += m[1] === "left" || m[1] === "begin" ? 1 : -1;
      const word = /^\\([a-zA-Z]+|.)/.exec(tex.slice(i));
      i += word ? word[0].length - 1 : 0;
      continue;
    }
    if (c === "{" || c === "(") depth += 1;
    else if (c === "}" || c === ")") depth -= 1;
    else if (depth === 0 && chars.includes(c)) found.push(i);
  }
  return found;
}

/** `a + b - c` → ["a", "+ b", "- c"]: the top-level terms with their signs (a leading sign stays). */
export function terms(tex) {
  const cuts = topLevel(tex, "+-").filter((i) => tex.slice(0, i).trim() !== "");
  const out = [];
  let from = 0;
  for (const i of cuts) {
    // "- " after an operator or "^"/"_" is a sign, not a cut: "=", "(" are already not top level
    const before = tex.slice(0, i).trimEnd();
    if (/[+\-=^_,]$|\\cdot$|\\quad$/.test(before)) continue;
    out.push(tex.slice(from, i).trim());
    from = i;
  }
  out.push(tex.slice(from).trim());
  return out.filter((t) => t !== "");
}

/**
 * The pieces a side can be broken into: its terms, or, for one product around a big bracket
 * (`m_2 \\left(a + b\\right)`), the bracket's terms with the bracket opened in the first piece and
 * closed in the last (as \\Bigl( … \\Bigr), which, unlike \\left … \\right, may span lines).
 */
export function pieces(side, fine = false) {
  const t = terms(side);
  if (t.length > 1) return fine ? t.flatMap(openBracket) : t;
  return openBracket(side);
}

/**
 * A term split inside its longest top-level \left( … \right) group (when that group holds most of
 * the term and is itself a sum), the bracket opened in the first piece and closed in the last.
 */
function openBracket(term) {
  let best = null;
  let depth = 0, open = -1;
  for (let i = 0; i < term.length; i++) {
    if (term.startsWith("\\left", i)) {
      if (depth === 0) open = i;
      depth += 1;
      i += 4;
    } else if (term.startsWith("\\right", i)) {
      depth -= 1;
      if (depth === 0 && term.startsWith("\\left(", open) && term.startsWith("\\right)", i)) {
        if (!best || i - open > best[1] - best[0]) best = [open, i];
      }
      i += 5;
    }
  }
  if (!best) return [term];
  const [open0, close] = best;
  const inner = term.slice(open0 + 6, close);
  const innerTerms = terms(inner);
  if (innerTerms.length < 2 || inner.length < 0.4 * term.length) return [term];
  innerTerms[0] = `${term.slice(0, open0)}\\Bigl(${innerTerms[0]}`;
  innerTerms[innerTerms.length - 1] += `\\Bigr)${term.slice(close + 7)}`;
  return innerTerms;
}

/** The matrix of `\left[\begin{matrix}…\end{matrix}\right]`, or null. */
function matrixOf(tex) {
  const m = /^\\left\[\\begin\{matrix\}([\s\S]*)\\end\{matrix\}\\right\]$/.exec(tex.trim());
  if (!m) return null;
  const body = m[1];
  const rows = splitAt(body, topLevel(body, "\\"), 2);
  return rows.map((row) => splitAt(row, topLevel(row, "&"), 1).map((c) => c.trim()));
}

function splitAt(tex, positions, width) {
  const out = [];
  let from = 0;
  for (const i of positions) {
    out.push(tex.slice(from, i));
    from = i + width;
  }
  out.push(tex.slice(from));
  return out;
}

/** `\frac{N}{D}` filling all of `tex`: [N, D], or null. */
function fractionOf(tex) {
  const t = tex.trim();
  if (!t.startsWith("\\frac{")) return null;
  const group = (start) => {
    let depth = 0;
    for (let i = start; i < t.length; i++) {
      if (t[i] === "\\") { i += 1; continue; }
      if (t[i] === "{") depth += 1;
      else if (t[i] === "}" && --depth === 0) return i;
    }
    return -1;
  };
  const endN = group(5);
  if (endN < 0 || t[endN + 1] !== "{") return null;
  const endD = group(endN + 1);
  if (endD !== t.length - 1) return null;
  return [t.slice(6, endN), t.slice(endN + 2, endD)];
}

/** Pack `parts` (terms with their signs) into `lines` rows of roughly equal LaTeX length. */
function pack(parts, lines) {
  const total = parts.reduce((s, p) => s + p.length, 0);
  const rows = [[]];
  let used = 0;
  for (const p of parts) {
    const row = rows[rows.length - 1];
    if (row.length && used + p.length / 2 > (rows.length * total) / lines && rows.length < lines) {
      rows.push([p]);
    } else row.push(p);
    used += p.length;
  }
  return rows.map((r) => r.join(" "));
}

/** `lhs &= rows[0] \\ &\quad rows[1] …` for an aligned block; with `left` (a column too narrow
 * for the left side's width on every row: lecture mode at 1024 px) every row starts at the left
 * edge, the left side on a row of its own: `&lhs = \\ &\quad rows[0] \\ &\quad rows[1] …`. */
let left = false;
function alignedRows(lhs, parts, lines) {
  const rows = pack(parts, Math.min(lines, parts.length));
  if (left) return [`&${lhs} =`, ...rows.map((r) => `&\\quad ${r}`)];
  return rows.map((r, k) => (k === 0 ? `${lhs} &= ${r}` : `&\\quad ${r}`));
}

/**
 * The line `tex` broken into about `lines` lines (a LaTeX `aligned` block), or null when it has
 * nothing to break at. Exported for the tests.
 */
export function breakLine(tex, lines, fine = false, flush = false) {
  left = flush;
  try {
    return breakAt(tex, lines, fine);
  } finally {
    left = false;
  }
}

function breakAt(tex, lines, fine) {
  const eq = topLevel(tex, "=");
  if (!eq.length) {
    const parts = pieces(tex, fine);
    return parts.length > 1 ? `\\begin{aligned}${pack(parts, lines).join(" \\\\ ")}\\end{aligned}` : null;
  }
  // the longest side is the one to break: the right side, or the left of "… = 0"
  const sides = splitAt(tex, eq, 1).map((s) => s.trim());
  let k = 0;
  sides.forEach((s, j) => { if (s.length > sides[k].length) k = j; });
  if (k === 0) { // "long sum = 0": break the left side, keep "= 0" on the last line
    const parts = pieces(sides[0], fine);
    if (parts.length < 2 && !left) return null;
    const rows = pack(parts, Math.min(lines, parts.length));
    const rest = sides.slice(1).join(" = ");
    const out = rows.map((r, j) => (j === 0 ? `&${r}` : `&\\quad ${r}`));
    if (left) out.push(`&\\quad = ${rest}`); // (flush: the other side on a row of its own)
    else out[out.length - 1] += ` = ${rest}`;
    return `\\begin{aligned}${out.join(" \\\\ ")}\\end{aligned}`;
  }
  const lhs = sides.slice(0, k).join(" = ");
  const rhs = sides[k];
  const after = sides.slice(k + 1);
  const out = [];
  const matrix = matrixOf(rhs);
  const fraction = matrix ? null : fractionOf(rhs);
  if (matrix) { // entry by entry: M_{jk} = …, f_j = …
    const name = lhs.trim();
    const column = matrix.every((row) => row.length === 1);
    matrix.forEach((row, j) => row.forEach((cell, c) => {
      const sub = column ? `${j + 1}` : `${j + 1}${c + 1}`;
      const parts = pieces(cell, fine);
      const each = Math.max(1, Math.ceil(lines / Math.max(1, matrix.length)));
      out.push(...alignedRows(`${name}_{${sub}}`, parts, each));
    }));
  } else if (fraction && fraction[0].length > 2 * fraction[1].length / 3) {
    const [num, den] = fraction;
    out.push(left ? `&${lhs} = \\frac{\\text{num}}{\\text{den}}` : `${lhs} &= \\frac{\\text{num}}{\\text{den}}`);
    const numParts = pieces(num, fine), denParts = pieces(den, fine);
    const share = Math.max(1, lines - 1);
    out.push(...alignedRows("\\text{num}", numParts, Math.ceil((share * num.length) / (num.length + den.length))));
    // rows in proportion to length: a short denominator stays on one line
    const denRows = Math.max(1, Math.round((share * den.length) / (num.length + den.length)));
    out.push(...alignedRows("\\text{den}", denParts, denRows));
  } else {
    const parts = pieces(rhs, fine);
    if (parts.length < 2 && !left) return null;
    out.push(...alignedRows(lhs, parts, lines)); // (flush: one side a row, the other the next)
  }
  if (after.length) out[out.length - 1] += ` = ${after.join(" = ")}`;
  return `\\begin{aligned}${out.join(" \\\\ ")}\\end{aligned}`;
}

const overflows = (box) => box.scrollWidth > box.clientWidth + 1;

async function show(box, tex) {
  box.textContent = `\\[${tex}\\]`;
  await typeset([box]);
}

/** The typeset equation each box was last fitted with (a box typeset again is fitted again). */
const fitted = new WeakMap();

/** Fit one `.math` box (its original LaTeX in data-latex) to its current width. */
async function fitOne(box) {
  const node = box.querySelector("mjx-container");
  if (!box.clientWidth || !node) return; // not typeset yet: measured when it is
  const mode = inLecture() ? "lecture" : "page";
  if (box.dataset.fitWidth === String(box.clientWidth) && box.dataset.fitMode === mode && fitted.get(box) === node) return;
  const original = box.dataset.latex;
  box.classList.remove("scrolls", "scaled");
  box.removeAttribute("tabindex");
  box.style.removeProperty("--fit-scale");
  const width = box.clientWidth;
  if (original && box.dataset.broken) { // wider again: try the line as the engine wrote it
    await show(box, original);
    delete box.dataset.broken;
  }
  // a little too wide is only scaled; much too wide is broken into lines first. In lecture mode
  // nothing is scaled below the room's 24 px (49 of 202 lecture screens showed 19.7 px): any
  // equation too wide is broken, into as many lines as it takes (issue 26, item 2)
  const lecture = inLecture();
  if (original && overflows(box) && (lecture || width / box.scrollWidth < 0.85)) {
    const need = Math.ceil(box.scrollWidth / width);
    const tries = [[need, false], [need + 1, false], [need + 1, true], [need + 2, true], [need + 4, true]];
    if (lecture) tries.push([need + 6, true], [need + 9, true], [need + 14, true], [need + 14, true, true]);
    let tried = null;
    for (const [lines, fine, flush] of tries) {
      const broken = breakLine(original, lines, fine, flush);
      if (!broken || broken === tried) continue;
      tried = broken;
      await show(box, broken);
      box.dataset.broken = String(lines);
      if (!overflows(box)) break;
    }
  }
  scaleOrScroll(box);
  box.dataset.fitWidth = String(box.clientWidth);
  box.dataset.fitMode = mode;
  fitted.set(box, box.querySelector("mjx-container"));
}

/** Lecture mode: its 24 px type is the least the back of a hall reads (lecture.js sets it). */
const inLecture = () => document.documentElement.classList.contains("lecture");

/** Shrink an equation a little to fit (never in lecture mode), else mark its box as scrolling
 * (with the cue). */
function scaleOrScroll(box) {
  const svg = box.querySelector("mjx-container > svg");
  if (!overflows(box)) return;
  if (inLecture()) { // never below the room's size: it scrolls in its own box instead
    box.classList.add("scrolls");
    box.tabIndex = 0;
    return;
  }
  // a few pixels of slack: a centred equation's edge lands on fractional pixels
  const scale = (box.clientWidth - 4) / box.scrollWidth;
  for (const s of [scale, scale * 0.97]) {
    if (!svg || s < MIN_SCALE) break;
    box.style.setProperty("--fit-scale", s.toFixed(3));
    box.classList.add("scaled");
    if (!overflows(box)) return;
  }
  box.style.removeProperty("--fit-scale");
  box.classList.remove("scaled");
  box.classList.add("scrolls");
  box.tabIndex = 0; // a box that scrolls is reached by the keyboard too (arrow keys scroll it)
}

let queue = Promise.resolve();

/**
 * Fit every visible display equation under `root` (`.math` boxes are broken, others only get the
 * scroll cue). Calls are queued: MathJax typesets one batch at a time.
 */
export function fitEquations(root = document) {
  queue = queue.then(async () => {
    if (!window.MathJax?.startup) return;
    for (const box of root.querySelectorAll(".math")) {
      if (box.offsetParent === null) continue; // hidden (a lecture step not yet revealed)
      try { await fitOne(box); } catch { box.classList.add("scrolls"); }
    }
    markScrolling(root);
  });
  return queue;
}

/** The scroll cue on any other display equation wider than its box (answers, equilibria). */
export function markScrolling(root = document) {
  for (const m of root.querySelectorAll('mjx-container[display="true"]')) {
    if (m.closest(".math")) continue;
    m.classList.toggle("scrolls", overflows(m));
  }
}

/**
 * Keep the equations under `list` fitted: after each typeset (derivation.js/scene.js set
 * `data-typeset`), and when the list's width changes (a resize, lecture mode on or off).
 */
export function watchEquations(list) {
  let width = 0, timer = 0;
  const later = () => { clearTimeout(timer); timer = setTimeout(() => fitEquations(list), 120); };
  new ResizeObserver(() => {
    if (list.clientWidth !== width) { width = list.clientWidth; later(); }
  }).observe(list);
  new MutationObserver(() => { if (list.dataset.typeset === "1") later(); })
    .observe(list, { attributes: true, attributeFilter: ["data-typeset"] });
  return later;
}
