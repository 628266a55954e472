/* material.c - constitutive model dispatch and shared helpers (see material.h). */
#include "material.h"

#include <math.h>
#include <string.h>

#include "principal_return.h"

static const double DEGREE = 0.017453292519943295769;   /* pi / 180 */

/* Strength reduction, 000 Eq. 91: c_f = c / SRF, phi_f = arctan(tan(phi) / SRF). The paper reduces
 * c and phi only (its Table 3 has psi = 0); a dilation angle above the reduced friction angle is
 * capped at it (the flow would otherwise dilate more than the strength mobilises). */
static void init_plastic(struct material *m, const struct case_material *spec)
{
	double srf = spec->strength_reduction_factor > 0 ? spec->strength_reduction_factor : 1.0;
	m->srf = srf;
	m->phi = atan(tan(spec->friction_angle * DEGREE) / srf);
	m->psi = fmin(spec->dilation_angle * DEGREE, m->phi);
	m->psi_ini = spec->initial_dilation_angle * DEGREE;
	m->psi_crit = spec->critical_dilation_angle * DEGREE;
	m->eta = spec->dilation_evolution_parameter;
	m->sin_phi = sin(m->phi), m->cos_phi = cos(m->phi), m->sin_psi = sin(m->psi);
	if (m->model == MODEL_TRESCA_SOFTENING) {
		m->cohesion = spec->peak_cohesion / srf;
		m->residual_cohesion = spec->residual_cohesion / srf;
		m->residual_plastic_strain = spec->residual_plastic_strain;
	} else {
		m->cohesion = spec->cohesion / srf;
	}
}

/* Nor-Sand: the shear modulus is mu; Young's modulus and the Lame lambda have no meaning (the bulk
 * modulus p / kappa depends on the pressure) and stay 0. */
static void init_nor_sand(struct material *m, const struct case_material *spec)
{
	struct nor_sand_parameters *n = &m->ns;
	m->mu = spec->shear_modulus;
	m->E = m->nu = m->lambda = m->bulk = m->constrained = 0.0;
	n->kappa = spec->swelling_index;
	n->lambda = spec->compression_index;
	n->v_c0 = spec->reference_specific_volume;
	n->p_ref = spec->critical_state_reference_pressure > 0 ? spec->critical_state_reference_pressure : 1e3;
	n->M = spec->critical_stress_ratio;
	n->N = spec->yield_function_constant;
	n->N_bar = spec->plastic_potential_constant;
	n->h = spec->hardening_coefficient;
	n->alpha = spec->dilatancy_multiplier;
	n->v0 = spec->initial_specific_volume;
	n->ocr = spec->overconsolidation_ratio > 0 ? spec->overconsolidation_ratio : 1.0;
	n->p_start = spec->initial_reference_pressure > 0 ? spec->initial_reference_pressure : 2e3;
	n->through_stress = spec->yield_surface_through_stress;
	n->cutoff_start = spec->dilatancy_cutoff_start;
	n->cutoff_end = spec->dilatancy_cutoff_end > spec->dilatancy_cutoff_start ? spec->dilatancy_cutoff_end
										 : spec->dilatancy_cutoff_start + 0.5;
	n->gas_ratio = spec->gas_volume_ratio > 1 ? spec->gas_volume_ratio : 1.6;
}

void material_init(struct material *m, const struct case_material *spec)
{
	memset(m, 0, sizeof *m);
	m->model = spec->model;
	m->strain = spec->model == MODEL_LINEAR_ELASTIC ? STRAIN_SMALL
		    : spec->model == MODEL_HENCKY ? STRAIN_FINITE : spec->strain;
	m->density = spec->density;
	m->E = spec->youngs_modulus;
	m->nu = spec->poisson_ratio;
	m->mu = m->E / (2.0 * (1.0 + m->nu));
	m->lambda = m->E * m->nu / ((1.0 + m->nu) * (1.0 - 2.0 * m->nu));
	m->bulk = m->lambda + 2.0 * m->mu / 3.0;
	m->constrained = m->lambda + 2.0 * m->mu;
	m->cos_phi = 1.0;
	if (m->model == MODEL_NOR_SAND)
		init_nor_sand(m, spec);
	else if (m->model != MODEL_LINEAR_ELASTIC && m->model != MODEL_HENCKY)
		init_plastic(m, spec);
}

int material_is_finite_strain(const struct material *m)
{
	return m->strain == STRAIN_FINITE;
}

void material_init_state(const struct material *m, const double *stress, double *Be, double *state)
{
	memset(state, 0, sizeof(double) * STATE_MAX);
	if (m->model == MODEL_NOR_SAND) {
		nor_sand_init_state(m, stress, Be, state);
		return;
	}
	if (material_is_finite_strain(m)) {
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
	case MODEL_MOHR_COULOMB:
		return mohr_coulomb_update(m, u, err);
	case MODEL_TRESCA_SOFTENING:
		return tresca_softening_update(m, u, err);
	case MODEL_MOHR_COULOMB_DILATION:
		return mohr_coulomb_dilation_update(m, u, err);
	case MODEL_NOR_SAND:
		return nor_sand_update(m, u, err);
	}
	return poro_error_set(err, PORO_EINVAL, "unknown material model %d", (int)m->model);
}

int material_state_outputs(const struct material *m, const double *state, const char **names, double *values)
{
	static const char *const eps_d = "deviatoric_plastic_strain";
	struct plastic_law law;
	int n = 0;
	if (m->model == MODEL_LINEAR_ELASTIC || m->model == MODEL_HENCKY)
		return 0;
	if (m->model == MODEL_NOR_SAND)
		return nor_sand_state_outputs(m, state, names, values);
	if (names)
		names[n] = eps_d;
	values[n++] = state[STATE_DEVIATORIC_PLASTIC_STRAIN];
	if (m->model == MODEL_TRESCA_SOFTENING) {
		tresca_softening_law(m, state[STATE_DEVIATORIC_PLASTIC_STRAIN], &law);
		if (names)
			names[n] = "cohesion";
		values[n++] = law.c;
	} else if (m->model == MODEL_MOHR_COULOMB_DILATION) {
		mohr_coulomb_dilation_law(m, state[STATE_DEVIATORIC_PLASTIC_STRAIN], &law);
		if (names)
			names[n] = "dilation_angle";
		values[n++] = asin(law.sin_psi) / DEGREE;
	}
	return n;
}

void material_elastic_tangent(const struct material *m, double *T)
{
	static const int normal[4] = { 1, 1, 0, 1 };   /* xx, yy, xy, zz */
	for (int i = 0; i < 4; i++)
		for (int j = 0; j < 4; j++)
			T[4 * i + j] = m->lambda * normal[i] * normal[j] + (i == j ? 2.0 * m->mu : 0.0);
}

void sym2_eigen(double xx, double yy, double xy, double l[2], double *theta)
{
	double mean = 0.5 * (xx + yy), half = 0.5 * (xx - yy);
	double r = hypot(half, xy);
	l[0] = mean + r;
	l[1] = mean - r;
	*theta = 0.5 * atan2(xy, half);
}
