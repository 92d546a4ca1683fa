// Materials view: the work materials library (docs/spec/api.md, Materials): list, register,
// edit and delete through the shared registry view.
import { registryView } from '/views/registry.js';

const FORM = `
<div class="layout">
  <form id="material-form" novalidate>
    <fieldset><legend data-legend>Register a material</legend>
      <p class="hint" data-editing hidden><span data-editing-text></span> <button class="secondary small" type="button" id="material-cancel-edit">Cancel editing</button></p>
      <label>Name <input name="name" type="text" value="steel-c45" data-field="name"></label>
      <label><span>Specific cutting force, N/mm² <abbr class="symbol" title="k_c1.1: at h = 1 mm and b = 1 mm">kc1.1</abbr></span> <input name="kc11" type="number" step="any" value="1700" data-field="kc11"></label>
      <label><span>Kienzle exponent (no unit) <abbr class="symbol" title="m_c">mc</abbr></span> <input name="mc" type="number" step="any" value="0.25" data-field="mc"></label>
      <label>Radial to tangential force (ratio, no unit) <input name="radial_ratio" type="number" step="any" placeholder="0.3" data-field="radial_ratio"></label>
      <label>ISO 513 group <select name="iso_group" data-field="iso_group"><option value="">none</option><option>P</option><option>M</option><option>K</option><option>N</option><option>S</option><option>H</option></select></label>
      <label>Description <input name="description" type="text" placeholder="grade, condition, source" data-field="description"></label>
    </fieldset>
    <div class="actions"><button class="primary" type="submit" id="material-save">Save</button></div>
  </form>
  <section>
    <div id="material-messages"></div>
    <div class="table-scroll"><table><thead><tr><th>name</th><th>kc1.1, N/mm²</th><th>mc</th><th>radial ratio</th><th>ISO</th><th>description</th><th></th></tr></thead>
      <tbody id="material-rows"></tbody></table></div>
  </section>
</div>`;

export const materialsView = registryView({
  kind: 'material',
  plural: 'materials',
  title: 'Material',
  form: FORM,
  textFields: ['iso_group', 'description'],
  numberFields: ['kc11', 'mc', 'radial_ratio'],
  columns: (material) => [material.kc11, material.mc, material.radial_ratio, material.iso_group, material.description],
  describe: (material) => [`kc1.1 ${material.kc11} N/mm²`, `mc ${material.mc}`, material.iso_group && `ISO ${material.iso_group}`, material.description].filter(Boolean).join(', '),
});
