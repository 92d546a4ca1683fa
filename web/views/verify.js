// Verify view: cut a G-code program out of the stock with the tools it calls and list what went
// wrong at which line (docs/spec/verify.md): gouges, material left, rapids through material, the
// neck, shank or holder meeting the stock, air cutting; each finding opens its line in the listing
// and marks its position on the cut stock, drawn in 3-D from the GLB answer coloured by deviation
// from the part. Playback asks the server for the stock cut up to the line the clock has reached
// (`upto_line`), the clock running at the program's feeds times the chosen speed.
import { api } from '/api.js';
import { loadTools, message, number, numeric, showSummary, submitFlow, value } from '/form.js';
import { CutStock, showFindings, showListing } from '/plot/cut-stock.js';

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
    <fieldset><legend>Stock and part (boxes, mm)</legend>
      <label>Stock min x y z, mm <input name="stock_min" type="text" value="-20 -20 -10" data-field="stock"></label>
      <label>Stock max x y z, mm <input name="stock_max" type="text" value="70 20 0" data-field="stock"></label>
      <label>Part top z, mm <input name="part_top" type="number" step="any" value="-1.9" placeholder="none: no part" data-field="part"></label>
      <label>Spacing, mm <input name="resolution" type="number" step="any" placeholder="a twentieth of the cutter radius" data-field="resolution"></label>
    </fieldset>
    <div class="actions"><button class="primary" type="submit" id="verify-run">Verify</button></div>
  </form>
  <section id="verify-result">
    <div id="verify-messages"></div>
    <div class="summary" id="verify-summary"></div>
    <div class="table-scroll"><table class="worst"><thead><tr><th>finding</th><th>line</th><th>position, mm</th><th>depth, mm</th><th>volume, mm³</th></tr></thead>
      <tbody id="verify-findings"></tbody></table></div>
    <div id="verify-scene"></div>
    <ol class="listing" id="verify-listing" aria-label="G-code program" tabindex="0"></ol>
  </section>
</div>`;

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
  return {
    program: form.elements.program.value,
    tools: [tool],
    stock: { kind: 'box', min, max },
    part: top === undefined ? undefined : { kind: 'box', min, max: [max[0], max[1], top] },
    resolution: numeric(form, 'resolution'),
  };
}

function showAnswer(root, answer, program) {
  showSummary(root.querySelector('#verify-summary'), [
    ['Result ', answer.ok ? 'no findings' : `${answer.findings.length} findings`],
    ['Removed ', `${number(answer.removed_volume_mm3, 1)} mm³`],
    ['Cutting time ', `${number(answer.cutting_time_s, 1)} s`],
    ['In air ', `${number(100 * answer.air_share, 1)} %`],
    ['Spacing ', `${number(answer.resolution)} mm`],
  ]);
  const listing = root.querySelector('#verify-listing');
  showListing(listing, program, answer.findings);
  showFindings(root.querySelector('#verify-findings'), answer.findings, listing, () => root.verifyStock);
}

// The mesh request: the same cut, at a spacing coarsened to at most MESH_RAYS rays.
function meshBody(body, answer) {
  const [nx, ny] = answer.rays;
  const rays = nx * ny;
  const resolution = rays > MESH_RAYS ? answer.resolution * Math.sqrt(rays / MESH_RAYS) * 1.001 : answer.resolution;
  return { ...body, resolution };
}

// Draws the cut stock of `answer` under the findings; a refusal of the mesh (too large) is shown
// as a message, the findings stay.
async function drawStock(root, answer, body) {
  const mesh = meshBody(body, answer);
  const container = root.querySelector('#verify-scene');
  container.replaceChildren();
  const stock = new CutStock(container, {
    id: 'verify',
    program: body.program,
    findings: answer.findings,
    tolerance: body.tolerance ?? 0.01,
    allowance: body.allowance ?? 0.1,
    ask: async (line) => {
      const query = line === undefined ? '?format=glb' : `?format=glb&upto_line=${line}`;
      return (await api('POST', `/api/v1/verify${query}`, mesh, 'model/gltf-binary')).arrayBuffer();
    },
  });
  root.verifyStock = stock;
  try {
    await stock.draw();
  } catch (problem) {
    root.querySelector('#verify-messages').append(message('warning', `The cut stock cannot be drawn: ${problem.detail ?? problem.message ?? problem}`));
  }
}

export const verifyView = {
  mount(root) {
    root.innerHTML = FORM;
    const form = root.querySelector('#verify-form');
    const messages = root.querySelector('#verify-messages');
    const select = form.elements.tool;
    const syncInline = () => form.querySelectorAll('[data-inline]').forEach((e) => { e.hidden = select.value !== 'inline'; });
    loadTools(select, 'inline tool').then(syncInline);
    select.addEventListener('change', syncInline);
    form.elements.file.addEventListener('change', async () => {
      const file = form.elements.file.files[0];
      if (file) form.elements.program.value = await file.text();
    });
    submitFlow(form, {
      messages,
      result: root.querySelector('#verify-result'),
      read: () => request(form),
      ask: (body) => api('POST', '/api/v1/verify', body),
      show: (answer, body) => {
        showAnswer(root, answer, body.program);
        drawStock(root, answer, body);
        return answer.ok ? null : message('error', `The program cut wrong: ${[...new Set(answer.findings.map((f) => f.kind.replaceAll('_', ' ')))].join(', ')}.`);
      },
      done: (answer) => (answer.ok ? 'Verified: the program cuts the part as it should.' : 'Verified.'),
    });
  },
};

export const view = { title: 'Verify', mount: verifyView.mount };
