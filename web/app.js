// kerf page shell: tabs, the API helper, problem display and downloads shared by the views.
import { contourView } from '/views/contour.js';
import { deburrView } from '/views/deburr.js';
import { engagementView } from '/views/engagement.js';
import { jobsView } from '/views/jobs.js';
import { machinesView } from '/views/machines.js';
import { predictView } from '/views/predict.js';
import { segmentView } from '/views/segment.js';
import { toolsView } from '/views/tools.js';

const views = [deburrView, segmentView, contourView, engagementView, predictView, jobsView, toolsView, machinesView];

// The API token (KERF_API_TOKEN), kept in this browser once entered.
function token() {
  return localStorage.getItem('kerf-token') || '';
}

function askForToken() {
  const box = document.getElementById('token-box');
  box.hidden = false;
  box.querySelector('input').focus();
}

// Calls the API; resolves to the parsed JSON (or text for G-code); rejects with the problem document.
// A FormData body is sent as multipart/form-data.
export async function api(method, path, body, accept = 'application/json') {
  const options = { method, headers: { accept } };
  if (token()) options.headers.authorization = `Bearer ${token()}`;
  if (body instanceof FormData) {
    options.body = body;
  } else if (body !== undefined) {
    options.headers['content-type'] = 'application/json';
    options.body = JSON.stringify(body);
  }
  const response = await fetch(path, options);
  if (response.status === 401) askForToken();
  if (response.status === 204) return null;
  const type = response.headers.get('content-type') || '';
  const payload = type.includes('json') ? await response.json() : await response.text();
  if (!response.ok) {
    throw typeof payload === 'object' ? payload : { status: response.status, detail: String(payload) };
  }
  return payload;
}

// Shows a problem document in `box` and marks the inputs whose data-field matches an error path.
export function showProblem(box, form, problem) {
  form?.querySelectorAll('.invalid').forEach((e) => e.classList.remove('invalid'));
  const fields = (problem.errors || []).map((e) => e.path);
  for (const path of fields) {
    form?.querySelectorAll(`[data-field="${CSS.escape(path)}"]`).forEach((e) => e.classList.add('invalid'));
  }
  box.replaceChildren(message('error', `${problem.title || 'Error'} (${problem.status})${problem.code ? ' ' + problem.code : ''}: ${problem.detail}`));
}

export function message(kind, text) {
  const div = document.createElement('div');
  div.className = `message ${kind}`;
  div.textContent = text;
  return div;
}

export function download(name, text, type = 'text/plain') {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const link = document.createElement('a');
  link.href = url;
  link.download = name;
  document.body.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

// Fills a summary box with [name, value] pairs, each a line with the value in bold.
export function showSummary(box, items) {
  box.replaceChildren(...items.map(([name, value]) => {
    const div = document.createElement('div');
    const b = document.createElement('b');
    b.textContent = String(value);
    div.append(name, b);
    return div;
  }));
}

// The text of form control `name`.
export function value(form, name) {
  return form.elements[name].value;
}

// The number in form control `name`, or undefined when it is empty.
export function numeric(form, name) {
  const text = value(form, name).trim();
  return text === '' ? undefined : Number(text);
}

// Fills a tool <select> with an "inline" entry and the table's tools that `accepts`, keeping
// the choice when it is still there. Without the table the inline tool still works.
export async function loadTools(select, inlineLabel, accepts = () => true, describe = toolLabel) {
  const chosen = select.value;
  select.replaceChildren(new Option(inlineLabel, 'inline'));
  try {
    for (const tool of await api('GET', '/api/v1/tools')) {
      if (accepts(tool)) select.append(new Option(describe(tool), String(tool.number)));
    }
  } catch (problem) {
    // The inline tool still works without the table.
  }
  if ([...select.options].some((o) => o.value === chosen)) select.value = chosen;
}

export function toolLabel(tool) {
  return `T${tool.number} ${tool.kind} R${tool.radius}${tool.name ? ' ' + tool.name : ''}`;
}

// Fills a machine <select> with "none" and the registered machines, keeping the choice.
export async function loadMachines(select, noneLabel = 'none') {
  const chosen = select.value;
  select.replaceChildren(new Option(noneLabel, ''));
  try {
    for (const machine of await api('GET', '/api/v1/machines')) {
      select.append(new Option(`${machine.name}: ${machine.block_time_ms} ms, ${machine.max_feed} mm/min, ${machine.dialect}`, machine.name));
    }
  } catch (problem) {
    // The form's own values still work without the registry.
  }
  if ([...select.options].some((o) => o.value === chosen)) select.value = chosen;
}

// The G-code query of a form with a `dialect` select ('' = the machine's, else Fanuc) and a
// `reference` select.
export function gcodeQuery(form) {
  const dialect = form.elements.dialect.value;
  return `?format=gcode${dialect ? `&dialect=${dialect}` : ''}&reference=${form.elements.reference.value}`;
}

// The download name of a program: `kind-dialect.nc`, or the machine's name for its dialect.
export function programName(kind, form) {
  return `${kind}-${form.elements.dialect.value || form.elements.machine?.value || 'fanuc'}.nc`;
}

export function number(value, digits = 4) {
  return Number.isFinite(value) ? value.toFixed(digits) : '–';
}

function show(view) {
  for (const button of document.querySelectorAll('#tabs button')) {
    button.setAttribute('aria-selected', String(button.dataset.view === view.id));
  }
  const main = document.getElementById('view');
  main.replaceChildren();
  view.mount(main);
  history.replaceState(null, '', `#${view.id}`);
}

document.getElementById('token-box').addEventListener('submit', (event) => {
  event.preventDefault();
  localStorage.setItem('kerf-token', event.target.elements.token.value.trim());
  event.target.hidden = true;
});

const tabs = document.getElementById('tabs');
for (const view of views) {
  const button = document.createElement('button');
  button.textContent = view.title;
  button.dataset.view = view.id;
  button.addEventListener('click', () => show(view));
  tabs.append(button);
}
show(views.find((v) => `#${v.id}` === location.hash) || views[0]);
