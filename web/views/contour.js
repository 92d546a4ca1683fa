// Contour view: layered contour milling with corner loops and inside-corner relief (api.md,
// Contour). A form, a 2-D plot of the contour and the tool-centre path of one layer (layer
// selector; loops, reliefs, links and corners in their own colours; wheel to zoom, drag to pan,
// double-click to fit), the corner table with the material left or over-cut, the summary, the
// warnings and the G-code download. `contourResult` also renders job results.
import { api } from '/api.js';
import { clearProblem, computed, computing, download, gcodeQuery, keepForm, loadMachines, loadTools, markComputed, message, number, numeric, programName, showProblem, showSummary, value, warningMessages } from '/form.js';

// An arrow-shaped island: five protruding corners (a 64° tip among them) and two inside corners.
const SAMPLE = `# x, y in mm, counter-clockwise; one point a line
0, 10
40, 10
40, 0
80, 25
40, 50
40, 40
0, 40`;

const FORM = `
<div class="layout">
  <form id="contour-form" novalidate>
    <fieldset><legend>Tool</legend>
      <label>Tool <select name="tool_choice" data-field="tool"></select></label>
      <label data-inline-tool>Radius, mm <input name="tool_radius" type="number" step="any" value="3" data-field="tool.radius"></label>
    </fieldset>
    <fieldset><legend>Contour</legend>
      <label class="stacked">Points <span class="hint">x, y a line; # comments</span>
        <textarea name="points" rows="9" spellcheck="false" data-field="contour"></textarea></label>
      <label>Side <select name="side" data-field="side">
        <option value="outside">outside (island, outer profile)</option><option value="inside">inside (pocket)</option></select></label>
      <label>Direction <select name="direction" data-field="direction"><option value="climb">climb</option><option value="conventional">conventional</option></select></label>
    </fieldset>
    <fieldset><legend>Depths</legend>
      <label>Top Z <input name="top" type="number" step="any" value="0" data-field="depths.top"></label>
      <label>Bottom Z <input name="bottom" type="number" step="any" value="-9" data-field="depths.bottom"></label>
      <label>Step <input name="step" type="number" step="any" value="3" data-field="depths.step"></label>
    </fieldset>
    <fieldset><legend>Corners</legend>
      <label>Loop style <select name="loop_style" data-field="corner_loop.style">
        <option value="arc">arc</option><option value="triangle">triangle</option><option value="parallelogram">parallelogram</option><option value="none">none</option></select></label>
      <label>Inside corners <select name="relief" data-field="inside_corner_relief">
        <option value="dogbone">dogbone relief</option><option value="tbone">T-bone relief</option><option value="none">none (fillet)</option></select></label>
      <label>Roughing pass <select name="roughing">
        <option value="0.3">0.3 mm, round joins</option><option value="">none</option></select></label>
    </fieldset>
    <fieldset><legend>Feeds</legend>
      <label>Feed, mm/min <input name="feed" type="number" step="any" value="800" data-field="feed"></label>
      <label>Loop feed <input name="loop_feed" type="number" step="any" value="2000" data-field="loop_feed"></label>
      <label>Stock allowance <input name="stock_allowance" type="number" step="any" value="0.5" data-field="stock_allowance"></label>
      <label>Machine <select name="machine" data-field="machine"></select></label>
      <label>Block time, ms <input name="block_time_ms" type="number" step="any" placeholder="machine's, else off" data-field="block_time_ms"></label>
      <label>Tolerance, mm <input name="tolerance" type="number" step="any" value="0.01" data-field="tolerance"></label>
    </fieldset>
    <div class="actions">
      <button class="primary" type="submit" id="contour-compute">Compute</button>
      <select name="dialect" aria-label="G-code dialect"><option value="">machine's dialect (else Fanuc)</option><option value="fanuc">Fanuc</option><option value="linuxcnc">LinuxCNC</option></select>
      <select name="reference" aria-label="Programmed point"><option value="tip">tip</option><option value="centre">centre</option></select>
      <button class="secondary" type="button" id="contour-gcode">G-code</button>
    </div>
  </form>
  <section>
    <div id="contour-messages"></div>
    <div id="contour-result"></div>
  </section>
</div>`;

// Colours: readable on a white background, told apart without relying on red/green alone.
const COLOUR = {
  material: '#d9dde2', contour: '#1d2327', cut: '#0b63b6', loop: '#e07000', link: '#2e7d32',
  rapid: '#8a949c', relief: '#8e24aa', convex: '#e07000', concave: '#8e24aa', unreached: '#b3261e',
};

// Parses "x, y" lines; returns {points} or {error, line}.
export function parsePoints(text) {
  const points = [];
  const lines = text.split('\n');
  for (let i = 0; i < lines.length; i++) {
    const line = lines[i].replace(/#.*/, '').trim();
    if (!line) continue;
    const parts = line.split(/[\s,;]+/).filter((p) => p !== '');
    const values = parts.map(Number);
    if (values.length !== 2 || values.some((v) => !Number.isFinite(v))) {
      return { error: `line ${i + 1}: "${lines[i].trim()}" is not "x, y"`, line: i + 1 };
    }
    points.push(values);
  }
  return { points };
}

// The request body from the form (field names as api.md); throws {error, line} for bad points.
export function contourRequest(form) {
  const parsed = parsePoints(value(form, 'points'));
  if (parsed.error) throw parsed;
  const choice = value(form, 'tool_choice');
  const tool = choice === 'inline' ? { kind: 'flat', radius: numeric(form, 'tool_radius') } : Number(choice);
  const body = {
    tool,
    contour: parsed.points,
    side: value(form, 'side'),
    direction: value(form, 'direction'),
    depths: { top: numeric(form, 'top'), bottom: numeric(form, 'bottom'), step: numeric(form, 'step') },
    corner_loop: { style: value(form, 'loop_style') },
    inside_corner_relief: value(form, 'relief'),
    feed: numeric(form, 'feed'),
  };
  if (value(form, 'machine')) body.machine = value(form, 'machine');
  for (const name of ['loop_feed', 'stock_allowance', 'block_time_ms', 'tolerance']) {
    const v = numeric(form, name);
    if (v !== undefined) body[name] = v;
  }
  const roughing = numeric(form, 'roughing');
  if (roughing !== undefined) body.passes = [{ allowance: roughing, join: 'round' }, { allowance: 0 }];
  return body;
}


// A 2-D plot on a canvas: y up, equal scales, wheel zoom about the pointer, drag to pan,
// double-click to fit. scene = {material: {polygon, inside}, lines: [{points, colour, width,
// dash}], marks: [{at, colour, size, ring}]}.
class Plot2D {
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
      g.fillStyle = COLOUR.material;
      g.fill('evenodd');
      g.strokeStyle = COLOUR.contour;
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
    }
    g.setLineDash([]);
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

// The lines of one layer's moves, one polyline per run of moves of the same kind.
function layerLines(layer, start) {
  const style = {
    cut: [COLOUR.cut, 2.2], loop: [COLOUR.loop, 2.6], link: [COLOUR.link, 1.8, [6, 4]], rapid: [COLOUR.rapid, 1.2, [3, 4]],
  };
  const lines = [];
  let here = start;
  let current = null;
  for (const step of layer.moves) {
    const to = [step.to[0], step.to[1]];
    if (!current || current.kind !== step.kind) {
      const [colour, width, dash] = style[step.kind] || style.cut;
      current = { kind: step.kind, colour, width, dash, points: here ? [here] : [] };
      lines.push(current);
    }
    current.points.push(to);
    here = to;
  }
  return { lines, end: here };
}

const ACTION_TEXT = {
  loop_arc: 'arc loop', loop_triangle: 'triangle loop', loop_parallelogram: 'parallelogram loop', miter: 'miter',
  round: 'round join', reflex: 'fillet', unreached: 'not reached', dogbone: 'dogbone', tbone: 'T-bone',
};

function cornerMarks(answer) {
  const marks = [];
  for (const corner of answer.corners) {
    const colour = corner.action === 'unreached' ? COLOUR.unreached : corner.convexity === 'convex' ? COLOUR.convex : COLOUR.concave;
    marks.push({ at: corner.vertex, colour, size: 5, ring: !corner.looped && !corner.relief });
  }
  return marks;
}

function reliefLines(answer) {
  return answer.corners.filter((c) => c.relief).map((c) => ({ points: [c.cl_point, c.relief.target], colour: COLOUR.relief, width: 4 }));
}

function cell(text, className) {
  const td = document.createElement('td');
  td.textContent = text;
  if (className) td.className = className;
  return td;
}

// Zooms the plot to a corner with its loop or relief in view.
function focusCorner(plot, corner, radius) {
  const shape = corner.corner_loop;
  const points = [corner.vertex, corner.cl_point];
  if (shape) {
    points.push(shape.exit_end, shape.entry_start);
    if (shape.far_corner) points.push(shape.far_corner);
    if (shape.centre) {
      const [x, y] = shape.centre;
      points.push([x - shape.radius, y - shape.radius], [x + shape.radius, y + shape.radius]);
    }
  }
  if (corner.relief) points.push(corner.relief.target);
  const xs = points.map((p) => p[0]);
  const ys = points.map((p) => p[1]);
  const span = Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys)) + 2 * radius;
  plot.focus([(Math.max(...xs) + Math.min(...xs)) / 2, (Math.max(...ys) + Math.min(...ys)) / 2], 1.2 * span);
}

function cornerTable(answer, plot) {
  const table = document.createElement('table');
  table.className = 'corners';
  table.innerHTML = '<thead><tr><th>#</th><th>vertex x, y</th><th>angle °</th><th>corner</th><th>action</th>'
    + '<th>left mm²</th><th>left depth</th><th>over-cut mm²</th><th>over-cut depth</th></tr></thead>';
  const body = document.createElement('tbody');
  for (const corner of answer.corners) {
    const tr = document.createElement('tr');
    tr.dataset.corner = String(corner.index);
    tr.title = 'Click to zoom the plot to this corner';
    const m = corner.material;
    tr.append(cell(String(corner.index)), cell(`${number(corner.vertex[0], 3)}, ${number(corner.vertex[1], 3)}`),
      cell(number(corner.angle_deg, 1)), cell(corner.convexity, corner.convexity),
      cell(ACTION_TEXT[corner.action] || corner.action, `action ${corner.action}`),
      cell(number(m.left_area, 4)), cell(number(m.left_depth, 4)), cell(number(m.overcut_area, 4)), cell(number(m.overcut_depth, 4)));
    tr.addEventListener('click', () => focusCorner(plot, corner, answer.summary.tool_radius));
    body.append(tr);
  }
  table.append(body);
  return table;
}

function summaryItems(answer) {
  const s = answer.summary;
  const items = [
    ['side', `${s.side}, ${s.direction}`], ['tool radius, mm', number(s.tool_radius, 3)], ['corners', s.corners],
    ['layers × passes', `${s.layers} × ${s.passes}`], ['moves', s.moves], ['feed path, mm', number(s.feed_length, 1)],
    ['feed / loop feed', `${s.feed} / ${s.loop_feed}`], ['est. time, s', number(s.estimated_time_s, 1)],
    ['safe Z', number(s.safe_z, 3)], ['tolerance, mm', s.tolerance],
  ];
  if (s.blocks) {
    const b = s.blocks;
    items.push(['blocks', b.blocks], ['block length, mm', number(b.block_length, 4)],
      ['shortest block, mm', number(b.min_block_length, 4)], ['short blocks', `${b.short_blocks} (+${b.short_end_blocks} at ends)`],
      ['block-limited time, s', number(b.estimated_time_s, 1)]);
  }
  return items;
}

// Shows a contour answer in `container`: layer selector, plot, corner table, summary, warnings.
// Used by the form and by job results. Returns the canvas.
export function contourResult(container, answer) {
  container.replaceChildren();
  const bar = document.createElement('div');
  bar.className = 'actions layer-bar';
  const label = document.createElement('label');
  label.className = 'inline';
  label.append('Layer ');
  const select = document.createElement('select');
  select.name = 'layer';
  answer.layers.forEach((layer, index) => select.append(new Option(`${index + 1} of ${answer.layers.length}: Z ${number(layer.z, 3)}`, String(index))));
  label.append(select);
  bar.append(label);
  const canvas = document.createElement('canvas');
  canvas.className = 'plot';
  canvas.setAttribute('aria-label', 'Contour and tool-centre path of the selected layer');
  const hint = document.createElement('p');
  hint.className = 'hint';
  hint.textContent = 'Wheel to zoom, drag to pan, double-click to fit; click a corner row to zoom to it. Grey: material.';
  const note = document.createElement('div');
  const warnings = document.createElement('div');
  const summary = document.createElement('div');
  summary.className = 'summary';
  container.append(bar, canvas, hint, note, warnings, summary);

  const plot = new Plot2D(canvas);
  const contour = answer.corners.map((c) => c.vertex);
  const legend = [['contour', COLOUR.contour], ['cut', COLOUR.cut], ['loop', COLOUR.loop], ['relief', COLOUR.relief],
    ['link', COLOUR.link, [6, 4]], ['rapid', COLOUR.rapid, [3, 4]]];
  // Each layer's plot starts where the previous layer's moves ended.
  const starts = [];
  let end = null;
  for (const layer of answer.layers) {
    starts.push(end);
    if (layer.moves.length) end = [layer.moves[layer.moves.length - 1].to[0], layer.moves[layer.moves.length - 1].to[1]];
  }
  const show = (index, keepView) => {
    const layer = answer.layers[index];
    const { lines } = layerLines(layer, starts[index]);
    plot.setScene({
      material: { polygon: contour, inside: answer.summary.side === 'inside' },
      lines: [...lines, ...reliefLines(answer)],
      marks: cornerMarks(answer),
      legend,
    }, keepView);
    canvas.dataset.layer = String(index);
    note.replaceChildren(...(layer.moves.length ? [] : [message('warning', 'This layer was stored without its moves (see the warnings); the G-code has them all.')]));
  };
  select.addEventListener('change', () => show(Number(select.value), true));
  show(0, false);

  showSummary(summary, summaryItems(answer));
  warnings.replaceChildren(...warningMessages(answer.warnings));
  container.append(cornerTable(answer, plot));
  return canvas;
}

// Marks the points box when an error names the contour or one of its points.
function markContour(form, messages, problem) {
  const paths = (problem.errors || []).map((e) => e.path);
  const hit = paths.map((p) => /^contour(?:\[(\d+)\])?/.exec(p)).find(Boolean);
  if (!hit) return;
  const box = form.elements.points;
  box.classList.add('invalid');
  if (hit[1] !== undefined) {
    const index = Number(hit[1]);
    messages.append(message('error', `See contour[${index}]: point ${index + 1} of the list (comments and blank lines not counted).`));
  }
}

export const contourView = {
  mount(root, id) {
    root.innerHTML = FORM;
    const form = root.querySelector('#contour-form');
    const messages = root.querySelector('#contour-messages');
    const result = root.querySelector('#contour-result');
    form.elements.points.defaultValue = SAMPLE;
    const sync = () => { form.querySelector('[data-inline-tool]').hidden = value(form, 'tool_choice') !== 'inline'; };
    form.addEventListener('change', sync);
    loadTools(form.elements.tool_choice, 'inline flat end mill (radius below)').then(sync);
    loadMachines(form.elements.machine);
    sync();
    const request = () => {
      form.querySelectorAll('.invalid').forEach((e) => e.classList.remove('invalid'));
      try {
        return contourRequest(form);
      } catch (bad) {
        form.elements.points.classList.add('invalid');
        messages.replaceChildren(message('error', `Points: ${bad.error}`));
        return null;
      }
    };
    form.addEventListener('submit', async (event) => {
      event.preventDefault();
      const body = request();
      if (!body) return;
      computing(messages, result);
      try {
        const answer = await api('POST', '/api/v1/contour', body);
        computed(messages, result);
        markComputed(form);
        clearProblem(form);
        contourResult(result, answer).id = 'contour-plot';
      } catch (problem) {
        showProblem(messages, form, problem);
        markContour(form, messages, problem);
      }
    });
    root.querySelector('#contour-gcode').addEventListener('click', async () => {
      const body = request();
      if (!body) return;
      try {
        const program = await api('POST', `/api/v1/contour${gcodeQuery(form)}`, body, 'text/x-gcode');
        download(programName('contour', form), program);
      } catch (problem) {
        showProblem(messages, form, problem);
        markContour(form, messages, problem);
      }
    });
    keepForm(id, form);
  },
};
