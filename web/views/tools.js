// Tool table view: list, register or replace, edit and delete (with a confirmation) the tools
// (docs/spec/api.md, Tools). Sizes by diameter or radius; the optional data other views need:
// neck, stickout, flute length, helix, shape-error table and a static stiffness.
import { api, tagged } from '/api.js';
import { clearProblem, confirmButton, fieldProblem, message, numeric, parseDecimal, saveGuarded, showProblem, submitFlow, toolLabel, value } from '/form.js';

const FORM = `
<div class="layout">
  <form id="tool-form" novalidate>
    <fieldset><legend data-legend>Register a tool</legend>
      <p class="hint" data-editing hidden><span data-editing-text></span> <button class="secondary small" type="button" id="tool-cancel-edit">Cancel editing</button></p>
      <label>Tool number T <input name="number" type="number" min="1" max="9999" value="1" data-field="number"></label>
      <label>Kind <select name="kind" data-field="kind"><option value="ball">ball end mill</option><option value="flat">flat end mill</option><option value="bull">bull nose (corner radius)</option></select></label>
      <label>Size entered as <select name="size_as"><option value="diameter">diameter Ø</option><option value="radius">radius</option></select></label>
      <label><span data-size-label>Diameter Ø, mm</span> <input name="size" type="number" step="any" value="6" data-field="radius"></label>
      <label data-kind="bull">Corner radius, mm <input name="corner_radius" type="number" step="any" data-field="corner_radius"></label>
      <label>Flutes <input name="flutes" type="number" step="1" value="2" data-field="flutes"></label>
      <label>Name <input name="name" type="text" placeholder="e.g. lollipop Ø6" data-field="name"></label>
    </fieldset>
    <fieldset><legend>Optional data</legend>
      <label>Neck radius, mm <input name="neck_radius" type="number" step="any" placeholder="none (shank as big as the head)" data-field="neck_radius"></label>
      <label>Stickout, mm <input name="stickout" type="number" step="any" placeholder="none" data-field="stickout"></label>
      <label>Flute length, mm <input name="flute_length" type="number" step="any" placeholder="none (not checked)" data-field="flute_length" title="the longest depth of cut the flutes reach; a deeper a_p is refused"></label>
      <label>Helix angle, ° <input name="helix_deg" type="number" step="any" placeholder="none" data-field="helix_deg"></label>
      <label>Plunge feed, mm/min <input name="plunge_feed" type="number" step="any" placeholder="the machine's, else half the cutting feed" data-field="plunge_feed"></label>
      <label data-kinds="flat bull">Cuts at its centre <select name="centre_cutting" data-field="centre_cutting"><option value="">yes (default)</option><option value="false">no: enter layers on a ramp</option></select></label>
      <label class="stacked">Shape error: angle in °, error in mm, one pair a line <textarea name="shape_error" rows="4" spellcheck="false" placeholder="0 0.004&#10;45 0.006&#10;90 0.009" data-field="shape_error"></textarea></label>
      <label>Stiffness (static, X = Y), N/mm <input name="stiffness" type="number" step="any" placeholder="none" data-field="stiffness"></label>
      <p class="hint" data-kept-stiffness hidden>This tool has a measured (modal) stiffness; it is kept unless you enter a static one.</p>
    </fieldset>
    <div class="actions"><button class="primary" type="submit" id="tool-save">Save tool</button></div>
  </form>
  <section>
    <div id="tool-messages"></div>
    <div class="table-scroll"><table><thead><tr><th>T</th><th>kind</th><th>Ø, mm</th><th>corner, mm</th><th>neck radius, mm</th><th>flutes</th><th>extra data</th><th>name</th><th></th></tr></thead>
      <tbody id="tool-rows"></tbody></table></div>
  </section>
</div>`;

function syncForm(form) {
  form.querySelector('[data-size-label]').textContent = value(form, 'size_as') === 'diameter' ? 'Diameter Ø, mm' : 'Radius, mm';
  form.querySelectorAll('[data-kind]').forEach((e) => { e.hidden = e.dataset.kind !== value(form, 'kind'); });
  form.querySelectorAll('[data-kinds]').forEach((e) => { e.hidden = !e.dataset.kinds.split(' ').includes(value(form, 'kind')); });
}

// "angle error" lines into the API's table: two numbers a line, apart by spaces or a semicolon
// (a comma is a decimal comma here: "45 0,006").
function shapeError(control) {
  const rows = control.value.split('\n').map((l) => l.trim()).filter(Boolean);
  if (!rows.length) return undefined;
  return rows.map((line) => {
    const numbers = line.split(/[\s;]+/).map(parseDecimal);
    if (numbers.length !== 2 || numbers.some(Number.isNaN)) throw fieldProblem(control, `“${line}” is not an angle and an error: two numbers, e.g. 45 0.006.`);
    return { angle_deg: numbers[0], error: numbers[1] };
  });
}

// The tool in the form, as the API takes it (`keep`: data of the edited tool the form does not show).
function toolFrom(form, keep = {}) {
  const size = numeric(form, 'size');
  const radius = size === undefined ? undefined : value(form, 'size_as') === 'diameter' ? size / 2 : size;
  const k = numeric(form, 'stiffness');
  return {
    ...keep,
    kind: value(form, 'kind'),
    radius,
    corner_radius: value(form, 'kind') === 'bull' ? numeric(form, 'corner_radius') : undefined,
    neck_radius: numeric(form, 'neck_radius'),
    stickout: numeric(form, 'stickout'),
    helix_deg: numeric(form, 'helix_deg'),
    flute_length: numeric(form, 'flute_length'),
    plunge_feed: numeric(form, 'plunge_feed'),
    // A ball always cuts at its centre (the service refuses `false` on one).
    centre_cutting: value(form, 'kind') !== 'ball' && value(form, 'centre_cutting') === 'false' ? false : undefined,
    flutes: numeric(form, 'flutes'),
    name: value(form, 'name').trim() || undefined,
    shape_error: shapeError(form.elements.shape_error),
    stiffness: k === undefined ? keep.stiffness : { kind: 'static', x: k, y: k },
  };
}

// What the form edits: null for a new tool, else {number, etag} of the stored tool opened with
// Edit (saving it then replaces exactly that version).
function setEditing(form, editing) {
  form.editing = editing;
  const box = form.querySelector('[data-editing]');
  box.hidden = !editing;
  form.querySelector('[data-legend]').textContent = editing ? `Edit tool T${editing.number}` : 'Register a tool';
  form.querySelector('[data-editing-text]').textContent = editing ? `Editing T${editing.number}: saving replaces it.` : '';
  form.querySelector('#tool-save').textContent = editing ? `Save T${editing.number}` : 'Save tool';
}

// A stored tool in words, for the question before it is replaced.
function describeTool(tool) {
  return [toolLabel(tool), `${tool.flutes} flutes`, extras(tool)].filter(Boolean).join(', ');
}

// Puts a stored tool into the form for editing (`etag`: the version it is).
function edit(form, tool, etag) {
  clearProblem(form);
  setEditing(form, { number: tool.number, etag });
  form.elements.number.value = tool.number;
  form.elements.kind.value = tool.kind;
  form.elements.size_as.value = 'diameter';
  form.elements.size.value = String(2 * tool.radius);
  for (const name of ['corner_radius', 'neck_radius', 'stickout', 'flute_length', 'helix_deg', 'plunge_feed', 'flutes', 'name']) form.elements[name].value = tool[name] ?? '';
  form.elements.centre_cutting.value = tool.centre_cutting === false ? 'false' : '';
  form.elements.shape_error.value = (tool.shape_error || []).map((p) => `${p.angle_deg} ${p.error}`).join('\n');
  const stiffness = tool.stiffness;
  form.elements.stiffness.value = stiffness?.kind === 'static' && stiffness.x === stiffness.y ? stiffness.x : '';
  form.querySelector('[data-kept-stiffness]').hidden = !stiffness || form.elements.stiffness.value !== '';
  // Data the form does not show stays as stored (a measured stiffness).
  form.kept = {};
  if (stiffness && form.elements.stiffness.value === '') form.kept.stiffness = stiffness;
  syncForm(form);
  form.elements.size.focus();
}

function extras(tool) {
  return [tool.stickout && `stickout ${tool.stickout}`, tool.flute_length && `flutes ${tool.flute_length} long`, tool.helix_deg && `helix ${tool.helix_deg}°`,
    tool.shape_error && `shape error (${tool.shape_error.length})`, tool.stiffness && `stiffness (${tool.stiffness.kind})`]
    .filter(Boolean).join(', ');
}

async function refresh(root) {
  const rows = root.querySelector('#tool-rows');
  const messages = root.querySelector('#tool-messages');
  const form = root.querySelector('#tool-form');
  try {
    const tools = await api('GET', '/api/v1/tools');
    rows.replaceChildren(...tools.map((tool) => {
      const tr = document.createElement('tr');
      tr.dataset.tool = String(tool.number);
      for (const cell of [`T${tool.number}`, tool.kind, 2 * tool.radius, tool.corner_radius ?? '', tool.neck_radius ?? '', tool.flutes, extras(tool), tool.name ?? '']) {
        const td = document.createElement('td');
        td.textContent = String(cell);
        tr.append(td);
      }
      const td = document.createElement('td');
      const change = document.createElement('button');
      change.type = 'button';
      change.className = 'secondary small';
      change.textContent = 'Edit';
      change.addEventListener('click', async () => {
        // The listed tool at once, then the stored version with its ETag (refilled only if it
        // changed since the list was read, so what is saved replaces what the form showed).
        edit(form, tool);
        try {
          const stored = await tagged('GET', `/api/v1/tools/${tool.number}`);
          if (form.editing?.number !== tool.number) return;
          if (JSON.stringify(stored.body) !== JSON.stringify(tool)) edit(form, stored.body, stored.etag);
          else form.editing.etag = stored.etag;
        } catch (problem) {
          showProblem(messages, null, problem);
        }
      });
      const remove = confirmButton('Delete', `Delete T${tool.number}?`, async () => {
        try {
          await api('DELETE', `/api/v1/tools/${tool.number}`);
          messages.replaceChildren(message('ok', `Tool T${tool.number} deleted.`));
          refresh(root);
        } catch (problem) {
          showProblem(messages, null, problem);
        }
      });
      td.append(change, ' ', remove);
      tr.append(td);
      return tr;
    }));
  } catch (problem) {
    showProblem(messages, null, problem);
  }
}

export const toolsView = {
  mount(root) {
    root.innerHTML = FORM;
    const form = root.querySelector('#tool-form');
    const messages = root.querySelector('#tool-messages');
    form.kept = {};
    setEditing(form, null);
    form.addEventListener('change', () => syncForm(form));
    syncForm(form);
    root.querySelector('#tool-cancel-edit').addEventListener('click', () => {
      const number = form.editing?.number;
      clearProblem(form);
      form.reset();
      form.kept = {};
      form.querySelector('[data-kept-stiffness]').hidden = true;
      setEditing(form, null);
      syncForm(form);
      messages.replaceChildren(message('info', `Editing T${number} cancelled: T${number} is unchanged.`));
    });
    root.addEventListener('kerf:show', () => refresh(root));
    refresh(root);
    submitFlow(form, {
      messages,
      quiet: true,
      read: () => ({ number: value(form, 'number').trim(), tool: toolFrom(form, form.kept) }),
      // A new number is created only if it is free; the tool opened with Edit is replaced only
      // as it was opened. Otherwise the stored tool is shown and the user asked.
      ask: ({ number, tool }) => saveGuarded(messages, {
        path: `/api/v1/tools/${encodeURIComponent(number)}`,
        body: tool,
        etag: String(form.editing?.number) === number ? form.editing.etag : undefined,
        what: `T${number}`,
        describe: describeTool,
      }),
      show: (answer, { number }) => {
        // An edited tool stays open at its new version; a new one is saved and the form stays a
        // form for new tools (to change a stored tool, open it with Edit).
        if (answer.saved && String(form.editing?.number) === number) form.editing.etag = answer.etag;
        refresh(root);
      },
      done: (answer, { number }) => (answer.saved ? `Tool T${number} saved.` : `T${number} kept as stored: nothing saved.`),
    });
  },
};
