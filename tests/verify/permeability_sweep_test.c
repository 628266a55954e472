/*
 * permeability_sweep_test.c - one time step across permeabilities (000 §1, §5.3 and §6: the
 * critical time step of the semi-implicit scheme "is not affected by the soil's permeability").
 *
 * The Table 1 column (tests/cases/terzaghi.json, terzaghi_single_point.json) at its own dt = 1e-4 s
 * with k from 1e-9 to 1e-1 m/s, eight decades, for 2,000 steps (0.2 s), as the cases are written
 * (the paper's formulation). Asserted at every k:
 *  - every pore pressure stays within [-q, 1.5 q]: 1.5 q and not 2 q because the first step's
 *    overshoot next to the drained top is 1.39 q at low k (docs/numerics.md "Requirement c"), and
 *    -q because at high k the drained column rings (a sudden load on an undamped skeleton: period
 *    4 H / c_p = 0.054 s) and the water's inertia in the accelerating column gives pressures of
 *    either sign (measured down to -0.53 q at k = 0.1 m/s);
 *  - the settlement of the top: once consolidated (Tv >= 2 at the end) its mean over the last 0.1 s
 *    (about two periods of the ringing) within 2% of q H / E_oed; where the run spans Terzaghi's
 *    curve (the drained layer 2 sqrt(c_v t) at least two cells deep) within 5% of U(Tv) q H / E_oed
 *    at t = 0.1 and 0.2 s; where it does not (k <= 1e-7 m/s: a layer of 1e-2 cells) only bounded by
 *    the settlement of the top two cells, 2 h / H of q H / E_oed, which the drained skin of the top
 *    point row reaches in the first steps (docs/numerics.md "Drag in the velocity correction").
 * Known failures, reported as XFAIL (docs/numerics.md "Stable time step"):
 *  - the low-permeability case's own formulation (weak free surface) at k = 1 m/s leaves [-q, 2 q]
 *    after about 3,500 steps (with APIC velocities it stays within [-q, 1.5 q], asserted);
 * Also asserted: a soft double-point column (E = 1e6 Pa, k = 1e-3 m/s) runs 5,500 steps within
 * [-q, 1.5 q]. It used to end at an inverted point once its expelled water reached the empty cell
 * above the soil, which then counted as full; under the Laplacian a cell counts as full only at
 * 0.9 of its volume now (docs/numerics.md, "Columns whose top cuts a cell").
 */
#include <string.h>

#include "../harness.h"
#include "analytic.h"
#include "case.h"
#include "poro.h"

#define CASES "tests/cases/"
#define G 9.81
#define STEPS 2000             /* 0.2 s */
#define LONG_STEPS 6000        /* 0.6 s, where the column consolidates within the first steps and
				  rings: the drag damps the ringing by then (k = 0.1 m/s) */
#define SAMPLES 2              /* settlement compared at the middle and the end of a run */
#define CONSOLIDATED_TV 2.0
#define FINAL_TOL 0.01
#define CURVE_U_MIN 0.25       /* below it the top point row's instant drainage (h / 2H of the final
				  settlement) is a large share of the settlement */
#define CURVE_TOL 0.05
#define P_MIN (-1.0)           /* q */
#define P_MAX 1.5              /* q */

struct sweep_run {
	int ok;
	long steps;
	double pmin, pmax;         /* over all pressure points and steps, / q */
	double top0;               /* initial height of the top point row, m */
	double settle[SAMPLES];    /* top settlement at the sample steps (sample_step), m */
	char error[512];
};

/* The step of sample i of a run of steps steps: its middle and its end. */
static long sample_step(long steps, int i)
{
	return steps * (i + 1) / SAMPLES;
}

/* Mean settlement of the soil points that start on the top row. */
static double top_settlement(const struct sim *s, double top0)
{
	const struct particles *p = sim_soil(s);
	double sum = 0.0;
	int n = 0;
	for (idx_t q = 0; q < p->n; q++)
		if (p->x0[2 * q + 1] > top0 - 1e-9) {
			sum += p->x0[2 * q + 1] - p->x[2 * q + 1];
			n++;
		}
	return n ? sum / n : 0.0;
}

/* Runs c for steps steps, recording pressure extremes and settlements. */
static void run(const struct case_spec *c, long steps, struct sweep_run *r)
{
	struct sim *s = NULL;
	struct poro_error err = {0};
	memset(r, 0, sizeof *r);
	r->pmin = INFINITY, r->pmax = -INFINITY;
	if (sim_create(&s, c, &err)) {
		snprintf(r->error, sizeof r->error, "%.500s", err.message);
		return;
	}
	const double q = -c->loads[0].traction[1];
	const struct particles *soil = sim_soil(s);
	r->top0 = -INFINITY;
	for (idx_t i = 0; i < soil->n; i++)
		r->top0 = fmax(r->top0, soil->x0[2 * i + 1]);
	idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof *p * (size_t)(n + 1));
	r->ok = p != NULL;
	while (r->ok && r->steps < steps) {
		if (sim_step(s)) {
			snprintf(r->error, sizeof r->error, "%.500s", sim_error(s)->message);
			r->ok = 0;
			break;
		}
		r->steps++;
		sim_pore_pressure(s, p, NULL);
		for (idx_t i = 0; i < n; i++)
			r->pmin = fmin(r->pmin, p[i] / q), r->pmax = fmax(r->pmax, p[i] / q);
		for (int j = 0; j < SAMPLES; j++)
			if (r->steps == sample_step(steps, j))
				r->settle[j] = top_settlement(s, r->top0);
	}
	free(p);
	sim_destroy(&s);
}

/* Checks the settlement of sample j (time t, time factor Tv) against what applies there. */
static void check_settlement(const char *label, double k, const struct sweep_run *r, int j, double t, double Tv,
			     double layer, double h, double H, double Eoed, double q)
{
	char name[200];
	const double scale = q * H / Eoed, u = r->settle[j], U = consolidation_degree(Tv);
	if (Tv >= CONSOLIDATED_TV && j == SAMPLES - 1) {
		/* consolidated: a point starting at y0 settles q y0 / E_oed (linear elasticity) */
		const double final = q * r->top0 / Eoed;
		snprintf(name, sizeof name, "sweep_%s_k%.0e_final_settlement_q_y0/E_oed_within_1pct", label, k);
		CHECK(r->ok && rel_diff(u, final, 1e-30) <= FINAL_TOL, name, "%.4f of q y0 / E_oed", u / final);
	} else if (U >= CURVE_U_MIN) {
		snprintf(name, sizeof name, "sweep_%s_k%.0e_settlement_on_terzaghi_within_5pct_t%.2g", label, k, t);
		CHECK(r->ok && rel_diff(u, U * scale, 1e-30) <= CURVE_TOL, name, "%.4f against U = %.4f", u / scale, U);
	} else if (layer >= 2 * h) {
		snprintf(name, sizeof name, "sweep_%s_k%.0e_settlement_on_terzaghi_within_top_row_t%.2g", label, k, t);
		CHECK(r->ok && fabs(u / scale - U) <= h / (2 * H), name, "%.4f against U = %.4f, bound +-%.4f",
		      u / scale, U, h / (2 * H));
	} else {
		snprintf(name, sizeof name, "sweep_%s_k%.0e_settlement_at_most_top_two_cells_t%.2g", label, k, t);
		CHECK(r->ok && u / scale <= 2 * h / H, name, "%.4f of q H / E_oed, bound %.4f", u / scale, 2 * h / H);
	}
}

static void sweep(const char *label, const char *file)
{
	static const double ks[] = {1e-9, 1e-7, 1e-5, 1e-3, 1e-2, 1e-1};
	for (size_t i = 0; i < sizeof ks / sizeof *ks; i++) {
		struct case_spec *c = NULL;
		struct poro_error err = {0};
		char name[160];
		if (case_load_file(file, &c, &err)) {
			CHECK(0, "permeability_sweep_case_loads", "%s: %s", file, err.message);
			return;
		}
		const double k = ks[i];
		c->bodies[0].hydraulic_conductivity = k;
		const struct case_material *m = &c->materials[0];
		const double nu = m->poisson_ratio;
		const double Eoed = m->youngs_modulus * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
		const double H = c->bodies[0].max[1] - c->bodies[0].min[1], q = -c->loads[0].traction[1];
		const double dt = c->time.dt, h = c->grid.cell_size, cv = k * Eoed / (c->fluid.density * G);
		const long steps = cv * STEPS * dt / (H * H) > 10 * CONSOLIDATED_TV ? LONG_STEPS : STEPS;
		struct sweep_run r;
		run(c, steps, &r);
		printf("INFO sweep %s k=%.0e dt=%.0e: %ld steps, pressure in [%.4f, %.4f] q", label, k, dt, r.steps,
		       r.pmin, r.pmax);
		for (int j = 0; j < SAMPLES; j++) {
			const double t = sample_step(steps, j) * dt, Tv = cv * t / (H * H);
			printf("; t = %.2g s: settlement/(qH/E_oed) %.4f, Terzaghi U %.4f (Tv %.3g)", t,
			       r.settle[j] * Eoed / (q * H), consolidation_degree(Tv), Tv);
		}
		printf("%s%s\n", r.ok ? "" : "; failed: ", r.error);
		snprintf(name, sizeof name, "sweep_%s_k%.0e_runs_%ld_steps", label, k, steps);
		CHECK(r.ok, name, "%s", r.error);
		snprintf(name, sizeof name, "sweep_%s_k%.0e_pressure_within_-q_1.5q", label, k);
		CHECK(r.ok && r.pmin >= P_MIN && r.pmax <= P_MAX, name, "[%.4f, %.4f] q", r.pmin, r.pmax);
		for (int j = 0; j < SAMPLES; j++) {
			const double t = sample_step(steps, j) * dt;
			check_settlement(label, k, &r, j, t, cv * t / (H * H), 2 * sqrt(cv * t), h, H, Eoed, q);
		}
		case_destroy(&c);
	}
}

/* The low-permeability case's formulation (weak free surface, consistent projection, drag in the
 * correction, second-difference stabilisation) on a very permeable column. */
static void known_weak_surface_high_k(void)
{
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	struct sweep_run r;
	if (case_load_file(CASES "terzaghi_low_permeability.json", &c, &err)) {
		CHECK(0, "permeability_sweep_low_permeability_case_loads", "%s", err.message);
		return;
	}
	c->bodies[0].hydraulic_conductivity = 1.0;
	run(c, 4000, &r);
	printf("INFO sweep low-permeability formulation k=1: %ld steps, pressure in [%.4f, %.4f] q%s%s\n", r.steps,
	       r.pmin, r.pmax, r.ok ? "" : "; failed: ", r.error);
	CHECK_KNOWN_FAILURE(r.ok && r.pmin >= -1 && r.pmax <= 2, "sweep_weak_surface_k1_pressure_within_-q_2q",
			    "[%.4f, %.4f] q over 4000 steps", r.pmin, r.pmax);
	/* the cause: a row-to-row pattern of the water points' FLIP velocities, which the grid cannot
	 * see and the drag no longer damps at this k; APIC keeps none */
	c->formulation.velocity_update = VELOCITY_UPDATE_APIC;
	run(c, 4000, &r);
	printf("INFO sweep low-permeability formulation with APIC, k=1: %ld steps, pressure in [%.4f, %.4f] q%s%s\n",
	       r.steps, r.pmin, r.pmax, r.ok ? "" : "; failed: ", r.error);
	CHECK(r.ok && r.pmin >= P_MIN && r.pmax <= P_MAX, "sweep_weak_surface_apic_k1_pressure_within_-q_1.5q",
	      "[%.4f, %.4f] q over 4000 steps", r.pmin, r.pmax);
	case_destroy(&c);
}

/* The double-point column with E = 1e6 Pa (settlement 1 cm, 0.4 h) at k = 1e-3 m/s and dt = 1e-4 s. */
static void soft_double_point(void)
{
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	struct sweep_run r;
	if (case_load_file(CASES "terzaghi.json", &c, &err)) {
		CHECK(0, "permeability_sweep_soft_case_loads", "%s", err.message);
		return;
	}
	c->materials[0].youngs_modulus = 1e6;
	run(c, 5500, &r);
	printf("INFO sweep soft double point E=1e6: %ld steps, pressure in [%.4f, %.4f] q%s%.200s\n", r.steps, r.pmin,
	       r.pmax, r.ok ? "" : "; failed: ", r.error);
	CHECK(r.ok && r.pmin >= P_MIN && r.pmax <= P_MAX, "sweep_soft_double_point_runs_5500_steps",
	      "%ld steps, pressure [%.4f, %.4f] q", r.steps, r.pmin, r.pmax);
	case_destroy(&c);
}

int main(void)
{
	sweep("double_point", CASES "terzaghi.json");
	sweep("single_point", CASES "terzaghi_single_point.json");
	known_weak_surface_high_k();
	soft_double_point();
	HARNESS_EXIT();
}
