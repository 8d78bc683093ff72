// A `thzmap bands` output directory in Results: the chosen channels, the best set of each
// size with its score (bands.json, docs/analysis.md "Outputs") and the run's own figures.
import { q } from "./api.js";
import { formatNumber } from "./colour.js";

const $ = (id) => document.getElementById(id);
const FIGURES = ["bands-score.png", "bands-spectra.png", "bands-air.png"];

function cell(row, text, className) {
  const td = row.insertCell();
  td.textContent = text;
  if (className) td.className = className;
  return td;
}

const centres = (thz) => thz.map((v) => formatNumber(v)).join(", ");
const widths = (w) => w.map((v) => `${formatNumber(100 * v)} %`).join(", ");

// dir: the output directory (relative to the root), doc: its bands.json, names: the files
// in it (the figures shown are those present: bands-air.png only where the air attenuates)
export function showBands(dir, doc, names) {
  const pane = $("bands-pane");
  const chosen = doc.selected_thz || [];
  $("bands-summary").textContent =
    `${doc.scene_name ?? dir}, sensor ${doc.sensor}: chosen ${centres(chosen)} THz ` +
    `(relative width ${widths(doc.selected_relative_width || [])}); worst-pair JM ` +
    `${formatNumber(doc.score)} of 2 (${(doc.worst_pair || []).join(" vs ")}), mean JM ` +
    `${formatNumber(doc.mean_jm)}; ${doc.sets_scored} sets scored (${doc.search}), ` +
    `${doc.renders} renders at ${doc.paths_per_sample} paths a sample, ${Number(doc.seconds).toFixed(1)} s`;
  $("bands-warnings").replaceChildren(...(doc.warnings || []).map((w) => {
    const li = document.createElement("li");
    li.textContent = w;
    return li;
  }));
  const table = $("bands-table");
  table.replaceChildren();
  const head = table.createTHead().insertRow();
  for (const h of ["K", "centres (THz)", "relative widths", "worst-pair JM", "worst pair", "mean JM"]) {
    head.appendChild(document.createElement("th")).textContent = h;
  }
  const body = table.createTBody();
  for (const k of doc.per_k || []) {
    const row = body.insertRow();
    cell(row, String(k.k));
    cell(row, centres(k.selected_thz), "thz");
    cell(row, widths(k.selected_relative_width));
    cell(row, formatNumber(k.score), "score");
    cell(row, (k.worst_pair || []).join(" vs "));
    cell(row, formatNumber(k.mean_jm));
  }
  $("bands-figures").replaceChildren(...FIGURES.filter((f) => names.includes(f)).map((f) => {
    const img = document.createElement("img");
    img.alt = f;
    img.src = `/api/file?path=${q(dir ? `${dir}/${f}` : f)}`;
    return img;
  }));
  pane.hidden = false;
  // the image's controls and the pixel column would show the run opened before
  $("view-results").classList.add("bands");
}
