/*
 * deformation.c - the soil points' kinematics every scheme shares (000 §4.5 step 8b-g): the
 * deformation-gradient increment from a nodal displacement increment, and from it the deformation
 * gradient, volume, Jacobian, porosity and conductivity. A scheme may change the increment between
 * the two (the F-bar family of fbar.c, 000 step 9; a strain-rate smoothing), so that volume,
 * porosity and stress all see the same dF.
 */
#include "permeability.h"
#include "phases.h"
#include "transfer.h"

void deformation_increment(struct sim *s, const double *du)
{
	struct particles *p = &s->soil;
	g2p_vector_gradient(&s->grid, p, du, p->dF);
	if (s->spec->formulation.position_update == POSITION_UPDATE_MUSL_DISPLACEMENT) {
		/* 7b from the field whose gradient is dF, so volume and motion stay one (phases.h) */
		g2p_vector(&s->grid, p, du, s->soil_grad);
		#pragma omp parallel for schedule(static)
		for (idx_t k = 0; k < DIM * p->n; k++)
			p->x[k] += s->soil_grad[k];
	}
	#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		p->dF[4 * q] += 1.0, p->dF[4 * q + 3] += 1.0;
	}
}

/* Step 8d-g at point q for a volume change dJ: F <- dF F, V <- dJ V, and the porosity and
 * conductivity of J = V / V0. Returns 0 when the point inverted or its porosity left (0, 1). */
static inline int apply_point(struct sim *s, idx_t q, double dJ)
{
	struct particles *p = &s->soil;
	double *dF = p->dF + 4 * q, *F = p->F + 4 * q;
	double F0 = dF[0] * F[0] + dF[1] * F[2], F1 = dF[0] * F[1] + dF[1] * F[3];
	double F2 = dF[2] * F[0] + dF[3] * F[2], F3 = dF[2] * F[1] + dF[3] * F[3];
	F[0] = F0, F[1] = F1, F[2] = F2, F[3] = F3;
	p->volume[q] *= dJ;
	double J = p->volume[q] / p->volume0[q];
	double n = 1.0 - (1.0 - p->porosity0[q]) / J;
	if (!(dJ > 0.0) || !(n > 0.0 && n < 1.0))
		return 0;
	p->porosity[q] = n;
	const struct case_body *body = &s->spec->bodies[p->body[q]];
	p->conductivity[q] = permeability_conductivity(body->permeability_law, body->hydraulic_conductivity,
						       p->porosity0[q], n, J);   /* (8g) */
	return 1;
}

static enum poro_status inverted(struct sim *s, idx_t bad)
{
	const struct particles *p = &s->soil;
	return poro_error_set(&s->err, PORO_ESOLVER, "soil point %ld at (%.6g, %.6g) m: volume ratio %.6g "
			      "gives porosity outside (0, 1) or an inverted point at step %ld (J must stay "
			      "above 1 - n0 = %.6g, where the pores close)",
			      (long)bad, p->x[2 * bad], p->x[2 * bad + 1], p->volume[bad] / p->volume0[bad],
			      s->step + 1, 1.0 - p->porosity0[bad]);
}

/* Every point is updated, in parallel; the failure reported is the lowest-numbered failing
 * point's, as a serial loop stopping at the first would report it, at any thread count. */
enum poro_status deformation_apply(struct sim *s)
{
	const struct particles *p = &s->soil;
	idx_t bad = p->n;
	#pragma omp parallel for schedule(static) reduction(min : bad)
	for (idx_t q = 0; q < p->n; q++) {
		const double *dF = p->dF + 4 * q;
		if (!apply_point(s, q, dF[0] * dF[3] - dF[1] * dF[2]))
			bad = q < bad ? q : bad;
	}
	return bad < p->n ? inverted(s, bad) : PORO_OK;
}

enum poro_status deformation_apply_volumetric(struct sim *s, const double *rate)
{
	const struct particles *p = &s->soil;
	idx_t bad = p->n;
	#pragma omp parallel for schedule(static) reduction(min : bad)
	for (idx_t q = 0; q < p->n; q++)
		if (!apply_point(s, q, 1.0 + s->dt * rate[q]))
			bad = q < bad ? q : bad;
	return bad < p->n ? inverted(s, bad) : PORO_OK;
}
