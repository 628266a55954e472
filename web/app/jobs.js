// jobs.js - the jobs list: filters (states, user for admins, case title, label, creation dates),
// order, and pages of the server's keyset pagination (next_after), so a page costs the same at
// any depth and table size. The filters live in the hash (#/jobs?state=running&title=slope), so a
// list can be bookmarked or reloaded; "Previous" walks back the page starts seen. The page in view
// is fetched again every REFRESH_MS, so states and progress move without a reload.
import { get } from './api.js';
import { h, clear, fmtTime, fmtDuration, stateBadge, since } from './dom.js';

const STATES = ['queued', 'running', 'succeeded', 'failed', 'cancelled'];
const REFRESH_MS = 3000;
const FILTERS = ['user', 'title', 'name', 'created_after', 'created_before'];

function queryOf(q) {
  const p = new URLSearchParams();
  for (const [k, v] of q) if (v) p.set(k, v);
  return p;
}

function progressCell(job) {
  if (job.state !== 'running' || !job.progress) return job.state === 'queued' && job.waiting ? h('span', { class: 'muted', title: job.waiting.message }, job.waiting.reason.replace(/_/g, ' ')) : '';
  const f = Math.max(0, Math.min(1, job.progress.fraction || 0));
  return h('div', { class: 'bar small', title: `${(100 * f).toFixed(1)}%` }, h('div', { style: `width:${100 * f}%` }));
}

function row(job) {
  const elapsed = job.started_at ? ((job.finished_at ? new Date(job.finished_at) : Date.now()) - new Date(job.started_at)) / 1000 : null;
  return h('tr', { dataset: { id: job.id } },
    h('td', {}, h('a', { href: `#/jobs/${job.id}` }, String(job.id))),
    h('td', { class: 'label' }, job.name || ''),
    h('td', { class: 'title', title: job.case_title || '' }, job.case_title || ''),
    h('td', {}, job.user),
    h('td', {}, stateBadge(job.state)),
    h('td', {}, progressCell(job)),
    h('td', { class: 'time' }, fmtTime(job.created_at)),
    h('td', {}, job.state === 'queued' ? fmtDuration(since(job.created_at)) : fmtDuration(elapsed)));
}

export function render(root, { query, session }) {
  const starts = (query.get('starts') || '').split(',').filter(Boolean);
  const stateBoxes = STATES.map((s) => h('label', { class: 'check' },
    h('input', { type: 'checkbox', name: 'state', value: s, checked: (query.get('state') || '').split(',').includes(s) }), s));
  const field = (name, label, type, extra) => h('label', {}, label,
    h('input', Object.assign({ name, type: type || 'text', value: query.get(name) || '' }, extra || {})));
  const order = h('select', { name: 'order' },
    h('option', { value: 'newest', selected: query.get('order') !== 'oldest' }, 'newest first'),
    h('option', { value: 'oldest', selected: query.get('order') === 'oldest' }, 'oldest first'));
  const form = h('form', { class: 'filters', id: 'filters', onsubmit: (ev) => {
    ev.preventDefault();
    const fd = new FormData(form);
    const q = [['state', fd.getAll('state').join(',')]];
    for (const k of FILTERS) q.push([k, (fd.get(k) || '').trim()]);
    q.push(['order', fd.get('order') === 'oldest' ? 'oldest' : '']);
    location.hash = '#/jobs?' + queryOf(q).toString();
  } },
  h('fieldset', { class: 'states' }, h('legend', {}, 'State'), stateBoxes),
  session.admin ? field('user', 'User') : null,
  field('title', 'Case'), field('name', 'Label'),
  field('created_after', 'From', 'date'), field('created_before', 'To', 'date'),
  h('label', {}, 'Order', order),
  h('button', { type: 'submit' }, 'Filter'),
  h('a', { href: '#/jobs', class: 'button secondary' }, 'Clear'));

  const tbody = h('tbody', { id: 'jobs-rows' });
  const status = h('p', { class: 'muted', id: 'jobs-status' }, 'Loading…');
  const prev = h('button', { class: 'secondary', id: 'prev', disabled: starts.length === 0 }, '← Previous');
  const next = h('button', { class: 'secondary', id: 'next', disabled: true }, 'Next →');
  root.append(h('h1', {}, 'Jobs'), form,
    h('table', { class: 'jobs', id: 'jobs' },
      h('thead', {}, h('tr', {}, ['#', 'Label', 'Case', 'User', 'State', 'Progress', 'Submitted (UTC)', 'Time'].map((t) => h('th', {}, t)))),
      tbody),
    h('div', { class: 'pager' }, prev, h('span', { id: 'page-number' }, `page ${starts.length + 1}`), next), status);

  const api = new URLSearchParams();
  for (const k of ['state', 'order', ...FILTERS]) if (query.get(k)) api.set(k, query.get(k));
  api.set('limit', '100');
  const after = starts.length ? starts[starts.length - 1] : '';
  if (after) api.set('after', after);
  let nextAfter = null, timer = null, stopped = false, controller = null;

  const go = (newStarts) => {
    const q = new URLSearchParams(query);
    if (newStarts.length) q.set('starts', newStarts.join(',')); else q.delete('starts');
    location.hash = '#/jobs?' + q.toString();
  };
  next.onclick = () => nextAfter && go([...starts, String(nextAfter)]);
  prev.onclick = () => go(starts.slice(0, -1));

  async function load() {
    controller = new AbortController();
    const t0 = performance.now();
    try {
      const page = await get('/v1/jobs?' + api.toString(), { signal: controller.signal });
      if (stopped) return;
      const rows = page.jobs.map(row);
      clear(tbody).append(...rows);
      nextAfter = page.next_after;
      next.disabled = !nextAfter;
      status.textContent = page.jobs.length ? `${page.jobs.length} jobs on this page (${Math.round(performance.now() - t0)} ms)` : 'No jobs match.';
      root.dataset.loaded = String(Date.now());
    } catch (e) {
      if (!stopped && e.name !== 'AbortError') status.textContent = `Cannot list jobs: ${e.message}`;
    }
    if (!stopped) timer = setTimeout(load, REFRESH_MS);
  }
  load();
  return () => { stopped = true; clearTimeout(timer); if (controller) controller.abort(); };
}
