// Materials view: the work materials library (docs/spec/api.md, Materials): list, register,
// edit (saving replaces only the version opened) and delete (with a confirmation).
import { api, tagged } from '/api.js';
import { clearProblem, confirmButton, message, numeric, saveGuarded, showProblem, submitFlow } from '/form.js';

const FORM = `
<div class="layout">
  <form id="material-form" novalidate>
    <fieldset><legend data-legend>Register a material</legend>
      <p class="hint" data-editing hidden><span data-editing-text></span> <button class="secondary small" type="button" id="material-cancel-edit">Cancel editing</button></p>
      <label>Name <input name="name" type="text" value="steel-c45" data-field="name"></label>
      <label><span>Specific cutting force, N/mm² <abbr class="symbol" title="k_c1.1: at h = 1 mm and b = 1 mm">kc1.1</abbr></span> <input name="kc11" type="number" step="any" value="1700" data-field="kc11"></label>
      <label><span>Kienzle exponent (no unit) <abbr class="symbol" title="m_c">mc</abbr></span> <input name="mc" type="number" step="any" value="0.25" data-field="mc"></label>
      <label>Radial to tangential force (ratio, no unit) <input name="radial_ratio" type="number" step="any" placeholder="0.3" data-field="radial_ratio"></label>
      <label>ISO 513 group <select name="iso_group" data-field="iso_group"><option value="">none</option><option>P</option><option>M</option><option>K</option><option>N</option><option>S</option><option>H</option></select></label>
      <label>Description <input name="description" type="text" placeholder="grade, condition, source" data-field="description"></label>
    </fieldset>
    <div class="actions"><button class="primary" type="submit" id="material-save">Save</button></div>
  </form>
  <section>
    <div id="material-messages"></div>
    <div class="table-scroll"><table><thead><tr><th>name</th><th>kc1.1, N/mm²</th><th>mc</th><th>radial ratio</th><th>ISO</th><th>description</th><th></th></tr></thead>
      <tbody id="material-rows"></tbody></table></div>
  </section>
</div>`;

// The material opened with Edit and its version (`etag`), or null for a new one.
let editing = null;

function setEditing(form, material, etag) {
  editing = material ? { material, etag } : null;
  form.querySelector('[data-editing]').hidden = !material;
  form.querySelector('[data-legend]').textContent = material ? `Edit material ${material.name}` : 'Register a material';
  form.querySelector('[data-editing-text]').textContent = material ? `Editing ${material.name}: saving replaces it.` : '';
  form.querySelector('#material-save').textContent = material ? `Save ${material.name}` : 'Save';
}

// A stored material in words, for the question before it is replaced.
function describeMaterial(material) {
  return [`kc1.1 ${material.kc11} N/mm²`, `mc ${material.mc}`, material.iso_group && `ISO ${material.iso_group}`, material.description].filter(Boolean).join(', ');
}

function fill(form, material, etag) {
  clearProblem(form);
  setEditing(form, material, etag);
  form.elements.name.value = material.name ?? '';
  for (const name of ['kc11', 'mc', 'radial_ratio', 'iso_group', 'description']) form.elements[name].value = material[name] ?? '';
}

// The body of the PUT: the form's fields (empty: not sent).
function materialBody(form) {
  return {
    kc11: numeric(form, 'kc11'),
    mc: numeric(form, 'mc'),
    radial_ratio: numeric(form, 'radial_ratio'),
    iso_group: form.elements.iso_group.value || undefined,
    description: form.elements.description.value.trim() || undefined,
  };
}

async function refresh(root) {
  const rows = root.querySelector('#material-rows');
  const messages = root.querySelector('#material-messages');
  const form = root.querySelector('#material-form');
  try {
    const list = await api('GET', '/api/v1/materials');
    rows.replaceChildren(...list.map((material) => {
      const tr = document.createElement('tr');
      tr.dataset.material = material.name;
      for (const cell of [material.name, material.kc11, material.mc, material.radial_ratio ?? '', material.iso_group ?? '', material.description ?? '']) {
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
        // The listed material at once, then the stored version with its ETag (refilled only if
        // it changed since the list was read).
        fill(form, material);
        try {
          const stored = await tagged('GET', `/api/v1/materials/${encodeURIComponent(material.name)}`);
          if (editing?.material.name !== material.name) return;
          if (JSON.stringify(stored.body) !== JSON.stringify(material)) fill(form, stored.body, stored.etag);
          else editing.etag = stored.etag;
        } catch (problem) {
          showProblem(messages, null, problem);
        }
      });
      const remove = confirmButton('Delete', `Delete material ${material.name}?`, async () => {
        try {
          await api('DELETE', `/api/v1/materials/${encodeURIComponent(material.name)}`);
          messages.replaceChildren(message('ok', `Material ${material.name} deleted.`));
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

export const materialsView = {
  mount(root) {
    root.innerHTML = FORM;
    const form = root.querySelector('#material-form');
    const messages = root.querySelector('#material-messages');
    setEditing(form, null);
    refresh(root);
    root.addEventListener('kerf:show', () => refresh(root));
    root.querySelector('#material-cancel-edit').addEventListener('click', () => {
      const name = editing?.material.name;
      clearProblem(form);
      form.reset();
      setEditing(form, null);
      messages.replaceChildren(message('info', `Editing ${name} cancelled: ${name} is unchanged.`));
    });
    submitFlow(form, {
      messages,
      quiet: true,
      read: () => ({ name: form.elements.name.value.trim(), material: materialBody(form) }),
      // A new name is created only if it is free; the material opened with Edit is replaced
      // only as it was opened. Otherwise the stored material is shown and the user asked.
      ask: ({ name, material }) => saveGuarded(messages, {
        path: `/api/v1/materials/${encodeURIComponent(name || ' ')}`,
        body: material,
        etag: editing?.material.name === name ? editing.etag : undefined,
        what: `material ${name}`,
        describe: describeMaterial,
      }),
      show: async (answer, { name }) => {
        if (answer.saved && editing?.material.name === name) {
          const stored = await tagged('GET', `/api/v1/materials/${encodeURIComponent(name)}`).catch(() => null);
          if (stored) setEditing(form, stored.body, answer.etag ?? stored.etag);
        }
        refresh(root);
      },
      done: (answer, { name }) => (answer.saved ? `Material ${name} saved.` : `Material ${name} kept as stored: nothing saved.`),
    });
  },
};
