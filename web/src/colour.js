// Colour maps and the physics the page needs on its own (Planck's law for the standard
// error of a brightness temperature).

// viridis at 9 stops (matplotlib's), interpolated linearly
const VIRIDIS = [
  [68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
  [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37],
];
// blue - white - red for signed differences
const DIVERGING = [[33, 102, 172], [146, 197, 222], [247, 247, 247], [244, 165, 130], [178, 24, 43]];

function ramp(stops, t) {
  const x = Math.min(Math.max(t, 0), 1) * (stops.length - 1);
  const i = Math.min(Math.floor(x), stops.length - 2);
  const f = x - i;
  return stops[i].map((c, k) => c + f * (stops[i + 1][k] - c));
}
export const viridis = (t) => ramp(VIRIDIS, t);
export const diverging = (t) => ramp(DIVERGING, t);

export function cssColour(rgb) {
  return `rgb(${rgb.map((c) => Math.round(c)).join(",")})`;
}

// Draws a vertical colour bar with its unit on a canvas.
export function drawColourBar(canvas, lo, hi, unit, map = viridis) {
  const g = canvas.getContext("2d");
  const h = canvas.height;
  g.clearRect(0, 0, canvas.width, h);
  const top = 10;
  const bottom = h - 24;
  for (let y = top; y <= bottom; y++) {
    g.fillStyle = cssColour(map(1 - (y - top) / (bottom - top)));
    g.fillRect(0, y, 16, 1);
  }
  g.fillStyle = "#222";
  g.font = "11px sans-serif";
  for (let i = 0; i <= 4; i++) {
    const v = hi - (i / 4) * (hi - lo);
    const y = top + (i / 4) * (bottom - top);
    g.fillText(formatNumber(v), 20, y + 4);
  }
  g.fillText(unit, 2, h - 6);
}

export function formatNumber(v) {
  if (!Number.isFinite(v)) return String(v);
  const a = Math.abs(v);
  if (a !== 0 && (a < 1e-3 || a >= 1e5)) return v.toExponential(3);
  return String(Number(v.toPrecision(a < 100 ? 4 : 5)));
}

// dB_nu/dT at frequency nu (Hz) and temperature T (K): W m-2 sr-1 Hz-1 K-1
const H = 6.62607015e-34;
const K = 1.380649e-23;
const C = 299792458;
export function planckDerivative(nuHz, t) {
  const x = (H * nuHz) / (K * t);
  const ex = Math.exp(x);
  return ((2 * H * nuHz ** 3) / C ** 2) * (ex * x) / (t * (ex - 1) ** 2);
}
