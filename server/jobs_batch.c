/*
 * jobs_batch.c - the batch label and the exclusive flag of a submission (jobs_submit.h).
 *
 * A benchmark nightly submits its jobs as one batch: every job carries the run's label (so the
 * jobs of a run can be told apart in listings and logs), and the jobs that time the solver carry
 * "exclusive": true, which a worker honours by running such a job alone, neither beside another
 * job nor with another started beside it (worker/slot.c; docs/benchmarks.md "Exclusive jobs").
 */
#include "api.h"
#include "jobs_submit.h"

#include "bench_names.h"

#include <stdlib.h>
#include <string.h>

int jobs_batch_members(struct request *r, json_t *body, char **batch, int *exclusive)
{
	json_t *label = json_object_get(body, "batch"), *flag = json_object_get(body, "exclusive");
	*batch = NULL;
	*exclusive = 0;
	if (flag && !json_is_null(flag)) {
		if (!json_is_boolean(flag)) {
			reply_fail(r, API_INVALID_REQUEST, "/exclusive", "'exclusive' must be true or false");
			return -1;
		}
		*exclusive = json_is_true(flag);
	}
	if (!label || json_is_null(label))
		return 0;
	if (!json_is_string(label) || !bench_label_valid(json_string_value(label))) {
		reply_fail(r, API_INVALID_REQUEST, "/batch", "'batch' must be 1 to %d characters of A-Z a-z 0-9 . _ : -",
			   JOBS_BATCH_MAX);
		return -1;
	}
	if (!(*batch = strdup(json_string_value(label)))) {
		reply_fail(r, API_UNAVAILABLE, "", "no memory to store the batch label: retry later");
		return -1;
	}
	return 0;
}
