/*
 * bench.h - benchmark runs (docs/benchmarks.md, docs/service.md §3 "Benchmarks"), private to
 * poro-server: what the route handlers (bench_api.c), the plan check (bench_plan.c), the verdicts
 * at finish (bench_finish.c), the reading of the jobs' metrics.json (bench_metrics.c) and the
 * store (store_bench.c) share.
 *
 * A benchmark run is created by its client (`poro nightly run`) after it submitted the suite's
 * jobs as one batch: the plan names the suite, the batch label every job carries, the commit the
 * client ran from, the settings of the timing comparison, and per case its jobs (the repeats) and
 * the figures to judge, each with its check: "band" (an accuracy figure within [min, max]),
 * "history" (a timing figure against the same machine's recent runs, regression.h) or "none"
 * (recorded only). When every job has ended, the client asks the server to finish the run: the
 * server reads each job's metrics.json (the solver's own figures, uploaded by the worker), groups
 * the samples per figure, judges them and stores one row per figure. A figure is named CASE/KIND
 * ("terzaghi/terzaghi_rms"); its series is its rows in one suite, and for timing figures on one
 * machine fingerprint only: timings of two machines are never compared.
 */
#ifndef PORO_BENCH_H
#define PORO_BENCH_H

#include "api.h"
#include "bench_names.h"
#include "regression.h"

#define BENCH_FIGURE_MAX (2 * BENCH_NAME_MAX + 2) /* "CASE/KIND" and its NUL */
#define BENCH_CASES_MAX 500         /* cases of one run */
#define BENCH_JOBS_MAX 100          /* jobs (repeats) of one case */
#define BENCH_FIGURES_MAX 32        /* figures of one case */
#define BENCH_ERROR_MAX 1024        /* a case's submission error, bytes */
#define BENCH_FINGERPRINT_HEX 16    /* hex digits of a machine fingerprint */
#define BENCH_METRICS_MAX (1 << 20) /* bytes of a metrics.json the server reads */

/* ---- the plan (bench_plan.c) ---- */
/* Checks a creation body (POST /v1/benchmarks) completely: keys, names, settings, every case and
 * figure, and that each job exists, is visible to the caller and carries the run's label. 0 with
 * *plan (a new tree: {"settings", "cases": [{"name", "jobs", "error", "figures": [{"kind",
 * "check", "band"}]}]}), or -1 after replying 422 naming the field. */
int bench_plan_check(struct request *r, json_t *body, json_t **plan);
/* The settings of a plan as a regression rule. */
void bench_plan_rule(const json_t *plan, struct regression_rule *rule);

/* ---- metrics.json of a job (bench_metrics.c) ---- */
/* The metrics.json the job's newest attempt uploaded, parsed, after checking the stored copy
 * against its index row (size and SHA-256); NULL with why ("no metrics.json", damage, not JSON). */
json_t *bench_job_metrics(struct server *srv, long long job, char *why, size_t why_size);
/* The fingerprint of a machine object of metrics.json: the first BENCH_FINGERPRINT_HEX hex digits
 * of the SHA-256 of its cpu_model, cores, memory_mb, kernel, compiler and blas (not the host: two
 * identical machines compare), into out[BENCH_FINGERPRINT_HEX + 1]; "" when machine is not one. */
void bench_fingerprint(const json_t *machine, char *out);

/* ---- routes (bench_api.c, bench_finish.c) ---- */
void bench_create(struct request *r);
void bench_list(struct request *r);
void bench_show(struct request *r);
void bench_series(struct request *r);
void bench_finish(struct request *r);

#endif
