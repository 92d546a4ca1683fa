// Machines view: the controller profiles (api.md, Machines): list, register or replace, delete,
// and the block time from a saturation test (chord.md §2.1, Eq. 1).
import { api } from '/api.js';
import { clearProblem, confirmButton, message, showProblem } from '/form.js';

const FORM = `
<div class="layout">
  <form id="machine-form" novalidate>
    <fieldset><legend>Register or replace a machine</legend>
      <label>Name <input name="name" type="text" value="hsc-4ms" data-field="name"></label>
      <label>Block time, ms <input name="block_time_ms" type="number" step="any" value="4" data-field="block_time_ms"></label>
      <label>Max feed, mm/min <input name="max_feed" type="number" step="any" value="10000" data-field="max_feed"></label>
      <label>Dialect <select name="dialect" data-field="dialect"><option value="fanuc">Fanuc</option><option value="linuxcnc">LinuxCNC</option></select></label>
      <label><span>Block margin <abbr class="symbol" title="k_f in chord.md">k_f</abbr></span> <input name="margin" type="number" step="any" placeholder="1" data-field="margin"></label>
      <label>Min chord error, mm <input name="min_chord_error" type="number" step="any" placeholder="0" data-field="min_chord_error"></label>
      <label>Description <input name="description" type="text" placeholder="control, mode, date" data-field="description"></label>
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

function fill(form, machine) {
  for (const name of ['name', 'block_time_ms', 'max_feed', 'dialect', 'margin', 'min_chord_error', 'description']) {
    form.elements[name].value = machine[name] ?? '';
  }
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
      edit.addEventListener('click', () => fill(form, machine));
      const remove = confirmButton('Delete', `Delete machine ${machine.name}?`, async () => {
        try {
          await api('DELETE', `/api/v1/machines/${encodeURIComponent(machine.name)}`);
          messages.replaceChildren(message('ok', `Machine ${machine.name} deleted.`));
          root.addEventListener('kerf:show', () => refresh(root));
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
    refresh(root);
    root.querySelector('#machine-saturation').addEventListener('click', () => {
      const length = Number(form.elements.test_block.value);
      const speed = Number(form.elements.saturated.value);
      if (length > 0 && speed > 0) form.elements.block_time_ms.value = String(Number((length / speed * 60000).toPrecision(6)));
    });
    form.addEventListener('submit', async (event) => {
      event.preventDefault();
      const optional = (name) => (form.elements[name].value.trim() === '' ? undefined : Number(form.elements[name].value));
      const name = form.elements.name.value.trim();
      const machine = {
        block_time_ms: Number(form.elements.block_time_ms.value),
        max_feed: Number(form.elements.max_feed.value),
        dialect: form.elements.dialect.value,
        margin: optional('margin'),
        min_chord_error: optional('min_chord_error'),
        description: form.elements.description.value.trim() || undefined,
      };
      try {
        await api('PUT', `/api/v1/machines/${encodeURIComponent(name || ' ')}`, machine);
        clearProblem(form);
        messages.replaceChildren(message('ok', `Machine ${name} saved.`));
        refresh(root);
      } catch (problem) {
        showProblem(messages, form, problem);
      }
    });
  },
};
