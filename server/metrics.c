/*
 * metrics.c - counters, histograms and gauges of poro-server in Prometheus text format
 * (metrics.h). Histograms have fixed bucket bounds in seconds, chosen per quantity (commit times
 * are milliseconds, job durations hours). Worker heartbeat ages are kept per worker id (the id
 * each poro-worker sends in its claims and heartbeats, "host:pid" or its --name) and the user of
 * its token, so workers sharing one token are series of their own; at most WORKERS_MAX of them,
 * the least recently seen replaced first, so the label set stays bounded.
 * Job counts per state and the cost of job listings are read from the store at scrape time.
 */
#include "metrics.h"
#include "store.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BUCKETS_MAX 16
#define WORKERS_MAX 256
#define STATUS_MAX 600

struct histogram {
	const char *name, *help;
	int count;                        /* bucket bounds used */
	double bounds[BUCKETS_MAX];       /* seconds, ascending */
	unsigned long long buckets[BUCKETS_MAX + 1]; /* last: +Inf */
	double sum;
	unsigned long long total;
};

struct worker_seen {
	char id[SERVER_NAME_MAX + 1];     /* the worker's own id */
	char user[SERVER_NAME_MAX + 1];   /* the user of its token */
	long long at_ms;
	char host[SERVER_NAME_MAX + 1];   /* from its claims, "" before one */
	int threads;                      /* threads its claims offer, per slot; 0 before one */
	int claims_waiting;               /* its claims long-polling for work now: its idle slots */
};

struct metrics {
	pthread_mutex_t lock;
	unsigned long long requests[STATUS_MAX];
	unsigned long long lease_expiries, retries;
	struct histogram claim, duration, commit;
	struct worker_seen workers[WORKERS_MAX];
	int worker_count;
};

static const struct histogram CLAIM = {
	"poro_claim_latency_seconds", "time from submission (or re-queue) to claim", 12,
	{ 0.01, 0.05, 0.1, 0.5, 1, 5, 10, 30, 60, 300, 1800, 3600 }, { 0 }, 0, 0 };
static const struct histogram DURATION = {
	"poro_job_duration_seconds", "time from claim to finish of an attempt", 11,
	{ 1, 10, 30, 60, 300, 600, 1800, 3600, 7200, 21600, 86400 }, { 0 }, 0, 0 };
static const struct histogram COMMIT = {
	"poro_commit_seconds", "duration of one group-commit transaction of the writer", 11,
	{ 0.0005, 0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.25, 0.5, 1 }, { 0 }, 0, 0 };

struct metrics *metrics_create(void)
{
	struct metrics *m = calloc(1, sizeof *m);
	if (!m)
		return NULL;
	pthread_mutex_init(&m->lock, NULL);
	m->claim = CLAIM;
	m->duration = DURATION;
	m->commit = COMMIT;
	return m;
}

void metrics_destroy(struct metrics **m)
{
	if (!m || !*m)
		return;
	pthread_mutex_destroy(&(*m)->lock);
	free(*m);
	*m = NULL;
}

static void observe(struct metrics *m, struct histogram *h, double x)
{
	pthread_mutex_lock(&m->lock);
	int i = 0;
	while (i < h->count && x > h->bounds[i])
		i++;
	h->buckets[i]++;
	h->sum += x;
	h->total++;
	pthread_mutex_unlock(&m->lock);
}

void metrics_count_request(struct metrics *m, int status)
{
	if (!m || status < 0 || status >= STATUS_MAX)
		return;
	pthread_mutex_lock(&m->lock);
	m->requests[status]++;
	pthread_mutex_unlock(&m->lock);
}

void metrics_observe_claim_latency(struct metrics *m, double seconds) { observe(m, &m->claim, seconds); }
void metrics_observe_job_duration(struct metrics *m, double seconds) { observe(m, &m->duration, seconds); }

void metrics_observe_commit(void *cls, double seconds)
{
	struct metrics *m = cls;
	observe(m, &m->commit, seconds);
}

void metrics_add_lease_expiries(struct metrics *m, int n)
{
	pthread_mutex_lock(&m->lock);
	m->lease_expiries += (unsigned long long)n;
	pthread_mutex_unlock(&m->lock);
}

void metrics_add_retries(struct metrics *m, int n)
{
	pthread_mutex_lock(&m->lock);
	m->retries += (unsigned long long)n;
	pthread_mutex_unlock(&m->lock);
}

/* The slot of (worker, user), taken over from the least recently seen when new; under m->lock. */
static struct worker_seen *worker_slot(struct metrics *m, const char *worker, const char *user)
{
	int slot = -1, oldest = 0;
	for (int i = 0; i < m->worker_count; i++) {
		if (strcmp(m->workers[i].id, worker) == 0 && strcmp(m->workers[i].user, user) == 0)
			slot = i;
		if (m->workers[i].at_ms < m->workers[oldest].at_ms)
			oldest = i;
	}
	if (slot < 0) {
		slot = m->worker_count < WORKERS_MAX ? m->worker_count++ : oldest;
		memset(&m->workers[slot], 0, sizeof m->workers[slot]);
		snprintf(m->workers[slot].id, sizeof m->workers[slot].id, "%s", worker);
		snprintf(m->workers[slot].user, sizeof m->workers[slot].user, "%s", user);
	}
	return &m->workers[slot];
}

void metrics_worker_seen(struct metrics *m, const char *worker, const char *user)
{
	long long now = now_ms();
	pthread_mutex_lock(&m->lock);
	worker_slot(m, worker, user)->at_ms = now;
	pthread_mutex_unlock(&m->lock);
}

void metrics_worker_claim(struct metrics *m, const char *worker, const char *user, const char *host, int threads,
			  int delta)
{
	long long now = now_ms();
	pthread_mutex_lock(&m->lock);
	struct worker_seen *w = worker_slot(m, worker, user);
	w->at_ms = now;
	snprintf(w->host, sizeof w->host, "%s", host);
	w->threads = threads;
	w->claims_waiting += delta;
	if (w->claims_waiting < 0)   /* its slot was taken over by another worker meanwhile */
		w->claims_waiting = 0;
	pthread_mutex_unlock(&m->lock);
}

json_t *metrics_workers_json(struct metrics *m)
{
	json_t *list = json_array();
	long long now = now_ms();
	pthread_mutex_lock(&m->lock);
	for (int i = 0; list && i < m->worker_count; i++) {
		const struct worker_seen *w = &m->workers[i];
		char at[32];
		format_time(w->at_ms, at);
		json_array_append_new(list, json_pack("{s:s, s:s, s:o, s:i, s:i, s:s, s:f}", "worker", w->id, "user",
						      w->user, "host", w->host[0] ? json_string(w->host) : json_null(),
						      "threads", w->threads, "claims_waiting", w->claims_waiting,
						      "last_seen_at", at, "seconds_since_seen",
						      1e-3 * (double)(now - w->at_ms)));
	}
	pthread_mutex_unlock(&m->lock);
	return list;
}

/* ---- exposition ---- */

struct text {
	char *data;
	size_t size, cap;
	int failed;
};

static void put(struct text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(struct text *t, const char *fmt, ...)
{
	va_list ap;
	for (;;) {
		va_start(ap, fmt);
		int n = vsnprintf(t->data ? t->data + t->size : NULL, t->data ? t->cap - t->size : 0, fmt, ap);
		va_end(ap);
		if (n < 0) {
			t->failed = 1;
			return;
		}
		if (t->data && t->size + (size_t)n < t->cap) {
			t->size += (size_t)n;
			return;
		}
		size_t cap = 2 * (t->cap + (size_t)n + 256);
		char *grown = realloc(t->data, cap);
		if (!grown) {
			t->failed = 1;
			return;
		}
		t->data = grown;
		t->cap = cap;
	}
}

/* Label values: backslash, double quote and newline escaped. */
static void put_label(struct text *t, const char *value)
{
	for (const char *p = value; *p; p++) {
		if (*p == '\\' || *p == '"')
			put(t, "\\%c", *p);
		else if (*p == '\n')
			put(t, "\\n");
		else
			put(t, "%c", *p);
	}
}

static void put_histogram(struct text *t, const struct histogram *h)
{
	put(t, "# HELP %s %s\n# TYPE %s histogram\n", h->name, h->help, h->name);
	unsigned long long cumulative = 0;
	for (int i = 0; i < h->count; i++) {
		cumulative += h->buckets[i];
		put(t, "%s_bucket{le=\"%g\"} %llu\n", h->name, h->bounds[i], cumulative);
	}
	cumulative += h->buckets[h->count];
	put(t, "%s_bucket{le=\"+Inf\"} %llu\n%s_sum %.6f\n%s_count %llu\n", h->name, cumulative, h->name, h->sum,
	    h->name, h->total);
}

/* The cost of job listings, as SQLite counts it: a page that cost more with a bigger table
 * would show here without any timing. */
static void put_list_stats(struct text *t, struct store *store)
{
	struct list_stats ls;
	store_list_stats(store, &ls);
	put(t, "# HELP poro_job_list_requests_total job listings (GET /v1/jobs) answered from the database\n"
	       "# TYPE poro_job_list_requests_total counter\nporo_job_list_requests_total %llu\n", ls.requests);
	put(t, "# HELP poro_job_list_vm_steps_total SQLite virtual machine steps of job listings\n"
	       "# TYPE poro_job_list_vm_steps_total counter\nporo_job_list_vm_steps_total %llu\n", ls.vm_steps);
	put(t, "# HELP poro_job_list_fullscan_steps_total steps of job listings in full table scans\n"
	       "# TYPE poro_job_list_fullscan_steps_total counter\nporo_job_list_fullscan_steps_total %llu\n",
	    ls.fullscan_steps);
	put(t, "# HELP poro_job_list_sorts_total sorts done by job listings\n"
	       "# TYPE poro_job_list_sorts_total counter\nporo_job_list_sorts_total %llu\n", ls.sorts);
}

char *metrics_render(struct metrics *m, struct store *store, size_t *size)
{
	struct text t = { 0 };
	long long counts[JOB_STATE_COUNT];
	struct api_error err = { 0 };
	int have_counts = store_job_counts(store, counts, &err) == API_OK;
	api_error_release(&err);
	put(&t, "# HELP poro_jobs jobs per state\n# TYPE poro_jobs gauge\n");
	for (int i = 0; have_counts && i < JOB_STATE_COUNT; i++)
		put(&t, "poro_jobs{state=\"%s\"} %lld\n", job_state_name((enum job_state)i), counts[i]);
	put_list_stats(&t, store);
	long long now = now_ms();
	pthread_mutex_lock(&m->lock);
	put_histogram(&t, &m->claim);
	put_histogram(&t, &m->duration);
	put_histogram(&t, &m->commit);
	put(&t, "# HELP poro_lease_expiries_total leases that expired without a heartbeat\n"
		"# TYPE poro_lease_expiries_total counter\nporo_lease_expiries_total %llu\n", m->lease_expiries);
	put(&t, "# HELP poro_retries_total attempts re-queued after an infrastructure failure\n"
		"# TYPE poro_retries_total counter\nporo_retries_total %llu\n", m->retries);
	put(&t, "# HELP poro_worker_heartbeat_age_seconds seconds since a worker's last heartbeat or claim\n"
		"# TYPE poro_worker_heartbeat_age_seconds gauge\n");
	for (int i = 0; i < m->worker_count; i++) {
		put(&t, "poro_worker_heartbeat_age_seconds{worker=\"");
		put_label(&t, m->workers[i].id);
		put(&t, "\",user=\"");
		put_label(&t, m->workers[i].user);
		put(&t, "\"} %.3f\n", 1e-3 * (double)(now - m->workers[i].at_ms));
	}
	put(&t, "# HELP poro_http_requests_total HTTP requests answered, by status code\n"
		"# TYPE poro_http_requests_total counter\n");
	for (int code = 0; code < STATUS_MAX; code++)
		if (m->requests[code])
			put(&t, "poro_http_requests_total{code=\"%d\"} %llu\n", code, m->requests[code]);
	pthread_mutex_unlock(&m->lock);
	if (t.failed) {
		free(t.data);
		return NULL;
	}
	*size = t.size;
	return t.data;
}
