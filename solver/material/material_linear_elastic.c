/*
 * material_linear_elastic.c - small-strain isotropic linear elasticity, plane strain.
 *
 * The strain increment is the symmetric part of dF - I (the displacement-gradient increment of
 * the step); the stress increment is lambda tr(d eps) I + 2 mu d eps with d eps_zz = 0, so
 * sigma_zz picks up lambda tr(d eps). No rotation correction: this is the small-strain model the
 * papers' small-deformation benchmarks (Terzaghi, 000 §5.1) and 000 §5.2's comparison use.
 * The element driver may stretch z (u->dF_zz); the tangent is the constant elastic matrix.
 */
#include "material.h"

void linear_elastic_update(const struct material *m, struct stress_update *u)
{
	const double *dF = u->dF;
	double exx = dF[0] - 1.0, eyy = dF[3] - 1.0, exy = 0.5 * (dF[1] + dF[2]);
	double ezz = u->dF_zz != 0.0 ? u->dF_zz - 1.0 : 0.0;
	double lt = m->lambda * (exx + eyy + ezz);
	u->stress[0] += lt + 2.0 * m->mu * exx;
	u->stress[1] += lt + 2.0 * m->mu * eyy;
	u->stress[2] += 2.0 * m->mu * exy;
	u->stress[3] += lt + 2.0 * m->mu * ezz;
	if (u->tangent)
		material_elastic_tangent(m, u->tangent);
}
