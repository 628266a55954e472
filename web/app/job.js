// job.js - one job: its case, state history, attempts and workers, a progress bar with the
// simulated time and an estimate of the time left, the live log (GET .../log?follow=1, the stream
// `poro logs -f` reads, read with fetch so the token stays in a header), the probe series plotted
// as they arrive, and downloads. The job is read again every POLL_MS until it ends, so its state
// moves queued -> running -> succeeded on the page without a reload.
import { get, post, follow, download, ApiError } from './api.js';
import { h, clear, fmtTime, fmtDuration, fmtBytes, fmtValue, stateBadge, since } from './dom.js';
import { chart } from './chart.js';

const POLL_MS = 1000;
const TERMINAL = ['succeeded', 'failed', 'cancelled'];
const LOG_MAX_CHARS = 2000000;   // what the page keeps of a log; the rest stays on the server

// Time left from the progress this page has seen of the attempt (as poro wait does), else from
// the attempt's start.
function timeLeft(samples, job) {
  const f = job.progress && job.progress.fraction;
  if (!f || f <= 0 || f >= 1) return null;
  if (samples.length >= 2) {
    const a = samples[0], b = samples[samples.length - 1];
    if (b.f > a.f && b.t > a.t) return (1 - b.f) * (b.t - a.t) / (b.f - a.f) / 1000;
  }
  const elapsed = since(job.started_at);
  return elapsed ? elapsed * (1 - f) / f : null;
}

// The attempts, from the job's events and logs: who ran each, when, and how it ended.
function attempts(job) {
  const list = new Map();
  for (const e of job.events || []) {
    if (!e.attempt) continue;
    const a = list.get(e.attempt) || { attempt: e.attempt, worker: null, started: null, ended: null, outcome: null, detail: null };
    if (e.to === 'running' && e.from === 'queued') { a.worker = e.actor; a.started = e.at; }
    if (e.from === 'running' && e.to !== 'running') { a.ended = e.at; a.outcome = e.to; a.detail = e.detail; }
    list.set(e.attempt, a);
  }
  for (const l of job.logs || []) if (list.has(l.attempt)) list.get(l.attempt).log = l.bytes;
  return [...list.values()];
}

function table(head, rows, id) {
  return h('table', { class: 'grid', id }, h('thead', {}, h('tr', {}, head.map((t) => h('th', {}, t)))), h('tbody', {}, rows));
}

export function render(root, { id }) {
  let stopped = false, timer = null, logAbort = null, logAttempt = 0, probesSha = null, endTime = null;
  const samples = [];
  const title = h('h1', { id: 'job-title' }, `Job ${id}`);
  const badge = h('span', { id: 'job-state' });
  const actions = h('div', { class: 'actions' });
  const bar = h('div', { class: 'bar', id: 'progress-bar' }, h('div', { id: 'progress-fill', style: 'width:0%' }));
  const progressText = h('p', { id: 'progress-text', class: 'muted' }, '');
  const details = h('dl', { class: 'details', id: 'job-details' });
  const caseBox = h('div', { id: 'job-case' });
  const eventsBox = h('div', { id: 'job-events' });
  const attemptsBox = h('div', { id: 'job-attempts' });
  const files = h('div', { id: 'job-files' });
  const logPre = h('pre', { class: 'log', id: 'log' });
  const logNote = h('p', { class: 'muted', id: 'log-note' }, 'The log appears when a worker runs the job.');
  const probes = h('div', { id: 'probes', class: 'plots' },
    h('p', { class: 'muted' }, 'The probes appear with the first checkpoint the worker uploads, or at the end.'));
  const message = h('p', { class: 'error', id: 'job-message' });
  const charts = [];

  root.append(h('div', { class: 'job-head' }, title, badge, actions), message,
    h('section', { class: 'card' }, h('h2', {}, 'Progress'), bar, progressText),
    h('div', { class: 'columns' },
      h('section', { class: 'card' }, h('h2', {}, 'Job'), details),
      h('section', { class: 'card' }, h('h2', {}, 'Case'), caseBox)),
    h('section', { class: 'card' }, h('h2', {}, 'Log'), logNote, logPre),
    h('section', { class: 'card' }, h('h2', {}, 'Probes'), probes),
    h('div', { class: 'columns' },
      h('section', { class: 'card' }, h('h2', {}, 'State history'), eventsBox),
      h('section', { class: 'card' }, h('h2', {}, 'Attempts'), attemptsBox)),
    h('section', { class: 'card' }, h('h2', {}, 'Downloads'), files));

  get(`/v1/jobs/${id}/case`).then((c) => {
    endTime = c.time && c.time.end;
    const f = c.formulation || {};
    caseBox.append(h('p', { id: 'case-title' }, h('strong', {}, c.title || '(no title)')),
      h('p', { class: 'muted' }, `${f.scheme || 'semi_implicit'}, ${f.phases || 'double_point'}; ${(c.bodies || []).length} bodies; t_end = ${endTime} s; frames every ${c.output && c.output.frame_interval} s`),
      h('details', {}, h('summary', {}, 'Case JSON'), h('pre', { class: 'json' }, JSON.stringify(c, null, 2))));
  }).catch(() => {});

  function appendLog(text) {
    logPre.append(document.createTextNode(text));
    if (logPre.textContent.length > LOG_MAX_CHARS) logPre.textContent = logPre.textContent.slice(-LOG_MAX_CHARS / 2);
    logPre.scrollTop = logPre.scrollHeight;
  }

  async function followLog(attempt) {
    if (logAbort) logAbort.abort();
    logAbort = new AbortController();
    logAttempt = attempt;
    if (attempt > 1) appendLog(`\n--- attempt ${attempt} ---\n`);
    logNote.textContent = `Attempt ${attempt}, live.`;
    try {
      await follow(`/v1/jobs/${id}/log?attempt=${attempt}&follow=1`, appendLog, logAbort.signal);
      if (!stopped && logAttempt === attempt) logNote.textContent = `Attempt ${attempt}: the log is complete.`;
    } catch (e) {
      if (e.name !== 'AbortError' && !stopped) logNote.textContent = `Log: ${e.message}`;
    }
  }

  async function loadProbes(job) {
    const file = (job.files || []).filter((f) => f.name === 'probes.json').pop();
    if (!file || file.sha256 === probesSha) return;
    probesSha = file.sha256;
    let doc;
    try { doc = await get(`/v1/jobs/${id}/probes`); } catch (_) { return; }
    if (stopped) return;
    while (charts.length) charts.pop().destroy();
    clear(probes);
    const byUnit = new Map();
    for (const [name, p] of Object.entries(doc.probes)) {
      if (!byUnit.has(p.unit)) byUnit.set(p.unit, []);
      byUnit.get(p.unit).push({ label: name, x: p.time, y: p.value });
    }
    for (const [unit, series] of byUnit) {
      const el = h('div', { class: 'plot', id: `probes-${unit.replace(/\W/g, '_')}` });
      probes.append(el);
      const width = Math.max(360, Math.floor((probes.clientWidth - 16) / Math.min(2, byUnit.size)));
      const c = chart(el, { name: `probes-${unit}`, title: `Probes (${unit})`, xLabel: 'time, s', yLabel: unit, series, width });
      if (c) charts.push(c);
    }
    probes.dataset.attempt = String(doc.attempt);
    probes.dataset.samples = String(Math.max(...Object.values(doc.probes).map((p) => p.time.length)));
  }

  function show(job) {
    title.textContent = `Job ${job.id}${job.name ? ' · ' + job.name : ''}`;
    clear(badge).append(stateBadge(job.state));
    root.dataset.state = job.state;
    clear(actions);
    if (!TERMINAL.includes(job.state) && !job.cancel_requested)
      actions.append(h('button', { class: 'danger', id: 'cancel', onclick: async () => {
        try { show(await post(`/v1/jobs/${id}/cancel`)); } catch (e) { message.textContent = e.message; }
      } }, 'Cancel'));
    actions.append(h('a', { class: 'button secondary', href: `#/jobs/${id}/frames`, id: 'open-viewer' }, 'Field viewer'),
      h('a', { class: 'button secondary', href: `#/jobs/${id}/plots`, id: 'open-plots' }, 'Plots'));
    message.textContent = job.message || '';
    message.className = job.state === 'failed' ? 'error' : 'muted';

    const p = job.progress;
    let f = job.state === 'succeeded' ? 1 : p ? Math.max(0, Math.min(1, p.fraction || 0)) : 0;
    if (p && job.state === 'running') samples.push({ t: Date.now(), f });
    bar.firstChild.style.width = `${(100 * f).toFixed(2)}%`;
    bar.dataset.fraction = String(f);
    const parts = [];
    if (job.state === 'succeeded' && endTime) parts.push(`t = ${endTime} s, the end`, '100%');
    else if (p) parts.push(`t = ${Number(p.time).toPrecision(4)} s${endTime ? ' of ' + endTime + ' s' : ''}`, `step ${p.step}`, `${(100 * f).toFixed(1)}%`);
    if (job.state === 'running') parts.push(`about ${fmtDuration(timeLeft(samples, job))} left`);
    if (p && p.us_per_mp_step) parts.push(`${Number(p.us_per_mp_step).toPrecision(3)} µs per point-step`);
    if (job.state === 'queued' && job.waiting) parts.push(`queued: ${job.waiting.message}`);
    progressText.textContent = parts.join(' · ') || job.state;

    const elapsed = job.started_at ? ((job.finished_at ? new Date(job.finished_at) : Date.now()) - new Date(job.started_at)) / 1000 : null;
    clear(details);
    for (const [k, v] of [['user', job.user], ['label', job.name || '-'], ['state', job.state], ['attempt', job.attempt],
      ['worker host', job.worker_host || '-'], ['priority', job.priority], ['threads', job.threads],
      ['wall time limit', fmtDuration(job.wall_time_seconds)],
      ['memory', job.memory_mb ? `${job.memory_mb} MB` : 'not stated'], ['submitted', fmtTime(job.created_at)],
      ['started', fmtTime(job.started_at)], ['finished', fmtTime(job.finished_at)], ['run time', fmtDuration(elapsed)],
      ['solver', job.solver_version || '-'], ['stored', job.stored_bytes !== undefined ? fmtBytes(job.stored_bytes) : '-']])
      details.append(h('dt', {}, k), h('dd', { dataset: { key: k } }, String(v)));

    clear(eventsBox).append(table(['time (UTC)', 'from', 'to', 'attempt', 'by', 'detail'],
      (job.events || []).map((e) => h('tr', {}, h('td', { class: 'time' }, fmtTime(e.at)), h('td', {}, e.from || ''),
        h('td', {}, stateBadge(e.to)), h('td', {}, String(e.attempt)), h('td', {}, e.actor), h('td', {}, e.detail || ''))), 'events'));
    clear(attemptsBox).append(table(['attempt', 'worker', 'started', 'ended', 'outcome', 'log'],
      attempts(job).map((a) => h('tr', {}, h('td', {}, String(a.attempt)), h('td', {}, a.worker || '-'),
        h('td', { class: 'time' }, fmtTime(a.started)), h('td', { class: 'time' }, fmtTime(a.ended)),
        h('td', { title: a.detail || '' }, a.outcome || (a.attempt === job.attempt && job.state === 'running' ? 'running' : '-')),
        h('td', {}, a.log !== undefined ? fmtBytes(a.log) : '-'))), 'attempts'));

    clear(files);
    const newest = new Map();
    for (const fl of job.files || []) newest.set(fl.name, fl);
    if (!newest.size) files.append(h('p', { class: 'muted' }, 'No files yet.'));
    for (const fl of newest.values())
      files.append(h('div', { class: 'file' }, h('button', { class: 'link', dataset: { file: fl.name }, onclick: () =>
        download(`/v1/jobs/${id}/files/${encodeURIComponent(fl.name)}`, fl.name).catch((e) => { message.textContent = e.message; }) },
      fl.name), h('span', { class: 'muted' }, ` ${fmtBytes(fl.size)}, attempt ${fl.attempt}`)));
    if (job.attempt >= 1 && job.attempt !== logAttempt) followLog(job.attempt);
    loadProbes(job);
  }

  async function poll() {
    try {
      const job = await get(`/v1/jobs/${id}`);
      if (stopped) return;
      show(job);
      if (TERMINAL.includes(job.state)) return;
    } catch (e) {
      if (stopped) return;
      if (e instanceof ApiError && e.status === 404) {
        clear(root).append(h('h1', {}, `Job ${id}`), h('p', { class: 'error', id: 'not-found' }, 'No such job (or not yours).'));
        return;
      }
      message.textContent = e.message;
    }
    timer = setTimeout(poll, POLL_MS);
  }
  poll();
  return () => {
    stopped = true;
    clearTimeout(timer);
    if (logAbort) logAbort.abort();
    while (charts.length) charts.pop().destroy();
  };
}
