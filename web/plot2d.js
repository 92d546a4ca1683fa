// kerf: 2-D plots on a plain canvas for the segment view: the curve with its blocks (drag to pan,
// wheel to zoom at the pointer, double-click to reset) and line charts along the curve. No
// dependencies, so the page works offline.

const FONT = '14px system-ui, sans-serif';

function sizeCanvas(canvas) {
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

function legend(g, items, x = 12, y = 20) {
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
    g.fillText(item.label, x + 30, y);
    y += 20;
  }
}

// A plan view (XY) of polylines with equal scales on both axes.
// series: [{label, points: [[x, y, ...], ...], colour, width, dash, marks, segments: [[i, j], ...]}]
// `segments` draws only the listed pieces (i to i + 1) of `points`, for highlighting.
export class PlanPlot {
  constructor(canvas) {
    this.canvas = canvas;
    this.series = [];
    this.reset();
    this.drag = null;
    canvas.addEventListener('pointerdown', (e) => {
      this.drag = { x: e.clientX, y: e.clientY };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!this.drag) return;
      this.panX += e.clientX - this.drag.x;
      this.panY += e.clientY - this.drag.y;
      this.drag = { x: e.clientX, y: e.clientY };
      this.draw();
    });
    canvas.addEventListener('pointerup', () => { this.drag = null; });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      const factor = Math.exp(-e.deltaY * 0.0015);
      const box = canvas.getBoundingClientRect();
      // Zoom about the pointer: the point under it stays put.
      const px = e.clientX - box.left - this.width / 2 - this.panX;
      const py = e.clientY - box.top - this.height / 2 - this.shiftY - this.panY;
      this.panX -= px * (factor - 1);
      this.panY -= py * (factor - 1);
      this.zoom *= factor;
      this.draw();
    }, { passive: false });
    canvas.addEventListener('dblclick', () => { this.reset(); this.draw(); });
    new ResizeObserver(() => this.draw()).observe(canvas);
  }

  reset() {
    this.zoom = 1;
    this.panX = 0;
    this.panY = 0;
    this.shiftY = 0;
  }

  setSeries(series) {
    this.series = series;
    const all = series.flatMap((s) => s.points);
    this.low = [Math.min(...all.map((p) => p[0])), Math.min(...all.map((p) => p[1]))];
    this.high = [Math.max(...all.map((p) => p[0])), Math.max(...all.map((p) => p[1]))];
    this.draw();
  }

  project(p) {
    const scale = this.scale * this.zoom;
    return [this.width / 2 + this.panX + (p[0] - this.mid[0]) * scale, this.height / 2 + this.shiftY + this.panY - (p[1] - this.mid[1]) * scale];
  }

  draw() {
    const [g, width, height] = sizeCanvas(this.canvas);
    this.width = width;
    this.height = height;
    if (!this.series.length || !this.series.some((s) => s.points.length)) {
      this.canvas.dataset.state = 'empty';
      return;
    }
    // The legend takes the top rows, the scale bar the bottom one: fit the drawing between.
    const top = 14 + 20 * this.series.filter((s) => s.label).length;
    const bottom = 34;
    const span = Math.max(this.high[0] - this.low[0], this.high[1] - this.low[1], 1e-9);
    this.scale = 0.94 * Math.min(width / Math.max(this.high[0] - this.low[0], span * 1e-3),
      (height - top - bottom) / Math.max(this.high[1] - this.low[1], span * 1e-3));
    this.mid = [(this.low[0] + this.high[0]) / 2, (this.low[1] + this.high[1]) / 2];
    this.shiftY = (top - bottom) / 2;
    let segments = 0;
    for (const s of this.series) {
      g.strokeStyle = s.colour;
      g.fillStyle = s.colour;
      g.lineWidth = s.width || 1.5;
      g.setLineDash(s.dash || []);
      g.beginPath();
      if (s.segments) {
        for (const i of s.segments) {
          const [ax, ay] = this.project(s.points[i]);
          const [bx, by] = this.project(s.points[i + 1]);
          g.moveTo(ax, ay);
          g.lineTo(bx, by);
        }
      } else {
        s.points.forEach((p, i) => {
          const [x, y] = this.project(p);
          if (i === 0) g.moveTo(x, y); else { g.lineTo(x, y); if (s.count) segments++; }
        });
      }
      g.stroke();
      g.setLineDash([]);
      if (s.marks) {
        const size = s.marks;
        for (const p of s.points) {
          const [x, y] = this.project(p);
          if (x > -size && y > -size && x < width + size && y < height + size) g.fillRect(x - size / 2, y - size / 2, size, size);
        }
      }
    }
    this.drawScale(g);
    legend(g, this.series);
    this.canvas.dataset.state = 'drawn';
    this.canvas.dataset.segments = String(segments);
  }

  // A scale bar of a round length, bottom left.
  drawScale(g) {
    const scale = this.scale * this.zoom;
    const target = 120 / scale;
    const power = 10 ** Math.floor(Math.log10(target));
    const length = [1, 2, 5, 10].map((k) => k * power).filter((l) => l <= target).pop() || power;
    const x = 16;
    const y = this.height - 18;
    g.strokeStyle = '#222';
    g.lineWidth = 2;
    g.beginPath();
    g.moveTo(x, y - 5); g.lineTo(x, y); g.lineTo(x + length * scale, y); g.lineTo(x + length * scale, y - 5);
    g.stroke();
    g.fillStyle = '#222';
    g.font = FONT;
    g.fillText(`${length < 1 ? length.toPrecision(1) : length} mm`, x + length * scale + 6, y);
  }
}

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
  g.fillText(options.xLabel || '', (left + width - right) / 2, height - 6);
  g.save();
  g.translate(16, (top + height - bottom) / 2);
  g.rotate(-Math.PI / 2);
  g.fillText(options.yLabel || '', 0, 0);
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

function niceStep(raw) {
  const power = 10 ** Math.floor(Math.log10(raw || 1));
  return [1, 2, 5, 10].map((k) => k * power).find((s) => s >= raw) || power;
}

function formatTick(v) {
  const a = Math.abs(v);
  if (a === 0) return '0';
  if (a >= 1000 || a < 0.001) return v.toExponential(1);
  return String(Number(v.toPrecision(4)));
}
