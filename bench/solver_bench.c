/*
 * solver_bench.c - speed of the semi-implicit scheme: microseconds per material-point step.
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
 *   solver_bench [--cells-x N] [--cells-y N] [--ppc N] [--steps N] [--single-point]
 *                [--projection laplacian|consistent] [--threads N[,N...]]   (default 1,2)
 */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case.h"
#include "point_blocks.h"
#include "poro.h"
#include "sim_internal.h"

#define WARMUP 3
#define COUNTS_MAX 4   /* thread counts compared in one run */
#define BINNING_REPEATS 20

static char *make_case(int cells_x, int cells_y, int ppc, const char *phases, const char *projection)
{
	const double h = 0.1, width = cells_x * h, height = cells_y * h;
	char *json = malloc(4096);
	snprintf(json, 4096,
		 "{\"schema\": \"poro-case/1\", \"title\": \"benchmark block\","
		 " \"formulation\": {\"scheme\": \"semi_implicit\", \"phases\": \"%s\", \"pressure_projection\": \"%s\"},"
		 " \"grid\": {\"origin\": [0, 0], \"extent\": [%g, %g], \"cell_size\": %g},"
		 " \"materials\": [{\"name\": \"soil\", \"model\": \"linear_elastic\", \"density\": 2650,"
		 "   \"youngs_modulus\": 1e7, \"poisson_ratio\": 0.3}],"
		 " \"bodies\": [{\"name\": \"block\", \"material\": \"soil\", \"rectangle\": {\"min\": [0, 0], \"max\": [%g, %g]},"
		 "   \"particles_per_cell\": %d, \"porosity\": 0.3, \"hydraulic_conductivity\": 1e-4}],"
		 " \"gravity\": {\"acceleration\": [0, -9.81]},"
		 " \"boundaries\": {\"left\": {\"soil\": \"slip\", \"water\": \"slip\"}, \"right\": {\"soil\": \"slip\", \"water\": \"slip\"},"
		 "   \"bottom\": {\"soil\": \"fixed\", \"water\": \"slip\"}},"
		 " \"loads\": [{\"body\": \"block\", \"face\": \"top\", \"from\": 0, \"to\": %g, \"traction\": [0, -2e4]}],"
		 " \"time\": {\"dt\": 1e-4, \"end\": 1}}",
		 phases, projection, width, height + 1.0, h, width, height, ppc, width / 5);
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
	const char *phases = "double_point", *projection = "laplacian";
	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--cells-x") && i + 1 < argc) cells_x = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--cells-y") && i + 1 < argc) cells_y = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--ppc") && i + 1 < argc) ppc = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--steps") && i + 1 < argc) steps = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--single-point")) phases = "single_point";
		else if (!strcmp(argv[i], "--projection") && i + 1 < argc) projection = argv[++i];
		else if (!strcmp(argv[i], "--threads") && i + 1 < argc && (runs = parse_threads(argv[++i], counts))) ;
		else {
			fprintf(stderr, "solver_bench: unknown or malformed argument '%s'\n", argv[i]);
			return 2;
		}
	}
	char *json = make_case(cells_x, cells_y, ppc, phases, projection);
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
	double before[COUNTS_MAX][PHASE_COUNT];
	for (int k = 0; k < WARMUP + steps; k++)
		for (int r = 0; r < runs; r++) {
			if (k == WARMUP)
				for (int ph = 0; ph < PHASE_COUNT; ph++)
					before[r][ph] = sim_phase_seconds(s[r], ph);
			omp_set_num_threads(counts[r]);
			if (sim_step(s[r])) {
				fprintf(stderr, "solver_bench: %s\n", sim_error(s[r])->message);
				return 3;
			}
		}
	const char *policy = getenv("OMP_WAIT_POLICY");
	printf("%s, %s projection: %ld soil + %ld water points, %d x %d cells, %d steps timed, the thread counts "
	       "stepped in turn (OMP_WAIT_POLICY=%s)\n", phases, projection, (long)sim_soil(s[0])->n,
	       sim_is_double_point(s[0]) ? (long)sim_water(s[0])->n : 0L, cells_x, cells_y, steps,
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
	for (int row = 0; row < PHASE_COUNT + 3; row++) {
		const char *name = row < PHASE_COUNT ? sim_phase_name(row) : row == PHASE_COUNT ? "TOTAL" :
				   row == PHASE_COUNT + 1 ? "particle and grid phases" : "pressure assembly+solve";
		printf("  %-26s", name);
		for (int r = 0; r < runs; r++)
			printf("  %9.4f", us[r][row]);
		for (int r = 1; r < runs; r++)
			printf("  %10.2f", us[r][row] > 0.0 ? us[0][row] / us[r][row] : 0.0);
		printf("\n");
	}
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
