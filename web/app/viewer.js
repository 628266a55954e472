// viewer.js - the field viewer: the material points of any saved frame drawn on a canvas,
// coloured by a field (pore pressure, mean effective stress, deviatoric plastic strain,
// displacement) with a colour bar and its unit, a slider over the frames, zoom (wheel, buttons)
// and pan (drag). In double point the soil and the water points are drawn apart: either set alone,
// or both, the set without the field in grey. Colours run over the frame's own range of the field
// (every frame uses the whole colour bar), or over its range in the whole run (so frames compare).
import { h, clear, fmtValue } from './dom.js';
import { loadIndex, loadFrame } from './frames.js';
import { LUT, lutIndex, rgb } from './colour.js';

const GREY = [212, 212, 212];

export async function render(root, { id }) {
  root.append(h('h1', {}, h('a', { href: `#/jobs/${id}` }, `Job ${id}`), ' · field viewer'));
  let index;
  try {
    index = await loadIndex(id);
  } catch (e) {
    root.append(h('p', { class: 'error', id: 'viewer-error' }, e.status === 404 ? `No frames yet: ${e.message}` : e.message));
    return;
  }
  const fields = index.fields.filter((f) => f.range && f.sets.length);
  const sets = Object.keys(index.sets);
  const frameCount = index.frames.length;
  const fieldSel = h('select', { id: 'field' }, fields.map((f) => h('option', { value: f.name }, `${f.label} (${f.unit})`)));
  const setSel = h('select', { id: 'points' }, sets.length > 1
    ? [h('option', { value: 'both' }, 'soil and water'), ...sets.map((s) => h('option', { value: s }, `${s} points`))]
    : [h('option', { value: sets[0] }, `${sets[0]} points`)]);
  const rangeSel = h('select', { id: 'range-mode' }, h('option', { value: 'frame' }, 'range of this frame'), h('option', { value: 'run' }, 'range of the whole run'));
  const slider = h('input', { type: 'range', id: 'frame-slider', min: 0, max: Math.max(0, frameCount - 1), value: Math.max(0, frameCount - 1), step: 1 });
  const frameLabel = h('span', { id: 'frame-label' });
  const canvas = h('canvas', { id: 'field-canvas', width: 800, height: 560 });
  const bar = h('canvas', { id: 'colour-bar', width: 24, height: 400 });
  const barTicks = h('div', { class: 'colour-ticks', id: 'colour-ticks' });
  const barTitle = h('div', { class: 'colour-title', id: 'colour-title' });
  const status = h('p', { class: 'muted', id: 'viewer-status' });
  const zoomIn = h('button', { class: 'secondary', id: 'zoom-in' }, '+');
  const zoomOut = h('button', { class: 'secondary', id: 'zoom-out' }, '−');
  const reset = h('button', { class: 'secondary', id: 'zoom-reset' }, 'Fit');
  root.append(
    h('div', { class: 'viewer-controls' }, h('label', {}, 'Field ', fieldSel), h('label', {}, 'Points ', setSel),
      h('label', {}, 'Colours ', rangeSel), zoomIn, zoomOut, reset),
    h('div', { class: 'viewer-slider' }, slider, frameLabel),
    h('div', { class: 'viewer' }, canvas, h('div', { class: 'colour-bar' }, barTitle, h('div', { class: 'colour-body' }, bar, barTicks))),
    status);
  if (!frameCount) { status.textContent = 'The run has no frames yet.'; return; }
  if (sets.length > 1) setSel.value = 'both';
  if (fields.some((f) => f.name === 'pore_pressure')) fieldSel.value = 'pore_pressure';

  // world -> screen: x_s = ox + k * x, y_s = oy - k * y
  const g = index.grid;
  const view = { k: 1, ox: 0, oy: 0 };
  function fit() {
    const pad = 20, w = canvas.width - 2 * pad, hgt = canvas.height - 2 * pad;
    view.k = Math.min(w / g.extent[0], hgt / g.extent[1]);
    view.ox = pad + (w - view.k * g.extent[0]) / 2 - view.k * g.origin[0];
    view.oy = canvas.height - pad - (hgt - view.k * g.extent[1]) / 2 + view.k * g.origin[1];
  }
  fit();
  let frame = null, controller = null, loading = 0;

  function currentRange(field) {
    const f = index.fields.find((x) => x.name === field);
    if (rangeSel.value === 'frame' && frame) {
      const r = index.frames[frame.index].ranges[field];
      if (r) return r;
    }
    return f.range;
  }

  function drawBar(field, lo, hi) {
    const ctx = bar.getContext('2d');
    const img = ctx.createImageData(bar.width, bar.height);
    for (let y = 0; y < bar.height; y++) {
      const i = Math.round(255 * (1 - y / (bar.height - 1)));
      for (let x = 0; x < bar.width; x++) {
        const o = 4 * (y * bar.width + x);
        img.data[o] = LUT[3 * i]; img.data[o + 1] = LUT[3 * i + 1]; img.data[o + 2] = LUT[3 * i + 2]; img.data[o + 3] = 255;
      }
    }
    ctx.putImageData(img, 0, 0);
    const f = index.fields.find((x) => x.name === field);
    barTitle.textContent = `${f.label}, ${f.unit === '1' ? '-' : f.unit}`;
    clear(barTicks);
    for (let k = 0; k <= 4; k++) {
      const v = hi - (hi - lo) * k / 4;
      barTicks.append(h('span', { style: `top:${(100 * k / 4).toFixed(1)}%` }, fmtValue(v, f.unit)));
    }
  }

  // Writes a point as a square of side px (at least 2) into the image.
  function plot(img, sx, sy, px, c) {
    const half = px / 2, w = img.width, ht = img.height;
    const x0 = Math.max(0, Math.floor(sx - half)), x1 = Math.min(w - 1, Math.ceil(sx + half) - 1);
    const y0 = Math.max(0, Math.floor(sy - half)), y1 = Math.min(ht - 1, Math.ceil(sy + half) - 1);
    for (let y = y0; y <= y1; y++) for (let x = x0; x <= x1; x++) {
      const o = 4 * (y * w + x);
      img.data[o] = c[0]; img.data[o + 1] = c[1]; img.data[o + 2] = c[2]; img.data[o + 3] = 255;
    }
  }

  function spacing(s) {
    let xmin = Infinity, xmax = -Infinity, ymin = Infinity, ymax = -Infinity;
    for (let i = 0; i < s.count; i++) {
      xmin = Math.min(xmin, s.x[i]); xmax = Math.max(xmax, s.x[i]); ymin = Math.min(ymin, s.y[i]); ymax = Math.max(ymax, s.y[i]);
    }
    return s.count ? Math.sqrt(Math.max((xmax - xmin) * (ymax - ymin), 1e-30) / s.count) : g.cell_size / 2;
  }

  function draw() {
    const ctx = canvas.getContext('2d');
    ctx.fillStyle = '#fff';
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    if (!frame) return;
    const field = fieldSel.value;
    const [lo, hi] = currentRange(field);
    drawBar(field, lo, hi);
    const img = ctx.getImageData(0, 0, canvas.width, canvas.height);
    const visible = setSel.value === "both" ? sets : [setSel.value];
    let drawn = 0, coloured = 0;
    // the set without the field first (grey), so the coloured points lie on top
    const order = [...visible].sort((a, b) => (frame[a][field] ? 1 : 0) - (frame[b][field] ? 1 : 0));
    for (const set of order) {
      const s = frame[set];
      const px = Math.max(2, view.k * spacing(s) * (set === 'water' && visible.length > 1 ? 0.6 : 1));
      const values = s[field];
      for (let i = 0; i < s.count; i++) {
        const v = values ? values[i] : NaN;
        const c = values && isFinite(v) ? LUT.subarray(3 * lutIndex(v, lo, hi), 3 * lutIndex(v, lo, hi) + 3) : GREY;
        plot(img, view.ox + view.k * s.x[i], view.oy - view.k * s.y[i], px, c);
        drawn++;
        if (values && isFinite(v)) coloured++;
      }
    }
    ctx.putImageData(img, 0, 0);
    // the grid's extent
    ctx.strokeStyle = '#888';
    ctx.lineWidth = 1;
    ctx.strokeRect(view.ox + view.k * g.origin[0], view.oy - view.k * (g.origin[1] + g.extent[1]), view.k * g.extent[0], view.k * g.extent[1]);
    Object.assign(canvas.dataset, { frame: String(frame.index), field, drawn: String(drawn), coloured: String(coloured), lo: String(lo), hi: String(hi) });
    status.textContent = `${drawn} points drawn (${coloured} coloured); colours from ${fmtValue(lo, index.fields.find((x) => x.name === field).unit)} to ${fmtValue(hi, index.fields.find((x) => x.name === field).unit)}`;
  }

  async function show(n) {
    const ticket = ++loading;
    if (controller) controller.abort();
    controller = new AbortController();
    frameLabel.textContent = `frame ${n} of ${frameCount - 1}, t = ${Number(index.frames[n].time).toPrecision(4)} s (loading)`;
    try {
      const f = await loadFrame(id, index, n, controller.signal);
      if (ticket !== loading) return;
      frame = f;
      frameLabel.textContent = `frame ${n} of ${frameCount - 1}, t = ${Number(f.time).toPrecision(4)} s`;
      draw();
    } catch (e) {
      if (e.name !== 'AbortError') status.textContent = e.message;
    }
  }

  fieldSel.onchange = draw;
  setSel.onchange = draw;
  rangeSel.onchange = draw;
  slider.oninput = () => show(Number(slider.value));
  const zoom = (factor, cx, cy) => {
    view.ox = cx - (cx - view.ox) * factor;
    view.oy = cy - (cy - view.oy) * factor;
    view.k *= factor;
    draw();
  };
  zoomIn.onclick = () => zoom(1.5, canvas.width / 2, canvas.height / 2);
  zoomOut.onclick = () => zoom(1 / 1.5, canvas.width / 2, canvas.height / 2);
  reset.onclick = () => { fit(); draw(); };
  const toCanvas = (ev) => {
    const r = canvas.getBoundingClientRect();
    return [(ev.clientX - r.left) * canvas.width / r.width, (ev.clientY - r.top) * canvas.height / r.height];
  };
  canvas.addEventListener('wheel', (ev) => {
    ev.preventDefault();
    const [cx, cy] = toCanvas(ev);
    zoom(ev.deltaY < 0 ? 1.2 : 1 / 1.2, cx, cy);
  }, { passive: false });
  let drag = null;
  canvas.addEventListener('pointerdown', (ev) => { drag = toCanvas(ev); canvas.setPointerCapture(ev.pointerId); });
  canvas.addEventListener('pointermove', (ev) => {
    if (!drag) return;
    const [cx, cy] = toCanvas(ev);
    view.ox += cx - drag[0];
    view.oy += cy - drag[1];
    drag = [cx, cy];
    draw();
  });
  canvas.addEventListener('pointerup', () => { drag = null; });
  show(frameCount - 1);
  return () => { loading++; if (controller) controller.abort(); };
}
