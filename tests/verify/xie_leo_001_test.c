/*
 * xie_leo_001_test.c - paper 001's implicit u-p-U scheme on a column that settles by several cells:
 * Xie and Leo's large-strain closed form (000 Eqs. 87-90, tests/verify/analytic.h) and the
 * semi-implicit scheme on the same column. The small-strain checks (Terzaghi, Skempton's B, a
 * column at rest) are consolidation_001_test's; this one is about the surface moving through the
 * grid, which they never do.
 *
 * tests/cases/xie_leo_001.json is 000 Table 2's column (E = 1 MPa, nu = 0, k = k0 (V/V0)^2,
 * h = 0.05 m, 2 points a cell) at dt = 0.02 s, 40 times the semi-implicit case's:
 *  a. Under q = 50 kPa (5% strain, the surface crosses one row of nodes): the run reaches Tv = 2
 *     (it stopped at step 253 with a point inverted when Eq. 10b was integrated from t = 0), the
 *     RMS of (p - Eq. 90) / q within 5% at U = 0.25, 0.5, 0.75 and the top's settlement within 3%
 *     of Eq. 87 at Tv = 2 (000 §5.2's bounds for the semi-implicit scheme, xie_leo_test.c). Known
 *     failures: the settlement runs ahead of Eq. 87 at U = 0.25-0.75 (+3.6%, +8.7%, +5.5%; the
 *     same at dt = 0.005 s, so not the time step), and so the semi-implicit scheme on the same
 *     column (tests/cases/xie_leo_single_point.json under 50 kPa, -3.4%, -1.2%, -0.8%) is 9% behind
 *     it, beyond the 3% the schemes should agree to (docs/numerics.md, "Eq. 10b over a step").
 *  b. Under Table 2's q = 200 kPa (18% strain, four rows): the run reaches Tv = 2 and ends within
 *     0.7% of Eq. 87, but is 32%, 27% and 15% ahead at U = 0.25-0.75 (known failure), and at
 *     dt = 0.005 s the pore pressure rings step to step from t = 1.3 s until a point inverts at
 *     step 321.
 * Each figure is printed on an INFO line before the check that asserts it.
 */
#include <math.h>
#include <stdlib.h>

#include "../case_file.h"
#include "../harness.h"
#include "analytic.h"
#include "terzaghi_column.h"

#define CASES "tests/cases/"
#define SETTLEMENT_TOLERANCE 0.03   /* of Eq. 87's settlement, 000 §5.2 */
#define PRESSURE_TOLERANCE 0.05     /* RMS of q, 000 §5.2 */
#define SCHEMES_TOLERANCE 0.03      /* of the implicit run's settlement */
#define STAGES 4

static const double DEGREES[STAGES - 1] = {0.25, 0.5, 0.75};

struct xie_leo_run {
	int reached;                 /* stages reached before a failure */
	double Tv[STAGES], settlement[STAGES], analytic[STAGES], rms[STAGES];
};

/* The top surface's settlement: the top row's mean top edge (xie_leo_test.c). */
static double top_settlement(const struct sim *s, const struct column *col, double spacing)
{
	const struct particles *p = sim_soil(s);
	double sum = 0.0;
	int count = 0;
	for (idx_t q = 0; q < p->n; q++)
		if (p->x0[2 * q + 1] >= col->H - spacing) {
			sum += col->H - (p->x[2 * q + 1] + 0.5 * spacing * p->F[4 * q + 3]);
			count++;
		}
	return count ? sum / count : 0.0;
}

/* RMS of (p - Eq. 90) / q over the pressure points, each at its material depth. */
static double xie_leo_rms(const struct sim *s, const struct column *col, double Tv)
{
	const idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * n), *x = malloc(sizeof(double) * 2 * n), sum = 0.0;
	sim_pore_pressure(s, p, x);
	for (idx_t i = 0; i < n; i++) {
		const double y = soil_reference_height(s, x[2 * i + 1], col->H);
		const double e = p[i] - xie_leo_pressure(col->H - y, col->H, col->mv, col->q, Tv);
		sum += e * e;
	}
	free(p);
	free(x);
	return sqrt(sum / n) / col->q;
}

/* Runs c under the load q to U = 0.25, 0.5, 0.75 and Tv = 2 (the case's end), or fewer stages. */
static void run(struct case_spec *c, double q, int stages, struct xie_leo_run *r)
{
	c->loads[0].traction[1] = -q;
	const struct column col = column_of(c);
	const double spacing = c->grid.cell_size / c->bodies[0].particles_per_cell;
	const double cv = col.k / (col.rho_w * TERZAGHI_G * col.mv);
	struct poro_error err = {0};
	struct sim *s = NULL;
	*r = (struct xie_leo_run){0};
	if (sim_create(&s, c, &err)) {
		printf("INFO cannot build: %s\n", err.message);
		return;
	}
	for (int i = 0; i < stages; i++) {
		r->Tv[i] = i < STAGES - 1 ? time_factor_for_degree(DEGREES[i]) : cv * c->time.end / (col.H * col.H);
		if (!advance(s, r->Tv[i] * col.H * col.H / cv, c->time.dt))
			break;
		r->settlement[i] = top_settlement(s, &col, spacing);
		r->analytic[i] = xie_leo_settlement(col.H, col.mv, col.q, r->Tv[i]);
		r->rms[i] = xie_leo_rms(s, &col, r->Tv[i]);
		r->reached = i + 1;
	}
	sim_destroy(&s);
}

static void report(const char *label, const struct xie_leo_run *r)
{
	for (int i = 0; i < r->reached; i++)
		printf("INFO %s Tv=%.3f settlement %.5f m, Eq. 87 %.5f m (%+.2f%%), RMS (p - Eq. 90) / q %.4f\n", label,
		       r->Tv[i], r->settlement[i], r->analytic[i], 100.0 * (r->settlement[i] / r->analytic[i] - 1.0),
		       r->rms[i]);
}

/* a */
static void check_moderate(void)
{
	struct case_spec *c = test_case_load(CASES "xie_leo_001.json");
	struct case_spec *si = test_case_load(CASES "xie_leo_single_point.json");
	if (!c || !si)
		return;
	struct xie_leo_run imp, semi;
	run(c, 50e3, STAGES, &imp);
	report("implicit 50 kPa", &imp);
	CHECK(imp.reached == STAGES, "xie_leo_001_50kPa_runs_to_Tv2", "stopped after %d of %d stages", imp.reached,
	      STAGES);
	char name[96];
	for (int i = 0; i < imp.reached; i++) {
		snprintf(name, sizeof name, "xie_leo_001_50kPa_settlement_within_3pct_Tv%.3f", imp.Tv[i]);
		CHECK_UNLESS_KNOWN(i < STAGES - 1, fabs(imp.settlement[i] / imp.analytic[i] - 1.0) <= SETTLEMENT_TOLERANCE,
				   name, "%.5f against %.5f m", imp.settlement[i], imp.analytic[i]);
		if (i < STAGES - 1) {
			snprintf(name, sizeof name, "xie_leo_001_50kPa_pressure_rms_below_5pct_Tv%.3f", imp.Tv[i]);
			CHECK(imp.rms[i] <= PRESSURE_TOLERANCE, name, "rms/q = %.4f", imp.rms[i]);
		}
	}
	run(si, 50e3, STAGES - 1, &semi);
	report("semi-implicit 50 kPa", &semi);
	double worst = semi.reached == STAGES - 1 ? 0.0 : INFINITY;
	for (int i = 0; i < semi.reached && i < imp.reached; i++)
		worst = fmax(worst, fabs(semi.settlement[i] / imp.settlement[i] - 1.0));
	printf("INFO 50 kPa: the schemes' settlements differ by at most %.2f%% at U = 0.25-0.75\n", 100.0 * worst);
	CHECK_UNLESS_KNOWN(1, worst <= SCHEMES_TOLERANCE, "xie_leo_implicit_and_semi_implicit_agree", "%.4f", worst);
	case_destroy(&si);
	case_destroy(&c);
}

/* b */
static void check_table2(void)
{
	struct case_spec *c = test_case_load(CASES "xie_leo_001.json");
	if (!c)
		return;
	struct xie_leo_run r;
	run(c, 200e3, STAGES, &r);
	report("implicit 200 kPa", &r);
	CHECK(r.reached == STAGES, "xie_leo_001_200kPa_runs_to_Tv2", "stopped after %d of %d stages", r.reached, STAGES);
	double worst = r.reached == STAGES ? 0.0 : INFINITY;
	for (int i = 0; i < r.reached; i++)
		worst = fmax(worst, fabs(r.settlement[i] / r.analytic[i] - 1.0));
	CHECK_UNLESS_KNOWN(1, worst <= SETTLEMENT_TOLERANCE, "xie_leo_001_200kPa_settlement_within_3pct",
			   "worst %.4f of Eq. 87", worst);
	case_destroy(&c);
}

int main(void)
{
	check_moderate();
	check_table2();
	HARNESS_EXIT();
}
