/*
 * biot_column.h - a brute-force reference for a one-dimensional saturated column with a
 * compressible pore fluid and incompressible grains (Biot's quasi-static theory), loaded on top by
 * a traction of any history and by its own weight under a gravity ramp: the reference of 002 §4.3's
 * cyclic load (tests/verify/cyclic_load_002_test.c).
 *
 * Height y up from the impermeable base (y = 0) to the drained top (y = H, p = 0). In one
 * dimension the total vertical stress is known from equilibrium alone (inertia neglected: the
 * column's own period, 4 H / c_undrained, is about 2 ms against the load's 400 ms):
 *     sigma(y, t) = L(t) + rho_sat g(t) (H - y)        (compression positive, L the load on top)
 * and with the effective stress s' = sigma - p, the strain e = s' / M (M the constrained modulus,
 * compression positive), the fluid balance with Darcy's law
 *     (n / K_f + 1 / M) dp/dt = (1 / M) dsigma/dt + d/dy [ k / (rho_w g0) (dp/dy + rho_w g(t)) ]
 * (g0 = 9.81 m/s^2 in the conductivity's definition, g(t) the ramped body force). It is integrated
 * by finite volumes on BIOT_CELLS cells, backward Euler in time (a tridiagonal solve a step), from
 * a stress-free column at t = 0. Settlement of height y: the integral of e from 0 to y.
 */
#ifndef PORO_TEST_BIOT_COLUMN_H
#define PORO_TEST_BIOT_COLUMN_H

#include <math.h>

#define BIOT_CELLS 200
#define BIOT_G0 9.81

struct biot_column {
	double H, M, n, K_f, k, rho_w, rho_sat;   /* m, Pa, -, Pa, m/s, kg/m^3, kg/m^3 */
	double (*load)(double t, const void *user);    /* L(t), Pa, compression positive */
	double (*gravity)(double t, const void *user); /* g(t), m/s^2 (downward magnitude) */
	const void *user;
	double p[BIOT_CELLS];     /* pore pressure at the cell centres, Pa */
	double t;
};

static inline double biot_total_stress(const struct biot_column *c, double y, double t)
{
	return c->load(t, c->user) + c->rho_sat * c->gravity(t, c->user) * (c->H - y);
}

/* Backward-Euler steps of dt to time t_end. */
static inline void biot_advance(struct biot_column *c, double t_end, double dt)
{
	const double dy = c->H / BIOT_CELLS, storage = c->n / c->K_f + 1.0 / c->M, a = c->k / (c->rho_w * BIOT_G0);
	double lower[BIOT_CELLS], diag[BIOT_CELLS], upper[BIOT_CELLS], rhs[BIOT_CELLS];
	while (c->t < t_end - 1e-12) {
		const double h = fmin(dt, t_end - c->t), t1 = c->t + h, g1 = c->gravity(t1, c->user);
		for (int i = 0; i < BIOT_CELLS; i++) {
			const double y = (i + 0.5) * dy;
			const double dsigma = biot_total_stress(c, y, t1) - biot_total_stress(c, y, c->t);
			/* storage (p1 - p0) / h = dsigma / (M h) + (flux_in - flux_out) / dy, flux = -a (dp/dy + rho_w g) */
			lower[i] = upper[i] = 0.0;
			diag[i] = storage / h;
			rhs[i] = storage * c->p[i] / h + dsigma / (c->M * h);
			if (i > 0) {   /* face below: the flux up into the cell is -a ((p_i - p_{i-1}) / dy + rho_w g) */
				lower[i] = -a / (dy * dy);
				diag[i] += a / (dy * dy);
				rhs[i] -= a * c->rho_w * g1 / dy;
			}
			if (i < BIOT_CELLS - 1) {   /* face above, to cell i + 1 */
				upper[i] = -a / (dy * dy);
				diag[i] += a / (dy * dy);
				rhs[i] += a * c->rho_w * g1 / dy;
			} else {   /* the drained top, p = 0 half a cell above the centre */
				diag[i] += 2.0 * a / (dy * dy);
				rhs[i] += a * c->rho_w * g1 / dy;
			}
		}
		for (int i = 1; i < BIOT_CELLS; i++) {   /* the Thomas algorithm */
			const double m = lower[i] / diag[i - 1];
			diag[i] -= m * upper[i - 1];
			rhs[i] -= m * rhs[i - 1];
		}
		c->p[BIOT_CELLS - 1] = rhs[BIOT_CELLS - 1] / diag[BIOT_CELLS - 1];
		for (int i = BIOT_CELLS - 2; i >= 0; i--)
			c->p[i] = (rhs[i] - upper[i] * c->p[i + 1]) / diag[i];
		c->t = t1;
	}
}

/* Pore pressure at height y (linear between the cell centres; the base cell's value below it). */
static inline double biot_pressure(const struct biot_column *c, double y)
{
	const double dy = c->H / BIOT_CELLS, s = y / dy - 0.5;
	if (s <= 0.0)
		return c->p[0];
	const int i = (int)s;
	if (i >= BIOT_CELLS - 1)   /* between the top centre and the drained top */
		return c->p[BIOT_CELLS - 1] * (c->H - y) / (0.5 * dy);
	return c->p[i] + (s - i) * (c->p[i + 1] - c->p[i]);
}

/* Settlement (downward positive) of the soil at height y: the integral of e = (sigma - p) / M. */
static inline double biot_settlement(const struct biot_column *c, double y)
{
	const double dy = c->H / BIOT_CELLS;
	double u = 0.0;
	for (int i = 0; i < BIOT_CELLS && i * dy < y; i++) {
		const double top = fmin((i + 1) * dy, y), yc = 0.5 * (i * dy + top);
		u += (biot_total_stress(c, yc, c->t) - biot_pressure(c, yc)) / c->M * (top - i * dy);
	}
	return u;
}

#endif
