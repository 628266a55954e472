/*
 * store_worker.c - jobs as workers see them (store.h): the fair-share claim, heartbeats, log
 * chunks with the cap per attempt and the reads of them, the file index (docs/service.md §2).
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
#include "file_replace.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* Claims with exclusive_ok take exclusive jobs too. seconds_left < 0 lets any job fit; otherwise
 * only jobs whose wall_time_seconds fit (a pilot whose allocation ends sooner must not start what
 * it cannot finish), and jobs that asked for no wall time (JOB_WALL_TIME_DEFAULT, server.h), which
 * move from pilot to pilot by checkpoints; max_threads > 0 likewise leaves out jobs asking for
 * more threads than the worker has, and max_memory_mb > 0 jobs asking for more memory than its
 * solver may use (such a solver would only fail, out of memory). A job with memory_mb 0 stated
 * none and fits every claim. */
/* The claim's fit of a queued job j, parameters ?3-?7 (bind_fit), the same in both of pick's
 * statements so that the user chosen always has a job the second finds. */
#define JOB_FITS_CLAIM \
	" AND (?3 OR j.exclusive = 0)" \
	" AND (?4 < 0 OR j.wall_time_seconds <= ?4 OR j.wall_time_seconds = ?5) AND (?6 = 0 OR j.threads <= ?6)" \
	" AND (?7 = 0 OR j.memory_mb <= ?7)"

static void bind_fit(sqlite3_stmt *st, const struct job_claim *in)
{
	sqlite3_bind_int(st, 3, in->exclusive_ok);
	sqlite3_bind_int64(st, 4, in->seconds_left);
	sqlite3_bind_int(st, 5, JOB_WALL_TIME_DEFAULT);
	sqlite3_bind_int64(st, 6, in->max_threads);
	sqlite3_bind_int64(st, 7, in->max_memory_mb);
}

static enum api_code pick(struct store *s, struct conn *c, long long now, const struct job_claim *in, long long *id,
			  struct api_error *err)
{
	*id = 0;
	sqlite3_stmt *st = conn_stmt(c,
		"SELECT u.id FROM users u WHERE u.queued > 0"
		" AND (coalesce(u.max_running, ?2) = 0 OR u.running < coalesce(u.max_running, ?2))"
		" AND EXISTS (SELECT 1 FROM jobs j WHERE j.user_id = u.id AND j.state = 'queued' AND j.not_before <= ?1"
		JOB_FITS_CLAIM ")"
		" ORDER BY u.running, u.last_claim_seq, u.id LIMIT 1");
	if (!st)
		return db_fail(c, err, "choosing a user");
	sqlite3_bind_int64(st, 1, now);
	sqlite3_bind_int(st, 2, s->cfg->user_max_running);
	bind_fit(st, in);
	long long user = 0;
	if (sqlite3_step(st) == SQLITE_ROW)
		user = sqlite3_column_int64(st, 0);
	sqlite3_reset(st);
	if (!user)
		return API_OK;
	st = conn_stmt(c, "SELECT j.id FROM jobs j WHERE j.user_id = ?1 AND j.state = 'queued' AND j.not_before <= ?2"
			  JOB_FITS_CLAIM
			  " ORDER BY j.priority DESC, j.id LIMIT 1");
	if (!st)
		return db_fail(c, err, "choosing a job");
	sqlite3_bind_int64(st, 1, user);
	sqlite3_bind_int64(st, 2, now);
	bind_fit(st, in);
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
	enum api_code rc = pick(s, c, now, op->in, &id, err);
	if (rc != API_OK || !id)
		return rc;
	sqlite3_stmt *st = conn_stmt(c, "UPDATE jobs SET attempt = attempt + 1, started_at = ?2, lease_expires_at = ?3,"
					" worker = ?4, worker_host = ?5, lease_user_id = ?6, cancel_requested = 0,"
					" progress = NULL WHERE id = ?1"
					" RETURNING attempt, case_json, threads, wall_time_seconds, queued_at, exclusive, memory_mb");
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
	json_object_set_new(op->job, "exclusive", json_boolean(sqlite3_column_int(st, 5)));
	json_object_set_new(op->job, "memory_mb", json_integer(sqlite3_column_int64(st, 6)));
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

/* ---- logs ----
 *
 * The cap (--max-log-bytes, cap below): an attempt keeps its first H = cap / 2 bytes and its last
 * T = cap - H bytes. log_attempts holds, per attempt, the end offset (where the next chunk goes)
 * and the dropped range [dropped_from, dropped_to); the text stored is end - (to - from). When an
 * append makes that exceed the cap, the chunks between the head and the tail are deleted in the
 * same write with one range DELETE on the primary key (job_id, attempt, offset). The rule is
 * chunk-granular: the head is the chunks that end at or before H (dropped_from is the offset of
 * the chunk holding byte H), the tail the chunks from the one holding byte end - T on
 * (dropped_to is its offset). So the head is at most H bytes, the tail less than T plus one
 * chunk, and the text stored at most the cap plus one chunk (LOG_CHUNK_MAX; poro-worker sends
 * whole lines of at most 256 KiB). Offsets stay absolute, so a chunk at an offset below the end,
 * dropped or not, is accepted again without change, as before. */

#define LOG_CHUNK_MAX (1LL << 20)   /* bytes of one appended chunk */

static const char SQL_LOG_ATTEMPT[] =
	"SELECT end_offset, dropped_from, dropped_to FROM log_attempts WHERE job_id = ?1 AND attempt = ?2";
/* The offset of the chunk holding byte ?3 (the last chunk starting at or before it). */
static const char SQL_CHUNK_AT[] =
	"SELECT offset FROM log_chunks WHERE job_id = ?1 AND attempt = ?2 AND offset <= ?3"
	" ORDER BY offset DESC LIMIT 1";

struct log_op {
	const struct principal *who;
	long long id, offset, next;
	int attempt;
	const char *text;
	size_t size;
};

struct log_range {
	long long end, from, to;   /* end offset and dropped range of an attempt */
};

static enum api_code log_range_read(struct conn *c, long long id, int attempt, struct log_range *r,
				    struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, SQL_LOG_ATTEMPT);
	if (!st)
		return db_fail(c, err, "reading a log");
	sqlite3_bind_int64(st, 1, id);
	sqlite3_bind_int(st, 2, attempt);
	*r = (struct log_range){ 0, 0, 0 };
	int rc = sqlite3_step(st);
	if (rc == SQLITE_ROW)
		*r = (struct log_range){ sqlite3_column_int64(st, 0), sqlite3_column_int64(st, 1),
					 sqlite3_column_int64(st, 2) };
	sqlite3_reset(st);
	return rc == SQLITE_ROW || rc == SQLITE_DONE ? API_OK : db_fail(c, err, "reading a log");
}

static enum api_code chunk_at(struct conn *c, long long id, int attempt, long long byte, long long *offset,
			      struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, SQL_CHUNK_AT);
	if (!st)
		return db_fail(c, err, "finding a log chunk");
	sqlite3_bind_int64(st, 1, id);
	sqlite3_bind_int(st, 2, attempt);
	sqlite3_bind_int64(st, 3, byte);
	*offset = sqlite3_step(st) == SQLITE_ROW ? sqlite3_column_int64(st, 0) : 0;
	sqlite3_reset(st);
	return API_OK;
}

/* Drops the chunks between head and tail once the stored text exceeds the cap; *freed gets the
 * bytes deleted. Called after the chunk ending at r->end was inserted. */
static enum api_code log_trim(struct store *s, struct conn *c, long long id, int attempt, struct log_range *r,
			      long long *freed, struct api_error *err)
{
	long long cap = s->cfg->max_log_bytes, head = cap / 2, tail = cap - head;
	*freed = 0;
	if (cap <= 0 || r->end - (r->to - r->from) <= cap)
		return API_OK;
	long long from = r->from, to;
	enum api_code rc = API_OK;
	if (r->to == r->from)   /* the first drop of this attempt fixes where the head ends */
		rc = chunk_at(c, id, attempt, head, &from, err);
	/* end - tail lies past the old dropped range (the stored text exceeds head + tail), so the
	 * chunk holding it is present */
	if (rc == API_OK)
		rc = chunk_at(c, id, attempt, r->end - tail, &to, err);
	long long start = r->to > r->from ? r->to : from;
	if (rc != API_OK || to <= start)
		return rc;
	sqlite3_stmt *st = conn_stmt(c, "DELETE FROM log_chunks WHERE job_id = ?1 AND attempt = ?2"
					" AND offset >= ?3 AND offset < ?4");
	if (!st)
		return db_fail(c, err, "preparing a log trim");
	sqlite3_bind_int64(st, 1, id);
	sqlite3_bind_int(st, 2, attempt);
	sqlite3_bind_int64(st, 3, start);
	sqlite3_bind_int64(st, 4, to);
	if ((rc = step_done(c, st, err, "dropping log chunks")) != API_OK)
		return rc;
	*freed = to - start;   /* the chunks in [start, to) were contiguous */
	r->from = from;
	r->to = to;
	return API_OK;
}

static enum api_code log_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct log_op *op = arg;
	enum api_code rc = lease_live(c, op->who, op->id, op->attempt, NULL, NULL, err);
	if (rc != API_OK)
		return rc;
	struct log_range r;
	if ((rc = log_range_read(c, op->id, op->attempt, &r, err)) != API_OK)
		return rc;
	op->next = r.end;
	if (op->offset < op->next || op->size == 0)
		return API_OK; /* already stored, or dropped: accepted again without change */
	if (op->offset > op->next) {
		err->expected_offset = op->next;
		return api_fail(err, API_LOG_GAP, "/offset", "log chunk at offset %lld leaves a gap: expected %lld",
				op->offset, op->next);
	}
	sqlite3_stmt *st = conn_stmt(c, "INSERT INTO log_chunks (job_id, attempt, offset, text) VALUES (?1, ?2, ?3, ?4)");
	if (!st)
		return db_fail(c, err, "preparing a log chunk");
	sqlite3_bind_int64(st, 1, op->id);
	sqlite3_bind_int(st, 2, op->attempt);
	sqlite3_bind_int64(st, 3, op->offset);
	sqlite3_bind_blob64(st, 4, op->text, op->size, SQLITE_STATIC);
	if ((rc = step_done(c, st, err, "storing a log chunk")) != API_OK)
		return rc;
	r.end = op->offset + (long long)op->size;
	long long freed = 0;
	if ((rc = log_trim(s, c, op->id, op->attempt, &r, &freed, err)) != API_OK)
		return rc;
	st = conn_stmt(c, "INSERT INTO log_attempts (job_id, attempt, end_offset, dropped_from, dropped_to)"
			  " VALUES (?1, ?2, ?3, ?4, ?5) ON CONFLICT (job_id, attempt) DO UPDATE SET"
			  " end_offset = excluded.end_offset, dropped_from = excluded.dropped_from,"
			  " dropped_to = excluded.dropped_to");
	if (!st)
		return db_fail(c, err, "preparing a log record");
	sqlite3_bind_int64(st, 1, op->id);
	sqlite3_bind_int(st, 2, op->attempt);
	sqlite3_bind_int64(st, 3, r.end);
	sqlite3_bind_int64(st, 4, r.from);
	sqlite3_bind_int64(st, 5, r.to);
	if ((rc = step_done(c, st, err, "recording a log's end")) != API_OK ||
	    (rc = stored_bytes_add(c, op->id, (long long)op->size - freed, err)) != API_OK)
		return rc;
	op->next = r.end;
	store_after_commit(s, WAKE_LOG_READERS);
	return API_OK;
}

enum api_code store_log_append(struct store *s, const struct principal *who, long long id, int attempt,
			       long long offset, const char *text, size_t size, long long *next_offset,
			       struct api_error *err)
{
	*next_offset = 0;
	if ((long long)size > LOG_CHUNK_MAX)
		return api_fail(err, API_TOO_LARGE, "/text", "log chunk of %zu bytes exceeds the limit of %lld bytes",
				size, LOG_CHUNK_MAX);
	struct log_op op = { .who = who, .id = id, .attempt = attempt, .offset = offset, .text = text, .size = size };
	enum api_code rc = store_write(s, log_run, &op, err);
	*next_offset = op.next;
	return rc;
}

/* The attempt asked for (< 0: the current one), whether it is live, and its range; NOT_FOUND for
 * a missing job. Runs inside the caller's read transaction. */
static enum api_code log_state(struct conn *c, long long id, int *attempt, int *live, struct log_range *r,
			       struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "SELECT attempt, state FROM jobs WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "reading a job");
	sqlite3_bind_int64(st, 1, id);
	if (sqlite3_step(st) != SQLITE_ROW) {
		sqlite3_reset(st);
		return api_fail(err, API_NOT_FOUND, "", "no job %lld", id);
	}
	int current = sqlite3_column_int(st, 0);
	*live = strcmp(col_text(st, 1), "running") == 0;
	sqlite3_reset(st);
	if (*attempt < 0)
		*attempt = current;
	*live = *live && *attempt == current;
	return log_range_read(c, id, *attempt, r, err);
}

enum api_code store_log_info(struct store *s, long long id, int attempt, struct log_info *info,
			     struct api_error *err)
{
	memset(info, 0, sizeof *info);
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	conn_exec(c, "BEGIN");
	struct log_range r;
	enum api_code rc = log_state(c, id, &attempt, &info->live, &r, err);
	store_reader_done(s, c);
	info->attempt = attempt;
	info->end = r.end;
	info->dropped_from = r.from;
	info->dropped_to = r.to;
	return rc;
}

/* Appends blob[skip..n) to b, growing it; -1 when out of memory. */
static int block_append(struct log_block *b, const char *blob, size_t n, size_t skip)
{
	if (b->size + n - skip > b->cap) {
		size_t cap = b->size + n - skip;
		char *grown = realloc(b->text, cap);
		if (!grown)
			return -1;
		b->text = grown;
		b->cap = cap;
	}
	memcpy(b->text + b->size, blob + skip, n - skip);
	b->size += n - skip;
	return 0;
}

enum api_code store_log_read(struct store *s, long long id, int attempt, long long offset, long long until,
			     size_t max, struct log_block *b, struct api_error *err)
{
	b->size = 0;
	b->at = offset;
	b->live = 0;
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	conn_exec(c, "BEGIN"); /* one snapshot for the attempt's state and its chunks */
	struct log_range r;
	enum api_code rc = log_state(c, id, &attempt, &b->live, &r, err);
	b->end = r.end;
	/* From the chunk holding byte offset on; a chunk that ends at or before offset (the last of
	 * the head, when offset fell into the dropped range) is skipped. */
	sqlite3_stmt *st = rc != API_OK ? NULL : conn_stmt(c,
		"SELECT offset, text FROM log_chunks WHERE job_id = ?1 AND attempt = ?2"
		" AND offset >= coalesce((SELECT offset FROM log_chunks WHERE job_id = ?1 AND attempt = ?2"
		" AND offset <= ?3 ORDER BY offset DESC LIMIT 1), 0) AND offset < ?4 ORDER BY offset");
	if (rc == API_OK && !st)
		rc = db_fail(c, err, "reading a log");
	if (st) {
		sqlite3_bind_int64(st, 1, id);
		sqlite3_bind_int(st, 2, attempt);
		sqlite3_bind_int64(st, 3, offset);
		sqlite3_bind_int64(st, 4, until >= 0 ? until : LLONG_MAX);
	}
	long long next = -1;   /* offset the next chunk must have to continue the text */
	while (st && sqlite3_step(st) == SQLITE_ROW) {
		long long at = sqlite3_column_int64(st, 0);
		size_t n = (size_t)sqlite3_column_bytes(st, 1);
		if (at + (long long)n <= offset)
			continue;
		if (next >= 0 && (at != next || b->size + n > max))
			break; /* the dropped range, or enough for this block */
		if (next < 0)
			b->at = at > offset ? at : offset;
		if (block_append(b, sqlite3_column_blob(st, 1), n, (size_t)(b->at > at ? b->at - at : 0)) != 0) {
			rc = api_fail(err, API_UNAVAILABLE, "", "out of memory: retry later");
			break;
		}
		next = at + (long long)n;
		if (b->size >= max)
			break;
	}
	if (st)
		sqlite3_reset(st);
	store_reader_done(s, c);
	if (rc != API_OK)
		b->size = 0;
	return rc;
}

void log_block_release(struct log_block *b)
{
	free(b->text);
	memset(b, 0, sizeof *b);
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
	struct file_replace replace;
};

/* The order (file_replace.c): the row is written first, the file moved in place last, so nothing
 * in this write can fail after the disk changed; file_done then keeps or undoes that change by
 * whether the COMMIT made the row durable. */
static enum api_code file_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct file_op *op = arg;
	enum api_code rc = lease_live(c, op->who, op->id, op->attempt, NULL, NULL, err);
	if (rc != API_OK)
		return rc;
	/* a new version of the same name and attempt replaces the old file: only the difference counts */
	sqlite3_stmt *st = conn_stmt(c,
				     "SELECT size, sha256 FROM files WHERE job_id = ?1 AND name = ?2 AND attempt = ?3");
	if (!st)
		return db_fail(c, err, "reading the file index");
	sqlite3_bind_int64(st, 1, op->id);
	sqlite3_bind_text(st, 2, op->name, -1, SQLITE_STATIC);
	sqlite3_bind_int(st, 3, op->attempt);
	long long replaced = 0;
	char old_sha256[65] = "";
	if (sqlite3_step(st) == SQLITE_ROW) {
		replaced = sqlite3_column_int64(st, 0);
		snprintf(old_sha256, sizeof old_sha256, "%s", col_text(st, 1));
	}
	sqlite3_reset(st);
	if ((rc = stored_bytes_add(c, op->id, op->size - replaced, err)) != API_OK)
		return rc;
	st = conn_stmt(c, "INSERT OR REPLACE INTO files (job_id, attempt, name, size, sha256, created_at)"
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
	if (file_replace_begin(&op->replace, op->tmp_path, op->final_path, old_sha256[0] ? old_sha256 : NULL) != 0)
		return api_fail(err, api_storage_code(errno), "", "cannot store file '%s': %s", op->name, strerror(errno));
	return API_OK;
}

static void file_done(void *arg, int committed)
{
	struct file_op *op = arg;
	file_replace_end(&op->replace, committed);
}

enum api_code store_file_commit(struct store *s, const struct principal *who, long long id, int attempt,
				const char *name, long long size, const char *sha256, const char *tmp_path,
				const char *final_path, struct api_error *err)
{
	struct file_op op = { .who = who, .id = id, .size = size, .attempt = attempt, .name = name,
			      .sha256 = sha256, .tmp_path = tmp_path, .final_path = final_path };
	return store_write_then(s, file_run, file_done, &op, err);
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
