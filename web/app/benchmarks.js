// benchmarks.js - the benchmarks page (#/benchmarks): the history of the nightlies, read from the
// benchmark routes (GET /v1/benchmarks, /v1/benchmarks/{id}, /v1/benchmarks/series; their
// contract is docs/benchmarks.md and schemas/openapi.yaml). The runs, newest first, with their
// verdicts; the figures of the newest finished run of a suite; and for a figure chosen there, its
// median over the suite's runs with the band it is judged against. A timing figure's series is of
// the run's own machine (the server never compares two machines' timings). A server without the
// routes answers 404, and the page says it keeps no history.
import { get } from './api.js';
import { h, clear, fmtTime } from './dom.js';
import { chart } from './chart.js';

const RUNS = 100;   // runs listed, and the length of a figure's series

function runsTable(runs) {
  return h('table', { id: 'benchmark-runs' },
    h('thead', {}, h('tr', {}, ['run', 'suite', 'label', 'commit', 'state', 'created (UTC)', 'verdicts'].map((t) => h('th', {}, t)))),
    h('tbody', {}, runs.map((r) => h('tr', { dataset: { run: r.id } },
      h('td', {}, String(r.id)), h('td', {}, r.suite), h('td', {}, r.label), h('td', {}, (r.commit || '').slice(0, 12)),
      h('td', {}, h('span', { class: `state state-${r.state}` }, r.state)), h('td', {}, fmtTime(r.created_at)),
      h('td', {}, r.summary ? Object.entries(r.summary).map(([k, n]) => `${n} ${k}`).join(', ') : '-')))));
}

// figure: one BenchmarkFigure of a run; its series drawn in holder
async function drawSeries(holder, run, figure, charts) {
  const q = new URLSearchParams({ suite: run.suite, figure: figure.figure, limit: String(RUNS) });
  if (figure.class === 'timing' && figure.machine) q.set('machine', figure.machine);
  clear(holder);
  let s;
  try { s = await get(`/v1/benchmarks/series?${q}`); } catch (e) { holder.append(h('p', { class: 'error' }, e.message)); return; }
  const pts = s.points.filter((p) => p.median !== null);
  const x = pts.map((p) => p.run);
  const series = [{ label: 'median', x, y: pts.map((p) => p.median), points: true }];
  const band = (i) => pts.map((p) => (p.band && p.band[i] !== null ? p.band[i] : null));
  if (pts.some((p) => p.band && p.band[0] !== null)) series.push({ label: 'band, low', x, y: band(0), dash: [6, 4] });
  if (pts.some((p) => p.band && p.band[1] !== null)) series.push({ label: 'band, high', x, y: band(1), dash: [6, 4] });
  while (charts.length) { const c = charts.pop(); if (c) c.destroy(); }
  charts.push(chart(holder, { name: 'benchmark-series', title: `${s.figure}${s.machine ? ` on machine ${s.machine}` : ''}`,
    xLabel: 'run', yLabel: s.unit, series }));
}

function figuresTable(run, holder, charts) {
  return h('table', { id: 'benchmark-figures' },
    h('thead', {}, h('tr', {}, ['figure', 'median', 'unit', 'check', 'verdict', 'why'].map((t) => h('th', {}, t)))),
    h('tbody', {}, (run.figures || []).map((f) => h('tr', { dataset: { figure: f.figure } },
      h('td', {}, h('a', { href: '#/benchmarks', onclick: (ev) => { ev.preventDefault(); drawSeries(holder, run, f, charts); } }, f.figure)),
      h('td', {}, f.median === null ? '-' : Number(f.median).toPrecision(4)), h('td', {}, f.unit), h('td', {}, f.check),
      h('td', {}, h('span', { class: `state state-${f.status}` }, f.status)), h('td', { class: 'muted' }, f.detail || '')))));
}

async function fill(section, charts) {
  let page;
  try {
    page = await get(`/v1/benchmarks?limit=${RUNS}`);
  } catch (e) {
    section.append(h('p', { class: 'muted', id: 'benchmarks-none' },
      e.status === 404 ? 'This server keeps no benchmark history yet.' : e.message));
    return;
  }
  if (!page.runs.length) {
    section.append(h('p', { class: 'muted', id: 'benchmarks-none' }, 'No benchmark run yet (poro nightly run).'));
    return;
  }
  section.append(h('h2', {}, 'Runs'), runsTable(page.runs));
  const suites = [...new Set(page.runs.map((r) => r.suite))];
  for (const suite of suites) {
    const newest = page.runs.find((r) => r.suite === suite && r.state !== 'running');
    if (!newest) continue;
    const run = await get(`/v1/benchmarks/${newest.id}`);
    const holder = h('div', { class: 'plot', id: `benchmark-plot-${suite}` });
    section.append(h('h2', {}, `Suite ${suite}: run ${run.id} (${run.label}), ${run.state}`),
      h('p', { class: 'muted' }, 'Choose a figure to see it over the runs.'), figuresTable(run, holder, charts), holder);
    const first = (run.figures || []).find((f) => f.median !== null);
    if (first) await drawSeries(holder, run, first, charts);
  }
}

export function render(root) {
  const charts = [];
  const section = h('section', { class: 'card', id: 'benchmarks' });
  root.append(h('h1', {}, 'Benchmarks'), section);
  section.append(h('h2', {}, 'Benchmark history of the nightlies'));
  fill(section, charts).catch((e) => section.append(h('p', { class: 'error' }, e.message)));
  return () => { for (const c of charts) if (c) c.destroy(); };
}
