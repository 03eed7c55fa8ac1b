// Where a field path of the API's errors (`bodies[0].position[1]`, `parameters.m`) sits in the
// JSON text the user typed: an index from every path to the character range of its key and value.

/** Map each path in the JSON text to {start, end} (its key, if any, through its value). Parses as far
 * as it can: a broken document still gives the paths before the break. */
export function indexJSON(text) {
  const spans = new Map();
  let i = 0;
  const ws = () => { while (i < text.length && /\s/.test(text[i])) i++; };
  const fail = () => { throw new SyntaxError(`unexpected character at ${i}`); };
  const expect = (c) => { ws(); if (text[i] !== c) fail(); i++; };
  const string = () => {
    if (text[i] !== '"') fail();
    let j = i + 1;
    while (j < text.length && text[j] !== '"') j += text[j] === "\\" ? 2 : 1;
    const raw = text.slice(i, j + 1);
    i = j + 1;
    return JSON.parse(raw);
  };
  const value = (path, keyStart) => {
    ws();
    const start = i;
    const c = text[i];
    if (c === "{") {
      i++; ws();
      if (text[i] === "}") i++;
      else for (;;) {
        ws();
        const ks = i;
        const key = string();
        expect(":");
        value(path ? `${path}.${key}` : key, ks);
        ws();
        if (text[i] === ",") { i++; continue; }
        expect("}");
        break;
      }
    } else if (c === "[") {
      i++; ws();
      if (text[i] === "]") i++;
      else for (let n = 0; ; n++) {
        value(`${path}[${n}]`, null);
        ws();
        if (text[i] === ",") { i++; continue; }
        expect("]");
        break;
      }
    } else if (c === '"') {
      string();
    } else {
      while (i < text.length && /[^,\]}\s]/.test(text[i])) i++;
      if (i === start) fail();
    }
    spans.set(path, { start: keyStart ?? start, end: i });
  };
  try { value("", null); } catch { /* keep what was indexed */ }
  return spans;
}

/** The range for `field`, or for its nearest parent that exists (a missing key: its object). */
export function locate(text, field) {
  const spans = indexJSON(text);
  let path = field || "";
  for (;;) {
    if (spans.has(path)) return { ...spans.get(path), exact: path === field };
    const cut = Math.max(path.lastIndexOf("."), path.lastIndexOf("["));
    if (cut <= 0) return spans.get("") ? { ...spans.get(""), exact: false } : null;
    path = path.slice(0, cut);
  }
}

/** 1-based line number of a character offset. */
export function lineOf(text, offset) {
  let line = 1;
  for (let k = 0; k < offset && k < text.length; k++) if (text[k] === "\n") line++;
  return line;
}
