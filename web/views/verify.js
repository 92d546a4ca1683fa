// Verify view: cut a G-code program out of the stock with the tools it calls and list what went
// wrong at which line (docs/spec/verify.md): gouges, material left, rapids through material, the
// neck, shank or holder meeting the stock, air cutting; each finding opens its line in the listing
// and marks its position on the cut stock, drawn in 3-D from the GLB answer coloured by deviation
// from the part. Playback asks the server for the stock cut up to the line the clock has reached
// (`upto_line`), the clock running at the program's feeds times the chosen speed.
import { api } from '/api.js';
import { loadTools, message, number, numeric, showSummary, submitFlow, value } from '/form.js';
import { Scene3D, THREE, readGlb } from '/plot/scene3d.js';
import { parseProgram } from '/timeline.js';

// Most rays of the mesh the page asks for: a coarser spacing than the findings' beyond it, so the
// download and the drawing stay small.
const MESH_RAYS = 250000;
// Rapid moves are timed at this feed in playback, mm/min (the program gives none).
const PLAYBACK_RAPID = 10000;

const EXAMPLE = 'G21 G90\nG0 X0 Y0 Z5\nG1 Z-2 F300\nG1 X50 F600\nG0 X60 Z-2\nG0 Z5\nM30';

const FORM = `
<div class="layout">
  <form id="verify-form" novalidate>
    <fieldset><legend>Program</legend>
      <label>G-code file <input name="file" type="file" accept=".nc,.ngc,.tap,.gcode,.txt"></label>
      <label class="stacked">Program <textarea name="program" rows="10" spellcheck="false" data-field="program">${EXAMPLE}</textarea></label>
    </fieldset>
    <fieldset><legend>Tool</legend>
      <label>Tool <select name="tool" data-field="tools"></select></label>
      <label data-inline>Kind <select name="kind"><option value="flat">flat end mill</option><option value="ball">ball end mill</option></select></label>
      <label data-inline>Radius, mm <input name="radius" type="number" step="any" value="5" data-field="tools"></label>
    </fieldset>
    <fieldset><legend>Stock and part (boxes, mm)</legend>
      <label>Stock min x y z, mm <input name="stock_min" type="text" value="-20 -20 -10" data-field="stock"></label>
      <label>Stock max x y z, mm <input name="stock_max" type="text" value="70 20 0" data-field="stock"></label>
      <label>Part top z, mm <input name="part_top" type="number" step="any" value="-1.9" placeholder="none: no part" data-field="part"></label>
      <label>Spacing, mm <input name="resolution" type="number" step="any" placeholder="a twentieth of the cutter radius" data-field="resolution"></label>
    </fieldset>
    <div class="actions"><button class="primary" type="submit" id="verify-run">Verify</button></div>
  </form>
  <section id="verify-result">
    <div id="verify-messages"></div>
    <div class="summary" id="verify-summary"></div>
    <div class="table-scroll"><table class="worst"><thead><tr><th>finding</th><th>line</th><th>position, mm</th><th>depth, mm</th><th>volume, mm³</th></tr></thead>
      <tbody id="verify-findings"></tbody></table></div>
    <div id="verify-scene"></div>
    <div class="timeline-controls" id="verify-playback" hidden>
      <button type="button" class="secondary small" id="verify-play" aria-label="Play">▶</button>
      <input type="range" id="verify-position" min="0" max="0" step="1" value="0" aria-label="Cut up to move">
      <label>Speed <select id="verify-speed"><option value="1">1×</option><option value="10" selected>10×</option><option value="100">100×</option><option value="1000">1000×</option></select></label>
      <output id="verify-playback-readout"></output>
    </div>
    <ol class="listing" id="verify-listing" aria-label="G-code program" tabindex="0"></ol>
  </section>
</div>`;

// "x y z" (spaces or semicolons; a comma is a decimal comma) into three numbers, or a problem at
// the field.
function point(form, name, field) {
  const parts = value(form, name).trim().split(/[\s;]+/).map((p) => Number(p.replace(',', '.')));
  if (parts.length !== 3 || parts.some((p) => !Number.isFinite(p))) {
    throw { status: 400, title: 'Three numbers are needed', detail: `${field}: enter x y z, e.g. 0 0 -10`, field };
  }
  return parts;
}

function request(form) {
  const min = point(form, 'stock_min', 'stock');
  const max = point(form, 'stock_max', 'stock');
  const tool = value(form, 'tool') === 'inline'
    ? { kind: value(form, 'kind'), radius: numeric(form, 'radius') }
    : Number(value(form, 'tool'));
  const top = numeric(form, 'part_top');
  return {
    program: form.elements.program.value,
    tools: [tool],
    stock: { kind: 'box', min, max },
    part: top === undefined ? undefined : { kind: 'box', min, max: [max[0], max[1], top] },
    resolution: numeric(form, 'resolution'),
  };
}

// The program's lines, numbered as the findings count them (from 1), those with a finding marked.
function showListing(listing, program, findings) {
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

function showAnswer(root, answer, program) {
  showSummary(root.querySelector('#verify-summary'), [
    ['Result ', answer.ok ? 'no findings' : `${answer.findings.length} findings`],
    ['Removed ', `${number(answer.removed_volume_mm3, 1)} mm³`],
    ['Cutting time ', `${number(answer.cutting_time_s, 1)} s`],
    ['In air ', `${number(100 * answer.air_share, 1)} %`],
    ['Spacing ', `${number(answer.resolution)} mm`],
  ]);
  const listing = root.querySelector('#verify-listing');
  showListing(listing, program, answer.findings);
  root.querySelector('#verify-findings').replaceChildren(...answer.findings.map((finding) => {
    const tr = document.createElement('tr');
    tr.dataset.kind = finding.kind;
    const cells = [finding.kind.replaceAll('_', ' '), finding.line ?? '', (finding.position ?? []).map((v) => number(v, 3)).join(' '), finding.depth === undefined ? '' : number(finding.depth, 3), finding.volume_mm3 === undefined ? '' : number(finding.volume_mm3, 1)];
    for (const cell of cells) {
      const td = document.createElement('td');
      td.textContent = String(cell);
      tr.append(td);
    }
    tr.addEventListener('click', () => root.verifyStock?.mark(finding));
    if (finding.line) {
      tr.dataset.line = String(finding.line);
      tr.addEventListener('click', () => {
        listing.querySelectorAll('[aria-current]').forEach((li) => li.removeAttribute('aria-current'));
        const item = listing.querySelector(`[data-line="${finding.line}"]`);
        item?.setAttribute('aria-current', 'true');
        if (item) listing.scrollTop = item.offsetTop - listing.clientHeight / 2;
      });
    }
    return tr;
  }));
}

// The mesh request: the same cut, at a spacing coarsened to at most MESH_RAYS rays.
function meshBody(body, answer) {
  const [nx, ny] = answer.rays;
  const rays = nx * ny;
  const resolution = rays > MESH_RAYS ? answer.resolution * Math.sqrt(rays / MESH_RAYS) * 1.001 : answer.resolution;
  return { ...body, resolution };
}

async function askMesh(body, uptoLine) {
  const query = uptoLine === undefined ? '?format=glb' : `?format=glb&upto_line=${uptoLine}`;
  const blob = await api('POST', `/api/v1/verify${query}`, body, 'model/gltf-binary');
  return readGlb(await blob.arrayBuffer());
}

const FINDING_COLOURS = { gouge: '#d62728', left_material: '#1f77b4' };

// The cut stock in 3-D under the findings, with its playback.
class CutStock {
  constructor(root, answer, body) {
    this.root = root;
    this.body = meshBody(body, answer);
    const container = root.querySelector('#verify-scene');
    container.replaceChildren();
    this.scene = new Scene3D(container, { label: 'Cut stock coloured by deviation from the part' });
    this.scene.root.id = 'verify-stock';
    this.answer = answer;
    this.findings = answer.findings.filter((f) => f.position);
  }

  async draw() {
    const { json, geometry } = await askMesh(this.body);
    if (geometry) this.show(geometry, undefined, json);
    for (const [kind, colour] of Object.entries(FINDING_COLOURS)) {
      const points = this.findings.filter((f) => f.kind === kind).map((f) => f.position);
      this.scene.dots(`findings-${kind}`, points, { colour, size: 8, legend: `${kind.replaceAll('_', ' ')} (finding)` });
    }
    const others = this.findings.filter((f) => !FINDING_COLOURS[f.kind]).map((f) => f.position);
    this.scene.dots('findings-other', others, { colour: '#c47f17', size: 8, legend: 'other findings' });
    this.scene.finish();
    this.playback();
  }

  // Shows the stock `geometry` as cut up to `line` (undefined: the whole program); `json` is the
  // GLB's glTF JSON, with the answer in `extras.verify`.
  show(geometry, line, json) {
    const first = !this.scene.scene?.getObjectByName('stock');
    this.scene.coloured('stock', geometry, first ? { legend: 'cut stock: red gouge, blue material left, grey within tolerance', colour: 'linear-gradient(90deg, #d62728 33%, #b0b0b0 33% 66%, #1f77b4 66%)' } : {});
    const deviation = geometry.getAttribute('deviation');
    let deepest = 0;
    if (deviation) for (let k = 0; k < deviation.count; k += 1) deepest = Math.min(deepest, deviation.getX(k));
    const view = this.scene.root.dataset;
    view.stockVertices = String(geometry.getAttribute('position').count);
    view.deepestDeviation = deepest.toFixed(4);
    view.uptoLine = line === undefined ? 'end' : String(line);
    view.removedVolume = String(json.extras?.verify?.removed_volume_mm3 ?? 0);
    this.scene.render();
  }

  // Marks `finding` in 3-D: a marker at its position, which the camera turns to.
  mark(finding) {
    if (!this.scene.scene || !finding.position) return;
    let marker = this.scene.scene.getObjectByName('finding');
    if (!marker) {
      const size = Math.max(this.answer.resolution * 4, 0.2);
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
    const { moves } = parseProgram(this.body.program);
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
    const bar = this.root.querySelector('#verify-playback');
    bar.hidden = false;
    const slider = bar.querySelector('#verify-position');
    slider.max = String(moves.length - 1);
    slider.value = String(moves.length - 1);
    slider.oninput = () => this.go(Number(slider.value));
    const play = bar.querySelector('#verify-play');
    play.onclick = () => this.toggle(play);
  }

  // Cuts up to move `index` (0-based) and shows it; while a request is under way the latest asked
  // index waits and is asked for next.
  async go(index) {
    this.wanted = index;
    const move = this.moves[index];
    this.root.querySelector('#verify-position').value = String(index);
    this.root.querySelector('#verify-playback-readout').textContent = `Cut up to line ${move.line + 1} (move ${index + 1} of ${this.moves.length}, ${number(this.starts[index], 1)} s at the programmed feeds)`;
    if (this.busy) return;
    this.busy = true;
    try {
      while (this.asked !== this.wanted && this.root.isConnected) {
        this.asked = this.wanted;
        const line = this.moves[this.asked].line + 1;
        const { json, geometry } = await askMesh(this.body, line);
        if (geometry) this.show(geometry, line, json);
      }
    } catch (problem) {
      this.root.querySelector('#verify-playback-readout').textContent = `The stock cut up to that line cannot be drawn: ${problem.detail ?? problem.message ?? problem}`;
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
    const speed = () => Number(this.root.querySelector('#verify-speed').value);
    let index = Number(this.root.querySelector('#verify-position').value);
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
      if (index >= this.moves.length - 1 || !this.root.isConnected) {
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

// Draws the cut stock of `answer` under the findings; a refusal of the mesh (too large) is shown
// as a message, the findings stay.
async function drawStock(root, answer, body) {
  const stock = new CutStock(root, answer, body);
  root.verifyStock = stock;
  try {
    await stock.draw();
  } catch (problem) {
    root.querySelector('#verify-messages').append(message('warning', `The cut stock cannot be drawn: ${problem.detail ?? problem.message ?? problem}`));
  }
}

export const verifyView = {
  mount(root) {
    root.innerHTML = FORM;
    const form = root.querySelector('#verify-form');
    const messages = root.querySelector('#verify-messages');
    const select = form.elements.tool;
    const syncInline = () => form.querySelectorAll('[data-inline]').forEach((e) => { e.hidden = select.value !== 'inline'; });
    loadTools(select, 'inline tool').then(syncInline);
    select.addEventListener('change', syncInline);
    form.elements.file.addEventListener('change', async () => {
      const file = form.elements.file.files[0];
      if (file) form.elements.program.value = await file.text();
    });
    submitFlow(form, {
      messages,
      result: root.querySelector('#verify-result'),
      read: () => request(form),
      ask: (body) => api('POST', '/api/v1/verify', body),
      show: (answer, body) => {
        showAnswer(root, answer, body.program);
        drawStock(root, answer, body);
        return answer.ok ? null : message('error', `The program cut wrong: ${[...new Set(answer.findings.map((f) => f.kind.replaceAll('_', ' ')))].join(', ')}.`);
      },
      done: (answer) => (answer.ok ? 'Verified: the program cuts the part as it should.' : 'Verified.'),
    });
  },
};

export const view = { title: 'Verify', mount: verifyView.mount };
