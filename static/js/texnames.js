// Names as the derivation writes them: a coordinate `theta1` is \theta_{1}, its acceleration
// \ddot{\theta}_{1}; inline math for MathJax is \(...\). Shared by the Your-turn boxes and the
// equilibria panel, so no page shows `theta1` or `theta_ddot` as code.

const GREEK = new Set(["alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "iota", "kappa",
  "lambda", "mu", "nu", "xi", "pi", "rho", "sigma", "tau", "upsilon", "phi", "chi", "psi", "omega",
  "Gamma", "Delta", "Theta", "Lambda", "Xi", "Pi", "Sigma", "Phi", "Psi", "Omega"]);

function parts(name) {
  const m = /^([A-Za-z]+?)_?(\d*)$/.exec(name);
  if (!m) return [`\\mathrm{${name.replace(/_/g, "\\_")}}`, ""];
  return [GREEK.has(m[1]) ? `\\${m[1]}` : m[1], m[2] ? `_{${m[2]}}` : ""];
}

/** theta1 -> \theta_{1}, x -> x, x_cart -> \mathrm{x\_cart}. */
export function nameTex(name) {
  const [base, sub] = parts(name);
  return base + sub;
}

/** A time derivative of a coordinate: order 1 -> \dot{\theta}_{1}, 2 -> \ddot{\theta}_{1}. */
export function dottedTex(name, order) {
  const [base, sub] = parts(name);
  return `\\${order === 2 ? "ddot" : "dot"}{${base}}${sub}`;
}

/** Inline math MathJax renders: \(tex\). */
export const inline = (tex) => `\\(${tex}\\)`;

/** The engine's `$x$` inline math in a sentence, as MathJax's `\(x\)`. */
export const inlineMath = (text) => text.replace(/\$([^$]+)\$/g, "\\($1\\)");
