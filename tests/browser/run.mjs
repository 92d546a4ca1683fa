// Browser checks of the kerf page, driven by cargo test (tests/tests/api/browser.rs).
// Usage: node run.mjs <scenario> <base-url> <screenshot.png> [job-file]
// Prints one JSON line with what it saw; exits non-zero with the reason when a check fails.
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
    
    // A bad value is reported with the field highlighted.
    await page.fill('input[name="hole_radius"]', '-1');
    await page.click('#deburr-compute');
    await page.waitForSelector('#deburr-messages .message.error', { timeout: 15000 });
    const highlighted = await page.$$eval('.invalid', (list) => list.map((e) => e.name));
    if (!highlighted.includes('hole_radius')) throw new Error(`field not highlighted: ${highlighted}`);
    return { segments, inked };
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
