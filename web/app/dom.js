// dom.js - small helpers to build the pages without a framework: h() makes an element from a tag,
// attributes and children (text is always set as text, never parsed as HTML), and formatting of
// times, durations, sizes and numbers with units.

export function h(tag, attrs, ...children) {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (v === undefined || v === null || v === false) continue;
    if (k.startsWith('on')) el.addEventListener(k.slice(2), v);
    else if (k === 'class') el.className = v;
    else if (k === 'dataset') Object.assign(el.dataset, v);
    else if (k in el && k !== 'list' && k !== 'form') el[k] = v;
    else el.setAttribute(k, v === true ? '' : v);
  }
  for (const c of children.flat(Infinity)) {
    if (c === undefined || c === null || c === false) continue;
    el.append(c instanceof Node ? c : document.createTextNode(String(c)));
  }
  return el;
}

export function clear(el) {
  while (el.firstChild) el.removeChild(el.firstChild);
  return el;
}

export function fmtTime(iso) {
  if (!iso) return '-';
  const d = new Date(iso);
  return d.toISOString().replace('T', ' ').replace(/\.\d+Z$/, 'Z');
}

export function fmtDuration(seconds) {
  if (seconds === null || seconds === undefined || !isFinite(seconds)) return '-';
  seconds = Math.max(0, Math.round(seconds));
  const h = Math.floor(seconds / 3600), m = Math.floor((seconds % 3600) / 60), s = seconds % 60;
  if (h) return `${h} h ${String(m).padStart(2, '0')} min`;
  if (m) return `${m} min ${String(s).padStart(2, '0')} s`;
  return `${s} s`;
}

export function fmtBytes(n) {
  const units = ['bytes', 'kB', 'MB', 'GB', 'TB'];
  let u = 0;
  while (n >= 1000 && u < units.length - 1) { n /= 1000; u++; }
  return u ? `${n.toFixed(1)} ${units[u]}` : `${n} bytes`;
}

// A value with its SI unit, scaled to k/M for Pa and to mm for small lengths.
export function fmtValue(v, unit) {
  if (v === null || v === undefined || !isFinite(v)) return '-';
  if (unit === 'Pa') {
    const a = Math.abs(v);
    if (a >= 1e6) return `${(v / 1e6).toPrecision(3)} MPa`;
    if (a >= 1e3) return `${(v / 1e3).toPrecision(3)} kPa`;
    return `${v.toPrecision(3)} Pa`;
  }
  if (unit === 'm' && Math.abs(v) < 0.1 && v !== 0) return `${(v * 1e3).toPrecision(3)} mm`;
  if (unit === '1') return v.toPrecision(3);
  return `${v.toPrecision(3)} ${unit}`;
}

export function stateBadge(state) {
  return h('span', { class: 'state state-' + state, dataset: { state } }, state);
}

// Seconds since an ISO time.
export function since(iso) {
  return iso ? (Date.now() - new Date(iso).getTime()) / 1000 : null;
}
