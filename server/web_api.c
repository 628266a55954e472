/*
 * web_api.c - the routes the dashboard's pages read beyond the jobs routes (docs/web.md): a job's
 * case as stored (GET /v1/jobs/{id}/case) and the admin view of workers and queues
 * (GET /v1/admin/workers). The frames are in frames.c, the static files in web.c.
 */
#include "api.h"
#include "metrics.h"
#include "store.h"

#include <stdlib.h>
#include <string.h>

void web_job_case(struct request *r)
{
	char *text = NULL;
	struct api_error err = { 0 };
	if (store_job_case(r->srv->store, &r->who, r->id, &text, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	reply_text(r, 200, "application/json", text, strlen(text));
}

/* Adds to each worker the running jobs whose lease it holds ("jobs"), and its slots: busy (those
 * jobs) plus idle (its claims waiting for work now). A worker whose jobs run while none of its
 * claims waits has every slot busy, which is as many as it runs. */
static void attach_jobs(json_t *workers, json_t *running)
{
	size_t i, k;
	json_t *w, *job;
	json_array_foreach(workers, i, w) {
		json_t *jobs = json_array();
		const char *id = json_string_value(json_object_get(w, "worker"));
		json_array_foreach(running, k, job) {
			const char *holder = json_string_value(json_object_get(job, "worker"));
			if (id && holder && strcmp(id, holder) == 0)
				json_array_append(jobs, job);
		}
		json_int_t idle = json_integer_value(json_object_get(w, "claims_waiting"));
		json_object_set_new(w, "slots_busy", json_integer((json_int_t)json_array_size(jobs)));
		json_object_set_new(w, "slots", json_integer((json_int_t)json_array_size(jobs) + idle));
		json_object_set_new(w, "jobs", jobs);
	}
}

void web_admin_workers(struct request *r)
{
	json_t *overview = NULL;
	struct api_error err = { 0 };
	if (store_admin_overview(r->srv->store, &overview, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	json_t *workers = metrics_workers_json(r->srv->metrics);
	if (!workers) {
		json_decref(overview);
		reply_fail(r, API_UNAVAILABLE, "", "out of memory: retry later");
		return;
	}
	attach_jobs(workers, json_object_get(overview, "running"));
	json_object_set_new(overview, "workers", workers);
	json_object_set_new(overview, "lease_seconds", json_integer(r->srv->cfg.lease_seconds));
	reply_json(r, 200, overview);
}
