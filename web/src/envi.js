// ENVI cubes as thzmap writes them (float32, little-endian, band-sequential, no header
// bytes): read once whole through /api/file, then every pixel is an array lookup.
import { getBytes, getText, q } from "./api.js";
import { formatNumber } from "./colour.js";

export function parseHeader(text) {
  const h = {};
  const re = /^\s*([^=\n]+?)\s*=\s*(\{[^}]*\}|[^\n]*)/gm;
  let m;
  while ((m = re.exec(text))) {
    const key = m[1].trim().toLowerCase();
    let v = m[2].trim();
    if (v.startsWith("{")) v = v.slice(1, -1).split(",").map((s) => s.trim());
    h[key] = v;
  }
  return h;
}

const cache = new Map();

// path: "DIR/S.QUANTITY" without extension
export function loadCube(path) {
  if (!cache.has(path)) {
    const p = (async () => {
      const [hdrText, bytes] = await Promise.all([
        getText(`/api/file?path=${q(`${path}.hdr`)}`),
        getBytes(`/api/file?path=${q(`${path}.img`)}`),
      ]);
      const h = parseHeader(hdrText);
      const cols = Number(h.samples);
      const rows = Number(h.lines);
      const bands = Number(h.bands);
      if (Number(h["byte order"] || 0) !== 0 || Number(h["data type"]) !== 4) {
        throw new Error(`${path}.hdr: not little-endian float32`);
      }
      if (bytes.byteLength !== 4 * cols * rows * bands) {
        throw new Error(`${path}.img: ${bytes.byteLength} bytes, header says ${4 * cols * rows * bands}`);
      }
      const data = new Float32Array(bytes); // the web runs on little-endian hosts
      const ghz = (h.wavelength || []).map(Number);
      return {
        path, header: h, cols, rows, bands, data,
        unit: h["data units"] || "",
        bandNames: h["band names"] || [],
        freqThz: ghz.map((g) => g / 1000),
        ignore: h["data ignore value"] !== undefined ? Number(h["data ignore value"]) : null,
        at(band, row, col) {
          return data[(band * rows + row) * cols + col];
        },
        band(b) {
          return data.subarray(b * rows * cols, (b + 1) * rows * cols);
        },
        // channel b as the Channel list, the captions and the Pixel column name it: its
        // name in the header (the scene's, or its centre as the scene loader writes it,
        // "0.200 THz"), else its centre
        channelName(b) {
          return this.bandNames[b] || `${formatNumber(this.freqThz[b])} THz`;
        },
      };
    })();
    cache.set(path, p);
    p.catch(() => cache.delete(path));
  }
  return cache.get(path);
}

export function forget(prefix) {
  for (const k of cache.keys()) if (k.startsWith(prefix)) cache.delete(k);
}

// [lo, hi]: the 1st and 99th percentiles of the finite values that are not the ignore value
// (a few hot pixels of a noisy run would take the whole scale); at most 200 000 sampled.
// values: an array of numbers, or a list of them (a batch's frames) taken together.
export function range(values, ignore) {
  const parts = Array.isArray(values) && values.length && typeof values[0] !== "number" ? values : [values];
  const step = Math.max(1, Math.floor(parts.reduce((n, p) => n + p.length, 0) / 200000));
  const kept = [];
  for (const part of parts) {
    for (let i = 0; i < part.length; i += step) {
      const v = part[i];
      if (Number.isFinite(v) && v !== ignore) kept.push(v);
    }
  }
  if (!kept.length) return [0, 1];
  const sorted = Float64Array.from(kept).sort();
  const lo = sorted[Math.floor(0.01 * (sorted.length - 1))];
  const hi = sorted[Math.ceil(0.99 * (sorted.length - 1))];
  return lo === hi ? [lo - 0.5, hi + 0.5] : [lo, hi];
}
