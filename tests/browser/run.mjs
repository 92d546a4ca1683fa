// Browser checks of the kerf page, driven by cargo test (tests/tests/api/browser.rs).
// Usage: node run.mjs <scenario> <base-url> <screenshot.png> [job-file [second-job-file]]
// Prints one JSON line with what it saw; exits non-zero with the reason when a check fails.
import { readFileSync } from 'node:fs';
import { chromium } from 'playwright-core';
import { boxStl, unitScenarios } from './units.mjs';

const [scenario, base, screenshot, jobFile, secondJobFile] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.KERF_CHROMIUM || '/usr/bin/chromium',
  // WebGL without a GPU: SwiftShader, which Chromium needs asked for by name.
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
const problems = [];
page.on('pageerror', (error) => problems.push(`page error: ${error.message}`));
// Nothing may leave the machine: every request goes to the service under test on 127.0.0.1
// (or is a data:/blob: URL the page makes itself).
const requested = [];
page.on('request', (request) => {
  requested.push(request.url());
  const url = new URL(request.url());
  if (!['data:', 'blob:'].includes(url.protocol) && url.hostname !== '127.0.0.1') problems.push(`request left 127.0.0.1: ${request.url()}`);
});
// Chromium logs every non-2xx fetch as a console error; the API's 4xx answers are expected here.
page.on('console', (m) => {
  if (m.type() === 'error' && !/status of 4\d\d/.test(m.text())) problems.push(`console error: ${m.text()}`);
});

// The RGBA pixels of a canvas, 2-D or WebGL (copied through a 2-D canvas), in the page.
const PIXELS = `(canvas) => {
  const copy = document.createElement('canvas');
  copy.width = canvas.width;
  copy.height = canvas.height;
  const g = copy.getContext('2d');
  g.drawImage(canvas, 0, 0);
  return g.getImageData(0, 0, copy.width, copy.height).data;
}`;

// Counts plot pixels that differ from the white background.
async function inkedPixels(selector) {
  return page.$eval(selector, (canvas, pixels) => {
    const data = eval(pixels)(canvas);
    let inked = 0;
    for (let i = 0; i < data.length; i += 4) {
      if (data[i] < 200 || data[i + 1] < 200 || data[i + 2] < 200) inked++;
    }
    return inked;
  }, PIXELS);
}

// Counts plot pixels within 40 of the colour [r, g, b].
async function colouredPixels(selector, colour) {
  return page.$eval(selector, (canvas, [[r, g, b], pixels]) => {
    const data = eval(pixels)(canvas);
    let found = 0;
    for (let i = 0; i < data.length; i += 4) {
      if (Math.abs(data[i] - r) + Math.abs(data[i + 1] - g) + Math.abs(data[i + 2] - b) < 40) found++;
    }
    return found;
  }, [colour, PIXELS]);
}

// The cut stock of a view whose model has no part (`id`: predict, engagement), seen from the top:
// drawn (inked), green where the program cut and said to be coloured so; playback to a quarter, a
// half or three quarters of the moves removes less than the whole program (the first that removes
// some, less than all, is reported; a program of one cutting move removes none before it).
async function partlessCut(id) {
  const scene = `#${id}-stock`;
  await page.waitForSelector(`${scene}[data-state="drawn"][data-stock-vertices]`, { timeout: 120000 });
  const stock = await page.$eval(scene, (e) => ({ ...e.dataset }));
  if (stock.colouring !== 'cut' || !(Number(stock.cutVertices) > 0)) throw new Error(`not coloured by what was cut: ${JSON.stringify(stock)}`);
  await page.click(`${scene} button:text("Top")`);
  const counts = await page.$eval(`${scene} canvas`, (canvas, pixels) => {
    const data = eval(pixels)(canvas);
    let green = 0;
    let inked = 0;
    for (let i = 0; i < data.length; i += 4) {
      const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
      if (r < 200 || g < 200 || b < 200) inked++;
      if (g > 60 && g - r > 40 && g - b > 40) green++;
    }
    return { green, inked };
  }, PIXELS);
  if (counts.inked < 20000) throw new Error(`the cut stock is nearly blank: ${counts.inked} inked pixels`);
  if (counts.green < 500) throw new Error(`what the program cut is not drawn green: ${counts.green} green pixels`);
  const full = Number(stock.removedVolume);
  if (!(full > 0)) throw new Error(`nothing cut: ${JSON.stringify(stock)}`);
  let played = null;
  for (const share of [0.25, 0.5, 0.75]) {
    const line = await page.$eval(`#${id}-position`, (slider, [id, share]) => {
      slider.value = String(Math.floor(Number(slider.max) * share));
      slider.dispatchEvent(new Event('input'));
      return /line (\d+)/.exec(document.querySelector(`#${id}-playback-readout`).textContent)[1];
    }, [id, share]);
    await page.waitForSelector(`${scene}[data-upto-line="${line}"]`, { timeout: 120000 });
    const partly = Number(await page.getAttribute(scene, 'data-removed-volume'));
    if (partly < full && !(played?.partly > 0)) played = { line: Number(line), partly };
    if (partly > 0 && partly < full) break;
  }
  if (!played) throw new Error(`playback to a quarter, half and three quarters of the moves cut all ${full} mm³`);
  const { line, partly } = played;
  const listed = await page.$$eval(`#${id}-listing li`, (l) => l.length);
  return { ...counts, removed: full, partly, line, listed, vertices: Number(stock.stockVertices) };
}

// Every file the page downloads, by name: a refused download must add none.
const downloads = [];
page.on('download', (file) => downloads.push(file.suggestedFilename()));

// Clicks a download button: the file's name and text.
async function downloaded(selector) {
  const [file] = await Promise.all([page.waitForEvent('download', { timeout: 60000 }), page.click(selector)]);
  return { name: file.suggestedFilename(), text: readFileSync(await file.path(), 'utf8') };
}

// Clicks a download button on a form the service (or the page) refuses: the error shown in
// `messages` (emptied first, so the error is this click's), and no file.
async function refusedDownload(selector, messages) {
  const before = downloads.length;
  await page.$eval(messages, (box) => box.replaceChildren());
  await page.click(selector);
  await page.waitForSelector(`${messages} .message.error`, { timeout: 60000 });
  if (downloads.length !== before) throw new Error(`${selector} downloaded ${downloads.slice(before)} for a refused form`);
  return page.textContent(`${messages} .message.error`);
}

// Submits a job file as another client would (from this process, not the page); answers its id.
async function submitElsewhere(text, type) {
  const response = await fetch(`${base}/api/v1/jobs`, { method: 'POST', headers: { 'content-type': type }, body: text });
  if (response.status !== 202) throw new Error(`the job was not queued: ${response.status} ${await response.text()}`);
  return (await response.json()).id;
}

const scenarios = {
  // Loads the page, submits the sample deburr job with the button, waits for the 3-D scene: the
  // tube, the hole and the tool are in it; the timeline moves the tool and marks the G-code line
  // it is on; a machine spaces the points by its block time; a bad value is reported under its
  // field with aria-invalid while the last good result stays, dimmed.
  async deburr() {
    const started = Date.now();
    await page.goto(`${base}/`);
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-plot[data-state="drawn"]', { timeout: 60000 });
    const firstPlot = (Date.now() - started) / 1000;
    const segments = Number(await page.getAttribute('#deburr-plot', 'data-segments'));
    const objects = (await page.getAttribute('#deburr-plot', 'data-objects')).split(' ');
    const inked = await inkedPixels('#deburr-plot canvas');
    const summary = await page.textContent('#deburr-result .summary');
    if (segments < 10) throw new Error(`only ${segments} segments drawn`);
    for (const name of ['tube', 'hole', 'ridge', 'centres', 'tool', 'grid']) {
      if (!objects.includes(name)) throw new Error(`the scene has no ${name}: ${objects}`);
    }
    if (inked < 5000) throw new Error(`scene nearly blank: ${inked} inked pixels`);
    if (!requested.some((u) => u.endsWith('/vendor/three/three.core.js'))) throw new Error('three.js was not loaded from /vendor');
    if (!/points\s*\d+/.test(summary)) throw new Error(`no summary: ${summary}`);

    // The timeline: a slider named "Timeline…"; arrow keys step it; the tool follows and the
    // listing marks the line of the move (the tool's ball centre is the programmed tip + radius).
    const slider = page.getByRole('slider', { name: /Timeline/ });
    await slider.focus();
    const toolBefore = await page.getAttribute('#deburr-plot', 'data-tool');
    for (let i = 0; i < 12; i++) await page.keyboard.press('ArrowRight');
    const step = Number(await slider.inputValue());
    const toolAfter = await page.getAttribute('#deburr-plot', 'data-tool');
    const current = await page.$$eval('#deburr-result .listing li[aria-current="true"]', (l) => l.map((e) => e.textContent));
    if (step !== 12) throw new Error(`arrow keys moved the timeline to ${step}`);
    if (current.length !== 1) throw new Error(`${current.length} current G-code lines`);
    if (toolAfter === toolBefore) throw new Error(`the tool did not move: ${toolAfter}`);
    const word = (letter) => Number(new RegExp(`${letter}(-?[\\d.]+)`).exec(current[0])?.[1]);
    const [tx, ty, tz] = toolAfter.split(' ').map(Number);
    const radius = 2;
    if ([Math.abs(tx - word('X')), Math.abs(ty - word('Y')), Math.abs(tz - radius - word('Z'))].some((d) => !(d < 1e-3))) {
      throw new Error(`tool at ${toolAfter} but the current line is ${current[0]}`);
    }

    // A machine registered through the API and chosen on the form spaces the points by its block
    // time: the summary reports the blocks and the machine.
    await page.evaluate(async (url) => {
      const body = JSON.stringify({ block_time_ms: 4, max_feed: 6000, dialect: 'linuxcnc' });
      const response = await fetch(url, { method: 'PUT', headers: { 'content-type': 'application/json' }, body });
      if (!response.ok) throw new Error(`machine not stored: ${response.status}`);
    }, `${base}/api/v1/machines/page-4ms`);
    await page.goto(`${base}/#/deburr`);
    await page.reload();
    await page.waitForSelector('#deburr-form select[name="machine"] option[value="page-4ms"]', { state: 'attached', timeout: 60000 });
    await page.selectOption('#deburr-form select[name="machine"]', 'page-4ms');
    await page.click('#deburr-compute');
    await page.waitForFunction(() => /page-4ms/.test(document.querySelector('#deburr-result .summary')?.textContent ?? ''), null, { timeout: 60000 });
    const withMachine = await page.textContent('#deburr-result .summary');
    if (!/blocks \(short\)\d+ \(0\)/.test(withMachine)) throw new Error(`no block figures: ${withMachine}`);

    // A path without a program (the ball cannot pass the hole to reach the inner edge): the
    // G-code button is off and the scene shows the approach and the tool in red.
    await page.selectOption('#deburr-form select[name="machine"]', '');
    await page.selectOption('#deburr-form select[name="edge"]', 'inner');
    await page.fill('#deburr-form input[name="ball_diameter"]', '10.4');
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-plot[data-refused="true"]', { timeout: 60000 });
    if (!(await page.isDisabled('#deburr-gcode'))) throw new Error('G-code button enabled without a program');
    // The ball's way down the hole runs through its wall: drawn red, and the reason is beside the button.
    const blocked = await page.getAttribute('#deburr-plot', 'data-collisions');
    const reason = await page.textContent('#deburr-gcode-note');
    if (!blocked.split(' ').includes('approach') || !/^G-code off: ./.test(reason)) throw new Error(`approach through the wall: ${blocked}, "${reason}"`);

    // On the inner edge a plain ball's shank (no neck) rubs the hole wall: red dots, a warning;
    // a lollipop with a thin neck clears it.
    await page.fill('#deburr-form input[name="ball_diameter"]', '4');
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-plot[data-refused="false"]', { timeout: 60000 });
    const shank = await page.getAttribute('#deburr-plot', 'data-collisions');
    const shankNote = await page.textContent('#deburr-result');
    if (shank !== 'neck' || !/shank .* meets the wall at \d+ of \d+ path points/.test(shankNote)) throw new Error(`shank on the inner edge: "${shank}"`);
    // Half way along the program (on the loop round the edge) the tool is red.
    const middle = async () => page.$eval('#deburr-result input[type="range"]', (slider) => {
      slider.value = String(Math.round(Number(slider.max) / 2));
      slider.dispatchEvent(new Event('input'));
    });
    await middle();
    if (await page.getAttribute('#deburr-plot', 'data-tool-hit') !== 'true') throw new Error('the shank in the wall is not drawn red');
    await page.evaluate(async () => {
      const body = JSON.stringify({ kind: 'ball', radius: 2, neck_radius: 1, flutes: 2, name: 'lollipop' });
      const response = await fetch('/api/v1/tools/41', { method: 'PUT', headers: { 'content-type': 'application/json' }, body });
      if (!response.ok) throw new Error(`tool not stored: ${response.status}`);
    });
    await page.reload();
    await page.waitForSelector('#deburr-form select[name="tool_choice"] option[value="41"]', { state: 'attached', timeout: 60000 });
    await page.selectOption('#deburr-form select[name="tool_choice"]', '41');
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-result:not(.stale) #deburr-plot[data-collisions=""]', { timeout: 60000 });
    if (await page.isDisabled('#deburr-gcode')) throw new Error('G-code button off for a lollipop that clears the wall');
    await middle();
    if (await page.getAttribute('#deburr-plot', 'data-tool-hit') !== 'false') throw new Error('the lollipop is drawn red');
    await page.selectOption('#deburr-form select[name="tool_choice"]', 'inline');
    await page.selectOption('#deburr-form select[name="edge"]', 'outer');
    await page.fill('#deburr-form input[name="ball_diameter"]', '4');
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-plot[data-refused="false"]', { timeout: 60000 });
    if (await page.isDisabled('#deburr-gcode')) throw new Error('G-code button still off');
    // The G-code download: named after the dialect (none chosen, no machine: Fanuc), a Fanuc
    // program from its first lines to M30.
    const deburrProgram = await downloaded('#deburr-gcode');
    const deburrLines = deburrProgram.text.split('\n').slice(0, 2).join(' | ');
    if (deburrProgram.name !== 'deburr-fanuc.nc' || deburrLines !== '% | O1000 (KERF DEBURR)' || !/^M30$/m.test(deburrProgram.text)) {
      throw new Error(`deburr download ${deburrProgram.name}: ${deburrProgram.text.slice(0, 300)}`);
    }

    // Both edges in one request, the bore edge with the lollipop: both loops drawn, the summary
    // counts them and the one tool change, and the program changes tools once.
    await page.selectOption('#deburr-form select[name="edge"]', 'both');
    await page.selectOption('#deburr-form select[name="inner_tool_choice"]', '41');
    await page.click('#deburr-compute');
    await page.waitForFunction(() => /loops \(holes × edges\)\s*2/.test(document.querySelector('#deburr-result:not(.stale) .summary')?.textContent ?? ''), null, { timeout: 60000 });
    const bothObjects = (await page.getAttribute('#deburr-plot', 'data-objects')).split(' ');
    const bothSummary = await page.textContent('#deburr-result .summary');
    if (!bothObjects.includes('centres-1')) throw new Error(`the bore loop is not drawn: ${bothObjects}`);
    if (!/tool changes\s*1/.test(bothSummary)) throw new Error(`no tool change in the summary: ${bothSummary}`);
    const bothProgram = await page.evaluate(async () => (await fetch('/api/v1/deburr?format=gcode', {
      method: 'POST', headers: { 'content-type': 'application/json' },
      body: JSON.stringify({ tool: { kind: 'ball', radius: 2 }, inner_tool: 41, edge: 'both', cut_amount: 0.2,
        workpiece: { kind: 'tube', origin: [0, 0, 0], inner_radius: 15, outer_radius: 25 }, hole: { shape: 'round', radius: 5 } }),
    })).text());
    if ((bothProgram.match(/M06/g) || []).length !== 1 || !/M00/.test(bothProgram)) throw new Error(`both edges program: ${bothProgram.slice(0, 400)}`);
    await page.selectOption('#deburr-form select[name="edge"]', 'outer');

    // A bad value: its message under the field, aria-invalid, aria-describedby naming the message,
    // focus on the field, the last result still there but dimmed.
    await page.fill('input[name="hole_size"]', '-1');
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-form [aria-invalid="true"]', { timeout: 60000 });
    const bad = await page.$eval('#deburr-form [aria-invalid="true"]', (e) => {
      const note = document.getElementById(e.getAttribute('aria-describedby'));
      const field = e.getBoundingClientRect();
      const under = note?.getBoundingClientRect();
      return { name: e.name, note: note?.textContent, below: under ? under.top >= field.bottom - 1 : false, focused: document.activeElement === e };
    });
    if (bad.name !== 'hole_size' || !bad.note || !bad.below || !bad.focused) throw new Error(`field error: ${JSON.stringify(bad)}`);
    const kept = await page.$$eval('#deburr-result.stale #deburr-plot', (l) => l.length);
    if (kept !== 1) throw new Error('the last good result was not kept dimmed');
    // The G-code button with the bad value: the service's refusal at the field, no file.
    const deburrRefused = await refusedDownload('#deburr-gcode', '#deburr-messages');
    const refusedMarks = await page.$$eval('#deburr-form [aria-invalid="true"]', (l) => l.map((e) => e.name));
    if (!/marked field/.test(deburrRefused) || refusedMarks.join() !== 'hole_size') throw new Error(`deburr download refused: "${deburrRefused}", ${refusedMarks}`);
    return { segments, inked, objects, firstPlot, note: bad.note, program: deburrLines };
  },

  // The workbench: routes with Back, state kept across a view switch and a reload, a machine's
  // values honoured by Segment (the request leaves them out; an override is sent and named), and
  // no sideways scrolling at three window sizes.
  async workbench() {
    await page.goto(`${base}/#/segment`);
    await page.evaluate(async () => {
      const body = JSON.stringify({ block_time_ms: 2, max_feed: 15000, dialect: 'fanuc' });
      const response = await fetch('/api/v1/machines/fast-2ms', { method: 'PUT', headers: { 'content-type': 'application/json' }, body });
      if (!response.ok) throw new Error(`machine not stored: ${response.status}`);
    });
    await page.reload();
    await page.waitForSelector('#segment-form select[name="machine"] option[value="fast-2ms"]', { state: 'attached', timeout: 60000 });
    await page.selectOption('#segment-form select[name="machine"]', 'fast-2ms');
    const placeholder = await page.getAttribute('#segment-form input[name="block_time_ms"]', 'placeholder');
    let [request] = await Promise.all([page.waitForRequest((r) => r.url().endsWith('/api/v1/segment')), page.click('#segment-compute')]);
    let body = request.postDataJSON();
    const sent = ['feed', 'block_time_ms', 'margin', 'min_chord_error'].filter((k) => k in body);
    if (sent.length || body.machine !== 'fast-2ms') throw new Error(`the request overrides the machine: ${JSON.stringify(body)}`);
    await page.waitForSelector('#segment-plot[data-state="drawn"]', { timeout: 60000 });
    let summary = await page.textContent('#segment-result .summary');
    if (!/block time2 ms \(machine\)/.test(summary) || !/15000 mm\/min \(machine\)/.test(summary)) throw new Error(`machine values not used: ${summary}`);
    await page.fill('#segment-form input[name="block_time_ms"]', '4');
    [request] = await Promise.all([page.waitForRequest((r) => r.url().endsWith('/api/v1/segment')), page.click('#segment-compute')]);
    body = request.postDataJSON();
    if (body.block_time_ms !== 4 || 'feed' in body) throw new Error(`override: ${JSON.stringify(body)}`);
    await page.waitForFunction(() => /overridden/.test(document.querySelector('#segment-result .summary')?.textContent ?? ''), null, { timeout: 60000 });
    summary = await page.textContent('#segment-result .summary');
    if (!/block time4 ms \(machine: 2 ms, overridden\)/.test(summary)) throw new Error(`override not named: ${summary}`);

    // Another view and Back: the form and the result are still there.
    await page.click('#tabs a[data-view="contour"]');
    await page.waitForSelector('#contour-form', { state: 'visible' });
    if (!page.url().endsWith('#/contour')) throw new Error(`route: ${page.url()}`);
    await page.goBack();
    await page.waitForSelector('#segment-form', { state: 'visible' });
    const afterSwitch = await page.inputValue('#segment-form input[name="block_time_ms"]');
    const plotAfterSwitch = await page.$$eval('#segment-plot[data-state="drawn"]', (l) => l.length);
    if (afterSwitch !== '4' || plotAfterSwitch !== 1) throw new Error(`after switching back: ${afterSwitch}, ${plotAfterSwitch} plot`);

    // A reload: the same form (machine, override) and the result again.
    await page.reload();
    await page.waitForSelector('#segment-plot[data-state="drawn"]', { timeout: 60000 });
    const machine = await page.inputValue('#segment-form select[name="machine"]');
    const blockTime = await page.inputValue('#segment-form input[name="block_time_ms"]');
    summary = await page.textContent('#segment-result .summary');
    if (machine !== 'fast-2ms' || blockTime !== '4' || !/overridden/.test(summary)) throw new Error(`after reload: ${machine}, ${blockTime}, ${summary}`);

    // Load example puts the sample back.
    await page.click('#segment-form button:has-text("Load example")');
    if (await page.inputValue('#segment-form input[name="block_time_ms"]') !== '4' || await page.inputValue('#segment-form select[name="machine"]') !== '') {
      throw new Error('load example did not restore the sample');
    }

    // Tools: save one by diameter, edit it, delete it only after confirming.
    await page.click('#tabs a[data-view="tools"]');
    await page.fill('#tool-form input[name="number"]', '12');
    await page.fill('#tool-form input[name="size"]', '8');
    await page.fill('#tool-form input[name="neck_radius"]', '2.5');
    await page.fill('#tool-form input[name="flute_length"]', '20');
    await page.click('#tool-save');
    await page.waitForSelector('#tool-rows tr[data-tool="12"]', { timeout: 60000 });
    const stored = await page.evaluate(async () => (await (await fetch('/api/v1/tools/12')).json()));
    if (stored.radius !== 4 || stored.neck_radius !== 2.5 || stored.flute_length !== 20) throw new Error(`tool by diameter: ${JSON.stringify(stored)}`);
    const extras = await page.textContent('#tool-rows tr[data-tool="12"]');
    if (!extras.includes('flutes 20 long')) throw new Error(`flute length not listed: ${extras}`);
    await page.click('#tool-rows tr[data-tool="12"] button:has-text("Edit")');
    if (await page.inputValue('#tool-form input[name="size"]') !== '8') throw new Error('edit did not fill the form');
    if (await page.inputValue('#tool-form input[name="flute_length"]') !== '20') throw new Error('edit did not fill the flute length');
    // A flat end mill that does not cut at its centre, with its own plunge feed.
    await page.selectOption('#tool-form select[name="kind"]', 'flat');
    await page.fill('#tool-form input[name="plunge_feed"]', '250');
    await page.selectOption('#tool-form select[name="centre_cutting"]', 'false');
    await page.click('#tool-save');
    await page.waitForSelector('#tool-rows tr[data-tool="12"] td:text-is("flat")', { timeout: 60000 });
    const flat = await page.evaluate(async () => (await (await fetch('/api/v1/tools/12')).json()));
    if (flat.plunge_feed !== 250 || flat.centre_cutting !== false) throw new Error(`entries of the tool: ${JSON.stringify(flat)}`);
    await page.click('#tool-rows tr[data-tool="12"] button:has-text("Edit")');
    if (await page.inputValue('#tool-form select[name="centre_cutting"]') !== 'false') throw new Error('edit did not fill centre cutting');
    await page.click('#tool-rows tr[data-tool="12"] button:has-text("Delete")');
    if (!(await page.$('#tool-rows tr[data-tool="12"]'))) throw new Error('deleted without asking');
    await page.click('#tool-rows tr[data-tool="12"] button:has-text("Yes, delete")');
    await page.waitForSelector('#tool-rows tr[data-tool="12"]', { state: 'detached', timeout: 60000 });

    // No sideways scrolling, with the deburr scene drawn, at three sizes.
    await page.goto(`${base}/#/deburr`);
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-plot[data-state="drawn"]', { timeout: 60000 });
    const widths = {};
    for (const [width, height] of [[1440, 900], [1280, 720], [390, 844]]) {
      await page.setViewportSize({ width, height });
      await page.waitForTimeout(200);
      const overflow = await page.evaluate(() => document.documentElement.scrollWidth - document.documentElement.clientWidth);
      widths[`${width}x${height}`] = overflow;
      if (screenshot) await page.screenshot({ path: screenshot.replace(/\.png$/, `-${width}.png`), fullPage: false });
      if (overflow > 0) throw new Error(`sideways scrolling at ${width}×${height}: ${overflow} px`);
    }
    // At phone width, the views with wide tables too (contour's corners, the jobs list).
    await page.click('#tabs a[data-view="contour"]');
    await page.click('#contour-compute');
    await page.waitForSelector('#contour-result:not(.stale) #contour-plot[data-state="drawn"]', { timeout: 60000 });
    for (const view of ['contour', 'jobs', 'tools', 'machines', 'engagement', 'predict', 'segment']) {
      await page.click(`#tabs a[data-view="${view}"]`);
      await page.waitForTimeout(100);
      const overflow = await page.evaluate(() => document.documentElement.scrollWidth - document.documentElement.clientWidth);
      if (overflow > 0) throw new Error(`sideways scrolling on ${view} at 390 px: ${overflow} px`);
    }
    return { overflow: widths, placeholder };
  },

  // The Segment view with its sample (the patent's R50 circle at 10 m/min, 4 ms): plan, charts,
  // the comparison with a fixed 0.01 mm, a bad value highlighted, a machine registered on the
  // Machines view and used, the G-code downloaded, the machine deleted.
  async segment() {
    await page.goto(`${base}/#segment`);
    // The per-window mode of the patent (the page's default is the guarantee mode).
    await page.selectOption('#segment-form select[name="mode"]', 'window');
    await page.click('#segment-compute');
    await page.waitForSelector('#segment-plot[data-state="drawn"]', { timeout: 60000 });
    await page.waitForSelector('#segment-chart[data-state="drawn"]', { timeout: 60000 });
    await page.waitForSelector('#segment-lengths[data-state="drawn"]', { timeout: 60000 });
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
    // Segment has no stock to cut: the page says so rather than drawing nothing.
    const noStock = await page.textContent('#segment-result .no-stock');
    if (!/No cut stock/.test(noStock)) throw new Error(`no word on the missing cut stock: ${noStock}`);

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
    if (file.suggestedFilename() !== 'segment-fanuc.nc') throw new Error(`segment download named ${file.suggestedFilename()}`);

    // A bad value is reported with the field highlighted.
    await page.fill('input[name="feed"]', '-1');
    await page.click('#segment-compute');
    await page.waitForSelector('#segment-messages .message.error', { timeout: 60000 });
    const highlighted = await page.$$eval('.invalid', (list) => list.map((e) => e.name));
    if (!highlighted.includes('feed')) throw new Error(`field not highlighted: ${highlighted}`);

    // Register a machine, then cut the curve with its values.
    await page.click('#tabs a[data-view="machines"]');
    await page.fill('#machine-form input[name="name"]', 'hsc-page');
    await page.fill('#machine-form input[name="max_feed"]', '12000');
    await page.fill('#machine-form input[name="margin"]', '1.1');
    await page.selectOption('#machine-form select[name="dialect"]', 'linuxcnc');
    await page.click('#machine-save');
    await page.waitForSelector('#machine-rows tr[data-machine="hsc-page"]', { timeout: 60000 });
    await page.click('#tabs a[data-view="segment"]');
    await page.waitForSelector('#segment-form select[name="machine"] option[value="hsc-page"]', { state: 'attached', timeout: 60000 });
    await page.selectOption('#segment-form select[name="machine"]', 'hsc-page');
    for (const name of ['feed', 'block_time_ms', 'margin', 'min_chord_error']) await page.fill(`#segment-form input[name="${name}"]`, '');
    await page.click('#segment-compute');
    // The earlier result stays on the page: wait for the one that names the machine.
    await page.waitForFunction(() => /hsc-page/.test(document.querySelector('#segment-result .summary')?.textContent ?? ''), null, { timeout: 60000 });
    const withMachine = await page.textContent('#segment-result .summary');
    if (!/hsc-page/.test(withMachine) || !/12000 mm\/min/.test(withMachine)) throw new Error(`machine not used: ${withMachine}`);
    const machineBlocks = Number(await page.getAttribute('#segment-plot', 'data-segments'));
    // With the machine chosen and no dialect, the program is in the machine's and named after it.
    const machineProgram = await downloaded('#segment-gcode');
    if (machineProgram.name !== 'segment-hsc-page.nc' || !machineProgram.text.includes('M30')) throw new Error(`segment download with a machine ${machineProgram.name}: ${machineProgram.text.slice(0, 300)}`);

    // A machine registered through the API with motion and spindle values, edited on the page
    // (its margin), keeps every value it had.
    const full = { block_time_ms: 2, max_feed: 15000, dialect: 'fanuc', mode: 'guarantee', arcs: 'g2g3', plunge_feed: 300, max_accel: 2000, rapid_feed: 30000, tool_change_s: 4, spindle_power_kw: 5.5, spindle_torque_nm: 30 };
    await page.evaluate(async ([url, machine]) => {
      const response = await fetch(url, { method: 'PUT', headers: { 'content-type': 'application/json' }, body: JSON.stringify(machine) });
      if (!response.ok) throw new Error(`machine not stored: ${response.status}`);
    }, [`${base}/api/v1/machines/api-full`, full]);
    await page.click('#tabs a[data-view="machines"]');
    // The stored version Edit asks for (its ETag) arrives only after Save is clicked, as from a
    // busy service: the save waits for it and replaces that version rather than finding a
    // machine of that name "already exists".
    const apiFull = `${base}/api/v1/machines/api-full`;
    let releaseVersion;
    const versionHeld = new Promise((resolve) => { releaseVersion = resolve; });
    const holdVersion = async (route) => {
      if (route.request().method() === 'GET') await versionHeld;
      await route.continue();
    };
    await page.route(apiFull, holdVersion);
    const versionAsked = page.waitForRequest((r) => r.url() === apiFull && r.method() === 'GET', { timeout: 60000 });
    await page.click('#machine-rows tr[data-machine="api-full"] button:has-text("Edit")');
    if (await page.inputValue('#machine-form input[name="spindle_power_kw"]') !== '5.5') throw new Error('Edit did not fill the spindle power');
    await page.fill('#machine-form input[name="margin"]', '1.2');
    await versionAsked;
    // The rows as they are before the save, which lists the machines again.
    await page.$$eval('#machine-rows tr', (rows) => rows.forEach((row) => { row.dataset.old = 'yes'; }));
    await page.click('#machine-save');
    releaseVersion();
    // The message of hsc-page's save is still there: wait for the one naming this machine.
    await page.waitForFunction(() => /Machine api-full saved/.test(document.querySelector('#machine-messages .message.ok')?.textContent ?? ''), null, { timeout: 60000 });
    await page.unroute(apiFull, holdVersion);
    const edited = await page.evaluate(async (url) => (await fetch(url)).json(), `${base}/api/v1/machines/api-full`);
    for (const [key, expected] of Object.entries({ ...full, margin: 1.2 })) {
      if (edited[key] !== expected) throw new Error(`editing on the page changed ${key}: ${JSON.stringify(edited)}`);
    }
    await page.evaluate(async (url) => { await fetch(url, { method: 'DELETE' }); }, `${base}/api/v1/machines/api-full`);

    // Delete it again, in the rows listed after the save (a list arriving between Delete and
    // its confirmation would put back the row unasked).
    await page.click('#tabs a[data-view="machines"]');
    await page.waitForSelector('#machine-rows tr[data-machine="hsc-page"]:not([data-old])', { timeout: 60000 });
    await page.click('#machine-rows tr[data-machine="hsc-page"] button:has-text("Delete")');
    await page.click('#machine-rows tr[data-machine="hsc-page"] button:has-text("Yes, delete")');
    await page.waitForSelector('#machine-rows tr[data-machine="hsc-page"]', { state: 'detached', timeout: 60000 });
    return { segments, inked, chartInked, lengthsInked, machineBlocks };
  },

  // Computes the sample contour, checks the plot (loops and reliefs in their colours), the
  // corner table and the layer selector, downloads the G-code, and reports bad input on the
  // right field.
  async contour() {
    await page.goto(`${base}/#contour`);
    await page.click('#contour-compute');
    await page.waitForSelector('#contour-plot[data-state="drawn"]', { timeout: 60000 });
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
    await page.waitForSelector('#contour-plot[data-layer="2"][data-state="drawn"]', { timeout: 60000 });
    await page.click('#contour-result table.corners tbody tr[data-corner="3"]');
    const zoomed = Number(await page.getAttribute('#contour-plot', 'data-scale'));
    const zoomedLoop = await colouredPixels('#contour-plot', [224, 112, 0]);
    if (zoomed < 2 * fitted || zoomedLoop < 500) throw new Error(`zoom to the tip: scale ${fitted} → ${zoomed}, loop ${zoomedLoop} px`);

    // The G-code download.
    await page.selectOption('#contour-form select[name="dialect"]', 'linuxcnc');
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#contour-gcode')]);
    const program = readFileSync(await download.path(), 'utf8');
    if (!program.includes('G64 P') || !program.trim().endsWith('M30')) throw new Error(`program: ${program.slice(0, 200)}`);
    if (download.suggestedFilename() !== 'contour-linuxcnc.nc') throw new Error(`contour download named ${download.suggestedFilename()}`);

    // A bad step is reported on its field; a crossing contour on the points box; a line that is
    // not "x, y" before anything is sent.
    await page.fill('#contour-form input[name="step"]', '0');
    await page.click('#contour-compute');
    await page.waitForSelector('#contour-messages .message.error', { timeout: 60000 });
    const invalidStep = await page.$$eval('#contour-form .invalid', (l) => l.map((e) => e.name));
    if (!invalidStep.includes('step')) throw new Error(`step not highlighted: ${invalidStep}`);
    await page.fill('#contour-form input[name="step"]', '3');
    await page.fill('#contour-form textarea[name="points"]', '0, 0\n10, 10\n10, 0\n0, 10');
    await page.click('#contour-compute');
    await page.waitForFunction(() => /E_SELF_INTERSECTION/.test(document.querySelector('#contour-messages .message.error')?.title ?? ''), null, { timeout: 60000 });
    const invalidPoints = await page.$$eval('#contour-form .invalid', (l) => l.map((e) => e.name));
    if (!invalidPoints.includes('points')) throw new Error(`points not highlighted: ${invalidPoints}`);
    await page.fill('#contour-form textarea[name="points"]', '0, 0\n10 0 5\n10, 10');
    await page.click('#contour-compute');
    const local = await page.textContent('#contour-messages');
    if (!/line 2/i.test(local)) throw new Error(`local check: ${local}`);
    const contourRefused = await refusedDownload('#contour-gcode', '#contour-messages');
    const contourMarks = await page.$$eval('#contour-form .invalid', (l) => l.map((e) => e.name));
    if (!/line 2/i.test(contourRefused) || !contourMarks.includes('points')) throw new Error(`contour download refused: "${contourRefused}", ${contourMarks}`);
    // Every layer in 3-D, and the timeline moves the tool there too. The program comes slowly
    // (as on a busy machine): the old plot stays dimmed until the new one replaces it.
    const slowProgram = async (route) => { await new Promise((r) => setTimeout(r, 1500)); await route.continue(); };
    await page.route('**/api/v1/contour?format=gcode*', slowProgram);
    await page.$eval('#contour-plot', (plot) => { plot.dataset.old = 'yes'; });
    await page.fill('#contour-form input[name="points"], #contour-form textarea[name="points"]', '0, 10\n40, 10\n40, 0\n80, 25\n40, 50\n40, 40\n0, 40');
    await page.click('#contour-compute');
    await page.waitForSelector('#contour-result:not(.stale) #contour-plot[data-state="drawn"]', { timeout: 60000 });
    await page.unroute('**/api/v1/contour?format=gcode*', slowProgram);
    if (await page.$('#contour-plot[data-old]')) throw new Error('the old plot was undimmed before the new one came');
    await page.selectOption('#contour-result select[aria-label="View"]', '3d');
    await page.waitForSelector('#contour-plot-3d[data-state="drawn"]', { timeout: 60000 });
    const objects = (await page.getAttribute('#contour-plot-3d', 'data-objects')).split(' ');
    if (!['part', 'cut', 'loop', 'tool'].every((o) => objects.includes(o))) throw new Error(`3-D contour: ${objects}`);
    const slider = page.getByRole('slider', { name: /Timeline/ });
    await slider.focus();
    for (let i = 0; i < 30; i++) await page.keyboard.press('ArrowRight');
    const tool3d = await page.getAttribute('#contour-plot-3d', 'data-tool');
    if (!tool3d) throw new Error('no tool in the 3-D contour');
    return { segments, inked, loopPixels, reliefPixels, zoomed: zoomed / fitted, objects };
  },

  // The Engagement view: computes its three sample paths (one shown at a time, the others not
  // drawn), checks every chart of the shown one is drawn, among them spindle torque and power
  // from the form's Kienzle values, moves the cursor over a contact graph and sees the tool
  // marked on the path, downloads the G-code of the second path, and highlights a bad flute count.
  async engagement() {
    await page.goto(`${base}/#engagement`);
    const [request] = await Promise.all([page.waitForRequest((r) => r.url().endsWith('/api/v1/engagement')), page.click('#engagement-compute')]);
    const sent = request.postDataJSON();
    if (sent.kienzle?.kc11 !== 1800 || sent.kienzle?.mc !== 0.25 || sent.axial_depth !== 2) throw new Error(`no Kienzle values sent: ${JSON.stringify(sent.kienzle)}`);
    if (sent.candidate !== 0) throw new Error(`the path chosen for G-code is not the one verified: candidate ${sent.candidate}`);
    await page.waitForSelector('#engagement-result[data-state="drawn"]', { timeout: 30000 });
    const columns = await page.$$eval('#engagement-result [role="tabpanel"]', (list) => list.length);
    const shown = '#engagement-result .candidate:not([hidden])';
    await page.waitForFunction((selector) => [...document.querySelectorAll(`${selector} canvas`)].every((c) => c.dataset.state === 'drawn'), shown, { timeout: 30000 });
    const states = await page.$$eval(`${shown} canvas`, (list) => list.map((c) => c.dataset.state));
    const hiddenCharts = await page.$$eval('#engagement-result .candidate[hidden] canvas', (list) => list.length);
    if (hiddenCharts !== 0) throw new Error(`${hiddenCharts} charts drawn for paths not shown`);
    // The answer's own verification: its findings (or none) and why no cut stock is drawn.
    const verification = await page.textContent('#engagement-verification', { timeout: 30000 });
    const firstName = await page.$eval('#engagement-result .candidate:not([hidden])', (e) => e.querySelector('h3').textContent);
    const verifiedTitle = await page.textContent('#engagement-verification h3');
    if (!verifiedTitle.includes(`the program of ${firstName}`)) throw new Error(`verification of which path: "${verifiedTitle}" (shown: ${firstName})`);
    // Torque and power over the path (power on the right axis) and per flute count in the table.
    const torqueChart = `${shown} canvas[aria-label^="Spindle torque and power"]`;
    const torqueInked = await inkedPixels(torqueChart);
    if (torqueInked < 2000) throw new Error(`torque chart nearly blank: ${torqueInked}`);
    const head = await page.textContent(`${shown} table.flutes thead`);
    if (!/torque mean \/ peak, N·m/.test(head) || !/power mean \/ peak, kW/.test(head)) throw new Error(`flute table: ${head}`);
    const torqueCells = await page.$$eval(`${shown} table.flutes tbody tr td:nth-child(10)`, (l) => l.map((e) => e.textContent));
    if (!torqueCells.length || !torqueCells.every((t) => /^\d+\.\d\d \/ \d+\.\d\d$/.test(t))) throw new Error(`torque cells: ${torqueCells}`);
    const contactGraph = `${shown} canvas[aria-label^="Contact position"]`;
    const inked = await inkedPixels(contactGraph);
    if (inked < 2000) throw new Error(`contact graph nearly blank: ${inked} inked pixels`);
    const recommendation = await page.textContent('#engagement-result .recommendation');
    // A cursor on the contact graph marks the tool on the path.
    await page.locator(contactGraph).first().scrollIntoViewIfNeeded();
    const box = await (await page.$(contactGraph)).boundingBox();
    const plan = `${shown} canvas.plan`;
    const before = await inkedPixels(plan);
    await page.mouse.move(box.x + box.width * 0.45, box.y + box.height / 2);
    const cursor = Number(await page.getAttribute(plan, 'data-cursor'));
    const after = await inkedPixels(plan);
    const readout = await page.textContent('#engagement-result .cursor-readout');
    if (!Number.isInteger(cursor) || cursor <= 0) throw new Error(`no cursor on the path: ${cursor}`);
    if (after <= before) throw new Error(`tool circle not drawn: ${before} -> ${after} inked pixels`);
    if (!/s = [\d.]+ mm/.test(readout) || !/torque [\d.]+ N·m, power [\d.]+ kW/.test(readout)) throw new Error(`no readout: ${readout}`);
    // The timeline slider moves the same cursor from the keyboard.
    const timeline = page.getByRole('slider', { name: /Timeline along straight/ });
    await timeline.focus();
    await page.keyboard.press('Home');
    for (let i = 0; i < 50; i++) await page.keyboard.press('ArrowRight');
    const stepped = Number(await page.getAttribute(plan, 'data-cursor'));
    if (stepped !== 50) throw new Error(`timeline moved the cursor to ${stepped}`);
    // The x axis switches to time; every chart is drawn again.
    await page.selectOption('#engagement-result select[aria-label="x axis"]', 'time');
    const redrawn = await page.$$eval(`${shown} canvas`, (list) => list.filter((c) => c.dataset.state === 'drawn').length);
    if (redrawn !== states.length) throw new Error(`after switching to time: ${redrawn} of ${states.length} charts drawn`);
    // The second path's tab draws its charts, leaves the first undrawn, and is the G-code choice.
    await page.click('#engagement-result [role="tab"]:nth-child(2)');
    await page.waitForFunction((selector) => {
      const list = [...document.querySelectorAll(`${selector} canvas`)];
      return list.length > 0 && list.every((c) => c.dataset.state === 'drawn');
    }, shown, { timeout: 30000 });
    const second = await page.$eval(shown, (e) => e.querySelector('h3').textContent);
    const leftDrawn = await page.$$eval('#engagement-result .candidate[hidden] canvas', (list) => list.length);
    if (second !== 'two bends' || leftDrawn !== 0) throw new Error(`second tab: ${second}, ${leftDrawn} charts left drawn`);
    if (await page.inputValue('select[name="candidate"]') !== '1') throw new Error('the G-code choice did not follow the tab');
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#engagement-gcode')]);
    const { readFile } = await import('node:fs/promises');
    const program = await readFile(await download.path(), 'utf8');
    const feeds = new Set([...program.matchAll(/ F(\d+(?:\.\d)?)/g)].map((m) => m[1]));
    if (!program.includes('M30') || feeds.size < 2) throw new Error(`program without its feed plan: ${program.slice(0, 400)}`);
    // Computed again with the second path chosen: that path's program is the one verified, named
    // so, and its tab is shown first.
    const [again1] = await Promise.all([page.waitForRequest((r) => r.url().endsWith('/api/v1/engagement')), page.click('#engagement-compute')]);
    if (again1.postDataJSON().candidate !== 1) throw new Error(`second path chosen, candidate ${again1.postDataJSON().candidate} sent`);
    await page.waitForFunction(() => /the program of two bends/.test(document.querySelector('#engagement-verification h3')?.textContent ?? ''), null, { timeout: 30000 });
    const shownAgain = await page.$eval(shown, (e) => e.querySelector('h3').textContent);
    if (shownAgain !== 'two bends' || await page.inputValue('select[name="candidate"]') !== '1') throw new Error(`after computing again: ${shownAgain} shown`);
    // A flute count out of range is refused with the field highlighted.
    const fluteCounts = await page.inputValue('input[name="flute_counts"]');
    await page.fill('input[name="flute_counts"]', '2, 40');
    await page.click('#engagement-compute');
    await page.waitForSelector('#engagement-messages .message.error', { timeout: 60000 });
    const highlighted = await page.$$eval('.invalid', (list) => list.map((e) => e.name));
    if (!highlighted.includes('flute_counts')) throw new Error(`field not highlighted: ${highlighted}`);
    const engagementRefused = await refusedDownload('#engagement-gcode', '#engagement-messages');
    const refusedMarks = await page.$$eval('#engagement-form .invalid', (list) => list.map((e) => e.name));
    if (!refusedMarks.includes('flute_counts')) throw new Error(`download refused without the field marked: "${engagementRefused}", ${refusedMarks}`);
    await page.fill('input[name="flute_counts"]', fluteCounts);
    const again = await downloaded('#engagement-gcode');
    const left = await page.$$eval('#engagement-messages > *', (list) => list.length);
    const marksLeft = await page.$$eval('#engagement-form .invalid', (list) => list.length);
    if (again.name !== 'engagement-1-fanuc.nc' || !again.text.includes('M30') || left || marksLeft) throw new Error(`download after the fix: ${again.name}, ${left} messages, ${marksLeft} marks left`);
    return { columns, charts: states.length, torqueInked, inked, cursor, recommendation, feeds: feeds.size, file: download.suggestedFilename(), verification };
  },

  // Predict page: runs the sample raster over the dome, checks the path coloured by error (several
  // colours), the colour scale, the histogram, the worst passes with NC lines, the download of the
  // corrected program, and a G-code error with its line.
  async predict() {
    await page.goto(`${base}/#predict`);
    // The inline ball is entered by diameter (Ø6) and sent as the radius the API takes.
    const [request] = await Promise.all([page.waitForRequest((r) => r.url().includes('/api/v1/predict')), page.click('#predict-compute')]);
    const radius = request.postDataJSON().tool.radius;
    if (radius !== 3) throw new Error(`Ø6 sent as radius ${radius}`);
    await page.waitForSelector('#predict-plot[data-state="drawn"]', { timeout: 30000 });
    await page.waitForSelector('#predict-histogram[data-state="drawn"]', { timeout: 60000 });
    const verification = await page.textContent('#predict-verification', { timeout: 30000 });
    const segments = Number(await page.getAttribute('#predict-plot', 'data-segments'));
    const inked = await inkedPixels('#predict-plot canvas');
    const histogram = await inkedPixels('#predict-histogram');
    const scale = await inkedPixels('#predict-result canvas.scale');
    const colours = await page.$eval('#predict-plot canvas', (canvas, pixels) => {
      const data = eval(pixels)(canvas);
      const seen = new Set();
      for (let i = 0; i < data.length; i += 4) {
        const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
        if (Math.max(r, g, b) - Math.min(r, g, b) > 60) seen.add(`${r >> 5},${g >> 5},${b >> 5}`);
      }
      return seen.size;
    }, PIXELS);
    const lines = await page.$$eval('#predict-result table.worst tr[data-line]', (rows) => rows.map((r) => Number(r.dataset.line)));
    const summary = await page.textContent('#predict-result .summary');
    if (segments < 100) throw new Error(`only ${segments} segments drawn`);
    if (inked < 1000) throw new Error(`plot nearly blank: ${inked} inked pixels`);
    if (histogram < 500 || scale < 500) throw new Error(`histogram ${histogram}, scale ${scale} inked pixels`);
    if (colours < 4) throw new Error(`the path is not coloured by error: ${colours} colours`);
    if (lines.length < 10 || !lines.every((l) => l > 6)) throw new Error(`worst passes: ${lines}`);
    if (!/441 of 441 predicted/.test(summary)) throw new Error(`summary: ${summary}`);

    // A tolerance band of ±5 µm counts the passes outside it.
    await page.fill('#predict-result input[name="tolerance_band"]', '5');
    const outside = await page.textContent('#predict-result output');
    if (!/^\d+ of 441 passes outside ±5 µm\.$/.test(outside)) throw new Error(`tolerance band: ${outside}`);

    // A worst pass selects its line in the listing and puts the tool there.
    await page.click('#predict-result table.worst tr[data-line]:nth-child(3)');
    const wanted = Number(await page.getAttribute('#predict-result table.worst tr[aria-selected="true"]', 'data-line'));
    const currentLine = Number(await page.getAttribute('#predict-result .timeline', 'data-line'));
    const tool = await page.getAttribute('#predict-plot', 'data-tool');
    if (currentLine !== wanted || !tool) throw new Error(`worst pass on line ${wanted}, listing at ${currentLine}, tool ${tool}`);
    const scene = (await page.getAttribute('#predict-plot', 'data-objects')).split(' ');
    if (!scene.includes('stock') || !scene.includes('tool')) throw new Error(`predict scene: ${scene}`);

    // The corrected program downloads with the input's lines.
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#predict-gcode')]);
    const program = await (await import('node:fs/promises')).readFile(await download.path(), 'utf8');
    if (!program.includes('M30') || !program.includes('O3100')) throw new Error(`corrected program: ${program.slice(0, 200)}`);
    if (download.suggestedFilename() !== 'corrected.nc') throw new Error(`corrected program named ${download.suggestedFilename()}`);

    // Entered as a radius, the size is sent as it is.
    await page.selectOption('#predict-form select[name="size_as"]', 'radius');
    await page.fill('#predict-form input[name="ball_size"]', '2.5');
    // The prediction itself, not the cut stock's program and stock the answer's panel asks for.
    const prediction = (r) => new URL(r.url()).pathname === '/api/v1/predict';
    const [byRadius] = await Promise.all([page.waitForRequest(prediction),
      page.waitForResponse(prediction, { timeout: 60000 }), page.click('#predict-compute')]);
    if (byRadius.postDataJSON().tool.radius !== 2.5) throw new Error(`radius 2.5 sent as ${byRadius.postDataJSON().tool.radius}`);
    const sizeLabel = await page.textContent('#predict-form [data-size-label]');
    if (sizeLabel !== 'Ball radius, mm') throw new Error(`size label: ${sizeLabel}`);

    // A G-code error names its line and marks the program.
    await page.fill('textarea[name="program"]', 'G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F500 Q1\nM30\n');
    await page.click('#predict-compute');
    await page.waitForSelector('#predict-messages .message.error', { timeout: 60000 });
    const error = await page.textContent('#predict-messages .message.error');
    if (!/line 3/i.test(error)) throw new Error(`error without its line: ${error}`);
    const highlighted = await page.$$eval('.invalid', (list) => list.map((e) => e.name));
    if (!highlighted.includes('program')) throw new Error(`program not highlighted: ${highlighted}`);
    // The same program refused by "Corrected program": its line named and selected in the program.
    await page.$eval('textarea[name="program"]', (area) => area.setSelectionRange(0, 0));
    const predictRefused = await refusedDownload('#predict-gcode', '#predict-messages');
    const selected = await page.$eval('textarea[name="program"]', (area) => area.value.slice(area.selectionStart, area.selectionEnd));
    if (!/line 3/i.test(predictRefused) || selected !== 'G1 Z0 F500 Q1') throw new Error(`corrected program refused: "${predictRefused}", selected "${selected}"`);
    return { segments, inked, histogram, colours, worst: lines.length, programLines: program.split('\n').length, verification };
  },

  // Job progress as the service reports it, with one job worker: a prediction long enough to
  // watch (the example's job with a raster of 0.01 mm steps) shows a bar with the fraction it
  // reports; jobs queued behind it show no bar at all; cancelling the prediction lets an
  // engagement job run, whose bar moves within its one operation, then the second job file's,
  // which ends at 100 %.
  async progress() {
    const example = readFileSync(jobFile, 'utf8');
    const lines = ['%', 'G21 G90 G17', 'T3 M06', 'G00 G43 H3 Z20.', 'S8000 M03', 'G00 X0 Y0 Z5.', 'G01 Z0 F1600'];
    const k = Math.PI / 20;
    for (let j = 0; j <= 20; j++) {
      for (let i = 0; i <= 2000; i++) {
        const [x, y] = [(j % 2 ? 2000 - i : i) * 0.01, j];
        const [z, dx, dy] = [2 * Math.sin(k * x) * Math.sin(k * y), 2 * k * Math.cos(k * x) * Math.sin(k * y), 2 * k * Math.sin(k * x) * Math.cos(k * y)];
        const l = Math.hypot(dx, dy, 1);
        lines.push(`X${(x - 3 * dx / l).toFixed(4)} Y${(y - 3 * dy / l).toFixed(4)} Z${(z + 3 / l - 3).toFixed(4)}`);
      }
    }
    lines.push('G00 Z20.', 'M30', '%');
    const long = example.replace(/program = """[\s\S]*?"""/, `program = """\n${lines.join('\n')}\n"""`);
    if (long === example) throw new Error('the example has no program to replace');
    await page.goto(`${base}/#jobs`);
    await page.setInputFiles('#job-file', { name: 'long-prediction.toml', mimeType: 'application/toml', buffer: Buffer.from(long) });
    const running = '#job-rows tr[data-status="running"]';
    await page.waitForSelector(`${running} td[data-progress="reported"] progress[value]`, { timeout: 120000 });
    // Queued behind it: an engagement job (some seconds of work on a 2 µm dot grid, with a small
    // answer) and the second job file.
    const engagement = {
      name: 'long engagement', operations: [{
        operation: 'engagement', tool: { kind: 'flat', radius: 5, flutes: 2 }, stock: { polygon: [[0, 0], [60, 0], [60, 40], [0, 40]] },
        path: [[-10, 20], [70, 20]], spindle_rpm: 3000, feed_per_tooth: 0.05, flute_counts: [2], engine: 'dots', grid: 0.002, step: 0.25,
      }],
    };
    await page.setInputFiles('#job-file', { name: 'long-engagement.json', mimeType: 'application/json', buffer: Buffer.from(JSON.stringify(engagement)) });
    await page.waitForSelector('#job-rows tr[data-status="queued"]', { timeout: 60000 });
    await page.setInputFiles('#job-file', secondJobFile);
    await page.waitForFunction(() => document.querySelectorAll('#job-rows tr[data-status="queued"] td[data-progress="waiting"]').length === 2, null, { timeout: 60000 });
    const queuedBars = await page.$$eval('#job-rows tr[data-status="queued"] progress', (l) => l.length);
    if (queuedBars !== 0) throw new Error('a queued job shows a progress bar');
    // The bar moves with what the service reports.
    await page.waitForFunction((row) => {
      const bar = document.querySelector(`${row} progress`);
      return bar && bar.value > 0 && bar.value < 1;
    }, running, { timeout: 120000 });
    const reported = await page.$eval(`${running} td.progress`, (e) => e.textContent.trim());
    if (!/^\d+(\.\d)?%$/.test(reported)) throw new Error(`reported progress: ${reported}`);
    await page.click(`${running} button:has-text("Cancel")`);
    await page.waitForSelector('#job-rows tr[data-status="cancelled"]', { timeout: 60000 });
    // The engagement job runs next, and its bar moves within the one operation (per sample).
    await page.waitForFunction((row) => {
      const bar = document.querySelector(`${row} td[data-progress="reported"] progress`);
      return bar && bar.value > 0 && bar.value < 1 && /engagement/.test(bar.getAttribute('aria-label'));
    }, running, { timeout: 120000 });
    const moving = await page.$eval(`${running} td.progress progress`, (e) => e.getAttribute('aria-label'));
    await page.waitForSelector('#job-rows tr[data-status="done"] td[data-progress="done"]', { timeout: 180000 });
    const done = await page.$eval('#job-rows tr[data-status="done"] td.progress', (e) => ({ text: e.textContent.trim(), value: e.querySelector('progress')?.value }));
    if (done.text !== '100%' || done.value !== 1) throw new Error(`finished job: ${JSON.stringify(done)}`);
    return { reported, moving };
  },

  // Chooses a material of the library on the engagement form: the k_c1.1 and m_c fields show
  // its values, greyed; the request names the material instead of sending values; and the
  // torque and power per flute count in the table are the API's answer for that material, equal
  // to the answer with its values typed in and unlike the answer for the form's example values.
  async engagementMaterial() {
    await page.goto(`${base}/#engagement`);
    const select = '#engagement-form select[name="material"]';
    await page.waitForSelector(`${select} option[value="C45"]`, { state: 'attached', timeout: 60000 });
    const stored = await page.evaluate(async (url) => (await fetch(url)).json(), `${base}/api/v1/materials/C45`);
    await page.selectOption(select, 'C45');
    const fields = await page.$$eval('#engagement-form input[name="kc11"], #engagement-form input[name="mc"]',
      (list) => list.map((e) => ({ value: Number(e.value), disabled: e.disabled })));
    if (fields[0].value !== stored.kc11 || fields[1].value !== stored.mc || !fields.every((f) => f.disabled)) {
      throw new Error(`the form does not show C45's values: ${JSON.stringify(fields)} vs ${stored.kc11}, ${stored.mc}`);
    }
    const [request] = await Promise.all([
      page.waitForRequest((r) => r.url().endsWith('/api/v1/engagement') && r.method() === 'POST'),
      page.click('#engagement-compute'),
    ]);
    const sent = request.postDataJSON();
    if (sent.material !== 'C45' || sent.kienzle !== undefined) throw new Error(`sent ${JSON.stringify({ material: sent.material, kienzle: sent.kienzle })}`);
    await page.waitForSelector('#engagement-result[data-state="drawn"]', { timeout: 30000 });
    const shown = '#engagement-result .candidate:not([hidden])';
    const head = await page.$$eval(`${shown} table.flutes thead th`, (l) => l.map((e) => e.textContent));
    const [torqueColumn, powerColumn] = [head.indexOf('torque mean / peak, N·m'), head.indexOf('power mean / peak, kW')];
    if (torqueColumn < 0 || powerColumn < 0) throw new Error(`flute table without torque and power: ${head}`);
    const rows = await page.$$eval(`${shown} table.flutes tbody tr`, (list) => list.map((r) => [...r.children].map((td) => td.textContent)));
    // The same request straight to the API: by name, with C45's values typed, with the example's.
    const answers = await page.evaluate(async ([url, body, values]) => {
      const post = async (b) => {
        const response = await fetch(url, { method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify(b) });
        if (!response.ok) throw new Error(`API ${response.status}: ${await response.text()}`);
        const answer = await response.json();
        return answer.candidates ? answer.candidates[0] : answer;
      };
      const { material, ...rest } = body;
      return {
        named: await post(body),
        typed: await post({ ...rest, kienzle: values }),
        example: await post({ ...rest, kienzle: { kc11: 1800, mc: 0.25 } }),
      };
    }, [`${base}/api/v1/engagement`, sent, { kc11: stored.kc11, mc: stored.mc }]);
    const { named, typed, example } = answers;
    if (named.forces?.kc11 !== stored.kc11 || named.forces?.mc !== stored.mc) throw new Error(`API forces: ${JSON.stringify(named.forces)}`);
    if (rows.length !== named.flutes.length || !rows.length) throw new Error(`${rows.length} rows for ${named.flutes.length} flute counts`);
    named.flutes.forEach((f, i) => {
      const torque = `${f.mean_torque_nm.toFixed(2)} / ${f.peak_torque_nm.toFixed(2)}`;
      const power = `${f.mean_power_kw.toFixed(3)} / ${f.peak_power_kw.toFixed(3)}`;
      if (rows[i][0] !== String(f.flute_count) || rows[i][torqueColumn] !== torque || rows[i][powerColumn] !== power) {
        throw new Error(`row ${i}: page ${rows[i][0]} flutes ${rows[i][torqueColumn]} N·m, ${rows[i][powerColumn]} kW; API ${f.flute_count} flutes ${torque} N·m, ${power} kW`);
      }
      if (f.mean_torque_nm !== typed.flutes[i].mean_torque_nm || f.peak_power_kw !== typed.flutes[i].peak_power_kw) {
        throw new Error(`C45 by name and by its values differ: ${f.mean_torque_nm} vs ${typed.flutes[i].mean_torque_nm}`);
      }
      if (!(f.mean_torque_nm > 0) || Math.abs(f.mean_torque_nm - example.flutes[i].mean_torque_nm) < 1e-3 * f.mean_torque_nm) {
        throw new Error(`C45's torque ${f.mean_torque_nm} is the example values' ${example.flutes[i].mean_torque_nm}`);
      }
    });
    // Depth of cut from the heights: no a_p typed, stock top at Z 5 and the tip at Z 2 cut 3 mm.
    await page.fill('#engagement-form input[name="axial_depth"]', '');
    await page.fill('#engagement-form input[name="stock_top_z"]', '5');
    await page.fill('#engagement-form input[name="cut_z"]', '2');
    const [fromHeights] = await Promise.all([
      page.waitForRequest((r) => r.url().endsWith('/api/v1/engagement') && r.method() === 'POST'),
      page.click('#engagement-compute'),
    ]);
    const heights = fromHeights.postDataJSON();
    if (heights.axial_depth !== undefined || heights.stock_top_z !== 5 || heights.cut_z !== 2) {
      throw new Error(`heights sent as ${JSON.stringify({ axial_depth: heights.axial_depth, stock_top_z: heights.stock_top_z, cut_z: heights.cut_z })}`);
    }
    await page.waitForFunction(() => /depth of cut a_p, mm\s*3\.000/.test(document.querySelector('#engagement-result .candidate:not([hidden]) .summary')?.textContent ?? ''), null, { timeout: 30000 });
    return { rows: rows.length, torque: rows[0][torqueColumn], power: rows[0][powerColumn] };
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
    // Every operation's plots, not only the first one's (each waits for its own program).
    await page.waitForSelector('#job-result[data-state="shown"]', { timeout: 60000 });
    await page.waitForSelector('#job-result [data-state="drawn"]', { timeout: 60000 });
    const plots = await page.$$eval('#job-result canvas', (list) => list.length);
    const inked = await inkedPixels('#job-result canvas');
    const downloads = await page.$$eval('#job-result button', (list) => list.map((b) => b.textContent));
    if (inked < 500) throw new Error(`job plot nearly blank: ${inked} inked pixels`);
    if (!downloads.includes('G-code') || !downloads.includes('JSON')) throw new Error(`downloads: ${downloads}`);
    return { plots, inked, seconds };
  },

  // Uploads a job file, opens the finished job and clicks "All outputs (zip)": the download is
  // the service's outputs.zip byte for byte (a zip: PK\x03\x04), and its central directory
  // names the expected entries.
  async jobzip() {
    await page.goto(`${base}/#jobs`);
    await page.setInputFiles('#job-file', jobFile);
    await page.waitForSelector('#job-rows tr[data-status="done"]', { timeout: 120000 });
    await page.click('#job-rows tr[data-status="done"] button');
    await page.waitForSelector('#job-zip', { timeout: 60000 });
    const [download] = await Promise.all([page.waitForEvent('download', { timeout: 60000 }), page.click('#job-zip')]);
    const bytes = readFileSync(await download.path());
    if (!bytes.subarray(0, 4).equals(Buffer.from([0x50, 0x4b, 0x03, 0x04]))) {
      throw new Error(`not a zip: ${bytes.subarray(0, 8).toString('hex')}`);
    }
    // The end of central directory record, then each central directory entry's name.
    const end = bytes.lastIndexOf(Buffer.from([0x50, 0x4b, 0x05, 0x06]));
    if (end < 0) throw new Error('no end of central directory');
    const count = bytes.readUInt16LE(end + 10);
    let at = bytes.readUInt32LE(end + 16);
    const entries = [];
    for (let i = 0; i < count; i++) {
      if (bytes.readUInt32LE(at) !== 0x02014b50) throw new Error(`bad central directory entry ${i}`);
      const [nameLength, extra, comment] = [bytes.readUInt16LE(at + 28), bytes.readUInt16LE(at + 30), bytes.readUInt16LE(at + 32)];
      entries.push(bytes.subarray(at + 46, at + 46 + nameLength).toString('utf8'));
      at += 46 + nameLength + extra + comment;
    }
    const id = await page.$eval('#job-rows tr[data-status="done"]', (row) => row.dataset.job);
    return { id: Number(id), file: download.suggestedFilename(), size: bytes.length, entries: entries.sort() };
  },

  // Tools: saving a number that exists asks first (the stored tool shown), keeps the old tool on
  // "keep", replaces it only on "replace"; Edit says which number it edits and Cancel leaves the
  // tool as stored. The saves are conditional (If-None-Match: * to create, If-Match to replace).
  async toolOverwrite() {
    const conditions = [];
    page.on('request', (request) => {
      if (request.method() === 'PUT' && /\/api\/v1\/tools\/7$/.test(request.url())) {
        const headers = request.headers();
        conditions.push(headers['if-none-match'] ? `if-none-match ${headers['if-none-match']}` : headers['if-match'] ? 'if-match' : 'none');
      }
    });
    const stored = () => page.evaluate(async () => (await (await fetch('/api/v1/tools/7')).json()));
    await page.goto(`${base}/#/tools`);
    const enter = async (kind, diameter, name) => {
      await page.fill('#tool-form input[name="number"]', '7');
      await page.selectOption('#tool-form select[name="kind"]', kind);
      await page.fill('#tool-form input[name="size"]', diameter);
      await page.fill('#tool-form input[name="name"]', name);
      await page.click('#tool-save');
    };
    await enter('ball', '6', 'ball six');
    await page.waitForSelector('#tool-rows tr[data-tool="7"]', { timeout: 60000 });
    // The same number again, another tool: a question showing the stored one, nothing saved yet.
    await enter('flat', '10', 'flat ten');
    const ask = await page.waitForSelector('#tool-messages [data-ask="replace"]', { timeout: 15000 })
      .catch(async () => { throw new Error(`saving T7 again did not ask first; stored now: ${JSON.stringify(await stored())}`); });
    const question = await ask.textContent();
    if (!/T7/.test(question) || !/Ø6 ball/.test(question)) throw new Error(`the question does not show the stored tool: ${question}`);
    if ((await stored()).radius !== 3) throw new Error('T7 was replaced before the answer');
    await page.click('#tool-messages button[data-answer="keep"]');
    await page.waitForSelector('#tool-messages .message.ok', { timeout: 15000 });
    const kept = await stored();
    if (kept.kind !== 'ball' || kept.radius !== 3 || kept.name !== 'ball six') throw new Error(`keep changed T7: ${JSON.stringify(kept)}`);
    // Edit names the number; Cancel leaves the stored tool and the form says so.
    await page.click('#tool-rows tr[data-tool="7"] button:has-text("Edit")');
    const legend = await page.textContent('#tool-form legend[data-legend]');
    if (!/T7/.test(legend)) throw new Error(`editing does not say which tool: ${legend}`);
    await page.fill('#tool-form input[name="size"]', '12');
    await page.click('#tool-cancel-edit');
    const after = await page.textContent('#tool-form legend[data-legend]');
    if (/T7/.test(after)) throw new Error(`cancel left the form editing: ${after}`);
    if ((await stored()).radius !== 3) throw new Error('cancel changed T7');
    // Replace on purpose: asked again, then replaced with If-Match of the version shown.
    await enter('flat', '10', 'flat ten');
    await page.waitForSelector('#tool-messages [data-ask="replace"]', { timeout: 15000 });
    await page.click('#tool-messages button[data-answer="replace"]');
    await page.waitForSelector('#tool-messages .message.ok', { timeout: 15000 });
    const replaced = await stored();
    if (replaced.kind !== 'flat' || replaced.radius !== 5) throw new Error(`replace did not replace: ${JSON.stringify(replaced)}`);
    if (conditions[0] !== 'if-none-match *' || !conditions.includes('if-match')) throw new Error(`conditions sent: ${conditions}`);
    return { question, conditions };
  },

  // A decimal comma, in a German browser: "6,5" is 6.5 (never 65), "6,5,1" is refused at its
  // field; every number field on every view names its unit.
  async decimalComma() {
    const context = await browser.newContext({ locale: 'de-DE', viewport: { width: 1400, height: 1000 } });
    const german = await context.newPage();
    german.on('pageerror', (error) => problems.push(`page error: ${error.message}`));
    german.on('console', (m) => {
      if (m.type() === 'error' && !/status of 4\d\d/.test(m.text())) problems.push(`console error: ${m.text()}`);
    });
    await german.goto(`${base}/#/tools`);
    const language = await german.evaluate(() => navigator.language);
    await german.fill('#tool-form input[name="number"]', '').catch(() => {});
    await german.click('#tool-form input[name="number"]', { clickCount: 3 });
    await german.keyboard.type('21');
    await german.click('#tool-form input[name="size"]', { clickCount: 3 });
    await german.keyboard.press('Backspace');
    await german.keyboard.type('6,5');
    await german.click('#tool-save');
    await german.waitForSelector('#tool-messages .message', { timeout: 15000 });
    await german.waitForTimeout(300);
    const tool = await german.evaluate(async () => {
      const response = await fetch('/api/v1/tools/21');
      return response.ok ? response.json() : null;
    });
    const marked = await german.$$eval('#tool-form [aria-invalid="true"]', (l) => l.map((e) => e.name));
    if (tool && tool.radius !== 3.25) throw new Error(`"6,5" saved as Ø${2 * tool.radius}`);
    if (!tool && marked.join() !== 'size') throw new Error(`"6,5" neither saved as 6.5 nor refused at the field (marked: ${marked})`);
    // Not one number: refused at the field, nothing sent.
    await german.click('#tool-form input[name="number"]', { clickCount: 3 });
    await german.keyboard.type('22');
    await german.click('#tool-form input[name="size"]', { clickCount: 3 });
    await german.keyboard.press('Backspace');
    await german.keyboard.type('6,5,1');
    await german.click('#tool-save');
    await german.waitForSelector('#tool-form [aria-invalid="true"]', { timeout: 15000 });
    const refused = await german.$$eval('#tool-form [aria-invalid="true"]', (l) => l.map((e) => e.name));
    const none = await german.evaluate(async () => (await fetch('/api/v1/tools/22')).status);
    if (refused.join() !== 'size' || none !== 404) throw new Error(`"6,5,1": marked ${refused}, T22 status ${none}`);
    // Every number field the page shows names its unit (or says it counts something, or is an
    // angle, a factor or a ratio without one).
    const unitless = [];
    for (const view of await german.$$eval('#tabs a', (l) => l.map((a) => a.dataset.view))) {
      await german.click(`#tabs a[data-view="${view}"]`);
      await german.waitForTimeout(300);
      unitless.push(...await german.$$eval(`[data-view-root="${view}"] input[inputmode="decimal"], [data-view-root="${view}"] input[type="number"]`, (inputs, id) => inputs
        .map((input) => `${id}: ${(input.closest('label')?.textContent || input.getAttribute('aria-label') || input.name).replace(/\s+/g, ' ').trim()}`)
        .filter((label) => !/(mm|°|ms|rpm|\bs\b|%|N·m|N\/mm|kW|Hz|µm|cells|count|no unit|Flutes|exponent|ratio|Tool number T|Save as T)/.test(label)), view));
    }
    await context.close();
    if (unitless.length) throw new Error(`number fields without a unit: ${[...new Set(unitless)].join('; ')}`);
    return { language, radius: tool?.radius ?? null, marked };
  },

  // Deburr by OD, ID and Ø as a drawing gives them: the same path as by the radii; a negative
  // OD is refused quoting the OD typed.
  async deburrDiameters() {
    await page.goto(`${base}/#/deburr`);
    await page.waitForSelector('#deburr-form');
    const computed = async () => {
      const [response] = await Promise.all([
        page.waitForResponse((r) => r.request().method() === 'POST' && /\/api\/v1\/deburr$/.test(r.url()), { timeout: 60000 }),
        page.click('#deburr-compute'),
      ]);
      const answer = await response.json();
      await page.waitForSelector('#deburr-result:not(.stale) #deburr-plot[data-state="drawn"]', { timeout: 60000 });
      return { request: JSON.parse(response.request().postData()), answer, objects: await page.getAttribute('#deburr-plot', 'data-objects') };
    };
    if (!(await page.$('#deburr-form select[name="sizes_as"]'))) throw new Error('deburr has no OD/ID/Ø entry');
    await page.selectOption('#deburr-form select[name="sizes_as"]', 'diameter');
    const label = await page.textContent('#deburr-form label:has(input[name="outer_size"])');
    await page.fill('#deburr-form input[name="outer_size"]', '50');
    await page.fill('#deburr-form input[name="inner_size"]', '30');
    await page.fill('#deburr-form input[name="hole_size"]', '16');
    const byDiameter = await computed();
    await page.selectOption('#deburr-form select[name="sizes_as"]', 'radius');
    await page.fill('#deburr-form input[name="outer_size"]', '25');
    await page.fill('#deburr-form input[name="inner_size"]', '15');
    await page.fill('#deburr-form input[name="hole_size"]', '8');
    const byRadius = await computed();
    const { workpiece, hole } = byDiameter.request;
    if (workpiece.outer_diameter !== 50 || workpiece.inner_diameter !== 30 || hole.diameter !== 16) throw new Error(`request by diameter: ${JSON.stringify(byDiameter.request)}`);
    if (byRadius.request.workpiece.outer_radius !== 25 || byRadius.request.hole.radius !== 8) throw new Error(`request by radius: ${JSON.stringify(byRadius.request)}`);
    const path = (a) => JSON.stringify(a.result?.points ?? a.points);
    if (path(byDiameter.answer) !== path(byRadius.answer)) throw new Error('OD/ID/Ø gave another path than the radii');
    for (const name of ['tube', 'hole']) if (!byDiameter.objects.split(' ').includes(name)) throw new Error(`no ${name} drawn by diameter: ${byDiameter.objects}`);
    // A negative OD: refused at the OD field, quoting what was typed.
    await page.selectOption('#deburr-form select[name="sizes_as"]', 'diameter');
    await page.fill('#deburr-form input[name="outer_size"]', '-6');
    await page.fill('#deburr-form input[name="inner_size"]', '30');
    await page.fill('#deburr-form input[name="hole_size"]', '16');
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-form [aria-invalid="true"]', { timeout: 60000 });
    const bad = await page.$eval('#deburr-form [aria-invalid="true"]', (e) => ({ name: e.name, note: document.getElementById(e.getAttribute('aria-describedby'))?.textContent, tip: document.getElementById(e.getAttribute('aria-describedby'))?.title }));
    if (bad.name !== 'outer_size' || !/-6\b/.test(bad.note) || /-3\b/.test(bad.note) || !/outer_diameter/.test(bad.tip)) throw new Error(`negative OD: ${JSON.stringify(bad)}`);
    return { label, points: byDiameter.answer.result?.points?.length ?? byDiameter.answer.points?.length, note: bad.note };
  },

  // A DXF drawing (the job-file argument) into Contour and Segment: every layer at once is
  // refused naming the open line and its field; layer CUT is drawn (boundary and two islands)
  // before anything is computed and fills the points, which then compute.
  async dxf() {
    await page.goto(`${base}/#contour`);
    await page.setInputFiles('#contour-form input[name="dxf_file"]', jobFile);
    await page.waitForSelector('#contour-messages .message.error', { timeout: 60000 });
    const refusal = await page.textContent('#contour-messages');
    if (!/open chain/i.test(refusal) || !/NOTES/.test(refusal)) throw new Error(`refusal: ${refusal}`);
    const highlighted = await page.$$eval('.invalid', (list) => list.map((e) => e.name));
    if (!highlighted.includes('dxf_file')) throw new Error(`file not highlighted: ${highlighted}`);
    await page.fill('#contour-form input[name="dxf_layer"]', 'CUT');
    await page.dispatchEvent('#contour-form input[name="dxf_layer"]', 'change');
    await page.waitForSelector('#contour-form [data-dxf-preview] polygon[data-loop="island 2"]', { timeout: 60000 });
    const loops = await page.$$eval('#contour-form [data-dxf-preview] polygon', (list) => list.length);
    const points = (await page.inputValue('#contour-form textarea[name="points"]')).split('\n').length;
    if (loops !== 3 || points < 100) throw new Error(`drawn ${loops} loops, ${points} points`);
    await page.click('#contour-compute');
    await page.waitForSelector('#contour-result:not(.stale) #contour-plot[data-state="drawn"]', { timeout: 60000 });

    await page.click('#tabs a[data-view="segment"]');
    await page.selectOption('#segment-form select[name="kind"]', 'polyline');
    await page.fill('#segment-form input[name="dxf_layer"]', 'CUT');
    await page.setInputFiles('#segment-form input[name="dxf_file"]', jobFile);
    await page.waitForSelector('#segment-form [data-dxf-preview] polygon[data-loop="island 1"]', { timeout: 60000 });
    await page.selectOption('#segment-form select[name="dxf_loop"]', '1');
    const circle = (await page.inputValue('#segment-form textarea[name="points"]')).split('\n');
    if (circle[0] !== circle[circle.length - 1] || circle.length < 50) throw new Error(`island polyline: ${circle.length} points`);
    await page.screenshot({ path: screenshot });
    return { loops, points, island: circle.length };
  },

  // Segment's default is the guarantee mode: no short blocks; every piece of advice names a
  // control the form has (and a choice it offers).
  async segmentDefault() {
    await page.goto(`${base}/#/segment`);
    await page.waitForSelector('#segment-form');
    // An ellipse, whose changing curvature leaves short blocks in the per-window mode.
    await page.selectOption('#segment-form select[name="kind"]', 'ellipse');
    await page.click('#segment-compute');
    await page.waitForSelector('#segment-result:not(.stale) .summary', { timeout: 60000 });
    const mode = await page.inputValue('#segment-form select[name="mode"]');
    const summary = await page.textContent('#segment-result .summary');
    const short = Number(/short blocks(?: \(<[^)]*\))?\s*(\d+)/.exec(summary)?.[1]);
    if (mode !== 'guarantee' || short !== 0) throw new Error(`default mode ${mode}: ${short} short blocks (${summary.slice(0, 300)})`);
    // The per-window mode leaves short blocks; the advice then names what the page offers.
    await page.selectOption('#segment-form select[name="mode"]', 'window');
    await page.click('#segment-compute');
    await page.waitForFunction(() => document.querySelector('#segment-result:not(.stale) .message.warning'), null, { timeout: 60000 });
    const advice = await page.$$eval('#segment-result .message.warning', (list) => list.map((m) => ({ text: m.textContent, raw: m.title })));
    const missing = await page.$eval('#segment-form', (form, advice) => {
      const lacking = [];
      for (const { raw } of advice) {
        const message = raw.replace(/^[A-Z_]+: /, '');
        for (const [, name, choice] of message.matchAll(/\b([a-z]+(?:_[a-z]+)*) "([^"]+)"/g)) {
          const control = form.elements[name];
          if (!control || (control.tagName === 'SELECT' && ![...control.options].some((o) => o.value === choice))) lacking.push(`${name} "${choice}"`);
        }
        for (const [name] of message.matchAll(/\b[a-z]+(?:_[a-z]+)+\b/g)) {
          if (!form.elements[name] && !['block_time', 'min_block_length'].includes(name)) lacking.push(name);
        }
        for (const name of ['margin', 'tolerance', 'window']) {
          if (new RegExp(`(raise|lower|shorter) ${name}\\b`).test(message) && !form.elements[name]) lacking.push(name);
        }
      }
      return lacking;
    }, advice);
    const windowSummary = await page.textContent('#segment-result .summary');
    const windowShort = Number(/short blocks(?: \(<[^)]*\))?\s*(\d+)/.exec(windowSummary)?.[1]);
    if (!(windowShort > 0)) throw new Error(`the per-window mode left no short blocks on the ellipse (${windowShort}): the case shows nothing`);
    if (!advice.length) throw new Error('the per-window mode gave no advice to check');
    if (missing.length) throw new Error(`advice names controls the page lacks: ${missing.join(', ')} in ${advice.map((a) => a.text).join(' | ')}`);
    return { short, windowShort, advice: advice.map((a) => a.text) };
  },

  // A job that fails: its reason in words (no "[object Object]" in the page or a tooltip); it can
  // be opened, re-submitted and deleted. The job re-submitted was sent as TOML by another client
  // (this process, not the page): the page re-submits the file the service keeps.
  async jobsFailed() {
    const elsewhere = await submitElsewhere(`name = "hole too large, from another client"
[[operations]]
operation = "deburr"
tool = { kind = "ball", radius = 2 }
edge = "outer"
cut_amount = 0.2
workpiece = { kind = "tube", origin = [0, 0, 0], inner_radius = 15, outer_radius = 25 }
hole = { shape = "round", radius = 60 }
`, 'application/toml');
    const bad = {
      name: 'hole too large',
      operations: [{ operation: 'deburr', tool: { kind: 'ball', radius: 2 }, edge: 'outer', cut_amount: 0.2,
        workpiece: { kind: 'tube', origin: [0, 0, 0], inner_radius: 15, outer_radius: 25 }, hole: { shape: 'round', radius: 60 } }],
    };
    await page.goto(`${base}/#/jobs`);
    await page.setInputFiles('#job-file', { name: 'too-large.json', mimeType: 'application/json', buffer: Buffer.from(JSON.stringify(bad)) });
    await page.waitForSelector('#job-rows tr[data-status="failed"]', { timeout: 60000 });
    await page.waitForSelector('#job-messages .message.error', { timeout: 15000 });
    const objectShown = () => page.evaluate(() => {
      const texts = [document.body.innerText, ...[...document.querySelectorAll('[title]')].map((e) => e.title)];
      return texts.filter((t) => t.includes('[object Object]'));
    });
    const banner = await page.textContent('#job-messages .message.error');
    let shown = await objectShown();
    if (shown.length) throw new Error(`"[object Object]" shown: ${shown.map((t) => t.slice(0, 200)).join(' | ')}`);
    if (!/hole too large|cylinder radius/i.test(banner)) throw new Error(`the banner does not say why: ${banner}`);
    const fromPage = Number(await page.$eval('#job-rows tr[data-status="failed"]', (row) => row.dataset.job));
    const id = elsewhere;
    await page.waitForSelector(`#job-rows tr[data-job="${id}"][data-status="failed"]`, { timeout: 60000 });
    // Open: the reason and what can be done.
    await page.click(`#job-rows tr[data-job="${id}"] button:has-text("Open")`);
    await page.waitForSelector('#job-result[data-state="shown"]', { timeout: 15000 });
    const opened = await page.textContent('#job-result');
    if (!/failed/.test(opened)) throw new Error(`opened failed job: ${opened.slice(0, 300)}`);
    // Re-submit: a new job from the same file.
    const newest = Math.max(id, fromPage);
    await page.click(`#job-rows tr[data-job="${id}"] button:has-text("Re-submit")`);
    await page.waitForFunction((first) => [...document.querySelectorAll('#job-rows tr[data-status="failed"]')].some((r) => Number(r.dataset.job) > first), newest, { timeout: 60000 })
      .catch(async () => { throw new Error(`re-submitting job #${id} made no new job: ${await page.textContent('#job-messages')}`); });
    const again = await page.$$eval('#job-rows tr[data-status="failed"]', (rows) => rows.map((r) => Number(r.dataset.job)));
    const resubmitted = await (await fetch(`${base}/api/v1/jobs/${Math.max(...again)}`)).json();
    if (resubmitted.name !== 'hole too large, from another client') throw new Error(`the re-submitted job is not the other client's: ${JSON.stringify(resubmitted)}`);
    // Delete: asked first, then gone from the page and from the service (the messages emptied
    // first, so an error there is the delete's).
    await page.waitForFunction(() => !document.querySelector('#job-rows tr[data-status="queued"], #job-rows tr[data-status="running"]'), null, { timeout: 60000 });
    await page.$eval('#job-messages', (box) => box.replaceChildren());
    await page.click(`#job-rows tr[data-job="${id}"] button:has-text("Delete")`);
    await page.click(`#job-rows tr[data-job="${id}"] button:has-text("Yes, delete")`);
    await page.waitForFunction((job) => !document.querySelector(`#job-rows tr[data-job="${job}"]`) || document.querySelector('#job-messages .message.error'), id, { timeout: 15000 });
    const refusedDelete = await page.$('#job-messages .message.error');
    if (refusedDelete) throw new Error(`deleting failed job #${id} was refused: ${await refusedDelete.textContent()} (${await refusedDelete.getAttribute('title')})`);
    const status = await page.evaluate(async (job) => (await fetch(`/api/v1/jobs/${job}`)).status, id);
    if (status !== 404) throw new Error(`deleted job #${id} still answers ${status}`);
    shown = await objectShown();
    if (shown.length) throw new Error(`"[object Object]" shown: ${shown.join(' | ')}`);
    return { id, fromPage, again, banner };
  },

  // Predict with an uploaded STL stock (a binary STL box round the sample path): the stock is
  // drawn in the scene, as a box or grid stock is.
  async predictStl() {
    const stl = boxStl([-5, -5, -10], [25, 25, 2.2]);
    await page.goto(`${base}/#/predict`);
    await page.waitForSelector('#predict-form');
    await page.selectOption('#predict-form select[name="stock_kind"]', 'mesh');
    await page.setInputFiles('#predict-form input[name="stock_file"]', { name: 'box.stl', mimeType: 'model/stl', buffer: stl });
    await page.click('#predict-compute');
    await page.waitForSelector('#predict-result:not(.stale) #predict-plot[data-state="drawn"]', { timeout: 60000 });
    const objects = (await page.getAttribute('#predict-plot', 'data-objects')).split(' ');
    const summary = await page.textContent('#predict-result .summary');
    if (!objects.includes('stock')) throw new Error(`the STL stock is not drawn: ${objects}`);
    return { objects, triangles: stl.readUInt32LE(80), summary: summary.slice(0, 200) };
  },

  // A deburr job opened on the Jobs view shows what the Deburr view shows: the tube and hole
  // (sizes as OD/ID/Ø), the path and the clearance check, for a TOML job sent by another client
  // (this process, not the page) with its tool by number.
  async jobDeburrSolids() {
    const id = await submitElsewhere(`name = "tube by diameters, from another client"
[[tools]]
number = 31
kind = "ball"
radius = 2

[[operations]]
operation = "deburr"
tool = 31
edge = "outer"
cut_amount = 0.2
workpiece = { kind = "tube", origin = [0, 0, 0], inner_diameter = 30, outer_diameter = 50 }
hole = { shape = "round", diameter = 16 }
`, 'application/toml');
    await page.goto(`${base}/#/jobs`);
    await page.waitForSelector(`#job-rows tr[data-job="${id}"][data-status="done"]`, { timeout: 60000 });
    await page.click(`#job-rows tr[data-job="${id}"] button:has-text("Open")`);
    await page.waitForSelector('#job-result[data-state="shown"]', { timeout: 60000 });
    const objects = (await page.getAttribute('#job-result [data-objects]', 'data-objects')).split(' ');
    for (const name of ['tube', 'hole', 'centres', 'tool']) if (!objects.includes(name)) throw new Error(`the job's deburr result has no ${name}: ${objects}`);
    const refused = await page.getAttribute('#job-result [data-objects]', 'data-refused');
    const collisions = await page.getAttribute('#job-result [data-objects]', 'data-collisions');
    if (refused !== 'false' || collisions !== '') throw new Error(`the clearance check of a ball well clear of the wall says refused=${refused}, collisions="${collisions}"`);
    return { id, objects, refused };
  },

  // Machines and materials as tools: saving a name that exists asks first, showing what is
  // stored, and "keep" leaves it; Edit names what it edits and Cancel leaves it as stored.
  async registryOverwrite() {
    const stored = (path) => page.evaluate(async (p) => (await (await fetch(p)).json()), path);
    const seen = {};
    for (const [view, field, first, second, path, key] of [
      ['machines', 'block_time_ms', '4', '2', '/api/v1/machines/hsc-4ms', 'block_time_ms'],
      ['materials', 'kc11', '1700', '2000', '/api/v1/materials/steel-c45', 'kc11'],
    ]) {
      const form = `#${view.slice(0, -1)}-form`;
      const messages = `#${view.slice(0, -1)}-messages`;
      await page.goto(`${base}/#/${view}`);
      await page.waitForSelector(form);
      await page.fill(`${form} input[name="${field}"]`, first);
      await page.click(`${form} button[type="submit"]`);
      await page.waitForSelector(`${messages} .message.ok`, { timeout: 15000 });
      await page.fill(`${form} input[name="${field}"]`, second);
      await page.click(`${form} button[type="submit"]`);
      const ask = await page.waitForSelector(`${messages} [data-ask="replace"]`, { timeout: 15000 })
        .catch(async () => { throw new Error(`${view}: saving again did not ask first; stored now: ${JSON.stringify(await stored(path))}`); });
      seen[view] = await ask.textContent();
      await page.click(`${messages} button[data-answer="keep"]`);
      await page.waitForSelector(`${messages} .message.ok`, { timeout: 15000 });
      if (String((await stored(path))[key]) !== first) throw new Error(`${view}: keep changed it: ${JSON.stringify(await stored(path))}`);
      await page.click(`#${view.slice(0, -1)}-rows tr button:has-text("Edit")`);
      const legend = await page.textContent(`${form} legend[data-legend]`);
      if (!/Edit/.test(legend)) throw new Error(`${view}: editing does not say what: ${legend}`);
      await page.click(`#${view.slice(0, -1)}-cancel-edit`);
      if (/Edit/.test(await page.textContent(`${form} legend[data-legend]`))) throw new Error(`${view}: cancel left the form editing`);
    }
    return { seen };
  },

  // The engagement form with the machine `vmc-2nm` (2 N·m spindle, 12 000 mm/min, stored by
  // the test): the form's max feed stays 2000 and is sent; the starred flute count's torque
  // (the highest phase-mean torque of the API's samples, what the torque chart draws) holds the
  // machine's 2 N·m, no flute count over it says "yes", and the verdict naming the torque limit
  // is visible above the charts, not folded away.
  async engagementMachineLimits() {
    await page.goto(`${base}/#engagement`);
    const select = '#engagement-form select[name="machine"]';
    await page.waitForSelector(`${select} option[value="vmc-2nm"]`, { state: 'attached', timeout: 60000 });
    await page.selectOption(select, 'vmc-2nm');
    const maxFeed = await page.inputValue('#engagement-form input[name="max_feed"]');
    if (maxFeed !== '2000') throw new Error(`choosing the machine changed the max feed to "${maxFeed}"`);
    const [request] = await Promise.all([
      page.waitForRequest((r) => r.url().endsWith('/api/v1/engagement') && r.method() === 'POST'),
      page.click('#engagement-compute'),
    ]);
    const sent = request.postDataJSON();
    if (sent.machine !== 'vmc-2nm' || sent.feed_plan?.max_feed !== 2000) throw new Error(`sent ${JSON.stringify({ machine: sent.machine, feed_plan: sent.feed_plan })}`);
    await page.waitForSelector('#engagement-result[data-state="drawn"]', { timeout: 60000 });
    const shown = '#engagement-result .candidate:not([hidden])';
    const answer = await page.evaluate(async ([url, body]) => {
      const response = await fetch(url, { method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify(body) });
      if (!response.ok) throw new Error(`API ${response.status}: ${await response.text()}`);
      const json = await response.json();
      return json.candidates ? json.candidates[0] : json;
    }, [`${base}/api/v1/engagement`, sent]);
    const limit = answer.forces?.spindle_torque_nm;
    if (limit !== 2) throw new Error(`the answer's torque limit is ${limit}`);
    const highest = answer.flutes.map((f, column) => Math.max(0, ...answer.samples.map((s) => s.torque_nm[column] ?? 0)));
    const over = answer.flutes.filter((f, column) => highest[column] > limit).map((f) => f.flute_count);
    if (!over.length) throw new Error(`no flute count needs more than ${limit} N·m: ${highest}`);
    const rows = await page.$$eval(`${shown} table.flutes tbody tr`, (list) => list.map((r) => ({
      k: Number(r.children[0].textContent), best: r.classList.contains('best'), verdict: r.lastElementChild.textContent,
    })));
    const starred = rows.find((r) => r.best);
    if (starred) {
      const column = answer.flutes.findIndex((f) => f.flute_count === starred.k);
      if (highest[column] > limit) throw new Error(`★ ${starred.k} flutes at ${highest[column].toFixed(2)} N·m over the machine's ${limit} N·m`);
    }
    for (const row of rows) {
      if (over.includes(row.k) && row.verdict.startsWith('yes')) throw new Error(`${row.k} flutes over the torque says "${row.verdict}"`);
      if (over.includes(row.k) && !row.verdict.includes('spindle torque')) throw new Error(`${row.k} flutes: "${row.verdict}" does not name the torque`);
    }
    const verdict = `${shown} .recommendation .over-limits`;
    const visible = await page.isVisible(verdict);
    const text = visible ? await page.textContent(verdict) : '';
    if (!visible || !/spindle torque [\d.]+ N·m > 2 N·m/.test(text)) throw new Error(`verdict not visible or without the torque: "${text}"`);
    const folded = await page.$eval(verdict, (e) => Boolean(e.closest('details')));
    if (folded) throw new Error('the verdict is folded away');
    const program = await page.textContent(`${shown} .recommendation .program-flutes`);
    const planned = answer.program_flute_count;
    if (starred && planned !== starred.k) throw new Error(`the program is for ${planned} flutes, ★ is ${starred.k}`);
    if (!program.includes(`for ${planned} flutes`)) throw new Error(`the verdict does not say which flute count the program is for: "${program}"`);
    return { starred: starred?.k ?? null, over, program: planned, verdict: text };
  },

  // The Verify view cuts its sample program (a slot 0.1 mm too deep, then a rapid through the
  // stock) and lists the findings at their lines; a finding marks its line in the listing and its
  // position on the cut stock, drawn in 3-D with the gouge red; playback cuts up to a line.
  async verify() {
    await page.goto(`${base}/#/verify`);
    await page.click('#verify-run');
    await page.waitForSelector('#verify-findings tr', { timeout: 60000 });
    const findings = await page.$$eval('#verify-findings tr', (rows) => rows.map((r) => ({ kind: r.dataset.kind, line: Number(r.dataset.line || 0) })));
    const at = (kind) => findings.filter((f) => f.kind === kind).map((f) => f.line);
    if (!at('gouge').includes(4)) throw new Error(`no gouge at line 4: ${JSON.stringify(findings)}`);
    if (!at('rapid_through_material').includes(5)) throw new Error(`no rapid through material at line 5: ${JSON.stringify(findings)}`);
    const marked = await page.$$eval('#verify-listing li.finding', (l) => l.map((e) => Number(e.dataset.line)));
    if (!marked.includes(5)) throw new Error(`line 5 not marked in the listing: ${marked}`);
    await page.click('#verify-findings tr[data-kind="rapid_through_material"]');
    const current = await page.$$eval('#verify-listing li[aria-current="true"]', (l) => l.map((e) => e.textContent));
    if (current.length !== 1 || !current[0].startsWith('G0 X60')) throw new Error(`the finding opened ${JSON.stringify(current)}`);
    const summary = await page.textContent('#verify-summary');
    if (!/findings/.test(summary)) throw new Error(`summary: ${summary}`);
    // The cut stock in 3-D from the GLB answer: the slot's floor 0.1 below the part is red.
    await page.waitForSelector('#verify-stock[data-state="drawn"][data-stock-vertices]', { timeout: 60000 });
    const stock = await page.$eval('#verify-stock', (e) => ({ ...e.dataset }));
    if (!(Number(stock.deepestDeviation) < -0.09)) throw new Error(`no gouge in the stock's deviations: ${JSON.stringify(stock)}`);
    await page.click('#verify-stock button:text("Top")');
    const red = await page.$eval('#verify-stock canvas', (canvas, pixels) => {
      const data = eval(pixels)(canvas);
      let found = 0;
      for (let i = 0; i < data.length; i += 4) if (data[i] > 150 && data[i] - data[i + 1] > 80 && data[i] - data[i + 2] > 80) found++;
      return found;
    }, PIXELS);
    if (red < 500) throw new Error(`the gouge is not drawn red: ${red} red pixels`);
    await page.click('#verify-findings tr[data-kind="gouge"][data-line="4"]');
    const marked3d = await page.getAttribute('#verify-stock', 'data-marked');
    if (marked3d !== 'gouge 4') throw new Error(`the gouge finding marked ${marked3d} in 3-D`);
    // Playback: the stock cut up to the plunge (line 3), then played to the end at 1000×.
    const full = Number(stock.removedVolume);
    await page.$eval('#verify-position', (slider) => { slider.value = '1'; slider.dispatchEvent(new Event('input')); });
    await page.waitForSelector('#verify-stock[data-upto-line="3"]', { timeout: 60000 });
    const plunged = Number(await page.getAttribute('#verify-stock', 'data-removed-volume'));
    if (!(plunged > 0 && plunged < full / 3)) throw new Error(`the stock cut up to line 3 lost ${plunged} mm³, the whole program ${full} mm³`);
    await page.selectOption('#verify-speed', '1000');
    await page.click('#verify-play');
    await page.waitForSelector('#verify-stock[data-upto-line="6"]', { timeout: 60000 });
    const played = Number(await page.getAttribute('#verify-stock', 'data-removed-volume'));
    if (played !== full) throw new Error(`played to the end, the stock lost ${played} mm³, not ${full}`);
    return { findings: findings.length, marked: marked.length, red, removed: full, plunged };
  },

  // The deburr view draws the tube its program cuts, from the server's cut stock of the deburr's
  // own verification: the tube with its hole in the scene (the see-through hole wall gone), the
  // chamfer band green (cut to the part), the findings' table and listing, and playback: the
  // stock cut up to an early line has lost less than the whole program removes.
  async deburrCut() {
    await page.goto(`${base}/`);
    const started = Date.now();
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-plot[data-cut-tube="drawn"], #deburr-result .message.warning', { timeout: 120000 });
    const seconds = (Date.now() - started) / 1000;
    const refused = await page.$$eval('#deburr-result .message.warning', (l) => l.map((e) => e.textContent));
    if (refused.length) throw new Error(`the cut tube is not drawn: ${refused.join(' ')}`);
    const stock = await page.$eval('#deburr-plot', (e) => ({ ...e.dataset }));
    if (!stock.objects.split(' ').includes('stock')) throw new Error(`no cut stock in the scene: ${stock.objects}`);
    const listed = await page.$$eval('#deburr-listing li', (l) => l.length);
    if (listed < 20) throw new Error(`the verified program lists ${listed} lines`);
    await page.click('#deburr-plot button:text("Along hole axis")');
    const counts = await page.$eval('#deburr-plot canvas', (canvas, pixels) => {
      const data = eval(pixels)(canvas);
      let green = 0;
      let tube = 0;
      for (let i = 0; i < data.length; i += 4) {
        const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
        if (g > 110 && g - r > 50 && g - b > 50) green++;
        else if (Math.abs(r - g) < 12 && Math.abs(g - b) < 12 && r > 110 && r < 235) tube++;
      }
      return { green, tube };
    }, PIXELS);
    if (counts.tube < 20000) throw new Error(`the cut tube is not drawn: ${counts.tube} grey pixels`);
    if (counts.green < 300) throw new Error(`the chamfer band is not drawn green: ${counts.green} green pixels`);
    const full = Number(stock.removedVolume);
    if (!(full > 0) || !(Number(stock.cutVertices) > 0)) throw new Error(`nothing cut: ${JSON.stringify(stock)}`);
    // Playback: a third of the way through the moves.
    const moves = Number(await page.getAttribute('#deburr-position', 'max'));
    const early = Math.floor(moves / 3);
    const line = await page.$eval('#deburr-position', (slider, early) => {
      slider.value = String(early);
      slider.dispatchEvent(new Event('input'));
      return /line (\d+)/.exec(document.querySelector('#deburr-playback-readout').textContent)[1];
    }, early);
    await page.waitForSelector(`#deburr-plot[data-upto-line="${line}"]`, { timeout: 120000 });
    const partly = Number(await page.getAttribute('#deburr-plot', 'data-removed-volume'));
    if (!(partly < full)) throw new Error(`cut up to line ${line} the tube lost ${partly} mm³, the whole program ${full} mm³`);
    return { ...counts, removed: full, partly, line: Number(line), vertices: Number(stock.stockVertices), seconds };
  },

  // The contour view draws the stock block its program cuts (the server's cut stock of the
  // contour's own verification) under the plan, with playback.
  async contourCut() {
    await page.goto(`${base}/#contour`);
    await page.click('#contour-compute');
    await page.waitForSelector('#contour-stock[data-state="drawn"][data-stock-vertices]', { timeout: 120000 });
    const stock = await page.$eval('#contour-stock', (e) => ({ ...e.dataset }));
    const inked = await inkedPixels('#contour-stock canvas');
    if (inked < 20000) throw new Error(`the cut stock is nearly blank: ${inked} inked pixels`);
    const full = Number(stock.removedVolume);
    if (!(full > 0)) throw new Error(`nothing cut: ${JSON.stringify(stock)}`);
    const line = await page.$eval('#contour-position', (slider) => {
      slider.value = String(Math.floor(Number(slider.max) / 4));
      slider.dispatchEvent(new Event('input'));
      return /line (\d+)/.exec(document.querySelector('#contour-playback-readout').textContent)[1];
    });
    await page.waitForSelector(`#contour-stock[data-upto-line="${line}"]`, { timeout: 120000 });
    const partly = Number(await page.getAttribute('#contour-stock', 'data-removed-volume'));
    if (!(partly < full)) throw new Error(`cut up to line ${line} the stock lost ${partly} mm³, the whole program ${full} mm³`);
    return { inked, removed: full, partly, line: Number(line), vertices: Number(stock.stockVertices) };
  },

  // The predict view draws the stock the corrected program cuts (the server's cut stock of the
  // prediction's own verification, no part: green where cut), with the program listed and playback.
  async predictCut() {
    await page.goto(`${base}/#predict`);
    await page.click('#predict-compute');
    return partlessCut('predict');
  },

  // The engagement view draws the plan-view stock extruded as the candidate's program cuts it.
  async engagementCut() {
    await page.goto(`${base}/#engagement`);
    await page.click('#engagement-compute');
    return partlessCut('engagement');
  },
  // An opened job draws an operation's cut stock when asked ("Cut stock"), not before: a contour
  // on a machine only the job file gives (which the capability's own stock route cannot find),
  // with its program listed, playback removing less; and a verify operation's stock with its
  // gouge (a negative deviation) at the finding's line.
  async jobCut() {
    const id = await submitElsewhere(`name = "cut stock of a job"
[[machines]]
name = "only-in-this-file"
block_time_ms = 2
max_feed = 10000

[[tools]]
number = 3
kind = "flat"
radius = 3

[[operations]]
operation = "contour"
tool = 3
machine = "only-in-this-file"
contour = [[0, 0], [40, 0], [40, 30], [0, 30]]
side = "outside"
depths = { top = 0, bottom = -4, step = 2 }
feed = 800

[[operations]]
operation = "verify"
program = """T1 M6
G0 X-10 Y0 Z5
G1 Z-1 F500
G1 X10
G1 X12 Z-1.2
G1 X14 Z-1
G1 X30
G0 Z50
M30"""
tools = [{ number = 1, kind = "flat", radius = 5 }]
stock = { kind = "box", min = [-5, -4, -10], max = [25, 30, 0] }
part = { kind = "box", min = [-5, -4, -10], max = [25, 30, -1] }
resolution = 0.25
`, 'application/toml');
    await page.goto(`${base}/#/jobs`);
    await page.waitForSelector(`#job-rows tr[data-job="${id}"][data-status="done"]`, { timeout: 60000 });
    await page.click(`#job-rows tr[data-job="${id}"] button:has-text("Open")`);
    await page.waitForSelector('#job-result[data-state="shown"]', { timeout: 60000 });
    const contour = '#job-result section[data-operation="0"]';
    const before = await page.$$eval(`${contour} #contour-stock`, (l) => l.length);
    if (before) throw new Error('the cut stock was drawn before it was asked for');
    const hint = await page.textContent(`${contour} .verification .hint:last-child`);
    if (!/Cut stock/.test(hint)) throw new Error(`the verification does not say how to draw the stock: ${hint}`);
    await page.click(`${contour} button[data-action="cut-stock"]`);
    await page.waitForSelector(`${contour} #contour-stock[data-state="drawn"][data-stock-vertices]`, { timeout: 120000 });
    const stock = await page.$eval(`${contour} #contour-stock`, (e) => ({ ...e.dataset }));
    const inked = await inkedPixels(`${contour} #contour-stock canvas`);
    if (inked < 20000) throw new Error(`the job's cut stock is nearly blank: ${inked} inked pixels`);
    const full = Number(stock.removedVolume);
    if (!(full > 0)) throw new Error(`nothing cut: ${JSON.stringify(stock)}`);
    const listed = await page.$$eval(`${contour} #contour-listing li`, (l) => l.length);
    if (listed < 10) throw new Error(`the program cut is not listed: ${listed} lines`);
    const line = await page.$eval(`${contour} #contour-position`, (slider) => {
      slider.value = String(Math.floor(Number(slider.max) / 4));
      slider.dispatchEvent(new Event('input'));
      return /line (\d+)/.exec(slider.closest('section').querySelector('#contour-playback-readout').textContent)[1];
    });
    await page.waitForSelector(`${contour} #contour-stock[data-upto-line="${line}"]`, { timeout: 120000 });
    const partly = Number(await page.getAttribute(`${contour} #contour-stock`, 'data-removed-volume'));
    if (!(partly < full)) throw new Error(`cut up to line ${line} the stock lost ${partly} mm³, the whole program ${full} mm³`);
    const verify = '#job-result section[data-operation="1"]';
    const findings = await page.$$eval(`${verify} #verify-findings tr`, (rows) => rows.map((r) => `${r.dataset.kind} ${r.dataset.line}`));
    if (!findings.includes('gouge 5')) throw new Error(`the verify result lists ${findings}`);
    await page.click(`${verify} button[data-action="cut-stock"]`);
    await page.waitForSelector(`${verify} #verify-stock[data-state="drawn"][data-stock-vertices]`, { timeout: 120000 });
    const deepest = Number(await page.getAttribute(`${verify} #verify-stock`, 'data-deepest-deviation'));
    if (!(deepest < -0.1)) throw new Error(`the verify operation's gouge is not in its stock: deepest deviation ${deepest}`);
    return { id, inked, removed: full, partly, line: Number(line), listed, findings, deepest };
  },
};

// Scenarios kept in files of their own.
Object.assign(scenarios, unitScenarios({ page, base }));

try {
  const result = await scenarios[scenario]();
  if (screenshot) await page.screenshot({ path: screenshot, fullPage: true });
  if (problems.length) throw new Error(problems.join('; '));
  console.log(JSON.stringify({ ok: true, ...result }));
  await browser.close();
} catch (error) {
  if (screenshot) await page.screenshot({ path: screenshot, fullPage: true }).catch(() => {});
  // What the page itself said (a refusal or a failed request shows as an error message): a wait
  // that timed out is often explained there.
  const shown = await page.$$eval('.message.error, .message.warning', (list) => list.map((m) => m.textContent.trim())).catch(() => []);
  console.log(JSON.stringify({ ok: false, error: String(error.message || error).slice(0, 800), shown, problems }));
  await browser.close();
  process.exit(1);
}
