/*
 * consolidation_002_test.c - paper 002 §4.1, the explicit stabilised single-point scheme
 * (solver/schemes/explicit/), against the closed forms and against the semi-implicit scheme.
 *
 *  a. Terzaghi (§4.1.1, tests/cases/terzaghi_002.json at the paper's size: 160 points, uGIMP,
 *     dt = 1e-5 s): at Tv = 0.05, 0.1, 0.2, 0.5 and 1 the RMS of (p - p_Terzaghi) / q over the
 *     points within 2% (each point at the soil's reference height there, column.h) and the top row's
 *     settlement within 2% of the closed form at its own reference height (analytic.h); the soil mass
 *     conserved to round-off. The same column without the stabilisations (Eqs. 26-27 and 33-34
 *     off): its figures printed.
 *  b. The same column by both schemes: tests/cases/terzaghi_single_point.json is 000's Table 1,
 *     the same soil as 002's Table 1, run by the semi-implicit scheme on its own grid; each within
 *     2% RMS of q of Terzaghi, and their pore pressures at the base and mid-height probes within
 *     2% of q of each other at every Tv, so a user can switch schemes and trust both.
 *  c. Xie-Leo's large deformation (§4.1.2, tests/cases/xie_leo_002.json), at reduced cost: a
 *     fluid bulk modulus of 2.2e7 Pa instead of 2.2e9 (it slows the consolidation by n m_v K_f^-1
 *     = 1.4%), the "auto" step (0.9 of the critical step) and 0.1 m cells on a column two cells
 *     wide (80 points; dt 88 times the paper's 1e-5 s). The paper's
 *     constant conductivity consolidates faster than Xie and Leo's closed form (which holds for
 *     k = k0 J^2), so the history is held against the brute-force Gibson solution with constant
 *     k (tests/verify/gibson.h), each at the reference height of the top point the settlement
 *     probe follows: within 2% of S_inf at t = 5-200 s; and at 300 s the surface's settlement
 *     (the point's, extrapolated by the Gibson profile's ratio) within 1.5% of the paper's
 *     analytic 0.1802 m (its numerical result is 0.1815 m; S_inf = H (1 - exp(-m_v q)) =
 *     0.18127 m). The paper-size run (K_f = 2.2e9 Pa, 0.05 m cells, dt = 1e-5 s, 3e7 steps) runs
 *     in `make verify` (PORO_VERIFY_LONG=1).
 * Each figure is printed on an INFO line before the check that asserts it.
 */
#include <string.h>

#include "../case_file.h"
#include "../harness.h"
#include "analytic.h"
#include "terzaghi_column.h"
#include "gibson.h"
#include "case.h"
#include "poro.h"
#include "stable_dt.h"

#define CASES "tests/cases/"
#define G 9.81
#define TOLERANCE 0.02                /* of q, of the closed-form settlement, of S_inf */
#define XIE_LEO_ANALYTIC 0.1802       /* m, 002 §4.1.2's analytic final settlement */
#define XIE_LEO_TOLERANCE 0.015       /* of it */
#define REDUCED_BULK_MODULUS 2.2e7    /* Pa */
#define REDUCED_CELL 0.1              /* m */

static void check_terzaghi(struct column_run *explicit_run)
{
	struct case_spec *c = test_case_load(CASES "terzaghi_002.json");
	if (!c)
		return;
	const double t0 = harness_wall_seconds();
	int ok = run_terzaghi(c, TV_COUNT, explicit_run);
	printf("INFO terzaghi 002 (explicit, stabilised): %.1f s of wall time\n", harness_wall_seconds() - t0);
	CHECK(ok, "terzaghi_002_runs", "the run failed");
	for (int i = 0; ok && i < TV_COUNT; i++) {
		char name[96];
		printf("INFO terzaghi 002 Tv=%.2f rms/q=%.5f settlement error %.5f of the surface's\n", TVS[i],
		       explicit_run->rms[i], explicit_run->settlement[i]);
		snprintf(name, sizeof name, "terzaghi_002_rms_below_2pct_Tv%.2f", TVS[i]);
		CHECK(explicit_run->rms[i] <= TOLERANCE, name, "rms/q = %.5f", explicit_run->rms[i]);
		snprintf(name, sizeof name, "terzaghi_002_settlement_within_2pct_Tv%.2f", TVS[i]);
		CHECK(explicit_run->settlement[i] <= TOLERANCE, name, "error %.5f", explicit_run->settlement[i]);
	}
	printf("INFO terzaghi 002 soil mass drift %.2e\n", explicit_run->mass_drift);
	CHECK(ok && explicit_run->mass_drift < 1e-12, "terzaghi_002_soil_mass_conserved", "drift %.3e",
	      explicit_run->mass_drift);

	/* without the stabilisations: printed for the docs, asserted only to run */
	struct column_run plain;
	c->formulation.strain_rate_smoothing = STRAIN_RATE_SMOOTHING_NONE;
	c->formulation.pressure_rate_projection = PRESSURE_RATE_NONE;
	ok = run_terzaghi(c, 3, &plain);
	for (int i = 0; ok && i < 3; i++)
		printf("INFO terzaghi 002 without stabilisation Tv=%.2f rms/q=%.5f settlement error %.5f\n", TVS[i],
		       plain.rms[i], plain.settlement[i]);
	CHECK(ok, "terzaghi_002_runs_without_stabilisation", "the run failed");
	case_destroy(&c);
}

/* b: the semi-implicit single-point column of 000 §5.1, the same soil, against the explicit one. */
static void check_schemes_agree(const struct column_run *e)
{
	struct case_spec *c = test_case_load(CASES "terzaghi_single_point.json");
	if (!c)
		return;
	struct column_run si;
	const int ok = run_terzaghi(c, TV_COUNT, &si);
	CHECK(ok, "terzaghi_semi_implicit_runs", "the run failed");
	double worst = 0.0, worst_rms = 0.0;
	for (int i = 0; ok && i < TV_COUNT; i++) {
		const double d = fmax(fabs(e->base[i] - si.base[i]), fabs(e->mid[i] - si.mid[i]));
		printf("INFO Tv=%.2f semi-implicit rms/q=%.5f; base p/q explicit %.5f semi-implicit %.5f; mid %.5f %.5f\n",
		       TVS[i], si.rms[i], e->base[i], si.base[i], e->mid[i], si.mid[i]);
		worst = fmax(worst, d), worst_rms = fmax(worst_rms, si.rms[i]);
	}
	CHECK(ok && worst_rms <= TOLERANCE, "terzaghi_semi_implicit_rms_below_2pct", "worst rms/q %.5f", worst_rms);
	printf("INFO explicit against semi-implicit: largest probe difference %.5f of q\n", worst);
	CHECK(ok && worst <= TOLERANCE, "terzaghi_explicit_and_semi_implicit_agree", "largest difference %.5f of q",
	      worst);
	case_destroy(&c);
}

/* c: Xie-Leo at reduced cost against the Gibson solution with constant k. */
static void check_xie_leo(void)
{
	struct case_spec *c = test_case_load(CASES "xie_leo_002.json");
	if (!c)
		return;
	if (!getenv("PORO_VERIFY_LONG")) {   /* the reduced run; make verify keeps the paper's */
		c->fluid.bulk_modulus = REDUCED_BULK_MODULUS;
		c->grid.cell_size = REDUCED_CELL;
		c->grid.extent[0] = c->bodies[0].max[0] = c->loads[0].to = 2 * REDUCED_CELL;
		struct stable_dt e;   /* "auto" at the reduced bulk modulus and cell */
		stable_dt_estimate(c, &e);
		c->time.dt = stable_dt_recommended(&e);
	}
	const struct column col = column_of(c);
	struct gibson_column ref = {.H = col.H, .mv = col.mv, .q = col.q, .k0 = col.k, .n0 = c->bodies[0].porosity,
				    .rho_w = col.rho_w, .law = PERMEABILITY_CONSTANT};
	gibson_start(&ref);
	const double S_inf = col.H * (1.0 - exp(-col.mv * col.q));
	static const double times[] = {5, 10, 20, 30, 50, 75, 100, 150, 200};
	struct poro_error err = {0};
	struct sim *s = NULL;
	int ok = !sim_create(&s, c, &err);
	double worst = 0.0, y0 = 0.0;
	const double t0 = harness_wall_seconds();
	if (ok) {   /* the reference height of the point the settlement probe follows (the top row's) */
		const struct particles *p = sim_soil(s);
		for (idx_t q = 0; q < p->n; q++)
			y0 = fmax(y0, p->x0[2 * q + 1]);
	}
	for (size_t i = 0; ok && i < sizeof times / sizeof *times; i++) {
		ok = advance(s, times[i], c->time.dt);
		gibson_advance(&ref, times[i]);
		const double S = -sim_probe_value(s, 1), S_ref = gibson_settlement_at(&ref, y0);
		printf("INFO xie-leo 002 t=%g s settlement %.5f m, Gibson constant k %.5f m (%+.2f%% of S_inf), Eq. 87 "
		       "%.5f m\n", times[i], S, S_ref, 100 * (S - S_ref) / S_inf,
		       xie_leo_settlement(col.H, col.mv, col.q, col.k * times[i] / (col.rho_w * G * col.mv)));
		worst = fmax(worst, fabs(S - S_ref) / S_inf);
	}
	CHECK(ok && worst <= TOLERANCE, "xie_leo_002_follows_gibson_constant_k", "worst %.4f of S_inf", worst);
	ok = ok && advance(s, c->time.end, c->time.dt);
	gibson_advance(&ref, c->time.end);
	/* the surface's settlement: the point's, scaled by the reference's surface-to-point ratio */
	const double S_end = ok ? -sim_probe_value(s, 1) * gibson_settlement(&ref) / gibson_settlement_at(&ref, y0) : 0.0;
	printf("INFO xie-leo 002 surface settlement at %g s: %.5f m (paper: 0.1815 numerical, 0.1802 analytic; S_inf "
	       "%.5f); %.1f s of wall time, h %.3g m, dt %.3g s, K_f %.3g Pa\n", c->time.end, S_end, S_inf,
	       harness_wall_seconds() - t0, c->grid.cell_size, c->time.dt, c->fluid.bulk_modulus);
	CHECK(ok && fabs(S_end - XIE_LEO_ANALYTIC) <= XIE_LEO_TOLERANCE * XIE_LEO_ANALYTIC,
	      "xie_leo_002_final_settlement_within_1.5pct_of_analytic", "%.5f m", S_end);
	sim_destroy(&s);
	case_destroy(&c);
}

int main(void)
{
	struct column_run explicit_run;
	check_terzaghi(&explicit_run);
	check_schemes_agree(&explicit_run);
	check_xie_leo();
	HARNESS_EXIT();
}
