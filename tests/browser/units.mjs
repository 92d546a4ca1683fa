// Browser checks of the page's units switch and the machine form's post fields (run by run.mjs:
// `node run.mjs units|machinePosts <base-url> <screenshot.png>`).

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

export function unitScenarios({ page, base }) {
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
    // (the part stays the same size) and the result is computed again in mm. Predict says it works
    // in mm; choosing a machine with units moves the switch, and its values stay said in mm.
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

      // Predict works in mm, and says so, whatever the switch.
      await page.selectOption('#units', 'inch');
      await page.goto(`${base}/#/predict`);
      await page.waitForSelector('[data-view-root="predict"] .units-mm');
      const note = await page.textContent('[data-view-root="predict"] .units-mm');
      const predictLabels = await page.$$eval('[data-view-root="predict"] form label', (l) => l.map((e) => e.textContent).join(' '));
      if (!/works in mm/.test(note) || /\bin\/min\b|, in\b/.test(predictLabels)) throw new Error(`predict: ${note}; ${predictLabels.slice(0, 300)}`);

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
      const job = await fetch(`${base}/api/v1/jobs`, {
        method: 'POST',
        headers: { 'content-type': 'application/json' },
        body: JSON.stringify({ name: 'inch contour', operations: [{ operation: 'contour', ...body }] }),
      });
      if (job.status !== 202) throw new Error(`the job was not queued: ${job.status} ${await job.text()}`);
      await page.selectOption('#units', 'mm');
      await page.goto(`${base}/#/jobs`);
      await page.waitForSelector('#job-rows tr[data-status="done"]', { timeout: 120000 });
      await page.click('#job-rows tr[data-status="done"] button');
      await page.waitForSelector('#job-result[data-state="shown"]', { timeout: 60000 });
      const jobSummary = await page.textContent('#job-result .summary');
      if (!/tool Ø, in\s*0\.250/.test(jobSummary) || /\bmm\b/.test(jobSummary)) throw new Error(`the inch job's summary: ${jobSummary}`);
      return { flipped, summary: inch.slice(0, 120), readout, why, feedHint, jobSummary: jobSummary.slice(0, 120) };
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
