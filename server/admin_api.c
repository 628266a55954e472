/*
 * admin_api.c - the operators' routes (docs/service.md §3 "Operators"): /healthz (no token),
 * /metrics (admin or worker token), and creating users and tokens (admin). A new token is shown
 * once, in the answer; only its SHA-256 is stored.
 */
#include "api.h"
#include "metrics.h"
#include "store.h"

#include "digest.h"

#include <stdlib.h>
#include <string.h>

#define CAP_MAX 10000000
#define STORED_MAX (1LL << 60)   /* bytes */

void admin_healthz(struct request *r)
{
	int ok = store_ping(r->srv->store) == 0;
	reply_header(r, "Cache-Control", "no-store");
	reply_json(r, ok ? 200 : 503, json_pack("{s:s, s:s, s:s}", "status", ok ? "ok" : "degraded", "database",
						ok ? "ok" : "unavailable", "version", PORO_VERSION));
}

void admin_metrics(struct request *r)
{
	size_t size = 0;
	char *text = metrics_render(r->srv->metrics, r->srv->store, &size);
	if (!text) {
		reply_fail(r, API_INTERNAL, "", "out of memory");
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
	static const char *const keys[] = { "user", NULL };
	json_t *body = api_body_object(r);
	if (!body)
		return;
	const char *user;
	if (api_known_keys(r, body, keys) || api_string_member(r, body, "user", SERVER_NAME_MAX, 1, &user))
		goto done;
	char token[DIGEST_TOKEN_SIZE], hash[DIGEST_HEX_SIZE];
	if (digest_new_token(token) != 0) {
		reply_fail(r, API_INTERNAL, "", "no randomness available for a token");
		goto done;
	}
	digest_hex(token, strlen(token), hash);
	struct api_error err = { 0 };
	if (store_token_add(r->srv->store, user, 0, hash, &err) != API_OK) {
		reply_error(r, &err);
		goto done;
	}
	reply_header(r, "Cache-Control", "no-store");
	reply_json(r, 201, json_pack("{s:s, s:s}", "user", user, "token", token));
done:
	json_decref(body);
}
