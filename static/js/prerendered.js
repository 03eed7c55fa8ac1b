// Math typeset ahead of time: a built-in scene's derivation, rendered by this same MathJax with
// this same configuration when the package was built (`python -m app.prerender`), is put on the
// page as it is instead of being typeset again on every visit (issue 13: the double pendulum's
// steps held the main thread for 0.4–0.9 s). Looked up by the exact TeX, display mode and font
// size (MathJax's smallest script size is in pixels: a subscript's subscript is drawn a little
// differently at 16 px and at lecture mode's 24 px), so a derivation whose text changed since
// simply misses and is typeset live: a stale file can cost time, never show other math. Tests
// check that the files cover every built-in derivation (tests/test_prerendered_files.py) and
// equal what MathJax renders now (tests/browser/test_prerendered_math.py).
//
// The ready-made equations have no MathJax menu behind them (no speech, no explorer): the first
// time one is focused or right-clicked it is typeset live, in place, and gets the menu.

/** Display (\[…\]) and inline (\(…\)) math in a text node, as MathJax's TeX input finds it. */
const DELIMITED = /\\\[([\s\S]*?)\\\]|\\\(([\s\S]*?)\\\)/g;
/** Where no math is looked for: as MathJax skips them (its ignore class), plus form fields. */
const SKIP = ".mathjax_ignore, textarea, input, script, style, mjx-container";

let table = null; // key ("D" or "I", the font size in px, "|", the TeX) → the container's HTML
let adopting = null;

/**
 * Use a prerendered-math file (fetched once; the page names it in a <link rel="preload">). A
 * missing or malformed file leaves every equation to be typeset live. `live(elements)` is the
 * ordinary typesetting, used to give an equation MathJax's menu when a reader asks for it.
 * Resolves true once the table is in place (the derivation costs only its insertion), false when
 * the math will be typeset live.
 */
export async function usePrerendered(url, live) {
  try {
    const response = await fetch(url, { credentials: "same-origin" });
    if (!response.ok) return false;
    const data = await response.json();
    if (!data || typeof data.math !== "object" || !Array.isArray(data.html)
      || typeof data.defs !== "string" || typeof data.css !== "string") return false;
    const defs = new DOMParser().parseFromString(data.defs, "image/svg+xml").documentElement;
    if (defs.nodeName !== "svg") return false;
    defs.id = "MJX-SVG-prerendered-cache"; // the glyphs the <use> elements point at
    defs.setAttribute("aria-hidden", "true");
    document.body.prepend(document.importNode(defs, true));
    // MathJax's own rules for its output (the assistive MathML kept out of sight, display math
    // centred), which it would add itself on its first typeset
    document.head.append(Object.assign(document.createElement("style"), { id: "MJX-prerendered-styles", textContent: data.css }));
    table = new Map(Object.entries(data.math).map(([key, i]) => [key, data.html[i]]));
    adopting = live;
    for (const type of ["focusin", "contextmenu"]) document.addEventListener(type, adopt, true);
    return true;
  } catch {
    table = null; // typeset live, as without the file
    return false;
  }
}

/**
 * Put ready-made math in place of the TeX in `elements` where the table has every formula of a
 * text node (a node is never half replaced). Returns the elements that still hold TeX for
 * MathJax. Only math in the derivation's steps is looked up: the rest of the page (equilibria,
 * answers, warnings) depends on the values asked for and is always typeset live.
 */
export function applyPrerendered(elements) {
  if (!table) return elements;
  const left = [];
  const found = []; // [root, text node, its font size]: all read before anything is written, as
  // each change of the page would make the next font size cost a new style pass of it all
  for (const root of elements) {
    if (!root.closest?.("#steps")) { left.push(root); continue; }
    const walker = document.createTreeWalker(root, NodeFilter.SHOW_TEXT, {
      acceptNode: (n) => (n.parentElement?.closest(SKIP) ? NodeFilter.FILTER_REJECT : NodeFilter.FILTER_ACCEPT),
    });
    for (let n = walker.nextNode(); n; n = walker.nextNode()) {
      if (n.nodeValue.includes("\\[") || n.nodeValue.includes("\\(")) found.push([root, n]);
    }
  }
  for (const item of found) item.push(+parseFloat(getComputedStyle(item[1].parentElement).fontSize).toFixed(2));
  const missed = new Set();
  for (const [root, node, px] of found) if (!replace(node, px)) missed.add(root);
  return [...left, ...elements.filter((root) => missed.has(root))];
}

/** One text node's math, all of it from the table, or nothing (false). */
function replace(node, px) {
  const text = node.nodeValue;
  const parts = [];
  let at = 0;
  for (const m of text.matchAll(DELIMITED)) {
    const display = m[1] !== undefined;
    const tex = display ? m[1] : m[2];
    const html = table.get(`${display ? "D" : "I"}${px}|${tex}`);
    if (typeof html !== "string") return false;
    parts.push(text.slice(at, m.index), container(html, tex, display));
    at = m.index + m[0].length;
  }
  if (!parts.length) return true; // a lone "\(" in words: nothing MathJax would typeset either
  parts.push(text.slice(at));
  node.replaceWith(...parts.filter((p) => p !== ""));
  return true;
}

function container(html, tex, display) {
  const tpl = document.createElement("template");
  tpl.innerHTML = html;
  const node = tpl.content.firstElementChild;
  node.dataset.tex = tex; // what the equation says (MathJax keeps it in its items; tests read it)
  node.dataset.display = display ? "true" : "false";
  node.dataset.prerendered = "";
  return node;
}

/** A ready-made equation focused or right-clicked: typeset it live (hidden until done, beside
 * the ready-made one, so nothing moves), then hand the focus or the menu to the live one. */
async function adopt(event) {
  const old = event.target?.closest?.("mjx-container[data-prerendered]");
  if (!old || old.dataset.adopting) return;
  old.dataset.adopting = "1";
  const { clientX, clientY } = event;
  if (event.type === "contextmenu") event.preventDefault();
  const display = old.dataset.display === "true";
  const holder = document.createElement(display ? "div" : "span");
  holder.className = "mathjax-adopt";
  holder.style.cssText = "position:absolute;visibility:hidden;";
  holder.textContent = display ? `\\[${old.dataset.tex}\\]` : `\\(${old.dataset.tex}\\)`;
  old.after(holder);
  try {
    await adopting([holder]);
  } catch {
    holder.remove();
    delete old.dataset.adopting;
    return;
  }
  const fresh = holder.querySelector("mjx-container");
  if (!fresh) { holder.remove(); delete old.dataset.adopting; return; }
  const focused = document.activeElement === old;
  old.replaceWith(fresh);
  holder.remove();
  if (event.type === "focusin" || focused) fresh.focus();
  if (event.type === "contextmenu") {
    fresh.dispatchEvent(new MouseEvent("contextmenu", { bubbles: true, cancelable: true, clientX, clientY }));
  }
}
