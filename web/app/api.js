// api.js - the dashboard's one gateway to poro-server's API (docs/web.md). The token lives in
// session storage only: it is sent as "Authorization: Bearer" on every request and never put in a
// URL, the page's HTML or a log. Errors come back as ApiError with the server's
// {"error": {"code", "message", "field", "problems"}}.

const TOKEN_KEY = 'poro.token';

export class ApiError extends Error {
  constructor(status, body) {
    const e = (body && body.error) || {};
    super(e.message || `HTTP ${status}`);
    this.status = status;
    this.code = e.code || 'http_' + status;
    this.field = e.field || null;
    this.problems = e.problems || [];
  }
}

export const token = {
  get: () => sessionStorage.getItem(TOKEN_KEY),
  set: (t) => sessionStorage.setItem(TOKEN_KEY, t),
  clear: () => sessionStorage.removeItem(TOKEN_KEY),
};

function headers(extra) {
  const h = Object.assign({}, extra || {});
  const t = token.get();
  if (t) h.Authorization = 'Bearer ' + t;
  return h;
}

// A 401 anywhere means the token is gone (revoked, or a new server): back to the sign-in page.
function unauthorized() {
  token.clear();
  window.dispatchEvent(new CustomEvent('poro:signed-out'));
}

async function failure(res) {
  let body = null;
  try { body = await res.json(); } catch (_) { /* not JSON: the status says it */ }
  if (res.status === 401) unauthorized();
  return new ApiError(res.status, body);
}

// Whether a token may list jobs, before it is kept: 0 when it may, else the HTTP status.
export async function tryToken(t) {
  const res = await fetch('/v1/jobs?limit=1', { headers: { Authorization: 'Bearer ' + t } });
  return res.ok ? 0 : res.status;
}

// GET/POST/DELETE with a JSON answer.
export async function request(method, path, body, options) {
  const init = { method, headers: headers(body !== undefined ? { 'Content-Type': 'application/json' } : {}) };
  if (body !== undefined) init.body = typeof body === 'string' ? body : JSON.stringify(body);
  if (options && options.signal) init.signal = options.signal;
  const res = await fetch(path, init);
  if (!res.ok) throw await failure(res);
  return res.status === 204 ? null : res.json();
}

export const get = (path, options) => request('GET', path, undefined, options);
export const post = (path, body) => request('POST', path, body);

// The raw bytes of a route (frames, files).
export async function bytes(path, options) {
  const res = await fetch(path, { headers: headers(), signal: options && options.signal });
  if (!res.ok) throw await failure(res);
  return res.arrayBuffer();
}

// Follows a text stream (the log with follow=1: the stream `poro logs -f` reads), calling onText
// with each decoded piece until the server ends it or signal aborts it.
export async function follow(path, onText, signal) {
  const res = await fetch(path, { headers: headers(), signal });
  if (!res.ok) throw await failure(res);
  const reader = res.body.getReader();
  const decoder = new TextDecoder();
  for (;;) {
    const { done, value } = await reader.read();
    if (done) break;
    onText(decoder.decode(value, { stream: true }));
  }
  onText(decoder.decode());
}

// Saves a job's file: fetched with the token in the header (a plain link would need it in the
// URL), then handed to the browser as a download of an object URL.
export async function download(path, name) {
  const res = await fetch(path, { headers: headers() });
  if (!res.ok) throw await failure(res);
  const url = URL.createObjectURL(await res.blob());
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}
