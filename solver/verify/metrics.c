/*
 * metrics.c - a run's figures from its final state, see metrics.h. The accuracy figures read the
 * state the run ended in (the last frame of result.h5 holds the same state), except run-out,
 * which report.c derives from result.h5's frames, as `poro-solve report` does.
 */
#include "metrics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case.h"
#include "element.h"
#include "poro.h"
#include "report.h"

void metrics_init(struct metrics *m, const char *kind, const char *title, const char *solver_version)
{
	memset(m, 0, sizeof *m);
	m->kind = kind;
	snprintf(m->title, sizeof m->title, "%s", title ? title : "");
	snprintf(m->solver_version, sizeof m->solver_version, "%s", solver_version ? solver_version : "unknown");
	machine_describe(&m->machine);
	for (int k = 0; k < FIGURE_COUNT; k++)
		m->value[k] = NAN;
}

void metrics_set(struct metrics *m, enum figure_kind k, double value)
{
	m->present |= 1u << k;
	m->value[k] = value;
}

static void set_error(struct metrics *m, const char *error)
{
	m->succeeded = !error;
	snprintf(m->error, sizeof m->error, "%s", error ? error : "");
}

/* Run-out at the last frame of out_dir/result.h5 (report.h); NAN when it cannot be derived. */
static double runout(const char *out_dir)
{
	char path[4200];
	struct report *rep = NULL;
	struct report_row *rows = NULL;
	struct report_settings set = REPORT_SETTINGS_DEFAULT;
	struct poro_error err = {0};
	long n = 0;
	double value = NAN;
	snprintf(path, sizeof path, "%s/result.h5", out_dir);
	if (!report_open(&rep, path, &set, &err) && !report_frames(rep, &rows, &n, &err) && n > 0)
		value = rows[n - 1].runout;
	free(rows);
	report_close(&rep);
	return value;
}

/* The Terzaghi figure over the points that carry pore pressure. */
static double terzaghi(const struct sim *s, const struct case_spec *c)
{
	long n = (long)sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * (size_t)(n + 1)), *xy = malloc(sizeof(double) * 2 * (size_t)(n + 1));
	double value = NAN;
	if (p && xy) {
		sim_pore_pressure(s, p, xy);
		value = figure_terzaghi_rms(c, sim_soil(s), sim_time(s), p, xy, n);
	}
	free(p);
	free(xy);
	return value;
}

void metrics_of_run(struct metrics *m, const struct sim *s, const struct case_spec *c, const char *out_dir,
		    const char *error)
{
	struct sim_timing t;
	sim_get_timing(s, &t);
	set_error(m, error);
	m->at_time = sim_time(s);
	double point_steps = (double)t.steps * (double)t.points;
	metrics_set(m, FIGURE_WALL_SECONDS, t.wall_seconds);
	metrics_set(m, FIGURE_CPU_SECONDS, t.cpu_seconds);
	metrics_set(m, FIGURE_US_PER_POINT_STEP, point_steps > 0 ? 1e6 * t.wall_seconds / point_steps : NAN);
	metrics_set(m, FIGURE_CPU_US_PER_POINT_STEP, point_steps > 0 ? 1e6 * t.cpu_seconds / point_steps : NAN);
	metrics_set(m, FIGURE_MEDIAN_STEP_CPU_US, t.points > 0 ? 1e6 * t.median_step_cpu / (double)t.points : NAN);
	if (c->metrics & FIGURES_NEEDING_REFERENCE) {
		metrics_set(m, FIGURE_REFERENCE_KERNEL_US, 1e6 * t.median_reference_cpu);
		metrics_set(m, FIGURE_RELATIVE_STEP_COST,
			    t.points > 0 && t.median_reference_cpu > 0
				    ? 1e3 * t.median_step_cpu / (double)t.points / t.median_reference_cpu
				    : NAN);
	}
	metrics_set(m, FIGURE_STEPS, (double)sim_steps_taken(s));
	if (c->metrics & 1u << FIGURE_NEWTON_ITERATIONS) {
		/* a count of the steps taken, so a failed run reports it too */
		int last, kept;
		long total = 0;
		sim_iterations(s, &last, &total, NULL, &kept);
		metrics_set(m, FIGURE_NEWTON_ITERATIONS, (double)total);
	}
	if (error)
		return;   /* the state a failure left says nothing about accuracy */
	metrics_set(m, FIGURE_MAX_DISPLACEMENT, figure_max_displacement(sim_soil(s)));
	if (c->metrics & 1u << FIGURE_TERZAGHI_RMS)
		metrics_set(m, FIGURE_TERZAGHI_RMS, terzaghi(s, c));
	if (c->metrics & 1u << FIGURE_XIE_LEO_SETTLEMENT)
		metrics_set(m, FIGURE_XIE_LEO_SETTLEMENT, figure_xie_leo_settlement(c, sim_soil(s), sim_time(s)));
	if (c->metrics & 1u << FIGURE_RUNOUT)
		metrics_set(m, FIGURE_RUNOUT, runout(out_dir));
}

void metrics_of_element(struct metrics *m, const struct element_case *c, const struct element_result *r,
			double wall_seconds, double cpu_seconds, const char *error)
{
	set_error(m, error);
	metrics_set(m, FIGURE_WALL_SECONDS, wall_seconds);
	metrics_set(m, FIGURE_CPU_SECONDS, cpu_seconds);
	metrics_set(m, FIGURE_STEPS, r->rows > 0 ? r->rows - 1 : 0);
	metrics_set(m, FIGURE_NEWTON_ITERATIONS, (double)r->newton_iterations);
	if (error || r->rows < 1)
		return;
	double peak = -INFINITY;
	for (int i = 0; i < r->rows; i++)
		peak = fmax(peak, r->row[i].q);
	metrics_set(m, FIGURE_PEAK_Q, peak);
	const struct element_row *last = &r->row[r->rows - 1];
	if (c->metrics & 1u << FIGURE_MOHR_COULOMB_PEAK)
		metrics_set(m, FIGURE_MOHR_COULOMB_PEAK, figure_mohr_coulomb_peak_error(c, last->q, last->J));
}
