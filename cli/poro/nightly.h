/*
 * nightly.h - what the files of `poro nightly` share (docs/benchmarks.md): the suite file read
 * and expanded into jobs and a plan (suite.c), the commands (nightly.c: run, show, compare, ls,
 * report) and the reports (nightly_report.c: JUnit XML, and a self-contained HTML page with one
 * plot per figure, drawn as inline SVG).
 */
#ifndef PORO_NIGHTLY_H
#define PORO_NIGHTLY_H

#include <jansson.h>
#include <stdio.h>

#include "bench_names.h"

#define SUITE_SCHEMA "poro-suite/1"
#define SUITE_REPEATS_MAX 100
#define SUITE_HISTORY_REPEATS_MIN 3   /* a lone sample can never make the rank test significant */

/* One case of a suite, ready to submit. */
struct suite_case {
	char name[BENCH_NAME_MAX + 1];
	char path[4096];              /* the case file, as the suite names it (relative to the suite) */
	json_t *spec;                 /* the case after the suite's patch and the metrics it asks for */
	int repeats;                  /* jobs of the case: samples of each figure */
	int exclusive;                /* its jobs run alone on their worker */
	int threads;
	long long wall_time_seconds;  /* 0: the server's default */
	json_t *figures;              /* the plan's list: [{"kind", "check", "band"}] */
};

struct suite {
	char name[BENCH_NAME_MAX + 1];
	char dir[4096];               /* the suite file's directory */
	json_t *settings;             /* {"alpha", "min_effect", "history_runs"} as given, or NULL */
	int count;
	struct suite_case *cases;
};

/* Reads and checks a suite file and every case it names, keeping the cases named in only[]
 * (only_count 0: all). Every problem is printed on stderr as "poro: FILE: POINTER: message"; 0,
 * or the exit status (PORO_EXIT_INVALID_CASE) when there was one. */
int suite_load(const char *path, const char *const *only, int only_count, struct suite *s);
void suite_release(struct suite *s);

/* ---- reports (nightly_report.c) ---- */
/* The JUnit XML of a finished run (the API's BenchmarkRun) into f: a <testsuite> of the suite, a
 * <testcase> per figure (classname SUITE.CASE, name KIND); regressed figures are <failure>s,
 * failed ones <error>s, those that did not run <skipped>; the run's commit, label, solver
 * version and machine are <properties>. */
void nightly_junit(FILE *f, const json_t *run);
/* The HTML report of a run into f: a table of its figures, then per figure an SVG plot of its
 * series over the runs (series[i]: the API's BenchmarkSeries of figure i, or NULL). */
void nightly_html(FILE *f, const json_t *run, json_t *const *series);

/* Writes a report to path through a temporary file renamed into place; 0, or the exit status
 * after saying why not. */
int nightly_write_report(const char *path, const json_t *run, int html);

#endif
