// kerf's units switch (docs/guide/page.md, Units): mm or inch for every view whose capability takes
// `units` (docs/spec/api.md). The page converts no request or answer: it sends `units` with each
// request (api.js) and the service answers in them. It only names the units: every length
// label, plot axis and readout in those views says mm or in (mm/min or in/min) as the units of
// its section (`data-units`) say, and when the switch flips the values already typed are
// converted once, so the part stays the same size.

const KEY = 'kerf.units';
const MM_PER_INCH = 25.4;

// The views whose capability takes `units`.
export const UNIT_VIEWS = ['deburr', 'segment', 'contour', 'engagement', 'resegment', 'predict', 'verify'];

// The capability paths that take `units` (a POST of their JSON request, with or without a query).
const UNIT_PATHS = new RegExp(`^/api/v1/(${UNIT_VIEWS.join('|')})(\\?|$)`);

// The units the switch is at: 'mm' (the default) or 'inch'.
export function currentUnits() {
  try {
    return localStorage.getItem(KEY) === 'inch' ? 'inch' : 'mm';
  } catch (error) {
    return 'mm';
  }
}

// Whether a POST to `path` is a request of a capability that takes `units`.
export function takesUnits(path) {
  return UNIT_PATHS.test(path);
}

// `text` (written in mm words) in the words of `units`: mm → in, mm/min → in/min, mm² → in²,
// mm³/min → in³/min, mm/s² → in/s²; a material's N/mm² stays (the service keeps it in N/mm²).
export function inUnits(text, units) {
  if (units !== 'inch') return text;
  return String(text)
    .replace(/\bin mm\b/g, 'in inches')
    .replace(/(?<![/\w])mm(?!\w)/g, 'in');
}

// The units an element is shown in: those of its section (`data-units`), else mm.
export function unitsOf(element) {
  return element?.closest?.('[data-units]')?.dataset.units === 'inch' ? 'inch' : 'mm';
}

// A label drawn on `canvas` in the units of its section.
export function canvasText(canvas, text) {
  return inUnits(text, unitsOf(canvas));
}

// ---------------------------------------------------------------- labels and readouts

// Text the page does not rewrite: the service's own words (messages, field errors), programs,
// typed text, choices (a select's options name stored tools and machines in their own mm), and
// values marked as stated in their own units (`data-units-fixed`: a machine profile's mm).
const KEEP = '.message, .field-error, option, textarea, pre, code, script, style, .listing, [data-units-fixed]';

// The forms of the views that take units that have shown a result (computed again on a flip).
const computed = new WeakSet();

// The mm words each rewritten text node had, and what was written into it, so a flip back to mm
// restores them and text the page's code changes later is read afresh.
const based = new WeakMap();

// The words of a text node as the page wrote them (mm), whatever it shows now.
function baseText(node) {
  const known = based.get(node);
  return known && known.written === node.data ? known.base : node.data;
}

function relabel(node) {
  const parent = node.parentElement;
  if (!parent || parent.closest(KEEP)) return;
  const known = based.get(node);
  const base = baseText(node);
  const written = inUnits(base, unitsOf(parent));
  if (written === base && !known) return;
  based.set(node, { base, written });
  if (node.data !== written) node.data = written;
}

function relabelAll(root) {
  const walker = document.createTreeWalker(root, NodeFilter.SHOW_TEXT);
  for (let node = walker.nextNode(); node; node = walker.nextNode()) relabel(node);
}

// Shows `element` (an answer's result) in `units`, the answer's, whatever its section's: the
// words already there follow, and those added later.
export function showInUnits(element, units) {
  element.dataset.units = units === 'inch' ? 'inch' : 'mm';
  relabelAll(element);
}

// Keeps the words of `root` in the units of their sections as the page adds and changes text.
function followWords(root) {
  new MutationObserver((records) => {
    for (const record of records) {
      if (record.type === 'characterData') relabel(record.target);
      for (const node of record.addedNodes) {
        if (node.nodeType === Node.TEXT_NODE) relabel(node);
        else if (node.nodeType === Node.ELEMENT_NODE) relabelAll(node);
      }
    }
  }).observe(root, { childList: true, subtree: true, characterData: true });
}

// ---------------------------------------------------------------- values typed

// What a control holds, from its label's mm words: a length, a feed (mm/min), an acceleration
// or jerk (the same factor) or an area; `data-dim` in the markup says it where the label does
// not (a points box, a choice of lengths, a table of keyed lengths).
function dimensionOf(control) {
  if (control.dataset.dim) return control.dataset.dim;
  const label = control.closest('label');
  if (!label || control.type === 'file' || control.type === 'checkbox') return '';
  let words = [];
  for (const node of label.childNodes) {
    if (node.nodeType === Node.TEXT_NODE) words.push(baseText(node));
    else if (node.nodeType === Node.ELEMENT_NODE && !node.matches('input, select, textarea, abbr, .hint')) {
      const walker = document.createTreeWalker(node, NodeFilter.SHOW_TEXT);
      for (let text = walker.nextNode(); text; text = walker.nextNode()) if (!text.parentElement.closest('abbr')) words.push(baseText(text));
    }
  }
  words = words.join(' ');
  if (/N\/mm/.test(words)) return '';
  if (/(?<![/\w])mm²/.test(words)) return 'area';
  const unit = /(?<![/\w])mm(\/min|\/s²|\/s³)?(?!\w)/.exec(words);
  if (!unit) return '';
  if (control.tagName === 'TEXTAREA') return 'points';
  return { '/min': 'feed', '/s²': 'acceleration', '/s³': 'jerk' }[unit[1]] ?? 'length';
}

// The mm words of a control's quantity ('mm/min' for a feed), '' for one without a length.
export function mmWords(control) {
  return { length: 'mm', points: 'mm', 'keyed-lengths': 'mm', feed: 'mm/min', acceleration: 'mm/s²', jerk: 'mm/s³', area: 'mm²' }[dimensionOf(control)] ?? '';
}

// The factor that takes a length in `from` to `to` (1, 25.4 or 1/25.4).
export function lengthFactor(from, to) {
  if (from === to) return 1;
  return from === 'inch' ? MM_PER_INCH : 1 / MM_PER_INCH;
}

// `value` (a number in `from`) in `to`, to six significant digits.
function converted(value, power, from, to) {
  const factor = (from === 'inch' ? MM_PER_INCH : 1 / MM_PER_INCH) ** power;
  return String(Number((value * factor).toPrecision(6)));
}

// The number in a typed field ("6,5" is 6.5), or NaN.
function typed(text) {
  const plain = String(text).trim().replace(/[\u2212\u2013]/g, '-');
  return /^[+-]?(\d+([.,]\d*)?|[.,]\d+)([eE][+-]?\d+)?$/.test(plain) ? Number(plain.replace(',', '.')) : NaN;
}

// A points box: every number of a line that is not a comment; a comment's "in mm" follows too.
// A G-code program (engagement's path boxes take either) keeps its own G20/G21.
function convertedPoints(text, from, to) {
  if (/^\s*[GMNO%(]/m.test(text) && /\b[GM]\d/.test(text)) return text;
  return text.split('\n').map((line) => {
    if (/^\s*#/.test(line)) return to === 'inch' ? line.replace(/\bin mm\b/g, 'in inches') : line.replace(/\bin inches\b/g, 'in mm');
    return line.replace(/[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?/g, (n) => converted(Number(n), 1, from, to));
  }).join('\n');
}

// A table of keyed lengths (a tool's shape error: a contact angle, then its error, a row a line):
// every number of a row but its first.
function convertedKeyedLengths(text, from, to) {
  return text.split('\n').map((line) => {
    let first = true;
    return line.replace(/[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?/g, (n) => {
      if (first) {
        first = false;
        return n;
      }
      return converted(Number(n), 1, from, to);
    });
  }).join('\n');
}

// The choices of a select of lengths in `to`: each option's mm value and words are kept and
// shown converted.
function convertChoices(select, to) {
  for (const option of select.options) {
    const mm = Number(option.dataset.mm ?? option.value);
    if (option.value === '' || !Number.isFinite(mm)) continue;
    option.dataset.mm ??= option.value;
    option.dataset.words ??= option.textContent;
    option.value = to === 'inch' ? converted(mm, 1, 'mm', 'inch') : option.dataset.mm;
    option.textContent = inUnits(option.dataset.words.replace(option.dataset.mm, option.value), to);
  }
}

// An example points box of `form`'s view written in mm (a sample path), in the form's units.
export function examplePoints(form, text) {
  return convertedPoints(text, 'mm', unitsOf(form));
}

// One control's text (`value` or `defaultValue`) from `from` to `to`.
function convertText(control, text, from, to) {
  if (from === to) return text;
  const dim = dimensionOf(control);
  if (dim === 'keyed-lengths') return convertedKeyedLengths(text, from, to);
  if (dim === 'points' || control.tagName === 'TEXTAREA') return convertedPoints(text, from, to);
  const number = typed(text);
  return Number.isNaN(number) ? text : converted(number, dim === 'area' ? 2 : 1, from, to);
}

// The last conversion of each control: a value not changed since is put back as it was when the
// switch goes back (6 mm → 0.23622 in → 6 mm, not 5.99999).
const flipped = new WeakMap();

// Converts the controls of `form` that hold lengths, feeds or areas from `from` to `to`: what is
// typed, and with `examples` the example values too (what "Load example" puts back), from the
// markup's mm each time.
export function convertForm(form, from, to, { examples = true } = {}) {
  if (from === to) return;
  for (const control of form.elements) {
    if (!dimensionOf(control)) continue;
    if (control.tagName === 'SELECT') {
      if (examples) convertChoices(control, to);
      continue;
    }
    const now = control.value;
    if (examples) {
      control.dataset.example ??= control.defaultValue;
      control.defaultValue = convertText(control, control.dataset.example, 'mm', to);
    }
    const last = flipped.get(control);
    const value = last && last.written === now && last.units === to ? last.value : convertText(control, now, from, to);
    flipped.set(control, { units: from, value: now, written: value });
    control.value = value;
  }
}

// The forms of the views that take units.
function unitRoots() {
  return [...document.querySelectorAll('[data-view-root]')].filter((root) => UNIT_VIEWS.includes(root.dataset.viewRoot));
}

// Converts the typed values of `root`'s forms from `from` to `to`, keeps them (a change event
// saves the form) and computes again what had a result, so it is shown in `to`.
function convertRoot(root, from, to) {
  for (const form of root.querySelectorAll('form')) {
    convertForm(form, from, to);
    form.dispatchEvent(new Event('kerf:units'));
    form.dispatchEvent(new Event('change'));
    if (computed.has(form)) form.requestSubmit();
  }
}

// ---------------------------------------------------------------- the switch

// Sets the switch to `units`: the sections of the views that take units follow, typed values are
// converted once, and `why` (e.g. "machine hsc-inch") is said beside the switch.
export function setUnits(units, why = '') {
  const from = currentUnits();
  try {
    localStorage.setItem(KEY, units);
  } catch (error) {
    // Storage off: the switch still works for this visit.
  }
  const select = document.getElementById('units');
  if (select) select.value = units;
  const note = document.getElementById('units-note');
  if (note) note.textContent = why ? `(${why})` : '';
  for (const root of unitRoots()) {
    root.dataset.units = units;
    if (from !== units) convertRoot(root, from, units);
    relabelAll(root);
  }
}

// The units a view's section works in, set before its view is mounted (so its form's examples
// are converted before what was kept is put back, see keepForm).
export function prepareRoot(root, id) {
  if (UNIT_VIEWS.includes(id)) root.dataset.units = currentUnits();
}

// Finishes a view's section once its view is mounted: its labels in its units, and a machine
// with units moves the switch to them.
export function mountUnits(root, id) {
  if (!UNIT_VIEWS.includes(id)) return;
  root.addEventListener('kerf:computed', (event) => computed.add(event.target), true);
  relabelAll(root);
  // A machine chosen that has units moves the switch to them (a choice put back from storage
  // does not: the switch was kept too).
  root.addEventListener('change', (event) => {
    const select = event.target;
    if (select.name !== 'machine' || event.detail === 'restore') return;
    const machine = select.machines?.get(select.value);
    if (machine?.units && machine.units !== currentUnits()) setUnits(machine.units, `units of machine ${machine.name}`);
  });
}

// The switch in the page's header; the words of every view follow from here on.
export function unitsSwitch() {
  const select = document.getElementById('units');
  select.value = currentUnits();
  select.addEventListener('change', () => setUnits(select.value));
  // Off in the markup until here, so a choice made while the page loads is not lost.
  select.disabled = false;
  followWords(document.getElementById('view'));
}
