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

const GREEK_CHARS = {
  alpha: "α", beta: "β", gamma: "γ", delta: "δ", epsilon: "ε", zeta: "ζ", eta: "η", theta: "θ",
  iota: "ι", kappa: "κ", lambda: "λ", mu: "μ", nu: "ν", xi: "ξ", pi: "π", rho: "ρ", sigma: "σ",
  tau: "τ", upsilon: "υ", phi: "φ", chi: "χ", psi: "ψ", omega: "ω", Gamma: "Γ", Delta: "Δ",
  Theta: "Θ", Lambda: "Λ", Xi: "Ξ", Pi: "Π", Sigma: "Σ", Phi: "Φ", Psi: "Ψ", Omega: "Ω",
};
const SUBSCRIPTS = "₀₁₂₃₄₅₆₇₈₉";

/**
 * A name as plain text where nothing typesets it (a slider's label, a select's options, a line's
 * caption): theta1 -> θ₁, theta1_dot -> θ̇₁, x_ddot -> ẍ, Omega -> Ω. A name that is not one
 * letter (or a Greek one) with digits stays as it is (x_cart, x_cart_dot): it is what the editor
 * and the answers use, and no symbol would say more.
 */
export function nameText(name) {
  const m = /^([A-Za-z]+?)_?(\d*)(_dot|_ddot)?$/.exec(name);
  if (!m) return name;
  const [, stem, digits, dots] = m;
  const base = GREEK_CHARS[stem] || (stem.length === 1 ? stem : null);
  if (!base) return name;
  const mark = dots === "_ddot" ? "\u0308" : dots === "_dot" ? "\u0307" : "";
  return base + mark + [...digits].map((d) => SUBSCRIPTS[Number(d)]).join("");
}

/** Every coordinate (and its _dot, _ddot) in an engine's label as `nameText` writes it, and a
 * derivative of L by one as ∂L/∂q: "dL/dtheta1_dot" -> "∂L/∂θ̇₁", "EoM theta" -> "EoM θ",
 * "Q_theta" -> "Q_θ". */
export function labelText(label, coordinates = []) {
  const names = [...coordinates].sort((a, b) => b.length - a.length).map((q) => q.replace(/\W/g, ""));
  if (!names.length) return label;
  const token = new RegExp(`(^|[^A-Za-z0-9_]|\\bQ_)(dL/d)?(${names.join("|")})(_ddot|_dot)?(?![A-Za-z0-9_])`, "g");
  return label.replace(token, (_, before, partial, q, dots) =>
    `${before}${partial ? "∂L/∂" : ""}${nameText(q + (dots || ""))}`);
}
