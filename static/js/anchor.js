// A link to a place on a scene page (#h-derivation, the skip link) lands there and stays there
// while the page is still filling in above it: the plots, the work panel and the typeset math
// arrive after the browser has scrolled to the anchor and push it down (seen on the rolling
// disk: the derivation's heading ended up a screen below the top). Until the reader scrolls,
// presses a key or touches the page, the anchor is brought back to the top after each change,
// for the first KEEP_MS.

const KEEP_MS = 8000;

/** Keep `location.hash`'s element at the top while the page fills in (see above). */
export function keepAnchor() {
  const target = location.hash.length > 1 ? document.getElementById(decodeURIComponent(location.hash.slice(1))) : null;
  if (!target || !("ResizeObserver" in window)) return;
  let on = true;
  const stop = () => {
    if (!on) return;
    on = false;
    observer.disconnect();
    for (const type of MOVES) window.removeEventListener(type, stop, true);
  };
  const MOVES = ["keydown", "wheel", "touchstart", "pointerdown"];
  for (const type of MOVES) window.addEventListener(type, stop, { passive: true, capture: true });
  let queued = false;
  const align = () => {
    if (!on || queued) return;
    queued = true;
    requestAnimationFrame(() => {
      queued = false;
      if (!on) return;
      // scrollIntoView honours the page's scroll-padding-top (the sticky header)
      const pad = parseFloat(getComputedStyle(document.documentElement).scrollPaddingTop) || 0;
      if (Math.abs(target.getBoundingClientRect().top - pad) > 2) target.scrollIntoView({ block: "start" });
    });
  };
  // everything above the anchor is in <main>: any change of its size may have moved it
  const observer = new ResizeObserver(align);
  observer.observe(document.querySelector("main") || document.body);
  setTimeout(stop, KEEP_MS);
}
