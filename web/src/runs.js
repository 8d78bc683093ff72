// The Run tab: start simulate, render, batch or bands on the server (a queue: one runs,
// the others wait), follow the running run's progress by Server-Sent Events and the
// others' by polling, cancel.
import { del, getJSON, getText, q, reportError, sendJSON, status } from "./api.js";

const $ = (id) => document.getElementById(id);
const FINAL = new Set(["done", "finished", "succeeded", "failed", "cancelled", "canceled", "error"]);

const POLL_MS = 1000; // the states of the runs not streamed, while any is unfinished
// the form's fields each command takes (others are disabled and not sent)
const FIELDS = {
  simulate: ["run-photons", "run-seed", "run-integrator", "run-save-map"],
  render: ["run-integrator", "run-photon-map"],
  batch: [],
  bands: ["run-seed", "run-count"],
};

// A browser holds at most 6 connections to a host, and an event stream holds one for as
// long as its run lasts: the page streams only the running run (the server runs one at a
// time) and asks GET /api/runs for the others' states, so that requests are never left
// waiting for a connection however many runs are queued.
export class Runs {
  constructor() {
    this.runs = new Map();
    this.stream = null; // {id, source}: the running run's event stream
    this.pollTimer = null;
    this.integrator = null; // the run scene's integrator (null: not known)
    $("btn-run").onclick = () => this.start().catch(reportError);
    $("run-command").onchange = () => {
      this.defaults();
      this.updateForm();
    };
    $("run-scene").onchange = () => this.checkScene().catch(() => {});
    $("run-integrator").onchange = () => this.updateForm();
    this.updateForm();
  }

  sceneOpened(path) {
    $("run-scene").value = path;
    this.defaults();
    this.checkScene().catch(() => {});
  }

  defaults() {
    const scene = $("run-scene").value;
    const base = scene.split("/").pop().replace(/\.json$/, "");
    const dir = scene.includes("/") ? scene.slice(0, scene.lastIndexOf("/") + 1) : "";
    $("run-out").value = `${dir}out-${base}-${$("run-command").value}`;
  }

  // the integrator the scene to run names (render.integrator; path when it names none),
  // as the server decides it: a photon map is saved, or needed, only where one is made
  async checkScene() {
    const path = $("run-scene").value.trim();
    if (!path.endsWith(".json")) {
      this.integrator = null; // a sequence's or none yet: the server decides
      this.updateForm();
      return;
    }
    let integrator = null;
    try {
      const doc = JSON.parse(await getText(`/api/file?path=${q(path)}`));
      const named = doc?.render?.integrator;
      integrator = named === undefined ? "path" : typeof named === "string" ? named : null;
    } finally {
      if ($("run-scene").value === path) {
        this.integrator = integrator;
        this.updateForm();
      }
    }
  }

  updateForm() {
    const takes = FIELDS[$("run-command").value] || [];
    for (const id of new Set(Object.values(FIELDS).flat())) $(id).disabled = !takes.includes(id);
    // the path integrator fires no photons: no map to save (the server refuses it); what
    // the box said comes back with a scene that makes one
    const box = $("run-save-map");
    // the integrator chosen here, else the scene's
    const integrator = (!$("run-integrator").disabled && $("run-integrator").value) || this.integrator;
    const noPhotons = integrator === "path";
    if (noPhotons && box.dataset.wanted === undefined) {
      box.dataset.wanted = String(box.checked);
      box.checked = false;
    } else if (!noPhotons && box.dataset.wanted !== undefined) {
      box.checked = box.dataset.wanted === "true";
      delete box.dataset.wanted;
    }
    box.disabled ||= noPhotons;
    box.title = noPhotons ? "the integrator, path, fires no photons: no map to save" : "";
  }

  async start() {
    const command = $("run-command").value;
    // a run reads the file on the server: edits of it not saved would be ignored unseen
    const scenePath = $("run-scene").value.trim();
    if (this.unsaved?.(scenePath)) {
      throw new Error(`${scenePath} has changes in the Scene tab that are not saved: save them ` +
        "first (a run reads the saved file), or open the file again to drop them");
    }
    if (command === "simulate" || command === "render") await this.checkScene().catch(() => {});
    const takes = (id) => !$(id).disabled; // what updateForm left enabled for the command
    const options = {};
    const photons = $("run-photons").value;
    const seed = $("run-seed").value;
    if (takes("run-photons") && photons) options.photons = Number(photons);
    if (takes("run-seed") && seed) options.seed = Number(seed);
    if (takes("run-integrator") && $("run-integrator").value) options.integrator = $("run-integrator").value;
    if (takes("run-save-map") && $("run-save-map").checked) options.save_photon_map = true;
    const map = $("run-photon-map").value.trim();
    if (takes("run-photon-map") && map) options.photon_map = map; // none: the path integrator
    if (takes("run-count")) options.count = Number($("run-count").value);
    const body = { command, scene: $("run-scene").value, out: $("run-out").value, options };
    const { id } = await sendJSON("POST", "/api/runs", body);
    this.runs.set(String(id), { id, ...body, state: "queued" });
    status(`run ${id} queued`);
    this.renderTable();
    this.watch();
  }

  async refresh() {
    const list = await getJSON("/api/runs");
    for (const r of Array.isArray(list) ? list : list.runs || []) this.update(String(r.id), r);
    this.renderTable();
    this.watch();
  }

  // a run's new state, from the stream or a poll: logged, and announced once finished
  update(id, data) {
    const known = this.runs.get(id);
    const run = known || { id };
    const before = run.message;
    const wasOpen = known !== undefined && !FINAL.has(known.state); // else finished before this page
    Object.assign(run, data); // the job's JSON: state, progress 0..1, message, error
    // (a warning shown as the message is logged from the warnings below, once)
    if (run.message && run.message !== before && !run.message.startsWith("warning: ")) this.log(`[${id}] ${run.message}`);
    if (run.error && !run.errorLogged) {
      run.errorLogged = true;
      this.log(`[${id}] error: ${run.error}`);
    }
    // every warning once (the message shows each only until the next progress report)
    const warnings = run.warnings || [];
    for (let i = run.warningsLogged || 0; i < warnings.length; i++) this.log(`[${id}] warning: ${warnings[i]}`);
    run.warningsLogged = warnings.length;
    this.runs.set(id, run);
    if (FINAL.has(run.state) && wasOpen) this.finished(id, run);
  }

  // one stream, the running run's; a poll while any run is unfinished
  watch() {
    const open = [...this.runs.values()].filter((r) => !FINAL.has(r.state));
    const running = open.filter((r) => r.state === "running").map((r) => String(r.id)).pop();
    if (this.stream && this.stream.id !== running) this.closeStream();
    if (running && !this.stream && !this.runs.get(running).streamFailed) this.follow(running);
    clearTimeout(this.pollTimer);
    this.pollTimer = open.length ? setTimeout(() => this.poll(), POLL_MS) : null;
  }

  poll() {
    this.refresh().catch((e) => {
      reportError(e);
      clearTimeout(this.pollTimer);
      this.pollTimer = setTimeout(() => this.poll(), 5 * POLL_MS);
    });
  }

  closeStream() {
    this.stream?.source.close();
    this.stream = null;
  }

  follow(id) {
    const source = new EventSource(`/api/runs/${q(id)}/events`);
    this.stream = { id, source };
    const handle = (e) => {
      if (this.stream?.source !== source) return;
      let data = {};
      try {
        data = JSON.parse(e.data);
      } catch (_) {
        /* a comment or an empty end */
      }
      if (e.type !== "end") this.update(id, data);
      if (e.type === "end" || FINAL.has(this.runs.get(id)?.state)) {
        this.closeStream();
        this.refresh().catch(reportError); // the final state, and the next run to stream
      } else {
        this.renderTable();
      }
    };
    source.addEventListener("progress", handle);
    source.addEventListener("end", handle);
    source.onerror = () => {
      // not the stream's normal end (handled above): polling follows this run instead
      if (this.stream?.source !== source) return;
      this.closeStream();
      const run = this.runs.get(id);
      if (run) run.streamFailed = true;
      this.watch();
    };
  }

  finished(id, run) {
    if (run.announced) return;
    run.announced = true;
    const ok = ["done", "finished", "succeeded"].includes(run.state);
    // a cancelled run is what was asked for, not an error (it was shown in the error's red)
    status(`run ${id} ${run.state}${run.error ? `: ${run.error}` : ""}`, !ok && !run.state.startsWith("cancel"));
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
