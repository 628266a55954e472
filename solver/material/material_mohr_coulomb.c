/*
 * material_mohr_coulomb.c - perfectly plastic Mohr-Coulomb with non-associated flow, small or
 * finite strain (000 §4.3: "we strictly follow the algorithm documented by de Souza Neto et al.").
 *
 * Cohesion c, friction angle phi and dilation angle psi are constant (after the strength
 * reduction of 000 Eq. 91, material.c); the return mapping, its regimes (main plane, two edges,
 * apex) and the kinematics are principal_return.c and principal_update.c. State: slot 0 the
 * accumulated deviatoric plastic strain (output only: nothing depends on it).
 */
#include "principal_return.h"

void mohr_coulomb_law(const struct material *m, double eps_d, struct plastic_law *law)
{
	(void)eps_d;
	law->c = m->cohesion;
	law->dc = 0.0;
	law->sin_psi = m->sin_psi;
	law->dsin_psi = 0.0;
}

enum poro_status mohr_coulomb_update(const struct material *m, struct stress_update *u, struct poro_error *err)
{
	return principal_update(m, mohr_coulomb_law, u, err);
}
