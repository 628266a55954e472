/*
 * solver_bench.c - speed of a scheme's step: microseconds per material-point step.
 *
 * A 2-D double-point (or single-point) linear elastic block on a roller box, loaded by a strip
 * traction and its own weight, with at least 100,000 soil points by default (2x2 points per
 * 0.1 m cell on a 25 m x 10 m block). After WARMUP steps it times STEPS steps and prints, per
 * material-point step (soil plus water points), the total and each phase of the step: the
 * particle phases and the pressure assembly and factor-and-solve separately. Figures are
 * printed, never asserted.
 *
 * Thread counts are compared side by side in one run: one simulation per count in --threads,
 * stepped in turn (a step on one thread, then a step on two, ...), so that every count sees the
 * same machine. This machine is shared and its speed drifts by 10-40% within an hour
 * (docs/performance.md), which makes absolute times of separate runs useless as a comparison;
 * the ratio of counts stepped in turn is what the figures mean. The runs are also compared point
 * for point after the last step: a step's result must not depend on the thread count
 * (tests/solver/thread_count_test.c), and the bench says whether that held here.
 *
 * The binning of the points into the scatters' blocks (point_blocks.h), part of the shape
 * functions phase, is timed apart on one thread: BINNING_REPEATS sorts of each set, per
 * material-point step.
 *
 * --scheme runs the same block by paper 002's explicit scheme or paper 001's implicit u-p-U
 * scheme instead (scheme_keys: each as its cases run it, at its own step), so that the schemes'
 * costs per material-point step and their speed-ups on two threads stand side by side.
 *
 *   solver_bench [--cells-x N] [--cells-y N] [--ppc N] [--steps N] [--single-point]
 *                [--projection laplacian|consistent] [--threads N[,N...]]   (default 1,2)
 *                [--scheme semi_implicit|explicit|implicit_upU]
 */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "case.h"
#include "point_blocks.h"
#include "poro.h"
#include "sim_internal.h"

#define WARMUP 3
#define COUNTS_MAX 4   /* thread counts compared in one run */
#define BINNING_REPEATS 20

/* The formulation and time keys of each scheme: the semi-implicit scheme with the given phases
 * and projection at dt 1e-4 s; paper 002's explicit scheme as its cases run it (single point,
 * uGIMP, a compressible fluid) at 0.9 of its critical step ("auto"); paper 001's implicit scheme
 * (uGIMP, B-bar, the elastic tangent) at 1e-3 s, about 40 explicit critical steps of this block,
 * where its Terzaghi column stays within 2% of q (consolidation_001_test). */
static void scheme_keys(const char *scheme, const char *phases, const char *projection, char *formulation,
			size_t size, const char **dt)
{
	if (!strcmp(scheme, "explicit")) {
		snprintf(formulation, size, "\"scheme\": \"explicit\", \"phases\": \"single_point\", \"shape\": \"gimp\"");
		*dt = "\"auto\"";
	} else if (!strcmp(scheme, "implicit_upU")) {
		snprintf(formulation, size, "\"scheme\": \"implicit_upU\", \"shape\": \"gimp\"");
		*dt = "1e-3";
	} else {
		snprintf(formulation, size, "\"scheme\": \"%s\", \"phases\": \"%s\", \"pressure_projection\": \"%s\"",
			 scheme, phases, projection);
		*dt = "1e-4";
	}
}

static char *make_case(int cells_x, int cells_y, int ppc, const char *scheme, const char *phases,
		       const char *projection)
{
	const double h = 0.1, width = cells_x * h, height = cells_y * h;
	char formulation[256];
	const char *dt;
	scheme_keys(scheme, phases, projection, formulation, sizeof formulation, &dt);
	char *json = malloc(4096);
	snprintf(json, 4096,
		 "{\"schema\": \"poro-case/1\", \"title\": \"benchmark block\","
		 " \"formulation\": {%s},"
		 " \"grid\": {\"origin\": [0, 0], \"extent\": [%g, %g], \"cell_size\": %g},"
		 " \"materials\": [{\"name\": \"soil\", \"model\": \"linear_elastic\", \"density\": 2650,"
		 "   \"youngs_modulus\": 1e7, \"poisson_ratio\": 0.3}],"
		 " \"bodies\": [{\"name\": \"block\", \"material\": \"soil\", \"rectangle\": {\"min\": [0, 0], \"max\": [%g, %g]},"
		 "   \"particles_per_cell\": %d, \"porosity\": 0.3, \"hydraulic_conductivity\": 1e-4}],"
		 " \"fluid\": {\"density\": 1000, \"bulk_modulus\": 2.2e9},"
		 " \"gravity\": {\"acceleration\": [0, -9.81]},"
		 " \"boundaries\": {\"left\": {\"soil\": \"slip\", \"water\": \"slip\"}, \"right\": {\"soil\": \"slip\", \"water\": \"slip\"},"
		 "   \"bottom\": {\"soil\": \"fixed\", \"water\": \"slip\"}},"
		 " \"loads\": [{\"body\": \"block\", \"face\": \"top\", \"from\": 0, \"to\": %g, \"traction\": [0, -2e4]}],"
		 " \"time\": {\"dt\": %s, \"end\": 1}}",
		 formulation, width, height + 1.0, h, width, height, ppc, width / 5, dt);
	return json;
}

/* 1 if the two runs' points agree bit for bit (positions, velocities, pore pressures). */
static int same_points(const struct sim *a, const struct sim *b)
{
	const struct particles *sets[2][2] = {{sim_soil(a), sim_water(a)}, {sim_soil(b), sim_water(b)}};
	for (int k = 0; k < 2; k++) {
		const struct particles *p = sets[0][k], *q = sets[1][k];
		if (p->n != q->n || memcmp(p->x, q->x, 2 * sizeof(double) * (size_t)p->n) ||
		    memcmp(p->v, q->v, 2 * sizeof(double) * (size_t)p->n) ||
		    memcmp(p->pressure, q->pressure, sizeof(double) * (size_t)p->n))
			return 0;
	}
	return 1;
}

/* Microseconds per material-point step of sorting s's point sets into their blocks, one thread. */
static double binning_us(struct sim *s, long points)
{
	struct particles *sets[2] = {&s->soil, s->double_point ? &s->water : NULL};
	const int threads = omp_get_max_threads();
	omp_set_num_threads(1);
	const double t0 = sim_clock();
	for (int k = 0; k < BINNING_REPEATS; k++)
		for (int i = 0; i < 2; i++)
			if (sets[i] && sets[i]->blocks)
				point_blocks_sort(sets[i]->blocks, sets[i]);
	const double us = 1e6 * (sim_clock() - t0) / ((double)BINNING_REPEATS * points);
	omp_set_num_threads(threads);
	return us;
}

/* The process's CPU time, s, all threads: on a loaded machine the wall time of a step counts the
 * time its threads wait for a core; this counts what they did (with OMP_WAIT_POLICY=passive, no
 * spinning at the barriers). */
static double cpu_seconds(void)
{
	struct timespec t;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Parses "1,2" into counts; returns how many, 0 if malformed. */
static int parse_threads(const char *list, int *counts)
{
	int n = 0;
	for (const char *c = list; *c && n < COUNTS_MAX;) {
		char *end;
		long t = strtol(c, &end, 10);
		if (end == c || t < 1 || t > 256)
			return 0;
		counts[n++] = (int)t;
		c = *end == ',' ? end + 1 : end;
		if (*end && *end != ',')
			return 0;
	}
	return n;
}

int main(int argc, char **argv)
{
	int cells_x = 250, cells_y = 100, ppc = 2, steps = 20;
	int counts[COUNTS_MAX] = {1, 2}, runs = 2;
	const char *phases = "double_point", *projection = "laplacian", *scheme = "semi_implicit";
	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--cells-x") && i + 1 < argc) cells_x = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--cells-y") && i + 1 < argc) cells_y = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--ppc") && i + 1 < argc) ppc = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--steps") && i + 1 < argc) steps = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--single-point")) phases = "single_point";
		else if (!strcmp(argv[i], "--scheme") && i + 1 < argc) scheme = argv[++i];
		else if (!strcmp(argv[i], "--projection") && i + 1 < argc) projection = argv[++i];
		else if (!strcmp(argv[i], "--threads") && i + 1 < argc && (runs = parse_threads(argv[++i], counts))) ;
		else {
			fprintf(stderr, "solver_bench: unknown or malformed argument '%s'\n", argv[i]);
			return 2;
		}
	}
	char *json = make_case(cells_x, cells_y, ppc, scheme, phases, projection);
	struct case_spec *c = NULL;
	struct sim *s[COUNTS_MAX] = {NULL};
	struct poro_error err = {0};
	if (case_load_string(json, &c, &err)) {
		fprintf(stderr, "solver_bench: %s\n", err.message);
		return 2;
	}
	for (int r = 0; r < runs; r++)
		if (sim_create(&s[r], c, &err)) {
			fprintf(stderr, "solver_bench: %s\n", err.message);
			return 2;
		}
	long points = (long)sim_soil(s[0])->n + (sim_is_double_point(s[0]) ? (long)sim_water(s[0])->n : 0);
	double before[COUNTS_MAX][PHASE_COUNT], cpu[COUNTS_MAX] = {0};
	for (int k = 0; k < WARMUP + steps; k++)
		for (int r = 0; r < runs; r++) {
			if (k == WARMUP)
				for (int ph = 0; ph < PHASE_COUNT; ph++)
					before[r][ph] = sim_phase_seconds(s[r], ph);
			omp_set_num_threads(counts[r]);
			const double c0 = cpu_seconds();
			if (sim_step(s[r])) {
				fprintf(stderr, "solver_bench: %s\n", sim_error(s[r])->message);
				return 3;
			}
			if (k >= WARMUP)
				cpu[r] += cpu_seconds() - c0;
		}
	const char *policy = getenv("OMP_WAIT_POLICY");
	char what[96];
	if (!strcmp(scheme, "semi_implicit"))
		snprintf(what, sizeof what, "%s, %s, %s projection", scheme, phases, projection);
	else
		snprintf(what, sizeof what, "%s, single point, uGIMP", scheme);
	printf("%s: %ld soil + %ld water points, %d x %d cells, dt %.3g s, %d steps timed, the thread counts "
	       "stepped in turn (OMP_WAIT_POLICY=%s)\n", what, (long)sim_soil(s[0])->n,
	       sim_is_double_point(s[0]) ? (long)sim_water(s[0])->n : 0L, cells_x, cells_y, c->time.dt, steps,
	       policy ? policy : "unset");
	printf("  us per material-point step");
	for (int r = 0; r < runs; r++)
		printf("  %2d thread%s", counts[r], counts[r] > 1 ? "s" : " ");
	for (int r = 1; r < runs; r++)
		printf("  speed-up %d", counts[r]);
	printf("\n");
	double us[COUNTS_MAX][PHASE_COUNT + 3] = {{0}};   /* the phases, total, particle and grid, pressure */
	for (int r = 0; r < runs; r++)
		for (int ph = 0; ph < PHASE_COUNT; ph++) {
			const double v = 1e6 * (sim_phase_seconds(s[r], ph) - before[r][ph]) / ((double)steps * points);
			us[r][ph] = v;
			us[r][PHASE_COUNT] += v;
			us[r][ph == PHASE_PRESSURE_ASSEMBLY || ph == PHASE_PRESSURE_SOLVE ? PHASE_COUNT + 2 : PHASE_COUNT + 1] += v;
		}
	/* the semi-implicit pressure system's two phases (the implicit scheme's matrix and factors, the
	 * explicit scheme's pressure rate) against the rest of the step */
	const char *assembly = sim_phase_name_of(s[0], PHASE_PRESSURE_ASSEMBLY), *solve = sim_phase_name_of(s[0], PHASE_PRESSURE_SOLVE);
	char pair[80];
	snprintf(pair, sizeof pair, "%s%s%s", assembly ? assembly : "", solve ? " + " : "", solve ? solve : "");
	for (int row = 0; row < PHASE_COUNT + 3; row++) {
		const char *name = row < PHASE_COUNT ? sim_phase_name_of(s[0], row) : row == PHASE_COUNT ? "TOTAL" :
				   row == PHASE_COUNT + 1 ? "the other phases" : pair;
		if (!name)   /* a phase this scheme does not have */
			continue;
		printf("  %-26s", name);
		for (int r = 0; r < runs; r++)
			printf("  %9.4f", us[r][row]);
		for (int r = 1; r < runs; r++)
			printf("  %10.2f", us[r][row] > 0.0 ? us[0][row] / us[r][row] : 0.0);
		printf("\n");
	}
	printf("  CPU time, all threads     ");
	for (int r = 0; r < runs; r++)
		printf("  %9.4f", 1e6 * cpu[r] / ((double)steps * points));
	for (int r = 1; r < runs; r++)
		printf("  %10.2f", cpu[r] > 0.0 ? cpu[0] / cpu[r] : 0.0);
	printf("   (the process's CPU time: what the threads did, waiting for the machine left out)\n");
	printf("  binning into blocks (in the shape functions, one thread): %.4f us per material-point step\n",
	       binning_us(s[0], points));
	for (int r = 1; r < runs; r++)
		printf("  points after the last step on %d and %d threads: %s\n", counts[0], counts[r],
		       same_points(s[0], s[r]) ? "bit-identical" : "DIFFERENT");
	for (int r = 0; r < runs; r++)
		sim_destroy(&s[r]);
	case_destroy(&c);
	free(json);
	return 0;
}
