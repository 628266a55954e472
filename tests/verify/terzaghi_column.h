/*
 * terzaghi_column.h - one scheme's run of a Terzaghi column against the closed form (analytic.h),
 * shared by the schemes' consolidation tests: the column's parameters from its case (the first
 * body, its first load the top's traction), the RMS of the pore pressure over the points at their
 * reference heights (column.h), the top row's settlement, and the run sampled at a list of Tv.
 */
#ifndef PORO_TEST_TERZAGHI_COLUMN_H
#define PORO_TEST_TERZAGHI_COLUMN_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "analytic.h"
#include "case.h"
#include "column.h"
#include "poro.h"

#define TERZAGHI_G 9.81

struct column {
	double H, q, k, rho_w, mv;
};

static inline struct column column_of(const struct case_spec *c)
{
	const struct case_material *m = &c->materials[0];
	const double nu = m->poisson_ratio, E = m->youngs_modulus;
	return (struct column){
		.H = c->bodies[0].max[1] - c->bodies[0].min[1],
		.q = -c->loads[0].traction[1],
		.k = c->bodies[0].hydraulic_conductivity,
		.rho_w = c->fluid.density,
		.mv = (1 + nu) * (1 - 2 * nu) / ((1 - nu) * E),
	};
}

/* RMS of (p - p_Terzaghi) / q over the pressure points, each at the soil's reference height. */
static inline double terzaghi_rms(const struct sim *s, const struct column *col, double Tv)
{
	const idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * n), *x = malloc(sizeof(double) * 2 * n), sum = 0.0;
	sim_pore_pressure(s, p, x);
	for (idx_t i = 0; i < n; i++) {
		const double y = soil_reference_height(s, x[2 * i + 1], col->H);
		const double e = p[i] - terzaghi_pressure(col->H - y, col->H, Tv, col->q);
		sum += e * e;
	}
	free(p);
	free(x);
	return sqrt(sum / n) / col->q;
}

/* Largest error of the top row's settlement against the closed form at each point's reference
 * height, relative to the closed form's settlement of the surface. */
static inline double settlement_error(const struct sim *s, const struct column *col, double Tv)
{
	const struct particles *p = sim_soil(s);
	double top0 = 0.0, worst = 0.0;
	for (idx_t q = 0; q < p->n; q++)
		top0 = fmax(top0, p->x0[2 * q + 1]);
	const double surface = terzaghi_settlement(col->H, col->H, Tv, col->q, col->mv, 0);
	for (idx_t q = 0; q < p->n; q++) {
		if (p->x0[2 * q + 1] < top0 - 1e-9)
			continue;
		const double settled = p->x0[2 * q + 1] - p->x[2 * q + 1];
		const double closed = terzaghi_settlement(p->x0[2 * q + 1], col->H, Tv, col->q, col->mv, 0);
		worst = fmax(worst, fabs(settled - closed) / surface);
	}
	return worst;
}

/* Steps s to time t; 0 on a solver failure (printed). */
static inline int advance(struct sim *s, double t, double dt)
{
	const long target = lround(t / dt);
	while (sim_steps_taken(s) < target)
		if (sim_step(s)) {
			printf("INFO solver failed: %s\n", sim_error(s)->message);
			return 0;
		}
	return 1;
}

#define TV_COUNT 5
static const double TVS[TV_COUNT] = {0.05, 0.1, 0.2, 0.5, 1.0};

/* One scheme's run of a Terzaghi column: the RMS error, the settlement error and the base and
 * mid-height probes (pore_pressure_base, pore_pressure_mid: probes 0 and 1 of both cases) at each
 * Tv. Returns 0 on failure. */
struct column_run {
	double rms[TV_COUNT], settlement[TV_COUNT], base[TV_COUNT], mid[TV_COUNT];
	double mass_drift;
};

static inline int run_terzaghi(struct case_spec *c, int count, struct column_run *r)
{
	struct poro_error err = {0};
	struct sim *s = NULL;
	if (sim_create(&s, c, &err)) {
		printf("INFO cannot build: %s\n", err.message);
		return 0;
	}
	const struct column col = column_of(c);
	const double cv = col.k / (col.rho_w * TERZAGHI_G * col.mv), m0 = sim_soil_mass(s);
	int ok = 1;
	r->mass_drift = 0.0;
	for (int i = 0; ok && i < count; i++) {
		ok = advance(s, TVS[i] * col.H * col.H / cv, c->time.dt);
		if (!ok)
			break;
		r->rms[i] = terzaghi_rms(s, &col, TVS[i]);
		r->settlement[i] = settlement_error(s, &col, TVS[i]);
		r->base[i] = sim_probe_value(s, 0) / col.q;
		r->mid[i] = sim_probe_value(s, 1) / col.q;
		r->mass_drift = fmax(r->mass_drift, fabs(sim_soil_mass(s) - m0) / m0);
	}
	sim_destroy(&s);
	return ok;
}

#endif
