/*
 * reaper.c - the lease reaper thread (reaper.h). The work happens in the writer's transaction
 * (store_reap), so an expiry and a late heartbeat of the same attempt are ordered: whichever
 * commits first wins, and the loser sees the other's result (a renewed lease, or 409
 * stale_attempt).
 */
#include "reaper.h"
#include "log.h"
#include "metrics.h"
#include "store.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define REAP_INTERVAL_MS 1000

struct reaper {
	struct server *srv;
	pthread_t thread;
	pthread_mutex_t lock;
	pthread_cond_t cv;
	int stop;
};

static void *reaper_main(void *arg)
{
	struct reaper *r = arg;
	pthread_mutex_lock(&r->lock);
	while (!r->stop) {
		long long until = now_ms() + REAP_INTERVAL_MS;
		struct timespec ts = { .tv_sec = (time_t)(until / 1000), .tv_nsec = (long)(until % 1000) * 1000000L };
		int rc = 0;
		while (!r->stop && rc != ETIMEDOUT)
			rc = pthread_cond_timedwait(&r->cv, &r->lock, &ts);
		if (r->stop)
			break;
		pthread_mutex_unlock(&r->lock);
		struct reap_counts counts;
		struct api_error err = { 0 };
		if (store_reap(r->srv->store, &counts, &err) != API_OK)
			log_say(LOG_PRIO_ERR, "reaper: %s", err.message);
		api_error_release(&err);
		metrics_add_lease_expiries(r->srv->metrics, counts.expired);
		metrics_add_retries(r->srv->metrics, counts.retried);
		pthread_mutex_lock(&r->lock);
	}
	pthread_mutex_unlock(&r->lock);
	return NULL;
}

struct reaper *reaper_start(struct server *srv)
{
	struct reaper *r = calloc(1, sizeof *r);
	if (!r)
		return NULL;
	r->srv = srv;
	pthread_mutex_init(&r->lock, NULL);
	pthread_cond_init(&r->cv, NULL);
	if (pthread_create(&r->thread, NULL, reaper_main, r) != 0) {
		free(r);
		return NULL;
	}
	return r;
}

void reaper_stop(struct reaper **rp)
{
	struct reaper *r = rp ? *rp : NULL;
	if (!r)
		return;
	pthread_mutex_lock(&r->lock);
	r->stop = 1;
	pthread_cond_signal(&r->cv);
	pthread_mutex_unlock(&r->lock);
	pthread_join(r->thread, NULL);
	pthread_mutex_destroy(&r->lock);
	pthread_cond_destroy(&r->cv);
	free(r);
	*rp = NULL;
}
