/*
 * store_finish.c - how attempts end (docs/service.md §2): a worker's finish, and the reaper's
 * expiry of leases and wall-time overruns.
 *
 * Outcomes: "succeeded" and "failed" (a solver failure: final, message kept) and "cancelled" end
 * the job; "infrastructure" is retried with backoff while attempts are left (requeue_or_fail). An
 * expired lease is an infrastructure failure too, except when a cancel was requested: then the job
 * is cancelled, never re-queued. A running job past wall_time_seconds plus one lease period fails.
 *
 * A success must be backed by its files: the worker declares what it uploaded for the attempt
 * (name, size, SHA-256), and "succeeded" is accepted only when result.h5 is among them and every
 * declared file is in the index of this very attempt with the same size and digest
 * (check_artifacts, in the same transaction as the transition, so no upload can slip between the
 * check and the state change). Otherwise the finish is 409 artifact_missing and the attempt stays
 * running: the worker still holds its files and can report what happened.
 */
#include "store_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct finish_op {
	const struct principal *who;
	long long id;
	int attempt, exit_code;
	const char *worker, *outcome, *message, *solver_version;
	const struct finish_artifact *artifacts;
	int artifact_count;
	json_t *job;
	long long duration;
};

#define RESULT_NAME "result.h5"

/* The declared artifacts of a success against the file index of (id, attempt): API_OK, or
 * API_ARTIFACT_MISSING naming the first that is missing or differs. */
static enum api_code check_artifacts(struct conn *c, const struct finish_op *op, struct api_error *err)
{
	int has_result = 0;
	for (int i = 0; i < op->artifact_count; i++)
		has_result |= strcmp(op->artifacts[i].name, RESULT_NAME) == 0;
	if (!has_result)
		return api_fail(err, API_ARTIFACT_MISSING, "/artifacts",
				"attempt %d of job %lld cannot succeed without '%s': it is not among the %d declared "
				"artifacts", op->attempt, op->id, RESULT_NAME, op->artifact_count);
	sqlite3_stmt *st = conn_stmt(c, "SELECT size, sha256 FROM files WHERE job_id = ?1 AND attempt = ?2 AND name = ?3");
	if (!st)
		return db_fail(c, err, "preparing an artifact check");
	enum api_code rc = API_OK;
	for (int i = 0; i < op->artifact_count && rc == API_OK; i++) {
		const struct finish_artifact *a = &op->artifacts[i];
		char field[32];
		snprintf(field, sizeof field, "/artifacts/%d", i);
		sqlite3_reset(st);
		sqlite3_bind_int64(st, 1, op->id);
		sqlite3_bind_int(st, 2, op->attempt);
		sqlite3_bind_text(st, 3, a->name, -1, SQLITE_STATIC);
		int step = sqlite3_step(st);
		if (step != SQLITE_ROW && step != SQLITE_DONE)
			rc = db_fail(c, err, "checking an artifact");
		else if (step == SQLITE_DONE)
			rc = api_fail(err, API_ARTIFACT_MISSING, field, "artifact '%s' (%lld bytes) of attempt %d was never "
				      "stored", a->name, a->size, op->attempt);
		else if (sqlite3_column_int64(st, 0) != a->size)
			rc = api_fail(err, API_ARTIFACT_MISSING, field, "artifact '%s' of attempt %d is stored with %lld "
				      "bytes, the finish declares %lld", a->name, op->attempt,
				      (long long)sqlite3_column_int64(st, 0), a->size);
		else if (strcmp(col_text(st, 1), a->sha256) != 0)
			rc = api_fail(err, API_ARTIFACT_MISSING, field, "artifact '%s' of attempt %d is stored with SHA-256 "
				      "%s, the finish declares %s", a->name, op->attempt, col_text(st, 1), a->sha256);
	}
	sqlite3_reset(st);
	return rc;
}

static enum api_code finish_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct finish_op *op = arg;
	long long started = 0;
	enum api_code rc = lease_live(c, op->who, op->id, op->attempt, NULL, &started, err);
	if (rc == API_OK && strcmp(op->outcome, "succeeded") == 0)
		rc = check_artifacts(c, op, err);
	if (rc != API_OK)
		return rc;
	op->duration = now_ms() - started;
	sqlite3_stmt *st = conn_stmt(c, "UPDATE jobs SET message = ?2, exit_code = ?3, lease_expires_at = NULL,"
					" solver_version = coalesce(?4, solver_version) WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "preparing a finish");
	sqlite3_bind_int64(st, 1, op->id);
	if (op->message)
		sqlite3_bind_text(st, 2, op->message, -1, SQLITE_STATIC);
	if (op->exit_code >= 0)
		sqlite3_bind_int(st, 3, op->exit_code);
	if (op->solver_version)
		sqlite3_bind_text(st, 4, op->solver_version, -1, SQLITE_STATIC);
	if ((rc = step_done(c, st, err, "finishing a job")) != API_OK)
		return rc;
	enum job_state to = JOB_SUCCEEDED;
	if (strcmp(op->outcome, "infrastructure") == 0) {
		int retried;
		rc = requeue_or_fail(s, c, op->id, op->attempt, op->worker,
				     op->message ? op->message : "infrastructure failure", &retried, err);
	} else {
		if (strcmp(op->outcome, "failed") == 0)
			to = JOB_FAILED;
		else if (strcmp(op->outcome, "cancelled") == 0)
			to = JOB_CANCELLED;
		rc = job_transition(c, op->id, JOB_RUNNING, to, op->attempt, op->worker, op->message, err);
	}
	if (rc != API_OK)
		return rc;
	store_after_commit(s, WAKE_LOG_READERS);
	op->job = job_load(s, c, op->id, 0, err);
	return op->job ? API_OK : API_INTERNAL;
}

enum api_code store_finish(struct store *s, const struct principal *who, long long id, int attempt,
			   const char *worker, const char *outcome, const char *message, int exit_code,
			   const char *solver_version, const struct finish_artifact *artifacts, int artifact_count,
			   json_t **job, long long *duration_ms, struct api_error *err)
{
	struct finish_op op = { .who = who, .id = id, .attempt = attempt, .exit_code = exit_code, .worker = worker,
				.outcome = outcome, .message = message, .solver_version = solver_version,
				.artifacts = artifacts, .artifact_count = artifact_count };
	enum api_code rc = store_write(s, finish_run, &op, err);
	if (rc != API_OK) {
		json_decref(op.job);
		op.job = NULL;
	}
	*job = op.job;
	*duration_ms = op.duration;
	return rc;
}

/* ---- reaper ---- */

#define REAP_BATCH 256   /* jobs handled per reaper pass; the rest wait a second */

struct reap_op {
	struct reap_counts *counts;
};

struct overdue {
	long long id;
	int attempt, cancel, overrun;
};

static enum api_code reap_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct reap_op *op = arg;
	long long now = now_ms();
	sqlite3_stmt *st = conn_stmt(c, "SELECT id, attempt, cancel_requested,"
					" started_at + 1000 * (wall_time_seconds + ?2) < ?1 FROM jobs"
					" WHERE state = 'running' AND (lease_expires_at < ?1"
					" OR started_at + 1000 * (wall_time_seconds + ?2) < ?1) LIMIT ?3");
	if (!st)
		return db_fail(c, err, "finding expired leases");
	sqlite3_bind_int64(st, 1, now);
	sqlite3_bind_int(st, 2, s->cfg->lease_seconds);
	sqlite3_bind_int(st, 3, REAP_BATCH);
	struct overdue due[REAP_BATCH];
	int n = 0;
	while (n < REAP_BATCH && sqlite3_step(st) == SQLITE_ROW) {
		due[n] = (struct overdue){ sqlite3_column_int64(st, 0), sqlite3_column_int(st, 1),
					   sqlite3_column_int(st, 2), sqlite3_column_int(st, 3) };
		n++;
	}
	sqlite3_reset(st);
	enum api_code rc = API_OK;
	for (int i = 0; i < n && rc == API_OK; i++) {
		struct overdue *d = &due[i];
		if (d->overrun) {
			st = conn_stmt(c, "UPDATE jobs SET message = 'wall time exceeded', lease_expires_at = NULL"
					  " WHERE id = ?1");
			if (!st)
				return db_fail(c, err, "preparing a wall-time failure");
			sqlite3_bind_int64(st, 1, d->id);
			rc = step_done(c, st, err, "failing an overrun");
			if (rc == API_OK)
				rc = job_transition(c, d->id, JOB_RUNNING, JOB_FAILED, d->attempt, "reaper",
						    "wall time exceeded", err);
			op->counts->overrun++;
		} else if (d->cancel) {
			rc = job_transition(c, d->id, JOB_RUNNING, JOB_CANCELLED, d->attempt, "reaper",
					    "lease expired while cancel was requested", err);
			op->counts->expired++;
			op->counts->cancelled++;
		} else {
			int retried = 0;
			rc = requeue_or_fail(s, c, d->id, d->attempt, "reaper", "lease expired", &retried, err);
			op->counts->expired++;
			if (retried)
				op->counts->retried++;
			else
				op->counts->lost++;
		}
	}
	if (n)
		store_after_commit(s, WAKE_LOG_READERS);
	return rc;
}

enum api_code store_reap(struct store *s, struct reap_counts *counts, struct api_error *err)
{
	memset(counts, 0, sizeof *counts);
	struct reap_op op = { counts };
	enum api_code rc = store_write(s, reap_run, &op, err);
	if (rc != API_OK)
		memset(counts, 0, sizeof *counts);
	return rc;
}
