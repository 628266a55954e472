/*
 * admin_api.c - the operators' routes (docs/service.md §3 "Operators"): /healthz (no token),
 * /metrics (admin or worker token), creating users (admin), and creating (admin), listing and
 * revoking tokens (admin: every token; a user: their own). A new token is shown once, in the
 * answer; only its SHA-256 is stored, and listings show an id and a short fingerprint.
 *
 * /healthz checks what a working server needs rather than only that the database reads: a real
 * write through the writer thread (store_health_write), free space on the state file system
 * above --min-free-mb, and that files/ accepts a new file. It needs no token, so its answer is
 * computed at most once per HEALTH_CACHE_MS and shared: a client hammering it costs at most about
 * one write a second. While one request computes a fresh answer, others get the previous one
 * rather than queueing behind a write that may be stuck.
 */
#include "api.h"
#include "metrics.h"
#include "state_dir.h"
#include "store.h"

#include "digest.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#define CAP_MAX 10000000
#define STORED_MAX (1LL << 60)   /* bytes */
#define HEALTH_CACHE_MS 1000
#define TOKEN_LABEL_MAX 128
#define TOKEN_PAGE_DEFAULT 100
#define TOKEN_PAGE_MAX 1000
#define TOKEN_ID_MAX (1LL << 62)

/* The last /healthz answer, shared by every connection thread. */
static struct {
	pthread_mutex_t lock;
	pthread_cond_t done;       /* a computation finished */
	int computing;
	long long at_ms;           /* when text was computed; 0 before the first */
	int status;
	char *text;                /* JSON answer, malloc'ed */
	size_t size;
} health = { PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, 0, 0, 0, NULL, 0 };

/* Records one check in checks (and its name in failing when it failed). */
static void health_check(json_t *checks, json_t *failing, const char *name, int ok, const char *why)
{
	json_object_set_new(checks, name, json_string(ok ? "ok" : why));
	if (!ok)
		json_array_append_new(failing, json_string(name));
}

/* Runs every check; returns the HTTP status and the answer in *text. */
static int health_compute(struct server *srv, char **text, size_t *size)
{
	json_t *checks = json_object(), *failing = json_array();
	int read_ok = store_ping(srv->store) == 0;
	health_check(checks, failing, "database_read", read_ok, "the database cannot be read");
	struct api_error err = { 0 };
	int write_ok = store_health_write(srv->store, &err) == API_OK;
	health_check(checks, failing, "database_write", write_ok, err.message);
	char why[SERVER_MESSAGE_MAX];
	long long free_bytes = state_dir_free_bytes(srv->cfg.state), floor = (long long)srv->cfg.min_free_mb << 20;
	if (free_bytes < 0)
		snprintf(why, sizeof why, "cannot read the free space of the state file system");
	else
		snprintf(why, sizeof why, "%lld MiB free on the state file system, below the floor of %d MiB "
			 "(--min-free-mb)", free_bytes >> 20, srv->cfg.min_free_mb);
	health_check(checks, failing, "disk_space", free_bytes >= floor, why);
	int files_ok = state_dir_probe_files(srv->cfg.state, why, sizeof why) == 0;
	health_check(checks, failing, "files", files_ok, why);
	int ok = json_array_size(failing) == 0;
	json_t *body = json_pack("{s:s, s:s, s:s, s:o, s:o}", "status", ok ? "ok" : "degraded", "database",
				 read_ok && write_ok ? "ok" : "unavailable", "version", PORO_VERSION, "checks", checks,
				 "failing", failing);
	*text = body ? json_dumps(body, JSON_COMPACT) : NULL;
	json_decref(body);
	*size = *text ? strlen(*text) : 0;
	return ok ? 200 : 503;
}

void admin_healthz(struct request *r)
{
	pthread_mutex_lock(&health.lock);
	for (;;) {
		if (health.text && now_ms() - health.at_ms < HEALTH_CACHE_MS)
			break;
		if (!health.computing) {
			health.computing = 1;
			pthread_mutex_unlock(&health.lock);
			char *text = NULL;
			size_t size = 0;
			int status = health_compute(r->srv, &text, &size);
			pthread_mutex_lock(&health.lock);
			health.computing = 0;
			pthread_cond_broadcast(&health.done);
			if (text) {
				free(health.text);
				health.text = text;
				health.size = size;
				health.status = status;
				health.at_ms = now_ms();
			}
			break;
		}
		if (health.text)
			break; /* the previous answer while another request computes the next */
		pthread_cond_wait(&health.done, &health.lock);
	}
	char *copy = health.text ? malloc(health.size + 1) : NULL;
	if (copy) {
		memcpy(copy, health.text, health.size);
		copy[health.size] = '\n';
	}
	int status = health.status;
	size_t size = health.size + 1;
	pthread_mutex_unlock(&health.lock);
	if (!copy) {
		reply_fail(r, API_UNAVAILABLE, "", "out of memory: retry later");
		return;
	}
	reply_header(r, "Cache-Control", "no-store");
	reply_text(r, status, "application/json", copy, size);
}

void admin_metrics(struct request *r)
{
	size_t size = 0;
	char *text = metrics_render(r->srv->metrics, r->srv->store, &size);
	if (!text) {
		reply_fail(r, API_UNAVAILABLE, "", "out of memory: retry later");
		return;
	}
	reply_text(r, 200, "text/plain; version=0.0.4; charset=utf-8", text, size);
}

/* User names: like file names, so they are safe in logs, labels and events. */
static int valid_user_name(const char *name)
{
	for (size_t i = 0; name[i]; i++) {
		char c = name[i];
		int alnum = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
		if (!alnum && (i == 0 || (c != '.' && c != '_' && c != '-' && c != '@')))
			return 0;
	}
	return 1;
}

void admin_users_create(struct request *r)
{
	static const char *const keys[] = { "name", "role", "max_queued", "max_running", "max_stored_bytes", NULL };
	json_t *body = api_body_object(r);
	if (!body)
		return;
	const char *name, *role_text;
	long long max_queued, max_running, max_stored;
	enum role role = ROLE_USER;
	if (api_known_keys(r, body, keys) || api_string_member(r, body, "name", SERVER_NAME_MAX, 1, &name) ||
	    api_string_member(r, body, "role", 16, 0, &role_text) ||
	    api_int_member(r, body, "max_queued", 0, CAP_MAX, -1, &max_queued) ||
	    api_int_member(r, body, "max_running", 0, CAP_MAX, -1, &max_running) ||
	    api_int_member(r, body, "max_stored_bytes", 0, STORED_MAX, -1, &max_stored))
		goto done;
	if (!valid_user_name(name)) {
		reply_fail(r, API_INVALID_REQUEST, "/name", "user name must match ^[A-Za-z0-9][A-Za-z0-9._@-]*$");
		goto done;
	}
	if (role_text && role_parse(role_text, &role) != 0) {
		reply_fail(r, API_INVALID_REQUEST, "/role", "'role' must be user, worker or admin");
		goto done;
	}
	json_t *user = NULL;
	struct api_error err = { 0 };
	if (store_user_create(r->srv->store, name, role, (int)max_queued, (int)max_running, &user, &err) != API_OK ||
	    (max_stored >= 0 && store_user_set_max_stored(r->srv->store, name, max_stored, &err) != API_OK)) {
		json_decref(user);
		reply_error(r, &err);
		goto done;
	}
	json_object_set_new(user, "max_stored_bytes", max_stored >= 0 ? json_integer(max_stored) : json_null());
	reply_json(r, 201, user);
done:
	json_decref(body);
}

void admin_tokens_create(struct request *r)
{
	static const char *const keys[] = { "user", "label", NULL };
	json_t *body = api_body_object(r);
	if (!body)
		return;
	const char *user, *label;
	if (api_known_keys(r, body, keys) || api_string_member(r, body, "user", SERVER_NAME_MAX, 1, &user) ||
	    api_string_member(r, body, "label", TOKEN_LABEL_MAX, 0, &label))
		goto done;
	char token[DIGEST_TOKEN_SIZE], hash[DIGEST_HEX_SIZE];
	if (digest_new_token(token) != 0) {
		reply_fail(r, API_INTERNAL, "", "no randomness available for a token");
		goto done;
	}
	digest_hex(token, strlen(token), hash);
	struct api_error err = { 0 };
	json_t *listed = NULL;
	if (store_token_add(r->srv->store, user, 0, hash, label, &listed, &err) != API_OK) {
		reply_error(r, &err);
		goto done;
	}
	json_object_set_new(listed, "token", json_string(token));
	reply_header(r, "Cache-Control", "no-store");
	reply_json(r, 201, listed);
done:
	json_decref(body);
}

void admin_tokens_list(struct request *r)
{
	long long limit, after;
	if (api_query_int(r, "limit", 1, TOKEN_PAGE_MAX, TOKEN_PAGE_DEFAULT, &limit) ||
	    api_query_int(r, "after", 1, TOKEN_ID_MAX, 0, &after))
		return;
	json_t *page = NULL;
	struct api_error err = { 0 };
	if (store_token_list(r->srv->store, &r->who, (int)limit, after, &page, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	reply_header(r, "Cache-Control", "no-store");
	reply_json(r, 200, page);
}

void admin_tokens_revoke(struct request *r)
{
	json_t *token = NULL;
	struct api_error err = { 0 };
	if (store_token_revoke(r->srv->store, &r->who, r->id, &token, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	reply_json(r, 200, token);
}
