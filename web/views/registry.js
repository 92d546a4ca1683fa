// A named registry on the page (machines, materials; docs/spec/api.md): list, register, edit
// (saving replaces only the version opened and keeps the stored fields the form does not show)
// and delete (with a confirmation). Each registry gives its form, its fields and its columns.
import { api, tagged } from '/api.js';
import { clearProblem, confirmButton, message, numeric, saveGuarded, showProblem, submitFlow } from '/form.js';

// `spec`: `kind` ('machine'), `plural` ('machines', also the API path), `title` ('Machine'),
// `form` (HTML with `#<kind>-form`, `-save`, `-cancel-edit`, `-messages`, `-rows`),
// `textFields` and `numberFields` (the form's inputs by name, empty: not sent), `columns(item)`
// (the table cells after the name), `describe(item)` (in words, for the question before it is
// replaced) and optionally `mount(root, form)` for the registry's own controls.
export function registryView(spec) {
  const { kind, plural, title } = spec;
  const path = (name) => `/api/v1/${plural}/${encodeURIComponent(name)}`;
  // The item last opened with Edit and the version it was (`etag`): saving keeps the fields of
  // it the form does not show, so editing on the page never drops what was registered through
  // the API, and replaces only that version.
  let editing = null;

  function setEditing(form, item, etag) {
    editing = item ? { item, etag } : null;
    form.querySelector('[data-editing]').hidden = !item;
    form.querySelector('[data-legend]').textContent = item ? `Edit ${kind} ${item.name}` : `Register a ${kind}`;
    form.querySelector('[data-editing-text]').textContent = item ? `Editing ${item.name}: saving replaces it.` : '';
    form.querySelector(`#${kind}-save`).textContent = item ? `Save ${item.name}` : 'Save';
  }

  function fill(form, item, etag) {
    clearProblem(form);
    setEditing(form, item, etag);
    form.elements.name.value = item.name ?? '';
    for (const name of [...spec.textFields, ...spec.numberFields]) form.elements[name].value = item[name] ?? '';
  }

  // The body of the PUT: the edited item's other fields, then every field of the form.
  function body(form) {
    const fields = { ...(editing?.item ?? {}) };
    delete fields.name;
    for (const name of spec.textFields) fields[name] = form.elements[name].value.trim() || undefined;
    for (const name of spec.numberFields) fields[name] = numeric(form, name);
    return fields;
  }

  async function refresh(root) {
    const rows = root.querySelector(`#${kind}-rows`);
    const messages = root.querySelector(`#${kind}-messages`);
    const form = root.querySelector(`#${kind}-form`);
    try {
      const list = await api('GET', `/api/v1/${plural}`);
      rows.replaceChildren(...list.map((item) => {
        const tr = document.createElement('tr');
        tr.dataset[kind] = item.name;
        for (const cell of [item.name, ...spec.columns(item)]) {
          const td = document.createElement('td');
          td.textContent = String(cell ?? '');
          tr.append(td);
        }
        const td = document.createElement('td');
        const edit = document.createElement('button');
        edit.type = 'button';
        edit.className = 'secondary small';
        edit.textContent = 'Edit';
        edit.addEventListener('click', async () => {
          // The listed item at once, then the stored version with its ETag (refilled only if it
          // changed since the list was read). A save waits for it (`editing.version`): without
          // its ETag the save would find the item "already exists".
          fill(form, item);
          const opened = editing;
          opened.version = tagged('GET', path(item.name)).then((stored) => {
            if (editing !== opened) return;
            if (JSON.stringify(stored.body) !== JSON.stringify(item)) fill(form, stored.body, stored.etag);
            else editing.etag = stored.etag;
          }, (problem) => showProblem(messages, null, problem));
          await opened.version;
        });
        const remove = confirmButton('Delete', `Delete ${kind} ${item.name}?`, async () => {
          try {
            await api('DELETE', path(item.name));
            messages.replaceChildren(message('ok', `${title} ${item.name} deleted.`));
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

  return {
    mount(root) {
      root.innerHTML = spec.form;
      const form = root.querySelector(`#${kind}-form`);
      const messages = root.querySelector(`#${kind}-messages`);
      setEditing(form, null);
      refresh(root);
      root.addEventListener('kerf:show', () => refresh(root));
      root.querySelector(`#${kind}-cancel-edit`).addEventListener('click', () => {
        const name = editing?.item.name;
        clearProblem(form);
        form.reset();
        setEditing(form, null);
        messages.replaceChildren(message('info', `Editing ${name} cancelled: ${name} is unchanged.`));
      });
      spec.mount?.(root, form);
      submitFlow(form, {
        messages,
        quiet: true,
        read: () => ({ name: form.elements.name.value.trim(), item: body(form) }),
        // A new name is created only if it is free; the item opened with Edit is replaced only
        // as it was opened. Otherwise the stored item is shown and the user asked.
        ask: async ({ name, item }) => {
          // The version Edit opened, once its ETag is there; a stored version other than the
          // listed one refills the form, and the save asks before it replaces it.
          const opened = editing;
          await opened?.version;
          return saveGuarded(messages, {
            path: path(name || ' '),
            body: item,
            etag: opened && editing === opened && opened.item.name === name ? opened.etag : undefined,
            what: `${kind} ${name}`,
            describe: spec.describe,
          });
        },
        show: async (answer, { name }) => {
          // An edited item stays open at its new version; a new one is saved and the form stays
          // a form for new items (to change a stored one, open it with Edit).
          if (answer.saved && editing?.item.name === name) {
            const stored = await tagged('GET', path(name)).catch(() => null);
            if (stored) setEditing(form, stored.body, answer.etag ?? stored.etag);
          }
          refresh(root);
        },
        done: (answer, { name }) => (answer.saved ? `${title} ${name} saved.` : `${title} ${name} kept as stored: nothing saved.`),
      });
    },
  };
}
