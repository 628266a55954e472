/*
 * slope_cost_bench.c - the cost comparison of paper 000 §5.3, Table 4: the Mohr-Coulomb slope
 * (tests/cases/mc_slope_k1e-3_{single,double}_point.json) on a fixed 1.0 m grid with dt = 0.004 s,
 * varying only the points per cell, single point against double point.
 *
 * For each points-per-cell value both cases are loaded, given h = 1.0 m, dt = 0.004 s and that
 * value in memory, stripped of frames and checkpoints, and stepped from t = 0 for at most
 * --steps steps (default 300; the 1 s elastic gravity ramp is the first 250), a single-point
 * step and a double-point step in turn, so that a change in the machine's load falls on both
 * alike (run one after the other, the overhead moved by several per cent between repeats on a
 * shared machine). The wall and CPU time of every sim_step() are kept, so that:
 *  - "us/mp-step" is wall time over steps times material points. The material points are those
 *    Table 4 counts for both formulations: soil plus water points (in single point the water
 *    rides on the soil points and the count is the same), so the two figures compare directly;
 *  - the full-run projection prices the ramp steps and the steps after it at their own measured
 *    rates (the plastic return makes the later steps dearer) over the 250 + 1500 steps of 7 s;
 *  - the double-point overhead compares the two runs over the steps both took.
 * A run that fails (the case can lose a soil point off the grid some time after plasticity
 * starts at t = 1 s) is reported with the steps it took and its figures over those, marked
 * "FAILED"; rates after the ramp are then over fewer steps, or absent ("ramp only").
 *
 * Then the per-phase wall time (sim_phase_seconds) of single against double point at one
 * points-per-cell value (--phases-ppc, default 12), so the source of the overhead is visible.
 * Printed, never asserted; bench/run.sh runs it. Threads: OMP_NUM_THREADS (the scatters are
 * serial either way).
 *
 * By default the rows 6x6 to 24x24 (about two and a half minutes on one thread); 32x32, as many
 * points as the other rows together, on request (--ppc 32).
 *
 *   slope_cost_bench [--steps N] [--ppc N]... [--phases-ppc N] [--case-dir DIR]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "case.h"
#include "poro.h"

#define CELL_SIZE 1.0               /* m, Table 4's fixed mesh */
#define TIME_STEP 0.004             /* s */
#define DEFAULT_STEPS 300           /* the 250-step ramp and 50 plastic steps */
#define PPC_MAX 16
#define DEFAULT_PPC_MAX 24          /* rows run without --ppc */

/* 000 Table 4: points per cell, total material points, CPU time (s) single and double point. */
static const struct { int ppc; long points; double single_s, double_s; } paper[] = {
	{ 6, 21540, 1881, 2006 },     { 8, 38320, 3271, 3616 },      { 10, 59900, 5063, 5670 },
	{ 12, 86280, 7655, 8157 },    { 18, 194220, 16768, 17716 },  { 24, 345360, 28540, 31553 },
	{ 32, 614080, 50957, 55598 },
};
#define PAPER_ROWS ((int)(sizeof paper / sizeof paper[0]))

/* One run of one formulation at one points-per-cell value. */
struct run {
	struct case_spec *c;
	struct sim *s;                  /* NULL once closed */
	long max_steps;
	long points;                    /* soil + water points (Table 4's count) */
	long soil, water;
	long steps;                     /* steps completed */
	long ramp_steps;                /* of them, steps within the gravity ramp */
	double *elapsed;                /* [max_steps + 1] wall time of steps 1..k, s; elapsed[0] = 0 */
	double *cpu;                    /* [max_steps + 1] process CPU time of steps 1..k, s (all threads) */
	double phase[PHASE_COUNT];      /* sim_phase_seconds at the end */
	double end_time;                /* case end time, s */
	double ramp_time;               /* gravity ramp, s */
	int failed;
	char message[256];
};

static double clock_seconds(clockid_t id)
{
	struct timespec t;
	clock_gettime(id, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Loads a case file and builds it with Table 4's grid, step and ppc, to run at most max_steps.
 * Returns 0, or -1 if the case could not be set up (message printed). */
static int run_open(struct run *r, const char *path, int ppc, long max_steps)
{
	struct poro_error err = {0};
	memset(r, 0, sizeof *r);
	if (case_load_file(path, &r->c, &err)) {
		fprintf(stderr, "slope_cost_bench: %s\n", err.message);
		return -1;
	}
	r->c->grid.cell_size = CELL_SIZE;
	r->c->time.dt = TIME_STEP;
	r->c->bodies[0].particles_per_cell = ppc;
	r->c->output.frame_interval = 0;
	r->c->checkpoint.interval = 0;
	if (sim_create(&r->s, r->c, &err)) {
		fprintf(stderr, "slope_cost_bench: '%s' at %dx%d: %s\n", path, ppc, ppc, err.message);
		case_destroy(&r->c);
		return -1;
	}
	r->max_steps = max_steps;
	r->soil = sim_soil(r->s)->n;
	r->water = sim_water(r->s)->n;    /* single point: the soil points again */
	r->points = r->soil + r->water;
	r->end_time = r->c->time.end;
	r->ramp_time = r->c->gravity.ramp_time;
	r->elapsed = calloc((size_t)max_steps + 1, sizeof(double));
	r->cpu = calloc((size_t)max_steps + 1, sizeof(double));
	if (!r->elapsed || !r->cpu) {
		fprintf(stderr, "slope_cost_bench: out of memory\n");
		exit(2);
	}
	return 0;
}

/* Takes and times one step unless the run is over. Returns 1 if a step was taken. */
static int run_step(struct run *r)
{
	if (r->failed || r->steps >= r->max_steps || sim_done(r->s))
		return 0;
	const double t0 = clock_seconds(CLOCK_MONOTONIC), c0 = clock_seconds(CLOCK_PROCESS_CPUTIME_ID);
	if (sim_step(r->s)) {
		r->failed = 1;
		snprintf(r->message, sizeof r->message, "%.200s", sim_error(r->s)->message);
		return 0;
	}
	r->steps++;
	r->elapsed[r->steps] = r->elapsed[r->steps - 1] + clock_seconds(CLOCK_MONOTONIC) - t0;
	r->cpu[r->steps] = r->cpu[r->steps - 1] + clock_seconds(CLOCK_PROCESS_CPUTIME_ID) - c0;
	if (sim_time(r->s) <= r->ramp_time + 1e-9)
		r->ramp_steps = r->steps;
	return 1;
}

/* Keeps the phase times and frees the simulation and the case. */
static void run_close(struct run *r)
{
	for (int ph = 0; ph < PHASE_COUNT; ph++)
		r->phase[ph] = sim_phase_seconds(r->s, ph);
	sim_destroy(&r->s);
	case_destroy(&r->c);
}

static void run_release(struct run *r)
{
	free(r->elapsed);
	free(r->cpu);
	r->elapsed = r->cpu = NULL;
}

/* Wall time of the run over steps (a, b], s. */
static double span(const struct run *r, long a, long b)
{
	return r->elapsed[b] - r->elapsed[a];
}

/* Projected wall time of the full run: ramp and later steps each at their measured rate; the
 * ramp rate alone when no later step was timed. Sets *ramp_only then. */
static double projected_seconds(const struct run *r, int *ramp_only)
{
	const long full = lround(r->end_time / TIME_STEP), ramp = lround(r->ramp_time / TIME_STEP);
	const long later = r->steps - r->ramp_steps;
	const double ramp_rate = r->ramp_steps ? span(r, 0, r->ramp_steps) / r->ramp_steps : 0.0;
	*ramp_only = later == 0;
	if (later == 0)
		return ramp_rate * full;
	return ramp_rate * ramp + span(r, r->ramp_steps, r->steps) / later * (full - ramp);
}

static void print_row(int ppc, const struct run *sp, const struct run *dp)
{
	const long common = sp->steps < dp->steps ? sp->steps : dp->steps;
	if (common == 0) {
		printf("%2dx%-2d %8ld %5ld/%-5ld no figures: a run failed in its first step\n", ppc, ppc, dp->points,
		       sp->steps, dp->steps);
		return;
	}
	const double us_sp = 1e6 * span(sp, 0, sp->steps) / ((double)sp->steps * sp->points);
	const double us_dp = 1e6 * span(dp, 0, dp->steps) / ((double)dp->steps * dp->points);
	const double overhead = 100.0 * (span(dp, 0, common) / span(sp, 0, common) - 1.0);
	const double overhead_cpu = 100.0 * (dp->cpu[common] / sp->cpu[common] - 1.0);
	int sp_ramp_only, dp_ramp_only;
	const double full_sp = projected_seconds(sp, &sp_ramp_only), full_dp = projected_seconds(dp, &dp_ramp_only);
	char paper_cpu[48] = "-";
	for (int i = 0; i < PAPER_ROWS; i++)
		if (paper[i].ppc == ppc)
			snprintf(paper_cpu, sizeof paper_cpu, "%.0f / %.0f (%ld pts)", paper[i].single_s,
				 paper[i].double_s, paper[i].points);
	printf("%2dx%-2d %8ld %5ld/%-5ld %7.3f %7.3f %8.1f %8.1f %-28s %+6.1f %+6.1f%s%s\n", ppc, ppc, dp->points,
	       sp->steps, dp->steps, us_sp, us_dp, full_sp, full_dp, paper_cpu, overhead, overhead_cpu,
	       sp_ramp_only || dp_ramp_only ? "  (projection from the ramp only)" : "",
	       sp->failed || dp->failed ? "  FAILED, see below" : "");
	if (sp->points != dp->points)
		printf("      note: single point has %ld points, double point %ld\n", sp->points, dp->points);
}

static void report_failure(int ppc, const char *label, const struct run *r)
{
	if (r->failed)
		printf("  FAILED %dx%d %s after %ld steps (t = %.3f s; %ld after the ramp): %s\n", ppc, ppc, label,
		       r->steps, r->steps * TIME_STEP, r->steps - r->ramp_steps, r->message);
}

/* Per-phase seconds single against double point, and each phase's share of the difference. */
static void print_phases(int ppc, const struct run *sp, const struct run *dp)
{
	const long common = sp->steps < dp->steps ? sp->steps : dp->steps;
	if (common == 0)
		return;
	double sum_sp = 0, sum_dp = 0;
	printf("\nper phase at %dx%d (%ld points, %ld / %ld steps): us per material-point step, single / double / "
	       "difference; share of the total difference\n", ppc, ppc, dp->points, sp->steps, dp->steps);
	const double total_sp = span(sp, 0, sp->steps), total_dp = span(dp, 0, dp->steps);
	const double norm_sp = 1e6 / ((double)sp->steps * sp->points), norm_dp = 1e6 / ((double)dp->steps * dp->points);
	const double diff_total = total_dp * norm_dp - total_sp * norm_sp;
	for (int ph = 0; ph <= PHASE_COUNT; ph++) {
		double a, b;
		if (ph < PHASE_COUNT) {
			a = sp->phase[ph] * norm_sp, b = dp->phase[ph] * norm_dp;
			sum_sp += sp->phase[ph], sum_dp += dp->phase[ph];
		} else {     /* loads, the NaN scan of sim_step and what no phase timer covers */
			a = (total_sp - sum_sp) * norm_sp, b = (total_dp - sum_dp) * norm_dp;
		}
		printf("  %-24s %8.4f %8.4f %+8.4f  %5.1f%%\n", ph < PHASE_COUNT ? sim_phase_name(ph) : "other",
		       a, b, b - a, diff_total != 0.0 ? 100.0 * (b - a) / diff_total : 0.0);
	}
	printf("  %-24s %8.4f %8.4f %+8.4f  (%+.1f%% over the %ld common steps)\n", "TOTAL", total_sp * norm_sp,
	       total_dp * norm_dp, diff_total, 100.0 * (span(dp, 0, common) / span(sp, 0, common) - 1.0), common);
}

/* What is measured: the cases' formulation as they stand (the figures depend on it). */
static void print_header(const char *path, long steps)
{
	static const char *const shapes[] = { "linear", "quadratic_bspline", "cubic_bspline" };
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	printf("Mohr-Coulomb slope, 000 Table 4: h = %.1f m, dt = %.3f s, at most %ld steps timed per run "
	       "(full run 1750)\n", CELL_SIZE, TIME_STEP, steps);
	if (case_load_file(path, &c, &err) == PORO_OK) {
		printf("%s shape functions, %s pressure projection, drag in the correction %s, gravity ramp %g s\n",
		       shapes[c->formulation.shape],
		       c->formulation.pressure_projection == PROJECTION_CONSISTENT ? "consistent" : "laplacian",
		       c->formulation.drag_in_correction ? "on" : "off", c->gravity.ramp_time);
		case_destroy(&c);
	}
	printf("us/mp-s, us/mp-d: wall us per material-point step; full: projected wall s for 1750 steps; "
	       "ovhd: double over single, wall and CPU time\n");
}

int main(int argc, char **argv)
{
	int ppcs[PPC_MAX], count = 0, phases_ppc = 12;
	long steps = DEFAULT_STEPS;
	const char *dir = "tests/cases";
	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--steps") && i + 1 < argc) steps = atol(argv[++i]);
		else if (!strcmp(argv[i], "--ppc") && i + 1 < argc && count < PPC_MAX) ppcs[count++] = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--phases-ppc") && i + 1 < argc) phases_ppc = atoi(argv[++i]);
		else if (!strcmp(argv[i], "--case-dir") && i + 1 < argc) dir = argv[++i];
		else {
			fprintf(stderr, "slope_cost_bench: unknown argument '%s'\n", argv[i]);
			return 2;
		}
	}
	if (steps < 1) {
		fprintf(stderr, "slope_cost_bench: --steps must be at least 1\n");
		return 2;
	}
	if (count == 0)
		for (int i = 0; i < PAPER_ROWS && paper[i].ppc <= DEFAULT_PPC_MAX; i++)
			ppcs[count++] = paper[i].ppc;
	char sp_path[512], dp_path[512];
	snprintf(sp_path, sizeof sp_path, "%s/mc_slope_k1e-3_single_point.json", dir);
	snprintf(dp_path, sizeof dp_path, "%s/mc_slope_k1e-3_double_point.json", dir);
	print_header(dp_path, steps);
	printf("%-5s %8s %11s %7s %7s %8s %8s %-28s %6s %6s\n", "ppc", "points", "steps s/d", "us/mp-s", "us/mp-d",
	       "full s", "full d", "paper CPU s single / double", "ovhd %", "cpu %");
	struct run keep_sp = {0}, keep_dp = {0};   /* the runs of the phase breakdown */
	int keep_ppc = 0;
	for (int i = 0; i < count; i++) {
		struct run sp, dp;
		if (run_open(&sp, sp_path, ppcs[i], steps) || run_open(&dp, dp_path, ppcs[i], steps))
			return 2;
		/* step by step in turn, so that both see the same machine (other processes, clock) */
		while (run_step(&sp) | run_step(&dp))
			;
		run_close(&sp);
		run_close(&dp);
		print_row(ppcs[i], &sp, &dp);
		report_failure(ppcs[i], "single point", &sp);
		report_failure(ppcs[i], "double point", &dp);
		fflush(stdout);
		if (ppcs[i] == phases_ppc || (i == count - 1 && !keep_ppc)) {
			keep_sp = sp, keep_dp = dp, keep_ppc = ppcs[i];
			continue;
		}
		run_release(&sp);
		run_release(&dp);
	}
	print_phases(keep_ppc, &keep_sp, &keep_dp);
	run_release(&keep_sp);
	run_release(&keep_dp);
	return 0;
}
