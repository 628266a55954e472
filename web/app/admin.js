// admin.js - the admin view (role admin): each worker the server heard from, with its host, its
// slots (busy: the running jobs whose lease it holds; idle: its claims waiting for work), the age
// of its last heartbeat or claim and its current jobs; the queue per user (queued and running
// against their caps). From GET /v1/admin/workers, read again every REFRESH_MS.
import { get } from './api.js';
import { h, clear, fmtDuration, stateBadge } from './dom.js';

const REFRESH_MS = 2000;

export function render(root, { session }) {
  root.append(h('h1', {}, 'Workers and queues'));
  if (!session.admin) {
    root.append(h('p', { class: 'error' }, 'This view is for admin tokens.'));
    return;
  }
  const workers = h('div', { id: 'workers' }), queue = h('div', { id: 'queue' }), note = h('p', { class: 'muted' });
  root.append(h('section', { class: 'card' }, h('h2', {}, 'Workers'), workers),
    h('section', { class: 'card' }, h('h2', {}, 'Queue by user'), queue), note);
  let timer = null, stopped = false;
  async function load() {
    try {
      const o = await get('/v1/admin/workers');
      if (stopped) return;
      clear(workers).append(h('table', { class: 'grid', id: 'workers-table' },
        h('thead', {}, h('tr', {}, ['worker', 'user', 'host', 'threads per slot', 'slots busy / known', 'last heard', 'jobs'].map((t) => h('th', {}, t)))),
        h('tbody', {}, o.workers.map((w) => {
          const stale = w.seconds_since_seen > o.lease_seconds;
          return h('tr', { class: stale ? 'stale' : '', dataset: { worker: w.worker } }, h('td', {}, w.worker), h('td', {}, w.user),
            h('td', {}, w.host || '-'), h('td', {}, String(w.threads || '-')),
            h('td', {}, h('span', { class: 'slots' }, Array.from({ length: w.slots }, (_, i) => h('span', { class: i < w.slots_busy ? 'slot busy' : 'slot' }))), ` ${w.slots_busy} / ${w.slots}`),
            h('td', {}, `${fmtDuration(w.seconds_since_seen)} ago${stale ? ' (gone?)' : ''}`),
            h('td', {}, w.jobs.map((j) => h('div', {}, h('a', { href: `#/jobs/${j.id}` }, `#${j.id}`), ` ${j.user} `, stateBadge(j.state),
              j.progress ? ` ${(100 * (j.progress.fraction || 0)).toFixed(0)}%` : ''))));
        }))));
      if (!o.workers.length) workers.append(h('p', { class: 'muted' }, 'No worker has called this server since it started.'));
      clear(queue).append(h('table', { class: 'grid', id: 'queue-table' },
        h('thead', {}, h('tr', {}, ['user', 'queued', 'running', 'max queued', 'max running'].map((t) => h('th', {}, t)))),
        h('tbody', {}, o.queue.map((u) => h('tr', { dataset: { user: u.user } }, h('td', {}, u.user), h('td', {}, String(u.queued)),
          h('td', {}, String(u.running)), h('td', {}, String(u.max_queued)), h('td', {}, u.max_running ? String(u.max_running) : 'no cap'))))));
      if (!o.queue.length) queue.append(h('p', { class: 'muted' }, 'Nothing queued or running.'));
      note.textContent = `${o.running.length} running; updated ${new Date().toISOString().slice(11, 19)} UTC`;
    } catch (e) {
      if (!stopped) note.textContent = e.message;
    }
    if (!stopped) timer = setTimeout(load, REFRESH_MS);
  }
  load();
  return () => { stopped = true; clearTimeout(timer); };
}
