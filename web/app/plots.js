// plots.js - the plots a user asks of a job, each where the job's kind gives it:
//   - a consolidation column (one rectangular body loaded on top, a linear elastic material):
//     the pore pressure of the frame's points against Terzaghi's closed form (terzaghi.js) over
//     the height, at a chosen frame, and each pore-pressure probe against it over time;
//   - a slope or landslide (polygon bodies): the run-out over time, from the report the worker
//     extracted with the frames (frames.json "report", docs/report.md);
//   - a footing (a load on part of a face): the load-settlement curve, the load from the case's
//     time function and the settlement from a displacement probe.
import { get } from './api.js';
import { h, clear } from './dom.js';
import { chart } from './chart.js';
import { loadIndex, loadFrame } from './frames.js';
import { column, pressure } from './terzaghi.js';

function loadAt(load, t) {
  const f = load.time_function || { kind: 'constant' };
  if (f.kind === 'ramp') return Math.min(1, t / (f.ramp_time || 1));
  if (f.kind === 'sinusoid') return Math.sin(2 * Math.PI * (f.frequency || 0) * t);
  return 1;
}

async function terzaghi(section, id, c, index, probes, charts) {
  const col = column(c);
  if (!col || !index) return false;
  const carrier = index.sets.water ? 'water' : 'soil';
  const pick = h('input', { type: 'range', id: 'terzaghi-frame', min: 0, max: index.frames.length - 1, value: index.frames.length - 1 });
  const label = h('span', { id: 'terzaghi-frame-label' });
  const holder = h('div', { class: 'plot', id: 'plot-terzaghi' });
  section.append(h('h2', {}, 'Pore pressure against Terzaghi'),
    h('p', { class: 'muted' }, `q = ${col.q} Pa, drainage length ${col.Hd} m, c_v = ${col.cv.toPrecision(4)} m²/s; the ${carrier} points of the frame against the closed form.`),
    h('div', { class: 'viewer-slider' }, pick, label), holder);
  const draw = async () => {
    const n = Number(pick.value);
    const f = await loadFrame(id, index, n);
    const s = f[carrier];
    const y = Array.from(s.y), p = Array.from(s.pore_pressure);
    const ys = [], ps = [];
    for (let k = 0; k <= 100; k++) {
      const yy = col.base + (col.top - col.base) * k / 100;
      ys.push(yy);
      ps.push(pressure(col, yy, f.time));
    }
    label.textContent = `frame ${n}, t = ${Number(f.time).toPrecision(4)} s`;
    holder.dataset.frame = String(n);
    holder.dataset.time = String(f.time);
    while (charts.terzaghi && charts.terzaghi.length) charts.terzaghi.pop().destroy();
    clear(holder);
    charts.terzaghi = [chart(holder, { name: 'terzaghi', title: `t = ${Number(f.time).toPrecision(4)} s`, xLabel: 'height y, m', yLabel: 'pore pressure, Pa',
      series: [{ label: `run (${carrier} points)`, x: y, y: p, points: true }, { label: 'Terzaghi', x: ys, y: ps }] })].filter(Boolean);
  };
  pick.oninput = draw;
  await draw();
  // the pore-pressure probes against the closed form at their points
  if (probes) {
    for (const p of c.probes || []) {
      if (p.kind !== 'pore_pressure' || !probes.probes[p.name]) continue;
      const series = probes.probes[p.name];
      const el = h('div', { class: 'plot', id: `plot-probe-${p.name}` });
      section.append(el);
      charts.other.push(chart(el, { name: `terzaghi-${p.name}`, title: `${p.name} at y = ${p.point[1]} m`, xLabel: 'time, s', yLabel: 'Pa',
        series: [{ label: 'run', x: series.time, y: series.value, points: true },
          { label: 'Terzaghi', x: series.time, y: series.time.map((t) => pressure(col, p.point[1], t)) }] }));
    }
  }
  return true;
}

function runout(section, index, charts) {
  const r = index && index.report;
  if (!r) return false;
  const el = h('div', { class: 'plot', id: 'plot-runout' });
  section.append(h('h2', {}, 'Run-out'), h('p', { class: 'muted' }, 'How far the front of the soil from the slope has travelled (docs/report.md), per frame.'), el);
  charts.other.push(chart(el, { name: 'runout', title: 'Run-out over time', xLabel: 'time, s', yLabel: 'run-out, m',
    series: [{ label: 'run-out', x: r.time, y: r.runout }, { label: 'crest settlement', x: r.time, y: r.crest_settlement, dash: [6, 4] }] }));
  return true;
}

function footing(section, c, probes, charts) {
  const load = (c.loads || []).find((l) => l.from !== undefined && l.to !== undefined);
  if (!load || !probes) return false;
  const probe = (c.probes || []).find((p) => p.kind === 'displacement' && p.component === 'y' && probes.probes[p.name]);
  if (!probe) return false;
  const s = probes.probes[probe.name];
  const q = Math.hypot(load.traction[0], load.traction[1]);
  const el = h('div', { class: 'plot', id: 'plot-footing' });
  section.append(h('h2', {}, 'Load and settlement'), h('p', { class: 'muted' }, `Load on ${load.from}-${load.to} m from the case's time function; settlement from probe ${probe.name}.`), el);
  charts.other.push(chart(el, { name: 'footing', title: 'Load-settlement', xLabel: 'settlement, m', yLabel: 'load, Pa',
    series: [{ label: 'footing', x: s.value.map((v) => -v), y: s.time.map((t) => q * loadAt(load, t)) }] }));
  return true;
}

export async function render(root, { id }) {
  root.append(h('h1', {}, h('a', { href: `#/jobs/${id}` }, `Job ${id}`), ' · plots'));
  const charts = { other: [] };
  const section = h('section', { class: 'card', id: 'plots' });
  root.append(section);
  let c;
  try { c = await get(`/v1/jobs/${id}/case`); } catch (e) { section.append(h('p', { class: 'error' }, e.message)); return; }
  const [index, probes] = await Promise.all([loadIndex(id).catch(() => null), get(`/v1/jobs/${id}/probes`).catch(() => null)]);
  let any = false;
  try {
    any = await terzaghi(section, id, c, index, probes, charts);
    any = runout(section, index, charts) || any;
    any = footing(section, c, probes, charts) || any;
  } catch (e) {
    section.append(h('p', { class: 'error' }, e.message));
  }
  if (!any) section.append(h('p', { class: 'muted', id: 'plots-none' }, index ? 'This job is no consolidation column, slope or footing: see its probes on the job page and its fields in the viewer.' : 'No frames yet.'));
  return () => { for (const list of Object.values(charts)) for (const ch of list || []) ch && ch.destroy(); };
}
