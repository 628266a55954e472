/*
 * poro_load.c - load generator for the job service (make bench, crash tests).
 *
 *   poro-load submit --server URL --token T --case FILE --clients C --count N [--key-prefix P]
 *                    [--record FILE] [--retry-seconds S] [--pause-ms MS]
 *       N POST /v1/jobs from C threads, each with its own keep-alive connection; submission i
 *       carries Idempotency-Key P-i. Prints
 *       "submissions: N ok, E errors, X.X per second; latency p50 A ms, p90 B ms, p99 C ms, max D ms".
 *       --record writes one line per attempt, "key status job_id" (status 0 when no answer came,
 *       job_id "-" when none), flushed as it goes, so a test that kills the server mid-run can
 *       check that every acknowledged submission survived. With --retry-seconds a submission that
 *       got no answer or a 5xx is sent again with the same key every 50 ms for up to S seconds, as
 *       a client relying on Idempotency-Key would; each try is recorded. Latency is the last try's.
 *       --pause-ms makes each client wait between its submissions (a paced load for crash tests).
 *   poro-load claim --server URL --token WORKER_TOKEN --count N --clients C
 *       claims jobs and finishes each at once as "failed" (a success would need a stored result.h5,
 *       docs/service.md §3); prints claims per second and claim
 *       latency percentiles. A client stops when the queue stays empty for one short long-poll.
 *   poro-load get --server URL --token T --path PATH --count N --clients C
 *       N GET PATH (e.g. "/v1/jobs?state=queued") from C threads, each with its own keep-alive
 *       connection; prints "gets: N ok, E errors, X.X per second; latency p50 ..." (listing
 *       latency for make bench).
 *
 * Failures are counted, never fatal: the tool keeps going when the server disappears. Latency
 * percentiles are over the requests that got an answer (nearest-rank). Options are parsed by
 * getopt_long ("--count 10" or "--count=10", before or after the mode); --help, --version.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "http_client.h"
#include "json_get.h"

/* Long-poll of a load claim, seconds: short, so an empty queue ends the run quickly. */
#define LOAD_CLAIM_WAIT 1
/* Limits of --clients and --count. */
#define LOAD_CLIENTS_MAX 4096
#define LOAD_COUNT_MAX 100000000

#ifndef PORO_VERSION
#define PORO_VERSION "unknown"
#endif

struct load {
	const char *server, *token, *case_file, *key_prefix, *record_path, *path;
	int clients;
	double retry_seconds;    /* resend a failed submission for this long (0: never) */
	long pause_ms;           /* a client's wait between its submissions */
	long count;
	enum { LOAD_SUBMIT, LOAD_CLAIM, LOAD_GET } mode;
	json_t *body;            /* submission body (submit) */
	atomic_long next;        /* next submission index / claims started */
	atomic_long ok, errors, empty;
	double *latency_ms;      /* count entries, NaN where no answer came */
	FILE *record;
	pthread_mutex_t record_lock;
};

static double now_s(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void record(struct load *l, const char *key, long status, long long id)
{
	if (!l->record)
		return;
	pthread_mutex_lock(&l->record_lock);
	if (id >= 0)
		fprintf(l->record, "%s %ld %lld\n", key, status, id);
	else
		fprintf(l->record, "%s %ld -\n", key, status);
	fflush(l->record);
	pthread_mutex_unlock(&l->record_lock);
}

static void *submit_client(void *arg)
{
	struct load *l = arg;
	struct http_client *c = http_client_create(l->server, l->token);
	if (!c)
		return NULL;
	for (;;) {
		long i = atomic_fetch_add(&l->next, 1);
		if (i >= l->count)
			break;
		char key[256], header[300];
		snprintf(key, sizeof key, "%s-%ld", l->key_prefix, i);
		snprintf(header, sizeof header, "Idempotency-Key: %s", key);
		struct http_response r;
		long status;
		long long id;
		const double first = now_s();
		for (;;) {
			double t0 = now_s();
			status = http_json(c, "POST", "/v1/jobs", l->body, header, 60, &r);
			double ms = 1e3 * (now_s() - t0);
			l->latency_ms[i] = status ? ms : NAN;
			id = status == 200 || status == 201 ? json_get_int(r.json, "id", -1) : -1;
			int retry = (status == 0 || status >= 500) && now_s() - first < l->retry_seconds;
			if (!retry)
				break;
			record(l, key, status, id);
			http_response_release(&r);
			struct timespec pause = {0, 50000000};
			nanosleep(&pause, NULL);
		}
		if (id >= 0)
			atomic_fetch_add(&l->ok, 1);
		else
			atomic_fetch_add(&l->errors, 1);
		record(l, key, status, id);
		http_response_release(&r);
		if (l->pause_ms > 0) {
			struct timespec pause = {l->pause_ms / 1000, (l->pause_ms % 1000) * 1000000L};
			nanosleep(&pause, NULL);
		}
	}
	http_client_destroy(&c);
	return NULL;
}

static void *claim_client(void *arg)
{
	struct load *l = arg;
	struct http_client *c = http_client_create(l->server, l->token);
	if (!c)
		return NULL;
	char worker[128];
	snprintf(worker, sizeof worker, "poro-load:%d:%lu", (int)getpid(), (unsigned long)pthread_self());
	json_t *body = json_pack("{s:s, s:s, s:i, s:i}", "worker", worker, "host", "poro-load", "threads", 1,
				 "wait_seconds", LOAD_CLAIM_WAIT);
	for (;;) {
		long i = atomic_fetch_add(&l->next, 1);
		if (i >= l->count)
			break;
		struct http_response r;
		double t0 = now_s();
		long status = http_json(c, "POST", "/v1/worker/claim", body, NULL, LOAD_CLAIM_WAIT + 30, &r);
		l->latency_ms[i] = status ? 1e3 * (now_s() - t0) : NAN;
		json_t *job = json_object_get(r.json, "job");
		if (status == 204) {
			atomic_fetch_add(&l->empty, 1);
			http_response_release(&r);
			break;
		}
		if (status != 200 || !json_is_object(job)) {
			atomic_fetch_add(&l->errors, 1);
			http_response_release(&r);
			continue;
		}
		char path[128];
		snprintf(path, sizeof path, "/v1/worker/jobs/%lld/finish", json_get_int(job, "id", -1));
		json_t *fin = json_pack("{s:I, s:s, s:n, s:i}", "attempt", (json_int_t)json_get_int(job, "attempt", 0),
					"outcome", "failed", "message", "exit_code", 0);
		struct http_response f;
		http_json(c, "POST", path, fin, NULL, 30, &f);
		json_decref(fin);
		if (http_ok(&f))
			atomic_fetch_add(&l->ok, 1);
		else
			atomic_fetch_add(&l->errors, 1);
		http_response_release(&f);
		http_response_release(&r);
	}
	json_decref(body);
	http_client_destroy(&c);
	return NULL;
}

static void *get_client(void *arg)
{
	struct load *l = arg;
	struct http_client *c = http_client_create(l->server, l->token);
	if (!c)
		return NULL;
	for (;;) {
		long i = atomic_fetch_add(&l->next, 1);
		if (i >= l->count)
			break;
		struct http_response r;
		double t0 = now_s();
		long status = http_json(c, "GET", l->path, NULL, NULL, 60, &r);
		l->latency_ms[i] = status ? 1e3 * (now_s() - t0) : NAN;
		atomic_fetch_add(status == 200 ? &l->ok : &l->errors, 1);
		http_response_release(&r);
	}
	http_client_destroy(&c);
	return NULL;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* Nearest-rank percentile q of n sorted values. */
static double percentile(const double *v, size_t n, double q)
{
	if (n == 0)
		return 0;
	size_t k = (size_t)ceil(q * (double)n);
	return v[k > 0 ? k - 1 : 0];
}

static void usage(FILE *f)
{
	fprintf(f, "usage: poro-load submit --server URL --token T --case FILE --clients C --count N\n"
		   "                        [--key-prefix P] [--record FILE] [--retry-seconds S] [--pause-ms MS]\n"
		   "       poro-load claim --server URL --token WORKER_TOKEN --count N --clients C\n"
		   "       poro-load get --server URL --token T --path PATH --count N --clients C\n"
		   "       poro-load --help | --version\n");
}

static int help(void)
{
	usage(stdout);
	printf("\nA load generator for the job service (make bench, the crash tests):\n"
	       "  submit   N POST /v1/jobs of the case from C clients, submission i with Idempotency-Key P-i\n"
	       "  claim    N claims from C worker clients, each finished at once as failed\n"
	       "  get      N GET PATH from C clients\n"
	       "Prints what succeeded and failed, the rate, and latency percentiles; failures are counted,\n"
	       "never fatal.\n"
	       "  --server URL          the server's URL\n"
	       "  --token T             the bearer token\n"
	       "  --clients C           concurrent clients, each with its own keep-alive connection (>= 1)\n"
	       "  --count N             requests in all (>= 1)\n"
	       "  --case FILE           submit: the case file\n"
	       "  --key-prefix P        submit: the idempotency keys' prefix (load)\n"
	       "  --record FILE         submit: a line \"key status job_id\" per attempt\n"
	       "  --retry-seconds S     submit: resend a submission without an answer or with a 5xx, for S s\n"
	       "  --pause-ms MS         submit: each client's pause between its submissions\n"
	       "  --path PATH           get: the path, e.g. /v1/jobs?state=queued\n"
	       "Exit status: 0 (also when requests failed), 2 for a bad command line, 1 when it cannot start.\n");
	return 0;
}

/* An option value as a number in [lo, hi]: 0, or -1 after naming the option. */
static int number_arg(const char *option, const char *text, double lo, double hi, double *out)
{
	char *end;
	errno = 0;
	double v = strtod(text, &end);
	if (errno || end == text || *end || !(v >= lo && v <= hi)) {
		fprintf(stderr, "poro-load: --%s needs a number in %.15g..%.15g, got '%s'\n", option, lo, hi, text);
		return -1;
	}
	*out = v;
	return 0;
}

/* Parses the command line into l: 0; 1 after --help or --version; -1 after saying what is wrong. */
static int parse_args(struct load *l, int argc, char **argv)
{
	enum { O_SERVER = 1, O_TOKEN, O_CASE, O_KEY_PREFIX, O_RECORD, O_CLIENTS, O_COUNT, O_RETRY, O_PAUSE, O_PATH };
	static const struct option opts[] = {
		{ "server", required_argument, NULL, O_SERVER },   { "token", required_argument, NULL, O_TOKEN },
		{ "case", required_argument, NULL, O_CASE },       { "key-prefix", required_argument, NULL, O_KEY_PREFIX },
		{ "record", required_argument, NULL, O_RECORD },   { "clients", required_argument, NULL, O_CLIENTS },
		{ "count", required_argument, NULL, O_COUNT },     { "retry-seconds", required_argument, NULL, O_RETRY },
		{ "pause-ms", required_argument, NULL, O_PAUSE },  { "path", required_argument, NULL, O_PATH },
		{ "help", no_argument, NULL, 'h' },                { "version", no_argument, NULL, 'V' },
		{ NULL, 0, NULL, 0 }
	};
	int c, index = 0;
	double v;
	while ((c = getopt_long(argc, argv, "hV", opts, &index)) != -1) {
		const char *name = opts[index].name;   /* of a long option: the numbers below are long only */
		switch (c) {
		case 'h':
			help();
			return 1;
		case 'V':
			printf("poro-load %s\n", PORO_VERSION);
			return 1;
		case O_SERVER: l->server = optarg; break;
		case O_TOKEN: l->token = optarg; break;
		case O_CASE: l->case_file = optarg; break;
		case O_KEY_PREFIX: l->key_prefix = optarg; break;
		case O_RECORD: l->record_path = optarg; break;
		case O_PATH: l->path = optarg; break;
		case O_CLIENTS:
			if (number_arg(name, optarg, 1, LOAD_CLIENTS_MAX, &v))
				return -1;
			l->clients = (int)v;
			break;
		case O_COUNT:
			if (number_arg(name, optarg, 1, LOAD_COUNT_MAX, &v))
				return -1;
			l->count = (long)v;
			break;
		case O_RETRY:
			if (number_arg(name, optarg, 0, 86400, &l->retry_seconds))
				return -1;
			break;
		case O_PAUSE:
			if (number_arg(name, optarg, 0, 3600000, &v))
				return -1;
			l->pause_ms = (long)v;
			break;
		default: return -1;   /* getopt_long has said what */
		}
	}
	const char *mode = optind < argc ? argv[optind] : "";
	if (!strcmp(mode, "claim"))
		l->mode = LOAD_CLAIM;
	else if (!strcmp(mode, "get"))
		l->mode = LOAD_GET;
	else if (strcmp(mode, "submit")) {
		fprintf(stderr, *mode ? "poro-load: unknown mode '%s': submit, claim or get\n" : "poro-load: no mode%s\n", mode);
		return -1;
	}
	if (optind + 1 < argc) {
		fprintf(stderr, "poro-load: unexpected argument '%s'\n", argv[optind + 1]);
		return -1;
	}
	const char *missing = !l->server ? "--server URL" : !l->token ? "--token T" : !l->clients ? "--clients C" :
			      !l->count ? "--count N" : l->mode == LOAD_GET && !l->path ? "--path PATH" :
			      l->mode == LOAD_SUBMIT && !l->case_file ? "--case FILE" : NULL;
	if (missing) {
		fprintf(stderr, "poro-load: %s: missing %s\n", mode, missing);
		return -1;
	}
	return 0;
}

int main(int argc, char **argv)
{
	static struct load l;
	l.key_prefix = "load";
	int parsed = parse_args(&l, argc, argv);
	if (parsed) {
		if (parsed < 0)
			usage(stderr);
		return parsed < 0 ? 2 : 0;
	}
	if (l.mode == LOAD_SUBMIT) {
		json_error_t jerr;
		json_t *spec = json_load_file(l.case_file, 0, &jerr);
		if (!spec) {
			fprintf(stderr, "poro-load: cannot read '%s': %s (line %d)\n", l.case_file, jerr.text, jerr.line);
			return 1;
		}
		l.body = json_pack("{s:o}", "case", spec);
	}
	if (l.record_path && !(l.record = fopen(l.record_path, "w"))) {
		fprintf(stderr, "poro-load: cannot create '%s': %s\n", l.record_path, strerror(errno));
		return 1;
	}
	l.latency_ms = malloc((size_t)l.count * sizeof *l.latency_ms);
	pthread_t *threads = calloc((size_t)l.clients, sizeof *threads);
	if (!l.latency_ms || !threads || http_global_init() < 0) {
		fprintf(stderr, "poro-load: out of memory\n");
		return 1;
	}
	for (long i = 0; i < l.count; i++)
		l.latency_ms[i] = NAN;
	pthread_mutex_init(&l.record_lock, NULL);
	signal(SIGPIPE, SIG_IGN);
	double t0 = now_s();
	int started = 0;
	for (int i = 0; i < l.clients; i++)
		if (!pthread_create(&threads[started], NULL,
				    l.mode == LOAD_CLAIM ? claim_client : l.mode == LOAD_GET ? get_client : submit_client, &l))
			started++;
	for (int i = 0; i < started; i++)
		pthread_join(threads[i], NULL);
	double elapsed = now_s() - t0;
	size_t n = 0;
	for (long i = 0; i < l.count; i++)
		if (!isnan(l.latency_ms[i]))
			l.latency_ms[n++] = l.latency_ms[i];
	qsort(l.latency_ms, n, sizeof *l.latency_ms, cmp_double);
	long ok = atomic_load(&l.ok), errors = atomic_load(&l.errors);
	if (l.mode == LOAD_CLAIM)
		printf("claims: %ld ok, %ld errors, %ld empty, %.1f per second; ", ok, errors, atomic_load(&l.empty),
		       elapsed > 0 ? (double)ok / elapsed : 0.0);
	else if (l.mode == LOAD_GET)
		printf("gets: %ld ok, %ld errors, %.1f per second; ", ok, errors, elapsed > 0 ? (double)ok / elapsed : 0.0);
	else
		printf("submissions: %ld ok, %ld errors, %.1f per second; ", ok, errors,
		       elapsed > 0 ? (double)ok / elapsed : 0.0);
	printf("latency p50 %.1f ms, p90 %.1f ms, p99 %.1f ms, max %.1f ms\n", percentile(l.latency_ms, n, 0.5),
	       percentile(l.latency_ms, n, 0.9), percentile(l.latency_ms, n, 0.99), n ? l.latency_ms[n - 1] : 0.0);
	if (l.record)
		fclose(l.record);
	json_decref(l.body);
	free(l.latency_ms);
	free(threads);
	http_global_cleanup();
	return 0;
}
