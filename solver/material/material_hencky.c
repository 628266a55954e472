/*
 * material_hencky.c - Hencky hyperelasticity at finite strain, plane strain (000 Eqs. 69-76).
 *
 * Symbols: Be elastic left Cauchy-Green tensor, updated as Be_trial = dF Be dF^T (Eq. 70); its
 * eigenvalues are the squared principal stretches (Eq. 73); the logarithmic strain is
 * E = 1/2 ln Be (Eqs. 72, 74); the Kirchhoff stress is tau = lambda tr(E) I + 2 mu E, coaxial with
 * Be (Eq. 75 with the elastic operator); the Cauchy stress is sigma = tau / J (Eq. 76).
 * Plane strain: dF_zz = 1, so Be_zz is carried unchanged by elastic steps (the element driver may
 * stretch z: Be_zz picks up dF_zz^2). Tangent: d tau / d eps_trial is the constant elastic matrix
 * (material.h).
 */
#include "material.h"

#include <math.h>

enum poro_status hencky_update(const struct material *m, struct stress_update *u, struct poro_error *err)
{
	const double *f = u->dF;
	double *Be = u->Be;
	/* Be_trial = dF Be dF^T, with Be = [[Be0, Be2], [Be2, Be1]] */
	double a0 = f[0] * Be[0] + f[1] * Be[2], a1 = f[0] * Be[2] + f[1] * Be[1];
	double b0 = f[2] * Be[0] + f[3] * Be[2], b1 = f[2] * Be[2] + f[3] * Be[1];
	double bxx = a0 * f[0] + a1 * f[1];
	double bxy = a0 * f[2] + a1 * f[3];
	double byy = b0 * f[2] + b1 * f[3];
	double bzz = u->dF_zz != 0.0 ? u->dF_zz * Be[3] * u->dF_zz : Be[3];
	double l[2], theta;
	sym2_eigen(bxx, byy, bxy, l, &theta);
	if (!(l[1] > 0.0) || !(bzz > 0.0) || !(u->J > 0.0))
		return poro_error_set(err, PORO_ESOLVER, "hencky: non-positive stretch (%.3g, %.3g), J = %.3g",
				      l[0], l[1], u->J);
	double e1 = 0.5 * log(l[0]), e2 = 0.5 * log(l[1]), ez = 0.5 * log(bzz);
	double lt = m->lambda * (e1 + e2 + ez);
	double t1 = lt + 2.0 * m->mu * e1, t2 = lt + 2.0 * m->mu * e2, tz = lt + 2.0 * m->mu * ez;
	double c = cos(theta), s = sin(theta), invJ = 1.0 / u->J;
	u->stress[0] = (c * c * t1 + s * s * t2) * invJ;
	u->stress[1] = (s * s * t1 + c * c * t2) * invJ;
	u->stress[2] = c * s * (t1 - t2) * invJ;
	u->stress[3] = tz * invJ;
	Be[0] = bxx, Be[1] = byy, Be[2] = bxy, Be[3] = bzz;
	if (u->tangent)
		material_elastic_tangent(m, u->tangent);
	return PORO_OK;
}

/* Be = exp(2 E) with E = C^-1 : tau, tau = sigma at J = 1 (the initial configuration). */
void hencky_init_state(const struct material *m, const double *stress, double *Be)
{
	double l[2], theta;
	sym2_eigen(stress[0], stress[1], stress[2], l, &theta);
	double t[3] = {l[0], l[1], stress[3]};
	double tr = t[0] + t[1] + t[2];
	double e[3];
	for (int i = 0; i < 3; i++)   /* isotropic inverse: E = (tau - lambda/(3 lambda + 2 mu) tr tau I) / 2 mu */
		e[i] = (t[i] - m->lambda / (3.0 * m->lambda + 2.0 * m->mu) * tr) / (2.0 * m->mu);
	double b1 = exp(2.0 * e[0]), b2 = exp(2.0 * e[1]);
	double c = cos(theta), s = sin(theta);
	Be[0] = c * c * b1 + s * s * b2;
	Be[1] = s * s * b1 + c * c * b2;
	Be[2] = c * s * (b1 - b2);
	Be[3] = exp(2.0 * e[2]);
}
