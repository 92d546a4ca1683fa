// Colour by value: a diverging scale centred on zero, its colour bar and a histogram of values
// coloured by the same scale.
import { formatTick } from '/plot/canvas.js';

// A diverging scale centred on zero: blue below, white at zero, red above, symmetric limits
// ±`limit`. Returns an [r, g, b] triple in 0..255.
export function diverging(value, limit) {
  const t = Math.max(-1, Math.min(1, limit > 0 ? value / limit : 0));
  const blue = [33, 102, 172];
  const red = [178, 24, 43];
  const white = [247, 247, 247];
  const end = t < 0 ? blue : red;
  const a = Math.abs(t);
  return white.map((w, k) => Math.round(w + (end[k] - w) * a));
}

export function css([r, g, b]) {
  return `rgb(${r}, ${g}, ${b})`;
}

// A colour scale from `low` to `high` with its ends (and zero) labelled, and an optional band
// ±`band` as a dashed box. colour(v) gives a CSS colour, format(v) the number shown in `unit`.
export function drawColourScale(canvas, { low, high, band, colour, format = formatTick, unit = '' }) {
  const width = canvas.clientWidth;
  const height = canvas.clientHeight;
  const ratio = window.devicePixelRatio || 1;
  canvas.width = Math.round(width * ratio);
  canvas.height = Math.round(height * ratio);
  const g = canvas.getContext('2d');
  g.setTransform(ratio, 0, 0, ratio, 0, 0);
  g.fillStyle = '#fff';
  g.fillRect(0, 0, width, height);
  const left = 10;
  const right = width - 10;
  for (let x = left; x < right; x++) {
    g.fillStyle = colour(low + (high - low) * (x - left) / (right - left));
    g.fillRect(x, 4, 1, 22);
  }
  g.fillStyle = '#1d2327';
  g.font = '15px sans-serif';
  g.textBaseline = 'top';
  g.textAlign = 'left';
  g.fillText(`${format(low)} ${unit}`, left, 30);
  g.textAlign = 'right';
  g.fillText(`${format(high)} ${unit}`, right, 30);
  if (low < 0 && high > 0) {
    const zero = left + (right - left) * (-low / (high - low));
    g.fillRect(zero, 0, 2, 28);
    g.textAlign = 'center';
    g.fillText('0', zero, 30);
  }
  if (band > 0) {
    // The tolerance band: a dashed box over the scale from −band to +band.
    const at = (e) => left + (right - left) * ((Math.max(low, Math.min(high, e)) - low) / (high - low));
    g.strokeStyle = '#1d2327';
    g.lineWidth = 2;
    g.setLineDash([5, 3]);
    g.strokeRect(at(-band), 2, at(band) - at(-band), 26);
    g.setLineDash([]);
  }
  canvas.dataset.state = 'drawn';
}

// A histogram of `values` over [low, high] in 30 bins, each coloured by colour(centre), with
// dashed lines at ±`band`; format(v) and `unit` for the axis, `label` under it.
export function drawHistogram(canvas, values, { low, high, band, colour, format = formatTick, unit = '', label = '' }) {
  const errors = values;
  const width = canvas.clientWidth;
  const height = canvas.clientHeight;
  const ratio = window.devicePixelRatio || 1;
  canvas.width = Math.round(width * ratio);
  canvas.height = Math.round(height * ratio);
  const g = canvas.getContext('2d');
  g.setTransform(ratio, 0, 0, ratio, 0, 0);
  g.fillStyle = '#fff';
  g.fillRect(0, 0, width, height);
  if (!errors.length) {
    canvas.dataset.state = 'empty';
    return;
  }
  const bins = 30;
  const span = high - low || 1e-9;
  const counts = new Array(bins).fill(0);
  for (const e of errors) counts[Math.min(bins - 1, Math.floor(((e - low) / span) * bins))]++;
  const most = Math.max(...counts);
  const [left, right, top, bottom] = [50, width - 12, 12, height - 34];
  g.strokeStyle = '#5b6670';
  g.beginPath();
  g.moveTo(left, top);
  g.lineTo(left, bottom);
  g.lineTo(right, bottom);
  g.stroke();
  const w = (right - left) / bins;
  counts.forEach((count, i) => {
    const h = (count / most) * (bottom - top);
    g.fillStyle = colour(low + span * (i + 0.5) / bins);
    g.fillRect(left + i * w + 1, bottom - h, Math.max(1, w - 2), h);
  });
  g.fillStyle = '#1d2327';
  g.font = '14px sans-serif';
  g.textAlign = 'right';
  g.textBaseline = 'middle';
  g.fillText(String(most), left - 6, top + 4);
  g.fillText('0', left - 6, bottom);
  g.textBaseline = 'top';
  g.textAlign = 'left';
  g.fillText(`${format(low)}`, left, bottom + 6);
  g.textAlign = 'right';
  g.fillText(`${format(high)} ${unit}`, right, bottom + 6);
  g.textAlign = 'center';
  g.fillText(label, (left + right) / 2, bottom + 6);
  if (band > 0) {
    g.strokeStyle = '#1d2327';
    g.setLineDash([5, 3]);
    for (const e of [-band, band]) {
      if (e < low || e > high) continue;
      const x = left + (right - left) * ((e - low) / span);
      g.beginPath();
      g.moveTo(x, top);
      g.lineTo(x, bottom);
      g.stroke();
    }
    g.setLineDash([]);
  }
  canvas.dataset.state = 'drawn';
  canvas.dataset.bins = String(counts.filter((c) => c > 0).length);
}

