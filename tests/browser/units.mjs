// Browser checks of the page's units switch and the machine form's post fields (run by run.mjs:
// `node run.mjs units|unitsPredict|unitsVerify|machinePosts <base-url> <screenshot.png>`).
import { readFile } from 'node:fs/promises';

// Every text the page draws on a canvas, with the view it is in, recorded in the page (a plot's
// axis and scale bar are canvas text, not DOM).
const RECORD_CANVAS_TEXT = () => {
  window.canvasTexts = [];
  const fillText = CanvasRenderingContext2D.prototype.fillText;
  CanvasRenderingContext2D.prototype.fillText = function record(text, ...rest) {
    window.canvasTexts.push({ text: String(text), view: this.canvas.closest('[data-view-root]')?.dataset.viewRoot ?? '' });
    return fillText.call(this, text, ...rest);
  };
};

// The JSON part of every multipart request the page sends, with its URL, recorded in the page
// (Chromium hands the driver no body of a request with a file in it).
const RECORD_MULTIPART = () => {
  window.multipartRequests = [];
  const send = window.fetch;
  window.fetch = function record(url, options = {}) {
    if (options.body instanceof FormData) window.multipartRequests.push({ url: String(url), json: options.body.get('request').text() });
    return send.call(this, url, options);
  };
};

// A binary STL of the box from `min` to `max`, each face two triangles facing out (the corner
// indices by bit x, y, z).
export function boxStl(min, max) {
  const corner = (i) => [i & 1 ? max[0] : min[0], i & 2 ? max[1] : min[1], i & 4 ? max[2] : min[2]];
  const faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
  const triangles = faces.flatMap(([a, b, c, d]) => [[a, b, c], [a, c, d]]);
  const stl = Buffer.alloc(84 + 50 * triangles.length);
  stl.writeUInt32LE(triangles.length, 80);
  triangles.forEach((triangle, t) => triangle.forEach((index, v) => corner(index).forEach((x, k) => stl.writeFloatLE(x, 84 + 50 * t + 12 + 12 * v + 4 * k))));
  return stl;
}

// Whether `a` (inch) is `b` (mm) ÷ 25.4, within `within` mm.
function inchOf(a, b, within) {
  return Number.isFinite(a) && Number.isFinite(b) && Math.abs(a * 25.4 - b) <= within;
}

export function unitScenarios({ page, base }) {
  // Runs `operation` as a job named `name` and opens its result on the Jobs view with the switch
  // at mm: a job's operation is shown in its answer's units, whatever the switch says.
  async function openJobAtMm(name, operation) {
    const job = await fetch(`${base}/api/v1/jobs`, {
      method: 'POST',
      headers: { 'content-type': 'application/json' },
      body: JSON.stringify({ name, operations: [operation] }),
    });
    if (job.status !== 202) throw new Error(`the job was not queued: ${job.status} ${await job.text()}`);
    await page.selectOption('#units', 'mm');
    await page.goto(`${base}/#/jobs`);
    await page.waitForSelector('#job-rows tr[data-status="done"]', { timeout: 120000 });
    await page.click('#job-rows tr[data-status="done"] button');
    await page.waitForSelector('#job-result[data-state="shown"]', { timeout: 60000 });
  }

  // The JSON request and answer of the next POST to `path` (with any query but a program's or a
  // mesh's `format`) while `action` runs.
  // The JSON of a request: its body, or a multipart request's `request` part as the page sent it.
  async function requestJson(request) {
    if (!/multipart/.test(request.headers()['content-type'])) return request.postDataJSON();
    const url = new URL(request.url());
    return JSON.parse(await page.evaluate(async (sent) => window.multipartRequests.filter((r) => new URL(r.url, location.href).pathname + new URL(r.url, location.href).search === sent).at(-1)?.json, url.pathname + url.search));
  }

  async function exchanged(path, action) {
    const wanted = (r) => r.method() === 'POST' && new URL(r.url()).pathname === path && !new URL(r.url()).searchParams.has('format');
    const [request, response] = await Promise.all([
      page.waitForRequest(wanted, { timeout: 120000 }),
      page.waitForResponse((r) => wanted(r.request()), { timeout: 120000 }),
      action(),
    ]);
    if (!response.ok()) throw new Error(`${path} answered ${response.status()}: ${await response.text()}`);
    return { request: await requestJson(request), answer: await response.json() };
  }

  // The request body of the next POST to `path` while `action` runs.
  async function posted(path, action) {
    const [request] = await Promise.all([
      page.waitForRequest((r) => r.method() === 'POST' && new URL(r.url()).pathname === path && !new URL(r.url()).search, { timeout: 60000 }),
      action(),
    ]);
    return JSON.parse(request.postData());
  }
  const label = (name) => page.$eval(`#contour-form [name="${name}"]`, (e) => e.closest('label').textContent.replace(/\s+/g, ' ').trim());
  const summary = () => page.textContent('#contour-result:not(.stale) .summary');

  return {
    // Switch to inch, enter a contour in inch: the request says units inch with the numbers as
    // typed, the program is G20, the labels, the plot's scale bar and the timeline readout say in;
    // the switch and the values survive a reload; back to mm the typed values are converted once
    // (the part stays the same size) and the result is computed again in mm; choosing a machine
    // with units moves the switch, and its values stay said in mm.
    async units() {
      await page.addInitScript(RECORD_CANVAS_TEXT);
      await page.goto(`${base}/#/contour`);
      await page.waitForSelector('#contour-form');
      if (await page.inputValue('#units') !== 'mm') throw new Error('the switch does not start at mm');
      if (!/Tool diameter Ø, mm/.test(await label('tool_diameter'))) throw new Error(`mm label: ${await label('tool_diameter')}`);

      // Flipping converts what is there once: the 6 mm example tool is 0.23622 in.
      await page.selectOption('#units', 'inch');
      const flipped = await page.inputValue('#contour-form [name="tool_diameter"]');
      if (flipped !== '0.23622') throw new Error(`6 mm flipped to ${flipped} in`);
      for (const [name, words] of [['tool_diameter', 'Tool diameter Ø, in'], ['feed', 'Feed, in/min'], ['top', 'Top Z, in']]) {
        if (!(await label(name)).includes(words)) throw new Error(`label of ${name}: ${await label(name)}`);
      }

      // A contour typed in inch.
      await page.fill('#contour-form [name="tool_diameter"]', '0.25');
      await page.fill('#contour-form [name="points"]', '# inch\n0, 0\n3, 0\n3, 2\n0, 2');
      await page.fill('#contour-form [name="bottom"]', '-0.3');
      await page.fill('#contour-form [name="step"]', '0.1');
      await page.fill('#contour-form [name="feed"]', '30');
      await page.fill('#contour-form [name="loop_feed"]', '80');
      await page.fill('#contour-form [name="tolerance"]', '0.0005');
      await page.fill('#contour-form [name="stock_allowance"]', '0.02');
      const body = await posted('/api/v1/contour', () => page.click('#contour-compute'));
      if (body.units !== 'inch') throw new Error(`the request says units ${body.units}`);
      if (body.tool?.radius !== 0.125 || JSON.stringify(body.contour) !== '[[0,0],[3,0],[3,2],[0,2]]' || body.feed !== 30) {
        throw new Error(`the request is not the numbers typed: ${JSON.stringify(body)}`);
      }
      await page.waitForFunction(() => /tool Ø, in/.test(document.querySelector('#contour-result:not(.stale) .summary')?.textContent ?? ''), null, { timeout: 60000 });
      const inch = await summary();
      if (!/tool Ø, in\s*0\.250/.test(inch) || /\bmm\b/.test(inch)) throw new Error(`inch summary: ${inch}`);
      const listing = await page.$$eval('#contour-result .listing li', (lines) => lines.map((l) => l.textContent));
      if (!listing.some((line) => /\bG20\b/.test(line))) throw new Error(`the program is not in inch: ${listing.slice(0, 8).join(' | ')}`);
      // The plan's scale bar and legend: in inches, never mm.
      const drawn = await page.evaluate(() => window.canvasTexts.filter((t) => t.view === 'contour').map((t) => t.text));
      if (!drawn.some((t) => /^[\d.]+ in$/.test(t)) || drawn.some((t) => /\bmm\b/.test(t))) throw new Error(`contour plot texts: ${drawn.join(' | ')}`);
      // The timeline readout.
      const slider = page.getByRole('slider', { name: /Timeline/ }).first();
      await slider.focus();
      for (let i = 0; i < 3; i++) await page.keyboard.press('ArrowRight');
      const readout = await page.textContent('#contour-result .timeline-readout');
      if (!/Z -?[\d.]+ in\b/.test(readout) || /\bmm\b/.test(readout)) throw new Error(`readout: ${readout}`);

      // A reload keeps the switch and the inch values, and computes the same inch answer.
      await page.reload();
      await page.waitForFunction(() => /tool Ø, in/.test(document.querySelector('#contour-result:not(.stale) .summary')?.textContent ?? ''), null, { timeout: 60000 });
      if (await page.inputValue('#units') !== 'inch' || await page.inputValue('#contour-form [name="tool_diameter"]') !== '0.25') {
        throw new Error(`after reload: ${await page.inputValue('#units')}, ${await page.inputValue('#contour-form [name="tool_diameter"]')}`);
      }

      // Back to mm: the typed values converted once (0.25 in = 6.35 mm), computed again in mm.
      const again = await posted('/api/v1/contour', () => page.selectOption('#units', 'mm'));
      if (again.units !== 'mm' || again.tool.radius !== 3.175 || JSON.stringify(again.contour) !== '[[0,0],[76.2,0],[76.2,50.8],[0,50.8]]') {
        throw new Error(`back in mm: ${JSON.stringify(again)}`);
      }
      await page.waitForFunction(() => /tool Ø, mm\s*6\.350/.test(document.querySelector('#contour-result:not(.stale) .summary')?.textContent ?? ''), null, { timeout: 60000 });
      if (!/Tool diameter Ø, mm/.test(await label('tool_diameter'))) throw new Error(`label back in mm: ${await label('tool_diameter')}`);

      // A machine whose profile says inch moves the switch when chosen; its values stay in mm.
      await page.evaluate(async (url) => {
        const body = JSON.stringify({ block_time_ms: 2, max_feed: 5000, dialect: 'haas', units: 'inch' });
        const response = await fetch(url, { method: 'PUT', headers: { 'content-type': 'application/json' }, body });
        if (!response.ok) throw new Error(`machine not stored: ${response.status}`);
      }, `${base}/api/v1/machines/haas-inch`);
      await page.goto(`${base}/#/segment`);
      await page.waitForSelector('#segment-form select[name="machine"] option[value="haas-inch"]', { state: 'attached', timeout: 60000 });
      await page.selectOption('#units', 'mm');
      const radiusMm = await page.inputValue('#segment-form [name="radius"]');
      const segmentBody = await posted('/api/v1/segment', async () => {
        await page.selectOption('#segment-form select[name="machine"]', 'haas-inch');
        await page.click('#segment-compute');
      });
      const radiusInch = await page.inputValue('#segment-form [name="radius"]');
      const units = await page.inputValue('#units');
      const why = await page.textContent('#units-note');
      const feedHint = await page.getAttribute('#segment-form [name="feed"]', 'placeholder');
      if (units !== 'inch' || !/haas-inch/.test(why) || segmentBody.units !== 'inch') throw new Error(`machine units not followed: ${units}, "${why}", ${segmentBody.units}`);
      if (radiusMm !== '50' || radiusInch !== '1.9685') throw new Error(`radius ${radiusMm} mm became ${radiusInch} in`);
      if (feedHint !== '5000 mm/min (machine)') throw new Error(`the machine's feed in an inch form: ${feedHint}`);

      // A job's operation is shown in the units of its answer, whatever the switch: the inch
      // contour request the page sent, run as a job and opened with the switch at mm.
      await openJobAtMm('inch contour', { operation: 'contour', ...body });
      const jobSummary = await page.textContent('#job-result .summary');
      if (!/tool Ø, in\s*0\.250/.test(jobSummary) || /\bmm\b/.test(jobSummary)) throw new Error(`the inch job's summary: ${jobSummary}`);
      return { flipped, summary: inch.slice(0, 120), readout, why, feedHint, jobSummary: jobSummary.slice(0, 120) };
    },

    // Predict in inch: flipping converts the form once (the Ø6 ball is 0.23622 in, the shape
    // error's errors but not its angles) and computes again; the request says inch, the answer's
    // errors are the mm answer's ÷ 25.4 and are read in tenths (0.0001 in) in the summary, the
    // worst passes, the tolerance band and the plots' axes; the program keeps its own mm in the
    // timeline; a saved tool is stored in mm. Back to mm gives what was typed. An STL stock is said to be in mm (its default) in
    // an inch request; an inch job is shown in tenths with the switch at mm.
    async unitsPredict() {
      await page.addInitScript(RECORD_CANVAS_TEXT);
      await page.addInitScript(RECORD_MULTIPART);
      await page.goto(`${base}/#/predict`);
      await page.waitForSelector('#predict-form');
      if (await page.inputValue('#units') !== 'mm') throw new Error('the switch does not start at mm');
      const field = (name) => page.inputValue(`#predict-form [name="${name}"]`);
      const predictLabel = (name) => page.$eval(`#predict-form [name="${name}"]`, (e) => e.closest('label').textContent.replace(/\s+/g, ' ').trim());
      const shownSummary = (words) => page.waitForFunction((w) => document.querySelector('#predict-result:not(.stale) .summary')?.textContent.includes(w), words, { timeout: 120000 });
      const shape = await field('shape_error');
      const mm = await exchanged('/api/v1/predict', () => page.click('#predict-compute'));
      if (mm.request.units !== 'mm' || mm.answer.units !== 'mm') throw new Error(`the mm request says ${mm.request.units}, its answer ${mm.answer.units}`);
      await shownSummary('error range, µm');

      await page.evaluate(() => { window.canvasTexts = []; });
      const inch = await exchanged('/api/v1/predict', () => page.selectOption('#units', 'inch'));
      const flipped = await field('ball_size');
      if (flipped !== '0.23622') throw new Error(`Ø6 mm flipped to ${flipped} in`);
      const flippedShape = (await field('shape_error')).split('\n');
      if (flippedShape[0] !== '0 0.00015748' || flippedShape[1] !== '30 0.00019685' || await field('max_correction') !== '0.0019685') {
        throw new Error(`shape error ${flippedShape.join(' | ')}, largest correction ${await field('max_correction')} in`);
      }
      for (const [name, words] of [['ball_size', 'Ball diameter Ø, in'], ['max_correction', 'Largest correction, in'], ['feed', 'Feed, in/min'], ['shape_error', 'error in inches'], ['spacing', 'Grid spacing, in']]) {
        if (!(await predictLabel(name)).includes(words)) throw new Error(`label of ${name}: ${await predictLabel(name)}`);
      }
      const sent = inch.request;
      if (sent.units !== 'inch' || sent.tool.radius !== 0.11811 || sent.tool.shape_error[1].error !== 0.00019685 || sent.correction.max_correction !== 0.0019685) {
        throw new Error(`the inch request: ${JSON.stringify({ ...sent, path: undefined, stock: undefined })}`);
      }
      // The same part in inch: every error the mm one's ÷ 25.4 (within 0.01 µm: the form's six
      // significant digits move the ball and the grid by less than that).
      const [a, b] = [inch.answer.summary, mm.answer.summary];
      const errorFields = ['min_error', 'max_error', 'mean_error', 'rms_error', 'max_correction'];
      const off = errorFields.filter((k) => !inchOf(a[k], b[k], 1e-5));
      if (inch.answer.units !== 'inch' || off.length || !inchOf(inch.answer.tool.radius, 3, 1e-4) || a.predicted !== b.predicted) {
        throw new Error(`inch answer ${JSON.stringify(a)} is not the mm answer ${JSON.stringify(b)} ÷ 25.4 (${off})`);
      }
      const tenths = (e) => (e * 10000).toFixed(1);
      await shownSummary('error range (0.0001 in)');
      const summary = await page.textContent('#predict-result .summary');
      const wanted = [`error range (0.0001 in)${tenths(a.min_error)} … ${tenths(a.max_error)}`, `mean / RMS error (0.0001 in)${tenths(a.mean_error)} / ${tenths(a.rms_error)}`, 'ball Ø0.2362 in'];
      if (wanted.some((w) => !summary.includes(w)) || /µm|\bmm\b/.test(summary)) throw new Error(`inch summary: ${summary}`);
      // Tenths are the mm answer's µm × 10 / 25.4.
      const mmTenths = (b.max_error * 1000 * 10) / 25.4;
      if (Math.abs(Number(tenths(a.max_error)) - mmTenths) > 0.1) throw new Error(`largest error ${tenths(a.max_error)} tenths, the mm answer's ${b.max_error * 1000} µm`);
      const worstHead = await page.textContent('#predict-result table.worst tr:first-child');
      const worstError = await page.textContent('#predict-result table.worst tr[data-line] td:nth-child(4)');
      if (!worstHead.includes('error (0.0001 in)') || worstError.trim() !== tenths(a.worst[0].error)) throw new Error(`worst passes: ${worstHead}; ${worstError} for ${a.worst[0].error} in`);
      // The tolerance band in tenths: ±1 counts the passes off by more than 0.0001 in.
      await page.fill('#predict-result input[name="tolerance_band"]', '1');
      const outside = await page.textContent('#predict-result output');
      const finite = inch.answer.passes.filter((p) => Number.isFinite(p.error));
      const counted = finite.filter((p) => Math.abs(p.error) > 0.0001).length;
      if (outside !== `${counted} of ${finite.length} passes outside ±1 × 0.0001 in.`) throw new Error(`tolerance band: ${outside} (${counted} outside)`);
      // The colour scale's and the histogram's axes: in tenths, never µm or mm.
      await page.waitForSelector('#predict-result:not(.stale) #predict-histogram[data-state="drawn"]');
      const drawn = await page.evaluate(() => window.canvasTexts.filter((t) => t.view === 'predict').map((t) => t.text));
      if (!drawn.some((t) => /^-?[\d.]+ × 0\.0001 in$/.test(t)) || drawn.some((t) => /µm|\bmm\b/.test(t))) throw new Error(`predict plot texts: ${drawn.join(' | ')}`);
      // The sample program is G21: the timeline reads it in its own mm.
      const slider = page.getByRole('slider', { name: /Timeline/ }).first();
      await slider.focus();
      for (let i = 0; i < 3; i++) await page.keyboard.press('ArrowRight');
      const readout = await page.textContent('#predict-result .timeline-readout');
      if (!/Z -?[\d.]+ mm\b/.test(readout)) throw new Error(`the G21 program's readout: ${readout}`);

      // "Save tool" stores the inch inline ball in the tool table's mm.
      await page.fill('#predict-form input[name="save_number"]', '7');
      await page.click('#predict-save-tool');
      await page.waitForSelector('#predict-messages .message.ok', { timeout: 60000 });
      const saved = await (await fetch(`${base}/api/v1/tools/7`)).json();
      if (Math.abs(saved.radius - 3) > 1e-4 || Math.abs(saved.shape_error?.[1]?.error - 0.005) > 1e-7) throw new Error(`the inch ball saved as ${JSON.stringify(saved)}`);

      // Back to mm: what was typed, computed again in µm.
      const again = await exchanged('/api/v1/predict', () => page.selectOption('#units', 'mm'));
      const back = await field('ball_size');
      if (back !== '6' || await field('shape_error') !== shape || await field('max_correction') !== '0.05' || again.request.tool.radius !== 3) {
        throw new Error(`back in mm: Ø${back}, ${await field('max_correction')}, ${JSON.stringify(again.request.tool)}`);
      }
      await shownSummary('error range, µm');

      // An STL stock in an inch request: said to be in mm, the units it was exported in, and read
      // so: the same prediction as the same box typed in inch.
      await exchanged('/api/v1/predict', () => page.selectOption('#units', 'inch'));
      await page.selectOption('#predict-form select[name="stock_kind"]', 'box');
      const box = await exchanged('/api/v1/predict', () => page.click('#predict-compute'));
      await page.selectOption('#predict-form select[name="stock_kind"]', 'mesh');
      await page.setInputFiles('#predict-form input[name="stock_file"]', { name: 'box.stl', mimeType: 'model/stl', buffer: boxStl([-5, -5, -10], [25, 25, 2.2]) });
      const stl = await exchanged('/api/v1/predict', () => page.click('#predict-compute'));
      if (stl.request.units !== 'inch' || JSON.stringify(stl.request.stock) !== '{"kind":"mesh","units":"mm"}') throw new Error(`the STL request: ${JSON.stringify(stl.request.stock)}, ${stl.request.units}`);
      const [m, x] = [stl.answer.summary, box.answer.summary];
      if (m.predicted !== x.predicted || m.no_surface !== x.no_surface || errorFields.some((k) => Math.abs(m[k] - x[k]) > 1e-6)) {
        throw new Error(`the mm STL read in inch: ${JSON.stringify({ ...m, worst: undefined })}, the box typed in inch: ${JSON.stringify({ ...x, worst: undefined })}`);
      }

      // The corrected program of the STL request (multipart) in inch: the G21 program's own lines.
      const [download] = await Promise.all([page.waitForEvent('download'), page.click('#predict-gcode')]);
      const corrected = await readFile(await download.path(), 'utf8');
      if (!corrected.includes('O3100') || !/\bG21\b/.test(corrected)) throw new Error(`the corrected program: ${corrected.slice(0, 200)}`);

      // An inch prediction run as a job, opened with the switch at mm: shown in tenths.
      await openJobAtMm('inch prediction', { operation: 'predict', ...inch.request });
      const jobSummary = await page.textContent('#job-result .summary');
      if (!jobSummary.includes(wanted[0]) || !jobSummary.includes('ball Ø0.2362 in') || /µm/.test(jobSummary)) throw new Error(`the inch job's summary: ${jobSummary}`);
      return { flipped, back, summary: summary.slice(0, 160), readout, band: outside, jobSummary: jobSummary.slice(0, 120) };
    },

    // Verify in inch: flipping converts the form once and computes again; the request says inch,
    // the findings' depths and positions, the spacing and the cut stock's deviations are the mm
    // answer's ÷ 25.4 and said in inches, the removed volume stays mm³. Back to mm gives what was
    // typed. A part's STL file is said to be in mm in an inch request, and read so.
    async unitsVerify() {
      await page.addInitScript(RECORD_MULTIPART);
      await page.goto(`${base}/#/verify`);
      await page.waitForSelector('#verify-form');
      const field = (name) => page.inputValue(`#verify-form [name="${name}"]`);
      const verifyLabel = (name) => page.$eval(`#verify-form [name="${name}"]`, (e) => e.closest('label').textContent.replace(/\s+/g, ' ').trim());
      const deepest = async () => Number(await page.getAttribute('#verify-stock', 'data-deepest-deviation'));
      const mm = await exchanged('/api/v1/verify', () => page.click('#verify-run'));
      await page.waitForSelector('#verify-stock[data-state="drawn"][data-stock-vertices]', { timeout: 60000 });
      const mmDeepest = await deepest();
      const gouge = (answer) => answer.findings.find((f) => f.kind === 'gouge' && f.line === 4);
      if (mm.request.units !== 'mm' || !gouge(mm.answer)) throw new Error(`the mm run: ${mm.request.units}, ${JSON.stringify(mm.answer.findings)}`);

      const inch = await exchanged('/api/v1/verify', () => page.selectOption('#units', 'inch'));
      const flipped = await field('radius');
      if (flipped !== '0.19685' || await field('stock_min') !== '-0.787402 -0.787402 -0.393701' || await field('part_top') !== '-0.0748031') {
        throw new Error(`flipped to inch: radius ${flipped}, stock min ${await field('stock_min')}, part top ${await field('part_top')}`);
      }
      for (const [name, words] of [['radius', 'Radius, in'], ['stock_min', 'Stock min x y z, in'], ['part_top', 'Part top z, in']]) {
        if (!(await verifyLabel(name)).includes(words)) throw new Error(`label of ${name}: ${await verifyLabel(name)}`);
      }
      if (inch.request.units !== 'inch' || inch.request.tools[0].radius !== 0.19685 || JSON.stringify(inch.request.stock.min) !== '[-0.787402,-0.787402,-0.393701]') {
        throw new Error(`the inch request: ${JSON.stringify(inch.request)}`);
      }
      const [g, h] = [gouge(inch.answer), gouge(mm.answer)];
      if (inch.answer.units !== 'inch' || !g || !inchOf(g.depth, h.depth, 1e-3) || !g.position.every((v, k) => inchOf(v, h.position[k], 0.3))
        || !inchOf(inch.answer.resolution, mm.answer.resolution, 1e-4) || Math.abs(inch.answer.removed_volume_mm3 - mm.answer.removed_volume_mm3) > 1e-3 * mm.answer.removed_volume_mm3) {
        throw new Error(`inch answer ${JSON.stringify({ ...inch.answer, blocks: undefined })} is not the mm answer ÷ 25.4: ${JSON.stringify(h)}`);
      }
      await page.waitForFunction(() => /Spacing\s*[\d.]+ in/.test(document.querySelector('#verify-summary')?.textContent ?? ''), null, { timeout: 60000 });
      const summary = await page.textContent('#verify-summary');
      const head = await page.textContent('#verify-result table.worst thead');
      if (!summary.includes(`Spacing ${inch.answer.resolution.toFixed(4)} in`) || !/Removed [\d.]+ mm³/.test(summary)) throw new Error(`inch summary: ${summary}`);
      if (!head.includes('position, in') || !head.includes('depth, in') || !head.includes('volume, mm³')) throw new Error(`findings head: ${head}`);
      // Lengths to 0.0001 in.
      const depth = await page.textContent('#verify-findings tr[data-kind="gouge"][data-line="4"] td:nth-child(4)');
      if (depth !== g.depth.toFixed(4)) throw new Error(`the gouge's depth shown as ${depth}, ${g.depth} in`);
      // The cut stock's deviations from the inch GLB: the slot's floor 0.1 mm = 0.0039 in deep.
      await page.waitForFunction(() => Number(document.querySelector('#verify-stock')?.dataset.deepestDeviation) > -0.05, null, { timeout: 60000 });
      if (!inchOf(await deepest(), mmDeepest, 0.004)) throw new Error(`deepest deviation ${await deepest()} in, ${mmDeepest} mm`);

      const again = await exchanged('/api/v1/verify', () => page.selectOption('#units', 'mm'));
      const back = await field('radius');
      if (back !== '5' || await field('stock_min') !== '-20 -20 -10' || await field('part_top') !== '-1.9' || again.request.tools[0].radius !== 5) {
        throw new Error(`back in mm: radius ${back}, stock min ${await field('stock_min')}, part top ${await field('part_top')}`);
      }

      // The part as an STL file exported in mm, in an inch request: said and read in mm, so the
      // slot gouges it 0.1 mm deep as the box part.
      await exchanged('/api/v1/verify', () => page.selectOption('#units', 'inch'));
      await page.selectOption('#verify-form select[name="part_kind"]', 'mesh');
      await page.setInputFiles('#verify-form input[name="part_file"]', { name: 'part.stl', mimeType: 'model/stl', buffer: boxStl([-20, -20, -10], [70, 20, -1.9]) });
      const stl = await exchanged('/api/v1/verify', () => page.click('#verify-run'));
      const s = gouge(stl.answer);
      if (stl.request.units !== 'inch' || JSON.stringify(stl.request.part) !== '{"kind":"mesh","units":"mm"}' || !s || !inchOf(s.depth, h.depth, 2e-3)) {
        throw new Error(`the mm STL part in inch: ${JSON.stringify(stl.request.part)}, ${JSON.stringify(stl.answer.findings)}`);
      }
      return { flipped, back, summary, head, deepest: await deepest() };
    },

    // The machine form offers every post the service has (the Dialect enum of its OpenAPI
    // document) and saves a Haas machine's G187 smoothing level and its units.
    async machinePosts() {
      await page.goto(`${base}/#/machines`);
      await page.waitForSelector('#machine-form');
      const openapi = await (await fetch(`${base}/api/v1/openapi.json`)).json();
      const posts = openapi.components.schemas.Dialect.enum;
      const offered = await page.$$eval('#machine-form select[name="dialect"] option', (o) => o.map((e) => e.value));
      if (JSON.stringify([...offered].sort()) !== JSON.stringify([...posts].sort())) throw new Error(`the form offers ${offered}, the service has ${posts}`);
      await page.fill('#machine-form input[name="name"]', 'haas-smooth');
      await page.selectOption('#machine-form select[name="dialect"]', 'haas');
      await page.selectOption('#machine-form select[name="haas_smoothing"]', '2');
      await page.selectOption('#machine-form select[name="units"]', 'inch');
      await page.click('#machine-save');
      await page.waitForSelector('#machine-rows tr[data-machine="haas-smooth"]', { timeout: 60000 });
      const stored = await (await fetch(`${base}/api/v1/machines/haas-smooth`)).json();
      if (stored.haas_smoothing !== 2 || stored.units !== 'inch' || stored.dialect !== 'haas') throw new Error(`stored: ${JSON.stringify(stored)}`);
      const row = await page.textContent('#machine-rows tr[data-machine="haas-smooth"]');
      if (!/G187 P2/.test(row) || !/inch/.test(row)) throw new Error(`row: ${row}`);
      // Edit shows the stored level; "none" sends no smoothing.
      // (Edit reads the stored version's ETag, which the save sends as If-Match.)
      await Promise.all([
        page.waitForResponse((r) => r.request().method() === 'GET' && /\/api\/v1\/machines\/haas-smooth$/.test(r.url()), { timeout: 60000 }),
        page.click('#machine-rows tr[data-machine="haas-smooth"] button:has-text("Edit")'),
      ]);
      if (await page.inputValue('#machine-form select[name="haas_smoothing"]') !== '2') throw new Error('Edit did not show the smoothing level');
      await page.selectOption('#machine-form select[name="haas_smoothing"]', '');
      await page.$eval('#machine-messages', (box) => box.replaceChildren());
      await page.click('#machine-save');
      await page.waitForFunction(() => /saved/.test(document.querySelector('#machine-messages .message.ok')?.textContent ?? ''), null, { timeout: 60000 });
      const cleared = await (await fetch(`${base}/api/v1/machines/haas-smooth`)).json();
      if ('haas_smoothing' in cleared) throw new Error(`smoothing not cleared: ${JSON.stringify(cleared)}`);
      return { posts: offered, stored };
    },
  };
}
