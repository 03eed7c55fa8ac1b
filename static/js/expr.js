// The spec's plain-text expressions ("R*sin(theta)", "a*r**2") evaluated in the browser, so the
// drawing can sweep a body's position over a coordinate's range (the wire a bead rides on) at
// any parameters. A small recursive-descent parser for the same grammar mechanics/expr.py accepts
// (numbers, names, + - * / **, parentheses, its whitelist of functions and pi): never eval.

const FUNCTIONS = {
  sin: Math.sin, cos: Math.cos, tan: Math.tan,
  cot: (x) => 1 / Math.tan(x), sec: (x) => 1 / Math.cos(x), csc: (x) => 1 / Math.sin(x),
  asin: Math.asin, acos: Math.acos, atan: Math.atan, atan2: Math.atan2,
  sinh: Math.sinh, cosh: Math.cosh, tanh: Math.tanh,
  exp: Math.exp, log: Math.log, sqrt: Math.sqrt, abs: Math.abs, sign: Math.sign,
};
const PERIODIC = new Set(["sin", "cos", "tan", "cot", "sec", "csc"]);
const TOKEN = /\s*(?:(\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?)|([A-Za-z_][A-Za-z0-9_]*)|(\*\*|[-+*/(),]))/y;

function tokenize(text) {
  const out = [];
  TOKEN.lastIndex = 0;
  const s = String(text).trimEnd();
  while (TOKEN.lastIndex < s.length) {
    const m = TOKEN.exec(s);
    if (!m) return null;
    out.push(m[1] !== undefined ? { num: Number(m[1]) } : m[2] !== undefined ? { name: m[2] } : { op: m[3] });
  }
  return out;
}

/**
 * Compile an expression (a string or a number) to `env => number`, or null when it is outside
 * the grammar. The function carries `names` (every free name) and `periodic` (names that only
 * ever appear inside sin, cos, tan, ...: an angle whose full turn closes the curve).
 */
export function compile(text) {
  if (typeof text === "number") return Object.assign(() => text, { names: new Set(), periodic: new Set() });
  const toks = tokenize(text);
  if (!toks || !toks.length) return null;
  let k = 0;
  const names = new Set(), bare = new Set(), inTrig = new Set();
  let trigDepth = 0;
  const peek = () => toks[k];
  const isOp = (op) => toks[k] && toks[k].op === op;
  const expect = (op) => { if (!isOp(op)) throw new Error(op); k++; };

  function sum() {
    let f = product();
    while (isOp("+") || isOp("-")) {
      const op = toks[k++].op, a = f, b = product();
      f = op === "+" ? (e) => a(e) + b(e) : (e) => a(e) - b(e);
    }
    return f;
  }
  function product() {
    let f = unary();
    while (isOp("*") || isOp("/")) {
      const op = toks[k++].op, a = f, b = unary();
      f = op === "*" ? (e) => a(e) * b(e) : (e) => a(e) / b(e);
    }
    return f;
  }
  function unary() { // Python: -x**2 is -(x**2)
    if (isOp("-")) { k++; const a = unary(); return (e) => -a(e); }
    if (isOp("+")) { k++; return unary(); }
    return power();
  }
  function power() {
    const a = atom();
    if (!isOp("**")) return a;
    k++;
    const b = unary();
    return (e) => a(e) ** b(e);
  }
  function atom() {
    const t = peek();
    if (!t) throw new Error("end");
    k++;
    if (t.num !== undefined) return () => t.num;
    if (t.op === "(") { const a = sum(); expect(")"); return a; }
    if (t.name === undefined) throw new Error(t.op);
    if (isOp("(")) {
      const fn = FUNCTIONS[t.name];
      if (!fn) throw new Error(t.name);
      k++;
      if (PERIODIC.has(t.name)) trigDepth++;
      const args = [sum()];
      while (isOp(",")) { k++; args.push(sum()); }
      expect(")");
      if (PERIODIC.has(t.name)) trigDepth--;
      return args.length === 1 ? (e) => fn(args[0](e)) : (e) => fn(...args.map((a) => a(e)));
    }
    if (t.name === "pi") return () => Math.PI;
    names.add(t.name);
    (trigDepth ? inTrig : bare).add(t.name);
    const name = t.name;
    return (e) => (name in e ? e[name] : NaN);
  }

  try {
    const f = sum();
    if (k !== toks.length) return null;
    const periodic = new Set([...inTrig].filter((n) => !bare.has(n)));
    return Object.assign(f, { names, periodic });
  } catch {
    return null;
  }
}
