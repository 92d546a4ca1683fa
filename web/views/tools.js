// Tool table view: list, register or replace, delete (api.md, Tools).
import { api } from '/api.js';
import { message, showProblem } from '/form.js';

const FORM = `
<div class="layout">
  <form id="tool-form" novalidate>
    <fieldset><legend>Register or replace a tool</legend>
      <label>Number <input name="number" type="number" min="1" max="9999" value="1" data-field="number"></label>
      <label>Kind <select name="kind" data-field="kind"><option>ball</option><option>flat</option><option>bull</option></select></label>
      <label>Radius, mm <input name="radius" type="number" step="any" value="3" data-field="radius"></label>
      <label>Corner radius <input name="corner_radius" type="number" step="any" data-field="corner_radius"></label>
      <label>Neck radius <input name="neck_radius" type="number" step="any" data-field="neck_radius"></label>
      <label>Flutes <input name="flutes" type="number" value="2" data-field="flutes"></label>
      <label>Name <input name="name" type="text" data-field="name"></label>
    </fieldset>
    <div class="actions"><button class="primary" type="submit">Save</button></div>
  </form>
  <section>
    <div id="tool-messages"></div>
    <table><thead><tr><th>T</th><th>kind</th><th>radius</th><th>corner</th><th>neck</th><th>flutes</th><th>name</th><th></th></tr></thead>
      <tbody id="tool-rows"></tbody></table>
  </section>
</div>`;

async function refresh(rows, messages) {
  try {
    const tools = await api('GET', '/api/v1/tools');
    rows.replaceChildren(...tools.map((tool) => {
      const tr = document.createElement('tr');
      for (const cell of [tool.number, tool.kind, tool.radius, tool.corner_radius ?? '', tool.neck_radius ?? '', tool.flutes, tool.name ?? '']) {
        const td = document.createElement('td');
        td.textContent = String(cell);
        tr.append(td);
      }
      const td = document.createElement('td');
      const remove = document.createElement('button');
      remove.className = 'secondary';
      remove.textContent = 'Delete';
      remove.addEventListener('click', async () => {
        try {
          await api('DELETE', `/api/v1/tools/${tool.number}`);
          refresh(rows, messages);
        } catch (problem) {
          showProblem(messages, null, problem);
        }
      });
      td.append(remove);
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
    const rows = root.querySelector('#tool-rows');
    const messages = root.querySelector('#tool-messages');
    refresh(rows, messages);
    form.addEventListener('submit', async (event) => {
      event.preventDefault();
      const optional = (name) => (form.elements[name].value.trim() === '' ? undefined : Number(form.elements[name].value));
      const tool = {
        kind: form.elements.kind.value,
        radius: Number(form.elements.radius.value),
        corner_radius: optional('corner_radius'),
        neck_radius: optional('neck_radius'),
        flutes: Number(form.elements.flutes.value),
        name: form.elements.name.value.trim() || undefined,
      };
      try {
        await api('PUT', `/api/v1/tools/${encodeURIComponent(form.elements.number.value)}`, tool);
        form.querySelectorAll('.invalid').forEach((e) => e.classList.remove('invalid'));
        messages.replaceChildren(message('ok', `Tool ${form.elements.number.value} saved.`));
        refresh(rows, messages);
      } catch (problem) {
        showProblem(messages, form, problem);
      }
    });
  },
};
