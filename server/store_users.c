/*
 * store_users.c - users and bearer tokens (store.h). Tokens are stored only as their SHA-256 hex
 * (tokens.sha256), so a copy of the database reveals no usable token.
 */
#include "store_internal.h"

#include <stdio.h>
#include <string.h>

enum api_code store_auth(struct store *s, const char *token_sha256, struct principal *who, struct api_error *err)
{
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	sqlite3_stmt *st = conn_stmt(c, "SELECT u.id, u.name, u.role FROM tokens t JOIN users u ON u.id = t.user_id"
					" WHERE t.sha256 = ?1");
	enum api_code rc = API_UNAUTHORIZED;
	if (!st) {
		rc = db_fail(c, err, "checking a token");
	} else {
		sqlite3_bind_text(st, 1, token_sha256, -1, SQLITE_STATIC);
		if (sqlite3_step(st) == SQLITE_ROW && role_parse(col_text(st, 2), &who->role) == 0) {
			who->user_id = sqlite3_column_int64(st, 0);
			snprintf(who->name, sizeof who->name, "%s", col_text(st, 1));
			rc = API_OK;
		} else {
			api_fail(err, API_UNAUTHORIZED, "Authorization", "unknown token");
		}
		sqlite3_reset(st);
	}
	store_reader_done(s, c);
	return rc;
}

struct user_op {
	const char *name;
	enum role role;
	int max_queued, max_running;
	int create_if_missing;     /* token_add: create the user when absent */
	const char *token_sha256;  /* token_add */
	json_t *user;
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
	st = conn_stmt(c, "INSERT INTO tokens (sha256, user_id, created_at) VALUES (?1, ?2, ?3)");
	if (!st)
		return db_fail(c, err, "preparing a token insert");
	sqlite3_bind_text(st, 1, op->token_sha256, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 2, id);
	sqlite3_bind_int64(st, 3, now_ms());
	int rc = sqlite3_step(st);
	sqlite3_reset(st);
	return rc == SQLITE_DONE ? API_OK : db_fail(c, err, "storing a token");
}

enum api_code store_token_add(struct store *s, const char *user, int create_role, const char *token_sha256,
			      struct api_error *err)
{
	struct user_op op = { .name = user, .role = create_role > 0 ? (enum role)create_role : ROLE_USER,
			      .max_queued = -1, .max_running = -1, .create_if_missing = create_role > 0,
			      .token_sha256 = token_sha256 };
	return store_write(s, token_add_run, &op, err);
}
