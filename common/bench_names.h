/*
 * bench_names.h - the names of the benchmark nightlies (docs/benchmarks.md), checked alike by
 * `poro nightly` (cli/poro/suite.c) before it sends anything and by poro-server
 * (server/bench_plan.c, server/jobs_batch.c) when it receives them.
 */
#ifndef PORO_BENCH_NAMES_H
#define PORO_BENCH_NAMES_H

#include <jansson.h>

#define BENCH_NAME_MAX 64            /* suite and case names, bytes */
#define BENCH_LABEL_MAX 128          /* a run's label: the batch label of its jobs */

/* A suite or case name: 1 to BENCH_NAME_MAX of A-Z a-z 0-9 _ . -, not starting with '.'. */
int bench_name_valid(const char *name);
/* A label: 1 to BENCH_LABEL_MAX of A-Z a-z 0-9 . _ : - */
int bench_label_valid(const char *label);
/* The first key of obj not in allowed (NULL-terminated), or NULL. */
const char *bench_unknown_key(const json_t *obj, const char *const *allowed);

#endif
