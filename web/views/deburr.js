// Deburr view: a form for one cross-hole ridge, the 3-D plot of ridge and ball-centre path,
// the summary, warnings and the G-code download (api.md, Deburr).
import { api, download, gcodeQuery, loadMachines, loadTools, message, number, numeric, programName, showProblem, showSummary, value } from '/app.js';
import { Plot3D } from '/plot3d.js';

const FORM = `
<div class="layout">
  <form id="deburr-form" novalidate>
    <fieldset><legend>Tool</legend>
      <label>Tool <select name="tool_choice" data-field="tool"></select></label>
      <label data-inline-tool>Ball radius, mm <input name="ball_radius" type="number" step="any" value="2" data-field="tool.radius"></label>
    </fieldset>
    <fieldset><legend>Workpiece</legend>
      <label>Kind <select name="workpiece_kind" data-field="workpiece.kind">
        <option value="tube">tube</option><option value="bore_block">block with bore</option></select></label>
      <label>Origin on axis <span class="triple">
        <input name="ox" type="number" step="any" value="0" data-field="workpiece.origin">
        <input name="oy" type="number" step="any" value="0" data-field="workpiece.origin">
        <input name="oz" type="number" step="any" value="0" data-field="workpiece.origin"></span></label>
      <label>Arrangement, ° <input name="arrangement" type="number" step="any" value="0" data-field="workpiece.arrangement_angle_deg"></label>
      <label data-kind="tube">Inner radius <input name="inner_radius" type="number" step="any" value="15" data-field="workpiece.inner_radius"></label>
      <label data-kind="tube">Outer radius <input name="outer_radius" type="number" step="any" value="25" data-field="workpiece.outer_radius"></label>
      <label data-kind="bore_block">Bore radius <input name="bore_radius" type="number" step="any" value="20" data-field="workpiece.bore_radius"></label>
      <label data-kind="bore_block">Face distance <input name="face_distance" type="number" step="any" value="40" data-field="workpiece.face_distance"></label>
    </fieldset>
    <fieldset><legend>Hole</legend>
      <label>Shape <select name="shape" data-field="hole.shape">
        <option value="round">round</option><option value="slot">slot</option><option value="rounded_rect">rounded rectangle</option></select></label>
      <label>Radius R2 <input name="hole_radius" type="number" step="any" value="5" data-field="hole.radius"></label>
      <label data-shape="slot">Centre distance <input name="slot_length" type="number" step="any" value="10" data-field="hole.centre_distance"></label>
      <label data-shape="rounded_rect">Centres across, along <span class="pair">
        <input name="rect_across" type="number" step="any" value="8" data-field="hole.centre_distance">
        <input name="rect_along" type="number" step="any" value="12" data-field="hole.centre_distance"></span></label>
      <label>Eccentricity f <input name="eccentricity" type="number" step="any" value="0" data-field="hole.eccentricity"></label>
      <label>Penetration, ° <input name="penetration" type="number" step="any" value="0" data-field="hole.penetration_angle_deg"></label>
    </fieldset>
    <fieldset><legend>Cut</legend>
      <label>Edge <select name="edge" data-field="edge"><option value="outer">outer</option><option value="inner">inner</option></select></label>
      <label>Amount Q, mm <input name="cut_amount" type="number" step="any" value="0.2" data-field="cut_amount"></label>
      <label>Tolerance TA, mm <input name="tolerance" type="number" step="any" value="0.01" data-field="tolerance"></label>
      <label>Method <select name="method" data-field="method"><option value="tangent">tangent (seed)</option><option value="exact">exact width</option></select></label>
      <label>Direction <select name="direction" data-field="direction"><option value="ccw">ccw (climb)</option><option value="cw">cw</option></select></label>
      <label>Feed, mm/min <input name="feed" type="number" step="any" value="300" data-field="feed"></label>
      <label>Spindle, rpm <input name="spindle_rpm" type="number" step="any" value="6000" data-field="spindle_rpm"></label>
      <label>Machine <select name="machine" data-field="machine"></select></label>
      <label>Block time, ms <input name="block_time_ms" type="number" step="any" placeholder="machine's, else off" data-field="block_time_ms"></label>
    </fieldset>
    <div class="actions">
      <button class="primary" type="submit" id="deburr-compute">Compute</button>
      <select name="dialect" aria-label="G-code dialect"><option value="">machine's dialect (else Fanuc)</option><option value="fanuc">Fanuc</option><option value="linuxcnc">LinuxCNC</option></select>
      <select name="reference" aria-label="Programmed point"><option value="tip">tip</option><option value="centre">ball centre</option></select>
      <button class="secondary" type="button" id="deburr-gcode">G-code</button>
    </div>
  </form>
  <section>
    <div id="deburr-messages"></div>
    <div id="deburr-result"></div>
  </section>
</div>`;

// The request body from the form (field names as api.md).
export function deburrRequest(form) {
  const choice = value(form, 'tool_choice');
  const tool = choice === 'inline' ? { kind: 'ball', radius: numeric(form, 'ball_radius') } : Number(choice);
  const origin = [numeric(form, 'ox') ?? 0, numeric(form, 'oy') ?? 0, numeric(form, 'oz') ?? 0];
  const kind = value(form, 'workpiece_kind');
  const workpiece = kind === 'tube'
    ? { kind, origin, arrangement_angle_deg: numeric(form, 'arrangement') ?? 0, inner_radius: numeric(form, 'inner_radius'), outer_radius: numeric(form, 'outer_radius') }
    : { kind, origin, arrangement_angle_deg: numeric(form, 'arrangement') ?? 0, bore_radius: numeric(form, 'bore_radius'), face_distance: numeric(form, 'face_distance') };
  const shape = value(form, 'shape');
  const hole = { shape, radius: numeric(form, 'hole_radius'), eccentricity: numeric(form, 'eccentricity') ?? 0, penetration_angle_deg: numeric(form, 'penetration') ?? 0 };
  if (shape === 'slot') hole.centre_distance = numeric(form, 'slot_length');
  if (shape === 'rounded_rect') hole.centre_distance = [numeric(form, 'rect_across'), numeric(form, 'rect_along')];
  return {
    tool, workpiece, hole,
    edge: value(form, 'edge'),
    cut_amount: numeric(form, 'cut_amount'),
    tolerance: numeric(form, 'tolerance'),
    method: value(form, 'method'),
    direction: value(form, 'direction'),
    feed: numeric(form, 'feed'),
    spindle_rpm: numeric(form, 'spindle_rpm'),
    machine: value(form, 'machine') || undefined,
    block_time_ms: numeric(form, 'block_time_ms'),
  };
}

function syncVisibility(form) {
  const kind = value(form, 'workpiece_kind');
  const shape = value(form, 'shape');
  form.querySelectorAll('[data-kind]').forEach((e) => { e.hidden = e.dataset.kind !== kind; });
  form.querySelectorAll('[data-shape]').forEach((e) => { e.hidden = e.dataset.shape !== shape; });
  form.querySelector('[data-inline-tool]').hidden = value(form, 'tool_choice') !== 'inline';
  if (kind === 'bore_block') form.elements.edge.value = 'inner';
}


// Shows a deburr answer in `container`: plot of ridge, centres and leads, summary, warnings.
// Used by the form and by job results.
export function deburrResult(container, answer) {
  container.replaceChildren();
  const canvas = document.createElement('canvas');
  canvas.className = 'plot';
  canvas.setAttribute('aria-label', 'Ridge line and tool-centre path');
  const hint = document.createElement('p');
  hint.className = 'hint';
  hint.textContent = 'Drag to rotate, shift-drag to pan, wheel to zoom, double-click to reset.';
  const warnings = document.createElement('div');
  const summaryBox = document.createElement('div');
  summaryBox.className = 'summary';
  container.append(canvas, hint, warnings, summaryBox);

  const points = answer.points;
  const centres = (moves) => moves.map((m) => m.centre);
  new Plot3D(canvas).setSeries([
    { label: 'ridge (targets)', points: points.map((p) => p.target), colour: '#555', width: 1.5 },
    { label: 'ball centres', points: points.map((p) => p.centre), colour: '#0b63b6', width: 2, marks: true },
    { label: 'approach / retract', points: centres(answer.lead_in), colour: '#c77700', width: 1.5, dash: [5, 4] },
    { label: '', points: answer.lead_out.length ? [points[points.length - 1].centre, ...centres(answer.lead_out)] : [], colour: '#c77700', width: 1.5, dash: [5, 4] },
  ]);
  const s = answer.summary;
  const items = [
    ['edge', `${answer.edge} (${answer.method})`], ['points', s.count], ['path length, mm', number(s.path_length, 3)],
    ['max deviation, mm', number(s.max_deviation, 5)], ['width W, mm', number(s.width)],
    ['true width, mm', `${number(s.true_width_min)} – ${number(s.true_width_max)}`],
    ['wedge angle, °', `${number(s.wedge_angle_min_deg, 2)} – ${number(s.wedge_angle_max_deg, 2)}`],
    ['est. time, s', number(s.estimated_time_s, 1)],
  ];
  if (s.max_exact_offset !== undefined) items.push(['exact vs seed, mm', number(s.max_exact_offset, 5)]);
  if (s.blocks !== undefined) {
    items.push(['blocks (short)', `${s.blocks} (${s.short_blocks})`], ['block length, mm', number(s.block_length, 4)]);
  }
  if (answer.machine) items.push(['machine', `${answer.machine.name} (${answer.machine.dialect})`]);
  showSummary(summaryBox, items);
  warnings.replaceChildren(...answer.warnings.map((w) => message('warning', `${w.code}: ${w.message}`)));
  return canvas;
}

export const deburrView = {
  id: 'deburr',
  title: 'Deburr',
  mount(root) {
    root.innerHTML = FORM;
    const form = root.querySelector('#deburr-form');
    const messages = root.querySelector('#deburr-messages');
    const result = root.querySelector('#deburr-result');
    form.addEventListener('change', () => syncVisibility(form));
    loadTools(form.elements.tool_choice, 'inline ball (radius below)', (tool) => tool.kind === 'ball').then(() => syncVisibility(form));
    loadMachines(form.elements.machine);
    syncVisibility(form);
    form.addEventListener('submit', async (event) => {
      event.preventDefault();
      form.querySelectorAll('.invalid').forEach((e) => e.classList.remove('invalid'));
      messages.replaceChildren(message('warning', 'computing…'));
      try {
        const answer = await api('POST', '/api/v1/deburr', deburrRequest(form));
        messages.replaceChildren();
        deburrResult(result, answer).id = 'deburr-plot';
      } catch (problem) {
        result.replaceChildren();
        showProblem(messages, form, problem);
      }
    });
    root.querySelector('#deburr-gcode').addEventListener('click', async () => {
      try {
        const program = await api('POST', `/api/v1/deburr${gcodeQuery(form)}`, deburrRequest(form), 'text/x-gcode');
        download(programName('deburr', form), program);
      } catch (problem) {
        showProblem(messages, form, problem);
      }
    });
  },
};
