/*
 * jobs_submit.h - what a submission (POST /v1/jobs, jobs_api.c) carries beyond the settings of
 * docs/service.md §3's table: a single-element test as its case (jobs_element.c), and the batch
 * label and exclusive flag of the benchmark nightlies (jobs_batch.c, docs/benchmarks.md).
 */
#ifndef PORO_JOBS_SUBMIT_H
#define PORO_JOBS_SUBMIT_H

#include <jansson.h>

#include "case.h"
#include "http.h"

/* case_load_json for a simulation case; for an element case ("poro-element/1") its check by the
 * element loader, *loaded then holding only json (canonical: compact, keys sorted) and warnings.
 * Problems as case_load_json records them. */
enum poro_status jobs_case_load(const json_t *case_spec, struct case_spec **loaded, struct poro_error *err);

/* Largest batch label, bytes; a label is 1 to JOBS_BATCH_MAX characters of [A-Za-z0-9._:-]
 * (bench_label_valid, common/bench_names.h). */
#define JOBS_BATCH_MAX 128

/* The optional "batch" (a label every job of one benchmark run carries; *batch a copy the caller
 * frees, NULL when absent or null) and "exclusive" (true: the job runs alone on its worker;
 * default false) of a submission body. 0, or -1 after replying 422 naming the key. */
int jobs_batch_members(struct request *r, json_t *body, char **batch, int *exclusive);

#endif
