// Machines view: the controller profiles (docs/spec/api.md, Machines): list, register or replace, delete,
// and the block time from a saturation test (docs/spec/segment.md §2.1, Eq. 1).
import { api, tagged } from '/api.js';
import { clearProblem, confirmButton, message, numeric, parseDecimal, saveGuarded, showProblem, submitFlow } from '/form.js';

const FORM = `
<div class="layout">
  <form id="machine-form" novalidate>
    <fieldset><legend data-legend>Register a machine</legend>
      <p class="hint" data-editing hidden><span data-editing-text></span> <button class="secondary small" type="button" id="machine-cancel-edit">Cancel editing</button></p>
      <label>Name <input name="name" type="text" value="hsc-4ms" data-field="name"></label>
      <label>Block time, ms <input name="block_time_ms" type="number" step="any" value="4" data-field="block_time_ms"></label>
      <label>Max feed, mm/min <input name="max_feed" type="number" step="any" value="10000" data-field="max_feed"></label>
      <label>Dialect <select name="dialect" data-field="dialect"><option value="fanuc">Fanuc (also Mazak, Okuma ISO)</option><option value="haas">Haas</option><option value="linuxcnc">LinuxCNC</option><option value="sinumerik">Siemens Sinumerik 840D</option><option value="heidenhain">Heidenhain Klartext</option><option value="heidenhain_iso">Heidenhain ISO</option><option value="grbl">grbl</option></select></label>
      <label><span>Block margin (no unit) <abbr class="symbol" title="k_f in docs/spec/segment.md">k_f</abbr></span> <input name="margin" type="number" step="any" placeholder="1" data-field="margin"></label>
      <label>Min chord error, mm <input name="min_chord_error" type="number" step="any" placeholder="0" data-field="min_chord_error"></label>
      <label>Description <input name="description" type="text" placeholder="control, mode, date" data-field="description"></label>
    </fieldset>
    <fieldset><legend>Programs, motion and spindle (optional)</legend>
      <label>Chord error rule <select name="mode" data-field="mode"><option value="">default (window)</option><option value="window">window</option><option value="curve">curve</option><option value="guarantee">guarantee: no short block</option></select></label>
      <label>Circular moves <select name="arcs" data-field="arcs"><option value="">default (chords)</option><option value="chords">chords (G01)</option><option value="g2g3">G02/G03</option></select></label>
      <label>Plunge feed, mm/min <input name="plunge_feed" type="number" step="any" placeholder="half the cutting feed" data-field="plunge_feed"></label>
      <label>Acceleration, mm/s² <input name="max_accel" type="number" step="any" placeholder="none: no cycle time" data-field="max_accel"></label>
      <label>Jerk, mm/s³ <input name="max_jerk" type="number" step="any" placeholder="none: trapezoids" data-field="max_jerk"></label>
      <label>Rapid feed, mm/min <input name="rapid_feed" type="number" step="any" placeholder="max feed" data-field="rapid_feed"></label>
      <label>Tool change, s <input name="tool_change_s" type="number" step="any" placeholder="0" data-field="tool_change_s"></label>
      <label>Spindle power, kW <input name="spindle_power_kw" type="number" step="any" data-field="spindle_power_kw"></label>
      <label>Spindle torque, N·m <input name="spindle_torque_nm" type="number" step="any" data-field="spindle_torque_nm"></label>
    </fieldset>
    <fieldset><legend>Block time from a saturation test</legend>
      <label>Test block, mm <input name="test_block" type="number" step="any" value="0.1"></label>
      <label>Saturated speed, mm/min <input name="saturated" type="number" step="any" value="1500"></label>
      <div class="actions"><button class="secondary" type="button" id="machine-saturation">Use T_b = L / V_sat</button></div>
    </fieldset>
    <div class="actions"><button class="primary" type="submit" id="machine-save">Save</button></div>
  </form>
  <section>
    <div id="machine-messages"></div>
    <div class="table-scroll"><table><thead><tr><th>name</th><th>block time, ms</th><th>max feed</th><th>dialect</th><th>margin</th><th>min chord error</th><th>description</th><th></th></tr></thead>
      <tbody id="machine-rows"></tbody></table></div>
    <p class="hint">A request that names a machine takes its values as defaults: block time and margin for deburr, segment and contour, <code>max_feed</code> for segment and the engagement feed plan, the dialect for G-code.</p>
  </section>
</div>`;

// The profile's fields the form edits; text and choices, the rest numbers (empty: not sent).
const TEXT_FIELDS = ['dialect', 'description', 'mode', 'arcs'];
const NUMBER_FIELDS = ['block_time_ms', 'max_feed', 'margin', 'min_chord_error', 'plunge_feed', 'max_accel', 'max_jerk', 'rapid_feed', 'tool_change_s', 'spindle_power_kw', 'spindle_torque_nm'];

// The machine last opened with Edit and the version it was (`etag`): saving keeps the fields of
// it the form does not show, so editing on the page never drops what was registered through the
// API, and replaces only that version.
let editing = null;

function setEditing(form, machine, etag) {
  editing = machine ? { machine, etag } : null;
  form.querySelector('[data-editing]').hidden = !machine;
  form.querySelector('[data-legend]').textContent = machine ? `Edit machine ${machine.name}` : 'Register a machine';
  form.querySelector('[data-editing-text]').textContent = machine ? `Editing ${machine.name}: saving replaces it.` : '';
  form.querySelector('#machine-save').textContent = machine ? `Save ${machine.name}` : 'Save';
}

// A stored machine in words, for the question before it is replaced.
function describeMachine(machine) {
  return [`${machine.block_time_ms} ms`, `${machine.max_feed} mm/min`, machine.dialect, machine.description].filter(Boolean).join(', ');
}

function fill(form, machine, etag) {
  clearProblem(form);
  setEditing(form, machine, etag);
  form.elements.name.value = machine.name ?? '';
  for (const name of [...TEXT_FIELDS, ...NUMBER_FIELDS]) form.elements[name].value = machine[name] ?? '';
}

// The body of the PUT: the edited machine's other fields, then every field of the form.
function machineBody(form) {
  const body = { ...(editing?.machine ?? {}) };
  delete body.name;
  for (const name of TEXT_FIELDS) body[name] = form.elements[name].value.trim() || undefined;
  for (const name of NUMBER_FIELDS) body[name] = numeric(form, name);
  return body;
}

async function refresh(root) {
  const rows = root.querySelector('#machine-rows');
  const messages = root.querySelector('#machine-messages');
  const form = root.querySelector('#machine-form');
  try {
    const machines = await api('GET', '/api/v1/machines');
    rows.replaceChildren(...machines.map((machine) => {
      const tr = document.createElement('tr');
      tr.dataset.machine = machine.name;
      for (const cell of [machine.name, machine.block_time_ms, machine.max_feed, machine.dialect, machine.margin ?? '', machine.min_chord_error ?? '', machine.description ?? '']) {
        const td = document.createElement('td');
        td.textContent = String(cell);
        tr.append(td);
      }
      const td = document.createElement('td');
      const edit = document.createElement('button');
      edit.type = 'button';
      edit.className = 'secondary small';
      edit.textContent = 'Edit';
      edit.addEventListener('click', async () => {
        // The listed machine at once, then the stored version with its ETag (refilled only if
        // it changed since the list was read).
        fill(form, machine);
        try {
          const stored = await tagged('GET', `/api/v1/machines/${encodeURIComponent(machine.name)}`);
          if (editing?.machine.name !== machine.name) return;
          if (JSON.stringify(stored.body) !== JSON.stringify(machine)) fill(form, stored.body, stored.etag);
          else editing.etag = stored.etag;
        } catch (problem) {
          showProblem(messages, null, problem);
        }
      });
      const remove = confirmButton('Delete', `Delete machine ${machine.name}?`, async () => {
        try {
          await api('DELETE', `/api/v1/machines/${encodeURIComponent(machine.name)}`);
          messages.replaceChildren(message('ok', `Machine ${machine.name} deleted.`));
          refresh(root);
        } catch (problem) {
          showProblem(messages, null, problem);
        }
      });
      td.append(edit, ' ', remove);
      tr.append(td);
      return tr;
    }));
  } catch (problem) {
    showProblem(messages, null, problem);
  }
}

export const machinesView = {
  mount(root) {
    root.innerHTML = FORM;
    const form = root.querySelector('#machine-form');
    const messages = root.querySelector('#machine-messages');
    setEditing(form, null);
    refresh(root);
    root.addEventListener('kerf:show', () => refresh(root));
    root.querySelector('#machine-cancel-edit').addEventListener('click', () => {
      const name = editing?.machine.name;
      clearProblem(form);
      form.reset();
      setEditing(form, null);
      messages.replaceChildren(message('info', `Editing ${name} cancelled: ${name} is unchanged.`));
    });
    root.querySelector('#machine-saturation').addEventListener('click', () => {
      const length = parseDecimal(form.elements.test_block.value);
      const speed = parseDecimal(form.elements.saturated.value);
      if (length > 0 && speed > 0) form.elements.block_time_ms.value = String(Number((length / speed * 60000).toPrecision(6)));
    });
    submitFlow(form, {
      messages,
      quiet: true,
      read: () => ({ name: form.elements.name.value.trim(), machine: machineBody(form) }),
      // A new name is created only if it is free; the machine opened with Edit is replaced only
      // as it was opened. Otherwise the stored machine is shown and the user asked.
      ask: ({ name, machine }) => saveGuarded(messages, {
        path: `/api/v1/machines/${encodeURIComponent(name || ' ')}`,
        body: machine,
        etag: editing?.machine.name === name ? editing.etag : undefined,
        what: `machine ${name}`,
        describe: describeMachine,
      }),
      show: async (answer, { name }) => {
        // An edited machine stays open at its new version; a new one is saved and the form stays
        // a form for new machines (to change a stored machine, open it with Edit).
        if (answer.saved && editing?.machine.name === name) {
          const stored = await tagged('GET', `/api/v1/machines/${encodeURIComponent(name)}`).catch(() => null);
          if (stored) setEditing(form, stored.body, answer.etag ?? stored.etag);
        }
        refresh(root);
      },
      done: (answer, { name }) => (answer.saved ? `Machine ${name} saved.` : `Machine ${name} kept as stored: nothing saved.`),
    });
  },
};
