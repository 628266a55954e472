/*
 * slot.c - the claim loop of one slot: long-poll POST /v1/worker/claim, run the job it returns,
 * repeat until the worker drains. Each slot has two clients: the claim client aborts its long-poll
 * at once when the worker drains; the job client never aborts, so a draining worker still delivers
 * its running jobs' logs, files and outcomes. A claim that fails for want of a server is retried
 * with backoff; a refused token, or a server whose TLS certificate cannot be verified, ends the
 * worker.
 */
#include <stdio.h>
#include <string.h>

#include "backoff.h"
#include "http_client.h"
#include "job.h"
#include "worker.h"

static json_t *claim_body(void)
{
	return json_pack("{s:s, s:s, s:i, s:i}", "worker", worker_opt.name, "host", worker_opt.host, "threads",
			 worker_opt.threads, "wait_seconds", WORKER_CLAIM_WAIT);
}

void *slot_main(void *arg)
{
	int slot = (int)(size_t)arg;
	struct http_client *claimer = http_client_create(worker_opt.server, worker_opt.token);
	struct http_client *runner = http_client_create(worker_opt.server, worker_opt.token);
	if (!claimer || !runner) {
		worker_say("slot %d: out of memory", slot);
		atomic_store(&worker_fatal, 1);
		atomic_store(&worker_draining, 1);
	} else {
		http_client_set_abort(claimer, &worker_draining);
	}
	struct backoff b = {0};
	json_t *body = claim_body();
	while (!atomic_load(&worker_draining)) {
		struct http_response r;
		char why[700];
		long status = http_json(claimer, "POST", "/v1/worker/claim", body, NULL, WORKER_CLAIM_WAIT + 30, &r);
		if (atomic_load(&worker_draining) && status == 0) {
			http_response_release(&r);
			break;
		}
		if (status == 200 && json_is_object(json_object_get(r.json, "job"))) {
			backoff_reset(&b);
			job_run(runner, json_object_get(r.json, "job"));
		} else if (status == 204) {
			backoff_reset(&b);
		} else if (status == 401 || status == 403 || r.tls_unverified) {
			/* a refused token or an unverifiable server stays so: retrying would only hide it */
			worker_say("%s, stopping: %s", r.tls_unverified ? "server not trusted" : "claim refused",
				   http_describe(&r, why, sizeof why));
			atomic_store(&worker_fatal, 1);
			atomic_store(&worker_draining, 1);
		} else {
			double wait = backoff_fail(&b, worker_now());
			worker_say("slot %d: claim failed, retrying in %.1f s: %s", slot, wait,
				   status == 200 ? "answer without a job" : http_describe(&r, why, sizeof why));
			worker_sleep(wait, 1);
		}
		http_response_release(&r);
	}
	json_decref(body);
	http_client_destroy(&claimer);
	http_client_destroy(&runner);
	return NULL;
}
