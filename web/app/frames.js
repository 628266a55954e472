// frames.js - the compact frames of a job (docs/web.md, "Frames"): the index from
// GET /v1/jobs/{id}/frames and one frame's points from GET /v1/jobs/{id}/frames/{n}, decoded
// into Float32Array views per point set: {soil: {count, x, y, pore_pressure, ...}, water: {...}}.
import { get, bytes } from './api.js';

export const loadIndex = (id) => get(`/v1/jobs/${id}/frames`);

export async function loadFrame(id, index, n, signal) {
  const buf = await bytes(`/v1/jobs/${id}/frames/${n}`, { signal });
  const frame = index.frames[n];
  const out = { index: n, time: frame.time };
  let offset = 0;
  for (const [set, arrays] of Object.entries(index.sets)) {
    const count = frame.counts[set] || 0;
    const s = { count };
    for (const name of arrays) {
      if ((offset + count) * 4 > buf.byteLength) throw new Error(`frame ${n}: ${buf.byteLength} bytes, shorter than its index says`);
      s[name] = new Float32Array(buf, offset * 4, count);
      offset += count;
    }
    out[set] = s;
  }
  return out;
}
