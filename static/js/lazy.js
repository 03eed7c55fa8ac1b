// Plotly on demand: the plots sit below the animation, so their library (a partial bundle with
// the scatter traces the pages draw, static/vendor/plotly-basic/, MIT) is fetched once the
// motion is on screen instead of holding up the page. A page whose template still loads a plotly
// bundle itself is waited for instead of loading a second copy.

import { busy } from "./api.js";

const BUNDLE = new URL("../vendor/plotly-basic/plotly.min.js", import.meta.url).href;
let loading = null;

export function loadPlotly() {
  if (window.Plotly) return Promise.resolve(window.Plotly);
  if (loading) return loading;
  const done = busy("Loading the plots…");
  loading = new Promise((resolve, reject) => {
    const existing = [...document.scripts].find((s) => /plotly[^/]*\.js(\?|$)/.test(s.src));
    const script = existing || Object.assign(document.createElement("script"), { src: BUNDLE, async: true });
    const loaded = () => (window.Plotly ? resolve(window.Plotly) : reject(new Error("plotly did not load")));
    script.addEventListener("load", loaded, { once: true });
    script.addEventListener("error", () => { loading = null; reject(new Error("plotly did not load")); }, { once: true });
    if (existing) window.addEventListener("load", loaded, { once: true }); // it may have run already
    else document.head.append(script);
  });
  loading.then(done, done);
  return loading;
}
