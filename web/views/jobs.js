// Jobs workbench: drop or pick a job file, watch it queue and run, browse past jobs, open a
// result with the view of its operation, download G-code and JSON (docs/spec/api.md, Jobs).
import { api, binary, sentence, technical } from '/api.js';
import { confirmButton, download, message, showProblem, showSummary } from '/form.js';
import { jobStock } from '/plot/cut-stock.js';
import { resultView } from '/views.js';

const LAYOUT = `
<section>
  <div id="job-drop" class="drop" tabindex="0">
    <p><b>Drop a job file here</b> (JSON or TOML) or <label class="pick">choose one<input id="job-file" type="file" accept=".json,.toml,application/json,application/toml"></label></p>
  </div>
  <div id="job-messages"></div>
  <div class="table-scroll"><table class="jobs"><thead><tr><th>job</th><th>name</th><th>operations</th><th>status</th><th>progress</th><th>submitted</th><th></th></tr></thead>
    <tbody id="job-rows"></tbody></table></div>
  <div class="actions"><button class="secondary" id="job-older" type="button" hidden>Older jobs</button></div>
  <div id="job-result"></div>
</section>`;

const state = { jobs: new Map(), next: null, timer: null, open: null };

// Why a job failed or was cancelled, in words: the problem's detail (or title) and the field it
// names, never the problem object itself.
export function reasonText(error) {
  if (!error) return '';
  if (typeof error === 'string') return sentence(error);
  const field = error.errors?.[0]?.path;
  return `${sentence(error.detail || error.title || error.code || 'no reason given')}${field ? ` (field ${field})` : ''}`;
}

// A job's file as the service stores it (JSON, whichever format and client submitted it): every
// operation's `operation` and request, and the tools, machines and materials they name.
function jobFile(id) {
  return api('GET', `/api/v1/jobs/${id}/file`);
}

function button(text, action, className = 'secondary') {
  const b = document.createElement('button');
  b.type = 'button';
  b.className = className;
  b.textContent = text;
  b.addEventListener('click', action);
  return b;
}

function cell(text) {
  const td = document.createElement('td');
  td.textContent = text;
  return td;
}

// The progress cell: what the service reports, no more. Every operation reports its progress
// while it runs (a layer, a block, a sample, a pass at a time); a queued job has no bar.
function progressCell(job) {
  const td = document.createElement('td');
  td.className = 'progress';
  const count = job.operations.length;
  // A long job's first per cent takes a while: tenths until 10 %, so the number moves too.
  const percent = `${(job.progress * 100).toFixed(job.progress < 0.1 ? 1 : 0)}%`;
  const bar = document.createElement('progress');
  bar.max = 1;
  if (job.status === 'queued') {
    td.dataset.progress = 'waiting';
    td.append('waiting');
    return td;
  }
  if (job.status === 'running') {
    const index = Math.min(count - 1, Math.floor(job.progress * count + 1e-9));
    const of = count > 1 ? `operation ${index + 1} of ${count}, ` : '';
    bar.value = job.progress;
    td.dataset.progress = 'reported';
    td.append(bar, ` ${percent}`);
    bar.setAttribute('aria-label', `${of}${job.operations[index]}: ${percent}`);
    return td;
  }
  bar.value = job.status === 'done' ? 1 : job.progress;
  td.dataset.progress = job.status;
  td.append(bar, ` ${job.status === 'done' ? '100%' : percent}`);
  return td;
}

function row(job, root) {
  const tr = document.createElement('tr');
  tr.dataset.job = String(job.id);
  tr.dataset.status = job.status;
  const progress = progressCell(job);
  const status = cell(job.status);
  status.className = `status ${job.status}`;
  if (job.error) status.title = reasonText(job.error);
  const actions = document.createElement('td');
  actions.className = 'job-actions';
  const ended = ['done', 'failed', 'cancelled'].includes(job.status);
  if (ended) actions.append(button('Open', () => openJob(job.id, root)));
  if (job.status === 'failed' || job.status === 'cancelled') {
    const again = button('Re-submit', () => resubmit(job.id, root));
    again.dataset.action = 'resubmit';
    actions.append(' ', again);
  }
  if (ended) {
    const remove = confirmButton('Delete', `Delete job #${job.id} and its results?`, () => deleteJob(job.id, root));
    remove.dataset.action = 'delete';
    actions.append(' ', remove);
  }
  if (job.status === 'queued' || job.status === 'running') {
    const cancel = document.createElement('button');
    cancel.className = 'secondary';
    cancel.textContent = 'Cancel';
    cancel.addEventListener('click', async () => {
      try {
        await api('DELETE', `/api/v1/jobs/${job.id}`);
        refresh(root);
      } catch (problem) {
        showProblem(root.querySelector('#job-messages'), null, problem);
      }
    });
    actions.append(cancel);
  }
  tr.append(cell(`#${job.id}`), cell(job.name ?? ''), cell(job.operations.join(', ')), status, progress,
    cell(job.submitted_at.replace('T', ' ').slice(0, 19)), actions);
  if ((job.status === 'failed' || job.status === 'cancelled') && job.error) {
    const detail = document.createElement('tr');
    const field = job.error.errors?.[0]?.path;
    const td = cell(reasonText(job.error));
    td.title = [job.error.code, field].filter(Boolean).join(' · ');
    td.colSpan = 7;
    td.className = 'error-line';
    detail.append(td);
    return [tr, detail];
  }
  return [tr];
}

function render(root) {
  const rows = root.querySelector('#job-rows');
  const jobs = [...state.jobs.values()].sort((a, b) => b.id - a.id);
  rows.replaceChildren(...jobs.flatMap((job) => row(job, root)));
  root.querySelector('#job-older').hidden = state.next === null;
}

async function refresh(root) {
  try {
    const page = await api('GET', '/api/v1/jobs?limit=20');
    for (const job of page.jobs) state.jobs.set(job.id, job);
    if (state.next === null && page.next_before !== undefined) state.next = page.next_before;
    render(root);
    // The "queued" banner of a job that has finished says how it ended.
    const banner = root.querySelector('#job-messages .message[data-job]');
    const watched = banner && state.jobs.get(Number(banner.dataset.job));
    if (watched && !['queued', 'running'].includes(watched.status)) {
      const done = watched.status === 'done';
      const reason = reasonText(watched.error);
      const text = done ? `Job #${watched.id} is done: open it below.` : `Job #${watched.id} ${watched.status}${reason ? `: ${reason}` : '.'}`;
      root.querySelector('#job-messages').replaceChildren(message(done ? 'ok' : 'error', text));
    }
    const active = page.jobs.some((j) => j.status === 'queued' || j.status === 'running');
    clearTimeout(state.timer);
    if (active && document.body.contains(root)) state.timer = setTimeout(() => refresh(root), 700);
  } catch (problem) {
    showProblem(root.querySelector('#job-messages'), null, problem);
  }
}

async function older(root) {
  const page = await api('GET', `/api/v1/jobs?limit=20&before=${state.next}`);
  for (const job of page.jobs) state.jobs.set(job.id, job);
  state.next = page.next_before ?? null;
  render(root);
}

// Deletes an ended job and its results (the service answers 204; it is gone).
async function deleteJob(id, root) {
  const messages = root.querySelector('#job-messages');
  try {
    await api('DELETE', `/api/v1/jobs/${id}`);
    state.jobs.delete(id);
    const box = root.querySelector('#job-result');
    if (box.dataset.job === String(id)) box.replaceChildren();
    render(root);
    messages.replaceChildren(message('ok', `Job #${id} deleted.`));
  } catch (problem) {
    showProblem(messages, null, problem);
  }
}

// Sends a failed or cancelled job's file, as the service keeps it, again as a new job.
async function resubmit(id, root) {
  try {
    const file = await jobFile(id);
    submit(new File([JSON.stringify(file)], `job-${id}.json`, { type: 'application/json' }), root);
  } catch (problem) {
    showProblem(root.querySelector('#job-messages'), null, problem);
  }
}

async function openJob(id, root) {
  const box = root.querySelector('#job-result');
  try {
    const job = await api('GET', `/api/v1/jobs/${id}`);
    box.replaceChildren();
    delete box.dataset.state;
    box.dataset.job = String(job.id);
    const title = document.createElement('h2');
    title.textContent = `Job #${job.id}${job.name ? ': ' + job.name : ''}`;
    box.append(title);
    if (job.status !== 'done') {
      // A failed or cancelled job: how it ended, what it was, and what can be done with it.
      const reason = reasonText(job.error);
      box.append(message(job.status === 'failed' ? 'error' : 'warning', `Job #${job.id} ${job.status}${reason ? `: ${reason}` : '.'}`, job.error ? technical(job.error) : undefined));
      const facts = document.createElement('div');
      facts.className = 'summary';
      showSummary(facts, [['operations', job.operations.join(', ')], ['submitted', job.submitted_at.replace('T', ' ').slice(0, 19)],
        ['ended', (job.finished_at ?? '').replace('T', ' ').slice(0, 19) || '–'], ['attempts', job.attempts]]);
      const bar = document.createElement('div');
      bar.className = 'actions';
      const again = button('Re-submit', () => resubmit(job.id, root));
      bar.append(again, ' ', confirmButton('Delete', `Delete job #${job.id}?`, () => deleteJob(job.id, root)));
      box.append(facts, bar);
      box.dataset.state = 'shown';
      box.scrollIntoView({ behavior: 'smooth', block: 'start' });
      return;
    }
    // Without its file (removed in between) the results are drawn without their requests.
    const file = await jobFile(job.id).catch(() => null);
    // The whole job as one program: every operation with its tool change, and every
    // output in one zip (job.json, each answer and program, the job's program).
    const whole = document.createElement('div');
    whole.className = 'actions';
    const zip = document.createElement('button');
    zip.className = 'secondary';
    zip.id = 'job-zip';
    zip.textContent = 'All outputs (zip)';
    zip.addEventListener('click', async () => {
      try {
        download(`job-${job.id}.zip`, await binary(`/api/v1/jobs/${job.id}/outputs.zip`), 'application/zip');
      } catch (problem) {
        showProblem(root.querySelector('#job-messages'), null, problem);
      }
    });
    whole.append(zip);
    box.append(whole);
    if (job.results.some((result) => result.gcode)) {
      const program = document.createElement('button');
      program.className = 'secondary';
      program.textContent = 'Program (all operations)';
      program.addEventListener('click', async () => {
        try {
          download(`job-${job.id}.nc`, await api('GET', `/api/v1/jobs/${job.id}/program`, undefined, 'text/x-gcode'));
        } catch (problem) {
          showProblem(root.querySelector('#job-messages'), null, problem);
        }
      });
      whole.prepend(program);
    }
    const shown = [];
    job.results.forEach((result, index) => {
      const section = document.createElement('section');
      section.className = 'job-operation';
      section.dataset.operation = String(index);
      const heading = document.createElement('h3');
      heading.textContent = `${index}: ${result.operation}`;
      const actions = document.createElement('div');
      actions.className = 'actions';
      const json = document.createElement('button');
      json.className = 'secondary';
      json.textContent = 'JSON';
      json.addEventListener('click', () => download(`job-${id}-${index}-${result.operation}.json`, JSON.stringify(result.result, null, 2), 'application/json'));
      actions.append(json);
      if (result.gcode) {
        const gcode = document.createElement('button');
        gcode.className = 'secondary';
        gcode.textContent = 'G-code';
        gcode.addEventListener('click', async () => {
          download(`job-${id}-${index}-${result.operation}.nc`, await api('GET', `/api/v1/jobs/${id}/gcode?operation=${index}`, undefined, 'text/x-gcode'));
        });
        actions.append(gcode);
      } else if (result.gcode_problem) {
        actions.append(message('warning', `No G-code: ${sentence(result.gcode_problem)}`));
      }
      const view = document.createElement('div');
      // Its labels and plots in the units the operation's answer is in (`units`, mm without).
      view.dataset.units = result.result?.units === 'inch' ? 'inch' : 'mm';
      section.append(heading, actions, view);
      box.append(section);
      const show = resultView(result.operation) || ((c, r) => { c.textContent = JSON.stringify(r).slice(0, 2000); });
      shown.push((async () => {
        // With its program, the result gets the timeline and listing too.
        const program = result.gcode
          ? await api('GET', `/api/v1/jobs/${id}/gcode?operation=${index}`, undefined, 'text/x-gcode').catch(() => null)
          : null;
        // The operation's request from the job file: a deburr result then shows its tube and
        // hole and the clearance check, as the deburr view does.
        const request = file?.operations?.[index];
        const context = { ...(program ? { program } : {}), ...(request ? { request: requestOf(request, file) } : {}) };
        show(view, result.result, context);
        // The stock as the operation's program cut it solves the operation again, so it is drawn
        // when asked for, not on opening the job.
        if (request && cutsStock(result)) {
          const cut = button('Cut stock', () => {
            cut.disabled = true;
            show(view, result.result, { ...context, cutStock: jobStock(id, index) });
          });
          cut.dataset.action = 'cut-stock';
          cut.title = 'Cut the program again on the operation\'s model and draw the stock it leaves, with playback';
          actions.append(cut);
        }
      })());
    });
    await Promise.all(shown);
    // Each operation is shown once its program has come: only now is every plot on the page.
    box.dataset.state = 'shown';
    box.scrollIntoView({ behavior: 'smooth', block: 'start' });
  } catch (problem) {
    showProblem(root.querySelector('#job-messages'), null, problem);
  }
}

// Whether a job result has a cut stock to draw: a verify operation's, or a capability's whose
// answer carries its own verification (it has a model and verification was on).
function cutsStock(result) {
  return result.operation === 'verify' || Boolean(result.result?.verification);
}

// An operation of a job file as the request its endpoint takes: without `operation`, its tool
// numbers resolved from the file's own tools (a result is drawn with the tool it was cut with).
function requestOf(operation, file) {
  const { operation: _, ...request } = operation;
  const tools = new Map((file.tools || []).map((t) => [t.number, t]));
  for (const key of ['tool', 'inner_tool']) {
    if (typeof request[key] === 'number' && tools.has(request[key])) request[key] = tools.get(request[key]);
  }
  return request;
}

async function submit(file, root) {
  const messages = root.querySelector('#job-messages');
  const form = new FormData();
  form.append('file', file, file.name);
  try {
    const answer = await api('POST', '/api/v1/jobs', form);
    const banner = message(answer.reused ? 'ok' : 'info', answer.reused
      ? `${file.name}: identical to job #${answer.id}, reusing its result.`
      : `${file.name}: queued as job #${answer.id}.`);
    if (!answer.reused) banner.dataset.job = String(answer.id);
    messages.replaceChildren(banner);
    await refresh(root);
    if (answer.reused) openJob(answer.id, root);
  } catch (problem) {
    showProblem(messages, null, problem);
  }
}

export const jobsView = {
  mount(root) {
    root.innerHTML = LAYOUT;
    state.jobs.clear();
    state.next = null;
    const drop = root.querySelector('#job-drop');
    drop.addEventListener('dragover', (e) => { e.preventDefault(); drop.classList.add('over'); });
    drop.addEventListener('dragleave', () => drop.classList.remove('over'));
    drop.addEventListener('drop', (e) => {
      e.preventDefault();
      drop.classList.remove('over');
      for (const file of e.dataTransfer.files) submit(file, root);
    });
    root.querySelector('#job-file').addEventListener('change', (e) => {
      for (const file of e.target.files) submit(file, root);
      e.target.value = '';
    });
    root.querySelector('#job-older').addEventListener('click', () => older(root));
    refresh(root);
  },
};
