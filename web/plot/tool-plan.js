// The engagement view's plan: a tool moving over stock, always fitted to the canvas (it has no
// pan or zoom), with the tool's engaged arcs at a cursor.
import { canvasText } from '/units.js';
import { sizeCanvas } from '/plot/canvas.js';

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
      const label = canvasText(g.canvas, item.label);
      g.fillText(label, lx + 17, 3);
      lx += g.measureText(label).width + 30;
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

