// dashboard.mjs - the dashboard's browser test, run by dashboard_test.sh against a real server.
// Debian's /usr/bin/chromium, headless, driven by playwright-core. It prints "PASS name" or
// "FAIL name: why" per check (tests/run.sh counts them) and saves a screenshot of every page.
//
//   a. sign in; submit a short Terzaghi case from the example; the job page shows it queued
//      (no worker yet), then, once a real poro-worker is started, running and succeeded, without a
//      reload; log lines arrive while it runs; the progress bar advances; probes are plotted.
//   b. the field viewer draws the last frame (the canvas' colours span the colour bar), its slider
//      changes the frame; the Terzaghi plot's points are the run's values, as h5py reads them
//      from the job's result.h5.
//   c. a bad case, uploaded as a file, shows its JSON pointer error at its field and creates no job; another user's job
//      is not listed and its page says not found; no token in any URL, the page's HTML, its
//      console or its storage other than session storage.
//   5. a short slope's run-out plot is the run's report (poro-solve report on its result.h5), a
//      short footing's load-settlement plot its settlement probe (h5py) against the ramped load.
//   e. screenshots of the sign-in, jobs, submit, job, viewer, plots, benchmarks and admin pages.
import { chromium } from 'playwright-core';
import { spawn, execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';

const env = process.env;
const url = env.WEB_URL;
const tokens = JSON.parse(fs.readFileSync(env.WEB_TOKENS, 'utf8'));
const shots = env.WEB_SHOTS;
const WAIT = 180000;            // longest wait for a state: a bound on waiting, not a measurement

let failed = 0;
function check(name, ok, why) {
  if (ok) console.log(`PASS ${name}`);
  else { failed++; console.log(`FAIL ${name}: ${why}`); }
}

async function api(token, method, p, body) {
  const res = await fetch(url + p, { method, headers: Object.assign({ Authorization: `Bearer ${token}` },
    body ? { 'Content-Type': 'application/json' } : {}), body: body ? JSON.stringify(body) : undefined });
  const text = await res.text();
  return { status: res.status, body: text ? (() => { try { return JSON.parse(text); } catch (_) { return text; } })() : null };
}

const seenUrls = [], consoleLines = [];
function watch(page) {
  page.on('request', (r) => seenUrls.push(r.url()));
  page.on('console', (m) => consoleLines.push(m.text()));
  page.on('pageerror', (e) => consoleLines.push('pageerror: ' + e.message));
}

async function shot(page, name) {
  await page.screenshot({ path: path.join(shots, `${name}.png`), fullPage: true });
}

async function signIn(page, token) {
  await page.goto(url + '/');
  await page.waitForSelector('#token');
  await page.fill('#token', token);
  await page.click('#signin-button');
  await page.waitForSelector('#jobs');
}

// The Terzaghi example, shortened: 10,000 steps, about 4 s of one core on an idle machine, so
// that the page, which reads the job once a second, sees the progress of several heartbeats (at
// 2,500 steps an idle machine ran it between two reads); frames every 0.1 s, progress lines every
// 0.2 s of wall time, checkpoints (so probes arrive while it runs).
function shortTerzaghi(c) {
  c.time.end = 1.0;
  c.output.frame_interval = 0.1;
  c.output.progress_interval = 0.2;
  c.checkpoint = { interval: 0.2 };
  return c;
}

// A slope (polygon bodies: the run-out plot) and a footing (a load on part of a face: the
// load-settlement plot), each cut to tens of steps (about a second of one core together).
function caseFile(name) { return JSON.parse(fs.readFileSync(path.join('tests/cases', name), 'utf8')); }
function shortSlope() {
  const c = caseFile('mc_slope_k1e-3_single_point.json');
  c.time.end = 0.1;
  c.output.frame_interval = 0.02;
  return c;
}
const FOOTING_RAMP = 0.02;      // s: the load's whole ramp lies inside the short run
function shortFooting() {
  const c = caseFile('strip_footing_fbar.json');
  c.time.end = 0.02;
  c.output.frame_interval = 0.005;
  c.loads[0].time_function = { kind: 'ramp', ramp_time: FOOTING_RAMP };
  return c;
}

async function waitEnded(token, id) {
  for (const start = Date.now(); Date.now() - start < WAIT;) {
    const j = (await api(token, 'GET', `/v1/jobs/${id}`)).body;
    if (['succeeded', 'failed', 'cancelled'].includes(j.state)) return j.state;
    await new Promise((r) => setTimeout(r, 250));
  }
  return 'timed out';
}

async function download(token, id, file, to) {
  const res = await fetch(`${url}/v1/jobs/${id}/files/${file}`, { headers: { Authorization: `Bearer ${token}` } });
  fs.writeFileSync(to, Buffer.from(await res.arrayBuffer()));
  return to;
}

// a and b agree to within tol times the larger magnitude of b's values
function sameSeries(a, b, tol) {
  const scale = Math.max(...b.map(Math.abs)) || 1;
  return a.length === b.length && a.every((v, i) => Math.abs(v - b[i]) <= tol * scale);
}

const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium', headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync'],
});
let worker = null;
try {
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await context.newPage();
  watch(page);

  // ---- sign in ----
  await page.goto(url + '/');
  await page.waitForSelector('#token');
  await shot(page, '01-sign-in');
  await page.fill('#token', 'poro_not_a_token');
  await page.click('#signin-button');
  await page.waitForFunction(() => document.querySelector('#signin-error').textContent.length > 0);
  check('web_bad_token_refused', (await page.textContent('#signin-error')).includes('not valid'), await page.textContent('#signin-error'));
  await signIn(page, tokens.alice);
  check('web_signed_in_lists_jobs', await page.isVisible('#jobs'), 'no jobs table after sign-in');

  // ---- c: another user's job is not listed, its page is not found ----
  await page.waitForFunction(() => document.querySelector('#jobs-status').textContent !== 'Loading…');
  const listed = await page.$$eval('#jobs-rows tr', (rows) => rows.map((r) => r.dataset.id));
  check('web_other_users_job_not_listed', !listed.includes(env.WEB_OTHER_JOB), `job ${env.WEB_OTHER_JOB} listed: ${listed}`);
  await page.goto(`${url}/#/jobs/${env.WEB_OTHER_JOB}`);
  await page.waitForSelector('#not-found', { timeout: WAIT });
  check('web_other_users_job_page_not_found', (await page.textContent('#not-found')).includes('No such job'), 'no not-found message');

  // ---- c: a bad case shows its error at its field and creates no job ----
  const before = (await api(tokens.alice, 'GET', '/v1/jobs?limit=1000')).body.jobs.length;
  await page.goto(`${url}/#/submit`);
  await page.waitForSelector('#example option[value="terzaghi.json"]', { state: 'attached' });
  await page.selectOption('#example', 'terzaghi.json');
  await page.waitForFunction(() => document.querySelector('#case-editor').value.includes('Terzaghi'));
  const example = JSON.parse(await page.inputValue('#case-editor'));
  example.grid.cell_size = -0.025;
  const badText = JSON.stringify(example, null, 2);
  // the bad case arrives as an uploaded file
  const badFile = path.join(env.WEB_TMP, 'bad-case.json');
  fs.writeFileSync(badFile, badText);
  await page.setInputFiles('#case-file', badFile);
  await page.waitForFunction(() => document.querySelector('#case-editor').value.includes('-0.025'));
  check('web_uploaded_case_in_editor', (await page.inputValue('#case-editor')) === badText, 'the editor does not hold the uploaded file');
  await page.click('#submit');
  await page.waitForSelector('#notes .field-error', { timeout: WAIT });
  const note = await page.$eval('#notes .field-error', (e) => ({ field: e.dataset.field, line: Number(e.dataset.line), text: e.textContent }));
  const wantLine = badText.split('\n').findIndex((l) => l.includes('"cell_size"')) + 1;
  check('web_bad_case_error_at_its_field', note.field === '/case/grid/cell_size' && note.line === wantLine && note.text.includes('/grid/cell_size'),
    `note ${JSON.stringify(note)}, cell_size is on line ${wantLine}`);
  const gutterErr = await page.$$eval('#gutter .err', (els) => els.map((e) => e.textContent));
  check('web_bad_case_line_marked', gutterErr.includes(String(wantLine)), `marked lines ${gutterErr}`);
  await shot(page, '03-submit-error');
  const after = (await api(tokens.alice, 'GET', '/v1/jobs?limit=1000')).body.jobs.length;
  check('web_bad_case_creates_no_job', after === before, `${before} jobs before, ${after} after`);
  check('web_bad_case_stays_on_submit_page', page.url().endsWith('#/submit'), page.url());

  // ---- a valid case's warning is shown at its field, and the first Submit only shows it ----
  await page.selectOption('#example', 'mc_slope_k1e-3_single_point.json');
  await page.waitForFunction(() => document.querySelector('#case-editor').value.includes('friction_angle'));
  const warnedCase = JSON.parse(await page.inputValue('#case-editor'));
  warnedCase.materials[0].friction_angle = 0.52;   // valid, but most likely meant as radians
  const warnedText = JSON.stringify(warnedCase, null, 2);
  await page.fill('#case-editor', warnedText);
  await page.click('#submit');
  await page.waitForSelector('#notes .field-warning', { timeout: WAIT });
  const warning = await page.$eval('#notes .field-warning', (e) => ({ field: e.dataset.field, line: Number(e.dataset.line) }));
  const angleLine = warnedText.split('\n').findIndex((l) => l.includes('"friction_angle"')) + 1;
  check('web_warning_at_its_field', warning.field === '/case/materials/0/friction_angle' && warning.line === angleLine,
    `warning ${JSON.stringify(warning)}, friction_angle is on line ${angleLine}`);
  const afterWarning = (await api(tokens.alice, 'GET', '/v1/jobs?limit=1000')).body.jobs.length;
  check('web_first_submit_shows_warning_only', afterWarning === before && (await page.textContent('#submit-status')).includes('Submit again'),
    `${before} jobs before, ${afterWarning} after; status '${await page.textContent('#submit-status')}'`);
  await shot(page, '03-submit-warning');

  // ---- a: submit the Terzaghi case; queued -> running -> succeeded without a reload ----
  example.grid.cell_size = 0.025;
  await page.fill('#case-editor', JSON.stringify(shortTerzaghi(example), null, 2));
  await page.fill('#job-name', 'terzaghi-from-the-browser');
  await page.evaluate(() => { window.__sameDocument = true; });
  await page.click('#submit');
  await page.waitForFunction(() => /#\/jobs\/\d+$/.test(location.hash), null, { timeout: WAIT });
  const jobId = Number(page.url().match(/#\/jobs\/(\d+)$/)[1]);
  // record every state, bar width and log length the page shows, from inside the page
  await page.evaluate(() => {
    window.__seen = { states: [], fractions: [], logWhileRunning: 0, probesWhileRunning: false };
    const tick = () => {
      const root = document.querySelector('#page');
      const s = root.dataset.state;
      if (s && window.__seen.states[window.__seen.states.length - 1] !== s) window.__seen.states.push(s);
      const bar = document.querySelector('#progress-bar');
      if (bar && s === 'running') {
        const f = Number(bar.dataset.fraction);
        const fr = window.__seen.fractions;
        if (fr[fr.length - 1] !== f) fr.push(f);
        const lines = (document.querySelector('#log').textContent.match(/^step \d+/gm) || []).length;
        window.__seen.logWhileRunning = Math.max(window.__seen.logWhileRunning, lines);
        if (document.querySelector('#probes .uplot')) window.__seen.probesWhileRunning = true;
      }
    };
    new MutationObserver(tick).observe(document.querySelector('#page'), { subtree: true, childList: true, attributes: true, characterData: true });
    tick();
  });
  await page.waitForFunction(() => document.querySelector('#page').dataset.state === 'queued', null, { timeout: WAIT });
  await shot(page, '04-job-queued');
  // now a real worker
  const work = path.join(env.WEB_TMP, 'work');
  fs.mkdirSync(work, { recursive: true });
  const log = fs.openSync(path.join(env.WEB_TMP, 'worker.log'), 'a');
  worker = spawn(path.join(env.WEB_BUILD, 'poro-worker'), ['--server', url, '--token-file', env.WEB_WORKER_TOKEN_FILE,
    '--solver', path.join(env.WEB_BUILD, 'poro-solve'), '--work', work, '--threads', '1', '--name', 'web-test-worker'],
  { stdio: ['ignore', log, log] });
  await page.waitForFunction(() => document.querySelector('#page').dataset.state === 'running', null, { timeout: WAIT });
  await page.waitForFunction(() => window.__seen.logWhileRunning > 0 || document.querySelector('#page').dataset.state !== 'running', null, { timeout: WAIT });
  await page.waitForFunction(() => window.__seen.fractions.filter((f) => f > 0 && f < 1).length >= 2 || document.querySelector('#page').dataset.state !== 'running', null, { timeout: WAIT });
  await shot(page, '05-job-running');

  // the admin view while it runs, in a second browser context signed in as the admin
  const adminContext = await browser.newContext({ viewport: { width: 1280, height: 800 } });
  const adminPage = await adminContext.newPage();
  watch(adminPage);
  await signIn(adminPage, tokens.root);
  await adminPage.goto(`${url}/#/admin`);
  await adminPage.waitForSelector('#workers-table tr[data-worker="web-test-worker"]', { timeout: WAIT });
  await adminPage.waitForSelector('#queue-table', { timeout: WAIT });
  const workerRow = await adminPage.textContent('#workers-table tr[data-worker="web-test-worker"]');
  check('web_admin_lists_worker_with_slots', /\d+ \/ \d+/.test(workerRow), workerRow);
  await shot(adminPage, '08-admin');
  await adminContext.close();

  await page.waitForFunction(() => ['succeeded', 'failed', 'cancelled'].includes(document.querySelector('#page').dataset.state), null, { timeout: WAIT });
  const seen = await page.evaluate(() => window.__seen);
  const state = await page.evaluate(() => document.querySelector('#page').dataset.state);
  // the slope and the footing run on the same worker while the viewer and the Terzaghi plot are checked
  const slope = await api(tokens.alice, 'POST', '/v1/jobs', { case: shortSlope(), name: 'slope-short' });
  const foot = await api(tokens.alice, 'POST', '/v1/jobs', { case: shortFooting(), name: 'footing-short' });
  check('web_slope_and_footing_submitted', slope.status === 201 && foot.status === 201, `answers ${slope.status}, ${foot.status}`);
  check('web_job_succeeded', state === 'succeeded', `ended ${state}: ${await page.textContent('#job-message')}`);
  check('web_states_queued_running_succeeded', seen.states.join(',') === 'queued,running,succeeded', `states seen: ${seen.states}`);
  check('web_no_reload', await page.evaluate(() => window.__sameDocument === true), 'the page was reloaded');
  check('web_log_lines_while_running', seen.logWhileRunning > 0, 'no "step" line in the log while the job ran');
  const inRun = seen.fractions.filter((f) => f > 0 && f < 1);
  check('web_progress_bar_advances', inRun.length >= 2 && inRun.every((f, i) => i === 0 || f > inRun[i - 1]),
    `fractions shown while running: ${seen.fractions}`);
  // the worker uploads result.h5 and its probes at each checkpoint (every 0.2 s of the 1 s run)
  check('web_probes_plotted_while_running', seen.probesWhileRunning, 'no probe chart on the page while the job ran');
  await page.waitForFunction(() => Number(document.querySelector('#progress-bar').dataset.fraction) === 1);
  await page.waitForSelector('#probes .uplot', { timeout: WAIT });
  check('web_probes_plotted', (await page.$$('#probes .uplot')).length >= 2, 'fewer than 2 probe charts (Pa and m)');
  await page.waitForSelector('#job-files button[data-file="result.h5"]');
  await shot(page, '06-job-succeeded');
  // a download from the page: fetched with the token, saved by the browser (compared below)
  const [saved] = await Promise.all([page.waitForEvent('download', { timeout: WAIT }), page.click('#job-files button[data-file="result.h5"]')]);
  const savedPath = path.join(env.WEB_TMP, 'downloaded.h5');
  await saved.saveAs(savedPath);
  check('web_download_named_as_the_file', saved.suggestedFilename() === 'result.h5', saved.suggestedFilename());

  // ---- b: the field viewer ----
  const index = (await api(tokens.alice, 'GET', `/v1/jobs/${jobId}/frames`)).body;
  const last = index.frames.length - 1;
  await page.click('#open-viewer');
  await page.waitForFunction((n) => document.querySelector('#field-canvas') && document.querySelector('#field-canvas').dataset.frame === String(n), last, { timeout: WAIT });
  const pixels = await page.evaluate(() => {
    const bar = document.querySelector('#colour-bar').getContext('2d');
    const bh = document.querySelector('#colour-bar').height;
    const lut = [];
    for (let y = 0; y < bh; y++) lut.push(Array.from(bar.getImageData(2, y, 1, 1).data.slice(0, 3)));
    const c = document.querySelector('#field-canvas');
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    // each pixel that is a colour of the bar: its place on the bar, 0 (top, high) .. 1 (bottom, low)
    let lo = 1, hi = 0, matched = 0;
    const places = new Set();
    for (let o = 0; o < d.length; o += 4) {
      if (d[o] > 245 && d[o + 1] > 245 && d[o + 2] > 245) continue;
      let best = -1, dist = 1e9;
      for (let k = 0; k < lut.length; k += 1) {
        const e = Math.abs(d[o] - lut[k][0]) + Math.abs(d[o + 1] - lut[k][1]) + Math.abs(d[o + 2] - lut[k][2]);
        if (e < dist) { dist = e; best = k; }
      }
      if (dist > 6) continue;
      matched++;
      const t = best / (lut.length - 1);
      lo = Math.min(lo, t); hi = Math.max(hi, t);
      places.add(Math.round(t * 50));
    }
    return { lo, hi, matched, distinct: places.size, drawn: Number(c.dataset.drawn) };
  });
  check('web_viewer_draws_points', pixels.drawn > 100 && pixels.matched > 1000, JSON.stringify(pixels));
  check('web_viewer_colours_span_colour_bar', pixels.lo <= 0.05 && pixels.hi >= 0.95 && pixels.distinct >= 20, JSON.stringify(pixels));
  const unit = await page.textContent('#colour-title');
  check('web_viewer_colour_bar_has_unit', unit.includes('Pa'), unit);
  await shot(page, '07-viewer-last-frame');
  // double point: the soil and the water points apart (pore pressure is the water points' field)
  const counts = index.frames[last].counts;
  const drawnOf = () => page.$eval('#field-canvas', (c) => [Number(c.dataset.drawn), Number(c.dataset.coloured)]);
  const both = await drawnOf();
  await page.selectOption('#points', 'water');
  await page.waitForFunction((n) => Number(document.querySelector('#field-canvas').dataset.drawn) === n, counts.water, { timeout: 10000 }).catch(() => {});
  const water = await drawnOf();
  await page.selectOption('#points', 'soil');
  await page.selectOption('#field', 'mean_effective_stress');
  await page.waitForFunction(() => document.querySelector('#field-canvas').dataset.field === 'mean_effective_stress');
  const soil = await drawnOf();
  check('web_viewer_soil_and_water_apart', both[0] === counts.soil + counts.water && both[1] === counts.water &&
    water[0] === counts.water && water[1] === counts.water && soil[0] === counts.soil && soil[1] === counts.soil,
    `counts ${JSON.stringify(counts)}; drawn, coloured: both ${both}, water ${water}, soil ${soil}`);
  await page.selectOption('#points', 'both');
  await page.selectOption('#field', 'pore_pressure');
  await page.waitForFunction(() => document.querySelector('#field-canvas').dataset.field === 'pore_pressure');
  const image = () => page.evaluate(() => { const c = document.querySelector('#field-canvas'); return c.toDataURL(); });
  const lastImage = await image();
  await page.$eval('#frame-slider', (s) => { s.value = '0'; s.dispatchEvent(new Event('input')); });
  await page.waitForFunction(() => document.querySelector('#field-canvas').dataset.frame === '0', null, { timeout: WAIT });
  const label = await page.textContent('#frame-label');
  check('web_viewer_slider_changes_frame', label.startsWith('frame 0 ') && (await image()) !== lastImage, label);
  await page.selectOption('#field', 'displacement');
  await page.waitForFunction(() => document.querySelector('#field-canvas').dataset.field === 'displacement');
  await page.$eval('#frame-slider', (s, n) => { s.value = String(n); s.dispatchEvent(new Event('input')); }, last);
  await page.waitForFunction((n) => document.querySelector('#field-canvas').dataset.frame === String(n), last);
  const before_zoom = await image();
  await page.click('#zoom-in');
  check('web_viewer_zooms', (await image()) !== before_zoom, 'the canvas did not change on zoom');
  const box = await page.$eval('#field-canvas', (c) => { const r = c.getBoundingClientRect(); return { x: r.x + r.width / 2, y: r.y + r.height / 2 }; });
  const before_pan = await image();
  await page.mouse.move(box.x, box.y);
  await page.mouse.down();
  await page.mouse.move(box.x + 120, box.y + 40, { steps: 5 });
  await page.mouse.up();
  check('web_viewer_pans', (await image()) !== before_pan, 'the canvas did not change on a drag');
  await shot(page, '07-viewer-displacement-zoomed');

  // ---- b: the verification plot's points are the run's values ----
  await page.goto(`${url}/#/jobs/${jobId}/plots`);
  await page.waitForFunction(() => window.poroPlots && window.poroPlots.terzaghi, null, { timeout: WAIT });
  const plotted = await page.evaluate(() => window.poroPlots.terzaghi.series[0]);
  const h5 = await download(tokens.alice, jobId, 'result.h5', path.join(env.WEB_TMP, 'result.h5'));
  check('web_download_is_the_stored_file', fs.readFileSync(savedPath).equals(fs.readFileSync(h5)) && fs.statSync(h5).size > 1000,
    `page saved ${fs.statSync(savedPath).size} bytes, the API answers ${fs.statSync(h5).size}`);
  const run = JSON.parse(execFileSync('/usr/bin/python3', ['tests/web/frame_values.py', h5]).toString());
  const close = (a, b, scale) => Math.abs(a - b) <= 1e-6 * scale;   // the frames hold 32-bit floats
  const pScale = Math.max(...run.p.map(Math.abs)), yScale = Math.max(...run.y.map(Math.abs));
  const same = plotted.x.length === run.y.length && plotted.x.every((y, i) => close(y, run.y[i], yScale)) &&
    plotted.y.every((p, i) => close(p, run.p[i], pScale));
  check('web_terzaghi_points_are_the_runs_values', same,
    `plotted ${plotted.x.length} points, the run's last frame has ${run.y.length}; first plotted (${plotted.x[0]}, ${plotted.y[0]}), run (${run.y[0]}, ${run.p[0]})`);
  await page.waitForSelector('#plot-terzaghi .uplot');
  await shot(page, '09-plots-terzaghi');

  // ---- 5: a slope's run-out and a footing's load-settlement plots are the runs' values ----
  const slopeId = slope.body.id, footId = foot.body.id;
  const slopeState = await waitEnded(tokens.alice, slopeId), footState = await waitEnded(tokens.alice, footId);
  check('web_slope_and_footing_succeeded', slopeState === 'succeeded' && footState === 'succeeded', `slope ${slopeState}, footing ${footState}`);
  await page.goto(`${url}/#/jobs/${slopeId}/plots`);
  await page.waitForFunction(() => window.poroPlots && window.poroPlots.runout, null, { timeout: WAIT });
  const runout = await page.evaluate(() => window.poroPlots.runout.series);
  // poro-solve report reads the same result.h5 in a process of its own and prints its CSV
  const csv = execFileSync(path.join(env.WEB_BUILD, 'poro-solve'),
    ['report', await download(tokens.alice, slopeId, 'result.h5', path.join(env.WEB_TMP, 'slope.h5'))]).toString().trim().split('\n');
  const cols = csv[0].split(','), rows = csv.slice(1).map((l) => l.split(',').map(Number));
  const col = (name) => rows.map((r) => r[cols.indexOf(name)]);
  const tol = 1e-8;             // frames.json keeps 9 significant digits (half a unit: 5e-9 of a value), the CSV 12
  check('web_runout_plot_is_the_runs_report', rows.length >= 5 &&
    sameSeries(runout[0].x, col('time'), tol) && sameSeries(runout[0].y, col('runout'), tol) &&
    sameSeries(runout[1].x, col('time'), tol) && sameSeries(runout[1].y, col('crest_settlement'), tol),
    `plotted ${JSON.stringify(runout.map((r) => r.y.slice(0, 3)))}, report ${JSON.stringify([col('runout').slice(0, 3), col('crest_settlement').slice(0, 3)])}`);
  await page.waitForSelector('#plot-runout .uplot');
  await shot(page, '09-plots-runout');
  await page.goto(`${url}/#/jobs/${footId}/plots`);
  await page.waitForFunction(() => window.poroPlots && window.poroPlots.footing, null, { timeout: WAIT });
  const curve = (await page.evaluate(() => window.poroPlots.footing.series))[0];
  const probe = JSON.parse(execFileSync('/usr/bin/python3', ['tests/web/frame_values.py',
    await download(tokens.alice, footId, 'result.h5', path.join(env.WEB_TMP, 'footing.h5')), 'settlement_centre']).toString());
  const q = Math.hypot(...shortFooting().loads[0].traction);
  check('web_load_settlement_plot_is_the_runs_values', probe.time.length > 10 &&
    sameSeries(curve.x, probe.value.map((v) => -v), 1e-12) &&
    sameSeries(curve.y, probe.time.map((t) => q * Math.min(1, t / FOOTING_RAMP)), 1e-12),
    `plotted ${curve.x.length} points, the probe has ${probe.time.length}; last plotted (${curve.x.at(-1)}, ${curve.y.at(-1)})`);
  await page.waitForSelector('#plot-footing .uplot');
  await shot(page, '09-plots-footing');

  await page.goto(`${url}/#/benchmarks`);
  await page.waitForSelector('#benchmarks-none', { timeout: WAIT });
  check('web_benchmarks_page_says_none_yet', true, '');
  await shot(page, '10-benchmarks');

  await page.goto(`${url}/#/jobs`);
  await page.waitForSelector(`#jobs-rows tr[data-id="${jobId}"]`, { timeout: WAIT });
  await page.fill('input[name="name"]', 'from-the-browser');
  await page.click('#filters button[type="submit"]');
  await page.waitForFunction(() => location.hash.includes('name=from-the-browser'));
  await page.waitForFunction((id) => { const r = document.querySelectorAll('#jobs-rows tr'); return r.length === 1 && r[0].dataset.id === String(id); }, jobId, { timeout: WAIT });
  check('web_jobs_filter_by_label', true, '');
  await shot(page, '02-jobs');

  // ---- c: no token in any URL, the HTML, the console, or storage other than this tab's ----
  const html = await page.content();
  const all = Object.values(tokens);
  const leaks = (texts) => texts.filter((t) => all.some((tok) => t.includes(tok)));
  check('web_no_token_in_urls', leaks(seenUrls).length === 0 && seenUrls.length > 20, `${leaks(seenUrls).length} of ${seenUrls.length} URLs`);
  check('web_no_token_in_html', leaks([html]).length === 0, 'the page HTML holds a token');
  check('web_no_token_in_console', leaks(consoleLines).length === 0, 'a console line holds a token');
  const storage = await page.evaluate(() => ({ local: JSON.stringify(localStorage), cookies: document.cookie, session: sessionStorage.getItem('poro.token') }));
  check('web_token_in_session_storage_only', storage.session === tokens.alice && leaks([storage.local, storage.cookies]).length === 0, 'token elsewhere');
  const errors = consoleLines.filter((l) => /pageerror|Uncaught|TypeError|ReferenceError/.test(l));
  check('web_no_script_errors', errors.length === 0, errors.slice(0, 3).join(' | '));
  await page.click('#sign-out');
  await page.waitForSelector('#token');
  check('web_sign_out_forgets_token', (await page.evaluate(() => sessionStorage.getItem('poro.token'))) === null, 'token kept after sign-out');
} catch (e) {
  check('web_dashboard_script', false, e.stack || String(e));
} finally {
  if (worker) worker.kill('SIGTERM');
  await browser.close();
}
process.exit(failed ? 1 : 0);
