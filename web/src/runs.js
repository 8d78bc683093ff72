// The Run tab: start simulate, render, batch or bands on the server (a queue: one runs,
// the others wait), follow each run's progress by Server-Sent Events, cancel.
import { del, getJSON, q, reportError, sendJSON, status } from "./api.js";

const $ = (id) => document.getElementById(id);
const FINAL = new Set(["done", "finished", "succeeded", "failed", "cancelled", "canceled", "error"]);

export class Runs {
  constructor() {
    this.runs = new Map();
    this.streams = new Map();
    $("btn-run").onclick = () => this.start().catch(reportError);
    $("run-command").onchange = () => this.defaults();
  }

  sceneOpened(path) {
    $("run-scene").value = path;
    this.defaults();
  }

  defaults() {
    const scene = $("run-scene").value;
    const base = scene.split("/").pop().replace(/\.json$/, "");
    const dir = scene.includes("/") ? scene.slice(0, scene.lastIndexOf("/") + 1) : "";
    $("run-out").value = `${dir}out-${base}-${$("run-command").value}`;
  }

  async start() {
    const options = {};
    const photons = $("run-photons").value;
    const seed = $("run-seed").value;
    const command = $("run-command").value;
    if (photons) options.photons = Number(photons);
    if (seed) options.seed = Number(seed);
    if (command === "simulate" && $("run-save-map").checked) options.save_photon_map = true;
    if (command === "render") options.photon_map = $("run-photon-map").value;
    if (command === "bands") options.count = Number($("run-count").value);
    const body = { command, scene: $("run-scene").value, out: $("run-out").value, options };
    const { id } = await sendJSON("POST", "/api/runs", body);
    this.runs.set(String(id), { id, ...body, state: "queued" });
    status(`run ${id} queued`);
    this.follow(String(id));
    this.renderTable();
  }

  async refresh() {
    const list = await getJSON("/api/runs");
    for (const r of Array.isArray(list) ? list : list.runs || []) {
      const id = String(r.id);
      this.runs.set(id, { ...this.runs.get(id), ...r });
      if (!FINAL.has(r.state) && !this.streams.has(id)) this.follow(id);
    }
    this.renderTable();
  }

  follow(id) {
    const source = new EventSource(`/api/runs/${q(id)}/events`);
    this.streams.set(id, source);
    const handle = (e) => {
      let data;
      try {
        data = JSON.parse(e.data);
      } catch (_) {
        data = { message: e.data };
      }
      const run = this.runs.get(id) || { id };
      const before = run.message;
      Object.assign(run, data); // the job's JSON: state, progress 0..1, message, error
      if (run.message && run.message !== before) this.log(`[${id}] ${run.message}`);
      if (run.error) this.log(`[${id}] error: ${run.error}`);
      this.runs.set(id, run);
      if (FINAL.has(run.state) || e.type === "end") this.finished(id, run);
      this.renderTable();
    };
    source.onmessage = handle;
    for (const type of ["progress", "state", "log", "end", "done"]) source.addEventListener(type, handle);
    source.onerror = () => {
      // the server closes the stream when the run ends: ask it for the final state
      source.close();
      this.streams.delete(id);
      getJSON(`/api/runs`).then((list) => {
        const r = (Array.isArray(list) ? list : list.runs || []).find((x) => String(x.id) === id);
        if (r) {
          const run = { ...this.runs.get(id), ...r };
          this.runs.set(id, run);
          if (FINAL.has(run.state)) this.finished(id, run);
          else setTimeout(() => this.follow(id), 500);
        }
        this.renderTable();
      }).catch(reportError);
    };
  }

  finished(id, run) {
    this.streams.get(id)?.close();
    this.streams.delete(id);
    if (run.announced) return;
    run.announced = true;
    const ok = ["done", "finished", "succeeded"].includes(run.state);
    status(`run ${id} ${run.state}${run.error ? `: ${run.error}` : ""}`, !ok);
    if (ok) document.dispatchEvent(new CustomEvent("run-finished", { detail: run }));
  }

  log(line) {
    const pre = $("run-log");
    pre.textContent += `${line}\n`;
    pre.scrollTop = pre.scrollHeight;
  }

  renderTable() {
    const tbody = $("runs").querySelector("tbody");
    tbody.replaceChildren();
    for (const r of [...this.runs.values()].reverse()) {
      const tr = tbody.insertRow();
      tr.id = `run-${r.id}`;
      tr.dataset.state = r.state;
      for (const v of [r.id, r.command, r.scene, r.out, r.state]) tr.insertCell().textContent = v ?? "";
      const cell = tr.insertCell();
      if (typeof r.progress === "number" && !FINAL.has(r.state)) {
        const bar = document.createElement("progress");
        bar.max = 1;
        bar.value = r.progress;
        cell.append(bar, ` ${Math.round(100 * r.progress)} % ${r.message || ""}`);
      } else if (r.state === "failed") {
        cell.textContent = r.error || "";
      } else if (typeof r.seconds === "number") {
        cell.textContent = `${r.seconds.toFixed(1)} s`;
      }
      const act = tr.insertCell();
      if (!FINAL.has(r.state)) {
        const b = document.createElement("button");
        b.textContent = "Cancel";
        b.onclick = () => del(`/api/runs/${q(r.id)}`).then(() => this.refresh()).catch(reportError);
        act.appendChild(b);
      } else if (r.out && ["done", "finished", "succeeded"].includes(r.state)) {
        const b = document.createElement("button");
        b.textContent = "Results";
        b.onclick = () => document.dispatchEvent(new CustomEvent("show-results", { detail: r.out }));
        act.appendChild(b);
      }
    }
  }
}
