// Engagement view: tool–workpiece contact along one or several candidate paths (docs/spec/api.md,
// Engagement; docs/spec/engagement.md §3). A form for the tool, stock, paths, cutting conditions, limits and
// the work material (from the library, or typed Kienzle values); per path (one shown at a time)
// the plan view coloured by engagement, the contact-position graph, a_e, the summed chip
// thickness per flute count with the threshold, spindle torque and power with the machine's limits, the feed plan, and the
// representative values and time per k with the recommended k highlighted (the charts are
// plot/charts.js's); a cursor on any chart marks the tool on the path. The result renderer is shared
// with the Jobs view.
import { api } from '/api.js';
import { PathChart, barChart } from '/plot/charts.js';
import { ToolPlan } from '/plot/tool-plan.js';
import { examplePoints } from '/units.js';
import { partlessPanel, requestStock } from '/plot/cut-stock.js';
import { downloadFlow, gcodeQuery, half, keepForm, loadMachines, loadMaterials, loadTools, message, number, numeric, POST_OPTIONS, programName, showSummary, submitFlow, toolLabel, value, warningMessages } from '/form.js';

const SAMPLE_PATHS = [
  { name: 'straight', text: '-10 20\n70 20' },
  { name: 'two bends', text: '-10 10\n30 10\n30 30\n70 30' },
  { name: 'U-shaped', text: '-10 10\n45 10\n45 30\n-10 30' },
];

const FORM = `
<div class="layout">
  <form id="engagement-form" novalidate>
    <fieldset><legend>Tool</legend>
      <label>Tool <select name="tool_choice" data-field="tool"></select></label>
      <label data-inline-tool>Tool diameter Ø, mm <input name="tool_diameter" type="number" step="any" value="10" data-field="tool.radius"></label>
      <label data-inline-tool>Flutes <input name="tool_flutes" type="number" step="1" value="2" data-field="tool.flutes"></label>
    </fieldset>
    <fieldset><legend>Stock (plan view)</legend>
      <label>Outline, x y in mm per line <textarea name="stock_polygon" rows="4" data-field="stock.polygon" spellcheck="false">0 0
60 0
60 40
0 40</textarea></label>
      <label>Holes, mm <textarea name="stock_holes" rows="2" data-field="stock.holes" spellcheck="false" placeholder="x y per line; blank line between holes"></textarea></label>
    </fieldset>
    <fieldset><legend>Tool-centre paths</legend>
      <p class="hint">Points "x y" per line (feed moves), a G-code program (pasted or opened; its XY moves), or JSON: <code>[[x, y], ...]</code> or <code>{"start": [x, y], "segments": [{"type": "arc", "to": [x, y], "center": [x, y], "dir": "ccw"}]}</code>.</p>
      <div id="engagement-paths"></div>
      <div class="actions"><button class="secondary" type="button" id="engagement-add-path">Add path</button></div>
    </fieldset>
    <fieldset><legend>Cutting</legend>
      <label>Spindle, rpm <input name="spindle_rpm" type="number" step="any" value="3000" data-field="spindle_rpm"></label>
      <label>Feed per tooth, mm <input name="feed_per_tooth" type="number" step="any" value="0.05" data-field="feed_per_tooth"></label>
      <label>Flute counts to compare <input name="flute_counts" type="text" value="1-8" data-field="flute_counts" title="e.g. 1-8 or 2,3,4"></label>
      <label>Spindle rotation <select name="spindle_direction" data-field="spindle_direction"><option value="cw">cw (M03)</option><option value="ccw">ccw (M04)</option></select></label>
    </fieldset>
    <fieldset><legend>Limits</legend>
      <label><span>Chip thickness limit, mm <abbr class="symbol" title="T1 in docs/spec/engagement.md">T1</abbr></span> <input name="thickness_limit" type="number" step="any" value="0.075" data-field="thickness_limit"></label>
      <label><span>Machining time limit, s <abbr class="symbol" title="T2 in docs/spec/engagement.md">T2</abbr></span> <input name="time_limit_s" type="number" step="any" value="20" data-field="time_limit_s"></label>
      <label>Chip thickness judged by <select name="representative" data-field="representative"><option value="max">largest</option><option value="mean">mean</option><option value="median">median</option></select></label>
    </fieldset>
    <fieldset><legend>Simulation</legend>
      <label>Engine <select name="engine" data-field="engine"><option value="exact">exact boundary</option><option value="dots">dot grid (patent method)</option></select></label>
      <label><span>Step along the path, mm <abbr class="symbol" title="Δs">Δs</abbr></span> <input name="step" type="number" step="any" placeholder="D/50" data-field="step"></label>
      <label data-engine="dots"><span>Dot spacing, mm <abbr class="symbol" title="g">g</abbr></span> <input name="grid" type="number" step="any" placeholder="D/200" data-field="grid"></label>
    </fieldset>
    <fieldset><legend>Work material (torque and power)</legend>
      <label><span>Depth of cut, mm <abbr class="symbol" title="axial depth a_p">a_p</abbr></span> <input name="axial_depth" type="number" step="any" value="2" placeholder="stock top − cut Z" data-field="axial_depth" title="empty: a_p = stock top Z − cut Z (or a G-code path's Z)"></label>
      <label>Stock top Z, mm <input name="stock_top_z" type="number" step="any" placeholder="0" data-field="stock_top_z"></label>
      <label><span>Cut Z (tool tip), mm</span> <input name="cut_z" type="number" step="any" placeholder="none" data-field="cut_z" title="the tip's Z while cutting; a_p = stock top − cut Z where no depth of cut is given"></label>
      <label>Material <select name="material" data-field="material" title="a material of the library (GET /api/v1/materials), or the values below"></select></label>
      <label><span>Specific cutting force, N/mm² <abbr class="symbol" title="Kienzle k_c1.1">k<sub>c1.1</sub></abbr></span> <input name="kc11" type="number" step="any" value="1800" placeholder="none: no torque or power" data-field="kienzle.kc11" title="e.g. about 1800 for a plain carbon steel, 700 for an aluminium alloy"></label>
      <label><span>Kienzle exponent <abbr class="symbol" title="Kienzle m_c">m<sub>c</sub></abbr></span> <input name="mc" type="number" step="any" value="0.25" data-field="kienzle.mc" title="typically 0.15–0.3"></label>
    </fieldset>
    <fieldset><legend>G-code and feed plan</legend>
      <label><span>Target chip thickness, mm <abbr class="symbol" title="h*">h*</abbr></span> <input name="target_thickness" type="number" step="any" value="0.05" data-field="feed_plan.target_thickness" title="empty: no feed plan, nominal feed"></label>
      <label>Max feed, mm/min <input name="max_feed" type="number" step="any" value="2000" placeholder="machine's" data-field="feed_plan.max_feed"></label>
      <label>Machine <select name="machine" data-field="machine"></select></label>
    </fieldset>
    <div class="actions">
      <button class="primary" type="submit" id="engagement-compute">Compute</button>
      <select name="dialect" aria-label="G-code dialect"><option value="">machine's dialect (else Fanuc)</option>${POST_OPTIONS}</select>
      <select name="reference" aria-label="Programmed point"><option value="tip">tip</option><option value="centre">centre</option></select>
      <select name="candidate" aria-label="Path to program" data-field="candidate"></select>
      <button class="secondary" type="button" id="engagement-gcode">G-code</button>
    </div>
  </form>
  <section>
    <div id="engagement-messages"></div>
    <div id="engagement-result"></div>
  </section>
</div>`;

// ---------------------------------------------------------------------------------------------
// Request from the form

class InputError {
  constructor(field, detail) {
    this.status = 400;
    this.title = 'Bad input';
    this.detail = detail;
    this.errors = [{ path: field, message: detail }];
  }
}

// Whether a path box holds a G-code program (words like G1, X10) rather than "x y" lines.
function isGcode(text) {
  return /^\s*%|(^|\s)[GXYNO]\s*[-+]?\d/im.test(text) && !/^\s*[[{]/.test(text);
}

// "x y" per line (or "x, y"), or JSON. Returns the JSON value or a list of points; throws an
// InputError at `field` for a line it cannot read.
function parsePoints(text, field) {
  const trimmed = text.trim();
  if (trimmed.startsWith('[') || trimmed.startsWith('{')) {
    try {
      return JSON.parse(trimmed);
    } catch (error) {
      throw new InputError(field, `not valid JSON: ${error.message}`);
    }
  }
  return trimmed.split('\n').map((l) => l.trim()).filter(Boolean).map((line, index) => {
    const numbers = line.split(/[\s,;]+/).filter(Boolean).map(Number);
    if (numbers.length !== 2 || numbers.some((n) => !Number.isFinite(n))) {
      throw new InputError(field, `line ${index + 1}: expected two numbers "x y", got "${line}"`);
    }
    return numbers;
  });
}

function parseFlutes(text) {
  const counts = [];
  for (const part of text.split(/[\s,;]+/).filter(Boolean)) {
    const range = part.match(/^(\d+)\s*-\s*(\d+)$/);
    if (range) {
      for (let k = Number(range[1]); k <= Number(range[2]) && counts.length < 64; k++) counts.push(k);
    } else if (/^-?\d+$/.test(part)) {
      counts.push(Number(part));
    } else {
      throw new InputError('flute_counts', `"${part}" is not a flute count or a range like 1-8`);
    }
  }
  return counts;
}

function pathBoxes(form) {
  return [...form.querySelectorAll('.engagement-path')];
}

// The request body from the form (field names as docs/spec/api.md).
export function engagementRequest(form) {
  const choice = value(form, 'tool_choice');
  const tool = choice === 'inline'
    ? { kind: 'flat', radius: half(numeric(form, 'tool_diameter')), flutes: numeric(form, 'tool_flutes') }
    : Number(choice);
  const stock = { polygon: parsePoints(value(form, 'stock_polygon'), 'stock.polygon') };
  const holes = value(form, 'stock_holes').trim();
  if (holes) stock.holes = holes.split(/\n\s*\n/).map((block, i) => parsePoints(block, `stock.holes[${i}]`));
  const boxes = pathBoxes(form);
  const body = { tool, stock };
  const paths = boxes.map((box, index) => {
    const field = boxes.length > 1 ? `paths[${index}].path` : 'path';
    const text = box.querySelector('textarea').value;
    return { name: box.querySelector('input').value.trim() || undefined, path: isGcode(text) ? { gcode: text } : parsePoints(text, field) };
  });
  if (paths.length === 1) body.path = paths[0].path;
  else {
    body.paths = paths;
    // The path chosen for G-code is the one the answer's verification cuts.
    body.candidate = Number(value(form, 'candidate') || 0);
  }
  Object.assign(body, {
    spindle_rpm: numeric(form, 'spindle_rpm'),
    feed_per_tooth: numeric(form, 'feed_per_tooth'),
    flute_counts: parseFlutes(value(form, 'flute_counts')),
    spindle_direction: value(form, 'spindle_direction'),
    thickness_limit: numeric(form, 'thickness_limit'),
    time_limit_s: numeric(form, 'time_limit_s'),
    representative: value(form, 'representative'),
    engine: value(form, 'engine'),
    step: numeric(form, 'step'),
    axial_depth: numeric(form, 'axial_depth'),
    stock_top_z: numeric(form, 'stock_top_z'),
    cut_z: numeric(form, 'cut_z'),
  });
  if (body.engine === 'dots') body.grid = numeric(form, 'grid');
  const [kc11, mc] = [numeric(form, 'kc11'), numeric(form, 'mc')];
  if (value(form, 'material')) body.material = value(form, 'material');
  else if (kc11 !== undefined || mc !== undefined) body.kienzle = { kc11, mc };
  const target = numeric(form, 'target_thickness');
  if (target !== undefined) body.feed_plan = { target_thickness: target, max_feed: numeric(form, 'max_feed') };
  if (value(form, 'machine')) body.machine = value(form, 'machine');
  return body;
}

function addPath(form, name = '', text = '') {
  const box = document.createElement('div');
  box.className = 'engagement-path';
  box.innerHTML = `<label>Name <input type="text"></label>
    <label>Points or G-code <textarea rows="4" spellcheck="false" data-dim="points"></textarea></label>
    <div class="actions"><label class="pick secondary">Open a G-code file<input type="file" accept=".nc,.ngc,.tap,.gcode,.cnc,.txt"></label>
      <button class="secondary" type="button">Remove</button></div>`;
  box.querySelector('input[type="file"]').addEventListener('change', async (event) => {
    const file = event.target.files[0];
    if (!file) return;
    box.querySelector('textarea').value = await file.text();
    if (!box.querySelector('input[type="text"]').value) box.querySelector('input[type="text"]').value = file.name;
    event.target.value = '';
    form.dispatchEvent(new Event('input'));
  });
  box.querySelector('input').value = name;
  box.querySelector('textarea').value = text;
  box.querySelector('button').addEventListener('click', () => {
    if (pathBoxes(form).length > 1) box.remove();
    numberPaths(form);
  });
  form.querySelector('#engagement-paths').append(box);
  numberPaths(form);
}

// data-field of each path box: `path` for one, `paths[i].path` / `paths[i].name` for several.
function numberPaths(form) {
  const boxes = pathBoxes(form);
  boxes.forEach((box, index) => {
    box.querySelector('textarea').dataset.field = boxes.length > 1 ? `paths[${index}].path` : 'path';
    box.querySelector('input').dataset.field = boxes.length > 1 ? `paths[${index}].name` : 'name';
  });
}


function syncVisibility(form) {
  form.querySelectorAll('[data-inline-tool]').forEach((e) => { e.hidden = value(form, 'tool_choice') !== 'inline'; });
  form.querySelectorAll('[data-engine]').forEach((e) => { e.hidden = e.dataset.engine !== value(form, 'engine'); });
}

// ---------------------------------------------------------------------------------------------
// Drawing helpers

const KCOLOURS = ['#0b63b6', '#c23b22', '#2e8b57', '#8e44ad', '#d35400', '#16a085', '#7f8c8d', '#b7950b',
  '#2c3e50', '#e84393'];
const RECOMMENDED = '#1e8b3a';
const REJECTED = '#9aa5ae';
const LIMIT = '#b3261e';

function kColour(index) {
  return KCOLOURS[index % KCOLOURS.length];
}

// Engagement colour: grey for none, then blue → orange → red up to 180° and beyond.
function engagementColour(deg) {
  if (!(deg > 0)) return '#b8c2cb';
  const t = Math.min(1, deg / 180);
  const stops = [[11, 99, 182], [230, 150, 20], [200, 30, 30]];
  const [a, b, u] = t < 0.5 ? [stops[0], stops[1], t / 0.5] : [stops[1], stops[2], (t - 0.5) / 0.5];
  const c = a.map((v, i) => Math.round(v + (b[i] - v) * u));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}

// Index of the sample nearest to `v` on the axis `key` (sorted ascending).
function nearestIndex(samples, key, v) {
  let low = 0;
  let high = samples.length - 1;
  while (high - low > 1) {
    const mid = (low + high) >> 1;
    if (samples[mid][key] < v) low = mid; else high = mid;
  }
  return Math.abs(samples[low][key] - v) <= Math.abs(samples[high][key] - v) ? low : high;
}

// ---------------------------------------------------------------------------------------------
// Plan view: what plot/tool-plan.js's ToolPlan draws from an answer (stock, path coloured by engagement)

function base64Bits(text) {
  const binary = atob(text.replace(/\s/g, ''));
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

// Points of a path input ([[x, y], ...] or {start, segments}) as a polyline, arcs chorded.
function pathPolyline(path) {
  if (Array.isArray(path)) return path;
  if (!path || !path.start) return [];
  const points = [path.start];
  let at = path.start;
  for (const segment of path.segments || []) {
    if (segment.type === 'arc') {
      const c = segment.center || segment.centre;
      const r = Math.hypot(at[0] - c[0], at[1] - c[1]);
      const a0 = Math.atan2(at[1] - c[1], at[0] - c[0]);
      let a1 = Math.atan2(segment.to[1] - c[1], segment.to[0] - c[0]);
      const ccw = (segment.dir || segment.direction) !== 'cw';
      if (ccw && a1 <= a0) a1 += 2 * Math.PI;
      if (!ccw && a1 >= a0) a1 -= 2 * Math.PI;
      const steps = Math.max(4, Math.ceil(Math.abs(a1 - a0) / 0.1));
      for (let i = 1; i <= steps; i++) {
        const a = a0 + (a1 - a0) * i / steps;
        points.push([c[0] + r * Math.cos(a), c[1] + r * Math.sin(a)]);
      }
    } else {
      points.push(segment.to);
    }
    at = segment.to;
  }
  return points;
}

function stockRings(stock) {
  if (!stock) return [];
  if (stock.polygon) return [stock.polygon, ...(stock.holes || [])];
  if (stock.polygons) return stock.polygons.flatMap((p) => [p.outer, ...(p.holes || [])]);
  return [];
}

// The plan view's drawing (plot/tool-plan.js's ToolPlan) from an answer: the stock's rings, its bitmap's
// material cells, earlier cuts as swept strokes, and the path coloured by the engaged angle.
function planSpec(result, answer) {
  const stock = answer.stock;
  const bitmap = stock?.bitmap;
  let cells = null;
  if (bitmap && bitmap.width * bitmap.height <= 4e6) {
    const bits = base64Bits(bitmap.data);
    cells = { origin: bitmap.origin, size: bitmap.cell, width: bitmap.width, height: bitmap.height, filled: (i, j) => {
      const bit = j * bitmap.width + i;
      return Boolean(bits[bit >> 3] & (0x80 >> (bit & 7)));
    } };
  }
  const samples = result.samples;
  return {
    rings: stockRings(stock),
    cells,
    removed: (stock?.previous_cuts || []).map((cut) => ({ points: pathPolyline(cut.path), width: 2 * cut.radius })),
    path: samples.map((s, i) => {
      const rapid = (s.flags || []).includes('rapid');
      return { at: s.position, colour: i && rapid ? '#9aa5ae' : engagementColour(s.engaged_deg), dashed: rapid, heading: s.heading_deg, arcs: s.arcs };
    }),
    radius: answer.tool?.radius ?? 0,
    legend: [[0, 'no contact'], [45, '45°'], [90, '90°'], [135, '135°'], [180, '≥180° engaged']].map(([deg, label]) => ({ label, colour: engagementColour(deg) })),
  };
}

// ---------------------------------------------------------------------------------------------
// Charts over the path (x = s or t), sharing a cursor; drawn by plot/charts.js

// The sample (and its flute values) per flute count as [x, value] points.
function perFlute(samples, key, field, k) {
  return samples.map((s) => [s[key], s[field]?.[k]]);
}

function fluteLabel(flute) {
  return `${flute.flute_count} flute${flute.flute_count === 1 ? '' : 's'}${flute.recommended ? ' ✓' : ''}`;
}

function seriesCharts(column, result, answer, axis, onCursor) {
  const samples = result.samples;
  const key = axis === 'time' ? 't' : 's';
  const last = samples[samples.length - 1] || { s: 0, t: 0 };
  const x = [0, Math.max(1e-9, last[key])];
  const xLabel = axis === 'time' ? `time, s (${result.time_flute_count} flutes)` : 'path length s, mm';
  const charts = [];
  const chart = (label, height, spec) => {
    const made = new PathChart(column, { label, height });
    made.onHover((v) => onCursor(v === undefined || !samples.length ? undefined : nearestIndex(samples, key, v)));
    made.draw({ x, xLabel, ...spec });
    charts.push(made);
    return made;
  };
  const lines = (field) => result.flutes.map((flute, k) => ({
    label: fluteLabel(flute), colour: kColour(k), width: flute.recommended ? 2.2 : 1.1, points: perFlute(samples, key, field, k),
  }));

  // Contact-position graph (docs/spec/engagement.md §3.1, 410): engaged arcs at every sample.
  const back = samples.some((s) => s.arcs.some(([from]) => from < -1e-9));
  const thetaRange = back ? [-180, 180] : [0, 180];
  chart('Contact position over the path', 280, {
    yLabel: 'contact angle θ, °', y: thetaRange, series: [],
    legend: [{ label: 'engaged arc (θ: 90° ahead, 0° right, 180° left of travel)', colour: '#0b3d91' }]
      .concat(result.contact_dots ? [{ label: 'removed dots', colour: 'rgb(230, 120, 0)' }] : []),
    paint(g, map) {
      g.fillStyle = '#0b3d91';
      // Each sample's arcs span from its x to the next sample's, on whole pixels (no moiré).
      samples.forEach((sample, i) => {
        const next = samples[i + 1];
        const x0 = Math.floor(map.x(sample[key]));
        const w = Math.max(1, (next ? Math.floor(map.x(next[key])) : x0 + 1) - x0);
        for (const [from, to] of sample.arcs) {
          const pieces = to > 180 ? [[from, 180], [-180, to - 360]] : [[from, to]];
          for (const [a, b] of pieces) {
            const lo = Math.max(thetaRange[0], a);
            const hi = Math.min(thetaRange[1], b);
            if (hi < lo) continue;
            g.fillRect(x0, Math.floor(map.y(hi)), w, Math.max(1, Math.ceil(map.y(lo) - map.y(hi))));
          }
        }
      });
      if (result.contact_dots && key === 's') {
        // The dots engine's removed dots (the patent's scatter).
        g.fillStyle = 'rgba(230, 120, 0, 0.35)';
        for (const [s, theta] of result.contact_dots) g.fillRect(Math.floor(map.x(s)), Math.floor(map.y(theta)), 1, 1);
      }
    },
  });

  // Radial depth of cut (420).
  chart('Radial depth of cut over the path', 170, {
    yLabel: 'a_e, mm',
    series: [{ label: 'radial depth of cut a_e', colour: '#2e8b57', points: samples.map((s) => [s[key], s.radial_depth]) }],
  });

  // Summed chip thickness per flute count (430) with the limit.
  const limit = answer.thickness_limit;
  chart('Summed chip thickness per flute count over the path', 240, {
    yLabel: 'chip thickness H, mm', series: lines('thickness'),
    limits: [{ value: limit, label: `limit ${limit} mm`, colour: LIMIT }],
  });

  // Spindle torque and power per flute count (with Kienzle values): power is torque times
  // 2πN/60, so one curve per flute count reads on both axes, with the machine's limits.
  const torqueAt = samples.find((s) => s.torque_nm?.some((m) => m > 0));
  if (torqueAt) {
    const k = torqueAt.torque_nm.findIndex((m) => m > 0);
    const factor = torqueAt.power_kw[k] / torqueAt.torque_nm[k];
    const forces = result.forces || {};
    chart('Spindle torque and power per flute count over the path', 260, {
      yLabel: 'spindle torque, N·m', y2: { label: 'spindle power, kW', factor }, series: lines('torque_nm'),
      limits: [
        { value: forces.spindle_torque_nm, label: `machine torque ${forces.spindle_torque_nm} N·m`, colour: LIMIT },
        { value: forces.spindle_power_kw / factor, label: `machine power ${forces.spindle_power_kw} kW`, colour: '#8a5a00' },
      ],
    });
  }

  // The feed plan's F words along the path.
  const plan = result.feed_plan;
  if (plan && plan.blocks.length) {
    const toX = (s) => (key === 's' ? s : samples[nearestIndex(samples, 's', s)].t);
    chart('Planned feed over the path', 190, {
      yLabel: 'feed F, mm/min',
      series: [{ label: `planned feed (chip ${plan.target_thickness} mm, ${plan.flute_count} flutes)`, colour: '#8e44ad', width: 2,
        steps: plan.blocks.filter((b) => b.feed !== undefined).map((b) => [toX(b.from_s), toX(b.to_s), b.feed]) }],
      limits: [{ value: plan.max_feed, label: `max feed ${plan.max_feed}`, colour: LIMIT }],
    });
  }
  return {
    charts,
    cursor(index) {
      for (const made of charts) made.cursor(index === undefined ? undefined : samples[index][key]);
    },
  };
}

// ---------------------------------------------------------------------------------------------
// Per flute count: representative values (440) and time (450), recommended k highlighted

function fluteCharts(column, result, answer) {
  const flutes = result.flutes;
  const best = result.recommended[0];
  const row = document.createElement('div');
  row.className = 'chart-row';
  column.append(row);
  const colour = (f) => (f.recommended ? RECOMMENDED : REJECTED);
  const legend = [{ label: 'meets the limits', colour: RECOMMENDED, swatch: 'bar' }, { label: 'does not', colour: REJECTED, swatch: 'bar' }];
  const categories = flutes.map((f) => String(f.flute_count));
  barChart(row, 'Chip thickness per flute count', {
    title: 'chip thickness H, mm: largest (bar), mean ▬, least ▭', xLabel: 'flute count', categories, legend,
    bars: flutes.map((f) => ({ value: f.max_thickness, mean: f.mean_thickness, min: f.min_thickness, colour: colour(f), best: f.flute_count === best })),
    limits: [{ value: answer.thickness_limit, label: `limit ${answer.thickness_limit} mm`, colour: LIMIT }],
  });
  barChart(row, 'Machining time per flute count', {
    title: 'machining time, s', xLabel: 'flute count', categories, legend,
    bars: flutes.map((f) => ({ value: f.time_s, colour: colour(f), best: f.flute_count === best })),
    limits: [{ value: answer.time_limit_s, label: `limit ${answer.time_limit_s} s`, colour: LIMIT }],
  });
}

// ---------------------------------------------------------------------------------------------
// Result renderer (form and Jobs view)

// What a limit a flute count misses is called, and "spindle torque 14.7 N·m > 10 N·m (+47 %)".
const LIMIT_NAMES = {
  thickness: ['chip thickness', 'mm'], time: ['time', 's'], spindle_torque: ['spindle torque', 'N·m'],
  spindle_power: ['spindle power', 'kW'], spindle_speed: ['spindle speed', 'rpm'], machine_feed: ['feed', 'mm/min'],
};
const MACHINE_LIMITS = ['spindle_torque', 'spindle_power', 'spindle_speed', 'machine_feed'];

function overText(over) {
  const [name, unit] = LIMIT_NAMES[over.limit] || [over.limit, ''];
  const digits = Math.abs(over.value) >= 100 ? 0 : Math.abs(over.value) >= 1 ? 2 : 4;
  return `${name} ${number(over.value, digits)} ${unit} > ${over.allowed} ${unit} (+${number(100 * (over.value / over.allowed - 1), 0)} %)`;
}

// The verdict above the charts: the recommended flute counts, each flute count the machine's
// limits rule out with the limit and by how much, and the flute count the feed plan and the
// program are for.
function verdictMessage(result) {
  const rec = result.recommended;
  const lines = [rec.length
    ? `Recommended flute counts: ${rec.join(', ')} (fastest first; ★ = ${rec[0]})`
    : 'No flute count meets the limits'];
  const ruledOut = result.flutes.filter((f) => (f.over_limits || []).some((o) => MACHINE_LIMITS.includes(o.limit)));
  for (const f of ruledOut) {
    const over = f.over_limits.filter((o) => MACHINE_LIMITS.includes(o.limit));
    lines.push(`${f.flute_count} flutes over the machine's limits: ${over.map(overText).join(', ')}`);
  }
  if (result.program_flute_count !== undefined) {
    const own = result.program_flute_count === result.time_flute_count ? " (the tool's)" : ` (the tool has ${result.time_flute_count}: use a ${result.program_flute_count}-flute cutter)`;
    lines.push(`Feed plan and G-code for ${result.program_flute_count} flutes${own}`);
  }
  const box = message(rec.length ? 'ok' : 'warning', lines[0]);
  box.classList.add('recommendation');
  for (const line of lines.slice(1)) {
    const p = document.createElement('p');
    p.className = line.includes("machine's limits") ? 'over-limits' : 'program-flutes';
    p.textContent = line;
    box.append(p);
  }
  return box;
}

function fluteTable(result) {
  const table = document.createElement('table');
  table.className = 'flutes';
  // With Kienzle values the flute counts also carry torque, power and the tooth-passing frequency.
  const physics = result.flutes.some((f) => f.mean_torque_nm !== undefined && f.mean_torque_nm !== null);
  const head = ['flutes', 'feed per tooth, mm', 'feed, mm/min', 'largest H, mm', 'mean H', 'least H', 'median H', 'time, s', 'teeth at once']
    .concat(physics ? ['torque mean / peak, N·m', 'power mean / peak, kW', 'tooth passing, Hz'] : [], ['recommended']);
  table.innerHTML = `<thead><tr>${head.map((h) => `<th>${h}</th>`).join('')}</tr></thead>`;
  const body = document.createElement('tbody');
  for (const f of result.flutes) {
    const tr = document.createElement('tr');
    if (f.recommended) tr.className = 'recommended';
    if (f.flute_count === result.recommended[0]) tr.classList.add('best');
    const loads = physics ? [`${number(f.mean_torque_nm, 2)} / ${number(f.peak_torque_nm, 2)}`,
      `${number(f.mean_power_kw, 3)} / ${number(f.peak_power_kw, 3)}`, number(f.tooth_passing_hz, 1)] : [];
    for (const text of [f.flute_count, number(f.feed_per_tooth, 4), number(f.feed, 0), number(f.max_thickness, 5),
      number(f.mean_thickness, 5), number(f.min_thickness, 5), number(f.median_thickness, 5), number(f.time_s, 2),
      f.max_teeth, ...loads, f.recommended ? (f.flute_count === result.recommended[0] ? '★ yes (fastest)' : 'yes')
        : `no${f.over_limits?.length ? `: ${f.over_limits.map(overText).join(', ')}` : ''}`]) {
      const td = document.createElement('td');
      td.textContent = String(text);
      tr.append(td);
    }
    body.append(tr);
  }
  table.append(body);
  return table;
}

function readout(sample, result) {
  if (!sample) return 'Move over a chart or the path to place the tool.';
  const arcs = sample.arcs.map(([a, b]) => `[${a.toFixed(1)}°, ${b.toFixed(1)}°]`).join(' ') || 'none';
  const h = result.flutes.map((f, k) => `${f.flute_count} flutes ${sample.thickness[k].toFixed(4)}`).join(', ');
  // Torque and power at the tool's own flute count (the one the time axis is for).
  const own = result.flutes.findIndex((f) => f.flute_count === result.time_flute_count);
  const load = sample.torque_nm?.length && own >= 0
    ? `; torque ${sample.torque_nm[own].toFixed(2)} N·m, power ${sample.power_kw[own].toFixed(3)} kW (${result.time_flute_count} flutes)` : '';
  return `s = ${sample.s.toFixed(3)} mm, t = ${sample.t.toFixed(2)} s, at (${sample.position[0].toFixed(3)}, ${sample.position[1].toFixed(3)}): arcs ${arcs}, engaged ${sample.engaged_deg.toFixed(1)}°, a_e = ${sample.radial_depth.toFixed(3)} mm; chip thickness H: ${h}${load}`;
}

function renderColumn(column, result, answer, axis) {
  column.replaceChildren();
  const heading = document.createElement('h3');
  heading.textContent = result.name || 'path';
  const verdict = verdictMessage(result);
  const summary = document.createElement('div');
  summary.className = 'summary';
  const items = [
    ['path length, mm', number(result.path_length, 2)],
    ['feed length, mm', number(result.feed_length, 2)],
    ['largest engaged angle, °', `${number(result.max_engaged_deg, 1)} at s ${number(result.max_engaged_at_s, 2)}`],
    ['max radial depth, mm', number(result.max_radial_depth, 3)],
    ['engine, step', `${result.engine}, ${+result.step.toPrecision(4)} mm`],
    ['samples', result.samples.length],
  ];
  if (result.feed_plan) {
    const plan = result.feed_plan;
    items.push(['feed plan time, s', `${number(plan.time_s, 2)} (nominal ${number(plan.nominal_time_s, 2)})`]);
    items.push(['planned feeds, mm/min', `${+plan.feed_range[0].toPrecision(5)} – ${+plan.feed_range[1].toPrecision(5)}`]);
  }
  if (result.blocks) {
    const b = result.blocks;
    items.push(['program blocks (short)', `${b.blocks} (${b.short_blocks})`], ['block-limited time, s', number(b.estimated_time_s, 2)]);
  }
  if (result.forces) items.push(['depth of cut a_p, mm', number(result.forces.axial_depth, 3)]);
  if (result.max_mrr !== undefined) items.push(['max MRR, mm³/min', number(result.max_mrr, 0)]);
  showSummary(summary, items);
  const plan = document.createElement('canvas');
  plan.className = 'chart plan';
  plan.setAttribute('aria-label', 'Plan view: stock and path coloured by engagement');
  const info = document.createElement('p');
  info.className = 'hint cursor-readout';
  column.append(heading, verdict, summary, plan, info);
  const planView = new ToolPlan(plan, planSpec(result, answer));
  let series;
  // The timeline along the samples: the same cursor from the keyboard (arrow keys step).
  const slider = document.createElement('input');
  slider.type = 'range';
  slider.min = '0';
  slider.max = String(Math.max(0, result.samples.length - 1));
  slider.value = '0';
  slider.className = 'sample-timeline';
  slider.setAttribute('aria-label', `Timeline along ${result.name || 'the path'} (tool position)`);
  slider.addEventListener('input', () => setCursor(Number(slider.value)));
  info.before(slider);
  const setCursor = (index) => {
    planView.cursor(index);
    series.cursor(index);
    info.textContent = readout(index === undefined ? undefined : result.samples[index], result);
    if (index !== undefined) slider.value = String(index);
  };
  series = seriesCharts(column, result, answer, axis, setCursor);
  plan.addEventListener('pointermove', (event) => setCursor(planView.nearest(event)));
  plan.addEventListener('pointerleave', () => setCursor(undefined));
  info.textContent = readout(undefined, result);
  fluteCharts(column, result, answer);
  const scroll = document.createElement('div');
  scroll.className = 'table-scroll';
  scroll.append(fluteTable(result));
  column.append(scroll);
  if (result.warnings.length) {
    // Warnings folded under their codes, so the columns stay comparable.
    const details = document.createElement('details');
    details.className = 'warnings';
    const counts = new Map();
    for (const w of result.warnings) counts.set(w.code, (counts.get(w.code) || 0) + 1);
    const summaryLine = document.createElement('summary');
    const words = (code) => code.replace(/^W_/, '').toLowerCase().replace(/_/g, ' ');
    summaryLine.textContent = `Warnings: ${[...counts].map(([code, n]) => (n > 1 ? `${words(code)} ×${n}` : words(code))).join(', ')}`;
    summaryLine.title = [...counts.keys()].join(', ');
    details.append(summaryLine, ...warningMessages(result.warnings));
    column.append(details);
  }
  column.cursor = setCursor;
}

// Shows an engagement answer in `container`: one candidate path at a time, chosen with tabs that
// name each path's best flute count; the charts take the width of the result column.
// `onSelect(index)` hears which candidate is shown (the form's G-code choice follows it); with
// `cutStock` (where it comes from: `requestStock`, `jobStock`) the stock its program cuts is drawn
// in 3-D. With the `request`, the verification names the path whose program it cut (its
// `candidate`), whichever tab is shown.
export function engagementResult(container, answer, { onSelect, cutStock = null, request = null } = {}) {
  container.replaceChildren();
  const candidates = answer.candidates || [answer];
  const controls = document.createElement('div');
  controls.className = 'actions';
  const axis = document.createElement('select');
  axis.setAttribute('aria-label', 'x axis');
  axis.append(new Option('x axis: path length', 'length'), new Option('x axis: time', 'time'));
  const tabs = document.createElement('div');
  tabs.setAttribute('role', 'tablist');
  tabs.setAttribute('aria-label', 'Candidate paths');
  tabs.className = 'tabs';
  controls.append(tabs, axis);
  const columns = document.createElement('div');
  columns.className = 'candidates';
  container.append(controls, columns);
  // The path the request programs and verifies, shown first.
  const programmed = request?.candidate ?? 0;
  const verified = answer.candidates && request ? candidates[programmed] : null;
  if (answer.verification) {
    partlessPanel(container, {
      name: 'engagement',
      verification: answer.verification,
      source: cutStock,
      why: 'press “Cut stock” to cut the program again',
      title: verified ? `Verification: the program of ${verified.name || `path ${programmed}`} cut on its own model` : undefined,
    });
  }
  const id = `candidate-${Math.random().toString(36).slice(2, 8)}`;
  const cells = candidates.map((result, i) => {
    const column = document.createElement('div');
    column.className = 'candidate';
    column.id = `${id}-${i}`;
    column.setAttribute('role', 'tabpanel');
    const tab = document.createElement('button');
    tab.type = 'button';
    tab.setAttribute('role', 'tab');
    tab.setAttribute('aria-controls', column.id);
    const best = result.recommended?.[0];
    tab.textContent = `${result.name || `path ${i}`}${best ? ` · best ${best} flutes` : ' · no flute count fits'}`;
    tab.addEventListener('click', () => select(i));
    tab.addEventListener('keydown', (e) => {
      const step = { ArrowRight: 1, ArrowLeft: -1 }[e.key];
      if (!step) return;
      e.preventDefault();
      select((i + step + candidates.length) % candidates.length);
      tabs.children[(i + step + candidates.length) % candidates.length].focus();
    });
    tabs.append(tab);
    columns.append(column);
    return column;
  });
  let shown = verified ? programmed : 0;
  const select = (index) => {
    shown = index;
    cells.forEach((cell, i) => {
      cell.hidden = i !== index;
      if (i !== index) cell.replaceChildren();
      tabs.children[i].setAttribute('aria-selected', String(i === index));
      tabs.children[i].tabIndex = i === index ? 0 : -1;
    });
    // Drawn again now that it has its width.
    renderColumn(cells[index], candidates[index], answer, axis.value);
    onSelect?.(index);
  };
  // Only the candidate shown is drawn (select draws it), so a comparison of many paths is
  // as light as one.
  axis.addEventListener('change', () => select(shown));
  select(shown);
  // Charts follow the width of the result column (a window resized, columns stacked).
  let width = columns.clientWidth;
  let timer = null;
  new ResizeObserver(() => {
    if (!columns.isConnected || !columns.clientWidth || Math.abs(columns.clientWidth - width) < 20) return;
    width = columns.clientWidth;
    clearTimeout(timer);
    timer = setTimeout(() => renderColumn(cells[shown], candidates[shown], answer, axis.value), 150);
  }).observe(columns);
  return cells;
}

// ---------------------------------------------------------------------------------------------

export const engagementView = {
  mount(root, id) {
    root.innerHTML = FORM;
    const form = root.querySelector('#engagement-form');
    const messages = root.querySelector('#engagement-messages');
    const result = root.querySelector('#engagement-result');
    for (const sample of SAMPLE_PATHS) addPath(form, sample.name, sample.text);
    root.querySelector('#engagement-add-path').addEventListener('click', () => addPath(form, `path ${pathBoxes(form).length + 1}`, ''));
    form.addEventListener('change', () => syncVisibility(form));
    loadTools(form.elements.tool_choice, 'inline flat end mill (size below)', () => true, (tool) => `${toolLabel(tool)} z${tool.flutes}`).then(() => syncVisibility(form));
    loadMachines(form.elements.machine);
    // The max feed stays what the form says: a machine caps it (the answer says so), it never
    // replaces it; left empty, the machine's is used.
    loadMaterials(form.elements.material, 'the values below');
    // A stored material replaces the typed values: the fields show its values, greyed, and get
    // the typed ones back when "the values below" is chosen again.
    const showMaterial = () => {
      const material = form.elements.material.materials?.get(value(form, 'material'));
      for (const name of ['kc11', 'mc']) {
        const input = form.elements[name];
        if (material) {
          if (!input.disabled) input.dataset.typed = input.value;
          input.value = material[name];
        } else if (input.disabled) {
          input.value = input.dataset.typed ?? input.defaultValue;
        }
        input.disabled = Boolean(material);
      }
    };
    form.elements.material.addEventListener('change', showMaterial);
    syncVisibility(form);
    const fillCandidates = () => {
      const select = form.elements.candidate;
      const previous = select.value;
      select.replaceChildren(...pathBoxes(form).map((box, i) => new Option(`path ${i}: ${box.querySelector('input').value || 'unnamed'}`, String(i))));
      if (previous && Number(previous) < select.options.length) select.value = previous;
    };
    fillCandidates();
    form.addEventListener('input', fillCandidates);
    submitFlow(form, {
      messages,
      result,
      read: () => {
        fillCandidates();
        return engagementRequest(form);
      },
      ask: (body) => api('POST', '/api/v1/engagement', body),
      show: (answer, body) => {
        engagementResult(result, answer, { onSelect: (i) => { form.elements.candidate.value = String(i); }, cutStock: requestStock('engagement', body), request: body });
        result.dataset.state = 'drawn';
      },
    });
    // The program of the candidate chosen for G-code (the tab shown, or the select).
    const candidate = () => value(form, 'candidate') || '0';
    downloadFlow(root.querySelector('#engagement-gcode'), form, {
      messages,
      read: () => engagementRequest(form),
      path: '/api/v1/engagement',
      query: () => `${gcodeQuery(form)}&candidate=${candidate()}`,
      name: () => programName(`engagement-${candidate()}`, form),
      done: () => messages.replaceChildren(),
    });
    keepForm(id, form, {
      more: {
        save: () => pathBoxes(form).map((box) => ({ name: box.querySelector('input').value, text: box.querySelector('textarea').value })),
        restore: (paths) => {
          if (!Array.isArray(paths) || !paths.length) return;
          pathBoxes(form).forEach((box) => box.remove());
          for (const path of paths) addPath(form, path.name, path.text);
          fillCandidates();
        },
      },
      onReset: (clear) => {
        pathBoxes(form).forEach((box) => box.remove());
        for (const sample of clear ? [{ name: 'path 1', text: '' }] : SAMPLE_PATHS) addPath(form, sample.name, examplePoints(form, sample.text));
        fillCandidates();
      },
    });
  },
};

// This capability's view in the page's list (`web/views.js` loads it by the capability's name).
export const view = { title: 'Engagement', mount: engagementView.mount, result: engagementResult };
