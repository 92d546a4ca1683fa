// kerf: a small 3-D line plot on a plain canvas (orthographic, drag to rotate, wheel to zoom,
// shift-drag to pan, double-click to reset). No dependencies, so the page works offline.

export class Plot3D {
  constructor(canvas) {
    this.canvas = canvas;
    this.series = [];
    this.reset();
    this.drag = null;
    canvas.addEventListener('pointerdown', (e) => {
      this.drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 1 };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!this.drag) return;
      const dx = e.clientX - this.drag.x;
      const dy = e.clientY - this.drag.y;
      this.drag.x = e.clientX;
      this.drag.y = e.clientY;
      if (this.drag.pan) {
        this.panX += dx;
        this.panY += dy;
      } else {
        this.yaw += dx * 0.01;
        this.pitch = Math.max(-Math.PI / 2, Math.min(Math.PI / 2, this.pitch + dy * 0.01));
      }
      this.draw();
    });
    canvas.addEventListener('pointerup', () => { this.drag = null; });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.zoom *= Math.exp(-e.deltaY * 0.0015);
      this.draw();
    }, { passive: false });
    canvas.addEventListener('dblclick', () => { this.reset(); this.draw(); });
    new ResizeObserver(() => this.draw()).observe(canvas);
  }

  reset() {
    this.yaw = -0.7;
    this.pitch = 0.6;
    this.zoom = 1;
    this.panX = 0;
    this.panY = 0;
  }

  // series: [{label, points: [[x, y, z], ...], colour, width, dash, marks, colours}]; with
  // `colours` (one per point) each segment and mark takes the colour of the point it ends at.
  setSeries(series) {
    this.series = series;
    const all = series.flatMap((s) => s.points);
    const low = [Infinity, Infinity, Infinity];
    const high = [-Infinity, -Infinity, -Infinity];
    for (const p of all) {
      for (let k = 0; k < 3; k++) {
        low[k] = Math.min(low[k], p[k]);
        high[k] = Math.max(high[k], p[k]);
      }
    }
    this.centre = low.map((l, k) => (l + high[k]) / 2);
    this.extent = Math.max(1e-9, ...high.map((h, k) => h - low[k]));
    this.draw();
  }

  // Rotated view coordinates (right, up, depth) of p relative to the centre, before scaling.
  view(p) {
    const [x, y, z] = [p[0] - this.centre[0], p[1] - this.centre[1], p[2] - this.centre[2]];
    const cy = Math.cos(this.yaw), sy = Math.sin(this.yaw);
    const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    // Machine Z points up on screen; yaw turns about Z, pitch tilts towards the viewer.
    const v = sy * x + cy * y;
    return [cy * x - sy * y, cp * z - sp * v, sp * z + cp * v];
  }

  // Fits the projected drawing into the canvas at the current rotation (zoom 1 = fit).
  fit() {
    let [left, right, bottom, top] = [Infinity, -Infinity, Infinity, -Infinity];
    for (const s of this.series) {
      for (const p of s.points) {
        const [u, up] = this.view(p);
        left = Math.min(left, u); right = Math.max(right, u);
        bottom = Math.min(bottom, up); top = Math.max(top, up);
      }
    }
    const spanX = Math.max(right - left, 1e-9 * this.extent, 1e-12);
    const spanY = Math.max(top - bottom, 1e-9 * this.extent, 1e-12);
    this.scale = 0.9 * Math.min(this.width / spanX, this.height / spanY);
    this.offset = [(left + right) / 2, (bottom + top) / 2];
  }

  project(p) {
    const [u, up, depth] = this.view(p);
    const scale = this.scale * this.zoom;
    return [this.width / 2 + this.panX + (u - this.offset[0]) * scale, this.height / 2 + this.panY - (up - this.offset[1]) * scale, depth];
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
    if (!this.series.length) {
      canvas.dataset.state = 'empty';
      return;
    }
    this.fit();
    this.drawAxes(g);
    let segments = 0;
    for (const s of this.series) {
      g.strokeStyle = s.colour;
      g.fillStyle = s.colour;
      g.lineWidth = s.width || 1.5;
      g.setLineDash(s.dash || []);
      if (s.colours) {
        let last = null;
        s.points.forEach((p, i) => {
          const at = this.project(p);
          if (last) {
            g.strokeStyle = s.colours[i];
            g.beginPath();
            g.moveTo(last[0], last[1]);
            g.lineTo(at[0], at[1]);
            g.stroke();
            segments++;
          }
          last = at;
        });
      } else {
        g.beginPath();
        s.points.forEach((p, i) => {
          const [sx, sy] = this.project(p);
          if (i === 0) g.moveTo(sx, sy); else { g.lineTo(sx, sy); segments++; }
        });
        g.stroke();
      }
      if (s.marks) {
        s.points.forEach((p, i) => {
          const [sx, sy] = this.project(p);
          if (s.colours) g.fillStyle = s.colours[i];
          g.fillRect(sx - 1.5, sy - 1.5, 3, 3);
        });
      }
    }
    g.setLineDash([]);
    this.drawLegend(g);
    canvas.dataset.state = 'drawn';
    canvas.dataset.segments = String(segments);
  }

  drawAxes(g) {
    const origin = [40, this.height - 40];
    const length = 28;
    const axes = [[[1, 0, 0], 'X', '#c0392b'], [[0, 1, 0], 'Y', '#27ae60'], [[0, 0, 1], 'Z', '#2c3e50']];
    const base = this.project(this.centre);
    for (const [direction, name, colour] of axes) {
      const tip = this.project(this.centre.map((c, k) => c + direction[k] * this.extent));
      const dx = tip[0] - base[0], dy = tip[1] - base[1];
      const norm = Math.hypot(dx, dy) || 1;
      const end = [origin[0] + dx / norm * length * Math.min(1, norm / 40 + 0.3), origin[1] + dy / norm * length * Math.min(1, norm / 40 + 0.3)];
      g.strokeStyle = colour;
      g.lineWidth = 2;
      g.beginPath();
      g.moveTo(origin[0], origin[1]);
      g.lineTo(end[0], end[1]);
      g.stroke();
      g.fillStyle = colour;
      g.font = '13px sans-serif';
      g.fillText(name, end[0] + 3, end[1] - 3);
    }
  }

  drawLegend(g) {
    g.font = '14px sans-serif';
    let y = 20;
    for (const s of this.series) {
      if (!s.label) continue;
      g.fillStyle = s.colour;
      g.fillRect(12, y - 9, 18, 4);
      g.fillStyle = '#222';
      g.fillText(s.label, 36, y - 3);
      y += 20;
    }
  }
}
