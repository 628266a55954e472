// chart.js - line and point charts on uPlot (web/vendor/uplot, the pinned npm package that
// deploy/deps.sh installs). chart(el, spec) draws series that each have their own x values
// (uPlot.join aligns them); a series is a line, or points alone with points: true. What a chart
// shows is kept in window.poroPlots[spec.name] as the series given ({label, x, y}), so what is
// drawn can be read back and checked against the run (tests/web).
import uPlot from '/web/vendor/uplot/uPlot.esm.js';

const COLOURS = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#17becf', '#8c564b', '#e377c2'];
window.poroPlots = window.poroPlots || {};

function finiteSeries(s) {
  const x = [], y = [];
  for (let i = 0; i < s.x.length; i++) {
    if (s.x[i] === null || s.y[i] === null || !isFinite(s.x[i])) continue;
    x.push(s.x[i]);
    y.push(s.y[i] === null || !isFinite(s.y[i]) ? null : s.y[i]);
  }
  return [x, y];
}

// Tick labels with one number of decimals on an axis, as few as write every tick exactly, and
// one power of ten for the whole axis past 1e5 or below 1e-3 (uPlot's own labels print -0 for
// -0.0004, and labels formatted one by one mixed 3e-5 with 2.75e-4 on one axis).
const ticks = (u, values) => {
  const big = Math.max(...values.map(Math.abs));
  const e = big >= 1e5 || (big > 0 && big < 1e-3) ? Math.floor(Math.log10(big)) : 0;
  const scaled = values.map((v) => v / 10 ** e);
  let d = 0;
  while (d < 6 && scaled.some((v) => Math.abs(Number(v.toFixed(d)) - v) > 1e-9 * Math.max(1, Math.abs(v)))) d++;
  return scaled.map((v) => (Math.abs(v) < 0.5 * 10 ** -d ? '0' : e ? `${v.toFixed(d)}e${e}`
    : v.toLocaleString('en', { minimumFractionDigits: d, maximumFractionDigits: d })));
};

// spec: {name, title, xLabel, yLabel, series: [{label, x, y, points, colour, dash}], width, height}
// Returns the uPlot object (destroy() it when the chart goes), or null without data.
export function chart(el, spec) {
  window.poroPlots[spec.name] = { title: spec.title, series: spec.series.map((s) => ({ label: s.label, x: Array.from(s.x), y: Array.from(s.y) })) };
  el.dataset.plot = spec.name;
  const usable = spec.series.filter((s) => s.x.length);
  if (!usable.length) {
    el.append(Object.assign(document.createElement('p'), { className: 'muted', textContent: 'No data yet.' }));
    return null;
  }
  // uPlot.join wants each x ascending: sort a copy of each series by x
  const sorted = usable.map((s) => {
    const [x, y] = finiteSeries(s);
    const order = x.map((_, i) => i).sort((a, b) => x[a] - x[b]);
    return [order.map((i) => x[i]), order.map((i) => y[i])];
  });
  const data = uPlot.join(sorted);
  const series = [{ label: spec.xLabel }].concat(usable.map((s, i) => {
    const colour = s.colour || COLOURS[i % COLOURS.length];
    return s.points
      ? { label: s.label, stroke: colour, fill: colour, paths: () => null, points: { show: true, size: 5, stroke: colour, fill: colour } }
      : { label: s.label, stroke: colour, width: 2, dash: s.dash, spanGaps: true, points: { show: false } };
  }));
  const width = spec.width || Math.max(320, Math.min(el.clientWidth || 720, 900));
  const opts = {
    title: spec.title, width, height: spec.height || 300, series,
    scales: { x: { time: false } },
    axes: [{ label: spec.xLabel, values: ticks }, { label: spec.yLabel, size: 70, values: ticks }],
    legend: { live: false },
  };
  return new uPlot(opts, data, el);
}
