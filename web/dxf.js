// A DXF drawing into a form (docs/spec/dxf.md), shared by the Contour and Segment views: the file
// is sent to `POST /api/v1/dxf`, the outer boundary and islands it gives are drawn at once (before
// anything is computed), and the chosen loop fills the view's points box.
import { api } from '/api.js';
import { clearProblem, message, showProblem } from '/form.js';
import { setUnits, unitsOf } from '/units.js';

// The form fields: the file, the units of a drawing that has none, the layer, the loop.
export const DXF_FIELDS = `
      <label>DXF drawing <input name="dxf_file" type="file" accept=".dxf,application/dxf,image/vnd.dxf" data-field="file"></label>
      <label>Units if the drawing has none <select name="dxf_units" data-field="units">
        <option value="">the drawing's</option><option value="mm">mm</option><option value="inch">inch</option>
        <option value="cm">cm</option><option value="m">m</option><option value="foot">foot</option><option value="micron">micron</option></select></label>
      <label>Layer <input name="dxf_layer" type="text" data-field="layer" placeholder="all layers"></label>
      <label>Loop <select name="dxf_loop" disabled><option value="boundary">outer boundary</option></select></label>
      <div class="dxf-preview" data-dxf-preview></div>`;

const SVG = 'http://www.w3.org/2000/svg';

// The boundary and islands as an SVG (y up), the chosen loop drawn thicker.
function draw(box, profile, chosen) {
  const loops = [profile.boundary, ...profile.islands];
  const all = loops.flat();
  const xs = all.map((p) => p[0]);
  const ys = all.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const pad = 0.05 * Math.max(x1 - x0, y1 - y0, 1e-6);
  const svg = document.createElementNS(SVG, 'svg');
  svg.setAttribute('viewBox', `${x0 - pad} ${-y1 - pad} ${x1 - x0 + 2 * pad} ${y1 - y0 + 2 * pad}`);
  svg.setAttribute('role', 'img');
  svg.setAttribute('aria-label', `DXF profile: boundary and ${profile.islands.length} islands`);
  svg.style.width = '100%';
  svg.style.height = '220px';
  loops.forEach((loop, index) => {
    const polygon = document.createElementNS(SVG, 'polygon');
    polygon.setAttribute('points', loop.map((p) => `${p[0]},${-p[1]}`).join(' '));
    polygon.setAttribute('fill', index === 0 ? '#d9dde2' : '#ffffff');
    polygon.setAttribute('stroke', index === chosen ? '#0b63b6' : '#1d2327');
    polygon.setAttribute('stroke-width', index === chosen ? '3' : '1');
    polygon.setAttribute('vector-effect', 'non-scaling-stroke');
    polygon.dataset.loop = index === 0 ? 'boundary' : `island ${index}`;
    svg.append(polygon);
  });
  box.replaceChildren(svg);
}

// Wires the DXF fields of `form`: a new file, units or layer reads the drawing; the chosen loop
// is handed to `fill(points, profile)`. Problems are shown in `messages` at their fields.
export function dxfUpload(form, { messages, fill }) {
  const preview = form.querySelector('[data-dxf-preview]');
  const loop = form.elements.dxf_loop;
  let profile = null;
  const choose = () => {
    if (!profile) return;
    const index = loop.value === 'boundary' ? 0 : Number(loop.value);
    draw(preview, profile, index);
    fill(index === 0 ? profile.boundary : profile.islands[index - 1], profile);
  };
  const read = async () => {
    const file = form.elements.dxf_file.files[0];
    if (!file) return;
    clearProblem(form);
    const query = new URLSearchParams();
    if (form.elements.dxf_units.value) query.set('units', form.elements.dxf_units.value);
    if (form.elements.dxf_layer.value.trim()) query.set('layer', form.elements.dxf_layer.value.trim());
    try {
      profile = await api('POST', `/api/v1/dxf${query.size ? `?${query}` : ''}`, file);
    } catch (problem) {
      profile = null;
      preview.replaceChildren();
      showProblem(messages, form, problem);
      return;
    }
    if (profile.boundary.length === 0) {
      // One open SPLINE: a curve for segment, with no loop to draw or fill.
      preview.replaceChildren();
      messages.replaceChildren(message('ok', `Read ${file.name}: one open SPLINE of degree ${profile.curve.degree}, no closed loop: send the file with a segment request as its "drawing" curve.`));
      profile = null;
      return;
    }
    loop.replaceChildren(new Option('outer boundary', 'boundary'), ...profile.islands.map((_, i) => new Option(`island ${i + 1}`, String(i + 1))));
    loop.disabled = profile.islands.length === 0;
    // The points are the drawing's numbers: a drawing in mm or inch moves the units switch to
    // its units (the values already typed are converted once), one in other units is said.
    if (profile.units !== unitsOf(form) && ['mm', 'inch'].includes(profile.units)) setUnits(profile.units, `units of drawing ${file.name}`);
    choose();
    messages.replaceChildren(message('ok', `Read ${file.name}: ${profile.entities} entities in ${profile.units}, the outer boundary of ${profile.boundary.length} points and ${profile.islands.length} islands (layers: ${profile.layers.join(', ')}).`));
    if (unitsOf(form) !== profile.units) messages.append(message('warning', `The drawing is in ${profile.units} and its points are in the box as the drawing gives them, but this view works in ${unitsOf(form)}: scale them, or read the drawing with its units as mm or inch.`));
  };
  form.elements.dxf_file.addEventListener('change', read);
  form.elements.dxf_units.addEventListener('change', read);
  form.elements.dxf_layer.addEventListener('change', read);
  loop.addEventListener('change', choose);
}
