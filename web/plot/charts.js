// Line and bar charts: a chart of y against x with a log option (drawChart), charts of quantities
// along a path sharing a cursor (PathChart), and bar charts per category (barChart).
import { canvasText } from '/units.js';
import { FONT, formatTick, legend, niceStep, sizeCanvas } from '/plot/canvas.js';

// A chart of y against x (x along the curve, mm). series: [{label, points: [[x, y], ...], colour,
// width, dash, step (draw as steps), dots}]; options: {log (y on a log scale), xLabel, yLabel}.
export function drawChart(canvas, series, options = {}) {
  const [g, width, height] = sizeCanvas(canvas);
  const all = series.flatMap((s) => s.points).filter((p) => Number.isFinite(p[0]) && Number.isFinite(p[1]) && (!options.log || p[1] > 0));
  if (!all.length) {
    canvas.dataset.state = 'empty';
    return;
  }
  const left = 78;
  const right = 16;
  const top = 14 + 20 * series.filter((s) => s.label).length;
  const bottom = 44;
  const ty = (v) => (options.log ? Math.log10(v) : v);
  let [x0, x1] = [Math.min(...all.map((p) => p[0])), Math.max(...all.map((p) => p[0]))];
  let [y0, y1] = [Math.min(...all.map((p) => ty(p[1]))), Math.max(...all.map((p) => ty(p[1])))];
  if (x1 <= x0) x1 = x0 + 1;
  if (options.log) {
    y0 = Math.floor(y0 - 0.05);
    y1 = Math.ceil(y1 + 0.05);
  } else {
    const pad = (y1 - y0) * 0.08 || Math.abs(y1) * 0.1 || 1;
    y0 = Math.min(0, y0 - pad);
    y1 += pad;
  }
  const sx = (x) => left + (x - x0) / (x1 - x0) * (width - left - right);
  const sy = (y) => height - bottom - (ty(y) - y0) / (y1 - y0) * (height - top - bottom);
  // Axes and ticks.
  g.strokeStyle = '#9aa5ae';
  g.fillStyle = '#333';
  g.lineWidth = 1;
  g.font = FONT;
  g.beginPath();
  g.moveTo(left, top);
  g.lineTo(left, height - bottom);
  g.lineTo(width - right, height - bottom);
  g.stroke();
  const yTicks = [];
  if (options.log) {
    for (let e = y0; e <= y1; e++) yTicks.push(10 ** e);
  } else {
    const step = niceStep((y1 - y0) / 5);
    for (let v = Math.ceil(y0 / step) * step; v <= y1; v += step) yTicks.push(v);
  }
  g.textAlign = 'right';
  for (const v of yTicks) {
    const y = sy(v);
    g.strokeStyle = '#e3e8ec';
    g.beginPath(); g.moveTo(left, y); g.lineTo(width - right, y); g.stroke();
    g.fillText(options.log ? v.toExponential(0) : formatTick(v), left - 6, y + 5);
  }
  g.textAlign = 'center';
  const xStep = niceStep((x1 - x0) / 8);
  for (let v = Math.ceil(x0 / xStep) * xStep; v <= x1 + 1e-9; v += xStep) {
    const x = sx(v);
    g.strokeStyle = '#9aa5ae';
    g.beginPath(); g.moveTo(x, height - bottom); g.lineTo(x, height - bottom + 5); g.stroke();
    g.fillText(formatTick(v), x, height - bottom + 20);
  }
  g.fillText(canvasText(g.canvas, options.xLabel || ''), (left + width - right) / 2, height - 6);
  g.save();
  g.translate(16, (top + height - bottom) / 2);
  g.rotate(-Math.PI / 2);
  g.fillText(canvasText(g.canvas, options.yLabel || ''), 0, 0);
  g.restore();
  g.textAlign = 'left';
  // Series.
  let drawn = 0;
  for (const s of series) {
    const points = s.points.filter((p) => Number.isFinite(p[1]) && (!options.log || p[1] > 0));
    g.strokeStyle = s.colour;
    g.fillStyle = s.colour;
    g.lineWidth = s.width || 2;
    g.setLineDash(s.dash || []);
    if (s.dots) {
      for (const p of points) g.fillRect(sx(p[0]) - 1.5, sy(p[1]) - 1.5, 3, 3);
    } else {
      g.beginPath();
      points.forEach((p, i) => {
        if (i === 0) g.moveTo(sx(p[0]), sy(p[1]));
        else g.lineTo(sx(p[0]), sy(p[1]));
      });
      g.stroke();
    }
    g.setLineDash([]);
    drawn += points.length;
  }
  legend(g, series, left + 10, 18);
  canvas.dataset.state = 'drawn';
  canvas.dataset.points = String(drawn);
}

// Legend entries laid out in rows that wrap at `width` (nothing is clipped); returns the rows as
// [{x, y, item}] and the height they take.
function legendRows(g, items, left, width) {
  g.font = '13px system-ui, sans-serif';
  const placed = [];
  // On a narrow chart the legend starts at the edge, not above the plot area.
  if (width < 520) left = 8;
  let [x, y] = [left, 16];
  for (const entry of items.filter((i) => i.label)) {
    const item = { ...entry, label: fitText(g, entry.label, width - left - 34) };
    const size = 26 + g.measureText(item.label).width + 14;
    if (x > left && x + size > width - 8) {
      x = left;
      y += 18;
    }
    placed.push({ x, y, item });
    x += size;
  }
  return { placed, height: placed.length ? y + 8 : 4 };
}

// `text` shortened with an ellipsis to at most `room` pixels in the current font.
function fitText(g, text, room) {
  if (g.measureText(text).width <= room) return text;
  let cut = text;
  while (cut.length > 1 && g.measureText(`${cut}…`).width > room) cut = cut.slice(0, -1);
  return `${cut}…`;
}

function drawLegendRows(g, placed) {
  g.font = '13px system-ui, sans-serif';
  g.textAlign = 'left';
  g.textBaseline = 'alphabetic';
  for (const { x, y, item } of placed) {
    g.strokeStyle = item.colour;
    g.lineWidth = item.swatch === 'bar' ? 8 : 3;
    g.setLineDash(item.dash || []);
    g.beginPath();
    g.moveTo(x, y - 4);
    g.lineTo(x + 20, y - 4);
    g.stroke();
    g.setLineDash([]);
    g.fillStyle = '#1d2327';
    g.fillText(canvasText(g.canvas, item.label), x + 26, y);
  }
}

// Ticks of a nice step over [low, high].
function ticks(low, high, count) {
  const step = niceStep((high - low) / count || 1);
  const out = [];
  for (let v = Math.ceil(low / step - 1e-9) * step; v <= high + step * 1e-9; v += step) out.push(Number(v.toPrecision(12)));
  return out;
}

// A chart of quantities along a path: x is the path length or the time, y one quantity, and an
// optional second y axis on the right for a quantity proportional to the first (`y2: {label,
// factor}`: y2 = y·factor, e.g. spindle power beside torque). A legend that wraps, dashed limit
// lines with their labels, and a cursor: `onHover(x)` hears the x under the pointer (undefined
// when it leaves), `cursor(x)` draws the vertical line. Redraws itself when its width changes.
//
// spec: {x: [x0, x1], xLabel, yLabel, y: [low, high] (optional; else from the data, from 0),
//   series: [{label, colour, width, dash, points: [[x, y], ...]} or {…, steps: [[x0, x1, y], ...]}],
//   limits: [{value, label, colour}], paint(g, map) for anything else (map: {x(v), y(v)}),
//   legend: extra legend-only items [{label, colour, dash}]}
export class PathChart {
  constructor(parent, { label, height = 240 }) {
    this.canvas = document.createElement('canvas');
    this.canvas.className = 'chart';
    this.canvas.setAttribute('aria-label', label);
    this.canvas.style.height = `${height}px`;
    parent.append(this.canvas);
    this.spec = null;
    this.at = undefined;
    this.canvas.addEventListener('pointermove', (event) => {
      if (!this.box || !this.hover) return;
      const x = event.clientX - this.canvas.getBoundingClientRect().left;
      if (x < this.box.left || x > this.box.right) return;
      const [x0, x1] = this.spec.x;
      this.hover(x0 + (x - this.box.left) / (this.box.right - this.box.left) * (x1 - x0));
    });
    this.canvas.addEventListener('pointerleave', () => this.hover?.(undefined));
    let width = 0;
    new ResizeObserver(() => {
      if (!this.spec || !this.canvas.clientWidth || Math.abs(this.canvas.clientWidth - width) < 2) return;
      width = this.canvas.clientWidth;
      this.draw(this.spec);
    }).observe(this.canvas);
  }

  onHover(callback) {
    this.hover = callback;
  }

  draw(spec) {
    this.spec = spec;
    const canvas = this.canvas;
    if (!canvas.clientWidth) return;
    const [g, width, height] = sizeCanvas(canvas);
    const series = spec.series || [];
    const ys = series.flatMap((s) => (s.steps ? s.steps.map((b) => b[2]) : s.points.map((p) => p[1]))).filter(Number.isFinite);
    const limits = (spec.limits || []).filter((l) => Number.isFinite(l.value));
    let [low, high] = spec.y || [Math.min(0, ...ys), Math.max(...ys, ...limits.map((l) => l.value))];
    if (!Number.isFinite(high) || high <= low) high = low + 1;
    high += (high - low) * 0.06;
    const legendItems = [...series, ...limits.filter((l) => l.label).map((l) => ({ label: l.label, colour: l.colour, dash: [6, 4] })), ...(spec.legend || [])];
    const left = 62;
    const right = width - (spec.y2 ? 62 : 14);
    const { placed, height: legendHeight } = legendRows(g, legendItems, left, width);
    const top = legendHeight + 8;
    const bottom = height - 40;
    const [x0, x1] = spec.x[1] > spec.x[0] ? spec.x : [spec.x[0], spec.x[0] + 1];
    const map = {
      x: (v) => left + (v - x0) / (x1 - x0) * (right - left),
      y: (v) => bottom - (v - low) / (high - low) * (bottom - top),
    };
    this.box = { left, right, top, bottom };
    this.map = map;
    // Grid, ticks and axis titles.
    g.font = '12px system-ui, sans-serif';
    g.lineWidth = 1;
    g.textBaseline = 'middle';
    for (const v of ticks(low, high, 5)) {
      g.strokeStyle = '#e3e7eb';
      g.beginPath(); g.moveTo(left, map.y(v)); g.lineTo(right, map.y(v)); g.stroke();
      g.fillStyle = '#5b6670';
      g.textAlign = 'right';
      g.fillText(formatTick(v), left - 5, map.y(v));
    }
    if (spec.y2) {
      // The right axis has round numbers of its own, placed where y·factor has them.
      g.textAlign = 'left';
      for (const v of ticks(low * spec.y2.factor, high * spec.y2.factor, 5)) {
        g.strokeStyle = '#5b6670';
        g.beginPath(); g.moveTo(right, map.y(v / spec.y2.factor)); g.lineTo(right + 4, map.y(v / spec.y2.factor)); g.stroke();
        g.fillText(formatTick(v), right + 6, map.y(v / spec.y2.factor));
      }
    }
    g.textAlign = 'center';
    g.textBaseline = 'top';
    for (const v of ticks(x0, x1, Math.max(2, Math.floor((right - left) / 80)))) {
      g.strokeStyle = '#e3e7eb';
      g.beginPath(); g.moveTo(map.x(v), top); g.lineTo(map.x(v), bottom); g.stroke();
      g.fillStyle = '#5b6670';
      g.fillText(formatTick(v), map.x(v), bottom + 4);
    }
    g.strokeStyle = '#5b6670';
    g.strokeRect(left, top, right - left, bottom - top);
    g.fillStyle = '#1d2327';
    g.font = '13px system-ui, sans-serif';
    g.textBaseline = 'bottom';
    g.fillText(canvasText(g.canvas, spec.xLabel || ''), (left + right) / 2, height - 2);
    const vertical = (text, x) => {
      g.save();
      g.translate(x, (top + bottom) / 2);
      g.rotate(-Math.PI / 2);
      g.textBaseline = 'top';
      g.fillText(canvasText(g.canvas, text), 0, 0);
      g.restore();
    };
    vertical(spec.yLabel || '', 2);
    if (spec.y2) vertical(spec.y2.label, width - 18);
    // Data, clipped to the frame.
    g.save();
    g.beginPath();
    g.rect(left, top, right - left, bottom - top);
    g.clip();
    spec.paint?.(g, map);
    let drawn = 0;
    for (const s of series) {
      g.strokeStyle = s.colour;
      g.lineWidth = s.width || 1.5;
      g.setLineDash(s.dash || []);
      g.beginPath();
      if (s.steps) {
        for (const [from, to, y] of s.steps) {
          if (!Number.isFinite(y)) continue;
          g.moveTo(map.x(from), map.y(y));
          g.lineTo(map.x(to), map.y(y));
          drawn++;
        }
      } else {
        let pen = false;
        for (const [x, y] of s.points) {
          if (!Number.isFinite(y)) { pen = false; continue; }
          if (pen) g.lineTo(map.x(x), map.y(y)); else g.moveTo(map.x(x), map.y(y));
          pen = true;
          drawn++;
        }
      }
      g.stroke();
    }
    g.setLineDash([6, 4]);
    g.lineWidth = 2;
    for (const limit of limits) {
      g.strokeStyle = limit.colour || '#b3261e';
      g.beginPath(); g.moveTo(left, map.y(limit.value)); g.lineTo(right, map.y(limit.value)); g.stroke();
    }
    g.restore();
    drawLegendRows(g, placed);
    this.image = g.getImageData(0, 0, canvas.width, canvas.height);
    canvas.dataset.state = 'drawn';
    canvas.dataset.points = String(drawn);
    if (this.at !== undefined) this.cursor(this.at);
  }

  // A vertical line at x (undefined: none).
  cursor(x) {
    this.at = x;
    if (!this.image) return;
    const g = this.canvas.getContext('2d');
    g.putImageData(this.image, 0, 0);
    if (x === undefined) return;
    const ratio = window.devicePixelRatio || 1;
    g.setTransform(ratio, 0, 0, ratio, 0, 0);
    g.strokeStyle = '#1d2327';
    g.lineWidth = 1.5;
    g.beginPath();
    g.moveTo(this.map.x(x), this.box.top);
    g.lineTo(this.map.x(x), this.box.bottom);
    g.stroke();
  }
}

// A bar chart over categories (e.g. flute counts): one bar per category with optional marks
// (a thick line at `mean`, a thin box at `min`) and a ★ above the `best` one, and dashed limit
// lines. spec: {title, categories: [label], bars: [{value, colour, mean, min, best}],
// limits: [{value, label, colour}], legend: [{label, colour, swatch}]}.
export function barChart(parent, label, spec, height = 230) {
  const canvas = document.createElement('canvas');
  canvas.className = 'chart';
  canvas.setAttribute('aria-label', label);
  canvas.style.height = `${height}px`;
  parent.append(canvas);
  const draw = () => {
    if (!canvas.clientWidth) return;
    const [g, width, full] = sizeCanvas(canvas);
    const limits = (spec.limits || []).filter((l) => Number.isFinite(l.value));
    const left = 62;
    const right = width - 12;
    const legend = [...(spec.legend || []), ...limits.filter((l) => l.label).map((l) => ({ label: l.label, colour: l.colour, dash: [6, 4] }))];
    const { placed, height: legendHeight } = legendRows(g, legend, left, width);
    const top = legendHeight + 22;
    const bottom = full - 40;
    const high = Math.max(1e-9, ...spec.bars.map((b) => b.value), ...limits.map((l) => l.value)) * 1.12;
    const n = spec.categories.length;
    const x = (i) => left + (i + 0.5) / n * (right - left);
    const y = (v) => bottom - v / high * (bottom - top);
    g.font = '12px system-ui, sans-serif';
    g.textBaseline = 'middle';
    g.textAlign = 'right';
    g.lineWidth = 1;
    for (const v of ticks(0, high, 4)) {
      g.strokeStyle = '#e3e7eb';
      g.beginPath(); g.moveTo(left, y(v)); g.lineTo(right, y(v)); g.stroke();
      g.fillStyle = '#5b6670';
      g.fillText(formatTick(v), left - 5, y(v));
    }
    g.strokeStyle = '#5b6670';
    g.strokeRect(left, top, right - left, bottom - top);
    const w = Math.max(4, (right - left) / n * 0.6);
    g.textAlign = 'center';
    spec.bars.forEach((bar, i) => {
      g.fillStyle = bar.colour;
      g.fillRect(x(i) - w / 2, y(bar.value), w, bottom - y(bar.value));
      g.fillStyle = '#1d2327';
      if (Number.isFinite(bar.mean)) g.fillRect(x(i) - w / 2, y(bar.mean) - 1.5, w, 3);
      if (Number.isFinite(bar.min)) { g.strokeStyle = '#1d2327'; g.strokeRect(x(i) - w / 2, y(bar.min) - 1, w, 2); }
      if (bar.best) {
        g.font = 'bold 15px system-ui, sans-serif';
        g.textBaseline = 'bottom';
        g.fillStyle = '#1e6b31';
        g.fillText('★', x(i), y(bar.value) - 2);
      }
      g.font = '12px system-ui, sans-serif';
      g.textBaseline = 'top';
      g.fillStyle = '#5b6670';
      g.fillText(spec.categories[i], x(i), bottom + 4);
    });
    g.setLineDash([6, 4]);
    g.lineWidth = 2;
    for (const limit of limits) {
      g.strokeStyle = limit.colour || '#b3261e';
      g.beginPath(); g.moveTo(left, y(limit.value)); g.lineTo(right, y(limit.value)); g.stroke();
    }
    g.setLineDash([]);
    g.fillStyle = '#1d2327';
    g.font = '13px system-ui, sans-serif';
    g.textAlign = 'left';
    g.textBaseline = 'bottom';
    g.fillText(fitText(g, canvasText(g.canvas, spec.title), width - 16), Math.min(left, width < 520 ? 8 : left), legendHeight + 18);
    g.textAlign = 'center';
    g.fillText(canvasText(g.canvas, spec.xLabel || ''), (left + right) / 2, full - 2);
    drawLegendRows(g, placed);
    canvas.dataset.state = 'drawn';
  };
  let width = 0;
  new ResizeObserver(() => {
    if (!canvas.clientWidth || Math.abs(canvas.clientWidth - width) < 2) return;
    width = canvas.clientWidth;
    draw();
  }).observe(canvas);
  draw();
  return canvas;
}

