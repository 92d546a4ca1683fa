// Resegment view: a CAM program's feed moves cut again by the machine's block-time rule
// (docs/guide/resegment.md). A form (the program, pasted or loaded from a file, the machine or a
// block time), the block figures before and after, the largest deviation, warnings, and the new
// program to download.
import { noStockNote } from '/plot/cut-stock.js';
import { answerAndProgram, clearProblem, download, loadMachines, message, number, numeric, refusalMessage, showSummary, submitFlow, value, warningMessages } from '/form.js';

const FORM = `
<div class="layout">
  <form id="resegment-form" novalidate>
    <fieldset><legend>Program</legend>
      <label>G-code file <input name="file" type="file" accept=".nc,.ngc,.tap,.gcode,.txt,text/plain"></label>
      <label class="stacked"><span>Program</span><textarea name="program" rows="12" data-field="program" spellcheck="false"></textarea></label>
    </fieldset>
    <fieldset><legend>Control</legend>
      <label>Machine <select name="machine" data-field="machine"></select></label>
      <label>Block time, ms <input name="block_time_ms" type="text" inputmode="decimal" data-field="block_time_ms" placeholder="the machine's"></label>
      <label>Accuracy bound, mm <input name="tolerance" type="text" inputmode="decimal" data-field="tolerance" placeholder="none"></label>
    </fieldset>
    <button type="submit">Resegment</button>
    <button type="button" data-download disabled>Download program</button>
  </form>
  <div>
    <div data-messages></div>
    <div data-result></div>
  </div>
</div>`;

function figures(name, f) {
  return [
    [`${name}: feed blocks `, f.blocks],
    [`${name}: short blocks `, f.short_blocks],
    [`${name}: estimated time, s `, number(f.estimated_time_s, 2)],
  ];
}

// The answer's figures: blocks, short blocks and time before and after, the deviation.
function show(container, answer) {
  const box = document.createElement('div');
  box.className = 'summary';
  showSummary(box, [
    ['Runs cut again ', answer.runs],
    ...figures('Before', answer.before),
    ...figures('After', answer.after),
    ['Largest deviation, mm ', number(answer.max_deviation, 5)],
    ['Largest chord error, mm ', number(answer.chord_error, 5)],
  ]);
  container.replaceChildren(box, ...warningMessages(answer.warnings), noStockNote('resegment'));
}

export const view = {
  title: 'Resegment',
  mount(root) {
    root.innerHTML = FORM;
    const form = root.querySelector('form');
    const messages = root.querySelector('[data-messages]');
    const result = root.querySelector('[data-result]');
    const save = root.querySelector('[data-download]');
    loadMachines(form.elements.machine);
    let program = null;
    form.elements.file.addEventListener('change', async () => {
      const file = form.elements.file.files[0];
      if (file) form.elements.program.value = await file.text();
    });
    const read = () => {
      const request = { program: value(form, 'program') };
      if (value(form, 'machine')) request.machine = value(form, 'machine');
      for (const name of ['block_time_ms', 'tolerance']) {
        if (value(form, name) !== '') request[name] = numeric(form, name);
      }
      return request;
    };
    submitFlow(form, {
      messages,
      result,
      read,
      ask: (request) => answerAndProgram('/api/v1/resegment', request, '?format=gcode'),
      show: ({ answer, program: text, refusal }) => {
        show(result, answer);
        program = text;
        save.disabled = !text;
        return refusalMessage(refusal, 'the program');
      },
    });
    save.addEventListener('click', () => {
      clearProblem(form);
      if (program) download('resegmented.nc', program);
      else messages.replaceChildren(message('error', 'Resegment first.'));
    });
  },
  result: show,
};
