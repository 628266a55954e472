/*
 * phase_coupling.h - the drag coupling of the soil and water velocities at one node, shared by
 * the predictors (000 Eqs. 52-53), the velocity correction (Eqs. 64-65) and the pressure matrix
 * that must agree with the correction (pressure.c).
 *
 * At a node with soil mass M_s, water mass M_w and drag D = Q_I dt (Eq. 58 times the step), a
 * pair of phase forces (f_s, f_w) changes the velocities by the solution of
 *     M_s dv_s = f_s - D (dv_s - dv_w)
 *     M_w dv_w = f_w - D (dv_w - dv_s)
 * per velocity component. Their sum is the mixture equation (Eq. 52 or 64); the second is the
 * water equation (Eq. 53 or 65) with the drag taken at the new velocities. The matrix
 * K = [[M_s + D, -D], [-D, M_w + D]] is symmetric positive definite (det = M_s M_w + D (M_s + M_w)),
 * so a pressure matrix G^T K^-1 G built from it stays SPD. As D -> 0 the phases decouple (the
 * paper's Eq. 65); as D -> infinity they move together with the mixture mass, which is what lets
 * the step stay independent of permeability (docs/numerics.md).
 *
 * A phase that is constrained in the component, or has no mass at the node, keeps dv = 0; the
 * other phase then feels the drag against it (a wall takes the constrained phase's reaction).
 */
#ifndef PORO_PHASE_COUPLING_H
#define PORO_PHASE_COUPLING_H

/* K^-1 restricted to the free phases: dv_s = ss f_s + sw f_w, dv_w = sw f_s + ww f_w. */
struct phase_coupling {
	double ss, sw, ww;
};

static inline struct phase_coupling phase_coupling_inverse(double Ms, double Mw, double D, int soil_fixed,
							   int water_fixed)
{
	struct phase_coupling k = {0.0, 0.0, 0.0};
	const int soil_free = Ms > 0.0 && !soil_fixed, water_free = Mw > 0.0 && !water_fixed;
	if (!(Ms > 0.0 && Mw > 0.0))
		D = 0.0;   /* drag needs both phases at the node */
	if (soil_free && water_free) {
		const double det = Ms * Mw + D * (Ms + Mw);
		k.ss = (Mw + D) / det, k.sw = D / det, k.ww = (Ms + D) / det;
	} else if (soil_free) {
		k.ss = 1.0 / (Ms + D);
	} else if (water_free) {
		k.ww = 1.0 / (Mw + D);
	}
	return k;
}

#endif
