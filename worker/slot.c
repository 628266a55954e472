/*
 * slot.c - the claim loop of one slot: long-poll POST /v1/worker/claim, run the job it returns,
 * repeat until the worker drains. Each slot has two clients: the claim client aborts its long-poll
 * at once when the worker drains; the job client never aborts, so a draining worker still delivers
 * its running jobs' logs, files and outcomes. A claim that fails for want of a server is retried
 * with backoff; a refused token, or a server whose TLS certificate cannot be verified, ends the
 * worker.
 *
 * Exclusive jobs (docs/benchmarks.md "Exclusive jobs": the jobs that time the solver) run alone
 * on the worker. The slots share three facts under one lock: how many jobs run, whether an
 * exclusive job runs or waits for its turn, and whether a slot's claim is the one that may be
 * answered with an exclusive job. A claim says "exclusive": true only when no job runs and no
 * other slot's claim says so, so the server hands an exclusive job to an idle worker, one claim
 * at a time. A claim already waiting may still bring back another job; so a job also waits for
 * its turn before its solver starts (slot_try_start, job.c): an exclusive job until no other job
 * runs, any other job while an exclusive one runs or waits. And no slot claims while an exclusive
 * job runs or waits.
 */
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "backoff.h"
#include "http_client.h"
#include "job.h"
#include "worker.h"

static pthread_mutex_t turn_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t turn_changed = PTHREAD_COND_INITIALIZER;
static int jobs_running;        /* solvers started and not yet finished */
static int exclusive_pending;   /* an exclusive job was claimed: it runs or waits for its turn */
static int exclusive_claimer;   /* a slot's claim may bring back an exclusive job */

int slot_try_start(int exclusive)
{
	pthread_mutex_lock(&turn_lock);
	/* the exclusive job waiting for its turn is itself counted in exclusive_pending */
	int may = exclusive ? jobs_running == 0 : !exclusive_pending;
	if (may)
		jobs_running++;
	pthread_mutex_unlock(&turn_lock);
	return may;
}

void slot_finished(int exclusive)
{
	pthread_mutex_lock(&turn_lock);
	jobs_running--;
	if (exclusive)
		exclusive_pending = 0;
	pthread_cond_broadcast(&turn_changed);
	pthread_mutex_unlock(&turn_lock);
}

/* An exclusive job that never started (the worker stopped first) holds the worker no more. */
static void exclusive_abandoned(void)
{
	pthread_mutex_lock(&turn_lock);
	exclusive_pending = 0;
	pthread_cond_broadcast(&turn_changed);
	pthread_mutex_unlock(&turn_lock);
}

/* Before a claim: waits while an exclusive job runs or waits (the worker drains meanwhile, if
 * told to); then 1 when this claim may be answered with an exclusive job, and it holds that right
 * until claim_end. */
static int claim_begin(void)
{
	pthread_mutex_lock(&turn_lock);
	while (exclusive_pending && !atomic_load(&worker_draining)) {
		struct timespec ts;
		clock_gettime(CLOCK_REALTIME, &ts);
		ts.tv_nsec += 200000000L;   /* a drain is noticed within 0.2 s */
		if (ts.tv_nsec >= 1000000000L) {
			ts.tv_sec++;
			ts.tv_nsec -= 1000000000L;
		}
		pthread_cond_timedwait(&turn_changed, &turn_lock, &ts);
	}
	int may = jobs_running == 0 && !exclusive_claimer && !exclusive_pending;
	if (may)
		exclusive_claimer = 1;
	pthread_mutex_unlock(&turn_lock);
	return may;
}

/* After a claim: gives the right back; a claimed exclusive job holds the worker from now on. */
static void claim_end(int claimer, int got_exclusive)
{
	pthread_mutex_lock(&turn_lock);
	if (claimer)
		exclusive_claimer = 0;
	if (got_exclusive)
		exclusive_pending = 1;
	pthread_cond_broadcast(&turn_changed);
	pthread_mutex_unlock(&turn_lock);
}

/* The claim: "exclusive" when it may be answered with an exclusive job; with a lifetime it says
 * how many seconds a job may still run here (the server gives only jobs whose wall_time_seconds
 * fit), and with --idle-exit it waits no longer than the idle time left.
 *
 * With a memory limit it says the memory a job claimed now may use, max_memory_mb (the server
 * gives only jobs whose memory_mb fit, or that stated none). That is the limit itself: each
 * solver runs under its own RLIMIT_AS of --memory-limit-mb, whose default already divides the
 * machine among the slots, so what the other slots run takes nothing from this slot's share, and
 * a job asking more would only fail, out of memory, here. Sent by every worker with a limit, not
 * only by pilots: that failure is final wherever it happens. */
static json_t *claim_body(double now, double idle_since, int exclusive_ok)
{
	int wait = WORKER_CLAIM_WAIT;
	if (worker_opt.idle_exit > 0) {
		double left = idle_since + (double)worker_opt.idle_exit - now;
		wait = left < wait ? (left > 1 ? (int)left : 1) : wait;
	}
	long left = worker_seconds_left(now);
	if (left >= 0 && left < wait)   /* a job handed in now would be handed back at once */
		wait = left > 1 ? (int)left : 1;
	json_t *body = json_pack("{s:s, s:s, s:i, s:i, s:b}", "worker", worker_opt.name, "host", worker_opt.host,
				 "threads", worker_opt.threads, "wait_seconds", wait, "exclusive", exclusive_ok);
	if (body && left >= 0) {
		/* a pilot's allocation is fixed: it takes only what fits in its time and cores */
		json_object_set_new(body, "seconds_left", json_integer(left));
		json_object_set_new(body, "max_threads", json_integer(worker_opt.threads));
	}
	if (body && worker_opt.memory_limit_mb > 0)
		json_object_set_new(body, "max_memory_mb", json_integer(worker_opt.memory_limit_mb));
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
		int may_exclusive = claim_begin();
		if (atomic_load(&worker_draining)) {
			claim_end(may_exclusive, 0);
			break;
		}
		json_t *body = claim_body(worker_now(), idle_since, may_exclusive);
		long status = http_json(claimer, "POST", "/v1/worker/claim", body, NULL, WORKER_CLAIM_WAIT + 30, &r);
		json_decref(body);
		const json_t *job = status == 200 ? json_object_get(r.json, "job") : NULL;
		int exclusive = json_is_object(job) && json_is_true(json_object_get(job, "exclusive"));
		claim_end(may_exclusive, exclusive);
		if (atomic_load(&worker_draining) && status == 0) {
			http_response_release(&r);
			break;
		}
		if (json_is_object(job)) {
			backoff_reset(&b);
			if (job_run(runner, job))
				slot_finished(exclusive);
			else if (exclusive)
				exclusive_abandoned();
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
