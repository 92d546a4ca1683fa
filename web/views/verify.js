// Verify view: cut a G-code program out of the stock with the tools it calls and list what went
// wrong at which line (docs/spec/verify.md): gouges, material left, rapids through material, the
// neck, shank or holder meeting the stock, air cutting; each finding opens its line in the listing
// and marks its position on the cut stock, drawn in 3-D from the GLB answer coloured by deviation
// from the part. Playback asks the server for the stock cut up to the line the clock has reached
// (`upto_line`), the clock running at the program's feeds times the chosen speed.
import { api } from '/api.js';
import { loadTools, message, number, numeric, showSummary, submitFlow, value } from '/form.js';
import { CutStock, showFindings, showListing } from '/plot/cut-stock.js';
import { convertForm, lengthFactor, showInUnits, unitsOf } from '/units.js';

// Most rays of the mesh the page asks for: a coarser spacing than the findings' beyond it, so the
// download and the drawing stay small.
const MESH_RAYS = 250000;

const EXAMPLE = 'G21 G90\nG0 X0 Y0 Z5\nG1 Z-2 F300\nG1 X50 F600\nG0 X60 Z-2\nG0 Z5\nM30';

const FORM = `
<div class="layout">
  <form id="verify-form" novalidate>
    <fieldset><legend>Program</legend>
      <label>G-code file <input name="file" type="file" accept=".nc,.ngc,.tap,.gcode,.txt"></label>
      <label class="stacked">Program <textarea name="program" rows="10" spellcheck="false" data-field="program">${EXAMPLE}</textarea></label>
    </fieldset>
    <fieldset><legend>Tool</legend>
      <label>Tool <select name="tool" data-field="tools"></select></label>
      <label data-inline>Kind <select name="kind"><option value="flat">flat end mill</option><option value="ball">ball end mill</option></select></label>
      <label data-inline>Radius, mm <input name="radius" type="number" step="any" value="5" data-field="tools"></label>
    </fieldset>
    <fieldset><legend>Stock (a box) and part</legend>
      <label>Stock min x y z, mm <input name="stock_min" type="text" value="-20 -20 -10" data-dim="points" data-field="stock"></label>
      <label>Stock max x y z, mm <input name="stock_max" type="text" value="70 20 0" data-dim="points" data-field="stock"></label>
      <label>Part <select name="part_kind" data-field="part.kind"><option value="box">the stock box down to a top</option><option value="mesh">STL file</option></select></label>
      <label data-part="box">Part top z, mm <input name="part_top" type="number" step="any" value="-1.9" placeholder="none: no part" data-field="part"></label>
      <label data-part="mesh">Part STL file <input name="part_file" type="file" accept=".stl,model/stl,application/sla" data-field="part"></label>
      <label data-part="mesh">STL units <select name="stl_units" data-field="part.units" title="an STL file names no units; most are exported in mm whatever the shop works in"><option value="mm">mm</option><option value="inch">inch</option></select></label>
      <label>Spacing, mm <input name="resolution" type="number" step="any" placeholder="a twentieth of the cutter radius" data-field="resolution"></label>
    </fieldset>
    <div class="actions"><button class="primary" type="submit" id="verify-run">Verify</button></div>
  </form>
  <section id="verify-result">
    <div id="verify-messages"></div>
    <div id="verify-answer"></div>
  </section>
</div>`;

// A verify answer: its figures, the findings linked to the program's lines, the cut stock.
const ANSWER = `
  <div class="summary" id="verify-summary"></div>
  <div class="table-scroll"><table class="worst"><thead><tr><th>finding</th><th>line</th><th>position, mm</th><th>depth, mm</th><th data-units-fixed>volume, mm³</th></tr></thead>
    <tbody id="verify-findings"></tbody></table></div>
  <div id="verify-scene"></div>
  <ol class="listing" id="verify-listing" aria-label="G-code program" tabindex="0"></ol>`;

// "x y z" (spaces or semicolons; a comma is a decimal comma) into three numbers, or a problem at
// the field.
function point(form, name, field) {
  const parts = value(form, name).trim().split(/[\s;]+/).map((p) => Number(p.replace(',', '.')));
  if (parts.length !== 3 || parts.some((p) => !Number.isFinite(p))) {
    throw { status: 400, title: 'Three numbers are needed', detail: `${field}: enter x y z, e.g. 0 0 -10`, field };
  }
  return parts;
}

function request(form) {
  const min = point(form, 'stock_min', 'stock');
  const max = point(form, 'stock_max', 'stock');
  const tool = value(form, 'tool') === 'inline'
    ? { kind: value(form, 'kind'), radius: numeric(form, 'radius') }
    : Number(value(form, 'tool'));
  const top = numeric(form, 'part_top');
  // An STL file names no units: the part says which it was exported in.
  const part = value(form, 'part_kind') === 'mesh'
    ? { kind: 'mesh', units: value(form, 'stl_units') }
    : top === undefined ? undefined : { kind: 'box', min, max: [max[0], max[1], top] };
  return {
    units: unitsOf(form),
    program: form.elements.program.value,
    tools: [tool],
    stock: { kind: 'box', min, max },
    part,
    resolution: numeric(form, 'resolution'),
  };
}

// The part's STL file, when the part is one.
function partFile(form) {
  return value(form, 'part_kind') === 'mesh' ? form.elements.part_file.files[0] || null : null;
}

// The body to send: JSON, or a form with the JSON and the part's STL file.
function payload(body, file) {
  if (!file) return body;
  const form = new FormData();
  form.append('request', new Blob([JSON.stringify(body)], { type: 'application/json' }));
  form.append('part', file, file.name);
  return form;
}

// Shows a verify answer in `container`, in its own units (lengths in mm or in; volumes in the mm³
// their names say): its figures, the findings linked to the lines of `request.program`, and with
// `cutStock` (where the stock comes from: `formStock`, or a job operation's `jobStock`) the stock
// as the program cut it. Used by the form and by job results.
export function verifyResult(container, answer, { request, cutStock = null } = {}) {
  container.innerHTML = ANSWER;
  showInUnits(container, answer.units);
  const summary = container.querySelector('#verify-summary');
  showSummary(summary, [
    ['Result ', answer.ok ? 'no findings' : `${answer.findings.length} findings`],
    ['Removed ', `${number(answer.removed_volume_mm3, 1)} mm³`],
    ['Cutting time ', `${number(answer.cutting_time_s, 1)} s`],
    ['In air ', `${number(100 * answer.air_share, 1)} %`],
    ['Spacing ', `${number(answer.resolution)} mm`],
  ]);
  summary.children[1].dataset.unitsFixed = '';
  const listing = container.querySelector('#verify-listing');
  if (request?.program) showListing(listing, request.program, answer.findings);
  showFindings(container.querySelector('#verify-findings'), answer.findings, listing, () => container.verifyStock);
  if (request && cutStock) drawStock(container, answer, request, cutStock);
  return container;
}

// The spacing the page asks the mesh at: the answer's, coarsened to at most MESH_RAYS rays.
function meshResolution(answer) {
  const [nx, ny] = answer.rays;
  const rays = nx * ny;
  return rays > MESH_RAYS ? answer.resolution * Math.sqrt(rays / MESH_RAYS) * 1.001 : answer.resolution;
}

// Where the form's cut stock comes from: the same request (and part file) with `?format=glb`.
function formStock(body, file) {
  return {
    program: async () => body.program,
    ask: async (line, resolution) => {
      const query = line === undefined ? '?format=glb' : `?format=glb&upto_line=${line}`;
      return (await api('POST', `/api/v1/verify${query}`, payload({ ...body, resolution }, file), 'model/gltf-binary')).arrayBuffer();
    },
  };
}

// Draws the cut stock of `answer` under the findings; a refusal of the mesh (too large) is shown
// as a message, the findings stay.
async function drawStock(container, answer, request, source) {
  const resolution = meshResolution(answer);
  // The service's tolerance and allowance when the request gives none are in mm.
  const fromMm = lengthFactor('mm', answer.units ?? 'mm');
  const scene = container.querySelector('#verify-scene');
  scene.replaceChildren();
  const stock = new CutStock(scene, {
    id: 'verify',
    program: request.program,
    findings: answer.findings,
    tolerance: request.tolerance ?? 0.01 * fromMm,
    allowance: request.allowance ?? 0.1 * fromMm,
    ask: (line) => source.ask(line, resolution),
  });
  container.verifyStock = stock;
  try {
    await stock.draw();
  } catch (problem) {
    scene.append(message('warning', `The cut stock cannot be drawn: ${problem.detail ?? problem.message ?? problem}`));
  }
}

export const verifyView = {
  mount(root) {
    root.innerHTML = FORM;
    const form = root.querySelector('#verify-form');
    const messages = root.querySelector('#verify-messages');
    const select = form.elements.tool;
    const syncInline = () => form.querySelectorAll('[data-inline]').forEach((e) => { e.hidden = select.value !== 'inline'; });
    const syncPart = () => form.querySelectorAll('[data-part]').forEach((e) => { e.hidden = e.dataset.part !== value(form, 'part_kind'); });
    loadTools(select, 'inline tool').then(syncInline);
    select.addEventListener('change', syncInline);
    form.elements.part_kind.addEventListener('change', syncPart);
    syncPart();
    // The markup's example is in mm: in an inch section it is converted once (the same part).
    convertForm(form, 'mm', unitsOf(form));
    form.elements.file.addEventListener('change', async () => {
      const file = form.elements.file.files[0];
      if (file) form.elements.program.value = await file.text();
    });
    submitFlow(form, {
      messages,
      result: root.querySelector('#verify-result'),
      read: () => request(form),
      ask: (body) => api('POST', '/api/v1/verify', payload(body, partFile(form))),
      show: (answer, body) => {
        // The messages too are in the answer's units.
        showInUnits(root.querySelector('#verify-result'), answer.units);
        verifyResult(root.querySelector('#verify-answer'), answer, { request: body, cutStock: formStock(body, partFile(form)) });
        return answer.ok ? null : message('error', `The program cut wrong: ${[...new Set(answer.findings.map((f) => f.kind.replaceAll('_', ' ')))].join(', ')}.`);
      },
      done: (answer) => (answer.ok ? 'Verified: the program cuts the part as it should.' : 'Verified.'),
    });
  },
};

export const view = { title: 'Verify', mount: verifyView.mount, result: verifyResult };
