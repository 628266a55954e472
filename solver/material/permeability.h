/*
 * permeability.h - how a soil point's hydraulic conductivity follows its deformation (000 step 8g).
 *
 * k enters the drag as n^2 rho_w g / k (000 Eq. 15); it is Darcy's conductivity for the flux of
 * water relative to the soil, n (v_w - v_s) = -(k / (rho_w g)) grad p. The laws, chosen per body by
 * `permeability_law` (enum permeability_law in case.h), with n0, k0 the initial values and
 * J = V / V0 = (1 + e)/(1 + e0) the soil point's volume ratio:
 *  - constant:             k = k0
 *  - kozeny_carman:        k = C1 n^3 / (1 - n)^2, C1 = k0 (1 - n0)^2 / n0^3 (000 step 8g)
 *  - volume_ratio:         k = k0 J
 *  - volume_ratio_squared: k = k0 J^2, the law under which Xie and Leo's large-strain solution
 *                          (000 Eqs. 87-90) is exact: with (1 + e) = (1 + e0) exp(-m_v sigma') the
 *                          Gibson equation becomes linear in exp(m_v p) only if k / (1 + e) grows
 *                          like (1 + e) (docs/numerics.md, "Xie-Leo permeability").
 */
#ifndef PORO_PERMEABILITY_H
#define PORO_PERMEABILITY_H

#include "case.h"

/* Conductivity, m/s, of a point of initial conductivity k0 and porosity n0 that now has porosity n
 * and volume ratio J (0 < n0, n < 1; J > 0, as the caller has checked). */
double permeability_conductivity(enum permeability_law law, double k0, double n0, double n, double J);

/* Standard gravity in the drag term n^2 rho_w g / k (000 Eq. 15, 002 Eq. 12): hydraulic
 * conductivity is defined with it, so it stays 9.81 m/s^2 even when a case switches the body force
 * off. */
#define CONDUCTIVITY_GRAVITY 9.81

#endif
