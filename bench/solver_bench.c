/*
 * solver_bench.c - speed of the semi-implicit scheme: microseconds per material-point step.
 *
 * A 2-D double-point (or single-point) linear elastic block on a roller box, loaded by a strip
 * traction and its own weight, with at least 100,000 soil points by default (2x2 points per
 * 0.1 m cell on a 25 m x 10 m block). After WARMUP steps it times STEPS steps and prints, per
 * material-point step (soil plus water points), the total and each phase of the step: the
 * particle phases and the pressure assembly and factor-and-solve separately. Figures are
 * printed, never asserted; bench/run.sh runs it on one thread.
 *
 *   solver_bench [--cells-x N] [--cells-y N] [--ppc N] [--steps N] [--single-point]
 *                [--projection laplacian|consistent]
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case.h"
#include "poro.h"

#define WARMUP 3

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

int main(int argc, char **argv)
{
	int cells_x = 250, cells_y = 100, ppc = 2, steps = 20;
	const char *phases = "double_point", *projection = "laplacian";
	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--cells-x") && i + 1 < argc) cells_x = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--cells-y") && i + 1 < argc) cells_y = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--ppc") && i + 1 < argc) ppc = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--steps") && i + 1 < argc) steps = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--single-point")) phases = "single_point";
		else if (!strcmp(argv[i], "--projection") && i + 1 < argc) projection = argv[++i];
		else {
			fprintf(stderr, "solver_bench: unknown argument '%s'\n", argv[i]);
			return 2;
		}
	}
	char *json = make_case(cells_x, cells_y, ppc, phases, projection);
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	if (case_load_string(json, &c, &err) || sim_create(&s, c, &err)) {
		fprintf(stderr, "solver_bench: %s\n", err.message);
		return 2;
	}
	long points = (long)sim_soil(s)->n + (sim_is_double_point(s) ? (long)sim_water(s)->n : 0);
	for (int k = 0; k < WARMUP; k++)
		if (sim_step(s))
			break;
	double before[PHASE_COUNT];
	for (int ph = 0; ph < PHASE_COUNT; ph++)
		before[ph] = sim_phase_seconds(s, ph);
	for (int k = 0; k < steps; k++)
		if (sim_step(s)) {
			fprintf(stderr, "solver_bench: %s\n", sim_error(s)->message);
			return 3;
		}
	double total = 0, pressure = 0;
	printf("%s, %s projection: %ld soil + %ld water points, %d x %d cells, %d steps timed\n", phases, projection,
	       (long)sim_soil(s)->n, sim_is_double_point(s) ? (long)sim_water(s)->n : 0L, cells_x, cells_y, steps);
	for (int ph = 0; ph < PHASE_COUNT; ph++) {
		double sec = sim_phase_seconds(s, ph) - before[ph];
		double us = 1e6 * sec / ((double)steps * points);
		total += us;
		if (ph == PHASE_PRESSURE_ASSEMBLY || ph == PHASE_PRESSURE_SOLVE)
			pressure += us;
		printf("  %-24s %8.4f us per material-point step\n", sim_phase_name(ph), us);
	}
	printf("  %-24s %8.4f us  (particle and grid phases %.4f, pressure solve %.4f)\n", "TOTAL", total,
	       total - pressure, pressure);
	sim_destroy(&s);
	case_destroy(&c);
	free(json);
	return 0;
}
