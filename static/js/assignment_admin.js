// The instructor's assignment page: deploy a template's variants, preview them with their keys
// (and why a variant was not deployed), and the class report drawn as plots (plus its CSV).

import { typeset } from "./api.js";
import { api, askToken, el, forgetToken, say } from "./assignment_common.js";
import { loadPlotly } from "./lazy.js";

const BASE = "/api/v1/assignments";
const CONFIG = { displaylogo: false, responsive: true, modeBarButtonsToRemove: ["sendDataToCloud"] };

async function loadTemplates() {
  const { templates } = await api(`${BASE}/templates`);
  const select = document.getElementById("template");
  select.replaceChildren(...templates.map((t) => el("option", `${t.id} — ${t.title}`, { value: t.id })));
  document.getElementById("deploy-panel").hidden = false;
  document.getElementById("open-panel").hidden = false;
}

function showPreview(data) {
  const box = document.getElementById("preview");
  const table = el("table", "", { class: "assignment-preview" });
  table.append(el("caption", `${data.assignment_id}: ${data.variants.length} variants of ${data.template_id}`));
  const head = el("tr");
  for (const h of ["seed", "numbers", "deployed", "keys"]) head.append(el("th", h, { scope: "col" }));
  table.append(head);
  for (const v of data.variants) {
    const row = el("tr");
    const numbers = Object.entries({ ...v.parameters, ...v.switches }).map(([k, x]) => `${k} = ${x}`).join(", ");
    row.append(el("td", v.seed), el("td", numbers), el("td", v.deployable ? "yes" : `no: ${v.why_not}`));
    const keys = el("td");
    for (const k of v.keys) keys.append(el("div", `${k.part}: \\(${k.latex}\\)${k.verified ? "" : ` (${k.verification})`}`));
    row.append(keys);
    table.append(row);
  }
  box.replaceChildren(table);
  typeset([table]);
}

async function showReport(id) {
  const data = await api(`${BASE}/${encodeURIComponent(id)}/report`);
  const box = document.getElementById("report");
  box.replaceChildren(el("h3", `Class report: ${data.students} students`));
  await loadPlotly();
  for (const part of data.parts) {
    const section = el("section", "", { class: "assignment-report-part" });
    section.append(el("h4", `Part ${part.part} (mean ${part.mean === null ? "–" : part.mean.toFixed(2)})`));
    // the plots' numbers are also the list below them (a screen reader reads that list)
    const hist = el("div", "", { id: `hist-${part.part}`, class: "assignment-plot" });
    const codes = el("div", "", { id: `codes-${part.part}`, class: "assignment-plot" });
    const list = el("ul", "", { class: "assignment-codes" });
    list.append(el("li", `scores: ${part.histogram.map((n, i) => `${n} in ${(i / 10).toFixed(1)}–${((i + 1) / 10).toFixed(1)}`).filter((t) => !t.startsWith("0 ")).join(", ") || "none yet"}`));
    for (const c of part.codes) list.append(el("li", `${c.code}: ${c.submissions} submissions, ${Math.round(100 * c.share)} % of students`));
    section.append(hist, codes, list);
    box.append(section);
    if (window.Plotly) {
      const bins = part.histogram.map((_, i) => `${(i / 10).toFixed(1)}–${((i + 1) / 10).toFixed(1)}`);
      window.Plotly.newPlot(hist, [{ type: "bar", x: bins, y: part.histogram }],
        { title: { text: "scores" }, margin: { t: 40, b: 60 }, height: 260, xaxis: { title: { text: "score" } }, yaxis: { title: { text: "students" } } }, CONFIG);
      window.Plotly.newPlot(codes, [{ type: "bar", orientation: "h", x: part.codes.map((c) => 100 * c.share), y: part.codes.map((c) => c.code) }],
        { title: { text: "outcome codes" }, margin: { t: 40, l: 200 }, height: 80 + 28 * Math.max(1, part.codes.length), xaxis: { title: { text: "% of students" } } }, CONFIG);
    }
  }
  const csv = await api(`${BASE}/${encodeURIComponent(id)}/report?format=csv`, { raw: true });
  const link = document.getElementById("csv");
  link.href = URL.createObjectURL(await csv.blob());
  link.download = `${id}-report.csv`;
  link.hidden = false;
}

function wire() {
  document.getElementById("deploy-form").addEventListener("submit", async (event) => {
    event.preventDefault();
    const id = document.getElementById("assignment-id").value.trim();
    const seeds = document.getElementById("seeds").value.split(",").map((s) => s.trim()).filter(Boolean);
    say("Deploying: every key is verified first (about a second a variant)…");
    try {
      const data = await api(`${BASE}/templates/${encodeURIComponent(document.getElementById("template").value)}/deploy`, {
        method: "POST", body: { assignment_id: id, count: Number(document.getElementById("count").value), seeds },
      });
      document.getElementById("open-id").value = id;
      showPreview(data);
      say(`Deployed ${id}. Students open /assignments/${id} with their token.`);
    } catch (error) {
      say(error.message, true);
    }
  });
  document.getElementById("open-form").addEventListener("submit", async (event) => {
    event.preventDefault();
    try {
      showPreview(await api(`${BASE}/${encodeURIComponent(document.getElementById("open-id").value.trim())}/preview`));
      say("");
    } catch (error) {
      say(error.message, true);
    }
  });
  document.getElementById("report-button").addEventListener("click", async () => {
    try {
      await showReport(document.getElementById("open-id").value.trim());
      say("");
    } catch (error) {
      say(error.message, true);
    }
  });
}

async function main() {
  await askToken();
  wire();
  try {
    await loadTemplates();
  } catch (error) {
    if (error.status === 401 || error.status === 403) forgetToken();
    say(error.message, true);
  }
}

main();
