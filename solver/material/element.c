/*
 * element.c - the single-element triaxial driver (element.h; 000 App. B.2).
 *
 * Symbols: dE the axial increment of a step (strain, or logarithmic strain at finite strain),
 * d = (dy, dz) the lateral increments (the same kind), T the consistent tangent of material.h
 * (4x4 over xx, yy, xy, zz), C_ij of 000 Eq. 108 its entries with 1 = x (axial), 2 = y, 3 = z.
 *
 * Drained steps: predictor d_i = -dE C_i1 / (C_i2 + C_i3) (Eqs. 108, 110) with the tangent of
 * the last converged step, then Newton on r = (sigma_y + sigma_z) / 2 + confining_pressure with
 * one lateral increment d = dy = dz (the test is axisymmetric), slope sum_ij J_ij / 2 over
 * i, j in (y, z) with
 *   small strain   d sigma_i / d d_j = T_ij;
 *   finite strain  sigma = tau / J with tau(eps_trial), eps_trial_j = eps_j^t + ln dF_j for the
 *                  axis-aligned state, J = J^t prod dF, so d sigma_i / d ln dF_j = (T_ij - tau_i) / J.
 * Each Newton iterate repeats the step from the saved state of the point.
 */
#include "element.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ELEMENT_STRESS_TOLERANCE 1e-10  /* drained: |sigma_lateral + p_c| / (p_c + |sigma|) per step */
#define ELEMENT_ITERATIONS_MAX 30

/* The material point: what the particle arrays hold for one point. */
struct point {
	double stress[4], Be[4], state[STATE_MAX], plastic_strain, J, tangent[16];
};

/* One step from *from with axial increment dE and lateral increments d[2] into *to. */
static enum poro_status take_step(const struct material *m, const struct point *from, double dE, const double d[2],
				  struct point *to, struct poro_error *err)
{
	int finite = material_is_finite_strain(m);
	*to = *from;
	double fx = finite ? exp(dE) : 1 + dE, fy = finite ? exp(d[0]) : 1 + d[0], fz = finite ? exp(d[1]) : 1 + d[1];
	double dF[4] = { fx, 0, 0, fy };
	to->J = from->J * fx * fy * fz;
	struct stress_update u = { .dF = dF, .dF_zz = fz, .J = to->J, .stress = to->stress, .Be = to->Be,
				   .state = to->state, .plastic_strain = &to->plastic_strain, .tangent = to->tangent };
	return material_update(m, &u, err);
}

/* d sigma_lateral / d d for equal lateral increments: the mean of the lateral block's row sums. */
static double lateral_slope(const struct material *m, const struct point *pt)
{
	static const int lat[2] = { 1, 3 };
	double sum = 0;
	for (int i = 0; i < 2; i++)
		for (int j = 0; j < 2; j++) {
			double t = pt->tangent[4 * lat[i] + lat[j]];
			sum += material_is_finite_strain(m) ? (t - pt->stress[lat[i]] * pt->J) / pt->J : t;
		}
	return sum / 2;
}

/* The test is axisymmetric: y and z take the same lateral increment d. (Two separate unknowns
 * would not do: on an edge of the Mohr-Coulomb hexagon, where triaxial compression lies, the
 * lateral block of the tangent is singular because the two lateral stresses move together.) */
static enum poro_status drained_step(const struct material *m, const struct element_case *c, const struct point *from,
				     double dE, struct point *to, double d[2], long *newton, struct poro_error *err)
{
	const double *C = from->tangent, pc = c->confining_pressure;
	/* Eqs. 108 / 110, the y and z rows averaged */
	d[0] = -0.5 * dE * (C[4 * 1 + 0] / (C[4 * 1 + 1] + C[4 * 1 + 3]) + C[4 * 3 + 0] / (C[4 * 3 + 1] + C[4 * 3 + 3]));
	d[1] = d[0];
	for (int it = 0;; it++) {
		enum poro_status st = take_step(m, from, dE, d, to, err);
		if (st)
			return st;
		double r = 0.5 * (to->stress[1] + to->stress[3]) + pc;
		double scale = pc + fabs(to->stress[0]) + fabs(to->stress[1]) + fabs(to->stress[3]);
		if (fabs(r) <= ELEMENT_STRESS_TOLERANCE * scale) {
			*newton += it;   /* corrections taken; the predictor alone counts none */
			return PORO_OK;
		}
		double slope = lateral_slope(m, to);
		if (it == ELEMENT_ITERATIONS_MAX || !(fabs(slope) > 0))
			return poro_error_set(err, PORO_ESOLVER, "element: lateral stress not held at the confining "
					      "pressure after %d iterations (residual %.3g Pa, slope %.3g Pa)", it, r, slope);
		d[0] -= r / slope;
		d[1] = d[0];
	}
}

static void record(const struct material *m, const struct point *pt, double axial, double volumetric,
		   struct element_row *row)
{
	const double *s = pt->stress;
	row->axial_strain = axial;
	row->p = -(s[0] + s[1] + s[3]) / 3.0;
	row->q = 0.5 * (s[1] + s[3]) - s[0];
	row->volumetric_strain = volumetric;
	memcpy(row->stress, s, sizeof row->stress);
	row->J = pt->J;
	material_state_outputs(m, pt->state, NULL, row->outputs);
}

enum poro_status element_run(const struct element_case *c, struct element_result *r, struct poro_error *err)
{
	static const double zero[2] = { 0, 0 };
	struct material m;
	memset(r, 0, sizeof *r);
	material_init(&m, &c->material);
	r->output_count = material_state_outputs(&m, (double[STATE_MAX]){0}, r->output_names,
						 (double[MATERIAL_OUTPUTS_MAX]){0});
	r->row = calloc((size_t)c->steps + 1, sizeof *r->row);
	if (!r->row)
		return poro_error_set(err, PORO_ENOMEM, "element: cannot allocate %d rows", c->steps + 1);
	struct point a = { .J = 1 }, b;
	double pc = c->confining_pressure;
	a.stress[0] = a.stress[1] = a.stress[3] = -pc;
	material_init_state(&m, a.stress, a.Be, a.state);
	/* a zero step: the tangent at the initial state (and a check that the state is admissible) */
	enum poro_status st = take_step(&m, &a, 0, zero, &b, err);
	if (st)
		return st;
	memcpy(a.tangent, b.tangent, sizeof a.tangent);
	record(&m, &a, 0, 0, &r->row[0]);
	r->rows = 1;
	double dE = c->axial_strain / c->steps, volumetric = 0;
	for (int k = 1; k <= c->steps; k++) {
		double d[2] = { -dE / 2, -dE / 2 };  /* undrained: Eqs. 99, 106 */
		st = c->test == ELEMENT_DRAINED ? drained_step(&m, c, &a, dE, &b, d, &r->newton_iterations, err)
						 : take_step(&m, &a, dE, d, &b, err);
		if (st)
			return st;
		a = b;
		volumetric = material_is_finite_strain(&m) ? log(a.J) : volumetric + dE + d[0] + d[1];
		record(&m, &a, c->axial_strain * k / c->steps, volumetric, &r->row[k]);
		r->rows = k + 1;
	}
	return PORO_OK;
}

void element_result_release(struct element_result *r)
{
	free(r->row);
	r->row = NULL;
	r->rows = 0;
}
