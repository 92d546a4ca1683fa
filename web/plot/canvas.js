// What every 2-D plot of the page draws with: a canvas sized for the screen's pixel ratio and
// cleared to white, a line legend, and round tick steps and tick labels.
import { canvasText } from '/units.js';

export const FONT = '14px system-ui, sans-serif';

// Sizes `canvas`'s bitmap to its laid-out size times the pixel ratio (only when that changed, as
// resizing clears it and its drawing state), so drawing is in CSS pixels; clears it to white.
// Returns the context and the width and height in CSS pixels.
export function sizeCanvas(canvas) {
  const ratio = window.devicePixelRatio || 1;
  const width = canvas.clientWidth;
  const height = canvas.clientHeight;
  if (canvas.width !== Math.round(width * ratio) || canvas.height !== Math.round(height * ratio)) {
    canvas.width = Math.round(width * ratio);
    canvas.height = Math.round(height * ratio);
  }
  const g = canvas.getContext('2d');
  g.setTransform(ratio, 0, 0, ratio, 0, 0);
  g.fillStyle = '#ffffff';
  g.fillRect(0, 0, width, height);
  return [g, width, height];
}

// A legend of line samples, one row each, from (x, y) down; items without a label are left out.
export function legend(g, items, x = 12, y = 20) {
  g.font = FONT;
  for (const item of items) {
    if (!item.label) continue;
    g.strokeStyle = item.colour;
    g.lineWidth = 3;
    g.setLineDash(item.dash || []);
    g.beginPath();
    g.moveTo(x, y - 5);
    g.lineTo(x + 22, y - 5);
    g.stroke();
    g.setLineDash([]);
    g.fillStyle = '#222';
    g.fillText(canvasText(g.canvas, item.label), x + 30, y);
    y += 20;
  }
}

// The smallest step of 1, 2 or 5 times a power of ten that is at least `raw`.
export function niceStep(raw) {
  const power = 10 ** Math.floor(Math.log10(raw || 1));
  return [1, 2, 5, 10].map((k) => k * power).find((s) => s >= raw) || power;
}

// A tick label: four significant digits, exponent form for the very large and very small.
export function formatTick(v) {
  const a = Math.abs(v);
  if (a === 0) return '0';
  if (a >= 1e6 || a < 0.001) return v.toExponential(1);
  return String(Number(v.toPrecision(4)));
}

// The longest round length (1, 2 or 5 times a power of ten) not over `target` mm, for a scale bar.
export function roundLength(target) {
  const power = 10 ** Math.floor(Math.log10(target));
  return [1, 2, 5, 10].map((k) => k * power).filter((l) => l <= target).pop() || power;
}
