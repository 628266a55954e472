/*
 * permeability_test.c - the conductivity laws of solver/material/permeability.c, and why the Xie-Leo cases
 * use k = k0 (V/V0)^2.
 *
 * Oracles:
 *  - each law's closed form at random porosities and volume ratios (Kozeny-Carman also returns k0
 *    in the initial state);
 *  - a brute-force finite-volume solution of Gibson's one-dimensional large-strain consolidation
 *    equation, in the initial (Lagrangian) depth z of a column of height H drained at the top,
 *        dJ/dt = d/dz [ k(J) / (rho_w g J) dp/dz ],   J = (1 + e)/(1 + e0) = exp(-m_v (q - p)),
 *    integrated explicitly on 100 cells, against Xie and Leo's closed form (000 Eqs. 87 and 90,
 *    solver/verify/analytic.h). With k = k0 J^2 the equation is linear in exp(m_v p), so the
 *    closed form must be met to the discretisation error (asserted: settlement within 0.1%,
 *    pressure RMS within 0.1% of q); with k = k0 J it is not, and the column runs ahead (asserted:
 *    more than 5% ahead at U = 0.25). The column is the Xie-Leo one of 000 §5.2 (H = 1 m,
 *    E = 1 MPa, nu = 0, q = 200 kPa, k0 = 1e-3 m/s, n0 = 0.3).
 */
#include "../harness.h"
#include "analytic.h"
#include "../verify/gibson.h"
#include "permeability.h"

#define G 9.81

static double gibson_pressure_rms(const struct gibson_column *c, double Tv)
{
	double sum = 0.0;
	for (int i = 0; i < GIBSON_CELLS; i++) {
		double z = (i + 0.5) * c->H / GIBSON_CELLS;
		double e = c->p[i] - xie_leo_pressure(z, c->H, c->mv, c->q, Tv);
		sum += e * e;
	}
	return sqrt(sum / GIBSON_CELLS) / c->q;
}

static void check_closed_forms(void)
{
	double worst = 0.0;
	for (int trial = 0; trial < 1000; trial++) {
		double k0 = rnd(1e-9, 1e-2), n0 = rnd(0.05, 0.6), J = rnd(0.6, 1.8);
		double n = 1.0 - (1.0 - n0) / J;
		if (!(n > 0.0))
			continue;
		double C1 = k0 * (1 - n0) * (1 - n0) / (n0 * n0 * n0);
		worst = fmax(worst, rel_diff(permeability_conductivity(PERMEABILITY_CONSTANT, k0, n0, n, J), k0, 0));
		worst = fmax(worst, rel_diff(permeability_conductivity(PERMEABILITY_KOZENY_CARMAN, k0, n0, n, J),
					     C1 * pow(n, 3) / pow(1 - n, 2), 0));
		worst = fmax(worst, rel_diff(permeability_conductivity(PERMEABILITY_KOZENY_CARMAN, k0, n0, n0, 1.0), k0, 0));
		worst = fmax(worst, rel_diff(permeability_conductivity(PERMEABILITY_VOLUME_RATIO, k0, n0, n, J), k0 * J, 0));
		worst = fmax(worst, rel_diff(permeability_conductivity(PERMEABILITY_VOLUME_RATIO_SQUARED, k0, n0, n, J),
					     k0 * J * J, 0));
	}
	CHECK(worst < 1e-13, "permeability_laws_match_their_closed_forms", "worst relative difference %.3e", worst);
}

/* Largest settlement error (relative to Eq. 87) and pressure RMS over U = 0.25, 0.5, 0.75. */
static void gibson_against_xie_leo(enum permeability_law law, double *settle_err, double *rms, double *err_first)
{
	struct gibson_column c = { .H = 1.0, .mv = 1e-6, .q = 2e5, .k0 = 1e-3, .n0 = 0.3, .rho_w = 1000,
				  .law = law };
	const double cv = c.k0 / (c.rho_w * G * c.mv);
	const double U[3] = { 0.25, 0.5, 0.75 };
	*settle_err = *rms = 0.0;
	gibson_start(&c);
	for (int i = 0; i < 3; i++) {
		double Tv = time_factor_for_degree(U[i]);
		gibson_advance(&c, Tv * c.H * c.H / cv);
		double s = gibson_settlement(&c), s_closed = xie_leo_settlement(c.H, c.mv, c.q, Tv);
		double e = (s - s_closed) / s_closed;
		if (i == 0)
			*err_first = e;
		*settle_err = fmax(*settle_err, fabs(e));
		*rms = fmax(*rms, gibson_pressure_rms(&c, Tv));
		printf("INFO gibson column, law %d, U = %.2f: settlement %.5f m, Eq. 87 %.5f m (%+.3f%%), "
		       "pressure rms/q %.2e\n", (int)law, U[i], s, s_closed, 100 * e, gibson_pressure_rms(&c, Tv));
	}
}

int main(void)
{
	check_closed_forms();
	double settle_err, rms, first;
	gibson_against_xie_leo(PERMEABILITY_VOLUME_RATIO_SQUARED, &settle_err, &rms, &first);
	CHECK(settle_err < 0.001, "gibson_with_k0_J2_meets_xie_leo_settlement", "worst %.3f%%", 100 * settle_err);
	CHECK(rms < 0.001, "gibson_with_k0_J2_meets_xie_leo_pressure", "worst rms/q %.4f", rms);
	gibson_against_xie_leo(PERMEABILITY_VOLUME_RATIO, &settle_err, &rms, &first);
	CHECK(first > 0.05, "gibson_with_k0_J_runs_ahead_of_xie_leo", "%.2f%% at U = 0.25", 100 * first);
	HARNESS_EXIT();
}
