/*
 * gibson.h - a brute-force reference for one-dimensional large-strain consolidation: Gibson's
 * equation in the initial (Lagrangian) depth z of a column of height H drained at the top,
 *     dJ/dt = d/dz [ k(J) / (rho_w g J) dp/dz ],   J = (1 + e)/(1 + e0) = exp(-m_v (q - p)),
 * integrated explicitly by finite volumes on GIBSON_CELLS cells, with any of the solver's
 * permeability laws (solver/material/permeability.c). The constitutive law J = exp(-m_v sigma')
 * is the one the rate-form linear elastic model gives in one dimension with nu = 0 (spec-002 §6),
 * and the fluid is incompressible. Used by tests/solver/permeability_test.c (against Xie and Leo's
 * closed form) and tests/verify/consolidation_002_test.c (002 §4.1.2 with constant conductivity).
 */
#ifndef PORO_TEST_GIBSON_H
#define PORO_TEST_GIBSON_H

#include <math.h>

#include "permeability.h"

#define GIBSON_CELLS 100
#define GIBSON_G 9.81           /* m/s^2, in the conductivity's definition */
struct gibson_column {
	double H, mv, q, k0, n0, rho_w;   /* n0: initial porosity, for the laws that use it */
	enum permeability_law law;
	double p[GIBSON_CELLS];   /* excess pore pressure at the cell centres, Pa */
	double J[GIBSON_CELLS];   /* volume ratio of each cell */
	double t;                 /* s */
};

static inline void gibson_start(struct gibson_column *c)
{
	for (int i = 0; i < GIBSON_CELLS; i++)
		c->p[i] = c->q, c->J[i] = 1.0;   /* undrained at t = 0+: the water carries q */
	c->t = 0.0;
}

/* k / (rho_w g J) at a cell, the coefficient of dp/dz in the Lagrangian flux. */
static inline double flux_coefficient(const struct gibson_column *c, double J)
{
	double n = 1.0 - (1.0 - c->n0) / J;
	return permeability_conductivity(c->law, c->k0, c->n0, n, J) / (c->rho_w * GIBSON_G * J);
}

/* Explicit steps to time t_end; the top face (z = 0) is drained, the base impermeable. */
static inline void gibson_advance(struct gibson_column *c, double t_end)
{
	const double dz = c->H / GIBSON_CELLS;
	const double cv = c->k0 / (c->rho_w * GIBSON_G * c->mv);
	/* the diffusivity k / (rho_w g m_v J^2) stays below 2 cv for J > 0.7 and every law here */
	const double dt_max = 0.2 * dz * dz / (2.0 * cv);
	double flux[GIBSON_CELLS + 1];
	while (c->t < t_end) {
		double dt = fmin(dt_max, t_end - c->t);
		flux[0] = flux_coefficient(c, c->J[0]) * (c->p[0] - 0.0) / (0.5 * dz);   /* into the drain */
		for (int i = 1; i < GIBSON_CELLS; i++) {
			double a = 0.5 * (flux_coefficient(c, c->J[i - 1]) + flux_coefficient(c, c->J[i]));
			flux[i] = a * (c->p[i] - c->p[i - 1]) / dz;
		}
		flux[GIBSON_CELLS] = 0.0;
		for (int i = 0; i < GIBSON_CELLS; i++) {
			c->J[i] += dt * (flux[i + 1] - flux[i]) / dz;
			c->p[i] = c->q + log(c->J[i]) / c->mv;
		}
		c->t += dt;
	}
}

/* Settlement of the soil at reference height y0 above the base: the compression of the cells
 * below it (cell i lies at depth i dz from the top). */
static inline double gibson_settlement_at(const struct gibson_column *c, double y0)
{
	const double dz = c->H / GIBSON_CELLS;
	double s = 0.0;
	for (int i = 0; i < GIBSON_CELLS; i++) {
		const double bottom = c->H - (i + 1) * dz, top = fmin(c->H - i * dz, y0);
		if (top > bottom)
			s += (1.0 - c->J[i]) * (top - bottom);
	}
	return s;
}

static inline double gibson_settlement(const struct gibson_column *c)
{
	double s = 0.0;
	for (int i = 0; i < GIBSON_CELLS; i++)
		s += (1.0 - c->J[i]) * c->H / GIBSON_CELLS;
	return s;
}

#endif
