/*
 * metrics.h - the server's Prometheus metrics (docs/service.md §4): counters and histograms kept
 * in memory by the handlers and the writer, and the text exposition format for GET /metrics.
 * Job counts per state and the cost of job listings (SQLite VM steps, full-scan steps, sorts) are
 * read from the store at scrape time. Thread-safe.
 */
#ifndef PORO_METRICS_H
#define PORO_METRICS_H

#include "server.h"

struct metrics *metrics_create(void);             /* NULL when out of memory */
void metrics_destroy(struct metrics **m);

void metrics_count_request(struct metrics *m, int status);
void metrics_observe_claim_latency(struct metrics *m, double seconds);
void metrics_observe_job_duration(struct metrics *m, double seconds);
void metrics_observe_commit(void *m, double seconds);   /* a store commit observer (store.h) */
void metrics_add_lease_expiries(struct metrics *m, int n);
void metrics_add_retries(struct metrics *m, int n);
/* Records a heartbeat (or claim) of a worker for poro_worker_heartbeat_age_seconds{worker, user}:
 * worker is the id the worker sent, user its token's user. */
void metrics_worker_seen(struct metrics *m, const char *worker, const char *user);
/* The same for a claim, which also says the worker's host and the threads a slot offers: delta
 * +1 when the claim starts waiting for work, -1 when it ends, so that claims_waiting counts the
 * worker's idle slots (an idle slot long-polls a claim) for the admin view. */
void metrics_worker_claim(struct metrics *m, const char *worker, const char *user, const char *host, int threads,
			  int delta);
/* [{"worker", "user", "host", "threads", "claims_waiting", "last_seen_at", "seconds_since_seen"}]
 * of the workers remembered (at most 256, the least recently seen replaced first). */
json_t *metrics_workers_json(struct metrics *m);

/* The exposition text (malloc'ed) with job counts from the store; NULL when out of memory. */
char *metrics_render(struct metrics *m, struct store *store, size_t *size);

#endif
