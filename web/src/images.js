// A cube's band drawn on the Results tab's canvases: its pixels in a colour map, the
// image's size on screen (fitted to its pane), its colour bar beside it and the mark of
// the pixel clicked over it.
import { drawColourBar } from "./colour.js";

const $ = (id) => document.getElementById(id);

// values: the band (rows × columns, row-major) coloured over lo…hi by map; not finite or
// ignore (a value meaning none): grey
export function paint(canvas, cube, values, lo, hi, map, ignore) {
  canvas.width = cube.cols;
  canvas.height = cube.rows;
  canvas.dataset.painted = "1";
  fit(canvas);
  const g = canvas.getContext("2d");
  const img = g.createImageData(cube.cols, cube.rows);
  const lut = Array.from({ length: 256 }, (_, i) => map(i / 255));
  const scale = 255 / (hi - lo);
  for (let i = 0; i < values.length; i++) {
    const v = values[i];
    const o = 4 * i;
    if (!Number.isFinite(v) || v === ignore) {
      img.data[o] = img.data[o + 1] = img.data[o + 2] = 40;
    } else {
      const c = lut[Math.min(255, Math.max(0, Math.round((v - lo) * scale)))];
      img.data[o] = c[0];
      img.data[o + 1] = c[1];
      img.data[o + 2] = c[2];
    }
    img.data[o + 3] = 255;
  }
  g.putImageData(img, 0, 0);
}

// The image's size on screen: a whole number of screen pixels per pixel, up to 512 px a
// side, less in a narrow pane (the colour bar beside it, 110 px) or a low one (the pane's
// toolbar and caption above and under it: at 800 × 600 the caption needed a scroll);
// again at every resize. A pane out of sight (another tab) has no width: the size waits
// for the next resize. Its colour bar is drawn then too, at its height.
export function fit(canvas) {
  if (!canvas.dataset.painted) return;
  const pane = canvas.closest("#image-pane, #diff-pane");
  const width = pane?.clientWidth || 0;
  if (width || !canvas.style.width) {
    const room = width - 128;
    const side = room > 0 ? Math.min(512, room) : 512;
    let zoom = Math.floor(side / Math.max(canvas.width, canvas.height));
    if (width) {
      const style = getComputedStyle(pane);
      const others = [...pane.children].filter((c) => !c.contains(canvas)).reduce((h, c) => h + c.offsetHeight, 0);
      const tall = pane.clientHeight - parseFloat(style.paddingTop) - parseFloat(style.paddingBottom) - others - 2;
      zoom = Math.min(zoom, Math.floor(tall / canvas.height));
    }
    zoom = Math.max(1, zoom);
    canvas.style.width = `${canvas.width * zoom}px`;
    canvas.style.height = `${canvas.height * zoom}px`;
    drawMarker(canvas);
  }
  drawBar(canvas);
}

// The colour bar beside an image, from what was last asked of it (bar.args: drawColourBar's
// arguments after the canvas, or null for none), as tall as the image is drawn with its
// border: a fixed 300 px bar made the pane scroll under an image drawn 192 px tall at 800 ×
// 600. At least 120 px, which its five labels and unit need.
function drawBar(image) {
  const bar = $(image.id === "image" ? "colourbar" : "diff-bar");
  const height = Math.max(120, Math.round(parseFloat(image.style.height) || 0) + 2);
  if (bar.height !== height) bar.height = height; // (which clears it)
  if (bar.args) drawColourBar(bar, ...bar.args);
  else bar.getContext("2d").clearRect(0, 0, bar.width, bar.height);
}

// The mark of the pixel clicked (canvas.dataset.mark "row,col"), over the image as drawn:
// a box around the pixel, at least 9 px, with a tick out of each side.
export function drawMarker(canvas) {
  const svg = $(`${canvas.id}-marker`);
  const [row, col] = (canvas.dataset.mark || "").split(",").map(Number);
  const cell = canvas.clientWidth / canvas.width;
  if (!canvas.dataset.mark || !(row < canvas.height && col < canvas.width) || !cell) {
    svg.toggleAttribute("hidden", true); // an SVG element has no .hidden of its own
    return;
  }
  Object.assign(svg.style, { left: `${canvas.offsetLeft + canvas.clientLeft}px`,
    top: `${canvas.offsetTop + canvas.clientTop}px`, width: `${canvas.clientWidth}px`, height: `${canvas.clientHeight}px` });
  const x = (col + 0.5) * cell;
  const y = (row + 0.5) * cell;
  const h = Math.max(cell, 9) / 2 + 1;
  const t = h + 6;
  const d = `M${x - h},${y - h}h${2 * h}v${2 * h}h${-2 * h}z M${x},${y - h}V${y - t} M${x},${y + h}V${y + t}` +
    ` M${x - h},${y}H${x - t} M${x + h},${y}H${x + t}`;
  svg.innerHTML = `<path class="under" d="${d}"/><path class="over" d="${d}"/>`;
  svg.dataset.row = row;
  svg.dataset.col = col;
  svg.toggleAttribute("hidden", false);
}
