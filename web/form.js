// kerf form helpers shared by the views: the submit flow (read the form, ask the service, show the
// answer or mark the problem at its fields), the G-code download flow (the same, ending in a file),
// reading fields, the tool and machine choices (machine values as placeholders, only overrides
// sent), errors at the field, warnings as sentences, the per-view state kept in local storage,
// summaries and downloads.
import { convertForm, inUnits, mmWords, UNIT_VIEWS, unitsOf } from '/units.js';
import { api, machines, materials, plainFieldMessage, plainTitle, program, sentence, tagged, technical, tools } from '/api.js';

// ---------------------------------------------------------------- reading fields

// The text of form control `name`.
export function value(form, name) {
  return form.elements[name].value;
}

// The number a person typed: a decimal comma is a decimal point ("6,5" is 6.5, as a German
// keyboard types it) and a typographic minus a minus; text that is not one plain number
// ("6,5,1", "1.234,5", "6 mm") is NaN, never a number with a separator dropped.
export function parseDecimal(text) {
  const plain = String(text).trim().replace(/[\u2212\u2013]/g, '-');
  if (!/^[+-]?(\d+([.,]\d*)?|[.,]\d+)([eE][+-]?\d+)?$/.test(plain)) return NaN;
  return Number(plain.replace(',', '.'));
}

// A problem document for input the page refuses at `control` before asking the service.
export function fieldProblem(control, text) {
  return { status: 400, title: 'Not a number', errors: [{ path: control.dataset.field || control.name, message: text }] };
}

// The number in form control `name`, or undefined when it is empty. Text that is not a number
// is refused at its field (throws a problem document), so it is never sent as something else.
export function numeric(form, name) {
  const control = form.elements[name];
  const text = control.value.trim();
  if (text === '') return undefined;
  const number = parseDecimal(text);
  if (Number.isNaN(number)) throw fieldProblem(control, `“${text}” is not a number: type digits with one decimal point or comma, e.g. 6.5 or 6,5.`);
  return number;
}

// One number field as a text field with a decimal keyboard (see decimalInputs).
function decimalInput(input) {
  input.type = 'text';
  input.inputMode = 'decimal';
  input.autocomplete = 'off';
  input.spellcheck = false;
}

// Number fields as text fields with a decimal keyboard, in `root` and whatever is added to it
// later: a browser's number field drops a decimal comma it does not expect ("6,5" reads as 65 or
// as nothing), so the page reads what was typed itself (numeric).
export function decimalInputs(root) {
  const convert = decimalInput;
  root.querySelectorAll('input[type="number"]').forEach(convert);
  new MutationObserver((records) => {
    for (const record of records) {
      for (const node of record.addedNodes) {
        if (node.nodeType !== Node.ELEMENT_NODE) continue;
        if (node.matches('input[type="number"]')) convert(node);
        node.querySelectorAll('input[type="number"]').forEach(convert);
      }
    }
  }).observe(root, { childList: true, subtree: true });
}

// Half of a diameter entered in a form (the API takes radii), or undefined when empty.
export function half(diameter) {
  return diameter === undefined ? undefined : diameter / 2;
}

export function number(value, digits = 4) {
  return Number.isFinite(value) ? value.toFixed(digits) : '–';
}

// ---------------------------------------------------------------- messages

// A message box: kind is 'error', 'warning', 'ok' (green) or 'info'.
export function message(kind, text, tooltip) {
  const div = document.createElement('div');
  div.className = `message ${kind}`;
  div.setAttribute('role', kind === 'error' ? 'alert' : 'status');
  div.textContent = text;
  if (tooltip) div.title = tooltip;
  return div;
}

// The answer's warnings as sentences, the code as a tooltip. With the `form` that asked, advice
// that names a request field (`radius_estimate "minimum"`) names the form's control for it, by
// its label (“Radius estimate”), and a choice by the words the control shows for it.
export function warningMessages(warnings = [], form) {
  return warnings.map((w) => message('warning', sentence(form ? withLabels(w.message, form) : w.message), `${w.code}: ${w.message}`));
}

// `text` with each request field it names (snake_case, or `name "choice"`) as the label of the
// control of `form` with that name.
function withLabels(text, form) {
  const control = (name) => {
    const found = form.elements[name];
    return found instanceof HTMLElement ? found : null;
  };
  return text
    .replace(/\b([a-z]+(?:_[a-z]+)*) "([^"]+)"/g, (all, name, choice) => {
      const found = control(name);
      const option = found?.tagName === 'SELECT' ? [...found.options].find((o) => o.value === choice) : null;
      return found && option ? `${labelText(found)} “${option.textContent}”` : all;
    })
    .replace(/\b[a-z]+(?:_[a-z]+)+\b/g, (name) => (control(name) ? labelText(control(name)) : name));
}

// Shows "computing…" and dims the last result until the answer comes.
function computing(messages, result) {
  messages.replaceChildren(message('info', 'Computing…'));
  result?.classList.add('stale');
}

// Shows success in green and undims the result.
function computed(messages, result, text = 'Computed.') {
  messages.replaceChildren(message('ok', text));
  result?.classList.remove('stale');
}

// POSTs `body` to `path` for the answer, then asks for its program (`query`: the G-code options).
// A refused program does not refuse the answer: `refusal` says why there is none.
export async function answerAndProgram(path, body, query) {
  const answer = await api('POST', path, body);
  try {
    return { answer, program: await program(path, body, query), refusal: null };
  } catch (refusal) {
    return { answer, program: null, refusal };
  }
}

// The request a form of a view that takes units builds, with the units of its section (the
// values were typed in them; the service converts at its edge). A request that says its units
// keeps them, and so does a multipart one (its JSON part says them).
function withUnits(form, request) {
  const root = form.closest('[data-view-root]');
  if (!request || typeof request !== 'object' || request instanceof FormData || !UNIT_VIEWS.includes(root?.dataset.viewRoot) || 'units' in request) return request;
  return { ...request, units: unitsOf(form) };
}

// The flow of a form that asks the service, the same in every view. On submit the marks of an
// earlier problem go and `read()` builds the request from the form (throwing a problem document
// for input the page can already tell is wrong). `ask(request)` then asks the service while
// "Computing…" shows and the last result dims (`quiet`: no such notice, for a form that only
// saves); `show(answer, request)` draws the new result and may return a message to add, e.g. why
// there is no program. Only after the new result is drawn (until it replaces the old one, the old
// one is the stale one): success in green (`done`: a text, or a function of the answer, the
// request and the seconds the service took), the result undimmed, the form marked computed. A
// problem from any step is shown at its fields, then handed to `failed(problem)` for what the view
// adds to it.
export function submitFlow(form, { messages, result, read = () => null, ask, show = () => null, done = 'Computed.', failed, quiet = false }) {
  const fail = (problem) => {
    showProblem(messages, form, problem);
    failed?.(problem);
  };
  form.addEventListener('submit', async (event) => {
    event.preventDefault();
    clearProblem(form);
    let request;
    try {
      request = withUnits(form, read());
    } catch (problem) {
      fail(problem);
      return;
    }
    if (!quiet) computing(messages, result);
    try {
      const started = performance.now();
      const answer = await ask(request);
      const seconds = (performance.now() - started) / 1000;
      const note = await show(answer, request);
      clearProblem(form);
      computed(messages, result, typeof done === 'function' ? done(answer, request, seconds) : done);
      markComputed(form);
      if (note) messages.append(note);
    } catch (problem) {
      fail(problem);
    }
  });
}

// The G-code download behind a view's `button`, the same in every view. On click the marks of an
// earlier problem go (`keepMarks`: they stay until the next problem replaces them), `read()`
// builds the request from the form (throwing a problem document for input the page can already
// tell is wrong) and the program is asked of `path` with `query` (`?format=gcode…`). `query` and
// `name` may be functions of the form's state at the click, taken before the program is asked, so
// the file is named after the dialect it was asked in. The program downloads as `name`, then
// `done()` runs; a problem from any step is shown at its fields in `messages`, then handed to
// `failed(problem)` for what the view adds to it.
export function downloadFlow(button, form, { messages, read, path, query, name, done, failed, keepMarks = false }) {
  const now = (option) => (typeof option === 'function' ? option() : option);
  button.addEventListener('click', async () => {
    if (!keepMarks) clearProblem(form);
    try {
      const body = withUnits(form, read());
      const fileName = now(name);
      download(fileName, await program(path, body, now(query)));
      done?.();
    } catch (problem) {
      showProblem(messages, form, problem);
      failed?.(problem);
    }
  });
}

// Why a computed answer has no program, as a message for `submitFlow`'s `show` to return.
export function refusalMessage(refusal, what) {
  return refusal ? message('error', `No G-code for ${what}. ${sentence(refusal.detail || refusal.title)}`, refusal.code) : null;
}

// Fills a summary box with [name, value] pairs, each a line with the value in bold.
export function showSummary(box, items) {
  box.replaceChildren(...items.map(([name, value]) => {
    const div = document.createElement('div');
    const b = document.createElement('b');
    b.textContent = String(value);
    // A machine's value in a summary is in the profile's mm, whatever the answer's units.
    if (/\(machine[:)]/.test(b.textContent)) b.dataset.unitsFixed = '';
    div.append(name, b);
    return div;
  }));
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

// ---------------------------------------------------------------- errors at the field

// The visible label text of a control: its label's words without the controls and the
// patent's symbols.
export function labelText(control) {
  const label = control.closest('label');
  if (!label) return control.getAttribute('aria-label') || control.name;
  let text = '';
  for (const node of label.childNodes) {
    if (node.nodeType === Node.TEXT_NODE) text += node.textContent;
    else if (node.nodeType === Node.ELEMENT_NODE && !node.matches('abbr, input, select, textarea, span.pair, span.triple, .field-error')) {
      const copy = node.cloneNode(true);
      copy.querySelectorAll('abbr, input, select, textarea').forEach((e) => e.remove());
      text += copy.textContent;
    }
  }
  return text.replace(/\s+/g, ' ').trim() || control.name;
}

// Removes the marks of an earlier problem.
export function clearProblem(form) {
  if (!form) return;
  form.querySelectorAll('[aria-invalid]').forEach((e) => {
    e.removeAttribute('aria-invalid');
    e.classList.remove('invalid');
    const ids = (e.getAttribute('aria-describedby') || '').split(' ').filter((id) => id && !id.startsWith('error-'));
    if (ids.length) e.setAttribute('aria-describedby', ids.join(' ')); else e.removeAttribute('aria-describedby');
  });
  form.querySelectorAll('.field-error').forEach((e) => e.remove());
}

// The controls an error path names: data-field equal to the path or a prefix of it
// (curve.points[3] → curve.points); serde's "missing field `radius`" at `hole` names hole.radius.
function controlsFor(form, error) {
  const paths = [error.path];
  const missing = /missing field `([^`]+)`/.exec(error.message || '');
  if (missing) paths.unshift(error.path === 'body' ? missing[1] : `${error.path}.${missing[1]}`);
  for (const path of paths) {
    // data-field may name several paths (a size entered as a radius or a diameter).
    const found = [...form.querySelectorAll('[data-field]')].filter((e) => !e.closest('[hidden]') && e.dataset.field.split(' ')
      .some((field) => path === field || path.startsWith(`${field}[`) || path.startsWith(`${field}.`)));
    if (found.length) return found;
  }
  // A field the page refused itself may have no data-field: its control by name.
  const named = form.elements[error.path];
  return named instanceof HTMLElement && !named.closest('[hidden]') ? [named] : [];
}

// The API's message without its leading field path ("hole.radius must be …" → "must be …").
function withoutPath(text, path) {
  const message = String(text ?? '');
  return path && message.startsWith(path) ? message.slice(path.length).replace(/^[:\s]+/, '') : message;
}

let noteCount = 0;

// Shows a problem document: each field error under its field (aria-invalid, aria-describedby),
// a plain headline in `box` with the API's words as a tooltip, focus on the first bad field.
// The last good result stays, dimmed, until the next success.
export function showProblem(box, form, problem) {
  clearProblem(form);
  const errors = problem.errors || [];
  const lines = [];
  let first = null;
  for (const error of errors) {
    const controls = form ? controlsFor(form, error) : [];
    const text = plainFieldMessage(withoutPath(error.message || problem.detail, error.path));
    if (!controls.length) {
      lines.push(text);
      continue;
    }
    // One message under each field; a second error on the same field adds to it.
    const label = controls[0].closest('label') || controls[0];
    let note = label.nextElementSibling?.classList.contains('field-error') ? label.nextElementSibling : null;
    if (note) {
      note.textContent += ` ${text}`;
    } else {
      note = document.createElement('p');
      note.className = 'field-error';
      note.id = `error-${form.id || 'form'}-${++noteCount}`;
      note.textContent = text;
      note.title = [error.path, problem.code].filter(Boolean).join(' · ');
      label.after(note);
    }
    const id = note.id;
    for (const control of controls) {
      control.setAttribute('aria-invalid', 'true');
      control.classList.add('invalid');
      const described = (control.getAttribute('aria-describedby') || '').split(' ').filter(Boolean);
      if (!described.includes(id)) control.setAttribute('aria-describedby', [...described, id].join(' '));
    }
    lines.push(`${labelText(controls[0])}: ${text}`);
    first ??= controls[0];
  }
  if (!errors.length) lines.push(sentence(problem.detail || problem.title));
  const headline = first ? 'Check the marked field' + (lines.length > 1 ? 's' : '') : plainTitle(problem);
  const alert = message('error', `${headline}. ${lines.join(' ')}`, technical(problem));
  box?.replaceChildren(alert);
  if (first) {
    first.focus({ preventScroll: true });
    first.scrollIntoView({ block: 'center' });
  } else {
    alert.scrollIntoView({ block: 'nearest' });
  }
}

// ---------------------------------------------------------------- tools and machines

export function toolLabel(tool) {
  const size = tool.kind === 'ball' ? `Ø${2 * tool.radius} ball` : `Ø${2 * tool.radius} ${tool.kind}`;
  return `T${tool.number} ${size}${tool.name ? ` – ${tool.name}` : ''}`;
}

// Re-runs `fill` each time the view is shown again (another view may have changed the tables).
function onShow(element, fill) {
  element.closest('[data-view-root]')?.addEventListener('kerf:show', fill);
}

// Puts back a choice restored from storage before the options were there.
function restoreChoice(select, chosen) {
  const wanted = select.dataset.wanted ?? chosen;
  if ([...select.options].some((o) => o.value === wanted)) {
    select.value = wanted;
    delete select.dataset.wanted;
  }
  // Marked as put back, not chosen (a machine put back does not move the units switch).
  if (select.value !== chosen) select.dispatchEvent(new CustomEvent('change', { bubbles: true, detail: 'restore' }));
}

// Fills a tool <select> with an "inline" entry and the table's tools that `accepts`, keeping
// the choice when it is still there. Without the table the inline tool still works.
export function loadTools(select, inlineLabel, accepts = () => true, describe = toolLabel) {
  const fill = async () => {
    const chosen = select.value;
    const table = await tools();
    select.replaceChildren(new Option(inlineLabel, 'inline'));
    // A stored tool's sizes are in mm whatever the form's units: said so in an inch form.
    const inMm = unitsOf(select) === 'inch' ? ' (mm)' : '';
    for (const tool of table.values()) {
      if (accepts(tool)) select.append(new Option(`${describe(tool)}${inMm}`, String(tool.number)));
    }
    select.tools = table;
    restoreChoice(select, chosen);
  };
  // The inline choice is there at once, so a form sent before the table arrives is still whole.
  if (!select.options.length) select.append(new Option(inlineLabel, 'inline'));
  onShow(select, fill);
  select.form?.addEventListener('kerf:units', fill);
  return track(select.form, fill());
}

// Fills a machine <select> with "none" and the registered machines, keeping the choice.
// The chosen machine is `select.machine` (its profile) for placeholders and summaries.
export function loadMachines(select, noneLabel = 'none') {
  const fill = async () => {
    const chosen = select.value;
    const table = await machines();
    select.replaceChildren(new Option(noneLabel, ''));
    for (const machine of table.values()) {
      select.append(new Option(`${machine.name}: ${machine.block_time_ms} ms, ${machine.max_feed} mm/min, ${machine.dialect}${machine.units ? `, ${machine.units}` : ''}`, machine.name));
    }
    select.machines = table;
    restoreChoice(select, chosen);
    select.dispatchEvent(new Event('kerf:machines'));
  };
  if (!select.options.length) select.append(new Option(noneLabel, ''));
  onShow(select, fill);
  return track(select.form, fill());
}

// Fills a material <select> with "values below" and the library's materials, keeping the
// choice; `select.materials` holds the library for placeholders.
export function loadMaterials(select, noneLabel) {
  const fill = async () => {
    const chosen = select.value;
    const table = await materials();
    select.replaceChildren(new Option(noneLabel, ''));
    for (const material of table.values()) {
      select.append(new Option(`${material.name}: kc1.1 ${material.kc11} N/mm², mc ${material.mc}`, material.name));
    }
    select.materials = table;
    restoreChoice(select, chosen);
  };
  if (!select.options.length) select.append(new Option(noneLabel, ''));
  onShow(select, fill);
  return track(select.form, fill());
}

// Remembers a form's pending loads, so a restored form computes only once its choices are there.
function track(form, promise) {
  if (form) (form.loading ??= []).push(promise);
  return promise;
}

// Machine-backed fields: `fields` maps a control name to the machine profile's key. With a
// machine chosen, every field the user has not typed in is emptied and shows the machine's value
// as its placeholder (so the request leaves it out and the service takes the machine's); what the
// user types is an override. Without a machine the example values come back.
export function machineFields(form, fields) {
  const select = form.elements.machine;
  const apply = () => {
    const machine = select.machines?.get(select.value);
    for (const [name, key] of Object.entries(fields)) {
      const input = form.elements[name];
      input.dataset.placeholder ??= input.placeholder;
      if (machine) {
        if (input.dataset.dirty !== 'true') input.value = '';
        // A value the machine does not set: the service's default, which is the example's.
        const fallback = input.defaultValue ? `${input.defaultValue} (default)` : input.dataset.placeholder;
        // A profile's values are in mm whatever the request's units: said so, not converted.
        const mm = unitsOf(form) === 'inch' && mmWords(input) ? ` ${mmWords(input)}` : '';
        input.placeholder = machine[key] == null ? fallback : `${machine[key]}${mm} (machine)`;
      } else {
        input.placeholder = input.dataset.placeholder;
        if (input.dataset.dirty !== 'true' && input.value === '') input.value = input.defaultValue;
      }
    }
  };
  select.addEventListener('change', apply);
  select.addEventListener('kerf:machines', apply);
  form.addEventListener('kerf:units', apply);
}

// How a summary states a value that a machine may supply: "4 ms (machine: 2 ms, overridden)",
// "2 ms (machine)" or "4 ms".
// `unit` is in mm words; in an inch request the value used is in the request's units and the
// machine's stays in the profile's mm.
export function machineNote(used, unit, request, field, machine, key = field) {
  const shown = `${used} ${inUnits(unit, request?.units)}`.trim();
  if (!machine || machine[key] == null) return shown;
  if (request && request[field] !== undefined) return `${shown} (machine: ${machine[key]} ${unit}, overridden)`.replace(' ,', ',');
  return `${shown} (machine)`;
}

// ---------------------------------------------------------------- G-code options

// The G-code query of a form with a `dialect` select ('' = the machine's, else Fanuc) and a
// `reference` select.
export function gcodeQuery(form) {
  const dialect = form.elements.dialect.value;
  const reference = form.elements.reference ? `&reference=${form.elements.reference.value}` : '';
  return `?format=gcode${dialect ? `&dialect=${dialect}` : ''}${reference}`;
}

// The posts kerf writes (docs/guide/gcode.md), as the options of a dialect <select>.
export const POST_OPTIONS = '<option value="fanuc">Fanuc (also Mazak, Okuma ISO)</option><option value="haas">Haas</option><option value="linuxcnc">LinuxCNC</option><option value="sinumerik">Siemens Sinumerik 840D</option><option value="heidenhain">Heidenhain Klartext</option><option value="heidenhain_iso">Heidenhain ISO</option><option value="grbl">grbl</option>';

// The download name of a program: `kind-dialect.nc`, or the machine's name for its dialect.
export function programName(kind, form) {
  return `${kind}-${form.elements.dialect.value || form.elements.machine?.value || 'fanuc'}.nc`;
}

// ---------------------------------------------------------------- state per view

const STATE_VERSION = 1;
const stateKey = (view) => `kerf.v${STATE_VERSION}.${view}`;

function readState(view) {
  try {
    const state = JSON.parse(localStorage.getItem(stateKey(view)) || 'null');
    return state && state.version === STATE_VERSION ? state : null;
  } catch (error) {
    return null;
  }
}

function writeState(view, state) {
  try {
    localStorage.setItem(stateKey(view), JSON.stringify({ ...state, version: STATE_VERSION }));
  } catch (error) {
    // Storage full or off: the page still works, it only forgets.
  }
}

function controls(form) {
  return [...form.elements].filter((e) => e.name && !['button', 'submit', 'file'].includes(e.type));
}

function snapshot(form) {
  const fields = {};
  const dirty = [];
  for (const e of controls(form)) {
    fields[e.name] = e.type === 'checkbox' || e.type === 'radio' ? e.checked : e.value;
    if (e.dataset.dirty === 'true') dirty.push(e.name);
  }
  return { fields, dirty, units: unitsOf(form) };
}

function restore(form, { fields = {}, dirty = [] }) {
  for (const e of controls(form)) {
    if (!(e.name in fields)) continue;
    if (e.type === 'checkbox' || e.type === 'radio') e.checked = fields[e.name];
    else if (e.tagName === 'SELECT' && ![...e.options].some((o) => o.value === fields[e.name])) e.dataset.wanted = fields[e.name];
    else e.value = fields[e.name];
    if (dirty.includes(e.name)) e.dataset.dirty = 'true';
  }
}

// Keeps `form` of view `view` across reloads: its fields (and which ones the user typed) after
// every change, and whether it had a result, in which case the restored form computes again
// (the service is deterministic, so this is the same result). Adds "Load example" and "Reset".
// `more` ({save, restore}) keeps what has no form control name (e.g. a list of path boxes).
export function keepForm(view, form, { onReset, more } = {}) {
  // Before a kept "6,5" is put back: a number field would drop it.
  form.querySelectorAll('input[type="number"]').forEach(decimalInput);
  // The markup's examples are in mm: in an inch section they are converted once, so "Load
  // example" gives the same part.
  convertForm(form, 'mm', unitsOf(form));
  const saved = readState(view);
  const save = (extra = {}) => writeState(view, { ...(readState(view) || {}), ...snapshot(form), more: more?.save(), ...extra });
  form.addEventListener('input', (event) => {
    if (event.target.name) event.target.dataset.dirty = 'true';
    save();
  });
  form.addEventListener('change', () => save());
  form.addEventListener('kerf:computed', () => save({ computed: true }));

  const bar = document.createElement('div');
  bar.className = 'actions form-tools';
  const example = document.createElement('button');
  example.type = 'button';
  example.className = 'link';
  example.textContent = 'Load example';
  const reset = document.createElement('button');
  reset.type = 'button';
  reset.className = 'link';
  reset.textContent = 'Reset';
  bar.append(example, reset);
  form.prepend(bar);
  const startOver = (clear) => {
    clearProblem(form);
    form.reset();
    for (const e of controls(form)) {
      delete e.dataset.dirty;
      if (clear && e.tagName !== 'SELECT' && e.type !== 'checkbox' && e.type !== 'radio') e.value = '';
    }
    form.elements.machine?.dispatchEvent(new Event('change', { bubbles: true }));
    form.dispatchEvent(new Event('change'));
    onReset?.(clear);
    writeState(view, { ...snapshot(form), more: more?.save(), computed: false });
  };
  example.addEventListener('click', () => startOver(false));
  reset.addEventListener('click', () => startOver(true));

  if (saved) {
    if (saved.more !== undefined) more?.restore(saved.more);
    restore(form, saved);
    // Kept in other units (the switch flipped while this view was not open): converted once.
    convertForm(form, saved.units ?? 'mm', unitsOf(form), { examples: false });
    form.dispatchEvent(new Event('change'));
    if (saved.computed) Promise.all(form.loading || []).then(() => form.requestSubmit());
  }
}

// Tells keepForm that the form's request gave a result.
function markComputed(form) {
  form.dispatchEvent(new Event('kerf:computed'));
}

// ---------------------------------------------------------------- confirmation

// A button that asks before it acts: "Delete" becomes "Delete T3? [Yes, delete] [Cancel]".
export function confirmButton(text, question, action) {
  const box = document.createElement('span');
  box.className = 'confirm';
  const make = (label, className) => {
    const b = document.createElement('button');
    b.type = 'button';
    b.className = className;
    b.textContent = label;
    return b;
  };
  const ask = make(text, 'secondary small');
  const prompt = document.createElement('span');
  prompt.setAttribute('role', 'group');
  prompt.setAttribute('aria-label', question);
  const yes = make(`Yes, ${text.toLowerCase()}`, 'danger small');
  const no = make('Cancel', 'secondary small');
  prompt.append(`${question} `, yes, ' ', no);
  prompt.hidden = true;
  ask.addEventListener('click', () => {
    ask.hidden = true;
    prompt.hidden = false;
    no.focus();
  });
  no.addEventListener('click', () => {
    prompt.hidden = true;
    ask.hidden = false;
    ask.focus();
  });
  yes.addEventListener('click', action);
  box.append(ask, prompt);
  return box;
}

// ---------------------------------------------------------------- saving without overwriting

// Whether a problem is the service's "not as you last saw it" answer (412).
function stale(problem) {
  return problem?.status === 412 || problem?.code === 'E_PRECONDITION_FAILED';
}

// Saves `body` with PUT at `path` (one tool, machine or material) without overwriting what the
// user has not seen: a new entry with `If-None-Match: *`, an edited one with `If-Match: etag` of
// the version opened. When the service answers 412 (the entry exists, or someone changed it since
// it was opened), what is stored now is shown in `box` as `describe(stored)` and the user is
// asked: replace it (a PUT with `If-Match` of the version shown, so a third change is caught
// again) or keep it (nothing sent). Resolves to {saved: true, etag} or {saved: false}.
export async function saveGuarded(box, { path, body, etag, what, describe }) {
  let condition = etag ? { 'if-match': etag } : { 'if-none-match': '*' };
  for (;;) {
    try {
      const answer = await tagged('PUT', path, body, condition);
      return { saved: true, etag: answer.etag };
    } catch (problem) {
      if (!stale(problem)) throw problem;
      const stored = await tagged('GET', path);
      const replace = await askToReplace(box, etag ? `${what} was changed since you opened it.` : `${what} already exists.`, `${what} as stored: ${describe(stored.body)}.`, what);
      if (!replace) return { saved: false };
      condition = { 'if-match': stored.etag };
    }
  }
}

// Shows what is stored and asks whether to replace it; resolves to the answer.
function askToReplace(box, headline, storedText, what) {
  return new Promise((resolve) => {
    const ask = message('warning', `${headline} ${storedText} Replace it with the form's values?`);
    ask.setAttribute('role', 'alertdialog');
    ask.dataset.ask = 'replace';
    const bar = document.createElement('div');
    bar.className = 'actions';
    const yes = document.createElement('button');
    yes.type = 'button';
    yes.className = 'danger small';
    yes.dataset.answer = 'replace';
    yes.textContent = `Replace ${what}`;
    const no = document.createElement('button');
    no.type = 'button';
    no.className = 'secondary small';
    no.dataset.answer = 'keep';
    no.textContent = `Keep ${what} as stored`;
    bar.append(yes, ' ', no);
    ask.append(bar);
    box.replaceChildren(ask);
    no.focus();
    yes.addEventListener('click', () => resolve(true), { once: true });
    no.addEventListener('click', () => resolve(false), { once: true });
  });
}
