/*
 * material_mohr_coulomb_dilation.c - Mohr-Coulomb whose dilation angle evolves with the
 * deviatoric plastic strain (001 §4.2.2, Eq. 17, after Lei et al. 2020).
 *
 *     psi(eps_d) = psi_crit + (psi_ini - psi_crit) exp(-eta eps_d)            (001 Eq. 17)
 *
 * Cohesion and friction angle are constant. 001 Table 3 lists eta = -25 next to this equation,
 * which would make psi run away from its critical value; the text says psi evolves "towards its
 * (nil) critical state value", so eta here is the decay rate and must be >= 0 (25 for the
 * paper's sand; the loader says so when given a negative value). After a strength reduction
 * (000 Eq. 91) psi never exceeds the reduced friction angle. State: slot 0 eps_d; the backward
 * Euler return evaluates psi at eps_d^{n+1} (principal_return.c).
 */
#include <math.h>

#include "principal_return.h"

void mohr_coulomb_dilation_law(const struct material *m, double eps_d, struct plastic_law *law)
{
	double decay = exp(-m->eta * eps_d);
	double psi = m->psi_crit + (m->psi_ini - m->psi_crit) * decay;
	double dpsi = -m->eta * (m->psi_ini - m->psi_crit) * decay;
	if (psi > m->phi) {
		psi = m->phi;
		dpsi = 0.0;
	}
	law->c = m->cohesion;
	law->dc = 0.0;
	law->sin_psi = sin(psi);
	law->dsin_psi = cos(psi) * dpsi;
}

enum poro_status mohr_coulomb_dilation_update(const struct material *m, struct stress_update *u,
					      struct poro_error *err)
{
	return principal_update(m, mohr_coulomb_dilation_law, u, err);
}
