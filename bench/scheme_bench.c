/*
 * scheme_bench.c - the three schemes on one consolidation column, and the implicit scheme's cost
 * per Newton iteration.
 *
 * 1. 002 §4.1.1's Terzaghi column (the same soil in tests/cases/terzaghi_single_point.json,
 *    terzaghi_002.json and terzaghi_001.json), each scheme at its own case's step: the semi-implicit
 *    at 1e-4 s (0.14 of its CFL step h / c_p), the explicit at 1e-5 s (about 0.4 of its critical
 *    step h / c_fast) and the implicit at 1e-3 s (about 40 explicit critical steps; within 2% of q
 *    of Terzaghi even at 100, consolidation_001_test). Each runs SIMULATED seconds after a warm-up
 *    and prints the wall time per simulated second and per material-point step.
 * 2. The implicit scheme on 001 §4.1.1's strip footing (tests/cases/strip_footing_001.json, 1,600
 *    points on 0.25 m cells) for STEPS steps, its load rising to 5.5 c over them (past Prandtl's
 *    5.14 c: the plastic zone grows under the footing): the time per Newton iteration per point
 *    split into the residual (stress updates and internal forces), the assembly, the factorisation
 *    and the solves; the iterations a step; the symbolic analyses, factorisations and solves per
 *    1,000 steps (one analysis a run is the aim: the pattern is the grid's) and the factors'
 *    nonzeros. With the elastic tangent (001's modified Newton-Raphson) and the consistent one.
 * 3. 002 §4.2's strip load to its end by each scheme at its own step (strip): wall time per
 *    simulated second.
 * Figures are printed, never asserted; bench/run.sh runs it on one thread.
 *
 *   scheme_bench [--simulated SECONDS] [--steps N] [--only columns|strip|footing]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <jansson.h>

#include "case.h"
#include "poro.h"

static double wall(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static struct sim *build(struct case_spec *c)
{
	struct poro_error err = {0};
	struct sim *s = NULL;
	if (sim_create(&s, c, &err))
		fprintf(stderr, "scheme_bench: %s\n", err.message);
	return s;
}

static struct case_spec *load(const char *file)
{
	struct poro_error err = {0};
	struct case_spec *c = NULL;
	if (case_load_file(file, &c, &err))
		fprintf(stderr, "scheme_bench: %s: %s\n", file, err.message);
	return c;
}

static void column(const char *label, const char *file, double simulated)
{
	struct case_spec *c = load(file);
	struct sim *s = c ? build(c) : NULL;
	if (!s) {
		case_destroy(&c);
		return;
	}
	const long warmup = 3, steps = (long)(simulated / c->time.dt + 0.5);
	for (long i = 0; i < warmup; i++)
		sim_step(s);
	const double t0 = wall();
	long done = 0;
	for (; done < steps && !sim_done(s); done++)
		if (sim_step(s)) {
			fprintf(stderr, "scheme_bench: %s: %s\n", label, sim_error(s)->message);
			break;
		}
	const double seconds = wall() - t0, points = (double)sim_soil(s)->n + (sim_is_double_point(s) ? (double)sim_water(s)->n : 0);
	printf("  %-14s dt %8.2e s  %6ld steps  %9.3f s wall per simulated second  %8.3f us per material-point step\n",
	       label, c->time.dt, done, seconds / (done * c->time.dt), 1e6 * seconds / (done * points));
	sim_destroy(&s);
	case_destroy(&c);
}

/* The case in file with formulation.scheme set to scheme (NULL: as it is) and time.dt to dt
 * (a number, or "auto"). */
static struct case_spec *load_as(const char *file, const char *scheme, json_t *dt)
{
	json_error_t jerr;
	struct poro_error err = {0};
	struct case_spec *c = NULL;
	json_t *doc = json_load_file(file, 0, &jerr);
	if (!doc) {
		fprintf(stderr, "scheme_bench: %s: %s\n", file, jerr.text);
		json_decref(dt);
		return NULL;
	}
	if (scheme)
		json_object_set_new(json_object_get(doc, "formulation"), "scheme", json_string(scheme));
	json_object_set_new(json_object_get(doc, "time"), "dt", dt);
	char *text = json_dumps(doc, 0);
	if (!text || case_load_string(text, &c, &err))
		fprintf(stderr, "scheme_bench: %s as %s: %s\n", file, scheme ? scheme : "is", err.message);
	free(text);
	json_decref(doc);
	return c;
}

/* 002 §4.2's strip load (0.5 m cells) to its end, 0.1 s, by one scheme at its own step: the wall
 * time per simulated second, the figure that tells a user which scheme to pick for a run. */
static void strip(const char *label, const char *file, const char *scheme, json_t *dt)
{
	struct case_spec *c = load_as(file, scheme, dt);
	struct sim *s = c ? build(c) : NULL;
	if (!s) {
		case_destroy(&c);
		return;
	}
	const double t0 = wall();
	long done = 0;
	for (; !sim_done(s); done++)
		if (sim_step(s)) {
			fprintf(stderr, "scheme_bench: %s: %s\n", label, sim_error(s)->message);
			break;
		}
	const double seconds = wall() - t0, dt_used = sim_time(s) / (done > 0 ? done : 1);
	const double points = (double)sim_soil(s)->n + (sim_is_double_point(s) ? (double)sim_water(s)->n : 0);
	const struct particles *p = sim_soil(s);
	double largest = 0.0;   /* the maximum displacement, 002's figure (6.737 mm): the step's accuracy */
	for (idx_t q = 0; q < p->n; q++)
		largest = fmax(largest, hypot(p->x[2 * q] - p->x0[2 * q], p->x[2 * q + 1] - p->x0[2 * q + 1]));
	printf("  %-34s dt %8.2e s  %5ld steps  %8.3f s wall per simulated second  %8.3f us per material-point step"
	       "  max displacement %.3f mm\n", label, dt_used, done, seconds / sim_time(s),
	       1e6 * seconds / ((double)done * points), 1e3 * largest);
	sim_destroy(&s);
	case_destroy(&c);
}

static void footing(const char *label, enum newton_tangent tangent, int steps)
{
	struct case_spec *c = load("tests/cases/strip_footing_001.json");
	if (!c)
		return;
	c->formulation.tangent = tangent;
	/* the load rising to 5.5 c over the bench's steps: elastic steps first, then the plastic zone
	 * growing under the footing toward collapse (Prandtl's 5.14 c) */
	const double c_u = c->materials[0].peak_cohesion;
	c->loads[0].traction[1] = -6.0 * c_u;
	c->loads[0].time_function.ramp_time = (steps + 3) * c->time.dt * 6.0 / 5.5;
	struct sim *s = build(c);
	if (!s) {
		case_destroy(&c);
		return;
	}
	for (int i = 0; i < 3; i++)
		sim_step(s);
	double before[PHASE_COUNT];
	for (int k = 0; k < PHASE_COUNT; k++)
		before[k] = sim_phase_seconds(s, k);
	int last;
	long total0, total1, a0, f0, v0, nnz, a1, f1, v1;   /* a0: the analyses before the timed steps */
	int count;
	sim_iterations(s, &last, &total0, NULL, &count);
	sim_linear_solver_counts(s, &a0, &f0, &v0, &nnz);
	int taken = 0;
	for (; taken < steps && !sim_done(s); taken++)
		if (sim_step(s)) {
			fprintf(stderr, "scheme_bench: %s: %s\n", label, sim_error(s)->message);
			break;
		}
	sim_iterations(s, &last, &total1, NULL, &count);
	sim_linear_solver_counts(s, &a1, &f1, &v1, &nnz);
	const long iterations = total1 - total0, n = sim_soil(s)->n;
	printf("  %s: %d steps, %.2f Newton iterations a step; %ld symbolic analyses in the run's %ld steps; per "
	       "1,000 steps %ld factorisations, %ld solves; factors %ld nonzeros\n", label, taken,
	       taken ? (double)iterations / taken : 0.0, a1, sim_steps_taken(s),
	       taken ? 1000 * (f1 - f0) / taken : 0, taken ? 1000 * (v1 - v0) / taken : 0, nnz);
	for (int k = 0; k < PHASE_COUNT; k++) {
		const char *name = sim_phase_name_of(s, k);
		if (name && iterations > 0)
			printf("    %-26s %9.3f us per Newton iteration per point\n", name,
			       1e6 * (sim_phase_seconds(s, k) - before[k]) / ((double)iterations * n));
	}
	sim_destroy(&s);
	case_destroy(&c);
}

int main(int argc, char **argv)
{
	double simulated = 0.02;
	int steps = 40;
	const char *only = NULL;   /* "columns", "strip" or "footing": that part alone */
	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--simulated") && i + 1 < argc)
			simulated = atof(argv[++i]);
		else if (!strcmp(argv[i], "--steps") && i + 1 < argc)
			steps = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--only") && i + 1 < argc)
			only = argv[++i];
		else {
			fprintf(stderr, "scheme_bench: unknown argument '%s'\n", argv[i]);
			return 2;
		}
	}
	if (!only || !strcmp(only, "columns")) {
		printf("Terzaghi column of 002 §4.1.1, %g s simulated, each scheme at its own step:\n", simulated);
		column("semi_implicit", "tests/cases/terzaghi_single_point.json", simulated);
		column("explicit", "tests/cases/terzaghi_002.json", simulated);
		column("implicit_upU", "tests/cases/terzaghi_001.json", simulated);
	}
	if (!only || !strcmp(only, "strip")) {
		printf("strip load of 002 §4.2 (0.5 m cells) to 0.1 s, each scheme at its own step (\"auto\": the stable step it allows;\n"
		       "the implicit scheme has no bound: 1e-3 s):\n");
		strip("semi_implicit, double point", "tests/cases/strip_load_002.json", NULL, json_string("auto"));
		strip("semi_implicit, as its case, 2e-4", "tests/cases/strip_load_002.json", NULL, json_real(2e-4));
		strip("explicit", "tests/cases/strip_load_002_explicit.json", NULL, json_string("auto"));
		strip("implicit_upU", "tests/cases/strip_load_002_explicit.json", "implicit_upU", json_real(1e-3));
	}
	if (!only || !strcmp(only, "footing")) {
		printf("strip footing of 001 §4.1.1 (0.25 m cells), implicit_upU:\n");
		footing("elastic tangent", NEWTON_TANGENT_ELASTIC, steps);
		footing("consistent tangent", NEWTON_TANGENT_CONSISTENT, steps);
	}
	return 0;
}
