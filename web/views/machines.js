// Machines view: the controller profiles (docs/spec/api.md, Machines): list, register or replace, delete,
// and the block time from a saturation test (docs/spec/segment.md §2.1, Eq. 1).
import { POST_OPTIONS, parseDecimal } from '/form.js';
import { registryView } from '/views/registry.js';

const FORM = `
<div class="layout">
  <form id="machine-form" novalidate>
    <fieldset><legend data-legend>Register a machine</legend>
      <p class="hint" data-editing hidden><span data-editing-text></span> <button class="secondary small" type="button" id="machine-cancel-edit">Cancel editing</button></p>
      <label>Name <input name="name" type="text" value="hsc-4ms" data-field="name"></label>
      <label>Block time, ms <input name="block_time_ms" type="number" step="any" value="4" data-field="block_time_ms"></label>
      <label>Max feed, mm/min <input name="max_feed" type="number" step="any" value="10000" data-field="max_feed"></label>
      <label>Dialect <select name="dialect" data-field="dialect">${POST_OPTIONS}</select></label>
      <label><span>Block margin (no unit) <abbr class="symbol" title="k_f in docs/spec/segment.md">k_f</abbr></span> <input name="margin" type="number" step="any" placeholder="1" data-field="margin"></label>
      <label>Min chord error, mm <input name="min_chord_error" type="number" step="any" placeholder="0" data-field="min_chord_error"></label>
      <label>Description <input name="description" type="text" placeholder="control, mode, date" data-field="description"></label>
    </fieldset>
    <fieldset><legend>Programs, motion and spindle (optional)</legend>
      <label>Chord error rule <select name="mode" data-field="mode"><option value="">default (window)</option><option value="window">window</option><option value="curve">curve</option><option value="guarantee">guarantee: no short block</option></select></label>
      <label>Units of its requests and programs <select name="units" data-field="units"><option value="">default (mm)</option><option value="mm">mm</option><option value="inch">inch (G20)</option></select></label>
      <label>Haas smoothing <select name="haas_smoothing" data-field="haas_smoothing"><option value="">none: the control's setting</option><option value="1">G187 P1 rough</option><option value="2">G187 P2 medium</option><option value="3">G187 P3 finish</option></select></label>
      <label>Circular moves <select name="arcs" data-field="arcs"><option value="">default (chords)</option><option value="chords">chords (G01)</option><option value="g2g3">G02/G03</option></select></label>
      <label>Plunge feed, mm/min <input name="plunge_feed" type="number" step="any" placeholder="half the cutting feed" data-field="plunge_feed"></label>
      <label>Acceleration, mm/s² <input name="max_accel" type="number" step="any" placeholder="none: no cycle time" data-field="max_accel"></label>
      <label>Jerk, mm/s³ <input name="max_jerk" type="number" step="any" placeholder="none: trapezoids" data-field="max_jerk"></label>
      <label>Rapid feed, mm/min <input name="rapid_feed" type="number" step="any" placeholder="max feed" data-field="rapid_feed"></label>
      <label>Tool change, s <input name="tool_change_s" type="number" step="any" placeholder="0" data-field="tool_change_s"></label>
      <label>Spindle power, kW <input name="spindle_power_kw" type="number" step="any" data-field="spindle_power_kw"></label>
      <label>Spindle torque, N·m <input name="spindle_torque_nm" type="number" step="any" data-field="spindle_torque_nm"></label>
    </fieldset>
    <fieldset><legend>Block time from a saturation test</legend>
      <label>Test block, mm <input name="test_block" type="number" step="any" value="0.1"></label>
      <label>Saturated speed, mm/min <input name="saturated" type="number" step="any" value="1500"></label>
      <div class="actions"><button class="secondary" type="button" id="machine-saturation">Use T_b = L / V_sat</button></div>
    </fieldset>
    <div class="actions"><button class="primary" type="submit" id="machine-save">Save</button></div>
  </form>
  <section>
    <div id="machine-messages"></div>
    <div class="table-scroll"><table><thead><tr><th>name</th><th>block time, ms</th><th>max feed</th><th>dialect</th><th>units</th><th>margin</th><th>min chord error</th><th>description</th><th></th></tr></thead>
      <tbody id="machine-rows"></tbody></table></div>
    <p class="hint">A request that names a machine takes its values as defaults: block time and margin for deburr, segment and contour, <code>max_feed</code> for segment and the engagement feed plan, the dialect for G-code, and its units (mm or inch) for the requests that name it and give none: choosing a machine with units on a form moves the page's units switch to them. The profile's own values are in mm and mm/min whatever its units. Haas smoothing writes <code>G187 P1</code>–<code>P3</code> in the Haas post's programs; other posts ignore it.</p>
  </section>
</div>`;

export const machinesView = registryView({
  kind: 'machine',
  plural: 'machines',
  title: 'Machine',
  form: FORM,
  textFields: ['dialect', 'description', 'mode', 'arcs', 'units'],
  numberFields: ['block_time_ms', 'max_feed', 'margin', 'min_chord_error', 'plunge_feed', 'max_accel', 'max_jerk', 'rapid_feed', 'tool_change_s', 'spindle_power_kw', 'spindle_torque_nm', 'haas_smoothing'],
  columns: (machine) => [machine.block_time_ms, machine.max_feed, [machine.dialect, machine.haas_smoothing ? `G187 P${machine.haas_smoothing}` : ''].filter(Boolean).join(', '), machine.units ?? 'mm', machine.margin, machine.min_chord_error, machine.description],
  describe: (machine) => [`${machine.block_time_ms} ms`, `${machine.max_feed} mm/min`, machine.dialect, machine.units, machine.haas_smoothing && `G187 P${machine.haas_smoothing}`, machine.description].filter(Boolean).join(', '),
  mount(root, form) {
    root.querySelector('#machine-saturation').addEventListener('click', () => {
      const length = parseDecimal(form.elements.test_block.value);
      const speed = parseDecimal(form.elements.saturated.value);
      if (length > 0 && speed > 0) form.elements.block_time_ms.value = String(Number((length / speed * 60000).toPrecision(6)));
    });
  },
});
