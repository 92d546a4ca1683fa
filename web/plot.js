// kerf plot module: the page's plots. 2-D on a plain canvas (plan views with pan and zoom, charts
// along a path with a shared cursor, bar charts per category, a colour scale and a histogram) and
// 3-D with three.js (vendored in /vendor/three, no CDN): solids see-through, paths, the tool
// (ball, neck, shank) at a cursor, a mm grid and axes, view presets and zoom to fit.
import * as THREE from 'three';
import { OrbitControls } from '/vendor/three/OrbitControls.js';

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

// Makes a 2-D plot usable from the keyboard: focusable; arrow keys pan, + and − zoom, 0 fits.
function keyboard(canvas, { pan, zoom, reset, ready, draw }) {
  canvas.tabIndex = 0;
  const label = canvas.getAttribute('aria-label');
  if (label && !/arrow keys/.test(label)) canvas.setAttribute('aria-label', `${label}. Arrow keys pan, + and − zoom, 0 fits.`);
  canvas.addEventListener('keydown', (event) => {
    if (!ready()) return;
    const step = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1] }[event.key];
    if (step) pan(...step);
    else if (event.key === '+' || event.key === '=') zoom(1.25);
    else if (event.key === '-') zoom(1 / 1.25);
    else if (event.key === '0') reset();
    else return;
    event.preventDefault();
    draw();
  });
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
    keyboard(canvas, {
      pan: (dx, dy) => { this.panX -= dx * 40; this.panY -= dy * 40; },
      zoom: (factor) => { this.zoom *= factor; },
      reset: () => this.reset(),
      ready: () => this.series.length > 0,
      draw: () => this.draw(),
    });
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

  // Marks the point `at` (the timeline's position), or nothing for null.
  setMarker(at) {
    this.marker = at;
    this.canvas.dataset.tool = at ? at.map((v) => v.toFixed(3)).join(' ') : '';
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
    if (this.marker) {
      const [x, y] = this.project(this.marker);
      g.beginPath();
      g.arc(x, y, 7, 0, 2 * Math.PI);
      g.fillStyle = 'rgba(196, 127, 23, 0.4)';
      g.fill();
      g.strokeStyle = '#c47f17';
      g.lineWidth = 2.5;
      g.stroke();
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
  if (a >= 1e6 || a < 0.001) return v.toExponential(1);
  return String(Number(v.toPrecision(4)));
}

// A plan plot of a contour (layered milling): y up, equal scales, wheel zoom about the pointer, drag to pan,
// double-click to fit. scene = {material: {polygon, inside}, lines: [{points, colour, width,
// dash}], marks: [{at, colour, size, ring}]}.
export class Plot2D {
  constructor(canvas) {
    this.canvas = canvas;
    this.scene = null;
    this.view = null;
    this.drag = null;
    canvas.addEventListener('pointerdown', (e) => {
      this.drag = { x: e.clientX, y: e.clientY };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!this.drag || !this.view) return;
      this.view.cx -= (e.clientX - this.drag.x) / this.view.scale;
      this.view.cy += (e.clientY - this.drag.y) / this.view.scale;
      this.drag = { x: e.clientX, y: e.clientY };
      this.draw();
    });
    canvas.addEventListener('pointerup', () => { this.drag = null; });
    canvas.addEventListener('wheel', (e) => {
      if (!this.view) return;
      e.preventDefault();
      const rect = canvas.getBoundingClientRect();
      const before = this.toWorld(e.clientX - rect.left, e.clientY - rect.top);
      this.view.scale *= Math.exp(-e.deltaY * 0.0015);
      const after = this.toWorld(e.clientX - rect.left, e.clientY - rect.top);
      this.view.cx += before[0] - after[0];
      this.view.cy += before[1] - after[1];
      this.draw();
    }, { passive: false });
    canvas.addEventListener('dblclick', () => { this.fit(); this.draw(); });
    keyboard(canvas, {
      pan: (dx, dy) => { this.view.cx += dx * 40 / this.view.scale; this.view.cy -= dy * 40 / this.view.scale; },
      zoom: (factor) => { this.view.scale *= factor; },
      reset: () => this.fit(),
      ready: () => Boolean(this.view),
      draw: () => this.draw(),
    });
    new ResizeObserver(() => this.draw()).observe(canvas);
  }

  setScene(scene, keepView = false) {
    this.scene = scene;
    if (!keepView || !this.view) this.fit();
    this.draw();
  }

  bounds() {
    const low = [Infinity, Infinity];
    const high = [-Infinity, -Infinity];
    const add = (p) => {
      low[0] = Math.min(low[0], p[0]); low[1] = Math.min(low[1], p[1]);
      high[0] = Math.max(high[0], p[0]); high[1] = Math.max(high[1], p[1]);
    };
    this.scene.material?.polygon.forEach(add);
    this.scene.lines.forEach((l) => l.points.forEach(add));
    return { low, high };
  }

  fit() {
    if (!this.scene) return;
    const { low, high } = this.bounds();
    const width = this.canvas.clientWidth || 600;
    const height = this.canvas.clientHeight || 400;
    const span = [Math.max(high[0] - low[0], 1e-6), Math.max(high[1] - low[1], 1e-6)];
    this.view = { cx: (low[0] + high[0]) / 2, cy: (low[1] + high[1]) / 2, scale: 0.9 * Math.min(width / span[0], height / span[1]) };
  }

  // Centres the view on `point` with `span` mm across the smaller side.
  focus(point, span) {
    const size = Math.min(this.canvas.clientWidth, this.canvas.clientHeight) || 400;
    this.view = { cx: point[0], cy: point[1], scale: size / span };
    this.draw();
  }

  toScreen(p) {
    return [this.width / 2 + (p[0] - this.view.cx) * this.view.scale, this.height / 2 - (p[1] - this.view.cy) * this.view.scale];
  }

  toWorld(x, y) {
    return [this.view.cx + (x - this.width / 2) / this.view.scale, this.view.cy - (y - this.height / 2) / this.view.scale];
  }

  draw() {
    const canvas = this.canvas;
    const ratio = window.devicePixelRatio || 1;
    this.width = canvas.clientWidth;
    this.height = canvas.clientHeight;
    if (canvas.width !== Math.round(this.width * ratio) || canvas.height !== Math.round(this.height * ratio)) {
      canvas.width = Math.round(this.width * ratio);
      canvas.height = Math.round(this.height * ratio);
    }
    const g = canvas.getContext('2d');
    g.setTransform(ratio, 0, 0, ratio, 0, 0);
    g.fillStyle = '#ffffff';
    g.fillRect(0, 0, this.width, this.height);
    if (!this.scene || !this.view) {
      canvas.dataset.state = 'empty';
      return;
    }
    const material = this.scene.material;
    if (material && material.polygon.length > 2) {
      g.beginPath();
      if (material.inside) g.rect(0, 0, this.width, this.height); // a pocket: material all round
      material.polygon.forEach((p, i) => {
        const [x, y] = this.toScreen(p);
        if (i === 0) g.moveTo(x, y); else g.lineTo(x, y);
      });
      g.closePath();
      g.fillStyle = (this.scene.material.colour || '#d9dde2');
      g.fill('evenodd');
      g.strokeStyle = (this.scene.material.outline || '#1d2327');
      g.lineWidth = 2;
      g.stroke();
    }
    let segments = 0;
    for (const line of this.scene.lines) {
      if (line.points.length < 2) continue;
      g.strokeStyle = line.colour;
      g.lineWidth = line.width || 2;
      g.setLineDash(line.dash || []);
      g.beginPath();
      line.points.forEach((p, i) => {
        const [x, y] = this.toScreen(p);
        if (i === 0) g.moveTo(x, y); else { g.lineTo(x, y); segments++; }
      });
      g.stroke();
      if (line.arrows) this.drawArrows(g, line);
    }
    g.setLineDash([]);
    if (this.tool) {
      const [x, y] = this.toScreen(this.tool.at);
      const [edge] = this.toScreen([this.tool.at[0] + this.tool.radius, this.tool.at[1]]);
      g.beginPath();
      g.arc(x, y, Math.max(3, Math.abs(edge - x)), 0, 2 * Math.PI);
      g.fillStyle = 'rgba(196, 127, 23, 0.35)';
      g.fill();
      g.strokeStyle = '#c47f17';
      g.lineWidth = 2;
      g.stroke();
    }
    for (const mark of this.scene.marks) {
      const [x, y] = this.toScreen(mark.at);
      g.beginPath();
      g.arc(x, y, mark.size || 5, 0, 2 * Math.PI);
      if (mark.ring) {
        g.strokeStyle = mark.colour;
        g.lineWidth = 2.5;
        g.stroke();
      } else {
        g.fillStyle = mark.colour;
        g.fill();
      }
    }
    this.drawLegend(g);
    this.drawScale(g);
    canvas.dataset.state = 'drawn';
    canvas.dataset.segments = String(segments);
    canvas.dataset.scale = this.view.scale.toFixed(3);
  }

  // The tool (a circle of `radius` at `at`, plan coordinates), or none for null.
  setTool(at, radius) {
    this.tool = at ? { at, radius } : null;
    this.canvas.dataset.tool = at ? at.map((v) => v.toFixed(3)).join(' ') : '';
    this.draw();
  }

  // Arrowheads along a line about every 90 px, pointing the way it is cut.
  drawArrows(g, line) {
    let travelled = 45;
    g.fillStyle = line.colour;
    for (let i = 1; i < line.points.length; i++) {
      const [ax, ay] = this.toScreen(line.points[i - 1]);
      const [bx, by] = this.toScreen(line.points[i]);
      const length = Math.hypot(bx - ax, by - ay);
      let at = 90 - travelled;
      while (at <= length) {
        const [ux, uy] = [(bx - ax) / length, (by - ay) / length];
        const [x, y] = [ax + ux * at, ay + uy * at];
        g.beginPath();
        g.moveTo(x + ux * 6, y + uy * 6);
        g.lineTo(x - ux * 5 - uy * 5, y - uy * 5 + ux * 5);
        g.lineTo(x - ux * 5 + uy * 5, y - uy * 5 - ux * 5);
        g.closePath();
        g.fill();
        at += 90;
      }
      travelled = (travelled + length) % 90;
    }
  }

  drawLegend(g) {
    g.font = '15px sans-serif';
    let y = 22;
    for (const [label, colour, dash] of this.scene.legend || []) {
      g.strokeStyle = colour;
      g.lineWidth = 4;
      g.setLineDash(dash || []);
      g.beginPath();
      g.moveTo(12, y - 5);
      g.lineTo(34, y - 5);
      g.stroke();
      g.setLineDash([]);
      g.fillStyle = '#1d2327';
      g.fillText(label, 42, y);
      y += 21;
    }
  }

  // A scale bar of a round length at the bottom right.
  drawScale(g) {
    const target = 120 / this.view.scale;
    const power = 10 ** Math.floor(Math.log10(target));
    const length = [1, 2, 5, 10].map((k) => k * power).filter((l) => l <= target).pop() || power;
    const pixels = length * this.view.scale;
    const x = this.width - 20 - pixels;
    const y = this.height - 20;
    g.strokeStyle = '#1d2327';
    g.lineWidth = 3;
    g.beginPath();
    g.moveTo(x, y);
    g.lineTo(x + pixels, y);
    g.stroke();
    g.fillStyle = '#1d2327';
    g.font = '14px sans-serif';
    g.fillText(`${length} mm`, x, y - 7);
  }
}

// ---------------------------------------------------------------- a tool on a plan

// A plan view (XY, equal scales, fitted) of a tool moving over stock: `rings` filled under the
// even-odd rule, `cells` (a raster: {origin, size, width, height, filled(i, j)}) filled,
// `removed` strokes ({points, width} in mm) cleared to white, the `path` ([{at, colour, dashed,
// heading, arcs}] per point, each stretch in its end point's colour) and a colour `legend`.
// `cursor(i)` draws the tool circle of `radius` at path point i with its engaged `arcs` (tool
// angle: 0° right of travel, 90° ahead) in red and the travel direction; `nearest(event)` finds
// the path point under the pointer.
export class ToolPlan {
  constructor(canvas, spec) {
    this.canvas = canvas;
    this.spec = spec;
    const low = [Infinity, Infinity];
    const high = [-Infinity, -Infinity];
    const include = (p) => {
      low[0] = Math.min(low[0], p[0]); low[1] = Math.min(low[1], p[1]);
      high[0] = Math.max(high[0], p[0]); high[1] = Math.max(high[1], p[1]);
    };
    spec.rings.flat().forEach(include);
    if (spec.cells) {
      include(spec.cells.origin);
      include([spec.cells.origin[0] + spec.cells.width * spec.cells.size, spec.cells.origin[1] + spec.cells.height * spec.cells.size]);
    }
    spec.path.forEach((p) => include(p.at));
    this.low = [low[0] - spec.radius, low[1] - spec.radius];
    this.high = [high[0] + spec.radius, high[1] + spec.radius];
    this.draw();
  }

  draw() {
    const { rings, cells, removed, path, legend } = this.spec;
    const spanX = this.high[0] - this.low[0] || 1;
    const spanY = this.high[1] - this.low[1] || 1;
    const wanted = Math.max(280, this.canvas.clientWidth || 600);
    this.canvas.style.height = `${Math.max(180, Math.min(520, wanted * spanY / spanX + 20))}px`;
    const [g, width, height] = sizeCanvas(this.canvas);
    const pad = 10;
    const scale = Math.min((width - 2 * pad) / spanX, (height - 2 * pad - 16) / spanY);
    const ox = pad + ((width - 2 * pad) - spanX * scale) / 2;
    const oy = height - pad - ((height - 2 * pad - 16) - spanY * scale) / 2;
    this.map = (p) => [ox + (p[0] - this.low[0]) * scale, oy - (p[1] - this.low[1]) * scale];
    this.scale = scale;
    // Stock: rings under even-odd, or the raster's material cells.
    g.fillStyle = '#d9dfe5';
    g.strokeStyle = '#5b6670';
    g.lineWidth = 1;
    if (rings.length) {
      g.beginPath();
      for (const ring of rings) {
        ring.forEach((p, i) => { const [x, y] = this.map(p); if (i) g.lineTo(x, y); else g.moveTo(x, y); });
        g.closePath();
      }
      g.fill('evenodd');
      g.stroke();
    }
    if (cells) {
      const size = Math.max(1, cells.size * scale);
      for (let j = 0; j < cells.height; j++) {
        for (let i = 0; i < cells.width; i++) {
          if (!cells.filled(i, j)) continue;
          const [x, y] = this.map([cells.origin[0] + i * cells.size, cells.origin[1] + (j + 1) * cells.size]);
          g.fillRect(x, y, size, size);
        }
      }
    }
    // Material already removed (earlier cuts).
    g.save();
    g.strokeStyle = '#fff';
    g.lineCap = 'round';
    g.lineJoin = 'round';
    for (const cut of removed) {
      g.lineWidth = Math.max(1, cut.width * scale);
      g.beginPath();
      cut.points.forEach((p, i) => { const [x, y] = this.map(p); if (i) g.lineTo(x, y); else g.moveTo(x, y); });
      g.stroke();
    }
    g.restore();
    // The path, each stretch in its end point's colour, and its start.
    g.lineWidth = 3;
    g.lineCap = 'round';
    for (let i = 1; i < path.length; i++) {
      g.strokeStyle = path[i].colour;
      g.setLineDash(path[i].dashed ? [4, 4] : []);
      const [x0, y0] = this.map(path[i - 1].at);
      const [x1, y1] = this.map(path[i].at);
      g.beginPath();
      g.moveTo(x0, y0);
      g.lineTo(x1, y1);
      g.stroke();
    }
    g.setLineDash([]);
    if (path.length) {
      const [x, y] = this.map(path[0].at);
      g.fillStyle = '#1d2327';
      g.beginPath();
      g.arc(x, y, 4, 0, 2 * Math.PI);
      g.fill();
    }
    // The colour legend as swatches along the top.
    g.font = '12px system-ui, sans-serif';
    g.textBaseline = 'top';
    let lx = pad;
    for (const item of legend || []) {
      g.fillStyle = item.colour;
      g.fillRect(lx, 4, 14, 10);
      g.fillStyle = '#1d2327';
      g.fillText(item.label, lx + 17, 3);
      lx += g.measureText(item.label).width + 30;
    }
    this.image = g.getImageData(0, 0, this.canvas.width, this.canvas.height);
    this.canvas.dataset.state = 'drawn';
  }

  // The tool circle at path point `index` (undefined: none), its engaged arcs in red and the
  // travel direction.
  cursor(index) {
    const g = this.canvas.getContext('2d');
    g.putImageData(this.image, 0, 0);
    if (index === undefined) {
      delete this.canvas.dataset.cursor;
      return;
    }
    const ratio = window.devicePixelRatio || 1;
    g.setTransform(ratio, 0, 0, ratio, 0, 0);
    this.canvas.dataset.cursor = String(index);
    const point = this.spec.path[index];
    const [cx, cy] = this.map(point.at);
    const r = this.spec.radius * this.scale;
    const heading = point.heading * Math.PI / 180;
    const t = [Math.cos(heading), Math.sin(heading)];
    // Tool angle θ → global angle θ + the angle of the right-hand normal; canvas y is down.
    const rightAngle = Math.atan2(-t[0], t[1]);
    g.strokeStyle = '#1d2327';
    g.lineWidth = 1.5;
    g.beginPath();
    g.arc(cx, cy, r, 0, 2 * Math.PI);
    g.stroke();
    g.strokeStyle = '#d0021b';
    g.lineWidth = 5;
    for (const [from, to] of point.arcs || []) {
      g.beginPath();
      g.arc(cx, cy, r, -(rightAngle + from * Math.PI / 180), -(rightAngle + to * Math.PI / 180), true);
      g.stroke();
    }
    g.strokeStyle = '#1d2327';
    g.lineWidth = 2;
    g.beginPath();
    g.moveTo(cx, cy);
    g.lineTo(cx + t[0] * r * 1.3, cy - t[1] * r * 1.3);
    g.stroke();
  }

  nearest(event) {
    const box = this.canvas.getBoundingClientRect();
    const [mx, my] = [event.clientX - box.left, event.clientY - box.top];
    let best;
    let bestDistance = 400;
    this.spec.path.forEach((p, i) => {
      const [x, y] = this.map(p.at);
      const d = (x - mx) ** 2 + (y - my) ** 2;
      if (d < bestDistance) { bestDistance = d; best = i; }
    });
    return best;
  }
}

// ---------------------------------------------------------------- charts along a path

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
    g.fillText(item.label, x + 26, y);
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
    g.fillText(spec.xLabel || '', (left + right) / 2, height - 2);
    const vertical = (text, x) => {
      g.save();
      g.translate(x, (top + bottom) / 2);
      g.rotate(-Math.PI / 2);
      g.textBaseline = 'top';
      g.fillText(text, 0, 0);
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
    g.fillText(fitText(g, spec.title, width - 16), Math.min(left, width < 520 ? 8 : left), legendHeight + 18);
    g.textAlign = 'center';
    g.fillText(spec.xLabel || '', (left + right) / 2, full - 2);
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

// ---------------------------------------------------------------- colour scales

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

// ---------------------------------------------------------------- 3-D scene

// Grid spacing in mm for a scene `extent` mm across: 1, 2 or 5 times a power of ten, about 20 lines.
function gridStep(extent) {
  const raw = extent / 20;
  const power = 10 ** Math.floor(Math.log10(raw));
  return [1, 2, 5, 10].map((m) => m * power).find((s) => s >= raw);
}

function vector(p) {
  return new THREE.Vector3(p[0], p[1], p[2] ?? 0);
}

// Whether this browser can draw WebGL (a headless or locked-down browser may not).
function webglAvailable() {
  try {
    const canvas = document.createElement('canvas');
    return Boolean(canvas.getContext('webgl2') || canvas.getContext('webgl'));
  } catch (error) {
    return false;
  }
}

// A 3-D scene in `container`: a toolbar (view presets, zoom to fit), the WebGL canvas (drag to
// rotate, right-drag to pan, wheel to zoom; focused, the arrow keys rotate and +/- zoom) and a
// legend. Machine Z is up. `presets` adds named view directions, e.g. {label: 'Along hole axis',
// direction: [x, y, z]} (the direction the camera looks from).
export class Scene3D {
  constructor(container, { label, presets = [] } = {}) {
    this.root = document.createElement('div');
    this.root.className = 'scene';
    this.root.setAttribute('role', 'group');
    this.root.setAttribute('aria-label', label);
    container.append(this.root);
    this.names = [];
    this.segments = 0;
    this.box = new THREE.Box3();
    if (!webglAvailable()) {
      this.root.dataset.state = 'no-webgl';
      this.root.append(Object.assign(document.createElement('p'), { className: 'message warning', textContent: 'This browser cannot draw 3-D (WebGL is off). The numbers and the G-code are unaffected.' }));
      return;
    }
    const bar = document.createElement('div');
    bar.className = 'scene-bar';
    const views = [
      { label: 'Top', direction: [0, 0, 1] },
      { label: 'Front', direction: [0, -1, 0] },
      { label: 'Iso', direction: [1, -1.2, 0.9] },
      ...presets,
    ];
    for (const preset of views) {
      const button = document.createElement('button');
      button.type = 'button';
      button.className = 'secondary small';
      button.textContent = preset.label;
      button.addEventListener('click', () => this.look(preset.direction));
      bar.append(button);
    }
    const fit = document.createElement('button');
    fit.type = 'button';
    fit.className = 'secondary small';
    fit.textContent = 'Zoom to fit';
    fit.addEventListener('click', () => this.fit());
    bar.append(fit);
    this.legend = document.createElement('ul');
    this.legend.className = 'legend';
    this.root.append(bar);

    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setClearColor(0xffffff);
    this.canvas = this.renderer.domElement;
    this.canvas.className = 'plot';
    this.canvas.tabIndex = 0;
    this.canvas.setAttribute('role', 'img');
    this.canvas.setAttribute('aria-label', `${label}. Arrow keys rotate, + and − zoom.`);
    this.root.append(this.canvas, this.legend);
    this.scene = new THREE.Scene();
    this.scene.add(new THREE.AmbientLight(0xffffff, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 2);
    sun.position.set(1, -2, 3);
    this.scene.add(sun);
    this.camera = new THREE.OrthographicCamera(-1, 1, 1, -1, -1e5, 1e5);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.addEventListener('change', () => this.render());
    this.canvas.addEventListener('keydown', (e) => this.key(e));
    this.canvas.addEventListener('dblclick', () => this.fit());
    this.resize = new ResizeObserver(() => this.render());
    this.resize.observe(this.canvas);
    this.direction = views[2].direction;
  }

  // Names of what the scene shows, for tests and assistive text.
  note(name, legend, colour) {
    if (!this.names.includes(name)) this.names.push(name);
    this.root.dataset.objects = this.names.join(' ');
    if (legend) {
      const item = document.createElement('li');
      const swatch = document.createElement('span');
      swatch.className = 'swatch';
      swatch.style.background = colour;
      item.append(swatch, legend);
      this.legend.append(item);
    }
  }

  add(name, object, legend, colour) {
    if (!this.scene) return null;
    object.name = name;
    this.scene.add(object);
    if (!name.startsWith('tool')) this.box.expandByObject(object);
    this.note(name, legend, colour);
    return object;
  }

  // A see-through solid (BufferGeometry in machine coordinates, or with `matrix`).
  solid(name, geometry, { colour = '#8fa3b5', opacity = 0.25, legend, matrix, edges = true } = {}) {
    if (!this.scene) return null;
    const mesh = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial({
      color: colour, transparent: true, opacity, side: THREE.DoubleSide, depthWrite: false,
    }));
    if (matrix) mesh.applyMatrix4(matrix);
    if (edges) mesh.add(new THREE.LineSegments(new THREE.EdgesGeometry(geometry, 30), new THREE.LineBasicMaterial({ color: colour, transparent: true, opacity: Math.min(1, opacity * 2.5) })));
    return this.add(name, mesh, legend, colour);
  }

  // A polyline; `colours` (one CSS colour per point) colours each segment by its end point;
  // `arrows` (a spacing in mm) adds cones pointing the way the path runs.
  path(name, points, { colour = '#0b63b6', colours, dashed = false, legend, arrows } = {}) {
    if (!this.scene || points.length < 2) return null;
    const geometry = new THREE.BufferGeometry().setFromPoints(points.map(vector));
    let material;
    if (colours) {
      geometry.setAttribute('color', new THREE.Float32BufferAttribute(colours.flatMap((c) => new THREE.Color(c).toArray()), 3));
      material = new THREE.LineBasicMaterial({ vertexColors: true });
    } else if (dashed) {
      material = new THREE.LineDashedMaterial({ color: colour, dashSize: 1, gapSize: 0.6 });
    } else {
      material = new THREE.LineBasicMaterial({ color: colour });
    }
    const line = new THREE.Line(geometry, material);
    if (dashed) line.computeLineDistances();
    if (arrows > 0) this.arrows(line, points, arrows, colour);
    this.segments += points.length - 1;
    return this.add(name, line, legend, colour);
  }

  // Cones every `spacing` mm along `points`, children of `line`.
  arrows(line, points, spacing, colour) {
    const material = new THREE.MeshLambertMaterial({ color: colour });
    const cone = new THREE.ConeGeometry(spacing / 7, spacing / 2.5, 12);
    const up = new THREE.Vector3(0, 1, 0);
    let travelled = spacing / 2;
    for (let i = 1; i < points.length; i++) {
      const [a, b] = [vector(points[i - 1]), vector(points[i])];
      const length = a.distanceTo(b);
      const direction = b.clone().sub(a).normalize();
      for (let at = spacing - travelled; at <= length; at += spacing) {
        const arrow = new THREE.Mesh(cone, material);
        arrow.position.copy(a).addScaledVector(direction, at);
        arrow.quaternion.setFromUnitVectors(up, direction);
        line.add(arrow);
      }
      travelled = (travelled + length) % spacing;
    }
  }

  // Small dots at points.
  dots(name, points, { colour = '#0b63b6', size = 4, legend } = {}) {
    if (!this.scene || !points.length) return null;
    const geometry = new THREE.BufferGeometry().setFromPoints(points.map(vector));
    return this.add(name, new THREE.Points(geometry, new THREE.PointsMaterial({ color: colour, size, sizeAttenuation: false })), legend, colour);
  }

  // The tool: a ball of `radius` (or a flat end of that radius), a neck of `neck` radius and
  // `neckLength`, a shank above, its head in `colour` (red for a refused program); `moveTool`
  // puts its ball centre (or a flat tool's tip) at a point.
  tool({ radius, kind = 'ball', neck, neckLength, shank, shankLength, colour = '#c47f17' }) {
    if (!this.scene) return;
    const group = new THREE.Group();
    // Lambert shading: cheap enough for software WebGL, which is what a PC without a GPU driver has.
    const metal = new THREE.MeshLambertMaterial({ color: colour });
    const steel = new THREE.MeshLambertMaterial({ color: '#6b7780', transparent: true, opacity: 0.85 });
    const upright = (geometry, z) => {
      geometry.rotateX(Math.PI / 2);
      geometry.translate(0, 0, z);
      return geometry;
    };
    let z = 0;
    if (kind === 'ball') {
      group.add(new THREE.Mesh(new THREE.SphereGeometry(radius, 32, 16), metal));
    } else {
      group.add(new THREE.Mesh(upright(new THREE.CylinderGeometry(radius, radius, radius, 32), radius / 2), metal));
      z = radius;
    }
    const neckRadius = neck ?? radius;
    const neckTall = neckLength ?? (neck ? 3 * radius : 0);
    if (neckTall > 0) group.add(new THREE.Mesh(upright(new THREE.CylinderGeometry(neckRadius, neckRadius, neckTall, 24), z + neckTall / 2), steel));
    const shankRadius = shank ?? radius;
    const shankTall = shankLength ?? 6 * radius;
    group.add(new THREE.Mesh(upright(new THREE.CylinderGeometry(shankRadius, shankRadius, shankTall, 24), z + neckTall + shankTall / 2), steel));
    group.visible = false;
    this.toolParts = { metal, steel, colour };
    this.toolObject = this.add('tool', group, kind === 'ball' ? 'tool (ball, neck, shank)' : 'tool', colour);
  }

  // Draws the whole tool red while it is somewhere it must not be (`hit`), else in its colours.
  markTool(hit) {
    if (!this.toolParts) return;
    const { metal, steel, colour } = this.toolParts;
    metal.color.set(hit ? '#d50000' : colour);
    steel.color.set(hit ? '#d50000' : '#6b7780');
    this.root.dataset.toolHit = String(Boolean(hit));
    this.render();
  }

  // Puts the tool's ball centre (flat: tip) at `p`, or hides it for null.
  moveTool(p) {
    if (!this.toolObject) return;
    this.toolObject.visible = Boolean(p);
    if (p) this.toolObject.position.copy(vector(p));
    this.root.dataset.tool = p ? p.map((v) => v.toFixed(3)).join(' ') : '';
    this.render();
  }

  // Adds the mm grid in the XY plane under everything and the axes, then fits. Call once the
  // scene has its objects.
  finish() {
    if (!this.scene) return;
    if (this.box.isEmpty()) this.box.set(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
    const size = this.box.getSize(new THREE.Vector3());
    const centre = this.box.getCenter(new THREE.Vector3());
    const extent = Math.max(size.x, size.y, size.z, 1e-6);
    const step = gridStep(extent * 1.2);
    const span = Math.ceil((Math.max(size.x, size.y) * 1.2) / step / 2) * 2 * step;
    const grid = new THREE.GridHelper(span, Math.round(span / step), 0x9aa5ae, 0xd5dbe0);
    grid.rotation.x = Math.PI / 2;
    grid.position.set(Math.round(centre.x / step) * step, Math.round(centre.y / step) * step, this.box.min.z);
    this.scene.add(grid);
    this.note('grid', `grid ${step} mm`, '#d5dbe0');
    const axes = new THREE.AxesHelper(step * 3);
    axes.position.set(grid.position.x - span / 2, grid.position.y - span / 2, this.box.min.z);
    this.scene.add(axes);
    this.note('axes', 'axes X red, Y green, Z blue', 'linear-gradient(90deg, #e53935 33%, #43a047 33% 66%, #1e63d6 66%)');
    this.root.dataset.segments = String(this.segments);
    this.look(this.direction);
    this.root.dataset.state = 'drawn';
  }

  // Looks at the scene from `direction` and zooms to fit.
  look(direction) {
    if (!this.scene) return;
    this.direction = direction;
    const d = vector(direction).normalize();
    this.camera.up.set(0, 0, 1);
    if (Math.abs(d.z) > 0.999) this.camera.up.set(0, 1, 0);
    this.fit();
  }

  fit() {
    if (!this.scene) return;
    const centre = this.box.getCenter(new THREE.Vector3());
    const radius = Math.max(this.box.getBoundingSphere(new THREE.Sphere()).radius, 1e-6);
    const d = vector(this.direction).normalize();
    this.controls.target.copy(centre);
    this.camera.position.copy(centre).addScaledVector(d, radius * 4);
    this.camera.zoom = 1;
    this.radius = radius;
    this.camera.lookAt(centre);
    this.controls.update();
    this.render();
  }

  key(event) {
    const turn = { ArrowLeft: [-0.1, 0], ArrowRight: [0.1, 0], ArrowUp: [0, -0.1], ArrowDown: [0, 0.1] }[event.key];
    if (turn) {
      const offset = this.camera.position.clone().sub(this.controls.target);
      const spherical = new THREE.Spherical().setFromVector3(new THREE.Vector3(offset.x, offset.z, -offset.y));
      spherical.theta += turn[0];
      spherical.phi = Math.max(0.01, Math.min(Math.PI - 0.01, spherical.phi + turn[1]));
      const v = new THREE.Vector3().setFromSpherical(spherical);
      this.camera.position.copy(this.controls.target).add(new THREE.Vector3(v.x, -v.z, v.y));
      this.camera.lookAt(this.controls.target);
    } else if (event.key === '+' || event.key === '=') {
      this.camera.zoom *= 1.2;
    } else if (event.key === '-') {
      this.camera.zoom /= 1.2;
    } else {
      return;
    }
    event.preventDefault();
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() {
    if (!this.renderer || !this.canvas.isConnected) return;
    const width = this.canvas.clientWidth;
    const height = this.canvas.clientHeight;
    if (!width || !height) return;
    const size = this.renderer.getSize(new THREE.Vector2());
    if (size.x !== width || size.y !== height) this.renderer.setSize(width, height, false);
    const r = (this.radius || 1) * 1.2;
    const aspect = width / height;
    Object.assign(this.camera, aspect > 1
      ? { left: -r * aspect, right: r * aspect, top: r, bottom: -r }
      : { left: -r, right: r, top: r / aspect, bottom: -r / aspect });
    this.camera.updateProjectionMatrix();
    this.renderer.render(this.scene, this.camera);
  }
}

export { THREE };
