// main.js - the dashboard's shell: sign-in state, the navigation bar and the hash router. Every
// page is a module with render(root, params) that may return a function to call when the page is
// left (to stop its polls and streams). Routes (all in the hash, so the server serves one page):
//   #/jobs?state=...        the jobs list with its filters      (jobs.js)
//   #/jobs/ID               a job: case, history, progress, log  (job.js)
//   #/jobs/ID/frames        the field viewer                     (viewer.js)
//   #/jobs/ID/plots         plots of a job                       (plots.js)
//   #/submit                paste or upload a case               (submit.js)
//   #/admin                 workers and queues (admins)          (admin.js)
//   #/benchmarks            the nightlies' history               (benchmarks.js)
import { get, token } from './api.js';
import { h, clear } from './dom.js';
import * as signin from './signin.js';
import * as jobs from './jobs.js';
import * as job from './job.js';
import * as viewer from './viewer.js';
import * as plots from './plots.js';
import * as submit from './submit.js';
import * as admin from './admin.js';
import * as benchmarks from './benchmarks.js';

const ROUTES = [
  [/^\/jobs\/(\d+)\/frames$/, viewer, (m) => ({ id: Number(m[1]) })],
  [/^\/jobs\/(\d+)\/plots$/, plots, (m) => ({ id: Number(m[1]) })],
  [/^\/jobs\/(\d+)$/, job, (m) => ({ id: Number(m[1]) })],
  [/^\/jobs$/, jobs, () => ({})],
  [/^\/submit$/, submit, () => ({})],
  [/^\/admin$/, admin, () => ({})],
  [/^\/benchmarks$/, benchmarks, () => ({})],
];

export const session = { admin: false, user: null };
let leave = null;

function parseHash() {
  const raw = location.hash.replace(/^#/, '') || '/jobs';
  const [path, query] = raw.split('?');
  return { path, query: new URLSearchParams(query || '') };
}

function renderNav() {
  const nav = clear(document.getElementById('nav'));
  const who = clear(document.getElementById('who'));
  if (!token.get()) return;
  const here = parseHash().path;
  const link = (href, text) => h('a', { href, class: here.startsWith(href.slice(1)) ? 'active' : '' }, text);
  nav.append(link('#/jobs', 'Jobs'), link('#/submit', 'Submit'), link('#/benchmarks', 'Benchmarks'));
  if (session.admin) nav.append(link('#/admin', 'Admin'));
  who.append(session.user ? `${session.user}${session.admin ? ' (admin)' : ''}` : session.admin ? 'admin' : '',
             h('button', { class: 'link', id: 'sign-out', onclick: signOut }, 'Sign out'));
}

// Who the token belongs to: an admin may read /v1/admin/workers; a user's own token list names it.
export async function identify() {
  session.admin = false;
  session.user = null;
  try {
    await get('/v1/admin/workers');
    session.admin = true;
  } catch (e) {
    if (e.status === 401) throw e;
  }
  try {
    const page = await get('/v1/tokens?limit=1');
    if (!session.admin && page.tokens.length) session.user = page.tokens[0].user;
  } catch (e) {
    if (e.status === 401) throw e;
  }
}

function signOut() {
  token.clear();
  window.dispatchEvent(new CustomEvent('poro:signed-out'));
}

async function route() {
  if (leave) { try { leave(); } catch (_) { /* a page that fails to stop must not stop the next */ } }
  leave = null;
  const root = clear(document.getElementById('page'));
  renderNav();
  if (!token.get()) {
    leave = signin.render(root, { onSignedIn: () => { renderNav(); route(); } });
    return;
  }
  const { path, query } = parseHash();
  for (const [re, page, params] of ROUTES) {
    const m = path.match(re);
    if (m) {
      leave = await page.render(root, Object.assign(params(m), { query, session })) || null;
      return;
    }
  }
  root.append(h('p', { class: 'error' }, `No page '${path}'.`), h('a', { href: '#/jobs' }, 'Jobs'));
}

window.addEventListener('hashchange', route);
window.addEventListener('poro:signed-out', () => { session.admin = false; session.user = null; route(); });

(async () => {
  if (token.get()) {
    try { await identify(); } catch (_) { token.clear(); }
  }
  route();
})();
