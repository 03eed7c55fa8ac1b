// q(t), phase portraits and energies with plotly (served by the app, no CDN).

const LAYOUT = {
  margin: { l: 55, r: 15, t: 36, b: 42 },
  legend: { orientation: "h", y: -0.25 },
  font: { size: 12 },
};

function ready() {
  return typeof window.Plotly !== "undefined";
}

export function plotRun(result, compare, labels) {
  if (!ready()) return;
  const names = Object.keys(result.q);
  const t = result.t;
  window.Plotly.react("plot-q", names.map((n) => ({ x: t, y: result.q[n], name: n, mode: "lines" })),
    { ...LAYOUT, title: { text: "q(t)" }, xaxis: { title: "t (s)" } }, { responsive: true, displaylogo: false });
  window.Plotly.react("plot-phase",
    names.map((n) => ({ x: result.q[n], y: result.q_dot[n], name: `${n}, ${n}_dot`, mode: "lines" })),
    { ...LAYOUT, title: { text: "phase portrait" }, xaxis: { title: "q" }, yaxis: { title: "q̇" } },
    { responsive: true, displaylogo: false });
  const e = result.energy;
  const traces = [
    { x: t, y: e.T, name: "T", mode: "lines" },
    { x: t, y: e.V, name: "V", mode: "lines" },
    { x: t, y: e.E, name: "E = T + V", mode: "lines" },
  ];
  if (e.W_nc.some((w) => Math.abs(w) > 1e-12)) {
    traces.push({ x: t, y: e.W_nc, name: "W_NC", mode: "lines", line: { dash: "dot" } });
  }
  let title = "energy";
  if (compare) {
    const err = (r) => {
      const maxT = Math.max(...r.energy.T.map(Math.abs), 1e-300);
      return r.energy.E.map((v, i) => (v - r.energy.E[0] - r.energy.W_nc[i]) / maxT);
    };
    traces.length = 0;
    traces.push({ x: t, y: err(result), name: labels[0], mode: "lines" });
    traces.push({ x: compare.t, y: err(compare), name: labels[1], mode: "lines" });
    title = "energy error (E − E₀ − W_NC) / max T";
  }
  window.Plotly.react("plot-energy", traces,
    { ...LAYOUT, title: { text: title }, xaxis: { title: "t (s)" } }, { responsive: true, displaylogo: false });
}
