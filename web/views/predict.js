// Predict view: machining-error prediction and path correction for ball-end-mill finishing
// (docs/spec/api.md, Error prediction). A form (tool with its shape-error table and stiffness, stock, the
// G-code program, cutting conditions, method), the path coloured by predicted error with a colour
// scale, a histogram of the errors, the worst passes with their NC lines, warnings, and the
// corrected program. `predictResult` also shows prediction jobs.
import { api } from '/api.js';
import { clearProblem, downloadFlow, half, keepForm, loadTools, message, number, numeric, parseDecimal, showProblem, showSummary, submitFlow, toolLabel, value, warningMessages } from '/form.js';
import { css, diverging, drawColourScale, drawHistogram } from '/plot/colour.js';
import { partlessPanel, requestStock } from '/plot/cut-stock.js';
import { Scene3D, THREE } from '/plot/scene3d.js';
import { Timeline } from '/timeline.js';
import { inUnits, lengthFactor, showInUnits, unitsOf } from '/units.js';

// The sample: a raster finishing program over a gentle dome (20 × 20 mm, 2 mm high) with an R3
// ball, and the dome plus a 0.2 mm allowance as a height grid (as examples/predict-raster.toml).
const SAMPLE = { radius: 3, size: 20, pick: 1, step: 1, allowance: 0.2 };

function dome(x, y) {
  const k = Math.PI / SAMPLE.size;
  const a = 2;
  const z = a * Math.sin(k * x) * Math.sin(k * y);
  const dx = a * k * Math.cos(k * x) * Math.sin(k * y);
  const dy = a * k * Math.sin(k * x) * Math.cos(k * y);
  const l = Math.hypot(dx, dy, 1);
  return { z, n: [-dx / l, -dy / l, 1 / l] };
}

function mm(v) {
  const text = v.toFixed(4);
  return text === '-0.0000' ? '0.0000' : text;
}

export function sampleProgram() {
  const { radius: r, size, pick, step } = SAMPLE;
  const lines = Math.round(size / pick) + 1;
  const points = Math.round(size / step) + 1;
  const out = ['%', 'O3100 (DOME RASTER FINISHING R3 BALL)', 'G21 G90 G17 G40 G49 G80 G94', 'T3 M06', 'G00 G43 H3 Z20.', 'S8000 M03'];
  for (let j = 0; j < lines; j++) {
    for (let k = 0; k < points; k++) {
      const i = j % 2 === 0 ? k : points - 1 - k;
      const x = i * step;
      const y = j * pick;
      const { z, n } = dome(x, y);
      const tip = [x + r * n[0], y + r * n[1], z + r * n[2] - r];
      if (j === 0 && k === 0) {
        out.push(`G00 X${mm(tip[0])} Y${mm(tip[1])} Z5.`, `G01 Z${mm(tip[2])} F1600`);
      } else {
        out.push(`X${mm(tip[0])} Y${mm(tip[1])} Z${mm(tip[2])}`);
      }
    }
  }
  out.push('G00 Z20.', 'M05', 'M30', '%');
  return out.join('\n') + '\n';
}

function sampleGrid() {
  const margin = 2 * SAMPLE.radius;
  const count = Math.round((SAMPLE.size + 2 * margin) / 1) + 1;
  const rows = [];
  for (let j = 0; j < count; j++) {
    const row = [];
    for (let i = 0; i < count; i++) {
      const { z, n } = dome(-margin + i, -margin + j);
      row.push((z + SAMPLE.allowance / n[2]).toFixed(4));
    }
    rows.push(row.join(' '));
  }
  return { origin: -margin, heights: rows.join('\n') };
}

const FORM = `
<div class="layout">
  <form id="predict-form" novalidate>
    <fieldset><legend>Tool (ball end mill)</legend>
      <label>Tool <select name="tool_choice" data-field="tool"></select></label>
      <div data-inline-tool>
        <label>Size entered as <select name="size_as"><option value="diameter">diameter Ø</option><option value="radius">radius</option></select></label>
        <label><span data-size-label>Ball diameter Ø, mm</span> <input name="ball_size" type="number" step="any" value="6" data-field="tool.radius"></label>
        <label>Flutes <input name="flutes" type="number" value="2" data-field="tool.flutes"></label>
        <label>Helix angle, ° <input name="helix" type="number" step="any" value="30" data-field="tool.helix_deg"></label>
        <label class="stacked"><span>Shape error: contact angle in ° (0 = tip, 90 = equator) and error in mm, one pair a line <abbr class="symbol" title="δ(θ)">δ(θ)</abbr></span><textarea name="shape_error" rows="4" data-dim="keyed-lengths" data-field="tool.shape_error" title="one row per contact angle: angle in degrees (0 = tip, 90 = equator), error in mm">0 0.004
30 0.005
60 0.007
90 0.009</textarea></label>
        <label>Stiffness <select name="stiffness_kind" data-field="tool.stiffness">
          <option value="modal">one mode (X = Y)</option><option value="static">static (X = Y)</option><option value="none">none</option></select></label>
        <label data-stiffness="modal static"><span>Stiffness, N/mm <abbr class="symbol" title="k">k</abbr></span> <input name="k" type="number" step="any" value="3000" data-field="tool.stiffness"></label>
        <label data-stiffness="modal"><span>Natural frequency, Hz <abbr class="symbol" title="f_n">f<sub>n</sub></abbr></span> <input name="fn" type="number" step="any" value="1800" data-field="tool.stiffness"></label>
        <label data-stiffness="modal"><span>Damping ratio <abbr class="symbol" title="ζ">ζ</abbr></span> <input name="zeta" type="number" step="any" value="0.04" data-field="tool.stiffness"></label>
        <div class="actions"><label class="inline">Save as T <input name="save_number" type="number" min="1" max="9999" value="3" aria-label="tool number" style="width: 5rem"></label>
          <button class="secondary" type="button" id="predict-save-tool">Save tool</button></div>
      </div>
    </fieldset>
    <fieldset><legend>Stock</legend>
      <label>Kind <select name="stock_kind" data-field="stock.kind">
        <option value="grid">height grid</option><option value="box">box</option><option value="mesh">STL file</option></select></label>
      <label data-stock="box">Lowest corner x y z, mm <span class="triple">
        <input name="min_x" type="number" step="any" value="-5" data-field="stock.min">
        <input name="min_y" type="number" step="any" value="-5" data-field="stock.min">
        <input name="min_z" type="number" step="any" value="-10" data-field="stock.min"></span></label>
      <label data-stock="box">Highest corner x y z, mm <span class="triple">
        <input name="max_x" type="number" step="any" value="25" data-field="stock.max">
        <input name="max_y" type="number" step="any" value="25" data-field="stock.max">
        <input name="max_z" type="number" step="any" value="2.2" data-field="stock.max"></span></label>
      <label data-stock="grid">Grid origin x y, mm <span class="pair">
        <input name="origin_x" type="number" step="any" data-field="stock.origin">
        <input name="origin_y" type="number" step="any" data-field="stock.origin"></span></label>
      <label data-stock="grid">Grid spacing, mm <input name="spacing" type="number" step="any" value="1" data-field="stock.spacing"></label>
      <label data-stock="grid">Bottom z, mm <input name="bottom" type="number" step="any" value="-20" data-field="stock.bottom"></label>
      <label class="stacked" data-stock="grid">Heights, mm (a row per y, along x)<textarea name="heights" rows="4" data-field="stock.heights" title="one row per y, heights along x"></textarea></label>
      <label data-stock="mesh">STL file <input name="stock_file" type="file" accept=".stl,model/stl,application/sla" data-field="stock"></label>
      <label data-stock="mesh">STL units <select name="stl_units" data-field="stock.units" title="an STL file names no units; most are exported in mm whatever the shop works in"><option value="mm">mm</option><option value="inch">inch</option></select></label>
    </fieldset>
    <fieldset><legend>Path</legend>
      <label class="stacked">G-code program<textarea name="program" rows="14" spellcheck="false" class="code" data-field="path.program"></textarea></label>
      <label>Open a file <input name="program_file" type="file" accept=".nc,.ngc,.tap,.gcode,.txt"></label>
      <label>Programmed point <select name="reference" data-field="reference"><option value="tip">tool tip</option><option value="centre">ball centre</option></select></label>
    </fieldset>
    <fieldset><legend>Cutting</legend>
      <label>Spindle, rpm <input name="spindle_rpm" type="number" step="any" placeholder="from the program" data-field="spindle_rpm"></label>
      <label>Feed, mm/min <input name="feed" type="number" step="any" placeholder="from the program" data-field="feed"></label>
      <label><span>Cutting force coefficients (tangential, radial, axial), N/mm² <abbr class="symbol" title="K_tc K_rc K_ac">K<sub>tc</sub> K<sub>rc</sub> K<sub>ac</sub></abbr></span> <span class="triple">
        <input name="ktc" type="number" step="any" value="2000" data-field="cutting.ktc" title="N/mm²">
        <input name="krc" type="number" step="any" value="800" data-field="cutting.krc" title="N/mm²">
        <input name="kac" type="number" step="any" value="300" data-field="cutting.kac" title="N/mm²"></span></label>
      <label>Method <select name="method" data-field="method"><option value="sampling">surface sampling</option><option value="depth_buffer">depth buffer (patent)</option></select></label>
      <label><span>Resolution, cells across <abbr class="symbol" title="N">N</abbr></span> <input name="resolution" type="number" value="256" data-field="resolution"></label>
      <label>Largest correction, mm <input name="max_correction" type="number" step="any" value="0.05" data-field="correction.max_correction"></label>
    </fieldset>
    <div class="actions">
      <button class="primary" type="submit" id="predict-compute">Predict</button>
      <button class="secondary" type="button" id="predict-gcode">Corrected program</button>
    </div>
  </form>
  <section>
    <div id="predict-messages"></div>
    <div id="predict-result"></div>
  </section>
</div>`;

function rows(text) {
  return text.split('\n').map((l) => l.trim()).filter((l) => l !== '').map((l) => l.split(/[\s,;]+/).map(Number));
}

// The inline ball's radius, as the API takes it, from the size entered as a diameter or a radius.
function ballRadius(form) {
  const size = numeric(form, 'ball_size');
  return value(form, 'size_as') === 'diameter' ? half(size) : size;
}

// The request body from the form (field names as docs/spec/api.md) and, for an STL stock, the file.
export function predictRequest(form) {
  const choice = value(form, 'tool_choice');
  let tool = Number(choice);
  if (choice === 'inline') {
    tool = { kind: 'ball', radius: ballRadius(form), flutes: numeric(form, 'flutes') ?? 2, helix_deg: numeric(form, 'helix') };
    tool.shape_error = rows(value(form, 'shape_error')).map(([angle, error]) => ({ angle_deg: angle, error }));
    const kind = value(form, 'stiffness_kind');
    const k = numeric(form, 'k');
    if (kind === 'static') tool.stiffness = { kind, x: k, y: k };
    if (kind === 'modal') {
      const mode = { stiffness: k, frequency_hz: numeric(form, 'fn'), damping_ratio: numeric(form, 'zeta') };
      tool.stiffness = { kind, x: [mode], y: [mode] };
    }
  }
  const kind = value(form, 'stock_kind');
  let stock = { kind };
  let file = null;
  if (kind === 'box') {
    stock.min = ['min_x', 'min_y', 'min_z'].map((n) => numeric(form, n));
    stock.max = ['max_x', 'max_y', 'max_z'].map((n) => numeric(form, n));
  } else if (kind === 'grid') {
    stock = { kind, origin: [numeric(form, 'origin_x'), numeric(form, 'origin_y')], spacing: numeric(form, 'spacing'), heights: rows(value(form, 'heights')), bottom: numeric(form, 'bottom') };
  } else {
    // An STL file names no units: the solid says which it was exported in.
    stock.units = value(form, 'stl_units');
    file = form.elements.stock_file.files[0] || null;
  }
  const body = {
    units: unitsOf(form),
    tool, stock,
    path: { kind: 'gcode', program: value(form, 'program') },
    reference: value(form, 'reference'),
    spindle_rpm: numeric(form, 'spindle_rpm'),
    feed: numeric(form, 'feed'),
    method: value(form, 'method'),
    resolution: numeric(form, 'resolution'),
    correction: { max_correction: numeric(form, 'max_correction') },
  };
  const cutting = { ktc: numeric(form, 'ktc'), krc: numeric(form, 'krc'), kac: numeric(form, 'kac') };
  if (Object.values(cutting).some((v) => v !== undefined)) body.cutting = cutting;
  return { body, file };
}

// The body to send: JSON, or a form with the JSON and the STL file.
function payload({ body, file }) {
  if (!file) return body;
  const form = new FormData();
  form.append('request', new Blob([JSON.stringify(body)], { type: 'application/json' }));
  form.append('stock', file, file.name);
  return form;
}

const isBall = (tool) => tool.kind === 'ball';

// A ball's label with whether it has what a prediction needs.
function predictToolLabel(tool) {
  const note = tool.shape_error ? `${tool.shape_error.length}-row shape error${tool.stiffness ? ', stiffness' : ''}` : 'no shape-error table';
  return `${toolLabel(tool)} (${note})`;
}

function syncVisibility(form) {
  const kind = value(form, 'stock_kind');
  form.querySelectorAll('[data-stock]').forEach((e) => { e.hidden = e.dataset.stock !== kind; });
  form.querySelector('[data-inline-tool]').hidden = value(form, 'tool_choice') !== 'inline';
  form.querySelector('[data-size-label]').textContent = value(form, 'size_as') === 'diameter' ? 'Ball diameter Ø, mm' : 'Ball radius, mm';
  const stiffness = value(form, 'stiffness_kind');
  form.querySelectorAll('[data-stiffness]').forEach((e) => { e.hidden = !e.dataset.stiffness.split(' ').includes(stiffness); });
}


// Puts the cursor on the program line a G-code error names (showProblem marks the fields).
function markProblem(form, problem) {
  for (const { path } of problem.errors || []) {
    const line = /line (\d+)/.exec(problem.detail || '');
    if (path === 'path.program' && line) {
      const area = form.elements.program;
      const lines = area.value.split('\n');
      const at = Math.min(Number(line[1]), lines.length) - 1;
      const start = lines.slice(0, at).reduce((n, l) => n + l.length + 1, 0);
      area.focus();
      area.setSelectionRange(start, start + (lines[at] || '').length);
      area.scrollTop = Math.max(0, (at - 3) * (area.scrollHeight / lines.length));
    }
  }
}

// The error colour: a diverging scale centred on zero with symmetric limits ±limit (blue: cuts
// too deep, white: on size, red: leaves material).
function colourOf(error, limit) {
  return Number.isFinite(error) ? css(diverging(error, limit)) : '#9aa4ad';
}

// How an answer's machining errors are read: in µm in mm, and in an inch answer in tenths
// (0.0001 in), as an inch shop reads small errors. `per`: reading units per answer unit;
// `unit`: the reading's words after a figure, `heading(name)` a column or line named with it.
function errorReading(units) {
  if (units === 'inch') {
    return { per: 10000, unit: '× 0.0001 in', heading: (name) => `${name} (0.0001 in)` };
  }
  return { per: 1000, unit: 'µm', heading: (name) => `${name}, µm` };
}

// An error (in the answer's units) as its reading, to a tenth of the reading's unit.
function reading(e, { per }) {
  return Number.isFinite(e) ? (e * per).toFixed(1) : '–';
}

// A length of the answer with its unit: mm to 3 decimals, inch to 4 (0.0001 in).
function length(v, units) {
  return `${Number(v.toFixed(units === 'inch' ? 4 : 3))} ${inUnits('mm', units)}`;
}

// The units a G-code program's coordinates are in: its first G20 (inch) or G21 (mm), mm without.
function programUnits(program) {
  const word = /G0*2([01])(?![\d.])/i.exec(program.replace(/\([^)]*\)|;.*$/gm, ''));
  return word?.[1] === '0' ? 'inch' : 'mm';
}

// A height-grid stock as a see-through surface (heights: a row per y, along x).
function gridSurface(scene, stock) {
  const rows = stock.heights;
  const [x0, y0] = stock.origin;
  const step = stock.spacing;
  if (!rows?.length || !rows[0]?.length || !(step > 0) || ![x0, y0].every(Number.isFinite)) return;
  const nx = rows[0].length;
  const ny = rows.length;
  const positions = [];
  for (let j = 0; j < ny; j++) for (let i = 0; i < nx; i++) positions.push(x0 + i * step, y0 + j * step, rows[j][i] ?? 0);
  const index = [];
  for (let j = 0; j + 1 < ny; j++) {
    for (let i = 0; i + 1 < nx; i++) {
      const a = j * nx + i;
      index.push(a, a + 1, a + nx, a + 1, a + nx + 1, a + nx);
    }
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  geometry.setIndex(index);
  geometry.computeVertexNormals();
  scene.solid('stock', geometry, { legend: 'stock (height grid)', opacity: 0.3, colour: '#8fa3b5', edges: false });
}

// The triangles of an STL file (binary, or ASCII "solid … facet … vertex"), as a flat list of
// vertex coordinates, or null when it is neither.
export function stlTriangles(buffer) {
  const bytes = new Uint8Array(buffer);
  if (bytes.length >= 84) {
    const view = new DataView(buffer);
    const count = view.getUint32(80, true);
    if (84 + 50 * count === bytes.length) {
      const positions = new Float32Array(count * 9);
      for (let t = 0; t < count; t++) {
        for (let k = 0; k < 9; k++) positions[t * 9 + k] = view.getFloat32(84 + 50 * t + 12 + 4 * k, true);
      }
      return positions;
    }
  }
  const text = new TextDecoder().decode(bytes);
  const vertices = [...text.matchAll(/vertex\s+(\S+)\s+(\S+)\s+(\S+)/g)].flatMap((m) => [Number(m[1]), Number(m[2]), Number(m[3])]);
  return vertices.length >= 9 && vertices.every(Number.isFinite) ? new Float32Array(vertices.slice(0, vertices.length - (vertices.length % 9))) : null;
}

// An STL stock as a see-through solid.
function meshSolid(scene, triangles) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(triangles, 3));
  geometry.computeVertexNormals();
  scene.solid('stock', geometry, { legend: 'stock (STL)', opacity: 0.2, colour: '#8fa3b5', edges: false });
}

// The programmed path as runs of contiguous passes: each pass ends at its programmed end point
// (corrected − correction); a pass starts a new run when lines were skipped (a rapid between).
function runs(passes) {
  const out = [];
  let run = null;
  let previous = null;
  for (const pass of passes) {
    const end = pass.corrected.map((c, k) => c - pass.correction[k]);
    const contiguous = previous && (pass.line === undefined || previous.line === undefined || pass.line - previous.line <= 1);
    if (!contiguous) {
      run = { points: [], errors: [] };
      out.push(run);
    }
    run.points.push(end);
    run.errors.push(pass.error);
    previous = pass;
  }
  return out;
}

// Shows a prediction in `container`: path coloured by error with its scale, histogram, summary,
// worst passes and warnings. `context`: the `request` adds the stock, the `program` the timeline
// (a worst pass goes to its line), with `cutStock` (where the stock the corrected program cuts
// comes from: `requestStock` with the STL stock the request was sent with, or `jobStock`) that
// stock in 3-D. Used by the form and by job results.
export function predictResult(container, answer, { request, program, stockTriangles, cutStock = null } = {}) {
  container.replaceChildren();
  // Everything here is in the answer's units, whatever the switch says until it is computed again.
  const units = answer.units === 'inch' ? 'inch' : 'mm';
  showInUnits(container, units);
  const errorIn = errorReading(units);
  const shown = (e) => reading(e, errorIn);
  const warnings = document.createElement('div');
  const sceneBox = document.createElement('div');
  const timelineBox = document.createElement('div');
  // An optional tolerance band, drawn on the scale and the histogram, with the passes outside it.
  const bandBox = document.createElement('div');
  bandBox.className = 'actions';
  const bandLabel = document.createElement('label');
  bandLabel.className = 'inline';
  const bandInput = document.createElement('input');
  bandInput.type = 'number';
  bandInput.step = 'any';
  bandInput.min = '0';
  bandInput.placeholder = 'none';
  bandInput.name = 'tolerance_band';
  bandInput.style.width = '6rem';
  bandLabel.append('Tolerance band ±', bandInput, errorIn.unit);
  const bandCount = document.createElement('output');
  bandBox.append(bandLabel, bandCount);
  const scale = document.createElement('canvas');
  scale.className = 'scale';
  scale.setAttribute('aria-label', 'Colour scale of the predicted error');
  const caption = document.createElement('p');
  caption.className = 'hint';
  caption.textContent = 'Programmed path coloured by the predicted error along the surface normal: blue cuts too deep (below 0), white is on size, red leaves material (above 0); the scale is symmetric about zero. Drag to rotate, right-drag to pan, wheel to zoom. Click a worst pass to put the tool there.';
  const summaryBox = document.createElement('div');
  summaryBox.className = 'summary';
  const histogram = document.createElement('canvas');
  histogram.className = 'histogram';
  histogram.setAttribute('aria-label', 'Histogram of the predicted errors');
  const worstTitle = document.createElement('h3');
  worstTitle.textContent = 'Worst passes';
  const worst = document.createElement('table');
  worst.className = 'worst';
  container.append(warnings, sceneBox, scale, bandBox, caption, timelineBox, summaryBox, histogram, worstTitle, worst);

  const errors = answer.passes.map((p) => p.error).filter(Number.isFinite);
  const low = errors.length ? Math.min(...errors) : 0;
  const high = errors.length ? Math.max(...errors) : 0;
  const limit = Math.max(Math.abs(low), Math.abs(high), 1e-9);
  const scene = new Scene3D(sceneBox, { label: 'Tool path coloured by predicted error, with the stock' });
  if (request?.stock?.kind === 'box' && [...request.stock.min, ...request.stock.max].every(Number.isFinite)) {
    const [min, max] = [request.stock.min, request.stock.max];
    const box = new THREE.BoxGeometry(max[0] - min[0], max[1] - min[1], max[2] - min[2]);
    box.translate((min[0] + max[0]) / 2, (min[1] + max[1]) / 2, (min[2] + max[2]) / 2);
    scene.solid('stock', box, { legend: 'stock', opacity: 0.15 });
  }
  runs(answer.passes).forEach((run, i) => {
    const colours = run.errors.map((e) => colourOf(e, limit));
    if (run.points.length > 1) scene.path('path', run.points, { colours, legend: i === 0 ? 'path, coloured by error' : undefined, colour: '#9aa4ad' });
    else scene.dots('path', run.points, { colour: colours[0] });
  });
  if (request?.stock?.kind === 'grid') gridSurface(scene, request.stock);
  if (stockTriangles) meshSolid(scene, stockTriangles);
  scene.tool({ radius: answer.tool.radius || 1 });
  scene.finish();
  // With the program (the form view), the timeline walks it and a worst pass goes to its line.
  // The program keeps its own G20/G21: its readout says those, its positions are drawn in the
  // answer's units.
  const lift = request?.reference === 'centre' ? 0 : answer.tool.radius;
  const ownUnits = program ? programUnits(program) : units;
  const toAnswer = lengthFactor(ownUnits, units);
  timelineBox.dataset.units = ownUnits;
  const timeline = program ? new Timeline(timelineBox, program, {
    onMove: (move) => scene.moveTool([move.position[0] * toAnswer, move.position[1] * toAnswer, move.position[2] * toAnswer + lift]),
  }) : null;
  const end = (pass) => pass.corrected.map((c, k) => c - pass.correction[k]);
  const redraw = () => {
    const band = (parseDecimal(bandInput.value) || 0) / errorIn.per;
    const colour = (e) => colourOf(e, limit);
    drawColourScale(scale, { low: -limit, high: limit, band, colour, format: shown, unit: errorIn.unit });
    drawHistogram(histogram, errors, { low, high, band, colour, format: shown, unit: errorIn.unit, label: 'passes per error' });
    const outside = band > 0 ? errors.filter((e) => Math.abs(e) > band).length : null;
    bandCount.textContent = outside === null ? '' : `${outside} of ${errors.length} passes outside ±${bandInput.value} ${errorIn.unit}.`;
  };
  bandInput.addEventListener('input', redraw);
  redraw();
  new ResizeObserver(redraw).observe(histogram);

  const s = answer.summary;
  summaryBox.replaceChildren();
  // The pixel is a length: in µm in mm (it is of the errors' size), in inches to 0.0001 in.
  const pixel = units === 'inch' ? length(s.pixel_size, units) : `${number(s.pixel_size * 1000, 1)} µm`;
  showSummary(summaryBox, [
    ['passes', `${s.predicted} of ${s.passes} predicted`],
    [errorIn.heading('error range'), `${shown(s.min_error)} … ${shown(s.max_error)}`],
    [errorIn.heading('mean / RMS error'), `${shown(s.mean_error)} / ${shown(s.rms_error)}`],
    [errorIn.heading('largest correction'), `${shown(s.max_correction)}${s.clamped ? ` (${s.clamped} clamped)` : ''}`],
    ['no cut / no surface / outside', `${s.no_cut} / ${s.no_surface} / ${s.outside_stock}`],
    ['method', `${s.method.replace('_', ' ')}, N ${s.resolution} (${pixel})`],
    ['tool', `${answer.tool.number ? 'T' + answer.tool.number + ' ' : ''}ball Ø${length(2 * answer.tool.radius, units)}`],
  ].concat(s.merge ? [['merged passes', `${s.merge.merged} (${s.merge.simulated} simulated), error of the merge ≤ ${shown(s.merge.max_bound)} ${errorIn.unit}`]] : [])
    .concat(answer.timings ? [['time', `${number(answer.timings.solve_ms / 1000, 2)} s (${Math.round(answer.timings.passes_per_s)} passes/s)`]] : []));

  const head = document.createElement('tr');
  for (const title of ['#', 'pass', 'NC line', errorIn.heading('error'), 'contact angle, °', 'flags']) {
    const th = document.createElement('th');
    th.textContent = title;
    head.append(th);
  }
  const body = s.worst.map((w, rank) => {
    const pass = answer.passes[w.index] || {};
    const tr = document.createElement('tr');
    tr.dataset.line = String(w.line ?? '');
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = colourOf(w.error, limit);
    tr.tabIndex = 0;
    const select = () => {
      worst.querySelectorAll('[aria-selected]').forEach((r) => r.removeAttribute('aria-selected'));
      tr.setAttribute('aria-selected', 'true');
      if (timeline && w.line !== undefined) timeline.goToLine(w.line);
      else if (pass.corrected) scene.moveTool(end(pass).map((v, k) => v + (k === 2 ? lift : 0)));
    };
    tr.addEventListener('click', select);
    tr.addEventListener('keydown', (e) => { if (e.key === 'Enter' || e.key === ' ') { e.preventDefault(); select(); } });
    const cells = [String(rank + 1), String(w.index), w.line === undefined ? '–' : String(w.line), shown(w.error),
      number(pass.contact_angle_deg, 1), (pass.flags || []).join(', ')];
    cells.forEach((text, k) => {
      const td = document.createElement('td');
      if (k === 3) td.append(swatch, ' ');
      td.append(text);
      tr.append(td);
    });
    return tr;
  });
  worst.replaceChildren(head, ...body);
  warnings.replaceChildren(...warningMessages(answer.warnings));
  if (answer.verification) {
    partlessPanel(container, {
      name: 'predict',
      verification: answer.verification,
      source: cutStock,
      why: 'press “Cut stock” to cut the program again',
    });
  }
  return scene.root;
}

export const predictView = {
  mount(root, id) {
    root.innerHTML = FORM;
    const form = root.querySelector('#predict-form');
    const messages = root.querySelector('#predict-messages');
    const result = root.querySelector('#predict-result');
    const grid = sampleGrid();
    form.elements.program.defaultValue = sampleProgram();
    form.elements.heights.defaultValue = grid.heights;
    form.elements.origin_x.defaultValue = grid.origin;
    form.elements.origin_y.defaultValue = grid.origin;
    form.addEventListener('change', () => syncVisibility(form));
    loadTools(form.elements.tool_choice, 'inline ball (below)', isBall, predictToolLabel).then(() => syncVisibility(form));
    syncVisibility(form);
    form.elements.program_file.addEventListener('change', async (event) => {
      const file = event.target.files[0];
      if (file) form.elements.program.value = await file.text();
    });
    const clear = () => clearProblem(form);
    const fail = (problem) => {
      showProblem(messages, form, problem);
      markProblem(form, problem);
    };
    submitFlow(form, {
      messages,
      result,
      read: () => predictRequest(form),
      ask: (request) => api('POST', '/api/v1/predict?timings=true', payload(request)),
      show: async (answer, { body, file }) => {
        // The uploaded STL stock, drawn as the service read it (the same file, in its units).
        const stockTriangles = file ? stlTriangles(await file.arrayBuffer()) : null;
        const toAnswer = lengthFactor(body.stock.units ?? body.units, answer.units ?? 'mm');
        if (stockTriangles && toAnswer !== 1) stockTriangles.forEach((v, k) => { stockTriangles[k] = v * toAnswer; });
        predictResult(result, answer, { request: body, program: body.path.program, stockTriangles, cutStock: requestStock('predict', body, (request) => payload({ body: request, file })) }).id = 'predict-plot';
        result.querySelector('canvas.histogram').id = 'predict-histogram';
      },
      done: (answer, request, seconds) => `${answer.summary.passes} passes predicted in ${seconds.toFixed(2)} s.`,
      failed: (problem) => markProblem(form, problem),
    });
    downloadFlow(root.querySelector('#predict-gcode'), form, {
      messages,
      read: () => payload(predictRequest(form)),
      path: '/api/v1/predict',
      query: '?format=gcode',
      name: 'corrected.nc',
      failed: (problem) => markProblem(form, problem),
    });
    root.querySelector('#predict-save-tool').addEventListener('click', async () => {
      clear();
      const { body } = predictRequest(form);
      const slot = value(form, 'save_number');
      // The tool table is in mm whatever the form's units.
      const toMm = lengthFactor(body.units, 'mm');
      const tool = {
        ...body.tool,
        radius: body.tool.radius * toMm,
        shape_error: body.tool.shape_error?.map(({ angle_deg, error }) => ({ angle_deg, error: error * toMm })),
      };
      try {
        await api('PUT', `/api/v1/tools/${encodeURIComponent(slot)}`, { ...tool, name: `Ø${Number((2 * tool.radius).toPrecision(6))} ball, shape error` });
        messages.replaceChildren(message('ok', `tool ${slot} saved with its shape-error table`));
        await loadTools(form.elements.tool_choice, 'inline ball (below)', isBall, predictToolLabel);
      } catch (problem) {
        fail(problem);
      }
    });
    keepForm(id, form);
  },
};

// This capability's view in the page's list (`web/views.js` loads it by the capability's name).
export const view = { title: 'Predict', mount: predictView.mount, result: predictResult };
