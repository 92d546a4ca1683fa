// kerf API module: the one place the page talks HTTP. Calls the API with the token, turns
// problem documents into plain words, and keeps the tool and machine tables the forms offer.

// The API token (KERF_API_TOKEN), kept in this browser once entered.
function token() {
  return localStorage.getItem('kerf-token') || '';
}

function askForToken() {
  const box = document.getElementById('token-box');
  if (!box) return;
  box.hidden = false;
  box.querySelector('input').focus();
}

// Sends one request with the token; resolves to the response, rejects when there is no answer.
async function send(method, path, body, accept, headers = {}) {
  const options = { method, headers: { ...headers, accept } };
  if (token()) options.headers.authorization = `Bearer ${token()}`;
  if (body instanceof FormData) {
    options.body = body;
  } else if (body instanceof Blob) {
    // A file sent as it is (a DXF drawing).
    options.headers['content-type'] = body.type || 'application/octet-stream';
    options.body = body;
  } else if (body !== undefined) {
    options.headers['content-type'] = 'application/json';
    options.body = JSON.stringify(body);
  }
  let response;
  try {
    response = await fetch(path, options);
  } catch (error) {
    throw { status: 0, title: 'No connection', detail: 'The kerf service did not answer. Is it running?' };
  }
  if (response.status === 401) askForToken();
  return response;
}

// The problem document of a failed response (or one made of its text).
async function failure(response) {
  const type = response.headers.get('content-type') || '';
  const payload = type.includes('json') ? await response.json() : await response.text();
  return typeof payload === 'object' && payload ? { status: response.status, ...payload } : { status: response.status, detail: String(payload) };
}

// Calls the API; resolves to the parsed JSON, the text of a text answer (G-code) or a Blob of any
// other (a zip); rejects with the problem document. A FormData body is sent as multipart/form-data,
// a Blob (a file) as its bytes.
export async function api(method, path, body, accept = 'application/json') {
  const response = await send(method, path, body, accept);
  if (response.status === 204) return null;
  if (!response.ok) throw await failure(response);
  const type = response.headers.get('content-type') || '';
  if (type.includes('json')) return response.json();
  if (type === '' || type.startsWith('text/')) return response.text();
  return response.blob();
}

// Calls the API with extra request headers (`If-Match`, `If-None-Match`); resolves to the parsed
// JSON and the answer's `ETag` (null without one), rejects with the problem document.
export async function tagged(method, path, body, headers = {}) {
  const response = await send(method, path, body, 'application/json', headers);
  if (!response.ok) throw await failure(response);
  const etag = response.headers.get('etag');
  return { body: response.status === 204 ? null : await response.json(), etag };
}

// Fetches a binary answer (a job's outputs.zip) as a Blob, its bytes untouched; rejects with the
// problem document like api().
export async function binary(path, accept = 'application/zip') {
  const response = await send('GET', path, undefined, accept);
  if (!response.ok) throw await failure(response);
  return response.blob();
}

// Fetches a program: the same request with `?format=gcode…` and the G-code media type.
export function program(path, body, query) {
  return api('POST', `${path}${query}`, body, 'text/x-gcode');
}

// The registered machines by name (fresh on each call; the Machines view can change them).
export async function machines() {
  try {
    return new Map((await api('GET', '/api/v1/machines')).map((m) => [m.name, m]));
  } catch (problem) {
    return new Map();
  }
}

// The materials library by name.
export async function materials() {
  try {
    return new Map((await api('GET', '/api/v1/materials')).map((m) => [m.name, m]));
  } catch (problem) {
    return new Map();
  }
}

// The registered tools by number.
export async function tools() {
  try {
    return new Map((await api('GET', '/api/v1/tools')).map((t) => [t.number, t]));
  } catch (problem) {
    return new Map();
  }
}

// One sentence from an API message: capital first letter, a full stop, no Rust quoting.
// References to the specification's edge cases ("(E8)") stay out: they are in the tooltip.
export function sentence(text) {
  const plain = String(text ?? '').replace(/`([^`]*)`/g, '“$1”').replace(/\s*\(E\d+[a-z]?\)/g, '').trim();
  if (!plain) return '';
  const first = plain[0].toUpperCase() + plain.slice(1);
  return /[.!?]$/.test(first) ? first : `${first}.`;
}

// The plain words for one field error of the API: serde's parse messages become what the user
// has to do; the solver's messages are already about the geometry.
export function plainFieldMessage(message) {
  const text = String(message ?? '');
  if (/missing field/.test(text)) return 'Required: enter a value.';
  if (/invalid type: null/.test(text) || /expected f64|expected a number|invalid type/.test(text)) return 'Enter a number.';
  if (/unknown variant `([^`]*)`/.test(text)) return `“${RegExp.$1}” is not one of the choices.`;
  return sentence(text.replace(/ at line \d+ column \d+$/, ''));
}

// A problem's headline in plain words (the HTTP status and code stay for the tooltip).
export function plainTitle(problem) {
  if (problem.status === 0) return problem.title;
  if (problem.status === 404) return 'Not found';
  if (problem.status === 422) return 'This cannot be made as entered';
  if (problem.status === 400) return 'Some values are missing or not numbers';
  if (problem.status >= 500) return 'The service failed (this is a bug in kerf)';
  return problem.title || 'Error';
}

// The tooltip of a problem: status, code and the API's own detail, for the expert.
export function technical(problem) {
  return [`HTTP ${problem.status}`, problem.code, problem.detail].filter(Boolean).join(' · ');
}
