// The cut stock in 3-D, shared by every view that draws a program: the stock as a program left it
// (a GLB answer: `POST /api/v1/verify?format=glb`, or `POST /api/v1/{name}/stock` for a
// capability's own verification, docs/spec/verify.md §8 and §9.4) coloured by deviation from the
// part, or without a part by what the program cut, the findings as a list linked to the program's
// lines and marked in 3-D, and playback that removes material: at each step the stock cut up to
// the line the clock has reached is asked for, the clock running at the program's feeds times the
// chosen speed.
import { api } from '/api.js';
import { number } from '/form.js';
import { Scene3D, THREE, readGlb } from '/plot/scene3d.js';
import { parseProgram } from '/timeline.js';
import { unitsOf } from '/units.js';

// Rapid moves are timed at this feed in playback, mm/min (the program gives none).
const PLAYBACK_RAPID = 10000;

export const FINDING_COLOURS = { gouge: '#d62728', left_material: '#1f77b4' };

// The deviation colours: the GLB's own (red gouge, blue material left, grey within tolerance),
// with what is within tolerance split into cut to the part (green: its surface differs from the
// part's by a non-zero amount, which only a cut leaves) and untouched (grey: exactly the part's).
const DEVIATION_COLOURS = { gouge: '#d62728', left: '#1f77b4', cut: '#2ca02c', untouched: '#b0b0b0' };
const DEVIATION_LEGEND = {
  text: 'cut stock: red gouge, blue material left, green cut to the part, grey untouched',
  colour: `linear-gradient(90deg, ${DEVIATION_COLOURS.gouge} 25%, ${DEVIATION_COLOURS.left} 25% 50%, ${DEVIATION_COLOURS.cut} 50% 75%, ${DEVIATION_COLOURS.untouched} 75%)`,
};

// Without a part (`extras.colouring` "cut") the GLB's own colours: green where the program cut,
// grey where the stock is as given.
const CUT_LEGEND = {
  text: 'cut stock: green cut by the program, grey as given (no part to compare with)',
  colour: `linear-gradient(90deg, ${DEVIATION_COLOURS.cut} 50%, ${DEVIATION_COLOURS.untouched} 50%)`,
};

// The vertices of `geometry` the GLB colours green (cut, without a part): green well above red.
function cutColoured(geometry) {
  const colour = geometry.getAttribute('color');
  let count = 0;
  if (colour) for (let k = 0; k < colour.count; k += 1) if (colour.getY(k) > 2 * colour.getX(k)) count += 1;
  return count;
}

// Recolours `geometry` from its `deviation` attribute with `tolerance` and `allowance` (mm);
// the counts of vertices of each colour.
function recolour(geometry, tolerance, allowance) {
  const deviation = geometry.getAttribute('deviation');
  const counts = { gouge: 0, left: 0, cut: 0, untouched: 0 };
  if (!deviation) return counts;
  const colours = Object.fromEntries(Object.entries(DEVIATION_COLOURS).map(([k, c]) => [k, new THREE.Color(c)]));
  const values = new Float32Array(deviation.count * 3);
  for (let k = 0; k < deviation.count; k += 1) {
    const d = deviation.getX(k);
    const kind = d < -tolerance ? 'gouge' : d > allowance ? 'left' : Math.abs(d) > 1e-7 ? 'cut' : 'untouched';
    counts[kind] += 1;
    colours[kind].toArray(values, 3 * k);
  }
  geometry.setAttribute('color', new THREE.BufferAttribute(values, 3));
  return counts;
}

// Lists `program` in `listing` (an <ol>), its lines numbered as the findings count them (from 1),
// those with a finding marked.
export function showListing(listing, program, findings) {
  const marked = new Map(findings.filter((f) => f.line).map((f) => [f.line, f.kind]));
  listing.replaceChildren(...program.split('\n').map((text, i) => {
    const line = document.createElement('li');
    line.dataset.line = String(i + 1);
    line.textContent = text;
    if (marked.has(i + 1)) {
      line.className = 'finding';
      line.title = marked.get(i + 1).replaceAll('_', ' ');
    }
    return line;
  }));
}

// Opens line `line` of `listing`.
function openLine(listing, line) {
  listing.querySelectorAll('[aria-current]').forEach((li) => li.removeAttribute('aria-current'));
  const item = listing.querySelector(`[data-line="${line}"]`);
  item?.setAttribute('aria-current', 'true');
  if (item) listing.scrollTop = item.offsetTop - listing.clientHeight / 2;
}

// The rows of the findings table in `tbody`: a click opens the finding's line in `listing` and
// marks it on the cut stock `stock()` gives (when there is one).
export function showFindings(tbody, findings, listing, stock) {
  // Lengths to 0.001 mm or 0.0001 in, as the table's section shows them.
  const digits = unitsOf(tbody) === 'inch' ? 4 : 3;
  tbody.replaceChildren(...findings.map((finding) => {
    const tr = document.createElement('tr');
    tr.dataset.kind = finding.kind;
    const cells = [finding.kind.replaceAll('_', ' '), finding.line ?? '', (finding.position ?? []).map((v) => number(v, digits)).join(' '), finding.depth === undefined ? '' : number(finding.depth, digits), finding.volume_mm3 === undefined ? '' : number(finding.volume_mm3, 1)];
    for (const cell of cells) {
      const td = document.createElement('td');
      td.textContent = String(cell);
      tr.append(td);
    }
    tr.addEventListener('click', () => stock()?.mark(finding));
    if (finding.line) {
      tr.dataset.line = String(finding.line);
      tr.addEventListener('click', () => openLine(listing, finding.line));
    }
    return tr;
  }));
}

const PLAYBACK = (id) => `
  <button type="button" class="secondary small" id="${id}-play" aria-label="Play">▶</button>
  <input type="range" id="${id}-position" min="0" max="0" step="1" value="0" aria-label="Cut up to move">
  <label>Speed <select id="${id}-speed"><option value="1">1×</option><option value="10" selected>10×</option><option value="100">100×</option><option value="1000">1000×</option></select></label>
  <output id="${id}-playback-readout"></output>`;

// The cut stock in 3-D with its playback. `ask(line)` resolves to the GLB answer (an ArrayBuffer)
// of the stock cut up to `line` (undefined: the whole program); `program` is the program cut, its
// lines as `ask` and the findings count them; `id` names the scene (`{id}-stock`, unless `scene` is
// given) and the playback controls (`{id}-play`, `{id}-position`, `{id}-speed`); `scene` draws into
// an existing Scene3D (under its paths and tool) instead of a new one in `container`; `onMove(move)` follows playback
// (e.g. to move the tool). The glTF's `extras.verify` (verify) or `extras.verification` (a
// capability's own) holds the answer of the cut drawn.
export class CutStock {
  constructor(container, { id, ask, program, findings = [], tolerance = 0.01, allowance = 0.1, scene, label, onMove }) {
    this.container = container;
    this.id = id;
    this.ask = ask;
    this.program = program;
    this.limits = [tolerance, allowance];
    this.onMove = onMove;
    this.own = !scene;
    this.scene = scene ?? new Scene3D(container, { label: label ?? 'Cut stock coloured by deviation from the part' });
    if (this.own) this.scene.root.id = `${id}-stock`;
    this.findings = findings.filter((f) => f.position);
    this.bar = document.createElement('div');
    this.bar.className = 'timeline-controls';
    this.bar.id = `${id}-playback`;
    this.bar.hidden = true;
    this.bar.innerHTML = PLAYBACK(id);
    container.append(this.bar);
  }

  async fetch(line) {
    return readGlb(await this.ask(line));
  }

  // Draws the stock cut by the whole program, the findings' positions and the playback.
  async draw() {
    const { json, geometry } = await this.fetch();
    if (geometry) this.show(geometry, undefined, json);
    for (const [kind, colour] of Object.entries(FINDING_COLOURS)) {
      const points = this.findings.filter((f) => f.kind === kind).map((f) => f.position);
      this.scene.dots(`findings-${kind}`, points, { colour, size: 8, legend: `${kind.replaceAll('_', ' ')} (finding)` });
    }
    const others = this.findings.filter((f) => !FINDING_COLOURS[f.kind]).map((f) => f.position);
    this.scene.dots('findings-other', others, { colour: '#c47f17', size: 8, legend: 'other findings' });
    if (this.own) this.scene.finish();
    else this.scene.fit();
    this.playback();
  }

  // Shows the stock `geometry` as cut up to `line` (undefined: the whole program); `json` is the
  // GLB's glTF JSON.
  show(geometry, line, json) {
    const first = !this.scene.scene?.getObjectByName('stock');
    const byCut = json.extras?.colouring === 'cut';
    const counts = byCut ? { cut: cutColoured(geometry) } : recolour(geometry, ...this.limits);
    const legend = byCut ? CUT_LEGEND : DEVIATION_LEGEND;
    this.scene.coloured('stock', geometry, first ? { legend: legend.text, colour: legend.colour } : {});
    const deviation = geometry.getAttribute('deviation');
    let deepest = 0;
    if (deviation) for (let k = 0; k < deviation.count; k += 1) deepest = Math.min(deepest, deviation.getX(k));
    const view = this.scene.root.dataset;
    view.stockVertices = String(geometry.getAttribute('position').count);
    view.cutVertices = String(counts.cut);
    view.deepestDeviation = deepest.toFixed(4);
    view.uptoLine = line === undefined ? 'end' : String(line);
    view.colouring = byCut ? 'cut' : 'deviation';
    const answer = json.extras?.verify ?? json.extras?.verification;
    view.removedVolume = String(answer?.removed_volume_mm3 ?? 0);
    this.scene.render();
  }

  // Marks `finding` in 3-D: a marker at its position, which the camera turns to.
  mark(finding) {
    if (!this.scene.scene || !finding.position) return;
    let marker = this.scene.scene.getObjectByName('finding');
    if (!marker) {
      const size = Math.max((this.scene.radius ?? 10) / 60, 0.2);
      marker = new THREE.Mesh(new THREE.SphereGeometry(size, 16, 8), new THREE.MeshLambertMaterial({ color: FINDING_COLOURS[finding.kind] ?? '#c47f17' }));
      marker.name = 'finding';
      this.scene.scene.add(marker);
    }
    marker.position.set(...finding.position);
    this.scene.controls.target.set(...finding.position);
    this.scene.controls.update();
    this.scene.root.dataset.marked = `${finding.kind} ${finding.line ?? ''}`.trim();
    this.scene.render();
  }

  // The playback: a clock over the moves' times at their feeds, times the speed; at each step the
  // stock cut up to the move's line is asked for (one request at a time; steps passed while one is
  // under way are skipped).
  playback() {
    const { moves } = parseProgram(this.program);
    if (!moves.length) return;
    let clock = 0;
    this.starts = [];
    for (const move of moves) {
      this.starts.push(clock);
      const feed = move.motion === 'G0' ? PLAYBACK_RAPID : move.feed;
      clock += move.length && feed ? (move.length / feed) * 60 : 0;
    }
    this.total = clock;
    this.moves = moves;
    this.bar.hidden = false;
    const slider = this.control('position');
    slider.max = String(moves.length - 1);
    slider.value = String(moves.length - 1);
    slider.oninput = () => this.go(Number(slider.value));
    const play = this.control('play');
    play.onclick = () => this.toggle(play);
  }

  control(name) {
    return this.bar.querySelector(`#${this.id}-${name}`);
  }

  // Cuts up to move `index` (0-based) and shows it; while a request is under way the latest asked
  // index waits and is asked for next.
  async go(index) {
    this.wanted = index;
    const move = this.moves[index];
    this.control('position').value = String(index);
    this.control('playback-readout').textContent = `Cut up to line ${move.line + 1} (move ${index + 1} of ${this.moves.length}, ${number(this.starts[index], 1)} s at the programmed feeds)`;
    this.onMove?.(move);
    if (this.busy) return;
    this.busy = true;
    try {
      while (this.asked !== this.wanted && this.bar.isConnected) {
        this.asked = this.wanted;
        const line = this.moves[this.asked].line + 1;
        const { json, geometry } = await this.fetch(line);
        if (geometry) this.show(geometry, line, json);
      }
    } catch (problem) {
      this.control('playback-readout').textContent = `The stock cut up to that line cannot be drawn: ${problem.detail ?? problem.message ?? problem}`;
    } finally {
      this.busy = false;
    }
  }

  toggle(play) {
    if (this.timer) {
      cancelAnimationFrame(this.timer);
      this.timer = null;
      play.textContent = '▶';
      play.setAttribute('aria-label', 'Play');
      return;
    }
    play.textContent = '⏸';
    play.setAttribute('aria-label', 'Pause');
    const speed = () => Number(this.control('speed').value);
    let index = Number(this.control('position').value);
    if (index >= this.moves.length - 1) index = 0;
    let clock = this.starts[index];
    let last = performance.now();
    this.go(index);
    const tick = (now) => {
      clock += ((now - last) / 1000) * speed();
      last = now;
      let next = index;
      while (next + 1 < this.moves.length && this.starts[next + 1] <= clock) next += 1;
      if (next !== index) {
        index = next;
        this.go(index);
      }
      if (index >= this.moves.length - 1 || !this.bar.isConnected) {
        this.timer = null;
        play.textContent = '▶';
        play.setAttribute('aria-label', 'Play');
        return;
      }
      this.timer = requestAnimationFrame(tick);
    };
    this.timer = requestAnimationFrame(tick);
  }
}

// The verification of a capability's answer (its `verification` section, docs/spec/verify.md §9)
// in `container`: a summary, the findings linked to the lines of `program` (the program the
// verification cut: default output options, Fanuc) and, with a `source` of its cut stock
// (`requestStock`, `jobStock`), the stock in 3-D with playback, drawn into `scene` when given
// (`why` says why not, without `source`); `resolution` the spacing the page asks the stock at;
// `label` names the scene; `title` heads the panel (which program was cut, where that needs saying).
// Resolves to the CutStock, or null when the stock cannot be drawn (said in the panel).
export async function verificationPanel(container, { id, verification, program, source, resolution, scene, label, onMove, why = 'this capability does not answer its cut stock', title: heading = 'Verification: the program cut on its own model' }) {
  const box = document.createElement('section');
  box.className = 'verification';
  box.id = `${id}-verification`;
  const title = document.createElement('h3');
  title.textContent = heading;
  const summary = document.createElement('p');
  summary.className = 'hint';
  const found = verification.findings.length;
  // The removed volume is in mm³ whatever the units (its field's name says so): kept from the
  // units switch's relabelling, unlike the spacing.
  const removed = Object.assign(document.createElement('span'), { textContent: `${number(verification.removed_volume_mm3, 1)} mm³` });
  removed.dataset.unitsFixed = '';
  summary.append(
    `${verification.ok ? 'No findings' : `${found} finding${found === 1 ? '' : 's'}`}${verification.note ? ` (${verification.note})` : ''}; removed `,
    removed,
    ` at ${number(verification.resolution)} mm spacing. ${verification.model}.${(verification.assumed ?? []).map((sentence) => ` ${sentence[0].toUpperCase()}${sentence.slice(1)}.`).join('')}`,
  );
  const table = document.createElement('div');
  table.className = 'table-scroll';
  table.innerHTML = '<table class="worst"><thead><tr><th>finding</th><th>line</th><th>position, mm</th><th>depth, mm</th><th data-units-fixed>volume, mm³</th></tr></thead><tbody></tbody></table>';
  const listing = document.createElement('ol');
  listing.className = 'listing';
  listing.id = `${id}-listing`;
  listing.setAttribute('aria-label', 'G-code program as verified');
  listing.tabIndex = 0;
  const stockBox = document.createElement('div');
  box.append(title, summary, table, stockBox, listing);
  container.append(box);
  let stock = null;
  showFindings(table.querySelector('tbody'), verification.findings, listing, () => stock);
  if (program) showListing(listing, program, verification.findings);
  if (!source || !program) {
    stockBox.append(Object.assign(document.createElement('p'), { className: 'hint', textContent: `The cut stock is not drawn here: ${why}.` }));
    return null;
  }
  stock = new CutStock(stockBox, {
    id,
    program,
    findings: verification.findings,
    tolerance: verification.tolerance,
    allowance: verification.allowance,
    scene,
    label,
    onMove,
    ask: (line) => source.ask(line, resolution),
  });
  try {
    await stock.draw();
    return stock;
  } catch (problem) {
    stockBox.append(Object.assign(document.createElement('p'), { className: 'message warning', textContent: `The cut stock cannot be drawn: ${problem.detail ?? problem.message ?? problem}` }));
    return null;
  }
}

// Where a capability's cut stock comes from when the page holds its request: the program its
// verification cuts (the answer's with the default output options in the Fanuc dialect, from the
// capability's program route, whose lines the findings and `upto_line` count) and the stock cut
// up to a line at a spacing (`POST /api/v1/{name}/stock`). `body` as posted; `send(body)` what is
// posted for it (default the JSON; a form with a file the request reads).
export function requestStock(name, body, send = (request) => request) {
  return {
    program: () => api('POST', `/api/v1/${name}/program?dialect=fanuc`, send(body), 'text/x-gcode'),
    ask: async (line, resolution) => {
      const request = resolution === undefined ? body : { ...body, verification: { ...(body.verification ?? {}), resolution } };
      const query = line === undefined ? '' : `?upto_line=${line}`;
      return (await api('POST', `/api/v1/${name}/stock${query}`, send(request), 'model/gltf-binary')).arrayBuffer();
    },
  };
}

// Where a job operation's cut stock comes from: the job's stored file, through
// `GET /api/v1/jobs/{id}/stock` and `/stock/program` (the program cut, as the stored findings
// count its lines), so an operation on a machine or tool given only in the job file draws too.
export function jobStock(id, operation) {
  const at = `/api/v1/jobs/${id}/stock`;
  return {
    program: () => api('GET', `${at}/program?operation=${operation}`, undefined, 'text/x-gcode'),
    ask: async (line, resolution) => {
      const query = new URLSearchParams({ operation: String(operation) });
      if (line !== undefined) query.set('upto_line', String(line));
      if (resolution !== undefined) query.set('resolution', String(resolution));
      return (await api('GET', `${at}?${query}`, undefined, 'model/gltf-binary')).arrayBuffer();
    },
  };
}

// The note of a view whose program has no stock to cut (segment, resegment): said on the page,
// not left to a missing drawing.
export function noStockNote(capability) {
  return Object.assign(document.createElement('p'), {
    className: 'hint no-stock',
    textContent: `No cut stock is drawn: ${capability} writes a path along a curve, with no stock or part to cut it from (docs/spec/verify.md §9.2); its deviation from the curve is in the figures.`,
  });
}

// The verification of a capability whose model has no part (predict, engagement), in `container`:
// with the `source` of its cut stock (`requestStock`, `jobStock`) the program it cut and the
// stock it cut in 3-D, coloured by what was cut, with playback; without, the findings only, `why`
// saying why; `title` as for `verificationPanel`. Resolves to the CutStock, or null.
export async function partlessPanel(container, { name, verification, source, why, title }) {
  const panel = { id: name, verification, why, title, label: 'Cut stock coloured by what the program cut' };
  if (!source) return verificationPanel(container, panel);
  let program;
  try {
    program = await source.program();
  } catch (problem) {
    return verificationPanel(container, { ...panel, why: `its program cannot be written again: ${problem.detail ?? problem.title ?? problem}` });
  }
  return verificationPanel(container, { ...panel, program, source, resolution: verification.resolution });
}
