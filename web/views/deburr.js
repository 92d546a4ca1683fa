// Deburr view: a form for one cross-hole ridge, the 3-D plot of ridge and ball-centre path with
// where the tool would meet the wall, the summary, warnings and the G-code download (docs/spec/api.md,
// Deburr).
import { api, program as programOf, sentence } from '/api.js';
import { downloadFlow, gcodeQuery, half, keepForm, loadMachines, loadTools, machineFields, message, number, numeric, POST_OPTIONS, programName, showSummary, submitFlow, value, warningMessages } from '/form.js';
import { requestStock, verificationPanel } from '/plot/cut-stock.js';
import { Scene3D, THREE } from '/plot/scene3d.js';
import { Timeline } from '/timeline.js';
import { clearance, inRadii } from '/views/deburr-clearance.js';
import { inUnits } from '/units.js';

const FORM = `
<div class="layout">
  <form id="deburr-form" novalidate>
    <fieldset><legend>Tool</legend>
      <label>Tool <select name="tool_choice" data-field="tool"></select></label>
      <label data-inline-tool>Ball diameter Ø, mm <input name="ball_diameter" type="number" step="any" value="4" data-field="tool.radius"></label>
    </fieldset>
    <fieldset><legend>Workpiece</legend>
      <label>Kind <select name="workpiece_kind" data-field="workpiece.kind">
        <option value="tube">tube</option><option value="bore_block">block with bore</option></select></label>
      <label>Point on tube axis x, y, z, mm <span class="triple">
        <input name="ox" type="number" step="any" value="0" data-field="workpiece.origin">
        <input name="oy" type="number" step="any" value="0" data-field="workpiece.origin">
        <input name="oz" type="number" step="any" value="0" data-field="workpiece.origin"></span></label>
      <label><span>Axis angle from +Y, ° <abbr class="symbol" title="arrangement angle θ_A">θA</abbr></span> <input name="arrangement" type="number" step="any" value="0" data-field="workpiece.arrangement_angle_deg"></label>
      <label>Sizes entered as <select name="sizes_as"><option value="diameter">diameters (OD, ID, Ø), as drawn</option><option value="radius">radii</option></select></label>
      <label data-kind="tube"><span data-size="outer">Outer diameter OD, mm</span> <input name="outer_size" type="number" step="any" value="50" data-field="workpiece.outer_diameter workpiece.outer_radius"></label>
      <label data-kind="tube"><span data-size="inner">Inner diameter ID, mm</span> <input name="inner_size" type="number" step="any" value="30" data-field="workpiece.inner_diameter workpiece.inner_radius"></label>
      <label data-kind="bore_block">Bore radius, mm <input name="bore_radius" type="number" step="any" value="20" data-field="workpiece.bore_radius"></label>
      <label data-kind="bore_block">Axis to face, mm <input name="face_distance" type="number" step="any" value="40" data-field="workpiece.face_distance"></label>
    </fieldset>
    <fieldset><legend>Hole</legend>
      <label>Shape <select name="shape" data-field="hole.shape">
        <option value="round">round</option><option value="slot">slot</option><option value="rounded_rect">rounded rectangle</option></select></label>
      <label><span data-size="hole">Hole diameter Ø, mm</span> <input name="hole_size" type="number" step="any" value="10" data-field="hole.diameter hole.radius"></label>
      <label data-shape="slot">Slot centre distance, mm <input name="slot_length" type="number" step="any" value="10" data-field="hole.centre_distance"></label>
      <label data-shape="rounded_rect">Corner centres across, along, mm <span class="pair">
        <input name="rect_across" type="number" step="any" value="8" data-field="hole.centre_distance">
        <input name="rect_along" type="number" step="any" value="12" data-field="hole.centre_distance"></span></label>
      <label><span>Hole offset from axis, mm <abbr class="symbol" title="eccentricity f">f</abbr></span> <input name="eccentricity" type="number" step="any" value="0" data-field="hole.eccentricity"></label>
      <label><span>Hole tilt from +Z, ° <abbr class="symbol" title="penetration angle θ_P">θP</abbr></span> <input name="penetration" type="number" step="any" value="0" data-field="hole.penetration_angle_deg"></label>
    </fieldset>
    <fieldset><legend>Cut</legend>
      <label>Which edge <select name="edge" data-field="edge"><option value="outer">outer (tube outside)</option><option value="inner">inner (bore)</option><option value="both">both (one program)</option></select></label>
      <label data-edge="both">Tool for the bore edge <select name="inner_tool_choice" data-field="inner_tool"></select></label>
      <label><span>Chamfer size, mm <abbr class="symbol" title="cut amount Q; width W = √2·Q">Q</abbr></span> <input name="cut_amount" type="number" step="any" value="0.2" data-field="cut_amount"></label>
      <label><span>Path tolerance, mm <abbr class="symbol" title="TA">TA</abbr></span> <input name="tolerance" type="number" step="any" value="0.01" data-field="tolerance"></label>
      <label>Method <select name="method" data-field="method"><option value="tangent">tangent construction</option><option value="exact">exact chamfer width</option></select></label>
      <label>Cutting direction <select name="direction" data-field="direction"><option value="ccw">ccw (climb)</option><option value="cw">cw</option></select></label>
      <label>Feed, mm/min <input name="feed" type="number" step="any" value="300" data-field="feed"></label>
      <label>Spindle, rpm <input name="spindle_rpm" type="number" step="any" value="6000" data-field="spindle_rpm"></label>
      <label>Machine <select name="machine" data-field="machine"></select></label>
      <label>Block time, ms <input name="block_time_ms" type="number" step="any" placeholder="machine's, else off" data-field="block_time_ms"></label>
    </fieldset>
    <div class="actions">
      <button class="primary" type="submit" id="deburr-compute">Compute</button>
      <select name="dialect" aria-label="G-code dialect"><option value="">machine's dialect (else Fanuc)</option>${POST_OPTIONS}</select>
      <select name="reference" aria-label="Programmed point"><option value="tip">tip</option><option value="centre">ball centre</option></select>
      <button class="secondary" type="button" id="deburr-gcode" aria-describedby="deburr-gcode-note">G-code</button>
      <output id="deburr-gcode-note" class="hint"></output>
    </div>
  </form>
  <section>
    <div id="deburr-messages"></div>
    <div id="deburr-result"></div>
  </section>
</div>`;

// The request body from the form (field names as docs/spec/api.md).
export function deburrRequest(form) {
  const choice = value(form, 'tool_choice');
  const tool = choice === 'inline' ? { kind: 'ball', radius: half(numeric(form, 'ball_diameter')) } : Number(choice);
  const origin = [numeric(form, 'ox') ?? 0, numeric(form, 'oy') ?? 0, numeric(form, 'oz') ?? 0];
  const kind = value(form, 'workpiece_kind');
  // Sizes go to the service as typed, in the field of what they are (outer_diameter or
  // outer_radius), so its messages quote what the user typed.
  const as = value(form, 'sizes_as') === 'radius' ? 'radius' : 'diameter';
  const workpiece = kind === 'tube'
    ? { kind, origin, arrangement_angle_deg: numeric(form, 'arrangement') ?? 0, [`inner_${as}`]: numeric(form, 'inner_size'), [`outer_${as}`]: numeric(form, 'outer_size') }
    : { kind, origin, arrangement_angle_deg: numeric(form, 'arrangement') ?? 0, bore_radius: numeric(form, 'bore_radius'), face_distance: numeric(form, 'face_distance') };
  const shape = value(form, 'shape');
  const hole = { shape, [as]: numeric(form, 'hole_size'), eccentricity: numeric(form, 'eccentricity') ?? 0, penetration_angle_deg: numeric(form, 'penetration') ?? 0 };
  if (shape === 'slot') hole.centre_distance = numeric(form, 'slot_length');
  if (shape === 'rounded_rect') hole.centre_distance = [numeric(form, 'rect_across'), numeric(form, 'rect_along')];
  const edge = value(form, 'edge');
  const innerChoice = value(form, 'inner_tool_choice');
  return {
    tool, workpiece, hole,
    edge,
    inner_tool: edge === 'both' && innerChoice && innerChoice !== 'inline' ? Number(innerChoice) : undefined,
    cut_amount: numeric(form, 'cut_amount'),
    tolerance: numeric(form, 'tolerance'),
    method: value(form, 'method'),
    direction: value(form, 'direction'),
    feed: numeric(form, 'feed'),
    spindle_rpm: numeric(form, 'spindle_rpm'),
    machine: value(form, 'machine') || undefined,
    block_time_ms: numeric(form, 'block_time_ms'),
  };
}

// The labels of the sizes as they are entered: diameters as a drawing gives them, or radii.
const SIZE_LABELS = {
  diameter: { outer: 'Outer diameter OD, mm', inner: 'Inner diameter ID, mm', hole: 'Hole diameter Ø (slot width), mm' },
  radius: { outer: 'Outer radius RT, mm', inner: 'Inner radius RN, mm', hole: 'Hole radius R2 (slot half-width), mm' },
};

function syncVisibility(form) {
  const labels = SIZE_LABELS[value(form, 'sizes_as')] ?? SIZE_LABELS.diameter;
  form.querySelectorAll('[data-size]').forEach((e) => { e.textContent = labels[e.dataset.size]; });
  const kind = value(form, 'workpiece_kind');
  const shape = value(form, 'shape');
  form.querySelectorAll('[data-kind]').forEach((e) => { e.hidden = e.dataset.kind !== kind; });
  form.querySelectorAll('[data-shape]').forEach((e) => { e.hidden = e.dataset.shape !== shape; });
  form.querySelector('[data-inline-tool]').hidden = value(form, 'tool_choice') !== 'inline';
  if (kind === 'bore_block') form.elements.edge.value = 'inner';
  form.querySelectorAll('[data-edge]').forEach((e) => { e.hidden = e.dataset.edge !== value(form, 'edge'); });
}


// The solids of the request in machine coordinates (docs/spec/deburr.md §1.3: local y along the cylinder
// axis A1, z along the hole axis A2, g = O + R_z(θ_A)·R_y(θ_P)·l): the tube or bored block and the
// hole's wall, drawn see-through.
function addWorkpiece(scene, request) {
  const { workpiece, hole } = request;
  const deg = Math.PI / 180;
  const matrix = new THREE.Matrix4().makeRotationZ((workpiece.arrangement_angle_deg || 0) * deg)
    .multiply(new THREE.Matrix4().makeRotationY((hole.penetration_angle_deg || 0) * deg))
    .setPosition(...workpiece.origin);
  const sized = inRadii(request);
  const outer = workpiece.kind === 'tube' ? sized.workpiece.outer_radius : workpiece.face_distance ?? workpiece.bore_radius * 2;
  const inner = workpiece.kind === 'tube' ? sized.workpiece.inner_radius : workpiece.bore_radius;
  const r = sized.hole.radius;
  if (![outer, inner, r].every((v) => Number.isFinite(v) && v > 0)) return;
  const along = Array.isArray(hole.centre_distance) ? hole.centre_distance[1] : hole.centre_distance || 0;
  const across = Array.isArray(hole.centre_distance) ? hole.centre_distance[0] : 0;
  const length = Math.max(2.4 * outer, 4 * r + 2 * along);
  // Cross-sections in the x_L–z_L plane, extruded along z then turned so z becomes y_L (A1).
  const section = new THREE.Shape();
  if (workpiece.kind === 'tube') section.absarc(0, 0, outer, 0, 2 * Math.PI, false);
  else section.moveTo(-outer, -outer).lineTo(outer, -outer).lineTo(outer, outer).lineTo(-outer, outer).closePath();
  const bore = new THREE.Path();
  bore.absarc(0, 0, inner, 0, 2 * Math.PI, true);
  section.holes.push(bore);
  const body = new THREE.ExtrudeGeometry(section, { depth: length, bevelEnabled: false, curveSegments: 72 });
  body.translate(0, 0, -length / 2);
  body.rotateX(-Math.PI / 2);
  body.scale(1, 1, -1);
  scene.solid(workpiece.kind, body, { colour: '#7f97ad', opacity: 0.18, matrix, legend: workpiece.kind === 'tube' ? 'tube' : 'block with bore' });
  // The hole seen along A2: circle, slot (straight sides along A1) or rounded rectangle.
  const f = hole.eccentricity || 0;
  const a = across / 2;
  const b = along / 2;
  const wall = new THREE.Shape();
  wall.absarc(f + a, b, r, 0, Math.PI / 2, false);
  wall.absarc(f - a, b, r, Math.PI / 2, Math.PI, false);
  wall.absarc(f - a, -b, r, Math.PI, 1.5 * Math.PI, false);
  wall.absarc(f + a, -b, r, 1.5 * Math.PI, 2 * Math.PI, false);
  // Through the wall only: from just inside the bore to just outside the outer surface or face.
  const [from, to] = [inner * 0.8, outer * 1.1];
  const hollow = new THREE.ExtrudeGeometry(wall, { depth: to - from, bevelEnabled: false, curveSegments: 48 });
  hollow.translate(0, 0, from);
  scene.solid('hole', hollow, { colour: '#37474f', opacity: 0.22, matrix, legend: 'hole wall' });
}

// Shows a deburr answer in `container`: the 3-D scene (solids when the request is known, ridge,
// ball-centre path, approach and retract, the tool at the timeline's move), summary, warnings,
// and with a program the timeline and its listing, and its verification (`cutStock`: where the
// tube as cut comes from, `requestStock` or `jobStock`; drawing it cuts the program again, so a
// job result asks for it with a button). `context`: {request, program, problem, reference,
// cutStock}. Used by the form and by job results.
export function deburrResult(container, answer, context = {}) {
  container.replaceChildren();
  const { request, program, problem, reference = 'tip', cutStock = null } = context;
  const warnings = document.createElement('div');
  const summaryBox = document.createElement('div');
  summaryBox.className = 'summary';
  const sceneBox = document.createElement('div');
  container.append(summaryBox, warnings, sceneBox);
  const points = answer.points;
  const centres = (moves) => moves.map((m) => m.centre);
  const scene = new Scene3D(sceneBox, {
    label: 'Tube, hole, ridge line and tool-centre path in 3-D',
    presets: request ? [{ label: 'Along hole axis', direction: holeAxis(request) }] : [],
  });
  if (request) addWorkpiece(scene, request);
  scene.path('ridge', points.map((p) => p.target), { colour: '#555555', legend: 'ridge (where the edges meet)' });
  scene.path('centres', [...points.map((p) => p.centre), points[0].centre], { colour: '#0b63b6', legend: 'ball-centre path' });
  // Several loops (holes, both edges): every other loop too, in the order the program visits them.
  (answer.holes ?? []).slice(1).forEach((loop, i) => {
    scene.path(`ridge-${i + 1}`, loop.points.map((p) => p.target), { colour: '#555555' });
    scene.path(`centres-${i + 1}`, loop.points.map((p) => p.centre), { colour: loop.edge === 'inner' ? '#6a1b9a' : '#0b63b6', legend: i === 0 && loop.edge === 'inner' ? 'bore-edge centre path' : undefined });
  });
  // Where the ball on its way in or out, or the neck along the path, meets the wall: red.
  const found = request ? clearance(request, answer) : null;
  const blocked = Boolean(found?.approach.length);
  const refused = Boolean(problem) || blocked;
  const lead = { colour: refused ? '#b3261e' : '#c77700', dashed: true };
  scene.path('lead-in', [...centres(answer.lead_in), points[0].centre], { ...lead, legend: refused ? 'approach / retract (no program, see above)' : 'approach / retract' });
  if (answer.lead_out.length) scene.path('lead-out', [points[points.length - 1].centre, ...centres(answer.lead_out)], lead);
  found?.approach.forEach((piece, i) => scene.path('approach-collision', piece, { colour: '#d50000', legend: i === 0 ? 'ball through the wall' : undefined }));
  if (blocked) scene.dots('approach-collision', found.approach.flat(), { colour: '#d50000', size: 7 });
  if (found?.neck.length) scene.dots('neck-collision', found.neck, { colour: '#d50000', size: 7, legend: 'neck meets the wall' });
  const tool = answer.tool || {};
  scene.tool({ radius: tool.radius || 1, neck: tool.neck_radius, shankLength: tool.stickout, colour: refused ? '#b3261e' : undefined });
  scene.root.dataset.refused = String(refused);
  scene.root.dataset.collisions = [blocked ? 'approach' : '', found?.neck.length ? 'neck' : ''].filter(Boolean).join(' ');
  const notes = [];
  if (blocked) {
    scene.root.dataset.blocked = `the ball's way in or out runs through the wall for ${number(found.approachLength, 1)} ${inUnits('mm', answer.units)} (red in the view)`;
    notes.push(message('error', `No G-code: ${scene.root.dataset.blocked}.`));
  }
  if (found?.neck.length) {
    const part = tool.neck_radius ? `neck (radius ${tool.neck_radius} ${inUnits('mm', answer.units)})` : 'shank (as wide as the ball: no neck given)';
    notes.push(message('warning', `The ${part} meets the wall at ${found.neck.length} of ${found.checked} path points checked (red dots).`));
  }
  scene.finish();
  scene.moveTool(points[0].centre);
  if (found) scene.markTool(Object.values(found.at(points[0].centre)).some(Boolean));
  if (program) {
    const centreLift = lift(tool, reference);
    new Timeline(container, program, {
      label: 'Timeline',
      onMove: (move) => {
        const centre = [move.position[0], move.position[1], move.position[2] + centreLift];
        scene.moveTool(centre);
        // Red where the ball or the neck is in the wall at this move.
        if (found) {
          const hit = found.at(centre);
          scene.markTool(hit.ball || hit.neck);
        }
      },
    });
  }
  const s = answer.summary;
  const items = [
    ['edge', `${answer.edge} (${answer.method === 'exact' ? 'exact width' : 'tangent construction'})`], ['points', s.count], ['path length, mm', number(s.path_length, 3)],
    ['largest deviation, mm', number(s.max_deviation, 5)], ['chamfer width W, mm', number(s.width)],
    ['true width, mm', `${number(s.true_width_min)} – ${number(s.true_width_max)}`],
    ['wedge angle, °', `${number(s.wedge_angle_min_deg, 2)} – ${number(s.wedge_angle_max_deg, 2)}`],
    ['estimated time, s', number(s.estimated_time_s, 1)],
  ];
  if (s.max_exact_offset !== undefined) items.push(['exact vs tangent, mm', number(s.max_exact_offset, 5)]);
  if (s.blocks !== undefined) {
    items.push(['blocks (short)', `${s.blocks} (${s.short_blocks})`], ['block length, mm', number(s.block_length, 4)]);
  }
  if (answer.machine) items.push(['machine', `${answer.machine.name} (${answer.machine.dialect})`]);
  if (answer.holes) {
    const order = answer.visiting_order;
    items.push(['loops (holes × edges)', answer.holes.length]);
    if (order) {
      items.push(['travel between loops, mm', `${number(order.travel, 1)} (request order ${number(order.request_order_travel, 1)})`]);
      if (order.tool_changes) items.push(['tool changes', order.tool_changes]);
      if (order.turns) items.push(['tube turns (M00)', order.turns]);
    }
  }
  if (answer.cycle_time) items.push(['cycle time, s', number(answer.cycle_time.total_s, 1)]);
  showSummary(summaryBox, items);
  warnings.replaceChildren(...notes, ...warningMessages(answer.warnings));
  if (request && program && answer.verification) drawCutTube(container, scene, answer, lift(tool, 'tip'), cutStock);
  return scene.root;
}

// The height of the ball centre above the programmed point: the ball radius for the tip.
function lift(tool, reference) {
  return reference === 'tip' ? tool.radius || 0 : 0;
}

// Most rays of the cut tube the page asks for: the tube's faces are curved, so each ray keeps its
// own quads (about four a ray on the reference tube), and this many keep the mesh about a million
// vertices (some 40 MB from the service) and a few seconds to cut and draw.
const TUBE_RAYS = 60000;

// The spacing the page asks the cut tube at: a third of the chamfer width W (so the band is a few
// rays wide), coarsened to at most TUBE_RAYS over the verification's footprint.
export function tubeResolution(answer) {
  const { rays: [nx, ny], resolution } = answer.verification;
  const area = nx * ny * resolution * resolution;
  return Math.max((answer.summary.width || resolution) / 3, Math.sqrt(area / TUBE_RAYS));
}

// The tube with its holes and the chamfers as the program cuts them, from the server's cut stock
// of the deburr's own verification (`cutStock`: POST /api/v1/deburr/stock, or a job operation's,
// in the program's default Fanuc form, whose lines the findings count), drawn in the deburr scene
// in place of the see-through tube and hole wall (the view closes in on the chamfers); the
// findings listed under it, and playback that cuts the chamfer move by move.
async function drawCutTube(container, scene, answer, centreLift, cutStock) {
  let program = null;
  if (cutStock) {
    try {
      program = await cutStock.program();
    } catch (problem) {
      container.append(message('warning', `The cut tube cannot be drawn: ${sentence(problem.detail || problem.title)}`));
      return;
    }
  }
  const stock = await verificationPanel(container, {
    id: 'deburr',
    verification: answer.verification,
    program,
    source: cutStock,
    why: 'press “Cut stock” to cut the program again',
    resolution: tubeResolution(answer),
    scene,
    onMove: (move) => scene.moveTool([move.position[0], move.position[1], move.position[2] + centreLift]),
  });
  const cut = scene.scene?.getObjectByName('stock');
  if (stock && cut) {
    // The cut tube replaces the see-through solids, and the view closes in on the chamfers.
    for (const name of ['tube', 'bore_block', 'hole']) {
      const solid = scene.scene.getObjectByName(name);
      if (solid) solid.visible = false;
    }
    // The chamfer is the subject: the ridges and a ball's width about them.
    const reach = 2 * (answer.tool?.radius || 1) + (answer.summary.width || 0);
    const ridges = [answer.points, ...(answer.holes ?? []).map((loop) => loop.points)].flat().map((p) => new THREE.Vector3(...p.target));
    scene.box.setFromPoints(ridges).expandByScalar(reach);
    scene.fit();
    scene.root.dataset.cutTube = 'drawn';
  }
}

// The direction the hole axis A2 points (the view "along the hole axis" looks down it).
function holeAxis(request) {
  const deg = Math.PI / 180;
  const ta = (request.workpiece.arrangement_angle_deg || 0) * deg;
  const tp = (request.hole.penetration_angle_deg || 0) * deg;
  return [Math.cos(ta) * Math.sin(tp), Math.sin(ta) * Math.sin(tp), Math.cos(tp)];
}

export const deburrView = {
  mount(root, id) {
    root.innerHTML = FORM;
    const form = root.querySelector('#deburr-form');
    const messages = root.querySelector('#deburr-messages');
    const result = root.querySelector('#deburr-result');
    const gcode = root.querySelector('#deburr-gcode');
    const gcodeNote = root.querySelector('#deburr-gcode-note');
    form.addEventListener('change', () => syncVisibility(form));
    loadTools(form.elements.tool_choice, 'inline ball (size below)', (tool) => tool.kind === 'ball').then(() => syncVisibility(form));
    loadTools(form.elements.inner_tool_choice, 'the same tool', (tool) => tool.kind === 'ball');
    loadMachines(form.elements.machine);
    machineFields(form, { block_time_ms: 'block_time_ms' });
    syncVisibility(form);
    let last = null;
    // Draws the answer with the program in the chosen dialect and reference; without a program
    // (the service refuses it, e.g. a neck collision) the G-code button is off and says why.
    const draw = async () => {
      if (!last) return;
      const reference = value(form, 'reference');
      let program = null;
      let problem = null;
      try {
        program = await programOf('/api/v1/deburr', last.request, gcodeQuery(form));
      } catch (refused) {
        problem = refused;
      }
      const scene = deburrResult(result, last.answer, { request: last.request, program, problem, reference, cutStock: requestStock('deburr', last.request) });
      scene.id = 'deburr-plot';
      // Off when the service refuses the program or the page sees the approach cut the wall;
      // the reason is beside the button (a tooltip alone is out of reach on a touch screen).
      const reason = problem ? sentence(problem.detail || problem.title) : scene.dataset.blocked ? sentence(scene.dataset.blocked) : '';
      gcode.disabled = Boolean(reason);
      gcodeNote.textContent = reason ? `G-code off: ${reason}` : '';
      gcode.title = gcodeNote.textContent;
      // The answer says so itself when it carries W_NO_PROGRAM.
      if (problem && !last.answer.warnings.some((w) => w.code === 'W_NO_PROGRAM')) {
        return message('error', `No G-code for this path. ${sentence(problem.detail || problem.title)}`, problem.code);
      }
      return null;
    };
    const redraw = async () => {
      const refusal = await draw();
      if (refusal) messages.append(refusal);
    };
    form.elements.dialect.addEventListener('change', redraw);
    form.elements.reference.addEventListener('change', redraw);
    submitFlow(form, {
      messages,
      result,
      read: () => deburrRequest(form),
      ask: (request) => api('POST', '/api/v1/deburr', request),
      show: (answer, request) => {
        last = { request, answer };
        return draw();
      },
    });
    // The marks of an earlier problem stay on a download, as they always have here.
    downloadFlow(gcode, form, {
      messages,
      read: () => deburrRequest(form),
      path: '/api/v1/deburr',
      query: () => gcodeQuery(form),
      name: () => programName('deburr', form),
      keepMarks: true,
    });
    keepForm(id, form);
  },
};

// This capability's view in the page's list (`web/views.js` loads it by the capability's name).
export const view = { title: 'Deburr', mount: deburrView.mount, result: deburrResult };
