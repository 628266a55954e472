/*
 * store_users.c - users and bearer tokens (store.h). Tokens are stored only as their SHA-256 hex
 * (tokens.sha256), so a copy of the database reveals no usable token; listings show an integer
 * id and the first TOKEN_FINGERPRINT_HEX hex digits of the hash, never the hash itself.
 *
 * Authentication reads the token row on every request, revoked_at included, and keeps nothing
 * in memory: a revocation holds from the next request on. last_used_at is rewritten only when it
 * is older than TOKEN_TOUCH_INTERVAL_MS, so a busy token costs one write a minute, and a failed
 * rewrite (a full disk) never fails the request that triggered it.
 */
#include "store_internal.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define TOKEN_FINGERPRINT_TEXT "8"     /* TOKEN_FINGERPRINT_HEX as SQL text */
#define TOKEN_COLUMNS "t.id, u.name, u.role, t.label, t.created_at, t.last_used_at, t.revoked_at, " \
	"substr(t.sha256, 1, " TOKEN_FINGERPRINT_TEXT ") "
_Static_assert(TOKEN_FINGERPRINT_HEX == 8, "TOKEN_FINGERPRINT_TEXT must spell TOKEN_FINGERPRINT_HEX");

/* A row of TOKEN_COLUMNS as the JSON of a listed token. */
static json_t *token_from_row(sqlite3_stmt *st)
{
	return json_pack("{s:I, s:s, s:s, s:o, s:o, s:o, s:o, s:s}", "id", (json_int_t)sqlite3_column_int64(st, 0),
			 "user", col_text(st, 1), "role", col_text(st, 2), "label", col_json_text(st, 3), "created_at",
			 col_json_time(st, 4), "last_used_at", col_json_time(st, 5), "revoked_at", col_json_time(st, 6),
			 "fingerprint", col_text(st, 7));
}

/* The token id as listed, read through c; NULL with err set when missing. */
static json_t *token_load(struct conn *c, long long id, struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "SELECT " TOKEN_COLUMNS "FROM tokens t JOIN users u ON u.id = t.user_id"
					" WHERE t.id = ?1");
	if (!st) {
		db_fail(c, err, "reading a token");
		return NULL;
	}
	sqlite3_bind_int64(st, 1, id);
	json_t *token = sqlite3_step(st) == SQLITE_ROW ? token_from_row(st) : NULL;
	sqlite3_reset(st);
	if (!token)
		api_fail(err, API_NOT_FOUND, "", "no token %lld", id);
	return token;
}

struct token_touch {
	long long id, now;
};

static enum api_code token_touch_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct token_touch *t = arg;
	sqlite3_stmt *st = conn_stmt(c, "UPDATE tokens SET last_used_at = ?2 WHERE id = ?1"
					" AND (last_used_at IS NULL OR last_used_at <= ?2 - ?3)");
	if (!st)
		return db_fail(c, err, "preparing a token update");
	sqlite3_bind_int64(st, 1, t->id);
	sqlite3_bind_int64(st, 2, t->now);
	sqlite3_bind_int64(st, 3, TOKEN_TOUCH_INTERVAL_MS);
	return step_done(c, st, err, "recording a token's use");
}

/* The principal of a token; *touch gets the token's id when its last_used_at is due a rewrite. */
static enum api_code auth_lookup(struct store *s, const char *token_sha256, struct principal *who,
				 struct token_touch *touch_out, struct api_error *err)
{
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	sqlite3_stmt *st = conn_stmt(c, "SELECT u.id, u.name, u.role, t.id, t.last_used_at, t.revoked_at"
					" FROM tokens t JOIN users u ON u.id = t.user_id WHERE t.sha256 = ?1");
	enum api_code rc = API_UNAUTHORIZED;
	struct token_touch touch = { .id = -1, .now = now_ms() };
	if (!st) {
		rc = db_fail(c, err, "checking a token");
	} else {
		sqlite3_bind_text(st, 1, token_sha256, -1, SQLITE_STATIC);
		if (sqlite3_step(st) != SQLITE_ROW || role_parse(col_text(st, 2), &who->role) != 0) {
			api_fail(err, API_UNAUTHORIZED, "Authorization", "unknown token");
		} else if (sqlite3_column_type(st, 5) != SQLITE_NULL) {
			api_fail(err, API_UNAUTHORIZED, "Authorization", "revoked token");
		} else {
			who->user_id = sqlite3_column_int64(st, 0);
			snprintf(who->name, sizeof who->name, "%s", col_text(st, 1));
			if (sqlite3_column_type(st, 4) == SQLITE_NULL ||
			    sqlite3_column_int64(st, 4) <= touch.now - TOKEN_TOUCH_INTERVAL_MS)
				touch.id = sqlite3_column_int64(st, 3);
			rc = API_OK;
		}
		sqlite3_reset(st);
	}
	store_reader_done(s, c);
	*touch_out = touch;
	return rc;
}

enum api_code store_auth(struct store *s, const char *token_sha256, struct principal *who, struct api_error *err)
{
	struct token_touch touch;
	enum api_code rc = auth_lookup(s, token_sha256, who, &touch, err);
	if (rc == API_OK && touch.id > 0) {
		struct api_error ignored = { 0 };
		store_write(s, token_touch_run, &touch, &ignored); /* best effort, see the top of this file */
	}
	return rc;
}

enum api_code store_auth_peek(struct store *s, const char *token_sha256, struct principal *who,
			      struct api_error *err)
{
	struct token_touch touch;
	return auth_lookup(s, token_sha256, who, &touch, err);
}

struct user_op {
	const char *name;
	enum role role;
	int max_queued, max_running;
	int create_if_missing;     /* token_add: create the user when absent */
	const char *token_sha256;  /* token_add */
	const char *label;         /* token_add, or NULL */
	json_t *user;
	json_t *token;             /* token_add: the new token as listed */
};

static enum api_code insert_user(struct conn *c, struct user_op *op, struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "INSERT INTO users (name, role, max_queued, max_running, created_at)"
					" VALUES (?1, ?2, ?3, ?4, ?5)");
	if (!st)
		return db_fail(c, err, "preparing a user insert");
	sqlite3_bind_text(st, 1, op->name, -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 2, role_name(op->role), -1, SQLITE_STATIC);
	if (op->max_queued >= 0)
		sqlite3_bind_int(st, 3, op->max_queued);
	if (op->max_running >= 0)
		sqlite3_bind_int(st, 4, op->max_running);
	sqlite3_bind_int64(st, 5, now_ms());
	int rc = sqlite3_step(st);
	sqlite3_reset(st);
	if (rc == SQLITE_CONSTRAINT)
		return api_fail(err, API_ALREADY_EXISTS, "/name", "user '%s' already exists", op->name);
	return rc == SQLITE_DONE ? API_OK : db_fail(c, err, "inserting a user");
}

static enum api_code user_create_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct user_op *op = arg;
	enum api_code rc = insert_user(c, op, err);
	if (rc != API_OK)
		return rc;
	op->user = json_pack("{s:I, s:s, s:s, s:o, s:o}", "id", (json_int_t)sqlite3_last_insert_rowid(c->db),
			     "name", op->name, "role", role_name(op->role),
			     "max_queued", op->max_queued >= 0 ? json_integer(op->max_queued) : json_null(),
			     "max_running", op->max_running >= 0 ? json_integer(op->max_running) : json_null());
	return API_OK;
}

enum api_code store_user_create(struct store *s, const char *name, enum role role, int max_queued,
				int max_running, json_t **user, struct api_error *err)
{
	struct user_op op = { .name = name, .role = role, .max_queued = max_queued, .max_running = max_running };
	enum api_code rc = store_write(s, user_create_run, &op, err);
	if (rc != API_OK) {
		json_decref(op.user);
		return rc;
	}
	*user = op.user;
	return API_OK;
}

static enum api_code token_add_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct user_op *op = arg;
	sqlite3_stmt *st = conn_stmt(c, "SELECT id FROM users WHERE name = ?1");
	if (!st)
		return db_fail(c, err, "reading a user");
	sqlite3_bind_text(st, 1, op->name, -1, SQLITE_STATIC);
	long long id = -1;
	if (sqlite3_step(st) == SQLITE_ROW)
		id = sqlite3_column_int64(st, 0);
	sqlite3_reset(st);
	if (id < 0) {
		if (!op->create_if_missing)
			return api_fail(err, API_INVALID_REQUEST, "/user", "no user '%s'", op->name);
		enum api_code rc = insert_user(c, op, err);
		if (rc != API_OK)
			return rc;
		id = sqlite3_last_insert_rowid(c->db);
	}
	st = conn_stmt(c, "INSERT INTO tokens (sha256, user_id, label, created_at) VALUES (?1, ?2, ?3, ?4)");
	if (!st)
		return db_fail(c, err, "preparing a token insert");
	sqlite3_bind_text(st, 1, op->token_sha256, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 2, id);
	if (op->label)
		sqlite3_bind_text(st, 3, op->label, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 4, now_ms());
	int rc = sqlite3_step(st);
	sqlite3_reset(st);
	if (rc != SQLITE_DONE)
		return db_fail(c, err, "storing a token");
	op->token = token_load(c, sqlite3_last_insert_rowid(c->db), err);
	return op->token ? API_OK : API_INTERNAL;
}

enum api_code store_token_add(struct store *s, const char *user, int create_role, const char *token_sha256,
			      const char *label, json_t **token, struct api_error *err)
{
	struct user_op op = { .name = user, .role = create_role > 0 ? (enum role)create_role : ROLE_USER,
			      .max_queued = -1, .max_running = -1, .create_if_missing = create_role > 0,
			      .token_sha256 = token_sha256, .label = label };
	enum api_code rc = store_write(s, token_add_run, &op, err);
	if (rc == API_OK && token)
		*token = op.token;
	else
		json_decref(op.token);
	return rc;
}

/* Every token when who is NULL or an admin, else who's own. */
static int sees_all_tokens(const struct principal *who)
{
	return !who || who->role == ROLE_ADMIN;
}

enum api_code store_token_list(struct store *s, const struct principal *who, int limit, long long after,
			       json_t **page, struct api_error *err)
{
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	/* keyset paging on the primary key (or on tokens_user for one user's tokens); ?1 is unused
	 * in the first statement, so both take the same bindings */
	sqlite3_stmt *st = sees_all_tokens(who)
		? conn_stmt(c, "SELECT " TOKEN_COLUMNS "FROM tokens t JOIN users u ON u.id = t.user_id"
			       " WHERE t.id < ?2 ORDER BY t.id DESC LIMIT ?3")
		: conn_stmt(c, "SELECT " TOKEN_COLUMNS "FROM tokens t JOIN users u ON u.id = t.user_id"
			       " WHERE t.user_id = ?1 AND t.id < ?2 ORDER BY t.id DESC LIMIT ?3");
	if (!st) {
		enum api_code rc = db_fail(c, err, "listing tokens");
		store_reader_done(s, c);
		return rc;
	}
	sqlite3_bind_int64(st, 1, who ? who->user_id : 0);
	sqlite3_bind_int64(st, 2, after > 0 ? after : INT64_MAX);
	sqlite3_bind_int(st, 3, limit + 1);   /* one more tells whether another page follows */
	json_t *tokens = json_array();
	long long last = 0;
	int n = 0, more = 0, rc;
	while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
		if (n == limit) {
			more = 1;
			break;
		}
		last = sqlite3_column_int64(st, 0);
		json_array_append_new(tokens, token_from_row(st));
		n++;
	}
	enum api_code status = rc == SQLITE_ROW || rc == SQLITE_DONE ? API_OK : db_fail(c, err, "listing tokens");
	sqlite3_reset(st);
	store_reader_done(s, c);
	if (status != API_OK) {
		json_decref(tokens);
		return status;
	}
	*page = json_pack("{s:o, s:o}", "tokens", tokens, "next_after", more ? json_integer(last) : json_null());
	return API_OK;
}

struct token_revoke {
	const struct principal *who;
	long long id;
	json_t *token;
};

static enum api_code token_revoke_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct token_revoke *op = arg;
	sqlite3_stmt *st = conn_stmt(c, "SELECT user_id FROM tokens WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "reading a token");
	sqlite3_bind_int64(st, 1, op->id);
	long long owner = sqlite3_step(st) == SQLITE_ROW ? sqlite3_column_int64(st, 0) : -1;
	sqlite3_reset(st);
	if (owner < 0 || (!sees_all_tokens(op->who) && owner != op->who->user_id))
		return api_fail(err, API_NOT_FOUND, "", "no token %lld", op->id);
	st = conn_stmt(c, "UPDATE tokens SET revoked_at = ?2 WHERE id = ?1 AND revoked_at IS NULL");
	if (!st)
		return db_fail(c, err, "preparing a token update");
	sqlite3_bind_int64(st, 1, op->id);
	sqlite3_bind_int64(st, 2, now_ms());
	enum api_code rc = step_done(c, st, err, "revoking a token");
	if (rc != API_OK)
		return rc;
	op->token = token_load(c, op->id, err);
	return op->token ? API_OK : API_INTERNAL;
}

enum api_code store_token_revoke(struct store *s, const struct principal *who, long long id, json_t **token,
				 struct api_error *err)
{
	struct token_revoke op = { .who = who, .id = id };
	enum api_code rc = store_write(s, token_revoke_run, &op, err);
	if (rc == API_OK)
		*token = op.token;
	else
		json_decref(op.token);
	return rc;
}
