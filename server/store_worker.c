/*
 * store_worker.c - jobs as workers see them (store.h): the fair-share claim, heartbeats, log
 * chunks, the file index, finish, and the reaper's expiry of leases (docs/service.md §2).
 *
 * Fencing: every worker write runs lease_live() inside the writer's transaction, so the check and
 * the write are atomic with respect to claims, expiries and other finishes; a write from an
 * attempt that is no longer the job's running attempt is refused with API_STALE_ATTEMPT.
 *
 * Fair share: among users with a claimable job (queued, not_before passed) and fewer running jobs
 * than their cap, the one with fewest running jobs wins, ties to the one whose last claim is
 * oldest (users.last_claim_seq, a global claim counter), then the oldest user; within the user
 * the highest priority, then the oldest job. users.queued / users.running are kept by
 * job_transition(), so the choice costs one index probe per user with queued jobs.
 */
#include "store_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---- fencing ---- */

/* API_OK when (id, attempt) is the running lease of who; *cancel gets cancel_requested. */
enum api_code lease_live(struct conn *c, const struct principal *who, long long id, int attempt,
				int *cancel, long long *started, struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "SELECT state, attempt, cancel_requested, lease_user_id, started_at"
					" FROM jobs WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "reading a lease");
	sqlite3_bind_int64(st, 1, id);
	if (sqlite3_step(st) != SQLITE_ROW) {
		sqlite3_reset(st);
		return api_fail(err, API_NOT_FOUND, "", "no job %lld", id);
	}
	int running = strcmp(col_text(st, 0), "running") == 0;
	int current = sqlite3_column_int(st, 1);
	long long holder = sqlite3_column_int64(st, 3);
	if (cancel)
		*cancel = sqlite3_column_int(st, 2);
	if (started)
		*started = sqlite3_column_int64(st, 4);
	sqlite3_reset(st);
	if (!running || (attempt >= 0 && attempt != current))
		return api_fail(err, API_STALE_ATTEMPT, "/attempt",
				"attempt %d of job %lld is not live (current attempt %d, %s)", attempt, id, current,
				running ? "running" : "not running");
	if (holder != who->user_id)
		return api_fail(err, API_NOT_FOUND, "", "no job %lld leased by '%s'", id, who->name);
	return API_OK;
}

enum api_code step_done(struct conn *c, sqlite3_stmt *st, struct api_error *err, const char *what)
{
	int rc = sqlite3_step(st);
	sqlite3_reset(st);
	return rc == SQLITE_DONE ? API_OK : db_fail(c, err, what);
}

/* Infrastructure failure of (id, attempt): back to queued after backoff, or failed as lost. */
enum api_code requeue_or_fail(struct store *s, struct conn *c, long long id, int attempt, const char *actor,
				     const char *why, int *retried, struct api_error *err)
{
	char detail[SERVER_MESSAGE_MAX];
	if (attempt >= s->cfg->max_attempts) {
		snprintf(detail, sizeof detail, "lost: %s; no attempts left after %d", why, attempt);
		sqlite3_stmt *st = conn_stmt(c, "UPDATE jobs SET message = ?2, lease_expires_at = NULL WHERE id = ?1");
		if (!st)
			return db_fail(c, err, "preparing a failure");
		sqlite3_bind_int64(st, 1, id);
		sqlite3_bind_text(st, 2, detail, -1, SQLITE_TRANSIENT);
		enum api_code rc = step_done(c, st, err, "failing a lost job");
		*retried = 0;
		return rc != API_OK ? rc : job_transition(c, id, JOB_RUNNING, JOB_FAILED, attempt, actor, detail, err);
	}
	long long backoff = 1LL << (attempt > 1 ? (attempt - 1 < 20 ? attempt - 1 : 20) : 0);
	if (backoff > s->cfg->max_backoff_seconds)
		backoff = s->cfg->max_backoff_seconds;
	snprintf(detail, sizeof detail, "%s; retry after %lld s", why, backoff);
	sqlite3_stmt *st = conn_stmt(c, "UPDATE jobs SET not_before = ?2, lease_expires_at = NULL WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "preparing a retry");
	sqlite3_bind_int64(st, 1, id);
	sqlite3_bind_int64(st, 2, now_ms() + 1000 * backoff);
	enum api_code rc = step_done(c, st, err, "scheduling a retry");
	*retried = 1;
	store_after_commit(s, WAKE_CLAIMERS);
	return rc != API_OK ? rc : job_transition(c, id, JOB_RUNNING, JOB_QUEUED, attempt, actor, detail, err);
}

/* ---- claim ---- */

struct claim_op {
	struct job_claim *in;
	json_t *job;
};

static enum api_code pick(struct store *s, struct conn *c, long long now, long long *id, struct api_error *err)
{
	*id = 0;
	sqlite3_stmt *st = conn_stmt(c,
		"SELECT u.id FROM users u WHERE u.queued > 0"
		" AND (coalesce(u.max_running, ?2) = 0 OR u.running < coalesce(u.max_running, ?2))"
		" AND EXISTS (SELECT 1 FROM jobs j WHERE j.user_id = u.id AND j.state = 'queued' AND j.not_before <= ?1)"
		" ORDER BY u.running, u.last_claim_seq, u.id LIMIT 1");
	if (!st)
		return db_fail(c, err, "choosing a user");
	sqlite3_bind_int64(st, 1, now);
	sqlite3_bind_int(st, 2, s->cfg->user_max_running);
	long long user = 0;
	if (sqlite3_step(st) == SQLITE_ROW)
		user = sqlite3_column_int64(st, 0);
	sqlite3_reset(st);
	if (!user)
		return API_OK;
	st = conn_stmt(c, "SELECT id FROM jobs WHERE user_id = ?1 AND state = 'queued' AND not_before <= ?2"
			  " ORDER BY priority DESC, id LIMIT 1");
	if (!st)
		return db_fail(c, err, "choosing a job");
	sqlite3_bind_int64(st, 1, user);
	sqlite3_bind_int64(st, 2, now);
	if (sqlite3_step(st) == SQLITE_ROW)
		*id = sqlite3_column_int64(st, 0);
	sqlite3_reset(st);
	st = conn_stmt(c, "UPDATE users SET last_claim_seq = (SELECT max(last_claim_seq) + 1 FROM users) WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "recording a claim");
	sqlite3_bind_int64(st, 1, user);
	return step_done(c, st, err, "recording a claim");
}

static json_t *checkpoint_of(struct conn *c, long long id, int before_attempt)
{
	sqlite3_stmt *st = conn_stmt(c, "SELECT name, sha256, size FROM files WHERE job_id = ?1"
					" AND name = 'checkpoint.h5' AND attempt < ?2 ORDER BY attempt DESC LIMIT 1");
	if (!st)
		return json_null();
	sqlite3_bind_int64(st, 1, id);
	sqlite3_bind_int(st, 2, before_attempt);
	json_t *cp = json_null();
	if (sqlite3_step(st) == SQLITE_ROW) {
		json_decref(cp);
		cp = json_pack("{s:o, s:o, s:I}", "name", col_json_text(st, 0), "sha256", col_json_text(st, 1),
			       "size", (json_int_t)sqlite3_column_int64(st, 2));
	}
	sqlite3_reset(st);
	return cp;
}

static enum api_code claim_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct claim_op *op = arg;
	long long now = now_ms(), id;
	enum api_code rc = pick(s, c, now, &id, err);
	if (rc != API_OK || !id)
		return rc;
	sqlite3_stmt *st = conn_stmt(c, "UPDATE jobs SET attempt = attempt + 1, started_at = ?2, lease_expires_at = ?3,"
					" worker = ?4, worker_host = ?5, lease_user_id = ?6, cancel_requested = 0,"
					" progress = NULL WHERE id = ?1"
					" RETURNING attempt, case_json, threads, wall_time_seconds, queued_at");
	if (!st)
		return db_fail(c, err, "preparing a claim");
	sqlite3_bind_int64(st, 1, id);
	sqlite3_bind_int64(st, 2, now);
	sqlite3_bind_int64(st, 3, now + 1000LL * s->cfg->lease_seconds);
	sqlite3_bind_text(st, 4, op->in->worker, -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 5, op->in->host, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 6, op->in->who->user_id);
	if (sqlite3_step(st) != SQLITE_ROW) {
		sqlite3_reset(st);
		return db_fail(c, err, "claiming a job");
	}
	int attempt = sqlite3_column_int(st, 0);
	json_t *case_spec = json_loads(col_text(st, 1), 0, NULL);
	op->job = json_pack("{s:I, s:i, s:o, s:i, s:i, s:i}", "id", (json_int_t)id, "attempt", attempt, "case",
			    case_spec ? case_spec : json_null(), "threads", sqlite3_column_int(st, 2),
			    "wall_time_seconds", sqlite3_column_int(st, 3), "lease_seconds", s->cfg->lease_seconds);
	op->in->claim_latency_ms = now - sqlite3_column_int64(st, 4);
	sqlite3_step(st); /* a RETURNING statement completes its update on the step that returns DONE */
	sqlite3_reset(st);
	json_object_set_new(op->job, "checkpoint", checkpoint_of(c, id, attempt));
	char detail[2 * SERVER_NAME_MAX + 32];
	snprintf(detail, sizeof detail, "claimed on host '%s'", op->in->host);
	return job_transition(c, id, JOB_QUEUED, JOB_RUNNING, attempt, op->in->worker, detail, err);
}

enum api_code store_claim(struct store *s, struct job_claim *in, json_t **job, struct api_error *err)
{
	struct claim_op op = { .in = in };
	enum api_code rc = store_write(s, claim_run, &op, err);
	if (rc != API_OK) {
		json_decref(op.job);
		op.job = NULL;
	}
	*job = op.job;
	return rc;
}

/* ---- heartbeat ---- */

struct beat_op {
	const struct principal *who;
	long long id;
	int attempt;
	json_t *progress;
	const char *solver_version;
	int cancel;
	long long expires;
};

static enum api_code beat_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct beat_op *op = arg;
	enum api_code rc = lease_live(c, op->who, op->id, op->attempt, &op->cancel, NULL, err);
	if (rc != API_OK)
		return rc;
	op->expires = now_ms() + 1000LL * s->cfg->lease_seconds;
	sqlite3_stmt *st = conn_stmt(c, "UPDATE jobs SET lease_expires_at = ?2, progress = coalesce(?3, progress),"
					" solver_version = coalesce(?4, solver_version) WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "preparing a heartbeat");
	sqlite3_bind_int64(st, 1, op->id);
	sqlite3_bind_int64(st, 2, op->expires);
	char *progress = op->progress ? json_dumps(op->progress, JSON_COMPACT) : NULL;
	if (progress)
		sqlite3_bind_text(st, 3, progress, -1, free);
	if (op->solver_version)
		sqlite3_bind_text(st, 4, op->solver_version, -1, SQLITE_STATIC);
	return step_done(c, st, err, "renewing a lease");
}

enum api_code store_heartbeat(struct store *s, const struct principal *who, long long id, int attempt,
			      json_t *progress, const char *solver_version, int *cancel, long long *lease_expires_ms,
			      struct api_error *err)
{
	struct beat_op op = { .who = who, .id = id, .attempt = attempt, .progress = progress,
			      .solver_version = solver_version };
	enum api_code rc = store_write(s, beat_run, &op, err);
	*cancel = op.cancel;
	*lease_expires_ms = op.expires;
	return rc;
}

/* ---- logs ---- */

struct log_op {
	const struct principal *who;
	long long id, offset, next;
	int attempt;
	const char *text;
	size_t size;
};

static enum api_code log_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct log_op *op = arg;
	enum api_code rc = lease_live(c, op->who, op->id, op->attempt, NULL, NULL, err);
	if (rc != API_OK)
		return rc;
	sqlite3_stmt *st = conn_stmt(c, "SELECT offset + length(text) FROM log_chunks WHERE job_id = ?1 AND attempt = ?2"
					" ORDER BY offset DESC LIMIT 1");
	if (!st)
		return db_fail(c, err, "reading a log");
	sqlite3_bind_int64(st, 1, op->id);
	sqlite3_bind_int(st, 2, op->attempt);
	op->next = sqlite3_step(st) == SQLITE_ROW ? sqlite3_column_int64(st, 0) : 0;
	sqlite3_reset(st);
	if (op->offset < op->next || op->size == 0)
		return API_OK; /* already stored: accepted again without change */
	if (op->offset > op->next) {
		err->expected_offset = op->next;
		return api_fail(err, API_LOG_GAP, "/offset", "log chunk at offset %lld leaves a gap: expected %lld",
				op->offset, op->next);
	}
	st = conn_stmt(c, "INSERT INTO log_chunks (job_id, attempt, offset, text) VALUES (?1, ?2, ?3, ?4)");
	if (!st)
		return db_fail(c, err, "preparing a log chunk");
	sqlite3_bind_int64(st, 1, op->id);
	sqlite3_bind_int(st, 2, op->attempt);
	sqlite3_bind_int64(st, 3, op->offset);
	sqlite3_bind_blob64(st, 4, op->text, op->size, SQLITE_STATIC);
	rc = step_done(c, st, err, "storing a log chunk");
	op->next = op->offset + (long long)op->size;
	store_after_commit(s, WAKE_LOG_READERS);
	return rc;
}

enum api_code store_log_append(struct store *s, const struct principal *who, long long id, int attempt,
			       long long offset, const char *text, size_t size, long long *next_offset,
			       struct api_error *err)
{
	struct log_op op = { .who = who, .id = id, .attempt = attempt, .offset = offset, .text = text, .size = size };
	enum api_code rc = store_write(s, log_run, &op, err);
	*next_offset = op.next;
	return rc;
}

enum api_code store_log_read(struct store *s, long long id, int *attempt, long long offset, char **text,
			     size_t *size, int *live, struct api_error *err)
{
	*text = NULL;
	*size = 0;
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	conn_exec(c, "BEGIN");
	enum api_code rc = API_OK;
	sqlite3_stmt *st = conn_stmt(c, "SELECT attempt, state FROM jobs WHERE id = ?1");
	if (!st || (sqlite3_bind_int64(st, 1, id), sqlite3_step(st)) != SQLITE_ROW) {
		rc = st ? api_fail(err, API_NOT_FOUND, "", "no job %lld", id) : db_fail(c, err, "reading a job");
		goto done;
	}
	int current = sqlite3_column_int(st, 0);
	*live = strcmp(col_text(st, 1), "running") == 0;
	sqlite3_reset(st);
	if (*attempt < 0)
		*attempt = current;
	*live = *live && *attempt == current;
	st = conn_stmt(c, "SELECT offset, text FROM log_chunks WHERE job_id = ?1 AND attempt = ?2"
			  " AND offset + length(text) > ?3 ORDER BY offset");
	if (!st) {
		rc = db_fail(c, err, "reading a log");
		goto done;
	}
	sqlite3_bind_int64(st, 1, id);
	sqlite3_bind_int(st, 2, *attempt);
	sqlite3_bind_int64(st, 3, offset);
	size_t cap = 0;
	while (sqlite3_step(st) == SQLITE_ROW) {
		long long at = sqlite3_column_int64(st, 0);
		const char *blob = sqlite3_column_blob(st, 1);
		size_t n = (size_t)sqlite3_column_bytes(st, 1), skip = at < offset ? (size_t)(offset - at) : 0;
		if (*size + n - skip + 1 > cap) {
			cap = 2 * (*size + n + 1);
			char *grown = realloc(*text, cap);
			if (!grown) {
				rc = api_fail(err, API_INTERNAL, "", "out of memory");
				break;
			}
			*text = grown;
		}
		memcpy(*text + *size, blob + skip, n - skip);
		*size += n - skip;
	}
	sqlite3_reset(st);
done:
	if (st)
		sqlite3_reset(st);
	store_reader_done(s, c);
	if (rc != API_OK) {
		free(*text);
		*text = NULL;
		*size = 0;
	}
	return rc;
}

/* ---- files ---- */

enum api_code store_lease_check(struct store *s, const struct principal *who, long long id, int attempt,
				int *current_attempt, struct api_error *err)
{
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	enum api_code rc = lease_live(c, who, id, attempt, NULL, NULL, err);
	if (current_attempt) {
		sqlite3_stmt *st = conn_stmt(c, "SELECT attempt FROM jobs WHERE id = ?1");
		if (st) {
			sqlite3_bind_int64(st, 1, id);
			*current_attempt = sqlite3_step(st) == SQLITE_ROW ? sqlite3_column_int(st, 0) : 0;
			sqlite3_reset(st);
		}
	}
	store_reader_done(s, c);
	return rc;
}

struct file_op {
	const struct principal *who;
	long long id, size;
	int attempt;
	const char *name, *sha256, *tmp_path, *final_path;
};

static int fsync_dir_of(const char *path)
{
	char copy[SERVER_PATH_MAX + 256];
	snprintf(copy, sizeof copy, "%s", path);
	int fd = open(dirname(copy), O_RDONLY | O_DIRECTORY);
	if (fd < 0)
		return -1;
	int rc = fsync(fd);
	close(fd);
	return rc;
}

static enum api_code file_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct file_op *op = arg;
	enum api_code rc = lease_live(c, op->who, op->id, op->attempt, NULL, NULL, err);
	if (rc != API_OK)
		return rc;
	sqlite3_stmt *st = conn_stmt(c, "INSERT OR REPLACE INTO files (job_id, attempt, name, size, sha256, created_at)"
					" VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
	if (!st)
		return db_fail(c, err, "preparing a file index row");
	sqlite3_bind_int64(st, 1, op->id);
	sqlite3_bind_int(st, 2, op->attempt);
	sqlite3_bind_text(st, 3, op->name, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 4, op->size);
	sqlite3_bind_text(st, 5, op->sha256, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 6, now_ms());
	if ((rc = step_done(c, st, err, "indexing a file")) != API_OK)
		return rc;
	if (rename(op->tmp_path, op->final_path) != 0 || fsync_dir_of(op->final_path) != 0)
		return api_fail(err, API_INTERNAL, "", "cannot store file '%s': %s", op->name, strerror(errno));
	return API_OK;
}

enum api_code store_file_commit(struct store *s, const struct principal *who, long long id, int attempt,
				const char *name, long long size, const char *sha256, const char *tmp_path,
				const char *final_path, struct api_error *err)
{
	struct file_op op = { .who = who, .id = id, .size = size, .attempt = attempt, .name = name,
			      .sha256 = sha256, .tmp_path = tmp_path, .final_path = final_path };
	return store_write(s, file_run, &op, err);
}

enum api_code store_file_find(struct store *s, long long id, const char *name, int max_attempt, int *attempt,
			      long long *size, char sha256[65], struct api_error *err)
{
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	sqlite3_stmt *st = conn_stmt(c, "SELECT attempt, size, sha256 FROM files WHERE job_id = ?1 AND name = ?2"
					" AND (?3 < 0 OR attempt <= ?3) ORDER BY attempt DESC LIMIT 1");
	enum api_code rc = API_OK;
	if (!st) {
		rc = db_fail(c, err, "reading the file index");
	} else {
		sqlite3_bind_int64(st, 1, id);
		sqlite3_bind_text(st, 2, name, -1, SQLITE_STATIC);
		sqlite3_bind_int(st, 3, max_attempt);
		if (sqlite3_step(st) == SQLITE_ROW) {
			*attempt = sqlite3_column_int(st, 0);
			*size = sqlite3_column_int64(st, 1);
			snprintf(sha256, 65, "%s", col_text(st, 2));
		} else {
			rc = api_fail(err, API_NOT_FOUND, "", "job %lld has no file '%s'", id, name);
		}
		sqlite3_reset(st);
	}
	store_reader_done(s, c);
	return rc;
}
