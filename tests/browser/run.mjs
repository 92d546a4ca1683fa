// Browser checks of the kerf page, driven by cargo test (tests/tests/api/browser.rs).
// Usage: node run.mjs <scenario> <base-url> <screenshot.png> [job-file]
// Prints one JSON line with what it saw; exits non-zero with the reason when a check fails.
import { readFileSync } from 'node:fs';
import { chromium } from 'playwright-core';

const [scenario, base, screenshot, jobFile] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.KERF_CHROMIUM || '/usr/bin/chromium',
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync'],
});
const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
const problems = [];
page.on('pageerror', (error) => problems.push(`page error: ${error.message}`));
// Chromium logs every non-2xx fetch as a console error; the API's 4xx answers are expected here.
page.on('console', (m) => {
  if (m.type() === 'error' && !/status of 4\d\d/.test(m.text())) problems.push(`console error: ${m.text()}`);
});

// Counts plot pixels that differ from the white background.
async function inkedPixels(selector) {
  return page.$eval(selector, (canvas) => {
    const data = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
    let inked = 0;
    for (let i = 0; i < data.length; i += 4) {
      if (data[i] < 200 || data[i + 1] < 200 || data[i + 2] < 200) inked++;
    }
    return inked;
  });
}

// Counts plot pixels within 40 of the colour [r, g, b].
async function colouredPixels(selector, colour) {
  return page.$eval(selector, (canvas, [r, g, b]) => {
    const data = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
    let found = 0;
    for (let i = 0; i < data.length; i += 4) {
      if (Math.abs(data[i] - r) + Math.abs(data[i + 1] - g) + Math.abs(data[i + 2] - b) < 40) found++;
    }
    return found;
  }, colour);
}

const scenarios = {
  // Loads the page, submits the sample deburr job with the button, waits for the plot.
  async deburr() {
    await page.goto(`${base}/`);
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-plot[data-state="drawn"]', { timeout: 15000 });
    const segments = Number(await page.getAttribute('#deburr-plot', 'data-segments'));
    const inked = await inkedPixels('#deburr-plot');
    const summary = await page.textContent('#deburr-result .summary');
    if (segments < 10) throw new Error(`only ${segments} segments drawn`);
    if (inked < 500) throw new Error(`plot nearly blank: ${inked} inked pixels`);
    if (!/points\s*\d+/.test(summary)) throw new Error(`no summary: ${summary}`);

    // A machine registered through the API and chosen on the form spaces the points by its block
    // time: the summary reports the blocks and the machine.
    await page.evaluate(async (url) => {
      const body = JSON.stringify({ block_time_ms: 4, max_feed: 6000, dialect: 'linuxcnc' });
      const response = await fetch(url, { method: 'PUT', headers: { 'content-type': 'application/json' }, body });
      if (!response.ok) throw new Error(`machine not stored: ${response.status}`);
    }, `${base}/api/v1/machines/page-4ms`);
    await page.goto(`${base}/`);
    await page.waitForSelector('#deburr-form select[name="machine"] option[value="page-4ms"]', { state: 'attached', timeout: 15000 });
    await page.selectOption('#deburr-form select[name="machine"]', 'page-4ms');
    await page.click('#deburr-compute');
    await page.waitForFunction(() => /page-4ms/.test(document.querySelector('#deburr-result .summary')?.textContent ?? ''), null, { timeout: 15000 });
    const withMachine = await page.textContent('#deburr-result .summary');
    if (!/blocks \(short\)\d+ \(0\)/.test(withMachine)) throw new Error(`no block figures: ${withMachine}`);

    // A bad value is reported with the field highlighted.
    await page.fill('input[name="hole_radius"]', '-1');
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-messages .message.error', { timeout: 15000 });
    const highlighted = await page.$$eval('.invalid', (list) => list.map((e) => e.name));
    if (!highlighted.includes('hole_radius')) throw new Error(`field not highlighted: ${highlighted}`);
    return { segments, inked };
  },

  // The Segment view with its sample (the patent's R50 circle at 10 m/min, 4 ms): plan, charts,
  // the comparison with a fixed 0.01 mm, a bad value highlighted, a machine registered on the
  // Machines view and used, the G-code downloaded, the machine deleted.
  async segment() {
    await page.goto(`${base}/#segment`);
    await page.click('#segment-compute');
    await page.waitForSelector('#segment-plot[data-state="drawn"]', { timeout: 15000 });
    await page.waitForSelector('#segment-chart[data-state="drawn"]', { timeout: 15000 });
    await page.waitForSelector('#segment-lengths[data-state="drawn"]', { timeout: 15000 });
    const segments = Number(await page.getAttribute('#segment-plot', 'data-segments'));
    const inked = await inkedPixels('#segment-plot');
    const chartInked = await inkedPixels('#segment-chart');
    const lengthsInked = await inkedPixels('#segment-lengths');
    const summary = await page.textContent('#segment-result .summary');
    const comparison = await page.$$eval('table.comparison tbody tr:first-child td', (cells) => cells.map((c) => c.textContent));
    if (segments !== 472) throw new Error(`expected 472 blocks drawn, got ${segments}`);
    if (inked < 500 || chartInked < 300 || lengthsInked < 300) throw new Error(`plots nearly blank: ${inked}, ${chartInked}, ${lengthsInked}`);
    if (!/blocks\s*472/.test(summary)) throw new Error(`no summary: ${summary}`);
    if (comparison.join('|') !== 'blocks|472|158') throw new Error(`comparison: ${comparison}`);

    // The G-code download.
    const [file] = await Promise.all([page.waitForEvent('download'), page.click('#segment-gcode')]);
    const program = await new Promise((resolve, reject) => {
      file.createReadStream().then((stream) => {
        let text = '';
        stream.on('data', (chunk) => { text += chunk; });
        stream.on('end', () => resolve(text));
        stream.on('error', reject);
      }, reject);
    });
    if (!program.includes('G01 X49.9956 Y0.6667 Z0.0000') || !program.includes('M30')) throw new Error(`program: ${program.slice(0, 400)}`);

    // A bad value is reported with the field highlighted.
    await page.fill('input[name="feed"]', '-1');
    await page.click('#segment-compute');
    await page.waitForSelector('#segment-messages .message.error', { timeout: 15000 });
    const highlighted = await page.$$eval('.invalid', (list) => list.map((e) => e.name));
    if (!highlighted.includes('feed')) throw new Error(`field not highlighted: ${highlighted}`);

    // Register a machine, then cut the curve with its values.
    await page.click('#tabs button[data-view="machines"]');
    await page.fill('#machine-form input[name="name"]', 'hsc-page');
    await page.fill('#machine-form input[name="max_feed"]', '12000');
    await page.fill('#machine-form input[name="margin"]', '1.1');
    await page.selectOption('#machine-form select[name="dialect"]', 'linuxcnc');
    await page.click('#machine-save');
    await page.waitForSelector('#machine-rows tr[data-machine="hsc-page"]', { timeout: 15000 });
    await page.click('#tabs button[data-view="segment"]');
    await page.waitForSelector('#segment-form select[name="machine"] option[value="hsc-page"]', { state: 'attached', timeout: 15000 });
    await page.selectOption('#segment-form select[name="machine"]', 'hsc-page');
    for (const name of ['feed', 'block_time_ms', 'margin', 'min_chord_error']) await page.fill(`#segment-form input[name="${name}"]`, '');
    await page.click('#segment-compute');
    await page.waitForSelector('#segment-plot[data-state="drawn"]', { timeout: 15000 });
    const withMachine = await page.textContent('#segment-result .summary');
    if (!/hsc-page/.test(withMachine) || !/12000 mm\/min/.test(withMachine)) throw new Error(`machine not used: ${withMachine}`);
    const machineBlocks = Number(await page.getAttribute('#segment-plot', 'data-segments'));

    // Delete it again.
    await page.click('#tabs button[data-view="machines"]');
    await page.waitForSelector('#machine-rows tr[data-machine="hsc-page"]', { timeout: 15000 });
    await page.click('#machine-rows tr[data-machine="hsc-page"] button:has-text("Delete")');
    await page.waitForSelector('#machine-rows tr[data-machine="hsc-page"]', { state: 'detached', timeout: 15000 });
    return { segments, inked, chartInked, lengthsInked, machineBlocks };
  },

  // Computes the sample contour, checks the plot (loops and reliefs in their colours), the
  // corner table and the layer selector, downloads the G-code, and reports bad input on the
  // right field.
  async contour() {
    await page.goto(`${base}/#contour`);
    await page.click('#contour-compute');
    await page.waitForSelector('#contour-plot[data-state="drawn"]', { timeout: 15000 });
    const segments = Number(await page.getAttribute('#contour-plot', 'data-segments'));
    const inked = await inkedPixels('#contour-plot');
    const loopPixels = await colouredPixels('#contour-plot', [224, 112, 0]);
    const reliefPixels = await colouredPixels('#contour-plot', [142, 36, 170]);
    const actions = await page.$$eval('#contour-result table.corners td.action', (l) => l.map((e) => e.textContent));
    const summary = await page.textContent('#contour-result .summary');
    if (segments < 50) throw new Error(`only ${segments} segments drawn`);
    if (inked < 2000) throw new Error(`plot nearly blank: ${inked} inked pixels`);
    if (loopPixels < 100 || reliefPixels < 20) throw new Error(`loops ${loopPixels} / reliefs ${reliefPixels} pixels`);
    if (actions.filter((a) => a === 'arc loop').length !== 5 || actions.filter((a) => a === 'dogbone').length !== 2) {
      throw new Error(`corner actions: ${actions}`);
    }
    if (!/layers × passes\s*3 × 2/.test(summary)) throw new Error(`summary: ${summary}`);
    if (screenshot) await page.screenshot({ path: screenshot.replace(/\.png$/, '-first.png'), fullPage: true });
    const fitted = Number(await page.getAttribute('#contour-plot', 'data-scale'));

    // The last layer, then a corner zoomed in from the table.
    await page.selectOption('#contour-result select[name="layer"]', '2');
    await page.waitForSelector('#contour-plot[data-layer="2"][data-state="drawn"]', { timeout: 5000 });
    await page.click('#contour-result table.corners tbody tr[data-corner="3"]');
    const zoomed = Number(await page.getAttribute('#contour-plot', 'data-scale'));
    const zoomedLoop = await colouredPixels('#contour-plot', [224, 112, 0]);
    if (zoomed < 2 * fitted || zoomedLoop < 500) throw new Error(`zoom to the tip: scale ${fitted} → ${zoomed}, loop ${zoomedLoop} px`);

    // The G-code download.
    await page.selectOption('#contour-form select[name="dialect"]', 'linuxcnc');
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#contour-gcode')]);
    const program = readFileSync(await download.path(), 'utf8');
    if (!program.includes('G64 P') || !program.trim().endsWith('M30')) throw new Error(`program: ${program.slice(0, 200)}`);

    // A bad step is reported on its field; a crossing contour on the points box; a line that is
    // not "x, y" before anything is sent.
    await page.fill('#contour-form input[name="step"]', '0');
    await page.click('#contour-compute');
    await page.waitForSelector('#contour-messages .message.error', { timeout: 15000 });
    const invalidStep = await page.$$eval('#contour-form .invalid', (l) => l.map((e) => e.name));
    if (!invalidStep.includes('step')) throw new Error(`step not highlighted: ${invalidStep}`);
    await page.fill('#contour-form input[name="step"]', '3');
    await page.fill('#contour-form textarea[name="points"]', '0, 0\n10, 10\n10, 0\n0, 10');
    await page.click('#contour-compute');
    await page.waitForFunction(() => /E_SELF_INTERSECTION/.test(document.querySelector('#contour-messages').textContent), null, { timeout: 15000 });
    const invalidPoints = await page.$$eval('#contour-form .invalid', (l) => l.map((e) => e.name));
    if (!invalidPoints.includes('points')) throw new Error(`points not highlighted: ${invalidPoints}`);
    await page.fill('#contour-form textarea[name="points"]', '0, 0\n10 0 5\n10, 10');
    await page.click('#contour-compute');
    const local = await page.textContent('#contour-messages');
    if (!/line 2/.test(local)) throw new Error(`local check: ${local}`);
    return { segments, inked, loopPixels, reliefPixels, zoomed: zoomed / fitted };
  },

  // The Engagement view: computes its three sample paths side by side, checks every chart is
  // drawn, moves the cursor over a contact graph and sees the tool marked on the path, downloads
  // the G-code of the second path, and highlights a bad flute count.
  async engagement() {
    await page.goto(`${base}/#engagement`);
    await page.click('#engagement-compute');
    await page.waitForSelector('#engagement-result[data-state="drawn"]', { timeout: 30000 });
    const columns = await page.$$eval('#engagement-result .candidate', (list) => list.length);
    const states = await page.$$eval('#engagement-result canvas', (list) => list.map((c) => c.dataset.state));
    if (states.some((s) => s !== 'drawn')) throw new Error(`charts not drawn: ${states}`);
    const contactGraph = '#engagement-result .candidate canvas[aria-label^="Contact position"]';
    const inked = await inkedPixels(contactGraph);
    if (inked < 2000) throw new Error(`contact graph nearly blank: ${inked} inked pixels`);
    const recommendation = await page.textContent('#engagement-result .recommendation');
    // A cursor on the contact graph marks the tool on the path.
    const box = await (await page.$(contactGraph)).boundingBox();
    const plan = '#engagement-result .candidate canvas.plan';
    const before = await inkedPixels(plan);
    await page.mouse.move(box.x + box.width * 0.45, box.y + box.height / 2);
    const cursor = Number(await page.getAttribute(plan, 'data-cursor'));
    const after = await inkedPixels(plan);
    const readout = await page.textContent('#engagement-result .cursor-readout');
    if (!Number.isInteger(cursor) || cursor <= 0) throw new Error(`no cursor on the path: ${cursor}`);
    if (after <= before) throw new Error(`tool circle not drawn: ${before} -> ${after} inked pixels`);
    if (!/s = [\d.]+ mm/.test(readout)) throw new Error(`no readout: ${readout}`);
    // The x axis switches to time; every chart is drawn again.
    await page.selectOption('#engagement-result select[aria-label="x axis"]', 'time');
    const redrawn = await page.$$eval('#engagement-result canvas', (list) => list.filter((c) => c.dataset.state === 'drawn').length);
    if (redrawn !== states.length) throw new Error(`after switching to time: ${redrawn} of ${states.length} charts drawn`);
    // G-code of the second path.
    await page.selectOption('select[name="candidate"]', '1');
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#engagement-gcode')]);
    const { readFile } = await import('node:fs/promises');
    const program = await readFile(await download.path(), 'utf8');
    const feeds = new Set([...program.matchAll(/ F(\d+(?:\.\d)?)/g)].map((m) => m[1]));
    if (!program.includes('M30') || feeds.size < 2) throw new Error(`program without its feed plan: ${program.slice(0, 400)}`);
    // A flute count out of range is refused with the field highlighted.
    await page.fill('input[name="flute_counts"]', '2, 40');
    await page.click('#engagement-compute');
    await page.waitForSelector('#engagement-messages .message.error', { timeout: 15000 });
    const highlighted = await page.$$eval('.invalid', (list) => list.map((e) => e.name));
    if (!highlighted.includes('flute_counts')) throw new Error(`field not highlighted: ${highlighted}`);
    return { columns, charts: states.length, inked, cursor, recommendation, feeds: feeds.size, file: download.suggestedFilename() };
  },

  // Predict page: runs the sample raster over the dome, checks the path coloured by error (several
  // colours), the colour scale, the histogram, the worst passes with NC lines, the download of the
  // corrected program, and a G-code error with its line.
  async predict() {
    await page.goto(`${base}/#predict`);
    await page.click('#predict-compute');
    await page.waitForSelector('#predict-plot[data-state="drawn"]', { timeout: 30000 });
    await page.waitForSelector('#predict-histogram[data-state="drawn"]', { timeout: 5000 });
    const segments = Number(await page.getAttribute('#predict-plot', 'data-segments'));
    const inked = await inkedPixels('#predict-plot');
    const histogram = await inkedPixels('#predict-histogram');
    const scale = await inkedPixels('#predict-result canvas.scale');
    const colours = await page.$eval('#predict-plot', (canvas) => {
      const data = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
      const seen = new Set();
      for (let i = 0; i < data.length; i += 4) {
        const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
        if (Math.max(r, g, b) - Math.min(r, g, b) > 60) seen.add(`${r >> 5},${g >> 5},${b >> 5}`);
      }
      return seen.size;
    });
    const lines = await page.$$eval('#predict-result table.worst tr[data-line]', (rows) => rows.map((r) => Number(r.dataset.line)));
    const summary = await page.textContent('#predict-result .summary');
    if (segments < 100) throw new Error(`only ${segments} segments drawn`);
    if (inked < 1000) throw new Error(`plot nearly blank: ${inked} inked pixels`);
    if (histogram < 500 || scale < 500) throw new Error(`histogram ${histogram}, scale ${scale} inked pixels`);
    if (colours < 4) throw new Error(`the path is not coloured by error: ${colours} colours`);
    if (lines.length < 10 || !lines.every((l) => l > 6)) throw new Error(`worst passes: ${lines}`);
    if (!/441 of 441 predicted/.test(summary)) throw new Error(`summary: ${summary}`);

    // The corrected program downloads with the input's lines.
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#predict-gcode')]);
    const program = await (await import('node:fs/promises')).readFile(await download.path(), 'utf8');
    if (!program.includes('M30') || !program.includes('O3100')) throw new Error(`corrected program: ${program.slice(0, 200)}`);

    // A G-code error names its line and marks the program.
    await page.fill('textarea[name="program"]', 'G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F500 Q1\nM30\n');
    await page.click('#predict-compute');
    await page.waitForSelector('#predict-messages .message.error', { timeout: 15000 });
    const error = await page.textContent('#predict-messages .message.error');
    if (!/line 3/.test(error)) throw new Error(`error without its line: ${error}`);
    const highlighted = await page.$$eval('.invalid', (list) => list.map((e) => e.name));
    if (!highlighted.includes('program')) throw new Error(`program not highlighted: ${highlighted}`);
    return { segments, inked, histogram, colours, worst: lines.length, programLines: program.split('\n').length };
  },

  // Uploads a job file on the Jobs page, waits for it to finish, opens it, and checks each
  // operation's plot.
  async jobs() {
    await page.goto(`${base}/#jobs`);
    const started = Date.now();
    await page.setInputFiles('#job-file', jobFile);
    await page.waitForSelector('#job-rows tr[data-status="done"]', { timeout: 60000 });
    const seconds = (Date.now() - started) / 1000;
    await page.click('#job-rows tr[data-status="done"] button');
    await page.waitForSelector('#job-result canvas[data-state="drawn"]', { timeout: 15000 });
    const plots = await page.$$eval('#job-result canvas', (list) => list.length);
    const inked = await inkedPixels('#job-result canvas');
    const downloads = await page.$$eval('#job-result button', (list) => list.map((b) => b.textContent));
    if (inked < 500) throw new Error(`job plot nearly blank: ${inked} inked pixels`);
    if (!downloads.includes('G-code') || !downloads.includes('JSON')) throw new Error(`downloads: ${downloads}`);
    return { plots, inked, seconds };
  },
};

try {
  const result = await scenarios[scenario]();
  if (screenshot) await page.screenshot({ path: screenshot, fullPage: true });
  if (problems.length) throw new Error(problems.join('; '));
  console.log(JSON.stringify({ ok: true, ...result }));
  await browser.close();
} catch (error) {
  if (screenshot) await page.screenshot({ path: screenshot, fullPage: true }).catch(() => {});
  console.log(JSON.stringify({ ok: false, error: String(error.message || error) }));
  await browser.close();
  process.exit(1);
}
