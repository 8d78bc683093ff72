// The post-processor: per-channel images with a colour bar in kelvin, truth maps, measured
// cubes; a clicked pixel's spectrum with error bars and truth; A/B differences in units of
// the combined standard error; batch frames played one after the other, on one colour scale.
import { getBytes, getJSON, q, reportError, request, status } from "./api.js";
import { forget, loadCube, range } from "./envi.js";
import { cssColour, diverging, formatNumber, planckDerivative, viridis } from "./colour.js";
import { drawMarker, fit, paint } from "./images.js";
import { linePlot } from "./plots.js";
import { PhotonView } from "./photons.js";
import { showBands } from "./bands.js";

const $ = (id) => document.getElementById(id);
const QUANTITIES = ["brightness_temperature", "measured_brightness_temperature", "temperature",
  "distance", "object_id", "radiance", "radiance_stderr", "normalized", "power", "measured_radiance"];
const TRUTH = new Set(["temperature", "distance", "object_id"]); // one band, not per channel
const join = (dir, name) => (dir ? `${dir}/${name}` : name);

export class Results {
  constructor() {
    this.dir = "";
    this.frames = [];
    for (const id of ["res-quantity", "res-channel", "res-scale"]) {
      $(id).onchange = () => this.redraw().catch(reportError);
    }
    $("res-sensor").onchange = () => this.loadSensor().catch(reportError);
    // the A/B difference shown follows the sensor and channel chosen (it stayed at the
    // channel of its Compare while the list said another)
    for (const id of ["res-sensor", "res-channel"]) {
      $(id).addEventListener("change", () => {
        if ($("res-view").value === "diff" && this.diffZ) this.diff().catch(reportError);
      });
    }
    $("res-view").onchange = () => this.setView($("res-view").value);
    $("image").addEventListener("click", (e) => this.click(e, $("image")).catch(reportError));
    $("diff-image").addEventListener("click", (e) => this.clickDiff(e));
    $("btn-diff").onclick = () => this.diff().catch(reportError);
    for (const id of ["diff-a", "diff-b"]) $(id).addEventListener("input", () => (this.diffTyped = true));
    $("frame").oninput = () => this.openFrame(Number($("frame").value)).catch(reportError);
    $("btn-play").onclick = () => this.play();
    $("frames-lock").onchange = () => this.redraw().catch(reportError);
    // the images drawn again at the window's new size (they kept the old one: cut off at
    // the pane's edge, or small in a window made larger); the tabs send one when shown
    window.addEventListener("resize", () => {
      cancelAnimationFrame(this.refit);
      this.refit = requestAnimationFrame(() => ["image", "diff-image"].forEach((id) => fit($(id))));
    });
    $("btn-photons").onclick = () => this.loadPhotons().catch(reportError);
  }

  setView(view) {
    $("bands-pane").hidden = true; // shown by open() alone, for a bands run's directory
    $("view-results").classList.remove("bands", "empty"); // (open() sets either)
    $("image-pane").hidden = view !== "image";
    $("photon-pane").hidden = view !== "photons";
    $("diff-pane").hidden = view !== "diff";
    // the image's controls where they act: quantity and scale for the image alone, sensor
    // and channel for the difference too, none for the photons (they have their own)
    for (const [id, shown] of [["res-quantity", view === "image"], ["res-scale", view === "image"],
      ["res-sensor", view !== "photons"], ["res-channel", view !== "photons"]]) {
      $(id).closest("label").hidden = !shown;
    }
    if (view === "photons") this.photons?.resize();
    else fit($(view === "diff" ? "diff-image" : "image")); // the window may have changed meanwhile
  }

  async browse(dir) {
    const listing = await getJSON(`/api/files?dir=${q(dir)}`);
    $("outputs-dir").textContent = `/${dir}`;
    const ul = $("outputs");
    ul.replaceChildren();
    const add = (label, fn) => {
      const li = document.createElement("li");
      li.textContent = label;
      li.onclick = () => fn().catch(reportError);
      ul.appendChild(li);
    };
    if (dir) add("..", () => this.browse(dir.split("/").slice(0, -1).join("/")));
    const entries = listing.entries || [];
    for (const e of entries) {
      if (e.type === "dir" || e.type === "directory") add(`${e.name}/`, () => this.open(join(dir, e.name)));
    }
    return entries;
  }

  // an output directory: of one run, or of a batch (frame-NNNNN/, sweep-NN/frame-NNNNN/)
  // what is in it comes from /api/outputs: its sensors and their cubes, summary.json, the
  // photon map, a batch's frames (sweeps' included)
  async open(dir) {
    const seq = (this.openSeq = (this.openSeq || 0) + 1);
    // its cubes are read again: a run from another tab or a shell may have rewritten them
    // since (the cache is by path alone)
    forget(`${dir.replace(/\/+$/, "")}/`);
    if (this.playing) this.play(); // a batch's frames played: stopped (Play toggles)
    const [entries, outputs] = await Promise.all([this.browse(dir), getJSON(`/api/outputs?dir=${q(dir)}`)]);
    if (seq !== this.openSeq) return; // another directory was asked for meanwhile
    this.setView($("res-view").value); // a bands run's pane, shown before, hidden
    summaryNote(outputs);
    this.frames = outputs.frames.map((f) => join(dir, f));
    this.frameRanges = new Map(); // the colour scales over all frames, worked out once each
    $("frames").hidden = this.frames.length === 0;
    if (this.frames.length) {
      $("frame").max = this.frames.length - 1;
      $("frame").value = 0;
      return this.openFrame(0);
    }
    if (imageSensors(outputs).length) return this.openRun(dir, outputs);
    const names = entries.filter((e) => e.type === "file").map((e) => e.name);
    if (names.includes("bands.json")) {
      const doc = await getJSON(`/api/file?path=${q(join(dir, "bands.json"))}`);
      if (seq !== this.openSeq) return;
      this.hideImages();
      showBands(dir, doc, names);
      status(`${dir}: a bands run, ${doc.count} channel${doc.count === 1 ? "" : "s"} chosen`);
      return;
    }
    // nothing of this directory to show: nor the run opened before (its image stayed,
    // under a status line that said there was none), nor its controls
    this.hideImages();
    $("view-results").classList.add("empty");
    status(`${dir}: no images or bands.json here`);
  }

  // A directory without images opened: the image, photon and difference panes hidden, and
  // no pixel: the run opened next starts with an empty column (it showed the pixel clicked
  // before this directory, of a run that may be long gone from mind)
  hideImages() {
    for (const pane of ["image-pane", "photon-pane", "diff-pane"]) $(pane).hidden = true;
    this.clearPixel();
  }

  cubesOf(sensor) {
    return this.outputs?.sensors.find((s) => s.name === sensor)?.cubes || [];
  }

  async openFrame(i) {
    const dir = this.frames[i];
    $("frame-name").textContent = `${dir.split("/").slice(-2).join("/")} (${i + 1}/${this.frames.length})`;
    const outputs = await getJSON(`/api/outputs?dir=${q(dir)}`);
    summaryNote(outputs);
    return this.openRun(dir, outputs);
  }

  play() {
    if (this.playing) {
      clearInterval(this.playing);
      this.playing = null;
      $("btn-play").textContent = "Play";
      return;
    }
    $("btn-play").textContent = "Pause";
    this.playing = setInterval(() => {
      const next = (Number($("frame").value) + 1) % this.frames.length;
      $("frame").value = next;
      this.openFrame(next).catch(reportError);
    }, 600);
  }

  async openRun(dir, outputs) {
    this.runDir = dir;
    this.outputs = outputs;
    const sensors = imageSensors(outputs);
    const keep = $("res-sensor").value;
    $("res-sensor").replaceChildren(...sensors.map((s) => new Option(s, s, false, s === keep)));
    this.summary = outputs.summary;
    this.mapPath = outputs.photon_map;
    // A: the run open, B: the one opened before it (A stayed the first run ever opened),
    // until either is typed into
    if (!this.diffTyped && $("diff-a").value !== dir) {
      $("diff-b").value = $("diff-a").value;
      $("diff-a").value = dir;
    }
    await this.loadSensor();
  }

  async loadSensor() {
    const sensor = $("res-sensor").value;
    const base = join(this.runDir, sensor);
    const present = QUANTITIES.filter((qn) => this.cubesOf(sensor).includes(qn));
    const keep = $("res-quantity").value;
    $("res-quantity").replaceChildren(...present.map((qn) => new Option(qn.replace(/_/g, " "), qn, false, qn === keep)));
    const t0 = performance.now();
    const want = ["brightness_temperature", "radiance_stderr", "temperature", "distance", "object_id"];
    const cubes = await Promise.all(want.map((qn) => (present.includes(qn) ? loadCube(`${base}.${qn}`) : null)));
    if (base !== join(this.runDir, $("res-sensor").value)) return; // another run was opened meanwhile
    [this.tb, this.stderr, this.truthT, this.truthD, this.truthId] = cubes;
    this.base = base;
    const tb = this.tb;
    const keepCh = $("res-channel").value;
    $("res-channel").replaceChildren(...Array.from({ length: tb.bands }, (_, b) =>
      new Option(`${b + 1}: ${tb.channelName(b)}`, b, false, String(b) === keepCh)));
    const phCh = $("ph-channel");
    phCh.replaceChildren(...Array.from({ length: tb.bands }, (_, b) => new Option(tb.channelName(b), b)));
    const names = this.truthId?.header["object names"] || [];
    $("ph-object").replaceChildren(new Option("all", ""), ...names.map((n) => new Option(n, n)));
    status(`${base}: ${tb.cols} × ${tb.rows} pixels, ${tb.bands} channel${tb.bands === 1 ? "" : "s"}, loaded in ${Math.round(performance.now() - t0)} ms`);
    await this.redraw();
  }

  // The image drawn, then the pixel marked on it shown again: its spectrum (measured or
  // not, with the quantity) and the value of the image shown (the line kept the quantity
  // and channel of the click when another was chosen)
  async redraw() {
    if (await this.show()) await this.refreshPixel();
  }

  // The image drawn again (another run, frame, sensor, quantity or channel): the pixel
  // clicked on it shown again from its cubes, or, where the new image has no such pixel,
  // the Pixel column emptied and the mark taken off (the column kept the last run's values
  // under the new image). A pixel of the A/B difference stays: diff() refreshes it.
  async refreshPixel() {
    const mark = $("image").dataset.mark;
    if (!mark) return;
    const [row, col] = mark.split(",").map(Number);
    if (row < this.tb.rows && col < this.tb.cols) return this.showPixel(row, col);
    this.clearPixel();
  }

  // the Pixel column emptied, the marks taken off both images
  clearPixel() {
    this.pixelSeq = (this.pixelSeq || 0) + 1; // a spectrum still being read: not shown
    for (const canvas of [$("image"), $("diff-image")]) {
      canvas.dataset.mark = "";
      drawMarker(canvas);
    }
    const info = $("pixel-info");
    for (const key of ["row", "col", "ms"]) delete info.dataset[key];
    info.textContent = "Click a pixel of the image.";
    $("pixel-plot").replaceChildren();
    $("pixel-table").replaceChildren();
  }

  // The image of the quantity and channel chosen; false when another was asked for meanwhile
  // (a cube read late was drawn over the one chosen after it)
  async show() {
    const seq = (this.showSeq = (this.showSeq || 0) + 1);
    const qn = $("res-quantity").value || "brightness_temperature";
    const cube = await loadCube(`${this.base}.${qn}`);
    if (seq !== this.showSeq) return false;
    this.shown = cube;
    const band = Math.min(Number($("res-channel").value) || 0, cube.bands - 1);
    const values = cube.band(band);
    const ignore = cube.ignore ?? (qn.includes("brightness") ? 0 : null);
    const names = cube.header["object names"];
    if (qn === "object_id" && names) {
      this.showObjects(cube, names);
      return true;
    }
    const common = $("res-scale").value === "common";
    // a batch's frame: the scale over all its frames (each its own made a colour mean
    // another temperature in the next frame)
    const locked = this.frames.length > 1 && this.frames.includes(this.runDir) && $("frames-lock").checked;
    const all = locked ? await this.framesRange(qn, common ? null : band, ignore) : null;
    const over = all?.frames ? all : null; // no frame's values read: this frame's own scale
    if (seq !== this.showSeq) return false; // another image was asked for meanwhile
    const [lo, hi] = over ? over.range : common ? range(cube.data, ignore) : range(values, ignore);
    // the truth maps hold one band whatever the run; a one-channel run's cubes one channel
    // (the caption before the image, which is fitted to the room the caption leaves)
    const which = TRUTH.has(qn) ? "truth" : `channel ${band + 1} (${cube.channelName(band)})`;
    $("image-info").textContent = `${qn.replace(/_/g, " ")}, ${which}; colours span the 1st to 99th ` +
      `percentile${common ? " of all channels" : ""}${over ? ` of all ${over.frames} frames (one scale)` : ""}: ` +
      `${formatNumber(lo)} to ${formatNumber(hi)}${cube.unit === "1" ? "" : ` ${cube.unit}`}`;
    $("colourbar").args = [lo, hi, cube.unit === "1" ? "(1)" : cube.unit];
    paint($("image"), cube, values, lo, hi, viridis, ignore);
    return true;
  }

  // The 1st and 99th percentile of quantity qn (band, or all bands when null) over every
  // frame of the batch open that has it: {range, frames}. Each frame's values are read
  // once through /api/cube/data and sampled (range's 200 000 values over all frames), so
  // that a long batch does not stay in memory; four requests at a time.
  async framesRange(qn, band, ignore) {
    const sensor = $("res-sensor").value;
    const key = `${sensor}|${qn}|${band ?? "all"}`;
    if (!this.frameRanges.has(key)) {
      const frames = this.frames;
      const per = Math.max(1, Math.floor(200000 / frames.length));
      const parts = [];
      let next = 0;
      const worker = async () => {
        while (next < frames.length) {
          const path = `${frames[next++]}/${sensor}.${qn}.hdr`;
          const values = new Float32Array(await getBytes(
            `/api/cube/data?path=${q(path)}${band === null ? "" : `&band=${band}`}`).catch(() => new ArrayBuffer(0)));
          if (!values.length) continue; // a frame without it (not finished, or not written)
          const step = Math.max(1, Math.floor(values.length / per));
          parts.push(Float32Array.from({ length: Math.ceil(values.length / step) }, (_, i) => values[i * step]));
        }
      };
      const pending = Promise.all(Array.from({ length: Math.min(4, frames.length) }, worker))
        .then(() => ({ range: range(parts, ignore), frames: parts.length }));
      this.frameRanges.set(key, pending);
      pending.catch(() => this.frameRanges.delete(key));
    }
    return this.frameRanges.get(key);
  }

  // the truth map of objects: one colour per object, named beside the picture
  showObjects(cube, names) {
    const palette = names.map((_, i) => viridis(names.length > 1 ? i / (names.length - 1) : 0.5));
    const seen = new Set(cube.band(0));
    const info = $("image-info");
    info.replaceChildren("object seen, truth (grey: nothing hit): ");
    names.forEach((n, i) => {
      if (!seen.has(i)) return;
      const sw = document.createElement("span");
      sw.className = "swatch";
      sw.style.background = cssColour(palette[i]);
      info.append(sw, `${n}  `);
    });
    $("colourbar").args = null; // the names' swatches instead
    paint($("image"), cube, cube.band(0), 0, Math.max(names.length - 1, 1), viridis, -1);
  }

  // the pixel under a click, and marked so on the image (the other image's mark dropped:
  // the Pixel column holds one pixel)
  pixelOf(e, canvas, cube) {
    const r = canvas.getBoundingClientRect(); // the border's width left out: the image's box
    const col = Math.floor(((e.clientX - r.left - canvas.clientLeft) / canvas.clientWidth) * cube.cols);
    const row = Math.floor(((e.clientY - r.top - canvas.clientTop) / canvas.clientHeight) * cube.rows);
    const at = [Math.min(Math.max(row, 0), cube.rows - 1), Math.min(Math.max(col, 0), cube.cols - 1)];
    for (const c of [$("image"), $("diff-image")]) {
      c.dataset.mark = c === canvas ? at.join(",") : "";
      drawMarker(c);
    }
    return at;
  }

  click(e, canvas) {
    const [row, col] = this.pixelOf(e, canvas, this.tb);
    return this.showPixel(row, col);
  }

  // The Pixel column for pixel (row, col) of the run open: its truth, the value shown,
  // its spectrum and table (only the last pixel asked for is shown)
  async showPixel(row, col) {
    const t0 = performance.now();
    const seq = (this.pixelSeq = (this.pixelSeq || 0) + 1);
    const measured = $("res-quantity").value.startsWith("measured") &&
      this.cubesOf($("res-sensor").value).includes("measured_brightness_temperature");
    const tb = measured ? await loadCube(`${this.base}.measured_brightness_temperature`) : this.tb;
    if (seq !== this.pixelSeq) return; // another pixel or run asked for meanwhile
    const f = tb.freqThz;
    const y = [];
    const err = [];
    for (let b = 0; b < tb.bands; b++) {
      const t = tb.at(b, row, col);
      y.push(t);
      // σ_Tb = σ_L / (∂B/∂T) at the channel's centre and Tb (Tb is B_ν(ν_c, T) = L_c inverted)
      // (none for a measured cube: its sensor noise is not in the simulation's σ)
      const s = this.stderr && !measured ? this.stderr.at(b, row, col) : NaN;
      err.push(t > 0 && Number.isFinite(s) ? s / planckDerivative(f[b] * 1e12, t) : NaN);
    }
    const id = this.truthId ? this.truthId.at(0, row, col) : -1;
    const objectName = id >= 0 ? (this.truthId.header["object names"] || [])[id] ?? `object ${id}` : "nothing hit";
    const truthT = this.truthT ? this.truthT.at(0, row, col) : NaN;
    const truthD = this.truthD ? this.truthD.at(0, row, col) : NaN;
    const info = $("pixel-info");
    info.dataset.row = row;
    info.dataset.col = col;
    info.innerHTML = "";
    info.append(`row ${row}, column ${col}${measured ? " (measured)" : ""}: `);
    const truth = document.createElement("span");
    truth.id = "pixel-truth";
    truth.textContent = id >= 0
      ? `${objectName}, ${formatNumber(truthT)} K at ${formatNumber(truthD)} m` : objectName;
    info.appendChild(truth);
    // the quantity of the image when the spectrum below is not of it (radiance, power, …)
    const qn = $("res-quantity").value;
    const cube = this.shown;
    if (cube && !qn.includes("brightness") && !TRUTH.has(qn) && cube.rows === tb.rows && cube.cols === tb.cols) {
      const band = Math.min(Number($("res-channel").value) || 0, cube.bands - 1);
      const v = cube.at(band, row, col);
      const line = document.createElement("div");
      line.id = "pixel-shown";
      line.dataset.value = String(v);
      line.textContent = `${qn.replace(/_/g, " ")}, channel ${band + 1} (${cube.channelName(band)}): ` +
        `${formatNumber(v)}${cube.unit === "1" ? "" : ` ${cube.unit}`}`;
      info.appendChild(line);
    }
    $("pixel-plot").replaceChildren();
    linePlot($("pixel-plot"), [{ label: measured ? "measured Tb" : "Tb ± 1σ", x: f, y, err }], { xLabel: "frequency (THz)", yLabel: "Tb (K)" });
    const table = $("pixel-table");
    table.replaceChildren();
    const head = table.createTHead().insertRow();
    for (const h of ["channel", "THz", "Tb (K)", "σ (K)"]) head.insertCell().textContent = h;
    const body = table.createTBody();
    y.forEach((t, b) => {
      const tr = body.insertRow();
      tr.insertCell().textContent = tb.bandNames[b] || String(b + 1);
      tr.insertCell().textContent = formatNumber(f[b]);
      // σ to two significant digits and Tb to the same place: no digits σ cannot back
      // (23.5 K of σ: Tb 301 K, not 301.234); 3 decimals without a σ
      const s = err[b];
      const places = Number.isFinite(s) && s > 0 ? Math.min(6, Math.max(0, 1 - Math.floor(Math.log10(s)))) : 3;
      const c = tr.insertCell();
      c.className = "tb";
      c.dataset.value = String(t); // the float32 read from the cube, in full
      c.textContent = t.toFixed(places);
      const e = tr.insertCell();
      e.className = "sigma";
      e.dataset.value = String(s);
      e.textContent = Number.isFinite(s) ? s.toFixed(places) : "–";
    });
    info.dataset.ms = (performance.now() - t0).toFixed(1);
  }

  // the server's /api/diff: (Tb_A − Tb_B) / √(σ_A² + σ_B²), or Tb_A − Tb_B in K when a run
  // has no standard errors (its X-Thzmap-Diff-Units header says which)
  async diff() {
    const seq = (this.diffSeq = (this.diffSeq || 0) + 1);
    const sensor = $("res-sensor").value;
    const a = $("diff-a").value.trim();
    const b = $("diff-b").value.trim();
    const band = Number($("res-channel").value) || 0;
    // a comparison that fails leaves no earlier one on screen as if it were its answer
    this.diffZ = null;
    $("diff-bar").args = null;
    for (const id of ["diff-image", "diff-bar"]) {
      const canvas = $(id);
      canvas.getContext("2d").clearRect(0, 0, canvas.width, canvas.height);
    }
    $("diff-info").textContent = `comparing ${a} with ${b}…`;
    let cube, z, response;
    try {
      cube = await loadCube(join(a, `${sensor}.brightness_temperature`));
      response = await request(`/api/diff?a=${q(a)}&b=${q(b)}&sensor=${q(sensor)}&band=${band}`);
      z = new Float32Array(await response.arrayBuffer());
    } catch (e) {
      if (seq !== this.diffSeq) return;
      $("diff-info").textContent = `no comparison: ${e.message}`;
      if ($("diff-image").dataset.mark) this.clearPixel(); // its A − B is of no image now
      throw e;
    }
    if (seq !== this.diffSeq) return; // another comparison was asked for meanwhile
    const sigma = response.headers.get("X-Thzmap-Diff-Units") !== "K";
    let beyond = 0;
    let count = 0;
    for (const v of z) {
      if (!Number.isFinite(v)) continue;
      count++;
      if (Math.abs(v) > 3) beyond++;
    }
    // in K: symmetric about 0 over the 1st-99th percentile, as the other images (one hot
    // pixel would take the whole scale)
    const [lo, hi] = sigma ? [-4, 4] : range(z, null);
    const span = sigma ? 4 : Math.max(Math.abs(lo), Math.abs(hi)) || 1;
    this.diffZ = { z, cube, unit: sigma ? "σ" : "K" };
    const channel = `channel ${band + 1} (${cube.channelName(band)})`;
    // the runs compared named: A and B above are filled anew with each run opened, while
    // this image stays that of the last Compare
    const runs = `A ${a}, B ${b}: `;
    $("diff-info").textContent = sigma
      ? `${runs}(A − B) / √(σA² + σB²), ${channel}: ${((100 * beyond) / Math.max(count, 1)).toFixed(2)} % of ` +
        `${count} pixels beyond ±3 σ (0.27 % expected if A and B agree within their errors)`
      : `${runs}A − B in K, ${channel} (a run without standard errors: no σ to compare with)`;
    $("diff-bar").args = [-span, span, this.diffZ.unit, diverging];
    paint($("diff-image"), cube, z, -span, span, diverging, null);
    // the pixel marked on the difference: its A − B of this comparison (it kept the value
    // of the sensor and channel compared before), or none where this one has no such pixel
    const mark = $("diff-image").dataset.mark;
    if (!mark) return;
    const [row, col] = mark.split(",").map(Number);
    if (row < cube.rows && col < cube.cols) this.showDiffPixel(row, col);
    else this.clearPixel();
  }

  clickDiff(e) {
    if (!this.diffZ) return;
    this.showDiffPixel(...this.pixelOf(e, $("diff-image"), this.diffZ.cube));
  }

  // the Pixel column for pixel (row, col) of the A/B difference: its A − B alone
  showDiffPixel(row, col) {
    this.pixelSeq = (this.pixelSeq || 0) + 1; // an image's pixel still being read: not shown
    const info = $("pixel-info");
    info.dataset.row = row;
    info.dataset.col = col;
    // the image it is of named: in the image view, whose pixel is not marked, the line read
    // as of the image shown
    info.textContent = `row ${row}, column ${col} of the A/B difference: ` +
      `A − B = ${formatNumber(this.diffZ.z[row * this.diffZ.cube.cols + col])} ${this.diffZ.unit}`;
    // the spectrum and table below were those of the pixel last clicked on the image
    $("pixel-plot").replaceChildren();
    $("pixel-table").replaceChildren();
  }

  async loadPhotons() {
    if (!this.mapPath) throw new Error(`${this.runDir}: no photon-map.thzpm (run simulate with "save the photon map")`);
    const t0 = performance.now();
    // a number field holding text reads as "" (the request then said max=0, a value never typed)
    const max = $("ph-max").value.trim();
    if (!/^[0-9]+$/.test(max) || Number(max) < 1) {
      throw new Error(`At most: expected a whole number of photons, 1 or more; got "${max || "nothing (not a number)"}"`);
    }
    this.photons ||= new PhotonView($("photon-view")); // its WebGL context only when wanted
    const n = await this.photons.load(this.mapPath, $("ph-channel").value, $("ph-object").value, Number(max));
    const of = this.photons.total ? ` of ${this.photons.total}` : "";
    const { fetch_ms: fetchMs, draw_ms: drawMs } = this.photons.timing;
    $("ph-info").textContent = `${n}${of} photons, ${Math.round(performance.now() - t0)} ms ` +
      `(${Math.round(fetchMs)} ms to fetch, ${Math.round(drawMs)} ms to draw); ` +
      "colour: direction of arrival (red, green, blue = 0.5 + 0.5 × its x, y, z)";
  }
}

// Above the image: a summary.json that is there but damaged (/api/outputs' summary_error),
// the cubes still giving the image (the run's options, seed and warnings are not known);
// else the run's warnings, which say what its images cannot (a σ column of 0.000 K read
// as exact where paths_per_sample 1 estimated no standard error)
function summaryNote(outputs) {
  const note = $("res-note");
  const warnings = outputs.summary?.warnings || [];
  note.textContent = outputs.summary_error
    ? `damaged: ${outputs.summary_error} (the run's settings and warnings are not known)`
    : warnings.map((w) => `warning: ${w}`).join("\n");
  note.hidden = !note.textContent;
}

// the sensors of an /api/outputs answer that have brightness temperature images
function imageSensors(outputs) {
  return outputs.sensors.filter((s) => s.cubes.includes("brightness_temperature")).map((s) => s.name);
}
