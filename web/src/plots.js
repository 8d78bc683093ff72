// Small SVG line plots: material spectra, transmittance, a pixel's spectrum with error bars.
import { formatNumber } from "./colour.js";

const COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf"];
const NS = "http://www.w3.org/2000/svg";

function el(name, attrs, parent) {
  const node = document.createElementNS(NS, name);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
  if (parent) parent.appendChild(node);
  return node;
}

// series: [{label, x: [], y: [], err?: [], colour?}], axes {xLabel, yLabel, yMin?, yMax?}:
// yMin/yMax fix an end of the y axis (a quantity that cannot go below 0: yMin 0)
export function linePlot(container, series, axes) {
  const W = 320;
  const Hh = 150;
  // room for the y ticks' five digits beside the axis's name, and for half of the last
  // x tick's label (it was cut off at the right edge)
  const m = { l: 54, r: 14, t: 8, b: 30 };
  const svg = el("svg", { viewBox: `0 0 ${W} ${Hh}`, class: "plot" });
  const xs = series.flatMap((s) => s.x);
  const ys = series.flatMap((s) => s.y.map((y, i) => [y - (s.err?.[i] || 0), y + (s.err?.[i] || 0)]).flat());
  const finite = (a) => a.filter(Number.isFinite);
  let [x0, x1] = [Math.min(...finite(xs)), Math.max(...finite(xs))];
  let y0 = axes.yMin ?? Math.min(...finite(ys));
  let y1 = axes.yMax ?? Math.max(...finite(ys));
  if (!Number.isFinite(x0)) [x0, x1] = [0, 1];
  if (!Number.isFinite(y0) || !Number.isFinite(y1)) [y0, y1] = [0, 1];
  // one x (a one-channel run's spectrum): ±10 % about it (±0.5 made 0.35 THz's axis run
  // from −0.15 THz, a frequency no channel has)
  if (x1 === x0) [x0, x1] = [x0 - (0.1 * Math.abs(x0) || 0.5), x1 + (0.1 * Math.abs(x0) || 0.5)];
  // a flat curve: a unit range about it, but never past a bound the caller set (α ≡ 0
  // with yMin 0: 0…1, not −0.5…0.5)
  if (y1 === y0) {
    if (axes.yMin !== undefined && axes.yMax === undefined) y1 = y0 + 1;
    else if (axes.yMax !== undefined && axes.yMin === undefined) y0 = y1 - 1;
    else [y0, y1] = [y0 - 0.5, y1 + 0.5];
  }
  const px = (x) => m.l + ((x - x0) / (x1 - x0)) * (W - m.l - m.r);
  const py = (y) => Hh - m.b - ((y - y0) / (y1 - y0)) * (Hh - m.t - m.b);
  el("rect", { x: m.l, y: m.t, width: W - m.l - m.r, height: Hh - m.t - m.b, fill: "none", stroke: "#bbb" }, svg);
  for (let i = 0; i <= 4; i++) {
    const xv = x0 + (i / 4) * (x1 - x0);
    const yv = y0 + (i / 4) * (y1 - y0);
    // the first x tick's label from its tick on: centred, it ran into the lowest y tick's
    el("text", { x: px(xv), y: Hh - m.b + 11, "text-anchor": i ? "middle" : "start" }, svg).textContent = formatNumber(xv);
    el("text", { x: m.l - 3, y: py(yv) + 3, "text-anchor": "end" }, svg).textContent = formatNumber(yv);
  }
  el("text", { x: (W + m.l) / 2, y: Hh - 3, "text-anchor": "middle" }, svg).textContent = axes.xLabel;
  el("text", { x: 10, y: Hh / 2, transform: `rotate(-90 10 ${Hh / 2})`, "text-anchor": "middle" }, svg)
    .textContent = axes.yLabel;
  series.forEach((s, k) => {
    const colour = s.colour || COLOURS[k % COLOURS.length];
    const points = s.x.map((x, i) => [x, s.y[i]]).filter(([, y]) => Number.isFinite(y));
    if (points.length > 1) {
      el("polyline", {
        points: points.map(([x, y]) => `${px(x)},${py(y)}`).join(" "),
        fill: "none", stroke: colour, "stroke-width": 1.5,
      }, svg);
    }
    points.forEach(([x, y], i) => {
      if (s.err || points.length < 40) el("circle", { cx: px(x), cy: py(y), r: 2.2, fill: colour }, svg);
      const e = s.err?.[i];
      if (e) el("line", { x1: px(x), x2: px(x), y1: py(y - e), y2: py(y + e), stroke: colour }, svg);
    });
    // the label in its curve's colour (a style: app.css's grey for the axes' text would
    // override a fill attribute, leaving R and ε alike)
    el("text", { x: m.l + 6 + 70 * k, y: m.t + 11, style: `fill: ${colour}` }, svg).textContent = s.label;
  });
  container.appendChild(svg);
  return svg;
}
