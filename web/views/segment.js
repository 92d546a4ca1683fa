// Segment view: cut a curve into G01 blocks by the control's block time (docs/spec/api.md, Segment;
// docs/spec/segment.md). A form for the curve and the rule, the curve with its blocks, the chord error and the
// block length along the curve, the rule side by side with a fixed tolerance, G-code download.
import { DXF_FIELDS, dxfUpload } from '/dxf.js';
import { Timeline } from '/timeline.js';
import { noStockNote } from '/plot/cut-stock.js';
import { answerAndProgram, downloadFlow, keepForm, loadMachines, machineFields, machineNote, message, number, numeric, POST_OPTIONS, programName, refusalMessage, showSummary, submitFlow, value, warningMessages } from '/form.js';
import { drawChart } from '/plot/charts.js';
import { CurvePlan } from '/plot/plan.js';

const FORM = `
<div class="layout">
  <form id="segment-form" novalidate>
    <fieldset><legend>Curve</legend>
      <label>Curve <select name="kind" data-field="curve.kind">
        <option value="circle">circle</option><option value="arc">arc</option><option value="ellipse">ellipse</option>
        <option value="polyline">polyline (points)</option><option value="bspline">B-spline / NURBS</option></select></label>
      <label data-kinds="circle arc ellipse">Centre x, y, mm <span class="pair">
        <input name="cx" type="number" step="any" value="0" data-field="curve.centre">
        <input name="cy" type="number" step="any" value="0" data-field="curve.centre"></span></label>
      <label data-kinds="circle arc">Radius, mm <input name="radius" type="number" step="any" value="50" data-field="curve.radius"></label>
      <label data-kinds="ellipse">Semi-axes a, b, mm <span class="pair">
        <input name="a" type="number" step="any" value="100" data-field="curve.semi_axes">
        <input name="b" type="number" step="any" value="50" data-field="curve.semi_axes"></span></label>
      <label data-kinds="circle arc ellipse">Start, ° <input name="start_deg" type="number" step="any" value="0" data-field="curve.start_deg"></label>
      <label data-kinds="arc ellipse">End, ° <input name="end_deg" type="number" step="any" value="90" data-field="curve.end_deg"></label>
      <label data-kinds="ellipse">Rotation, ° <input name="rotation_deg" type="number" step="any" value="0" data-field="curve.rotation_deg"></label>
      <label data-kinds="circle arc ellipse">Direction <select name="direction" data-field="curve.direction"><option value="ccw">ccw</option><option value="cw">cw</option></select></label>
      <label data-kinds="polyline">Points (x y [z] per line) <textarea name="points" rows="6" data-field="curve.points" data-dim="points"></textarea></label>
      <div data-kinds="polyline">${DXF_FIELDS}</div>
      <label data-kinds="bspline">Degree (no unit) <input name="degree" type="number" min="1" max="5" value="3" data-field="curve.degree"></label>
      <label data-kinds="bspline">Control points (x y [z] per line) <textarea name="control_points" rows="6" data-field="curve.control_points" data-dim="points">0 0
40 0
40 40
0 40
0 80
40 80</textarea></label>
      <label data-kinds="bspline">Knots (optional) <input name="knots" type="text" placeholder="clamped uniform" data-field="curve.knots"></label>
      <label data-kinds="bspline">Weights (optional) <input name="weights" type="text" placeholder="all 1" data-field="curve.weights"></label>
    </fieldset>
    <fieldset><legend>Control and rule</legend>
      <label>Machine <select name="machine" data-field="machine"></select></label>
      <label>Feed, mm/min <input name="feed" type="number" step="any" value="10000" data-field="feed"></label>
      <label>Block time, ms <input name="block_time_ms" type="number" step="any" value="4" data-field="block_time_ms"></label>
      <label>Chord error chosen <select name="mode" data-field="mode"><option value="guarantee" selected>no short blocks (guarantee)</option><option value="window">per window</option><option value="curve">whole curve</option></select></label>
      <label data-mode="window">Window length, mm <input name="window" type="number" step="any" placeholder="5 target chords" data-field="window"></label>
      <label data-mode="window">Radius estimate <select name="radius_estimate" data-field="radius_estimate"><option value="three_point">three points per window</option><option value="minimum">smallest radius in the window</option></select></label>
      <label data-mode="curve">Rule <select name="rule" data-field="rule"><option value="extremes">smallest radius</option><option value="max">largest window value</option><option value="normal_accel">normal acceleration</option></select></label>
      <label><span>Block margin (no unit) <abbr class="symbol" title="k_f in docs/spec/segment.md">k_f</abbr></span> <input name="margin" type="number" step="any" value="1" data-field="margin"></label>
      <label>Smallest chord error, mm <input name="min_chord_error" type="number" step="any" value="0" data-field="min_chord_error"></label>
      <label>Tolerance, mm <input name="tolerance" type="number" step="any" placeholder="none" data-field="tolerance"></label>
      <label>Compare with a fixed tolerance, mm <input name="compare_tolerance" type="number" step="any" value="0.01" data-field="compare_tolerance"></label>
    </fieldset>
    <div class="actions">
      <button class="primary" type="submit" id="segment-compute">Compute</button>
      <select name="dialect" aria-label="G-code dialect"><option value="">machine's dialect</option>${POST_OPTIONS}</select>
      <button class="secondary" type="button" id="segment-gcode">G-code</button>
    </div>
    <p class="hint">With a machine chosen, its values show greyed in the empty fields and are used; type a value to override it.</p>
  </form>
  <section>
    <div id="segment-messages"></div>
    <div id="segment-result"></div>
  </section>
</div>`;

// The G-code query: the chosen dialect, else the machine's.
function segmentQuery(form) {
  const dialect = value(form, 'dialect');
  return `?format=gcode${dialect ? `&dialect=${dialect}` : ''}`;
}

// "x y [z]" per line (commas or spaces), or a JSON array.
function pointList(text) {
  const trimmed = text.trim();
  if (trimmed.startsWith('[')) return JSON.parse(trimmed);
  return trimmed.split('\n').map((line) => line.trim()).filter((line) => line && !line.startsWith('#'))
    .map((line) => line.split(/[\s,;]+/).filter(Boolean).map(Number));
}

function numberList(text) {
  const trimmed = text.trim();
  return trimmed === '' ? undefined : trimmed.replace(/^\[|\]$/g, '').split(/[\s,;]+/).filter(Boolean).map(Number);
}

function dropUndefined(object) {
  return Object.fromEntries(Object.entries(object).filter(([, v]) => v !== undefined && v !== ''));
}

// The request body from the form (field names as docs/spec/api.md).
export function segmentRequest(form) {
  const kind = value(form, 'kind');
  const centre = [numeric(form, 'cx') ?? 0, numeric(form, 'cy') ?? 0];
  let curve;
  if (kind === 'circle') curve = { kind, centre, radius: numeric(form, 'radius'), start_deg: numeric(form, 'start_deg') ?? 0, direction: value(form, 'direction') };
  if (kind === 'arc') curve = { kind, centre, radius: numeric(form, 'radius'), start_deg: numeric(form, 'start_deg') ?? 0, end_deg: numeric(form, 'end_deg') ?? 0, direction: value(form, 'direction') };
  if (kind === 'ellipse') {
    curve = { kind, centre, semi_axes: [numeric(form, 'a'), numeric(form, 'b')], start_deg: numeric(form, 'start_deg') ?? 0,
      end_deg: numeric(form, 'end_deg'), rotation_deg: numeric(form, 'rotation_deg') ?? 0, direction: value(form, 'direction') };
  }
  if (kind === 'polyline') curve = { kind, points: pointList(value(form, 'points')) };
  if (kind === 'bspline') {
    curve = dropUndefined({ kind, degree: numeric(form, 'degree'), control_points: pointList(value(form, 'control_points')),
      knots: numberList(value(form, 'knots')), weights: numberList(value(form, 'weights')) });
  }
  const mode = value(form, 'mode');
  return dropUndefined({
    curve,
    machine: value(form, 'machine') || undefined,
    feed: numeric(form, 'feed'),
    block_time_ms: numeric(form, 'block_time_ms'),
    mode,
    window: mode === 'window' ? numeric(form, 'window') : undefined,
    radius_estimate: mode === 'window' ? value(form, 'radius_estimate') : undefined,
    rule: mode === 'curve' ? value(form, 'rule') : undefined,
    margin: numeric(form, 'margin'),
    min_chord_error: numeric(form, 'min_chord_error'),
    tolerance: numeric(form, 'tolerance'),
    compare_tolerance: numeric(form, 'compare_tolerance'),
  });
}

function syncVisibility(form) {
  const kind = value(form, 'kind');
  const mode = value(form, 'mode');
  form.querySelectorAll('[data-kinds]').forEach((e) => { e.hidden = !e.dataset.kinds.split(' ').includes(kind); });
  form.querySelectorAll('[data-mode]').forEach((e) => { e.hidden = e.dataset.mode !== mode; });
}


// Points of the target curve for the plot, when the request is known (the form view).
function curvePoints(curve) {
  const steps = 720;
  const wrap = (start, end, direction) => {
    const forward = direction === 'cw' ? start - end : end - start;
    const wrapped = ((forward % 360) + 360) % 360;
    return wrapped === 0 && forward !== 0 ? 360 : wrapped;
  };
  const sense = (d) => (d === 'cw' ? -1 : 1);
  if (curve.kind === 'circle' || curve.kind === 'arc') {
    const sweep = curve.kind === 'circle' ? 360 : wrap(curve.start_deg, curve.end_deg, curve.direction);
    return Array.from({ length: steps + 1 }, (_, i) => {
      const t = (curve.start_deg + sense(curve.direction) * sweep * i / steps) * Math.PI / 180;
      return [curve.centre[0] + curve.radius * Math.cos(t), curve.centre[1] + curve.radius * Math.sin(t)];
    });
  }
  if (curve.kind === 'ellipse') {
    const end = curve.end_deg ?? curve.start_deg + 360;
    const sweep = wrap(curve.start_deg, end, curve.direction);
    const [a, b] = curve.semi_axes;
    const r = (curve.rotation_deg || 0) * Math.PI / 180;
    return Array.from({ length: steps + 1 }, (_, i) => {
      const t = (curve.start_deg + sense(curve.direction) * sweep * i / steps) * Math.PI / 180;
      const [x, y] = [a * Math.cos(t), b * Math.sin(t)];
      return [curve.centre[0] + x * Math.cos(r) - y * Math.sin(r), curve.centre[1] + x * Math.sin(r) + y * Math.cos(r)];
    });
  }
  if (curve.kind === 'polyline') return curve.points;
  if (curve.kind === 'bspline') return nurbsPoints(curve, 2000);
  return [];
}

// Evaluates a clamped NURBS (Cox–de Boor) at `count` + 1 parameters.
function nurbsPoints(curve, count) {
  const p = curve.degree;
  const control = curve.control_points;
  const n = control.length;
  const weights = curve.weights || control.map(() => 1);
  let knots = curve.knots;
  if (!knots) {
    const inner = n - p - 1;
    knots = [...Array(p + 1).fill(0), ...Array.from({ length: inner }, (_, i) => (i + 1) / (inner + 1)), ...Array(p + 1).fill(1)];
  }
  const [u0, u1] = [knots[p], knots[n]];
  const basis = (u) => {
    let span = p;
    while (span < n - 1 && u >= knots[span + 1]) span++;
    const values = Array(p + 1).fill(0);
    values[0] = 1;
    const left = [], right = [];
    for (let j = 1; j <= p; j++) {
      left[j] = u - knots[span + 1 - j];
      right[j] = knots[span + j] - u;
      let saved = 0;
      for (let r = 0; r < j; r++) {
        const temp = values[r] / (right[r + 1] + left[j - r]);
        values[r] = saved + right[r + 1] * temp;
        saved = left[j - r] * temp;
      }
      values[j] = saved;
    }
    return [span, values];
  };
  return Array.from({ length: count + 1 }, (_, i) => {
    const [span, values] = basis(u0 + (u1 - u0) * i / count);
    let [x, y, w] = [0, 0, 0];
    for (let j = 0; j <= p; j++) {
      const k = span - p + j;
      const bw = values[j] * weights[k];
      x += bw * control[k][0];
      y += bw * control[k][1];
      w += bw;
    }
    return [x / w, y / w];
  });
}

// The rule side by side with the fixed tolerance.
function comparisonTable(answer) {
  const table = document.createElement('table');
  table.className = 'comparison';
  const fixed = answer.comparison;
  const head = document.createElement('tr');
  for (const text of ['', 'block-time rule', fixed ? `fixed ${fixed.tolerance} mm` : 'fixed (set “compare with”)']) {
    const th = document.createElement('th');
    th.textContent = text;
    head.append(th);
  }
  const rows = [
    ['blocks', (s) => s.blocks],
    ['shortest block, mm', (s) => number(s.min_block_length, 4)],
    [`short blocks (< ${number(answer.block_length, 4)} mm)`, (s) => s.short_blocks],
    ['max deviation, mm', (s) => number(s.max_deviation, 6)],
    ['estimated time, s', (s) => number(s.estimated_time_s, 3)],
    ['largest vertex angle, °', (s) => number(s.max_vertex_angle_deg, 2)],
  ];
  const body = rows.map(([name, pick]) => {
    const tr = document.createElement('tr');
    for (const text of [name, pick(answer), fixed ? pick(fixed) : '–']) {
      const td = document.createElement('td');
      td.textContent = String(text);
      tr.append(td);
    }
    return tr;
  });
  const thead = document.createElement('thead');
  thead.append(head);
  const tbody = document.createElement('tbody');
  tbody.append(...body);
  table.append(thead, tbody);
  return table;
}

function canvas(className, label) {
  const c = document.createElement('canvas');
  c.className = className;
  c.setAttribute('aria-label', label);
  return c;
}

function heading(text) {
  const h = document.createElement('h3');
  h.textContent = text;
  return h;
}

// Shows a segment answer in `container`: summary, comparison, plan of the curve and its blocks,
// chord error and block length along the curve, warnings. `context`: the form view's `request`
// adds the target curve, `machine` names the machine's values, `program` adds the timeline.
// Used by the form and by job results.
export function segmentResult(container, answer, { request, machine, program, form } = {}) {
  container.replaceChildren();
  const warnings = document.createElement('div');
  const summaryBox = document.createElement('div');
  summaryBox.className = 'summary';
  const plan = canvas('plot', 'The curve, its blocks and their end points (plan view)');
  const hint = document.createElement('p');
  hint.className = 'hint';
  hint.textContent = 'Drag to pan, wheel to zoom at the pointer, double-click to reset. Red: blocks shorter than one block time.';
  const chordChart = canvas('chart', 'Chord error along the curve');
  const lengthChart = canvas('chart', 'Block length along the curve');
  container.append(summaryBox, comparisonTable(answer), warnings, heading('Curve and blocks'), plan, hint,
    heading('Chord error along the curve'), chordChart, heading('Block length along the curve'), lengthChart);

  const points = answer.points;
  const s = answer.s;
  const lengths = points.slice(1).map((p, i) => Math.hypot(p[0] - points[i][0], p[1] - points[i][1], (p[2] ?? 0) - (points[i][2] ?? 0)));
  const short = lengths.map((l, i) => [l, i]).filter(([l]) => l < answer.block_length * (1 - 1e-9)).map(([, i]) => i);
  const series = [];
  if (request?.curve) series.push({ label: 'target curve', points: curvePoints(request.curve), colour: '#9aa5ae', width: 1 });
  series.push({ label: `${answer.blocks} blocks`, points, colour: '#0b63b6', width: 2, marks: points.length > 4000 ? 0 : 4, count: true });
  if (short.length) series.push({ label: `shorter than one block time: ${short.length} (${answer.short_end_blocks} of them remainders at ends)`, points, segments: short, colour: '#b3261e', width: 3.5 });
  const planPlot = new CurvePlan(plan);
  planPlot.setSeries(series);
  if (program) {
    // The timeline walks the program block by block: feed, block length and time per block.
    const timeline = new Timeline(container, program, { onMove: (move) => planPlot.setMarker(move.position) });
    hint.after(timeline.root);
  }

  // Chord error per window as steps along s (each window until the next one starts: windows
  // overlap where a window's last chord runs past its end), the rule's own value, the bounds and
  // the fixed tolerance.
  const windows = answer.windows;
  const until = (i) => (i + 1 < windows.length ? Math.min(windows[i].s_end, windows[i + 1].s_start) : windows[i].s_end);
  const steps = (pick) => windows.flatMap((w, i) => [[w.s_start, pick(w)], [until(i), pick(w)]]);
  const level = (v) => [[0, v], [answer.curve_length, v]];
  const chordSeries = [{ label: 'chord error used', points: steps((w) => w.chord_error), colour: '#0b63b6', width: 2.5 }];
  if (answer.windows.some((w) => w.rule_chord_error !== w.chord_error)) {
    chordSeries.push({ label: 'rule before bounds', points: steps((w) => w.rule_chord_error), colour: '#c77700', width: 1.5, dash: [6, 4] });
  }
  if (answer.comparison) chordSeries.push({ label: `fixed ${answer.comparison.tolerance} mm`, points: level(answer.comparison.tolerance), colour: '#555', width: 1.5, dash: [3, 3] });
  if (answer.min_chord_error > 0) chordSeries.push({ label: `min chord error ${answer.min_chord_error} mm`, points: level(answer.min_chord_error), colour: '#1e7b34', width: 1.5, dash: [2, 4] });
  if (request?.tolerance) chordSeries.push({ label: `tolerance ${request.tolerance} mm`, points: level(request.tolerance), colour: '#b3261e', width: 1.5 });
  drawChart(chordChart, chordSeries, { log: true, xLabel: 'arc length s, mm', yLabel: 'chord error, mm' });

  drawChart(lengthChart, [
    { label: 'block length', points: lengths.map((l, i) => [s[i], l]), colour: '#0b63b6', dots: true },
    { label: `feed × block time = ${number(answer.block_length, 4)} mm`, points: level(answer.block_length), colour: '#b3261e', width: 1.5, dash: [6, 4] },
  ], { xLabel: 'arc length s, mm', yLabel: 'block length, mm' });

  const machineName = answer.machine ? `${answer.machine.name} (${answer.machine.dialect})` : 'none';
  showSummary(summaryBox, [
    ['blocks', answer.blocks],
    ['chord error, mm', `${number(answer.min_window_chord_error, 6)} – ${number(answer.chord_error, 6)}`],
    ['block length F·T_b, mm', number(answer.block_length, 4)],
    ['shortest block, mm', number(answer.min_block_length, 4)],
    ['short blocks', `${answer.short_blocks} (+${answer.short_end_blocks} at ends)`],
    ['max deviation, mm', number(answer.max_deviation, 6)],
    ['est. time, s', number(answer.estimated_time_s, 3)],
    ['curve length, mm', number(answer.curve_length, 3)],
    ['smallest radius, mm', answer.min_radius == null ? 'straight' : number(answer.min_radius, 3)],
    ['feed limit, mm/min', answer.feed_limit == null ? '–' : number(answer.feed_limit, 0)],
    ['feed', machineNote(answer.feed, 'mm/min', request, 'feed', machine, 'max_feed')],
    ['block time', machineNote(answer.block_time_ms, 'ms', request, 'block_time_ms', machine)],
    ['margin', machineNote(answer.margin, '', request, 'margin', machine)],
    ['machine', machineName],
  ]);
  warnings.replaceChildren(...warningMessages(answer.warnings, form), noStockNote('segment'));
  return plan;
}

export const segmentView = {
  mount(root, id) {
    root.innerHTML = FORM;
    const form = root.querySelector('#segment-form');
    const messages = root.querySelector('#segment-messages');
    const result = root.querySelector('#segment-result');
    form.elements.points.defaultValue = Array.from({ length: 91 }, (_, i) => {
      const t = i * Math.PI / 180;
      return `${(30 * Math.cos(t)).toFixed(4)} ${(20 * Math.sin(t)).toFixed(4)}`;
    }).join('\n');
    form.addEventListener('change', () => syncVisibility(form));
    syncVisibility(form);
    // A drawing's loop becomes the polyline, closed: back to its first point.
    dxfUpload(form, {
      messages,
      fill: (points) => {
        form.elements.points.value = [...points, points[0]].map((p) => `${p[0].toFixed(4)} ${p[1].toFixed(4)}`).join('\n');
      },
    });
    loadMachines(form.elements.machine, 'none (values below)');
    machineFields(form, { feed: 'max_feed', block_time_ms: 'block_time_ms', margin: 'margin', min_chord_error: 'min_chord_error' });
    // The request, or a problem at the points box for a line that is not a point.
    const request = () => {
      try {
        return segmentRequest(form);
      } catch (error) {
        // A field the page refused is shown at that field.
        if (error.errors) throw error;
        throw { status: 400, title: 'Bad input', detail: String(error.message || error), errors: [{ path: 'curve.points' }] };
      }
    };
    submitFlow(form, {
      messages,
      result,
      read: request,
      ask: (body) => answerAndProgram('/api/v1/segment', body, segmentQuery(form)),
      show: ({ answer, program, refusal }, body) => {
        root.querySelector('#segment-gcode').disabled = !program;
        segmentResult(result, answer, { request: body, machine: form.elements.machine.machines?.get(body.machine), program, form }).id = 'segment-plot';
        const charts = result.querySelectorAll('canvas.chart');
        charts[0].id = 'segment-chart';
        charts[1].id = 'segment-lengths';
        return refusalMessage(refusal, 'these blocks');
      },
    });
    downloadFlow(root.querySelector('#segment-gcode'), form, {
      messages,
      read: request,
      path: '/api/v1/segment',
      query: () => segmentQuery(form),
      name: () => programName('segment', form),
    });
    keepForm(id, form);
  },
};

// This capability's view in the page's list (`web/views.js` loads it by the capability's name).
export const view = { title: 'Segment', mount: segmentView.mount, result: segmentResult };
