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

/* The claim: with a lifetime it says how many seconds a job may still run here (the server
 * gives only jobs whose wall_time_seconds fit), and with --idle-exit it waits no longer than the
 * idle time left. */
static json_t *claim_body(double now, double idle_since)
{
	int wait = WORKER_CLAIM_WAIT;
	if (worker_opt.idle_exit > 0) {
		double left = idle_since + (double)worker_opt.idle_exit - now;
		wait = left < wait ? (left > 1 ? (int)left : 1) : wait;
	}
	long left = worker_seconds_left(now);
	if (left >= 0 && left < wait)   /* a job handed in now would be handed back at once */
		wait = left > 1 ? (int)left : 1;
	json_t *body = json_pack("{s:s, s:s, s:i, s:i}", "worker", worker_opt.name, "host", worker_opt.host, "threads",
				 worker_opt.threads, "wait_seconds", wait);
	if (body && left >= 0) {
		/* a pilot's allocation is fixed: it takes only what fits in its time and cores */
		json_object_set_new(body, "seconds_left", json_integer(left));
		json_object_set_new(body, "max_threads", json_integer(worker_opt.threads));
	}
	return body;
}

/* 1 when the slot should claim no more: the allocation is about to end, or it idled too long. */
static int slot_retires(int slot, double now, double idle_since)
{
	if (worker_retire_due(now, 1.0)) {
		worker_say("slot %d: the allocation ends in %.0f s: claiming no more", slot, worker_opt.end_at - now);
		return 1;
	}
	if (worker_opt.idle_exit > 0 && now - idle_since >= (double)worker_opt.idle_exit) {
		worker_say("slot %d: no job for %ld s: ending (--idle-exit)", slot, worker_opt.idle_exit);
		return 1;
	}
	return 0;
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
	double idle_since = worker_now();
	while (!atomic_load(&worker_draining) && !slot_retires(slot, worker_now(), idle_since)) {
		struct http_response r;
		char why[700];
		json_t *body = claim_body(worker_now(), idle_since);
		long status = http_json(claimer, "POST", "/v1/worker/claim", body, NULL, WORKER_CLAIM_WAIT + 30, &r);
		json_decref(body);
		if (atomic_load(&worker_draining) && status == 0) {
			http_response_release(&r);
			break;
		}
		if (status == 200 && json_is_object(json_object_get(r.json, "job"))) {
			backoff_reset(&b);
			job_run(runner, json_object_get(r.json, "job"));
			idle_since = worker_now();
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
	http_client_destroy(&claimer);
	http_client_destroy(&runner);
	return NULL;
}
