/*
 * store_delete.c - deleting a finished job (store.h, DELETE /v1/jobs/{id}, docs/service.md §3).
 *
 * A job in a terminal state is removed from the database in one write: its log chunks and their
 * log_attempts rows, its file index rows, its idempotency keys, its events and the job row, and
 * its stored bytes are subtracted from its owner's counter. The row goes rather than being marked
 * deleted, so listings never skip over dead rows; job ids come from counters.job_id, so the id of
 * a deleted job is never given to another. The files on disk are removed by the caller once the
 * write has committed (a crash in between leaves a directory without a job, which the start-up
 * sweep removes, file_sweep.c). Each DELETE is a range on a primary key or an index (log_chunks,
 * files and log_attempts start with job_id; events_job; idempotency_job), and so are the foreign
 * key checks of the job row's deletion.
 *
 * A queued or running job is refused (409 not_deletable): its worker may still write to it; cancel
 * it first.
 */
#include "store_internal.h"

#include <stdio.h>
#include <string.h>

struct delete_op {
	const struct principal *who;
	long long id;
	struct job_freed *freed;
};

/* Runs a DELETE bound to the job id; *rows gets the rows it removed. */
static enum api_code delete_rows(struct conn *c, const char *sql, long long id, long long *rows,
				 struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, sql);
	if (!st)
		return db_fail(c, err, "preparing a deletion");
	sqlite3_bind_int64(st, 1, id);
	enum api_code rc = step_done(c, st, err, "deleting a job");
	if (rows)
		*rows = sqlite3_changes(c->db);
	return rc;
}

static enum api_code delete_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct delete_op *op = arg;
	sqlite3_stmt *st = conn_stmt(c, "SELECT user_id, state, stored_bytes FROM jobs WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "reading a job");
	sqlite3_bind_int64(st, 1, op->id);
	if (sqlite3_step(st) != SQLITE_ROW || (op->who->role != ROLE_ADMIN &&
					       sqlite3_column_int64(st, 0) != op->who->user_id)) {
		sqlite3_reset(st);
		return api_fail(err, API_NOT_FOUND, "", "no job %lld", op->id);
	}
	long long owner = sqlite3_column_int64(st, 0);
	enum job_state state = JOB_FAILED;
	job_state_parse(col_text(st, 1), &state);
	op->freed->bytes = sqlite3_column_int64(st, 2);
	sqlite3_reset(st);
	if (state == JOB_QUEUED || state == JOB_RUNNING)
		return api_fail(err, API_NOT_DELETABLE, "", "job %lld is %s: cancel it first, then delete it", op->id,
				job_state_name(state));
	struct job_freed *f = op->freed;
	enum api_code rc;
	if ((rc = delete_rows(c, "DELETE FROM log_chunks WHERE job_id = ?1", op->id, &f->log_chunks, err)) ||
	    (rc = delete_rows(c, "DELETE FROM log_attempts WHERE job_id = ?1", op->id, NULL, err)) ||
	    (rc = delete_rows(c, "DELETE FROM files WHERE job_id = ?1", op->id, &f->files, err)) ||
	    (rc = delete_rows(c, "DELETE FROM idempotency WHERE job_id = ?1", op->id, &f->idempotency_keys, err)) ||
	    (rc = delete_rows(c, "DELETE FROM events WHERE job_id = ?1", op->id, &f->events, err)) ||
	    (rc = delete_rows(c, "DELETE FROM jobs WHERE id = ?1", op->id, NULL, err)))
		return rc;
	st = conn_stmt(c, "UPDATE users SET stored_bytes = stored_bytes - ?2 WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "preparing a stored-bytes update");
	sqlite3_bind_int64(st, 1, owner);
	sqlite3_bind_int64(st, 2, f->bytes);
	if ((rc = step_done(c, st, err, "freeing a user's stored bytes")) != API_OK)
		return rc;
	st = conn_stmt(c, "UPDATE job_counts SET jobs = jobs - 1 WHERE state = ?1");
	if (!st)
		return db_fail(c, err, "preparing a job count update");
	sqlite3_bind_text(st, 1, job_state_name(state), -1, SQLITE_STATIC);
	return step_done(c, st, err, "counting jobs per state");
}

enum api_code store_job_delete(struct store *s, const struct principal *who, long long id, struct job_freed *freed,
			       struct api_error *err)
{
	memset(freed, 0, sizeof *freed);
	struct delete_op op = { .who = who, .id = id, .freed = freed };
	enum api_code rc = store_write(s, delete_run, &op, err);
	if (rc != API_OK)
		memset(freed, 0, sizeof *freed);
	return rc;
}
