// Contour view: layered contour milling with corner loops and inside-corner relief (docs/spec/api.md,
// Contour). A form, a 2-D plot of the contour and the tool-centre path of one layer (layer
// selector; loops, reliefs, links and corners in their own colours; wheel to zoom, drag to pan,
// double-click to fit), the corner table with the material left or over-cut, the summary, the
// warnings and the G-code download. `contourResult` also renders job results.
import { Timeline } from '/timeline.js';
import { DXF_FIELDS, dxfUpload } from '/dxf.js';
import { requestStock, verificationPanel } from '/plot/cut-stock.js';
import { ContourPlan } from '/plot/plan.js';
import { Scene3D, THREE } from '/plot/scene3d.js';
import { answerAndProgram, downloadFlow, gcodeQuery, half, keepForm, loadMachines, loadTools, machineFields, message, number, numeric, POST_OPTIONS, programName, refusalMessage, showSummary, submitFlow, value, warningMessages } from '/form.js';

// An arrow-shaped island: five protruding corners (a 64° tip among them) and two inside corners.
const SAMPLE = `# x, y in mm, counter-clockwise; one point a line
0, 10
40, 10
40, 0
80, 25
40, 50
40, 40
0, 40`;

const FORM = `
<div class="layout">
  <form id="contour-form" novalidate>
    <fieldset><legend>Tool</legend>
      <label>Tool <select name="tool_choice" data-field="tool"></select></label>
      <label data-inline-tool>Tool diameter Ø, mm <input name="tool_diameter" type="number" step="any" value="6" data-field="tool.radius"></label>
    </fieldset>
    <fieldset><legend>Contour</legend>
      <label class="stacked">Points <span class="hint">x, y a line; # comments</span>
        <textarea name="points" rows="9" spellcheck="false" data-field="contour" data-dim="points"></textarea></label>
${DXF_FIELDS}
      <label>Side <select name="side" data-field="side">
        <option value="outside">outside (island, outer profile)</option><option value="inside">inside (pocket)</option></select></label>
      <label>Cutting direction <select name="direction" data-field="direction"><option value="climb">climb</option><option value="conventional">conventional</option></select></label>
    </fieldset>
    <fieldset><legend>Depths</legend>
      <label>Top Z, mm <input name="top" type="number" step="any" value="0" data-field="depths.top"></label>
      <label>Bottom Z, mm <input name="bottom" type="number" step="any" value="-9" data-field="depths.bottom"></label>
      <label>Depth per layer, mm <input name="step" type="number" step="any" value="3" data-field="depths.step"></label>
    </fieldset>
    <fieldset><legend>Corners</legend>
      <label>Loop style <select name="loop_style" data-field="corner_loop.style">
        <option value="arc">arc</option><option value="triangle">triangle</option><option value="parallelogram">parallelogram</option><option value="none">none</option></select></label>
      <label>Inside corners <select name="relief" data-field="inside_corner_relief">
        <option value="dogbone">dogbone relief</option><option value="tbone">T-bone relief</option><option value="none">none (fillet)</option></select></label>
      <label>Roughing pass <select name="roughing" data-dim="length">
        <option value="0.3">0.3 mm, round joins</option><option value="">none</option></select></label>
    </fieldset>
    <fieldset><legend>Feeds</legend>
      <label>Feed, mm/min <input name="feed" type="number" step="any" value="800" data-field="feed"></label>
      <label>Loop feed, mm/min <input name="loop_feed" type="number" step="any" value="2000" data-field="loop_feed"></label>
      <label>Roughing allowance, mm <input name="stock_allowance" type="number" step="any" value="0.5" data-field="stock_allowance"></label>
      <label>Machine <select name="machine" data-field="machine"></select></label>
      <label>Block time, ms <input name="block_time_ms" type="number" step="any" placeholder="machine's, else off" data-field="block_time_ms"></label>
      <label>Tolerance, mm <input name="tolerance" type="number" step="any" value="0.01" data-field="tolerance"></label>
    </fieldset>
    <div class="actions">
      <button class="primary" type="submit" id="contour-compute">Compute</button>
      <select name="dialect" aria-label="G-code dialect"><option value="">machine's dialect (else Fanuc)</option>${POST_OPTIONS}</select>
      <select name="reference" aria-label="Programmed point"><option value="tip">tip</option><option value="centre">centre</option></select>
      <button class="secondary" type="button" id="contour-gcode">G-code</button>
    </div>
  </form>
  <section>
    <div id="contour-messages"></div>
    <div id="contour-result"></div>
  </section>
</div>`;

// Colours: readable on a white background, told apart without relying on red/green alone.
const COLOUR = {
  material: '#d9dde2', contour: '#1d2327', cut: '#0b63b6', loop: '#e07000', link: '#2e7d32',
  rapid: '#8a949c', relief: '#8e24aa', convex: '#e07000', concave: '#8e24aa', unreached: '#b3261e',
};

// Parses "x, y" lines; returns {points} or {error, line}.
export function parsePoints(text) {
  const points = [];
  const lines = text.split('\n');
  for (let i = 0; i < lines.length; i++) {
    const line = lines[i].replace(/#.*/, '').trim();
    if (!line) continue;
    const parts = line.split(/[\s,;]+/).filter((p) => p !== '');
    const values = parts.map(Number);
    if (values.length !== 2 || values.some((v) => !Number.isFinite(v))) {
      return { error: `line ${i + 1}: "${lines[i].trim()}" is not "x, y"`, line: i + 1 };
    }
    points.push(values);
  }
  return { points };
}

// The request body from the form (field names as docs/spec/api.md); throws {error, line} for bad points.
export function contourRequest(form) {
  const parsed = parsePoints(value(form, 'points'));
  if (parsed.error) throw parsed;
  const choice = value(form, 'tool_choice');
  const tool = choice === 'inline' ? { kind: 'flat', radius: half(numeric(form, 'tool_diameter')) } : Number(choice);
  const body = {
    tool,
    contour: parsed.points,
    side: value(form, 'side'),
    direction: value(form, 'direction'),
    depths: { top: numeric(form, 'top'), bottom: numeric(form, 'bottom'), step: numeric(form, 'step') },
    corner_loop: { style: value(form, 'loop_style') },
    inside_corner_relief: value(form, 'relief'),
    feed: numeric(form, 'feed'),
  };
  if (value(form, 'machine')) body.machine = value(form, 'machine');
  for (const name of ['loop_feed', 'stock_allowance', 'block_time_ms', 'tolerance']) {
    const v = numeric(form, name);
    if (v !== undefined) body[name] = v;
  }
  const roughing = numeric(form, 'roughing');
  if (roughing !== undefined) body.passes = [{ allowance: roughing, join: 'round' }, { allowance: 0 }];
  return body;
}



// The lines of one layer's moves, one polyline per run of moves of the same kind.
function layerLines(layer, start) {
  const style = {
    cut: [COLOUR.cut, 2.2], loop: [COLOUR.loop, 2.6], link: [COLOUR.link, 1.8, [6, 4]], rapid: [COLOUR.rapid, 1.2, [3, 4]],
  };
  const lines = [];
  let here = start;
  let current = null;
  for (const step of layer.moves) {
    const to = [step.to[0], step.to[1]];
    if (!current || current.kind !== step.kind) {
      const [colour, width, dash] = style[step.kind] || style.cut;
      current = { kind: step.kind, colour, width, dash, arrows: step.kind === 'cut', points: here ? [here] : [] };
      lines.push(current);
    }
    current.points.push(to);
    here = to;
  }
  return { lines, end: here };
}

const ACTION_TEXT = {
  loop_arc: 'arc loop', loop_triangle: 'triangle loop', loop_parallelogram: 'parallelogram loop', miter: 'miter',
  round: 'round join', reflex: 'fillet', unreached: 'not reached', dogbone: 'dogbone', tbone: 'T-bone',
};

function cornerMarks(answer) {
  const marks = [];
  for (const corner of answer.corners) {
    const colour = corner.action === 'unreached' ? COLOUR.unreached : corner.convexity === 'convex' ? COLOUR.convex : COLOUR.concave;
    marks.push({ at: corner.vertex, colour, size: 5, ring: !corner.looped && !corner.relief });
  }
  return marks;
}

function reliefLines(answer) {
  return answer.corners.filter((c) => c.relief).map((c) => ({ points: [c.cl_point, c.relief.target], colour: COLOUR.relief, width: 4 }));
}

function cell(text, className) {
  const td = document.createElement('td');
  td.textContent = text;
  if (className) td.className = className;
  return td;
}

// Zooms the plot to a corner with its loop or relief in view.
function focusCorner(plot, corner, radius) {
  const shape = corner.corner_loop;
  const points = [corner.vertex, corner.cl_point];
  if (shape) {
    points.push(shape.exit_end, shape.entry_start);
    if (shape.far_corner) points.push(shape.far_corner);
    if (shape.centre) {
      const [x, y] = shape.centre;
      points.push([x - shape.radius, y - shape.radius], [x + shape.radius, y + shape.radius]);
    }
  }
  if (corner.relief) points.push(corner.relief.target);
  const xs = points.map((p) => p[0]);
  const ys = points.map((p) => p[1]);
  const span = Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys)) + 2 * radius;
  plot.focus([(Math.max(...xs) + Math.min(...xs)) / 2, (Math.max(...ys) + Math.min(...ys)) / 2], 1.2 * span);
}

function cornerTable(answer, plot) {
  const table = document.createElement('table');
  table.className = 'corners';
  table.innerHTML = '<thead><tr><th>#</th><th>vertex x, y</th><th>angle °</th><th>corner</th><th>action</th>'
    + '<th>left mm²</th><th>left depth</th><th>over-cut mm²</th><th>over-cut depth</th></tr></thead>';
  const body = document.createElement('tbody');
  for (const corner of answer.corners) {
    const tr = document.createElement('tr');
    tr.dataset.corner = String(corner.index);
    tr.title = 'Click to zoom the plot to this corner';
    const m = corner.material;
    tr.append(cell(String(corner.index)), cell(`${number(corner.vertex[0], 3)}, ${number(corner.vertex[1], 3)}`),
      cell(number(corner.angle_deg, 1)), cell(corner.convexity, corner.convexity),
      cell(ACTION_TEXT[corner.action] || corner.action, `action ${corner.action}`),
      cell(number(m.left_area, 4)), cell(number(m.left_depth, 4)), cell(number(m.overcut_area, 4)), cell(number(m.overcut_depth, 4)));
    tr.addEventListener('click', () => focusCorner(plot, corner, answer.summary.tool_radius));
    body.append(tr);
  }
  table.append(body);
  return table;
}

function summaryItems(answer) {
  const s = answer.summary;
  const items = [
    ['side', `${s.side}, ${s.direction}`], ['tool Ø, mm', number(2 * s.tool_radius, 3)], ['corners', s.corners],
    ['layers × passes', `${s.layers} × ${s.passes}`], ['moves', s.moves], ['feed path, mm', number(s.feed_length, 1)],
    ['feed / loop feed', `${s.feed} / ${s.loop_feed}`], ['est. time, s', number(s.estimated_time_s, 1)],
    ['safe Z', number(s.safe_z, 3)], ['tolerance, mm', s.tolerance],
  ];
  if (s.blocks) {
    const b = s.blocks;
    items.push(['blocks', b.blocks], ['block length, mm', number(b.block_length, 4)],
      ['shortest block, mm', number(b.min_block_length, 4)], ['short blocks', `${b.short_blocks} (+${b.short_end_blocks} at ends)`],
      ['block-limited time, s', number(b.estimated_time_s, 1)]);
  }
  return items;
}

// Shows a contour answer in `container`: layer selector, plot, corner table, summary, warnings,
// and with a program its verification (`cutStock`: where the stock as cut comes from,
// `requestStock` or `jobStock`; drawing it cuts the program again, so a job result asks for it
// with a button). Used by the form and by job results.
// Returns the canvas.
export function contourResult(container, answer, { program, request, cutStock = null } = {}) {
  container.replaceChildren();
  const bar = document.createElement('div');
  bar.className = 'actions layer-bar';
  const label = document.createElement('label');
  label.className = 'inline';
  label.append('Layer ');
  const select = document.createElement('select');
  select.name = 'layer';
  answer.layers.forEach((layer, index) => select.append(new Option(`${index + 1} of ${answer.layers.length}: Z ${number(layer.z, 3)}`, String(index))));
  label.append(select);
  bar.append(label);
  const canvas = document.createElement('canvas');
  canvas.className = 'plot';
  canvas.setAttribute('aria-label', 'Contour and tool-centre path of the selected layer');
  const hint = document.createElement('p');
  hint.className = 'hint';
  hint.textContent = 'Wheel to zoom, drag to pan, double-click to fit; click a corner row to zoom to it. Grey: material.';
  const note = document.createElement('div');
  const warnings = document.createElement('div');
  const summary = document.createElement('div');
  summary.className = 'summary';
  container.append(bar, canvas, hint, note, warnings, summary);

  const plot = new ContourPlan(canvas);
  const contour = answer.corners.map((c) => c.vertex);
  const legend = [['contour', COLOUR.contour], ['cut', COLOUR.cut], ['loop', COLOUR.loop], ['relief', COLOUR.relief],
    ['link', COLOUR.link, [6, 4]], ['rapid', COLOUR.rapid, [3, 4]]];
  // Each layer's plot starts where the previous layer's moves ended.
  const starts = [];
  let end = null;
  for (const layer of answer.layers) {
    starts.push(end);
    if (layer.moves.length) end = [layer.moves[layer.moves.length - 1].to[0], layer.moves[layer.moves.length - 1].to[1]];
  }
  const show = (index, keepView) => {
    const layer = answer.layers[index];
    const { lines } = layerLines(layer, starts[index]);
    plot.setScene({
      material: { polygon: contour, inside: answer.summary.side === 'inside' },
      lines: [...lines, ...reliefLines(answer)],
      marks: cornerMarks(answer),
      legend,
    }, keepView);
    canvas.dataset.layer = String(index);
    note.replaceChildren(...(layer.moves.length ? [] : [message('warning', 'This layer was stored without its moves (see the warnings); the G-code has them all.')]));
  };
  select.addEventListener('change', () => show(Number(select.value), true));
  show(0, false);

  showSummary(summary, summaryItems(answer));
  warnings.replaceChildren(...warningMessages(answer.warnings));
  const corners = document.createElement('div');
  corners.className = 'table-scroll';
  corners.append(cornerTable(answer, plot));
  container.append(corners);
  // Plan (one layer) or 3-D (every layer): the 3-D scene is built the first time it is asked for.
  const radius = answer.summary.tool_radius || answer.tool?.radius || 0;
  const mode = document.createElement('select');
  mode.setAttribute('aria-label', 'View');
  mode.append(new Option('plan, one layer', 'plan'), new Option('3-D, all layers', '3d'));
  bar.append(mode);
  const sceneBox = document.createElement('div');
  sceneBox.hidden = true;
  canvas.after(sceneBox);
  let scene = null;
  let toolAt = null;
  mode.addEventListener('change', () => {
    const threeD = mode.value === '3d';
    canvas.hidden = threeD;
    hint.hidden = threeD;
    label.hidden = threeD;
    sceneBox.hidden = !threeD;
    if (threeD && !scene) {
      scene = contourScene(sceneBox, answer, contour, radius);
      scene.root.id = `${canvas.id || 'contour-plot'}-3d`;
    }
    scene?.moveTool(toolAt);
  });
  if (program) {
    // The timeline walks the program; the plan follows it from layer to layer.
    const timeline = new Timeline(bar.parentElement, program, {
      onMove: (move) => {
        const [x, y, z] = move.position;
        const layer = answer.layers.findIndex((l) => Math.abs(l.z - z) < 1e-6);
        if (layer >= 0 && String(layer) !== select.value) {
          select.value = String(layer);
          show(layer, true);
        }
        plot.setTool([x, y], radius);
        toolAt = move.position;
        if (scene && !sceneBox.hidden) scene.moveTool(toolAt);
      },
    });
    sceneBox.after(timeline.root);
  }
  if (program && request && answer.verification) drawCutStock(container, answer, cutStock);
  return canvas;
}

// The findings of the contour's own verification, and (`cutStock`) the stock block as the program
// cuts it, from the server's cut stock of that verification (POST /api/v1/contour/stock, at the verification's spacing, in the program's
// default Fanuc form, whose lines the findings count), with the findings and playback.
async function drawCutStock(container, answer, cutStock) {
  let program = null;
  if (cutStock) {
    try {
      program = await cutStock.program();
    } catch (problem) {
      container.append(message('warning', `The cut stock cannot be drawn: ${problem.detail || problem.title}`));
      return;
    }
  }
  await verificationPanel(container, {
    id: 'contour',
    verification: answer.verification,
    program,
    source: cutStock,
    why: 'press “Cut stock” to cut the program again',
    resolution: answer.verification.resolution,
  });
}

// Every layer in 3-D: the part's outline as a see-through prism from the lowest layer to the top,
// the moves coloured by kind with arrows along the cuts, and the flat tool (its tip at the
// timeline's move).
function contourScene(box, answer, contour, radius) {
  const scene = new Scene3D(box, { label: 'Contour, every layer and the tool in 3-D' });
  const zs = answer.layers.map((l) => l.z);
  const top = Math.max(...zs, 0);
  const bottom = Math.min(...zs);
  if (contour.length > 2 && top > bottom) {
    const shape = new THREE.Shape(contour.map(([x, y]) => new THREE.Vector2(x, y)));
    const prism = new THREE.ExtrudeGeometry(shape, { depth: top - bottom, bevelEnabled: false });
    prism.translate(0, 0, bottom);
    scene.solid('part', prism, { legend: answer.summary.side === 'inside' ? 'pocket outline' : 'part outline', opacity: 0.2 });
  }
  const seen = new Set();
  let here = null;
  // Direction arrows about 12 along the longest side of the part.
  const xs = contour.map((p) => p[0]);
  const ys = contour.map((p) => p[1]);
  const arrowSpacing = Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys), 1) / 12;
  for (const layer of answer.layers) {
    let run = null;
    for (const move of layer.moves) {
      if (!run || run.kind !== move.kind) {
        if (run && run.points.length > 1) draw(run);
        run = { kind: move.kind, points: here ? [here] : [] };
      }
      run.points.push(move.to);
      here = move.to;
    }
    if (run && run.points.length > 1) draw(run);
  }
  function draw(run) {
    const legend = seen.has(run.kind) ? undefined : run.kind;
    seen.add(run.kind);
    scene.path(run.kind, run.points, {
      colour: COLOUR[run.kind] || COLOUR.cut, dashed: run.kind === 'link' || run.kind === 'rapid', legend,
      arrows: run.kind === 'cut' ? arrowSpacing : undefined,
    });
  }
  scene.tool({ radius, kind: 'flat' });
  scene.finish();
  return scene;
}

// When an error names one point of the contour, says which line of the points box it is.
function markContour(form, messages, problem) {
  const paths = (problem.errors || []).map((e) => e.path);
  const hit = paths.map((p) => /^contour(?:\[(\d+)\])?/.exec(p)).find(Boolean);
  if (!hit) return;
  if (hit[1] !== undefined) {
    const index = Number(hit[1]);
    messages.append(message('error', `It is point ${index + 1} of the list (comments and blank lines not counted).`, `contour[${index}]`));
  }
}

export const contourView = {
  mount(root, id) {
    root.innerHTML = FORM;
    const form = root.querySelector('#contour-form');
    const messages = root.querySelector('#contour-messages');
    const result = root.querySelector('#contour-result');
    form.elements.points.defaultValue = SAMPLE;
    const sync = () => { form.querySelector('[data-inline-tool]').hidden = value(form, 'tool_choice') !== 'inline'; };
    form.addEventListener('change', sync);
    loadTools(form.elements.tool_choice, 'inline flat end mill (size below)').then(sync);
    loadMachines(form.elements.machine);
    machineFields(form, { block_time_ms: 'block_time_ms' });
    sync();
    // A drawing's loop fills the points box, 4 decimals a coordinate.
    dxfUpload(form, {
      messages,
      fill: (points) => {
        form.elements.points.value = points.map((p) => `${p[0].toFixed(4)}, ${p[1].toFixed(4)}`).join('\n');
      },
    });
    // The request, or a problem at the points box for a line that is not "x, y".
    const request = () => {
      try {
        return contourRequest(form);
      } catch (bad) {
        throw { status: 400, title: 'Bad input', errors: [{ path: 'contour', message: bad.error }] };
      }
    };
    submitFlow(form, {
      messages,
      result,
      read: request,
      ask: (body) => answerAndProgram('/api/v1/contour', body, gcodeQuery(form)),
      show: ({ answer, program, refusal }, request) => {
        root.querySelector('#contour-gcode').disabled = !program;
        contourResult(result, answer, { program, request, cutStock: requestStock('contour', request) }).id = 'contour-plot';
        return refusalMessage(refusal, 'this path');
      },
      failed: (problem) => markContour(form, messages, problem),
    });
    downloadFlow(root.querySelector('#contour-gcode'), form, {
      messages,
      read: request,
      path: '/api/v1/contour',
      query: () => gcodeQuery(form),
      name: () => programName('contour', form),
      failed: (problem) => markContour(form, messages, problem),
    });
    keepForm(id, form);
  },
};

// This capability's view in the page's list (`web/views.js` loads it by the capability's name).
export const view = { title: 'Contour', mount: contourView.mount, result: contourResult };
