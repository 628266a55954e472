/*
 * store_quota.c - stored bytes per job and per user, and the quota on them (store.h,
 * docs/service.md §2 "Storage quota").
 *
 * What a job stores is its case text, its stored log text and its files. jobs.stored_bytes and
 * users.stored_bytes are counters kept in the same writes that add or remove those bytes (submit,
 * log append and trim, file commit, delete), like users.queued, so the quota check at submit is
 * one row read. The quota applies to submissions only: once a job is admitted its log and its
 * files are stored whatever they weigh (they count, but the job's outcome must not depend on
 * the quota), and deleting finished jobs (store_delete.c) frees their bytes.
 */
#include "store_internal.h"

#include <stdio.h>

enum api_code stored_bytes_add(struct conn *c, long long job_id, long long delta, struct api_error *err)
{
	if (delta == 0)
		return API_OK;
	sqlite3_stmt *st = conn_stmt(c, "UPDATE jobs SET stored_bytes = stored_bytes + ?2 WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "preparing a stored-bytes update");
	sqlite3_bind_int64(st, 1, job_id);
	sqlite3_bind_int64(st, 2, delta);
	enum api_code rc = step_done(c, st, err, "counting a job's stored bytes");
	if (rc != API_OK)
		return rc;
	st = conn_stmt(c, "UPDATE users SET stored_bytes = stored_bytes + ?2"
			  " WHERE id = (SELECT user_id FROM jobs WHERE id = ?1)");
	if (!st)
		return db_fail(c, err, "preparing a stored-bytes update");
	sqlite3_bind_int64(st, 1, job_id);
	sqlite3_bind_int64(st, 2, delta);
	return step_done(c, st, err, "counting a user's stored bytes");
}

enum api_code stored_quota_check(struct store *s, struct conn *c, long long user, long long bytes,
				 struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "SELECT name, stored_bytes, coalesce(max_stored_bytes, ?2) FROM users"
					" WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "reading a storage quota");
	sqlite3_bind_int64(st, 1, user);
	sqlite3_bind_int64(st, 2, s->cfg->user_max_stored_bytes);
	enum api_code rc = API_OK;
	if (sqlite3_step(st) == SQLITE_ROW) {
		long long stored = sqlite3_column_int64(st, 1), quota = sqlite3_column_int64(st, 2);
		if (quota > 0 && stored + bytes > quota)
			rc = api_fail(err, API_QUOTA_EXCEEDED, "/case",
				      "user '%s' stores %lld bytes; a case of %lld bytes would pass its quota of "
				      "%lld bytes (delete finished jobs to free space)",
				      col_text(st, 0), stored, bytes, quota);
	}
	sqlite3_reset(st);
	return rc;
}

struct max_stored_op {
	const char *name;
	long long bytes;
};

static enum api_code max_stored_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct max_stored_op *op = arg;
	sqlite3_stmt *st = conn_stmt(c, "UPDATE users SET max_stored_bytes = ?2 WHERE name = ?1");
	if (!st)
		return db_fail(c, err, "preparing a quota update");
	sqlite3_bind_text(st, 1, op->name, -1, SQLITE_STATIC);
	if (op->bytes >= 0)
		sqlite3_bind_int64(st, 2, op->bytes);
	enum api_code rc = step_done(c, st, err, "setting a storage quota");
	if (rc == API_OK && sqlite3_changes(c->db) == 0)
		return api_fail(err, API_INVALID_REQUEST, "/name", "no user '%s'", op->name);
	return rc;
}

enum api_code store_user_set_max_stored(struct store *s, const char *name, long long max_stored_bytes,
					struct api_error *err)
{
	struct max_stored_op op = { name, max_stored_bytes };
	return store_write(s, max_stored_run, &op, err);
}
