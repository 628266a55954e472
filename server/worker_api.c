/*
 * worker_api.c - the workers' JSON routes (docs/service.md §3 "Workers"): claim by long-poll,
 * heartbeat, log chunks, finish. File transfers are in files.c.
 *
 * A finish may declare "artifacts": [{"name", "size", "sha256"}], the files the worker uploaded for
 * the attempt; "succeeded" needs them (store_finish checks them against the file index).
 *
 * Long-poll: a claim that finds nothing waits on srv->claim_cv, which the writer broadcasts after
 * committing a submission or a re-queue, and retries; it also retries once a second, because a
 * job whose backoff (not_before) passes wakes nobody. The claim sequence number read before each
 * try makes a wake-up between the try and the wait impossible to miss.
 */
#include "api.h"
#include "metrics.h"
#include "store.h"

#include "digest.h"

#include <errno.h>
#include <string.h>
#include <time.h>

#define WAIT_SECONDS_MAX 60
#define THREADS_MAX 256
#define MESSAGE_MAX 8192
#define ATTEMPT_MAX 1000000
#define OFFSET_MAX (1LL << 50)
#define EXIT_CODE_MAX 255
#define ARTIFACTS_MAX 16   /* files one finish may declare; a worker uploads four */
#define MEMORY_MB_MAX (1LL << 30) /* a claim's max_memory_mb: the largest poro-worker --memory-limit-mb */

/* Required integer member: 0, or -1 after replying. */
static int required_int(struct request *r, json_t *body, const char *key, long long min, long long max,
			long long *out)
{
	if (!json_object_get(body, key)) {
		char field[SERVER_FIELD_MAX];
		snprintf(field, sizeof field, "/%s", key);
		reply_fail(r, API_INVALID_REQUEST, field, "missing required key '%s'", key);
		return -1;
	}
	return api_int_member(r, body, key, min, max, 0, out);
}

static void wait_for_work(struct server *srv, unsigned long long seq, long long deadline_ms)
{
	long long until = now_ms() + 1000;
	if (until > deadline_ms)
		until = deadline_ms;
	struct timespec ts = { .tv_sec = (time_t)(until / 1000), .tv_nsec = (long)(until % 1000) * 1000000L };
	pthread_mutex_lock(&srv->wake_lock);
	int rc = 0;
	while (srv->claim_seq == seq && !srv->stopping && rc != ETIMEDOUT)
		rc = pthread_cond_timedwait(&srv->claim_cv, &srv->wake_lock, &ts);
	pthread_mutex_unlock(&srv->wake_lock);
}

void worker_claim(struct request *r)
{
	static const char *const keys[] = { "worker", "host", "threads", "wait_seconds", "exclusive", "seconds_left",
					    "max_threads", "max_memory_mb", NULL };
	json_t *body = api_body_object(r);
	if (!body)
		return;
	const char *worker, *host;
	long long threads, wait, seconds_left, max_threads, max_memory_mb;
	if (api_known_keys(r, body, keys) || api_string_member(r, body, "worker", SERVER_NAME_MAX, 1, &worker) ||
	    api_string_member(r, body, "host", SERVER_NAME_MAX, 0, &host) ||
	    api_int_member(r, body, "threads", 1, THREADS_MAX, 1, &threads) ||
	    api_int_member(r, body, "wait_seconds", 0, WAIT_SECONDS_MAX, 0, &wait) ||
	    api_int_member(r, body, "seconds_left", 0, 1LL << 40, -1, &seconds_left) ||
	    api_int_member(r, body, "max_threads", 1, THREADS_MAX, 0, &max_threads) ||
	    api_int_member(r, body, "max_memory_mb", 1, MEMORY_MB_MAX, 0, &max_memory_mb)) {
		json_decref(body);
		return;
	}
	/* "exclusive": true says the worker runs nothing now and may take an exclusive job (a worker
	 * that does not say so never gets one) */
	json_t *exclusive = json_object_get(body, "exclusive");
	if (exclusive && !json_is_boolean(exclusive) && !json_is_null(exclusive)) {
		reply_fail(r, API_INVALID_REQUEST, "/exclusive", "'exclusive' must be true or false");
		json_decref(body);
		return;
	}
	struct server *srv = r->srv;
	struct job_claim in = { .who = &r->who, .worker = worker, .host = host ? host : worker,
				.exclusive_ok = json_is_true(exclusive), .seconds_left = seconds_left,
				.max_threads = max_threads, .max_memory_mb = max_memory_mb };
	long long deadline = now_ms() + 1000 * wait;
	metrics_worker_claim(srv->metrics, worker, r->who.name, in.host, (int)threads, 1);
	server_worker_seen(srv);
	atomic_fetch_add(&srv->claims_waiting, 1);
	for (;;) {
		pthread_mutex_lock(&srv->wake_lock);
		unsigned long long seq = srv->claim_seq;
		pthread_mutex_unlock(&srv->wake_lock);
		json_t *job = NULL;
		struct api_error err = { 0 };
		if (http_client_gone(r)) {   /* the worker stopped waiting: a job leased now would be lost */
			reply_text(r, 204, NULL, NULL, 0);
			break;
		}
		if (store_claim(srv->store, &in, &job, &err) != API_OK) {
			reply_error(r, &err);
			break;
		}
		if (job) {
			metrics_observe_claim_latency(srv->metrics, 1e-3 * (double)in.claim_latency_ms);
			reply_json(r, 200, json_pack("{s:o}", "job", job));
			break;
		}
		if (srv->stopping || now_ms() >= deadline) {
			reply_text(r, 204, NULL, NULL, 0);
			break;
		}
		wait_for_work(srv, seq, deadline);
	}
	atomic_fetch_sub(&srv->claims_waiting, 1);
	metrics_worker_claim(srv->metrics, worker, r->who.name, in.host, (int)threads, -1);
	server_worker_seen(srv);
	json_decref(body);
}

void worker_heartbeat(struct request *r)
{
	static const char *const keys[] = { "attempt", "progress", "solver_version", "worker", NULL };
	json_t *body = api_body_object(r);
	if (!body)
		return;
	long long attempt;
	const char *version, *worker;
	json_t *progress = json_object_get(body, "progress");
	if (api_known_keys(r, body, keys) || required_int(r, body, "attempt", 1, ATTEMPT_MAX, &attempt) ||
	    api_string_member(r, body, "solver_version", SERVER_NAME_MAX, 0, &version) ||
	    api_string_member(r, body, "worker", SERVER_NAME_MAX, 0, &worker))
		goto done;
	if (progress && !json_is_null(progress) && !json_is_object(progress)) {
		reply_fail(r, API_INVALID_REQUEST, "/progress", "'progress' must be an object or null");
		goto done;
	}
	int cancel = 0;
	long long expires = 0;
	struct api_error err = { 0 };
	if (store_heartbeat(r->srv->store, &r->who, r->id, (int)attempt, json_is_object(progress) ? progress : NULL,
			    version, &cancel, &expires, &err) != API_OK) {
		reply_error(r, &err);
		goto done;
	}
	/* a worker that sends no id (older ones) shows under its token's user */
	metrics_worker_seen(r->srv->metrics, worker ? worker : r->who.name, r->who.name);
	server_worker_seen(r->srv);
	char at[32];
	format_time(expires, at);
	reply_json(r, 200, json_pack("{s:b, s:s}", "cancel", cancel, "lease_expires_at", at));
done:
	json_decref(body);
}

void worker_log(struct request *r)
{
	static const char *const keys[] = { "attempt", "offset", "text", NULL };
	json_t *body = api_body_object(r);
	if (!body)
		return;
	long long attempt, offset;
	json_t *text = json_object_get(body, "text");
	if (api_known_keys(r, body, keys) || required_int(r, body, "attempt", 1, ATTEMPT_MAX, &attempt) ||
	    required_int(r, body, "offset", 0, OFFSET_MAX, &offset))
		goto done;
	if (!json_is_string(text)) {
		reply_fail(r, API_INVALID_REQUEST, "/text", text ? "'text' must be a string" : "missing required key 'text'");
		goto done;
	}
	long long next = 0;
	struct api_error err = { 0 };
	if (store_log_append(r->srv->store, &r->who, r->id, (int)attempt, offset, json_string_value(text),
			     json_string_length(text), &next, &err) != API_OK) {
		reply_error(r, &err);
		goto done;
	}
	reply_json(r, 200, json_pack("{s:I}", "next_offset", (json_int_t)next));
done:
	json_decref(body);
}

/* One declared artifact {"name", "size", "sha256"} at /artifacts/i: 0, or -1 after replying 422. */
static int parse_artifact(struct request *r, json_t *item, size_t i, struct finish_artifact *a, char *sha)
{
	char field[SERVER_FIELD_MAX];
	snprintf(field, sizeof field, "/artifacts/%zu", i);
	json_t *name = json_object_get(item, "name"), *size = json_object_get(item, "size");
	json_t *digest = json_object_get(item, "sha256");
	const char *hex = json_string_value(digest);
	int ok = json_is_object(item) && json_object_size(item) == 3 && json_is_string(name) &&
		 api_file_name_valid(json_string_value(name)) && json_is_integer(size) && json_integer_value(size) >= 0 &&
		 hex && strlen(hex) == DIGEST_HEX_SIZE - 1;
	for (int k = 0; ok && k < DIGEST_HEX_SIZE - 1; k++) {
		char c = hex[k];
		ok = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
		sha[k] = (char)(c >= 'A' && c <= 'F' ? c - 'A' + 'a' : c);
	}
	if (!ok) {
		reply_fail(r, API_INVALID_REQUEST, field,
			   "artifact %zu must be {\"name\": a file name, \"size\": bytes >= 0, \"sha256\": 64 hex digits} "
			   "and nothing else", i);
		return -1;
	}
	sha[DIGEST_HEX_SIZE - 1] = '\0';
	*a = (struct finish_artifact){ json_string_value(name), (long long)json_integer_value(size), sha };
	return 0;
}

/* The optional "artifacts" list of a finish: 0 with *count entries, or -1 after replying 422. */
static int parse_artifacts(struct request *r, json_t *body, struct finish_artifact *out,
			   char sha[][DIGEST_HEX_SIZE], int *count)
{
	json_t *list = json_object_get(body, "artifacts"), *item;
	*count = 0;
	if (!list || json_is_null(list))
		return 0;
	if (!json_is_array(list) || json_array_size(list) > ARTIFACTS_MAX) {
		reply_fail(r, API_INVALID_REQUEST, "/artifacts", "'artifacts' must be an array of at most %d files",
			   ARTIFACTS_MAX);
		return -1;
	}
	size_t i;
	json_array_foreach(list, i, item) {
		if (parse_artifact(r, item, i, &out[i], sha[i]))
			return -1;
	}
	*count = (int)json_array_size(list);
	return 0;
}

void worker_finish(struct request *r)
{
	static const char *const keys[] = { "attempt", "outcome", "message", "exit_code", "solver_version",
					    "artifacts", NULL };
	static const char *const outcomes[] = { "succeeded", "failed", "cancelled", "infrastructure", NULL };
	json_t *body = api_body_object(r);
	if (!body)
		return;
	long long attempt, exit_code;
	const char *outcome, *message, *version;
	struct finish_artifact artifacts[ARTIFACTS_MAX];
	char sha[ARTIFACTS_MAX][DIGEST_HEX_SIZE];
	int artifact_count = 0;
	if (api_known_keys(r, body, keys) || required_int(r, body, "attempt", 1, ATTEMPT_MAX, &attempt) ||
	    api_string_member(r, body, "outcome", 32, 1, &outcome) ||
	    api_string_member(r, body, "message", MESSAGE_MAX, 0, &message) ||
	    api_int_member(r, body, "exit_code", -EXIT_CODE_MAX, EXIT_CODE_MAX, -1, &exit_code) ||
	    api_string_member(r, body, "solver_version", SERVER_NAME_MAX, 0, &version) ||
	    parse_artifacts(r, body, artifacts, sha, &artifact_count))
		goto done;
	int known = 0;
	for (const char *const *o = outcomes; *o && !known; o++)
		known = strcmp(*o, outcome) == 0;
	if (!known) {
		reply_fail(r, API_INVALID_REQUEST, "/outcome",
			   "'outcome' must be succeeded, failed, cancelled or infrastructure");
		goto done;
	}
	json_t *job = NULL;
	long long duration = 0;
	struct api_error err = { 0 };
	if (store_finish(r->srv->store, &r->who, r->id, (int)attempt, r->who.name, outcome, message, (int)exit_code,
			 version, artifacts, artifact_count, &job, &duration, &err) != API_OK) {
		reply_error(r, &err);
		goto done;
	}
	metrics_observe_job_duration(r->srv->metrics, 1e-3 * (double)duration);
	if (strcmp(outcome, "infrastructure") == 0 &&
	    strcmp(json_string_value(json_object_get(job, "state")), "queued") == 0)
		metrics_add_retries(r->srv->metrics, 1);
	reply_json(r, 200, job);
done:
	json_decref(body);
}
