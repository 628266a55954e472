/*
 * material_tresca_softening.c - Tresca with linear softening of the cohesion (001 §4.2.1).
 *
 * The undrained strength of 001's softening clay: Mohr-Coulomb with phi = psi = 0 (isochoric
 * plastic flow, yield s1 - s3 = 2 c), whose cohesion falls linearly from its peak c_p to its
 * residual c_r as the accumulated deviatoric plastic strain eps_d grows from 0 to eps_p^r, and
 * stays at c_r beyond (001 Table 3: c_p = 6.4 kPa, c_r = 3.6 kPa, eps_p^r = 0.75):
 *     c(eps_d) = c_p - (c_p - c_r) eps_d / eps_p^r   (eps_d < eps_p^r),   c_r otherwise.
 * The return is principal_return.c's Newton iteration (the kink at eps_p^r costs one more
 * iteration). State: slot 0 eps_d.
 */
#include "principal_return.h"

void tresca_softening_law(const struct material *m, double eps_d, struct plastic_law *law)
{
	double slope = (m->cohesion - m->residual_cohesion) / m->residual_plastic_strain;
	if (eps_d < m->residual_plastic_strain) {
		law->c = m->cohesion - slope * eps_d;
		law->dc = -slope;
	} else {
		law->c = m->residual_cohesion;
		law->dc = 0.0;
	}
	law->sin_psi = 0.0;
	law->dsin_psi = 0.0;
}

enum poro_status tresca_softening_update(const struct material *m, struct stress_update *u,
					 struct poro_error *err)
{
	return principal_update(m, tresca_softening_law, u, err);
}
