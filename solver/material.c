/* material.c - constitutive model dispatch and shared helpers (see material.h). */
#include "material.h"

#include <math.h>
#include <string.h>

void material_init(struct material *m, const struct case_material *spec)
{
	memset(m, 0, sizeof *m);
	m->model = spec->model;
	m->density = spec->density;
	m->E = spec->youngs_modulus;
	m->nu = spec->poisson_ratio;
	m->mu = m->E / (2.0 * (1.0 + m->nu));
	m->lambda = m->E * m->nu / ((1.0 + m->nu) * (1.0 - 2.0 * m->nu));
	m->bulk = m->lambda + 2.0 * m->mu / 3.0;
	m->constrained = m->lambda + 2.0 * m->mu;
}

void material_init_state(const struct material *m, const double *stress, double *Be, double *state)
{
	memset(state, 0, sizeof(double) * STATE_MAX);
	if (m->model == MODEL_HENCKY) {
		hencky_init_state(m, stress, Be);
		return;
	}
	Be[0] = Be[1] = Be[3] = 1.0;
	Be[2] = 0.0;
}

enum poro_status material_update(const struct material *m, struct stress_update *u, struct poro_error *err)
{
	switch (m->model) {
	case MODEL_LINEAR_ELASTIC:
		linear_elastic_update(m, u);
		return PORO_OK;
	case MODEL_HENCKY:
		return hencky_update(m, u, err);
	}
	return poro_error_set(err, PORO_EINVAL, "unknown material model %d", (int)m->model);
}

void sym2_eigen(double xx, double yy, double xy, double l[2], double *theta)
{
	double mean = 0.5 * (xx + yy), half = 0.5 * (xx - yy);
	double r = hypot(half, xy);
	l[0] = mean + r;
	l[1] = mean - r;
	*theta = 0.5 * atan2(xy, half);
}
