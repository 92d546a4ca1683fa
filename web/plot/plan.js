// Plan views (XY, y up, equal scales) that the user can move: one pan and zoom for all of them
// (drag to pan, wheel to zoom about the pointer, double-click to fit; focused, arrow keys pan,
// + and − zoom, 0 fits), and what each draws: a curve and its blocks (CurvePlan) or a contour
// with its material, passes, corner marks and tool (ContourPlan).
import { canvasText } from '/units.js';
import { FONT, legend, roundLength, sizeCanvas } from '/plot/canvas.js';

// Makes a plan usable from the keyboard: focusable; arrow keys pan, + and − zoom, 0 fits.
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

// A plan on `canvas` with its pan and zoom. The view is the plan point at the middle of the
// drawing area (`cx`, `cy`, mm) and `scale` (px per mm). Until the user moves it the view fits
// the drawing, also after a resize; once moved it stays where the user put it.
//
// A kind of plan says what it draws by overriding: `hasDrawing()`, `bounds()` ({low, high} in mm),
// `margins()` ({top, bottom}: CSS pixels kept free of the drawing, e.g. for a legend), `fill`
// (the share of the free area a fitted drawing takes) and `paint(g)` (drawing with `toScreen`).
export class PlanView {
  constructor(canvas) {
    this.canvas = canvas;
    this.view = null;
    this.fitted = true;
    this.shift = 0;
    this.fill = 0.9;
    let drag = null;
    const moved = () => { this.fitted = false; this.draw(); };
    canvas.addEventListener('pointerdown', (e) => {
      drag = { x: e.clientX, y: e.clientY };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag || !this.view) return;
      this.view.cx -= (e.clientX - drag.x) / this.view.scale;
      this.view.cy += (e.clientY - drag.y) / this.view.scale;
      drag = { x: e.clientX, y: e.clientY };
      moved();
    });
    canvas.addEventListener('pointerup', () => { drag = null; });
    canvas.addEventListener('wheel', (e) => {
      if (!this.view) return;
      e.preventDefault();
      // Zoom about the pointer: the plan point under it stays put.
      const box = canvas.getBoundingClientRect();
      const [x, y] = [e.clientX - box.left, e.clientY - box.top];
      const before = this.toWorld(x, y);
      this.view.scale *= Math.exp(-e.deltaY * 0.0015);
      const after = this.toWorld(x, y);
      this.view.cx += before[0] - after[0];
      this.view.cy += before[1] - after[1];
      moved();
    }, { passive: false });
    canvas.addEventListener('dblclick', () => { this.fitted = true; this.draw(); });
    keyboard(canvas, {
      pan: (dx, dy) => { this.view.cx += dx * 40 / this.view.scale; this.view.cy -= dy * 40 / this.view.scale; this.fitted = false; },
      zoom: (factor) => { this.view.scale *= factor; this.fitted = false; },
      reset: () => { this.fitted = true; },
      ready: () => Boolean(this.view) && this.hasDrawing(),
      draw: () => this.draw(),
    });
    new ResizeObserver(() => this.draw()).observe(canvas);
  }

  hasDrawing() {
    return false;
  }

  margins() {
    return { top: 0, bottom: 0 };
  }

  // The view that shows all of `bounds()` in the free area, centred.
  fit() {
    const { top, bottom } = this.margins();
    const { low, high } = this.bounds();
    const width = this.width || this.canvas.clientWidth || 600;
    const height = (this.height || this.canvas.clientHeight || 400) - top - bottom;
    const [dx, dy] = [high[0] - low[0], high[1] - low[1]];
    // A straight line has no height (or width): fit its length, not the nothing across it.
    const least = Math.max(dx, dy, 1e-9) * 1e-3;
    const scale = this.fill * Math.min(width / Math.max(dx, least), height / Math.max(dy, least));
    this.view = { cx: (low[0] + high[0]) / 2, cy: (low[1] + high[1]) / 2, scale };
  }

  // Centres the view on `point` with `span` mm across the smaller side.
  focus(point, span) {
    const size = Math.min(this.canvas.clientWidth, this.canvas.clientHeight) || 400;
    this.view = { cx: point[0], cy: point[1], scale: size / span };
    this.fitted = false;
    this.draw();
  }

  toScreen(p) {
    return [this.width / 2 + (p[0] - this.view.cx) * this.view.scale, this.height / 2 + this.shift - (p[1] - this.view.cy) * this.view.scale];
  }

  toWorld(x, y) {
    return [this.view.cx + (x - this.width / 2) / this.view.scale, this.view.cy - (y - this.height / 2 - this.shift) / this.view.scale];
  }

  draw() {
    const [g, width, height] = sizeCanvas(this.canvas);
    this.width = width;
    this.height = height;
    if (!this.hasDrawing()) {
      this.canvas.dataset.state = 'empty';
      return;
    }
    const { top, bottom } = this.margins();
    this.shift = (top - bottom) / 2;
    if (this.fitted || !this.view) this.fit();
    this.paint(g);
    this.canvas.dataset.state = 'drawn';
    this.canvas.dataset.scale = this.view.scale.toFixed(3);
  }
}

// A plan of polylines, e.g. a curve and the blocks that cut it, with a marker at the timeline's
// position, a legend above the drawing and a scale bar below it.
// series: [{label, points: [[x, y, ...], ...], colour, width, dash, marks (square size), count
// (its segments are the ones counted in data-segments), segments: [i, ...]}]; `segments` draws
// only the listed pieces (i to i + 1) of `points`, for highlighting.
export class CurvePlan extends PlanView {
  constructor(canvas) {
    super(canvas);
    this.series = [];
    this.fill = 0.94;
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

  hasDrawing() {
    return this.series.some((s) => s.points.length);
  }

  bounds() {
    return { low: this.low, high: this.high };
  }

  // The legend takes the top rows, the scale bar the bottom one: the drawing fits between.
  margins() {
    return { top: 14 + 20 * this.series.filter((s) => s.label).length, bottom: 34 };
  }

  paint(g) {
    let segments = 0;
    for (const s of this.series) {
      g.strokeStyle = s.colour;
      g.fillStyle = s.colour;
      g.lineWidth = s.width || 1.5;
      g.setLineDash(s.dash || []);
      g.beginPath();
      if (s.segments) {
        for (const i of s.segments) {
          const [ax, ay] = this.toScreen(s.points[i]);
          const [bx, by] = this.toScreen(s.points[i + 1]);
          g.moveTo(ax, ay);
          g.lineTo(bx, by);
        }
      } else {
        s.points.forEach((p, i) => {
          const [x, y] = this.toScreen(p);
          if (i === 0) g.moveTo(x, y); else { g.lineTo(x, y); if (s.count) segments++; }
        });
      }
      g.stroke();
      g.setLineDash([]);
      if (s.marks) {
        const size = s.marks;
        for (const p of s.points) {
          const [x, y] = this.toScreen(p);
          if (x > -size && y > -size && x < this.width + size && y < this.height + size) g.fillRect(x - size / 2, y - size / 2, size, size);
        }
      }
    }
    if (this.marker) {
      const [x, y] = this.toScreen(this.marker);
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
    this.canvas.dataset.segments = String(segments);
  }

  // A scale bar of a round length, bottom left.
  drawScale(g) {
    const scale = this.view.scale;
    const length = roundLength(120 / scale);
    const x = 16;
    const y = this.height - 18;
    g.strokeStyle = '#222';
    g.lineWidth = 2;
    g.beginPath();
    g.moveTo(x, y - 5); g.lineTo(x, y); g.lineTo(x + length * scale, y); g.lineTo(x + length * scale, y - 5);
    g.stroke();
    g.fillStyle = '#222';
    g.font = FONT;
    g.fillText(canvasText(g.canvas, `${length < 1 ? length.toPrecision(1) : length} mm`), x + length * scale + 6, y);
  }
}

// A plan of a contour being milled: the material (grey; for a pocket, all round the polygon), the
// moves, corner marks, the tool at the timeline's position, a legend and a scale bar.
// scene = {material: {polygon, inside, colour, outline}, lines: [{points, colour, width, dash,
// arrows}], marks: [{at, colour, size, ring}], legend: [[label, colour, dash], ...]}.
export class ContourPlan extends PlanView {
  constructor(canvas) {
    super(canvas);
    this.scene = null;
  }

  // Shows `scene`, fitted, or (`keepView`) where the view already is, e.g. another layer of the
  // same part seen at the same place.
  setScene(scene, keepView = false) {
    this.scene = scene;
    this.fitted = !keepView || !this.view;
    this.draw();
  }

  // The tool (a circle of `radius` at `at`, plan coordinates), or none for null.
  setTool(at, radius) {
    this.tool = at ? { at, radius } : null;
    this.canvas.dataset.tool = at ? at.map((v) => v.toFixed(3)).join(' ') : '';
    this.draw();
  }

  hasDrawing() {
    return Boolean(this.scene);
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

  paint(g) {
    const material = this.scene.material;
    if (material && material.polygon.length > 2) {
      g.beginPath();
      if (material.inside) g.rect(0, 0, this.width, this.height); // a pocket: material all round
      material.polygon.forEach((p, i) => {
        const [x, y] = this.toScreen(p);
        if (i === 0) g.moveTo(x, y); else g.lineTo(x, y);
      });
      g.closePath();
      g.fillStyle = material.colour || '#d9dde2';
      g.fill('evenodd');
      g.strokeStyle = material.outline || '#1d2327';
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
    this.canvas.dataset.segments = String(segments);
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
      g.fillText(canvasText(g.canvas, label), 42, y);
      y += 21;
    }
  }

  // A scale bar of a round length at the bottom right.
  drawScale(g) {
    const length = roundLength(120 / this.view.scale);
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
    g.fillText(canvasText(g.canvas, `${length} mm`), x, y - 7);
  }
}
