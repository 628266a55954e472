/*
 * metrics.h - a run's figures (figures.h) as one record, computed from the finished run
 * (metrics.c) and written beside its results (output_metrics.c):
 *   DIR/metrics.json   the document schemas/metrics.schema.json describes: {"schema":
 *                      "poro-metrics/1", "kind", "title", "status", "error", "solver_version",
 *                      "machine": {...}, "figures": {NAME: {"value", "unit", "class"}}}; the job
 *                      service's worker uploads it like result.h5, and the server reads it
 *   DIR/result.h5      group /metrics: one scalar dataset per figure (attributes unit, class), the
 *                      machine and status as attributes of the group (schemas/results.md)
 * poro-solve run and element write both, for a run that succeeded and for one that failed (then
 * with the timing and count figures of the steps it took, and its error).
 */
#ifndef PORO_METRICS_H
#define PORO_METRICS_H

#include "error.h"
#include "figures.h"
#include "machine.h"

#define METRICS_SCHEMA "poro-metrics/1"
#define METRICS_FILE "metrics.json"

struct metrics {
	const char *kind;                 /* "simulation" or "element" */
	char title[256];                  /* the case's */
	int succeeded;                    /* the run reached its end */
	char error[1024];                 /* why it failed, "" when it did not */
	char solver_version[128];
	struct machine machine;           /* where the timings were taken */
	double at_time;                   /* simulated time of the state the accuracy figures read, s */
	unsigned present;                 /* bit (1u << k) per figure reported */
	double value[FIGURE_COUNT];       /* NAN: reported, but undefined for this run */
};

struct sim;
struct case_spec;
struct element_case;
struct element_result;

/* Starts a record: kind, title, version, this machine, nothing reported yet. */
void metrics_init(struct metrics *m, const char *kind, const char *title, const char *solver_version);
void metrics_set(struct metrics *m, enum figure_kind k, double value);

/* The figures of a simulation run that sim_run has ended in out_dir: every run's (timing, counts,
 * max_displacement) and those its case asks for; the accuracy figures only when it succeeded.
 * error is sim_error's message when it failed, else NULL. */
void metrics_of_run(struct metrics *m, const struct sim *s, const struct case_spec *c, const char *out_dir,
		    const char *error);

/* The figures of an element test: wall and processor seconds of element_run, its steps, peak q,
 * Newton iterations, and those its case asks for (r may hold no rows when it failed). */
void metrics_of_element(struct metrics *m, const struct element_case *c, const struct element_result *r,
			double wall_seconds, double cpu_seconds, const char *error);

/* Writes DIR/metrics.json (a temporary file renamed into place) and, when DIR/result.h5 exists,
 * its /metrics group. PORO_EIO naming the file that cannot be written. */
enum poro_status metrics_write(const struct metrics *m, const char *dir, struct poro_error *err);

#endif
