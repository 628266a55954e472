/*
 * consolidation_001_test.c - paper 001's fully implicit u-p-U scheme (solver/schemes/implicit/)
 * on the verification ladder of spec-001 §10: the closed forms a coupled solve must meet before
 * any of 001's examples means anything.
 *
 *  a. Terzaghi (tests/cases/terzaghi_001.json: 002 §4.1.1's column, uGIMP, B-bar, MLSA) at 10 and
 *     100 times the explicit scheme's critical step for the same column (stable_dt.h): at Tv =
 *     0.05, 0.1, 0.2, 0.5 and 1 the RMS of (p - p_Terzaghi) / q within 2% and the top row's
 *     settlement within 2% of the closed form (terzaghi_column.h): a step chosen by accuracy,
 *     not stability.
 *     make test samples the 10x run to Tv = 0.2, make verify (PORO_VERIFY_LONG=1) to 1.
 *  b. The same soil by the semi-implicit scheme (tests/cases/terzaghi_single_point.json, its own
 *     grid and dt): the base and mid-height probes within 2% of q of the implicit 10x run's at
 *     every Tv it samples (consolidation_002_test holds the explicit scheme to the same semi-implicit run).
 *  c. Undrained: the column filling its grid (no free surface), k = 1e-9 m/s, the load ramped over
 *     0.05 s: the mean pore pressure over the points, averaged over the next 0.15 s (the ramp's end
 *     leaves the column ringing: Newmark's average acceleration has no numerical damping), within
 *     1% of Skempton's B q, B = 1 / (1 + n m_v^-1 / K_w) (spec-001 §10.5).
 *  d. Hydrostatic: the column under its own weight (gravity ramped over 0.1 s, k = 1e-2 m/s,
 *     drained top) consolidated to rest: every point's pore pressure within 0.1% of rho_w g H of
 *     rho_w g d (spec-001 §10.6: an initial hydrostatic field is an equilibrium of Eq. 10b); the
 *     effective vertical stress against
 *     -(1 - n)(rho_s - rho_w) g d within 0.1% of rho_b g H on the mean over the points, and at
 *     every point within the weight of half a cell: B-bar samples the volumetric strain at the
 *     cell's centre, so in one dimension both points of a cell carry the stress of its centre,
 *     h/4 of depth away (1.25% of rho_b g H here; 1.38% at the bottom row, measured).
 *  e. Newton: with the elastic tangent on a linear elastic column the tangent is the Jacobian, so
 *     every step converges in at most two corrections; with tangent "consistent" on a column that
 *     yields (small-strain Mohr-Coulomb, K0 loading), the energy |delta . r| of each iteration is
 *     about the square of the last's relative to the first's (quadratic: proves the tangent
 *     consistent), where the elastic tangent needs many more iterations for the same step.
 *  f. A step that does not converge (one iteration allowed on the yielding footing) fails with the
 *     step, the iteration count and the last residual named.
 * Each figure is printed on an INFO line before the check that asserts it.
 */
#include <string.h>

#include "../case_file.h"
#include "../harness.h"
#include "stable_dt.h"
#include "terzaghi_column.h"

#define CASES "tests/cases/"
#define TOLERANCE 0.02                /* of q, of the closed-form settlement */
#define UNDRAINED_TOLERANCE 0.01      /* of B q */
#define HYDROSTATIC_TOLERANCE 1e-3    /* of rho_w g H */
#define EFFECTIVE_MEAN_TOLERANCE 1e-3 /* of the buoyant weight rho_b g H, the points' mean error */

static struct sim *build(const struct case_spec *c)
{
	struct poro_error err = {0};
	struct sim *s = NULL;
	if (sim_create(&s, c, &err))
		printf("INFO cannot build: %s\n", err.message);
	return s;
}

/* The explicit scheme's critical step for the same case (stable_dt.h). */
static double explicit_critical_step(const struct case_spec *c)
{
	struct case_spec e = *c;
	e.formulation.scheme = SCHEME_EXPLICIT;
	struct stable_dt est;
	stable_dt_estimate(&e, &est);
	return est.cfl;
}

/* a, b */
static void check_terzaghi(void)
{
	struct case_spec *c = test_case_load(CASES "terzaghi_001.json");
	struct case_spec *si = test_case_load(CASES "terzaghi_single_point.json");
	if (!c || !si)
		return;
	const double critical = explicit_critical_step(c);
	struct column_run runs[2];
	static const double multiples[2] = {10, 100};
	/* make test samples the 10x run to Tv = 0.2 (800 steps); make verify to Tv = 1 */
	const int long_run = getenv("PORO_VERIFY_LONG") != NULL;
	for (int k = 0; k < 2; k++) {
		c->time.dt = multiples[k] * critical;
		const double t0 = harness_wall_seconds();
		const int count = k == 0 && !long_run ? 3 : TV_COUNT;
		const int ok = run_terzaghi(c, count, &runs[k]);
		printf("INFO terzaghi 001 at dt = %g x the explicit critical %.3g s = %.3g s: %.1f s of wall time\n",
		       multiples[k], critical, c->time.dt, harness_wall_seconds() - t0);
		char name[96];
		snprintf(name, sizeof name, "terzaghi_001_runs_at_%gx_explicit_step", multiples[k]);
		CHECK(ok, name, "the run failed");
		for (int i = 0; ok && i < count; i++) {
			printf("INFO terzaghi 001 %gx Tv=%.2f rms/q=%.5f settlement error %.5f of the surface's\n",
			       multiples[k], TVS[i], runs[k].rms[i], runs[k].settlement[i]);
			snprintf(name, sizeof name, "terzaghi_001_%gx_rms_below_2pct_Tv%.2f", multiples[k], TVS[i]);
			CHECK(runs[k].rms[i] <= TOLERANCE, name, "rms/q = %.5f", runs[k].rms[i]);
			snprintf(name, sizeof name, "terzaghi_001_%gx_settlement_within_2pct_Tv%.2f", multiples[k], TVS[i]);
			CHECK(runs[k].settlement[i] <= TOLERANCE, name, "error %.5f", runs[k].settlement[i]);
		}
	}
	struct column_run semi;
	const int compared = long_run ? TV_COUNT : 3;
	const int ok = run_terzaghi(si, compared, &semi);
	double worst = 0.0;
	for (int i = 0; ok && i < compared; i++) {
		const struct column_run *r = &runs[0];
		printf("INFO Tv=%.2f base p/q implicit %.5f semi-implicit %.5f; mid %.5f %.5f\n", TVS[i], r->base[i],
		       semi.base[i], r->mid[i], semi.mid[i]);
		worst = fmax(worst, fmax(fabs(r->base[i] - semi.base[i]), fabs(r->mid[i] - semi.mid[i])));
	}
	printf("INFO implicit (10x) against semi-implicit: largest probe difference %.5f of q\n", worst);
	CHECK(ok && worst <= TOLERANCE, "terzaghi_implicit_and_semi_implicit_agree", "largest difference %.5f of q",
	      worst);
	case_destroy(&si);
	case_destroy(&c);
}

/* The column filling the grid to its top, which is then a wall and not a free surface. */
static void fill_grid(struct case_spec *c)
{
	c->grid.extent[1] = c->bodies[0].max[1];
}

static double mean_pore_pressure(const struct sim *s)
{
	const idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * (size_t)n), sum = 0.0;
	sim_pore_pressure(s, p, NULL);
	for (idx_t i = 0; i < n; i++)
		sum += p[i];
	free(p);
	return sum / (double)n;
}

/* c */
static void check_undrained(void)
{
	struct case_spec *c = test_case_load(CASES "terzaghi_001.json");
	if (!c)
		return;
	fill_grid(c);
	c->bodies[0].hydraulic_conductivity = 1e-9;
	c->bodies[0].initial_pore_pressure = 0.0;
	c->loads[0].time_function.kind = TIME_RAMP;
	c->loads[0].time_function.ramp_time = 0.05;
	c->time.end = 0.2;
	const struct column col = column_of(c);
	const double B = 1.0 / (1.0 + c->bodies[0].porosity / (col.mv * c->fluid.bulk_modulus));
	struct sim *s = build(c);
	double sum = 0.0;
	long samples = 0;
	int ok = s != NULL;
	while (ok && !sim_done(s)) {
		ok = !sim_step(s);
		if (sim_time(s) > 0.05 + 1e-9)
			sum += mean_pore_pressure(s), samples++;
	}
	if (s && !ok)
		printf("INFO solver failed: %s\n", sim_error(s)->message);
	const double p = samples ? sum / samples : 0.0;
	printf("INFO undrained column: mean p after the ramp %.2f Pa, B q = %.2f Pa (B = %.5f): %+.4f%%\n", p,
	       B * col.q, B, 100 * (p / (B * col.q) - 1));
	CHECK(ok && fabs(p / (B * col.q) - 1.0) <= UNDRAINED_TOLERANCE, "undrained_column_pressure_is_skempton_B_q",
	      "mean p %.2f Pa against B q %.2f Pa", p, B * col.q);
	sim_destroy(&s);
	case_destroy(&c);
}

/* d */
static void check_hydrostatic(void)
{
	struct case_spec *c = test_case_load(CASES "terzaghi_001.json");
	if (!c)
		return;
	c->bodies[0].hydraulic_conductivity = 1e-2;
	c->bodies[0].initial_pore_pressure = 0.0;
	c->load_count = 0;
	c->gravity.acceleration[1] = -TERZAGHI_G;
	c->gravity.ramp_time = 0.1;
	c->time.end = 0.5;
	struct sim *s = build(c);
	int ok = s != NULL;
	while (ok && !sim_done(s))
		ok = !sim_step(s);
	if (s && !ok)
		printf("INFO solver failed: %s\n", sim_error(s)->message);
	double worst_p = 0.0, worst_s = 0.0, mean_s = 0.0;
	const double H = c->bodies[0].max[1], n = c->bodies[0].porosity, rho_s = c->materials[0].density;
	const double rho_w = c->fluid.density, buoyant = (1.0 - n) * (rho_s - rho_w) * TERZAGHI_G;
	if (ok) {
		const struct particles *p = sim_soil(s), *w = sim_water(s);
		for (idx_t q = 0; q < w->n; q++) {
			const double d = H - p->x0[2 * q + 1];
			worst_p = fmax(worst_p, fabs(-w->pressure[q] - rho_w * TERZAGHI_G * d) / (rho_w * TERZAGHI_G * H));
			const double e = (p->stress[4 * q + 1] + buoyant * d) / (buoyant * H);
			worst_s = fmax(worst_s, fabs(e));
			mean_s += e / (double)w->n;
		}
	}
	const double half_cell = 0.5 * c->grid.cell_size / H;
	printf("INFO hydrostatic column at %g s: largest |p - rho_w g d| %.2e of rho_w g H; sigma'_yy + rho_b g d: "
	       "mean %.2e, largest %.2e of rho_b g H (half a cell's weight %.2e)\n", c->time.end, worst_p, mean_s,
	       worst_s, half_cell);
	CHECK(ok && worst_p <= HYDROSTATIC_TOLERANCE, "hydrostatic_column_pressure_within_0.1pct", "%.2e", worst_p);
	CHECK(ok && fabs(mean_s) <= EFFECTIVE_MEAN_TOLERANCE, "hydrostatic_column_effective_stress_mean_within_0.1pct",
	      "%.2e", mean_s);
	CHECK(ok && worst_s <= half_cell, "hydrostatic_column_effective_stress_within_half_a_cell", "%.2e", worst_s);
	sim_destroy(&s);
	case_destroy(&c);
}

/* The yielding problem of e and f: 001 §4.1.1's strip footing (tests/cases/strip_footing_001.json)
 * on 0.5 m cells, loaded to 6 c within a second so that a plastic zone grows under it step by
 * step: each step's return mappings change as points yield, which Newton must follow. */
static void make_plastic(struct case_spec *c)
{
	c->grid.cell_size = 0.5;
	c->loads[0].time_function.ramp_time = 1.0;
	c->loads[0].traction[1] *= 6.0 * c->materials[0].peak_cohesion / -c->loads[0].traction[1];
	c->time.dt = 0.05;
	c->time.end = 1.0;
}

/* Steps s to its end; returns the largest iteration count of a step, and in *energies the history
 * of the step whose count was largest. */
static int run_counting(struct sim *s, double *energies, int *count, int *ok)
{
	int most = 0;
	*count = 0;
	while (*ok && !sim_done(s)) {
		*ok = !sim_step(s);
		int last, n;
		long total;
		const double *e;
		sim_iterations(s, &last, &total, &e, &n);
		if (last > most) {
			most = last, *count = n;
			memcpy(energies, e, sizeof(double) * (size_t)n);
		}
	}
	if (!*ok)
		printf("INFO solver failed: %s\n", sim_error(s)->message);
	return most;
}

/* Runs c (tangent "consistent") to its end: the largest iteration count of a step, checked at 3 or
 * more, and that step's energies |delta . r| relative to the first, checked to fall quadratically
 * at least once (the rate log(now) / log(prev) at least 1.8, once out of the first iteration's
 * reach and above round-off). */
static int consistent_tangent_rate(const struct case_spec *c, const char *label, const char *suffix)
{
	double energies[SIM_ITERATIONS_KEPT];
	int count = 0, ok;
	struct sim *s = build(c);
	ok = s != NULL;
	const int full = s ? run_counting(s, energies, &count, &ok) : 0;
	printf("INFO %s, consistent tangent: at most %d iterations a step; that step's |delta . r| / first:", label,
	       full);
	int quadratic = 0;
	for (int k = 1; k < count; k++) {
		const double prev = energies[k - 1] / energies[0], now = energies[k] / energies[0];
		printf(" %.3e", now);
		if (k >= 2 && prev < 1e-2 && now > 1e-28 && log(now) / log(prev) >= 1.8)
			quadratic++;
	}
	printf("\n");
	char name[96];
	snprintf(name, sizeof name, "newton_yielding_column_iterates%s", suffix);
	CHECK(ok && full >= 3, name, "%d iterations", full);
	snprintf(name, sizeof name, "newton_consistent_tangent_converges_quadratically%s", suffix);
	CHECK(ok && quadratic >= 1, name, "no iteration squared the last's relative energy");
	sim_destroy(&s);
	return full;
}

/* e, f */
static void check_newton(void)
{
	struct case_spec *c = test_case_load(CASES "terzaghi_001.json");
	if (!c)
		return;
	double energies[SIM_ITERATIONS_KEPT];
	int count, ok = 1;
	c->time.end = 0.05;
	struct sim *s = build(c);
	ok = s != NULL;
	const int elastic = s ? run_counting(s, energies, &count, &ok) : 0;
	printf("INFO linear elastic column, elastic tangent: at most %d corrections a step\n", elastic);
	CHECK(ok && elastic <= 2, "newton_linear_elastic_converges_in_two", "%d corrections", elastic);
	sim_destroy(&s);

	case_destroy(&c);
	c = test_case_load(CASES "strip_footing_001.json");
	if (!c)
		return;
	make_plastic(c);
	c->formulation.tangent = NEWTON_TANGENT_CONSISTENT;
	const int full = consistent_tangent_rate(c, "yielding footing", "");
	/* the same with the finite-strain return of Eq. 70: its tangent by differences (system.c) */
	c->materials[0].strain = STRAIN_FINITE;
	consistent_tangent_rate(c, "yielding footing, finite strain", "_finite_strain");
	c->materials[0].strain = STRAIN_SMALL;

	c->formulation.tangent = NEWTON_TANGENT_ELASTIC;
	s = build(c);
	ok = s != NULL;
	const int modified = s ? run_counting(s, energies, &count, &ok) : 0;
	printf("INFO yielding footing, elastic tangent (modified Newton-Raphson): at most %d iterations a step\n",
	       modified);
	CHECK(ok && modified > full, "newton_elastic_tangent_needs_more_iterations", "%d against %d", modified, full);
	sim_destroy(&s);

	c->formulation.newton_max_iterations = 1;
	s = build(c);
	ok = s != NULL;
	enum poro_status st = PORO_OK;
	while (s && !st && !sim_done(s))
		st = sim_step(s);
	const char *message = s ? sim_error(s)->message : "";
	printf("INFO one iteration allowed: %s\n", message);
	CHECK(st == PORO_ESOLVER && strstr(message, "did not converge in 1 iterations") &&
	      strstr(message, "step ") && strstr(message, "largest residual"),
	      "newton_failure_names_step_iterations_residual", "status %d: %s", (int)st, message);
	sim_destroy(&s);
	case_destroy(&c);
}

int main(void)
{
	check_terzaghi();
	check_undrained();
	check_hydrostatic();
	check_newton();
	HARNESS_EXIT();
}
