// The pre-processor: files, the scene's objects and sensors, their properties, the 3D
// view, material and atmosphere plots; every edit validated by /api/validate.
import { getJSON, getText, putText, q, reportError, sendJSON, status } from "./api.js";
import { field, normalisePath, parsePath, showFieldErrors } from "./fields.js";
import { linePlot } from "./plots.js";
import { SceneView, materialColour } from "./view3d.js";
import { cssColour } from "./colour.js";

const $ = (id) => document.getElementById(id);
const SHAPES = ["box", "cylinder", "sphere", "rectangle", "disk", "mesh"];
const SHAPE_KEYS = {
  box: ["size_m", "inward"], cylinder: ["radius_m", "height_m", "caps", "segments"],
  sphere: ["radius_m", "subdivisions"], rectangle: ["size_m"], disk: ["radius_m", "segments"],
  mesh: ["file"],
};
const UNIT = (key) => (key.endsWith("_m") ? "m" : key.endsWith("_deg") ? "°" : key.endsWith("_k") ? "K" : "");

export class SceneEditor {
  constructor() {
    this.doc = null;
    this.path = "";
    this.selection = { kind: "object", index: 0 };
    this.errors = [];
    this.library = [];
    this.view = new SceneView($("view3d"), (i) => this.select("object", i));
    $("colour-by").onchange = (e) => this.setOption("colourBy", e.target.value);
    $("show-normals").onchange = (e) => this.setOption("normals", e.target.checked);
    $("cut-enclosure").onchange = (e) => this.setOption("cut", e.target.checked);
    $("show-preview").onchange = (e) => this.setOption("preview", e.target.checked);
    $("btn-save").onclick = () => this.save().catch(reportError);
    $("scene-text").addEventListener("input", () => this.textEdited());
    getJSON("/api/materials").then((m) => {
      const list = Array.isArray(m) ? m : m.materials || [];
      this.library = list.map((x) => (typeof x === "string" ? x : x.name));
    }).catch(() => {});
  }

  setOption(key, value) {
    this.view.options[key] = value;
    this.view.update(this.info, this.doc);
  }

  async listFiles(dir) {
    const listing = await getJSON(`/api/files?dir=${q(dir)}`);
    this.dir = listing.dir ?? dir;
    $("files-dir").textContent = `/${this.dir}`;
    const ul = $("files");
    ul.replaceChildren();
    const add = (label, onclick, title) => {
      const li = document.createElement("li");
      li.textContent = label;
      li.title = title || label;
      li.onclick = onclick;
      ul.appendChild(li);
    };
    if (this.dir) add("..", () => this.listFiles(this.dir.split("/").slice(0, -1).join("/")).catch(reportError));
    const join = (name) => (this.dir ? `${this.dir}/${name}` : name);
    for (const e of listing.entries || []) {
      if (e.type === "dir" || e.type === "directory") {
        add(`${e.name}/`, () => this.listFiles(join(e.name)).catch(reportError));
      } else if (e.name.endsWith(".json")) {
        add(e.name, () => this.open(join(e.name)).catch(reportError), `open ${join(e.name)}`);
      }
    }
  }

  // edits not yet saved: a run reads the file on the server, not this text
  get dirty() {
    return this.savedText !== undefined && $("scene-text").value !== this.savedText;
  }

  markDirty() {
    const dirty = this.dirty;
    $("scene-path").classList.toggle("unsaved", dirty);
    $("scene-path").title = dirty ? "unsaved changes: a run reads the saved file" : "";
  }

  async open(path) {
    const text = await getText(`/api/file?path=${q(path)}`);
    this.path = path;
    this.savedText = text;
    $("scene-path").value = path;
    this.view.framed = false;
    // nothing of the file open before may show under this one's name: a file that does not
    // parse showed the previous scene's objects, sensors, 3D view and plots
    this.doc = {};
    this.info = null;
    this.view.update(this.info, this.doc);
    this.renderPlots();
    this.setText(text);
    status(`opened ${path}`);
    document.dispatchEvent(new CustomEvent("scene-opened", { detail: path }));
  }

  setText(text) {
    $("scene-text").value = text;
    this.markDirty();
    try {
      this.doc = JSON.parse(text);
      this.setBroken(false);
    } catch (_) {
      this.setBroken(true); // the fields would edit the file open before
      /* the validator reports where */
    }
    this.selection = { kind: "object", index: 0 };
    try {
      this.renderLists();
      this.renderProps();
    } finally {
      this.validateNow(text); // whatever the panels made of it, the validator says what is wrong
    }
  }

  async save() {
    const path = $("scene-path").value.trim();
    if (!path) throw new Error("no path to save to");
    const text = $("scene-text").value;
    await putText(`/api/file?path=${q(path)}`, text);
    const moved = path !== this.path;
    this.path = path;
    this.savedText = text;
    this.markDirty();
    status(`saved ${path}`);
    this.listFiles(this.dir || "").catch(() => {});
    // saved as another file: that is the scene a run now takes
    if (moved) document.dispatchEvent(new CustomEvent("scene-opened", { detail: path }));
  }

  // While the text does not parse, the fields (which edit the last document that did)
  // are out of use: an edit there rewrote the text from that document, and the edits
  // made in the text since were lost.
  setBroken(broken) {
    this.broken = broken;
    $("props").inert = broken;
    $("props").classList.toggle("stale", broken);
    $("props").title = broken ? "the JSON text does not parse: fix it there first" : "";
  }

  textEdited() {
    const text = $("scene-text").value;
    try {
      this.doc = JSON.parse(text);
      this.setBroken(false);
      this.renderLists();
      this.renderProps();
    } catch (_) {
      this.setBroken(true); /* the validator names the line and column */
    }
    this.markDirty();
    this.scheduleValidate(text);
  }

  // a field changed the document: rewrite the text, validate
  edited(path) {
    if (this.broken) return; // the fields are inert then (setBroken)
    const keys = parsePath(path);
    // a library material chosen that the scene does not define yet: define it as
    // {"library": NAME}, else the scene names a material it does not have
    const mat = keys[0] === "objects" && keys[2] === "material" ? this.doc.objects?.[keys[1]]?.material : undefined;
    if (typeof mat === "string" && this.library.includes(mat) && !Object.hasOwn(this.doc.materials || {}, mat)) {
      if (this.doc.materials == null || typeof this.doc.materials !== "object") this.doc.materials = {};
      this.doc.materials[mat] = { library: mat };
    }
    const text = `${JSON.stringify(this.doc, null, 2)}\n`;
    $("scene-text").value = text;
    this.markDirty();
    if (keys[0] === "objects" && (keys[2] === "name" || keys[2] === "shape")) this.renderLists();
    // the fields of an object depend on its type (a shell's thickness) and its shape's
    if (keys[0] === "objects" && (keys[2] === "type" || (keys[2] === "shape" && keys[3] === "type"))) {
      this.renderProps();
    }
    if (keys[0] === "objects" && keys[2] === "material") this.renderPlots();
    this.scheduleValidate(text);
  }

  scheduleValidate(text) {
    clearTimeout(this.timer);
    this.timer = setTimeout(() => this.validateNow(text), 200);
  }

  // One validation in flight at a time: edits made meanwhile are validated, as one text,
  // when it returns. A request without an answer in 10 s is asked again (twice at most).
  async validateNow(text) {
    if (this.inflight) {
      this.pendingText = text;
      return;
    }
    this.inflight = true;
    $("validation").textContent = "validating…";
    let result = null, failure = null;
    for (let attempt = 0; attempt < 3 && !result; attempt++) {
      try {
        result = await sendJSON("POST", "/api/validate", { path: this.path, text }, AbortSignal.timeout(10000));
      } catch (e) {
        failure = e;
        if (e.name !== "TimeoutError" || attempt === 2) reportError(e);
        if (e.name !== "TimeoutError") break;
      }
    }
    if (!result) $("validation").textContent = `not validated: ${failure?.message || failure}`;
    this.inflight = false;
    if (this.pendingText !== undefined) {
      const next = this.pendingText;
      this.pendingText = undefined;
      this.validateNow(next);
      return; // a later edit's answer is what counts
    }
    if (!result) return;
    this.errors = (result.errors || []).map((e) => ({
      ...e,
      json_path: e.json_path || (String(e.message).match(/(?:^|: )([a-z_]+(?:\[\d+\])?(?:\.[a-z_]+(?:\[\d+\])?)*): /) || [])[1] || "",
    }));
    this.warnings = result.warnings || [];
    if (result.scene) {
      this.info = result.scene;
      this.view.update(this.info, this.doc);
      this.view.highlight(this.selection.kind === "object" ? this.selection.index : -1);
      this.renderPlots();
    }
    this.showValidation(result.ok);
  }

  showValidation(ok) {
    const box = $("validation");
    box.replaceChildren();
    const head = document.createElement("div");
    head.className = ok ? "ok" : "bad";
    head.id = "validation-state";
    head.textContent = ok ? "✓ scene is valid" : `✗ ${this.errors.length} error(s)`;
    box.appendChild(head);
    const ul = document.createElement("ul");
    for (const e of this.errors) {
      const li = document.createElement("li");
      li.className = "bad";
      const where = e.line ? ` (line ${e.line}:${e.column})` : "";
      li.textContent = `${e.json_path ? `${e.json_path}: ` : ""}${e.message}${where}`;
      li.onclick = () => this.goTo(e.json_path);
      ul.appendChild(li);
    }
    for (const w of this.warnings) {
      const li = document.createElement("li");
      li.className = "warn";
      li.textContent = typeof w === "string" ? w : w.message;
      ul.appendChild(li);
    }
    box.appendChild(ul);
    showFieldErrors($("props"), this.errors);
    for (const li of document.querySelectorAll("#objects li, #sensors li")) {
      const p = li.dataset.path;
      li.classList.toggle("invalid", this.errors.some((e) => {
        const ep = normalisePath(e.json_path);
        return ep === p || ep.startsWith(`${p}.`);
      }));
    }
  }

  goTo(path) {
    const keys = parsePath(path || "");
    if ((keys[0] === "objects" || keys[0] === "sensors") && typeof keys[1] === "number") {
      this.select(keys[0] === "objects" ? "object" : "sensor", keys[1]);
    }
  }

  select(kind, index) {
    this.selection = { kind, index };
    this.renderLists();
    this.renderProps();
    if (kind === "sensor") this.view.selectedSensor = index;
    this.view.update(this.info, this.doc);
    this.view.highlight(kind === "object" ? index : -1);
    this.renderPlots();
  }

  renderLists() {
    const fill = (ul, items, kind, prefix) => {
      ul.replaceChildren();
      // a list as the file has it, however wrong: the validator names what is wrong
      (Array.isArray(items) ? items : []).forEach((entry, i) => {
        const item = entry !== null && typeof entry === "object" ? entry : {};
        const li = document.createElement("li");
        li.dataset.path = `${prefix}[${i}]`;
        if (kind === "object") {
          const sw = document.createElement("span");
          sw.className = "swatch";
          sw.style.background = cssColour(materialColour(this.doc, item.material).map((c) => c * 255));
          li.appendChild(sw);
        }
        li.append(typeof item.name === "string" && item.name ? item.name : `${kind} ${i}`);
        li.classList.toggle("selected", this.selection.kind === kind && this.selection.index === i);
        li.onclick = () => this.select(kind, i);
        ul.appendChild(li);
      });
    };
    fill($("objects"), this.doc?.objects, "object", "objects");
    fill($("sensors"), this.doc?.sensors, "sensor", "sensors");
  }

  renderProps() {
    const box = $("props");
    box.replaceChildren();
    if (!this.doc) return;
    const { kind, index } = this.selection;
    const onChange = (path) => this.edited(path);
    const add = (spec) => box.appendChild(field(this.doc, spec, onChange));
    const entry = (list) => (Array.isArray(list) && list[index] !== null && typeof list[index] === "object"
      ? list[index] : null);
    if (kind === "object" && entry(this.doc.objects)) {
      const o = entry(this.doc.objects);
      const p = `objects[${index}]`;
      $("props-title").textContent = `Object ${o.name ?? index}`;
      add({ label: "name", path: `${p}.name`, kind: "text" });
      add({ label: "type", path: `${p}.type`, options: ["solid", "shell"] });
      add({ label: "material", path: `${p}.material`,
        options: [...Object.keys(this.doc.materials || {}), ...this.library] });
      add({ label: "temperature", path: `${p}.temperature_k`, kind: "number", unit: "K" });
      if (o.type === "shell" || o.thickness_m !== undefined) {
        add({ label: "thickness", path: `${p}.thickness_m`, kind: "number", unit: "m" });
      }
      add({ label: "shape", path: `${p}.shape.type`, options: SHAPES });
      const st = o.shape?.type;
      const keys = new Set([...(SHAPE_KEYS[st] || []), ...Object.keys(o.shape || {})]);
      keys.delete("type");
      for (const k of keys) {
        const kindOfKey = typeof o.shape?.[k] === "boolean" || ["inward", "caps"].includes(k) ? "boolean"
          : k === "file" ? "text" : "vector";
        // "radius (m)", not "radius_m (m)": the unit once, as the other fields give it
        add({ label: `  ${UNIT(k) ? k.replace(/_(m|deg|k)$/, "") : k}`, path: `${p}.shape.${k}`, kind: kindOfKey, unit: UNIT(k) });
      }
      add({ label: "translate", path: `${p}.transform.translate_m`, kind: "vector", unit: "m", placeholder: "0, 0, 0" });
      add({ label: "rotate", path: `${p}.transform.rotate_deg`, kind: "vector", unit: "°", placeholder: "0, 0, 0" });
      add({ label: "scale", path: `${p}.transform.scale`, kind: "vector", placeholder: "1" });
    } else if (kind === "sensor" && entry(this.doc.sensors)) {
      const s = entry(this.doc.sensors);
      const p = `sensors[${index}]`;
      $("props-title").textContent = `Sensor ${s.name ?? index}`;
      add({ label: "name", path: `${p}.name`, kind: "text" });
      add({ label: "position", path: `${p}.position_m`, kind: "vector", unit: "m" });
      if (s.direction !== undefined) add({ label: "direction", path: `${p}.direction`, kind: "vector" });
      else add({ label: "look at", path: `${p}.look_at_m`, kind: "vector", unit: "m" });
      add({ label: "up", path: `${p}.up`, kind: "vector", placeholder: "0, 0, 1" });
      add({ label: "horizontal fov", path: `${p}.fov_deg`, kind: "number", unit: "°" });
      add({ label: "resolution", path: `${p}.resolution`, kind: "vector", unit: "columns, rows" });
      add({ label: "aperture", path: `${p}.aperture_m2`, kind: "number", unit: "m²" });
    }
    showFieldErrors(box, this.errors);
  }

  renderPlots() {
    const box = $("material-plots");
    box.replaceChildren();
    const o = this.doc?.objects?.[this.selection.index];
    const mats = this.info?.materials;
    const name = this.selection.kind === "object" ? o?.material : null;
    const m = Array.isArray(mats) ? mats.find((x) => x.name === name) : mats?.[name];
    const sp = m?.spectra || m;
    if (sp?.freq_thz) {
      const title = document.createElement("div");
      title.textContent = `material ${name}${m.index_model ? ` (index model ${m.index_model})` : ""}`;
      box.appendChild(title);
      const f = sp.freq_thz;
      const series = [];
      if (sp.R) series.push({ label: "R", x: f, y: sp.R });
      if (sp.emissivity) series.push({ label: "ε", x: f, y: sp.emissivity });
      if (series.length) linePlot(box, series, { xLabel: "frequency (THz)", yLabel: "R, ε (1)", yMin: 0, yMax: 1 });
      const alpha = sp.alpha_per_m || sp.alpha;
      // α acts inside shells alone: a solid is opaque, and its α (0 when the material gives
      // none) would read as "transparent" (physics.md "Surfaces")
      const validated = this.info?.objects?.[this.selection.index]; // as the spectra: the last valid state
      if (alpha && (validated?.type ?? o?.type) === "solid") {
        const note = document.createElement("p");
        note.className = "note opaque";
        note.textContent = `α: none through ${o.name ?? "this object"}, a solid: opaque (nothing passes ` +
          "through it; a material's α acts inside shells)";
        box.appendChild(note);
      } else if (alpha) {
        linePlot(box, [{ label: "α", x: f, y: alpha }], { xLabel: "frequency (THz)", yLabel: "α (1/m)", yMin: 0 });
      }
      const nk = [];
      if (sp.n) nk.push({ label: "n", x: f, y: sp.n });
      if (sp.k) nk.push({ label: "k", x: f, y: sp.k });
      if (nk.length) linePlot(box, nk, { xLabel: "frequency (THz)", yLabel: "n, k (1)" });
    } else {
      box.textContent = name ? `no spectra for ${name} (the scene must be valid)` : "select an object";
    }
    const atm = $("atmosphere-plot");
    atm.replaceChildren();
    const a = this.info?.atmosphere;
    const x = (this.info?.channels || []).map((c) => c.centre_thz ?? c.frequency_thz);
    const series = (a?.sensors || []).map((s) => ({
      label: `${s.name} (${s.distance_m?.toFixed?.(2) ?? "?"} m)`, x, y: s.transmittance,
    })).filter((s) => Array.isArray(s.y) && s.y.length === x.length);
    if (series.length) {
      const title = document.createElement("div");
      // what the air emits at and the background (by default the enclosure's)
      const air = a.model === "none" ? ""
        : a.emission_temperature_k == null ? " (not emitting)"
          : ` (emitting at ${a.emission_temperature_k.toFixed(2)} K, background ${a.background_temperature_k.toFixed(2)} K)`;
      title.textContent = `model ${a.model}${air}: over each sensor's distance to what it looks at`;
      atm.appendChild(title);
      linePlot(atm, series, { xLabel: "channel centre (THz)", yLabel: "transmittance (1)", yMin: 0, yMax: 1 });
    } else {
      atm.textContent = a ? `model ${a.model}` : "no transmittance (the scene must be valid)";
    }
  }
}
