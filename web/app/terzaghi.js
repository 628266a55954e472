// terzaghi.js - Terzaghi's closed form for a consolidating column, as tools/terzaghi_error.c and
// tests/verify/analytic.h compute it (000 Eqs. 84-86): excess pore pressure
//   p(z, t) = q sum_m (2/M) sin(M z / Hd) exp(-M^2 Tv),  M = (m + 1/2) pi,  Tv = c_v t / Hd^2,
//   c_v = k / (rho_w g m_v),  m_v = (1 + nu)(1 - 2 nu) / ((1 - nu) E),
// z the depth below the drained top (the distance to the nearer drained face when the bottom
// drains too), Hd the drainage length. column() reads the column from a case: the first body
// (a rectangle), its material, the first load's traction, the bottom face's drainage.
const G = 9.81, TERMS = 400;

export function column(c) {
  const b = (c.bodies || [])[0], load = (c.loads || [])[0];
  if (!b || !b.rectangle || !load || !load.traction || load.from !== undefined || load.to !== undefined) return null;
  const m = (c.materials || []).find((x) => x.name === b.material);
  if (!m || m.youngs_modulus === undefined) return null;
  const nu = m.poisson_ratio || 0, E = m.youngs_modulus;
  const mv = (1 + nu) * (1 - 2 * nu) / ((1 - nu) * E);
  const bottom = ((c.boundaries || {}).bottom || {});
  const drainedBoth = bottom.drainage === 'drained';
  const top = b.rectangle.max[1], base = b.rectangle.min[1];
  const Hd = (top - base) / (drainedBoth ? 2 : 1);
  const q = Math.hypot(load.traction[0], load.traction[1]);
  const cv = b.hydraulic_conductivity / (((c.fluid || {}).density || 1000) * G * mv);
  return q > 0 && Hd > 0 ? { q, top, base, Hd, cv, drainedBoth } : null;
}

export function pressure(col, y, t) {
  let z = col.top - y;
  if (col.drainedBoth) z = Math.min(z, y - col.base);
  if (z <= 0) return 0;
  const Tv = col.cv * t / (col.Hd * col.Hd);
  let sum = 0;
  for (let m = 0; m < TERMS; m++) {
    const M = (m + 0.5) * Math.PI;
    sum += 2 / M * Math.sin(M * z / col.Hd) * Math.exp(-M * M * Tv);
  }
  return col.q * sum;
}
