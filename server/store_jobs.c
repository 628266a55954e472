/*
 * store_jobs.c - jobs as users see them (store.h): submit with idempotency keys, the queued cap
 * and the storage quota, get, list (index range scans, see "listing" below), cancel, counts; and
 * the helpers every job write shares: job_transition(), the one place a job changes state, which
 * also keeps the owner's queued/running counters and job_counts and writes the event row, and
 * the JSON form of a job (docs/service.md §3), with "waiting": why a queued job waits.
 *
 * Visibility: a user sees only its own jobs, an admin every job; another user's job is reported
 * exactly like a missing one (API_NOT_FOUND), so ids reveal nothing.
 */
#include "store_internal.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const STATE_NAMES[] = {
#define JOB_STATE_NAME(c, n) n,
	JOB_STATE_MAP(JOB_STATE_NAME)
#undef JOB_STATE_NAME
};

const char *job_state_name(enum job_state st)
{
	return STATE_NAMES[st];
}

int job_state_parse(const char *name, enum job_state *st)
{
	for (int i = 0; i < JOB_STATE_COUNT; i++)
		if (strcmp(name, STATE_NAMES[i]) == 0) {
			*st = (enum job_state)i;
			return 0;
		}
	return -1;
}

static int visible(const struct principal *who, long long owner)
{
	return who->role == ROLE_ADMIN || who->user_id == owner;
}

/* Why a queued job waits, for "waiting" (null unless queued), the first that holds of: a retry
 * after an infrastructure failure is not due yet (not_before); its user has as many running jobs
 * as the user's cap (max_running, else --user-max-running; 0 = none); no worker is live
 * (server_workers); a worker is waiting for work, so the job is about to be claimed (it or, first,
 * the jobs fair share hands out before it: docs/service.md §2 "Fair share"); else every live worker
 * is busy and the job waits behind other jobs. From the row and the server's memory alone, so a
 * listing costs no query more. */
static json_t *job_waiting(struct store *s, sqlite3_stmt *st)
{
	const char *state = col_text(st, 3);
	if (!state || strcmp(state, "queued") != 0)
		return json_null();
	long long not_before = sqlite3_column_int64(st, 18), now = now_ms();
	long long running = sqlite3_column_int64(st, 19);
	long long cap = sqlite3_column_type(st, 20) == SQLITE_NULL ? s->cfg->user_max_running
								   : sqlite3_column_int64(st, 20);
	enum worker_presence workers = s->srv ? server_workers(s->srv) : WORKERS_NONE;
	char message[SERVER_MESSAGE_MAX];
	const char *reason;
	if (not_before > now) {
		char at[32];
		format_time(not_before, at);
		reason = "retry_backoff";
		snprintf(message, sizeof message, "retried after an infrastructure failure, not before %s", at);
	} else if (cap > 0 && running >= cap) {
		reason = "user_running_cap";
		snprintf(message, sizeof message, "its user has %lld running job%s, the user's cap on running jobs "
			 "(max_running) is %lld", running, running == 1 ? "" : "s", cap);
	} else if (workers == WORKERS_NONE) {
		reason = "no_worker";
		snprintf(message, sizeof message, "no worker has asked for work or renewed a lease in the last %d s",
			 s->cfg->lease_seconds);
	} else if (workers == WORKERS_WAITING) {
		reason = "starting";
		snprintf(message, sizeof message, "a worker is waiting for work: the job is about to be claimed");
	} else {
		reason = "behind_other_jobs";
		snprintf(message, sizeof message, "every live worker is busy: it waits for a free slot behind the jobs "
			 "that fair share hands out before it");
	}
	return json_pack("{s:s, s:s}", "reason", reason, "message", message);
}

json_t *job_from_row(struct store *s, sqlite3_stmt *st)
{
	json_t *progress = json_null();
	const char *p = col_text(st, 14);
	if (p) {
		json_t *parsed = json_loads(p, 0, NULL);
		if (parsed) {
			json_decref(progress);
			progress = parsed;
		}
	}
	json_t *job = json_pack("{s:I, s:o, s:o, s:o, s:i, s:i, s:i, s:i, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:b, s:o}",
			 "id", (json_int_t)sqlite3_column_int64(st, 0), "user", col_json_text(st, 1),
			 "name", col_json_text(st, 2), "state", col_json_text(st, 3),
			 "priority", sqlite3_column_int(st, 4), "threads", sqlite3_column_int(st, 5),
			 "wall_time_seconds", sqlite3_column_int(st, 6), "attempt", sqlite3_column_int(st, 7),
			 "created_at", col_json_time(st, 8), "started_at", col_json_time(st, 9),
			 "finished_at", col_json_time(st, 10), "case_sha256", col_json_text(st, 11),
			 "solver_version", col_json_text(st, 12), "worker_host", col_json_text(st, 13),
			 "progress", progress, "message", col_json_text(st, 15),
			 "cancel_requested", sqlite3_column_int(st, 16), "waiting", job_waiting(s, st));
	/* the benchmark nightlies' batch label and exclusive flag (docs/benchmarks.md) */
	json_object_set_new(job, "batch", col_json_text(st, 21));
	json_object_set_new(job, "exclusive", json_boolean(sqlite3_column_int(st, 22)));
	/* the case's title, kept beside the job for the dashboard's search (store_search.c) */
	json_object_set_new(job, "case_title", col_json_text(st, 23));
	json_object_set_new(job, "memory_mb", json_integer(sqlite3_column_int64(st, 24)));
	return job;
}

static const char SQL_JOB[] = "SELECT " JOB_COLUMNS "FROM jobs j JOIN users u ON u.id = j.user_id WHERE j.id = ?1";
static const char SQL_FILES[] =
	"SELECT name, size, sha256, attempt FROM files WHERE job_id = ?1 ORDER BY attempt, name";
static const char SQL_EVENTS[] =
	"SELECT at, from_state, to_state, attempt, actor, detail FROM events WHERE job_id = ?1 ORDER BY id";

static const char SQL_LOGS[] =
	"SELECT attempt, end_offset, dropped_to - dropped_from FROM log_attempts WHERE job_id = ?1 ORDER BY attempt";

/* "stored_bytes" (case, log text and files) and "logs": [{"attempt", "bytes", "dropped_bytes"}]. */
static enum api_code add_storage(struct conn *c, long long id, json_t *job, struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "SELECT stored_bytes FROM jobs WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "reading stored bytes");
	sqlite3_bind_int64(st, 1, id);
	json_object_set_new(job, "stored_bytes", json_integer(sqlite3_step(st) == SQLITE_ROW ?
							      sqlite3_column_int64(st, 0) : 0));
	sqlite3_reset(st);
	json_t *logs = json_array();
	json_object_set_new(job, "logs", logs);
	if (!(st = conn_stmt(c, SQL_LOGS)))
		return db_fail(c, err, "reading logs");
	sqlite3_bind_int64(st, 1, id);
	while (sqlite3_step(st) == SQLITE_ROW)
		json_array_append_new(logs, json_pack("{s:i, s:I, s:I}", "attempt", sqlite3_column_int(st, 0),
						      "bytes", (json_int_t)sqlite3_column_int64(st, 1),
						      "dropped_bytes", (json_int_t)sqlite3_column_int64(st, 2)));
	sqlite3_reset(st);
	return API_OK;
}

static enum api_code add_details(struct conn *c, long long id, json_t *job, struct api_error *err)
{
	json_t *files = json_array(), *events = json_array();
	json_object_set_new(job, "files", files);
	json_object_set_new(job, "events", events);
	sqlite3_stmt *st = conn_stmt(c, SQL_FILES);
	if (!st)
		return db_fail(c, err, "reading files");
	sqlite3_bind_int64(st, 1, id);
	while (sqlite3_step(st) == SQLITE_ROW)
		json_array_append_new(files, json_pack("{s:o, s:I, s:o, s:i}", "name", col_json_text(st, 0),
						       "size", (json_int_t)sqlite3_column_int64(st, 1),
						       "sha256", col_json_text(st, 2), "attempt",
						       sqlite3_column_int(st, 3)));
	sqlite3_reset(st);
	st = conn_stmt(c, SQL_EVENTS);
	if (!st)
		return db_fail(c, err, "reading events");
	sqlite3_bind_int64(st, 1, id);
	while (sqlite3_step(st) == SQLITE_ROW)
		json_array_append_new(events, json_pack("{s:o, s:o, s:o, s:i, s:o, s:o}", "at", col_json_time(st, 0),
							"from", col_json_text(st, 1), "to", col_json_text(st, 2),
							"attempt", sqlite3_column_int(st, 3), "actor",
							col_json_text(st, 4), "detail", col_json_text(st, 5)));
	sqlite3_reset(st);
	return add_storage(c, id, job, err);
}

/* Loads a job; *owner gets its user id (for visibility checks). */
static json_t *job_load_owner(struct store *s, struct conn *c, long long id, int full, long long *owner,
			      struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, SQL_JOB);
	if (!st) {
		db_fail(c, err, "reading a job");
		return NULL;
	}
	sqlite3_bind_int64(st, 1, id);
	if (sqlite3_step(st) != SQLITE_ROW) {
		sqlite3_reset(st);
		api_fail(err, API_NOT_FOUND, "", "no job %lld", id);
		return NULL;
	}
	json_t *job = job_from_row(s, st);
	if (owner)
		*owner = sqlite3_column_int64(st, 17);
	sqlite3_reset(st);
	if (full && add_details(c, id, job, err) != API_OK) {
		json_decref(job);
		return NULL;
	}
	return job;
}

json_t *job_load(struct store *s, struct conn *c, long long id, int full, struct api_error *err)
{
	return job_load_owner(s, c, id, full, NULL, err);
}

enum api_code job_event(struct conn *c, long long id, enum job_state from, enum job_state to, int attempt,
			const char *actor, const char *detail, struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "INSERT INTO events (job_id, at, from_state, to_state, attempt, actor, detail)"
					" VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)");
	if (!st)
		return db_fail(c, err, "preparing an event");
	sqlite3_bind_int64(st, 1, id);
	sqlite3_bind_int64(st, 2, now_ms());
	if ((int)from >= 0)
		sqlite3_bind_text(st, 3, job_state_name(from), -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 4, job_state_name(to), -1, SQLITE_STATIC);
	sqlite3_bind_int(st, 5, attempt);
	sqlite3_bind_text(st, 6, actor, -1, SQLITE_TRANSIENT);
	if (detail)
		sqlite3_bind_text(st, 7, detail, -1, SQLITE_TRANSIENT);
	int rc = sqlite3_step(st);
	sqlite3_reset(st);
	return rc == SQLITE_DONE ? API_OK : db_fail(c, err, "writing an event");
}

enum api_code job_transition(struct conn *c, long long id, enum job_state from, enum job_state to, int attempt,
			     const char *actor, const char *detail, struct api_error *err)
{
	int terminal = to == JOB_SUCCEEDED || to == JOB_FAILED || to == JOB_CANCELLED;
	sqlite3_stmt *st = conn_stmt(c, "UPDATE jobs SET state = ?2, finished_at = CASE WHEN ?3 THEN ?4 ELSE NULL END,"
					" queued_at = CASE WHEN ?2 = 'queued' THEN ?4 ELSE queued_at END"
					" WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "preparing a transition");
	long long now = now_ms();
	sqlite3_bind_int64(st, 1, id);
	sqlite3_bind_text(st, 2, job_state_name(to), -1, SQLITE_STATIC);
	sqlite3_bind_int(st, 3, terminal);
	sqlite3_bind_int64(st, 4, now);
	int rc = sqlite3_step(st);
	sqlite3_reset(st);
	if (rc != SQLITE_DONE)
		return db_fail(c, err, "changing a job's state");
	st = conn_stmt(c, "UPDATE users SET queued = queued + ?2, running = running + ?3"
			  " WHERE id = (SELECT user_id FROM jobs WHERE id = ?1)");
	if (!st)
		return db_fail(c, err, "preparing a counter update");
	sqlite3_bind_int64(st, 1, id);
	sqlite3_bind_int(st, 2, (to == JOB_QUEUED) - ((int)from == JOB_QUEUED));
	sqlite3_bind_int(st, 3, (to == JOB_RUNNING) - ((int)from == JOB_RUNNING));
	rc = sqlite3_step(st);
	sqlite3_reset(st);
	if (rc != SQLITE_DONE)
		return db_fail(c, err, "updating a user's counters");
	st = conn_stmt(c, "UPDATE job_counts SET jobs = jobs + (state = ?2) - (state = ?1) WHERE state IN (?1, ?2)");
	if (!st)
		return db_fail(c, err, "preparing a job count update");
	sqlite3_bind_text(st, 1, job_state_name(from), -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 2, job_state_name(to), -1, SQLITE_STATIC);
	enum api_code done = step_done(c, st, err, "counting jobs per state");
	return done != API_OK ? done : job_event(c, id, from, to, attempt, actor, detail, err);
}

/* ---- submit ---- */

struct submit_op {
	const struct job_submit *in;
	json_t *job;
	int created;
};

static enum api_code existing_key(struct store *s, struct conn *c, struct submit_op *op, int *found,
				  struct api_error *err)
{
	*found = 0;
	sqlite3_stmt *st = conn_stmt(c, "SELECT body_sha256, job_id FROM idempotency WHERE user_id = ?1 AND key = ?2");
	if (!st)
		return db_fail(c, err, "reading an idempotency key");
	sqlite3_bind_int64(st, 1, op->in->who->user_id);
	sqlite3_bind_text(st, 2, op->in->idempotency_key, -1, SQLITE_STATIC);
	if (sqlite3_step(st) != SQLITE_ROW) {
		sqlite3_reset(st);
		return API_OK;
	}
	*found = 1;
	int same = strcmp(col_text(st, 0), op->in->body_sha256) == 0;
	long long id = sqlite3_column_int64(st, 1);
	sqlite3_reset(st);
	if (!same)
		return api_fail(err, API_IDEMPOTENCY_CONFLICT, "Idempotency-Key",
				"idempotency key was used for job %lld with another request body", id);
	op->job = job_load(s, c, id, 0, err);
	return op->job ? API_OK : API_INTERNAL;
}

static enum api_code check_quota(struct store *s, struct conn *c, long long user, struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "SELECT queued, coalesce(max_queued, ?2) FROM users WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "reading a quota");
	sqlite3_bind_int64(st, 1, user);
	sqlite3_bind_int(st, 2, s->cfg->user_max_queued);
	long long queued = 0, cap = 0;
	if (sqlite3_step(st) == SQLITE_ROW) {
		queued = sqlite3_column_int64(st, 0);
		cap = sqlite3_column_int64(st, 1);
	}
	sqlite3_reset(st);
	if (cap > 0 && queued >= cap)
		return api_fail(err, API_QUOTA_EXCEEDED, "", "user has %lld queued jobs, the cap is %lld", queued, cap);
	return API_OK;
}

/* The next job id: one past the highest ever given, so the id of a deleted job is never reused. */
static enum api_code next_job_id(struct conn *c, long long *id, struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "UPDATE counters SET value = value + 1 WHERE name = 'job_id' RETURNING value");
	if (!st)
		return db_fail(c, err, "preparing a job id");
	int rc = sqlite3_step(st);
	*id = rc == SQLITE_ROW ? sqlite3_column_int64(st, 0) : 0;
	if (rc == SQLITE_ROW)
		rc = sqlite3_step(st); /* a RETURNING statement completes its update on the step that returns DONE */
	sqlite3_reset(st);
	return rc == SQLITE_DONE && *id > 0 ? API_OK : db_fail(c, err, "allocating a job id");
}

static enum api_code submit_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct submit_op *op = arg;
	const struct job_submit *in = op->in;
	enum api_code rc;
	if (in->idempotency_key) {
		int found;
		if ((rc = existing_key(s, c, op, &found, err)) != API_OK || found)
			return rc;
	}
	long long case_bytes = (long long)strlen(in->case_json), id = 0;
	if ((rc = check_quota(s, c, in->who->user_id, err)) != API_OK ||
	    (rc = stored_quota_check(s, c, in->who->user_id, case_bytes, err)) != API_OK ||
	    (rc = next_job_id(c, &id, err)) != API_OK)
		return rc;
	sqlite3_stmt *st = conn_stmt(c, "INSERT INTO jobs (user_id, name, state, priority, threads, wall_time_seconds,"
					" case_json, case_sha256, created_at, queued_at, id, stored_bytes, batch, exclusive, case_title,"
					" memory_mb) VALUES (?1, ?2, 'queued', ?3, ?4, ?5, ?6, ?7, ?8, ?8, ?9, ?10, ?11, ?12, ?13, ?14)");
	if (!st)
		return db_fail(c, err, "preparing a job insert");
	sqlite3_bind_int64(st, 9, id);
	sqlite3_bind_int64(st, 10, case_bytes);
	if (in->batch)
		sqlite3_bind_text(st, 11, in->batch, -1, SQLITE_STATIC);
	sqlite3_bind_int(st, 12, in->exclusive != 0);
	if (in->case_title)
		sqlite3_bind_text(st, 13, in->case_title, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 1, in->who->user_id);
	if (in->name)
		sqlite3_bind_text(st, 2, in->name, -1, SQLITE_STATIC);
	sqlite3_bind_int(st, 3, in->priority);
	sqlite3_bind_int(st, 4, in->threads);
	sqlite3_bind_int(st, 5, in->wall_time_seconds);
	sqlite3_bind_int64(st, 14, in->memory_mb);
	sqlite3_bind_text(st, 6, in->case_json, -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 7, in->case_sha256, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 8, now_ms());
	int step = sqlite3_step(st);
	sqlite3_reset(st);
	if (step != SQLITE_DONE)
		return db_fail(c, err, "inserting a job");
	st = conn_stmt(c, "UPDATE users SET queued = queued + 1, stored_bytes = stored_bytes + ?2 WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "preparing a counter update");
	sqlite3_bind_int64(st, 1, in->who->user_id);
	sqlite3_bind_int64(st, 2, case_bytes);
	step = sqlite3_step(st);
	sqlite3_reset(st);
	if (step != SQLITE_DONE)
		return db_fail(c, err, "counting a queued job");
	st = conn_stmt(c, "UPDATE job_counts SET jobs = jobs + 1 WHERE state = 'queued'");
	if (!st || (rc = step_done(c, st, err, "counting jobs per state")) != API_OK)
		return st ? rc : db_fail(c, err, "preparing a job count update");
	if ((rc = job_event(c, id, (enum job_state)-1, JOB_QUEUED, 0, in->who->name, "submitted", err)) != API_OK)
		return rc;
	if (in->idempotency_key) {
		st = conn_stmt(c, "INSERT INTO idempotency (user_id, key, body_sha256, job_id) VALUES (?1, ?2, ?3, ?4)");
		if (!st)
			return db_fail(c, err, "preparing an idempotency key");
		sqlite3_bind_int64(st, 1, in->who->user_id);
		sqlite3_bind_text(st, 2, in->idempotency_key, -1, SQLITE_STATIC);
		sqlite3_bind_text(st, 3, in->body_sha256, -1, SQLITE_STATIC);
		sqlite3_bind_int64(st, 4, id);
		step = sqlite3_step(st);
		sqlite3_reset(st);
		if (step != SQLITE_DONE)
			return db_fail(c, err, "storing an idempotency key");
	}
	op->job = job_load(s, c, id, 0, err);
	if (!op->job)
		return API_INTERNAL;
	op->created = 1;
	store_after_commit(s, WAKE_CLAIMERS);
	return API_OK;
}

enum api_code store_job_submit(struct store *s, const struct job_submit *in, json_t **job, int *created,
			       struct api_error *err)
{
	struct submit_op op = { .in = in };
	enum api_code rc = store_write(s, submit_run, &op, err);
	if (rc != API_OK) {
		json_decref(op.job);
		return rc;
	}
	*job = op.job;
	*created = op.created;
	return API_OK;
}

/* ---- get ---- */

enum api_code store_job_get(struct store *s, const struct principal *who, long long id, int full, json_t **job,
			    struct api_error *err)
{
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	conn_exec(c, "BEGIN"); /* one snapshot for the job, its files and its events */
	long long owner = 0;
	*job = job_load_owner(s, c, id, full, &owner, err);
	store_reader_done(s, c);
	if (*job && !visible(who, owner)) {
		json_decref(*job);
		*job = NULL;
		return api_fail(err, API_NOT_FOUND, "", "no job %lld", id);
	}
	return *job ? API_OK : err->code;
}

/* ---- listing ----
 *
 * Every listing is one or more index range scans in id order, each LIMITed to limit + 1 rows,
 * so a page costs the same whatever the table's size and the page's depth (after=):
 *   admin, all states:  the rowid range id < after                  (INTEGER PRIMARY KEY)
 *   user, all states:   user_id = ? AND id < after                   (jobs_user)
 *   admin, some states: per state, state = ? AND id < after          (jobs_state_id)
 *   user, some states:  per state, user_id = ? AND state = ? AND id < after (jobs_user_state)
 * With a state filter, one cursor per state asked for is merged here by id, newest first: SQLite
 * would sort the rows of a UNION ALL of LIMITed subqueries (EXPLAIN QUERY PLAN shows a temporary
 * B-tree per arm), the merge needs none. The VM steps, full-scan steps and sorts of the
 * statements are added to s->list for /metrics, which is how the tests see the cost. */

#define LIST_FROM "SELECT " JOB_COLUMNS "FROM jobs j JOIN users u ON u.id = j.user_id WHERE "
#define LIST_ORDER " AND j.id < ?2 ORDER BY j.id DESC LIMIT ?3"
static const char SQL_LIST_ALL[] = LIST_FROM "?1 = ?1" LIST_ORDER;
static const char SQL_LIST_USER[] = LIST_FROM "j.user_id = ?1" LIST_ORDER;
#define LIST_STATE_SQL(c, n) LIST_FROM "?1 = ?1 AND j.state = '" n "'" LIST_ORDER,
static const char *const SQL_LIST_STATE[JOB_STATE_COUNT] = { JOB_STATE_MAP(LIST_STATE_SQL) };
#define LIST_USER_STATE_SQL(c, n) LIST_FROM "j.user_id = ?1 AND j.state = '" n "'" LIST_ORDER,
static const char *const SQL_LIST_USER_STATE[JOB_STATE_COUNT] = { JOB_STATE_MAP(LIST_USER_STATE_SQL) };

struct list_cursor {
	sqlite3_stmt *st;
	int row;                  /* st holds a row */
};

static void list_cost(struct list_stats *cost, sqlite3_stmt *st)
{
	cost->vm_steps += (unsigned long long)sqlite3_stmt_status(st, SQLITE_STMTSTATUS_VM_STEP, 1);
	cost->fullscan_steps += (unsigned long long)sqlite3_stmt_status(st, SQLITE_STMTSTATUS_FULLSCAN_STEP, 1);
	cost->sorts += (unsigned long long)sqlite3_stmt_status(st, SQLITE_STMTSTATUS_SORT, 1);
}

/* Opens the cursors of a listing (one, or one per state asked for); -1 on a database error. */
static int list_open(struct conn *c, const struct principal *who, unsigned states, int limit, long long after,
		     struct list_cursor cur[JOB_STATE_COUNT], int *count)
{
	int admin = who->role == ROLE_ADMIN;
	*count = 0;
	for (int i = 0; i < (states ? JOB_STATE_COUNT : 1); i++) {
		if (states && !(states & (1u << i)))
			continue;
		const char *sql = states ? (admin ? SQL_LIST_STATE[i] : SQL_LIST_USER_STATE[i])
					 : (admin ? SQL_LIST_ALL : SQL_LIST_USER);
		sqlite3_stmt *st = conn_stmt(c, sql);
		if (!st)
			return -1;
		sqlite3_bind_int64(st, 1, admin ? 0 : who->user_id);
		sqlite3_bind_int64(st, 2, after > 0 ? after : LLONG_MAX);
		sqlite3_bind_int(st, 3, limit + 1);
		cur[*count].st = st;
		cur[*count].row = sqlite3_step(st) == SQLITE_ROW;
		(*count)++;
	}
	return 0;
}

/* The cursor whose row has the highest id, or -1 when all are done. */
static int list_newest(struct list_cursor *cur, int count)
{
	int best = -1;
	for (int i = 0; i < count; i++)
		if (cur[i].row && (best < 0 || sqlite3_column_int64(cur[i].st, 0) >
						       sqlite3_column_int64(cur[best].st, 0)))
			best = i;
	return best;
}

enum api_code store_job_list(struct store *s, const struct principal *who, unsigned states, int limit,
			     long long after, json_t **page, struct api_error *err)
{
	*page = NULL;
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	conn_exec(c, "BEGIN"); /* the cursors of one listing read one snapshot */
	struct list_cursor cur[JOB_STATE_COUNT];
	int count = 0;
	enum api_code rc = API_OK;
	if (list_open(c, who, states, limit, after, cur, &count) != 0)
		rc = db_fail(c, err, "listing jobs");
	json_t *jobs = json_array();
	long long last = 0;
	int n = 0, more = 0, best;
	while (rc == API_OK && (best = list_newest(cur, count)) >= 0) {
		if (n == limit) {
			more = 1;
			break;
		}
		json_array_append_new(jobs, job_from_row(s, cur[best].st));
		last = sqlite3_column_int64(cur[best].st, 0);
		n++;
		cur[best].row = sqlite3_step(cur[best].st) == SQLITE_ROW;
	}
	struct list_stats cost = { .requests = 1 };
	for (int i = 0; i < count; i++) {
		sqlite3_reset(cur[i].st);
		list_cost(&cost, cur[i].st);
	}
	store_reader_done(s, c);
	pthread_mutex_lock(&s->lock);
	s->list.requests += cost.requests;
	s->list.vm_steps += cost.vm_steps;
	s->list.fullscan_steps += cost.fullscan_steps;
	s->list.sorts += cost.sorts;
	pthread_mutex_unlock(&s->lock);
	if (rc != API_OK) {
		json_decref(jobs);
		return rc;
	}
	*page = json_pack("{s:o, s:o}", "jobs", jobs, "next_after", more ? json_integer(last) : json_null());
	return API_OK;
}

void store_list_stats(struct store *s, struct list_stats *out)
{
	pthread_mutex_lock(&s->lock);
	*out = s->list;
	pthread_mutex_unlock(&s->lock);
}

enum api_code store_job_counts(struct store *s, long long counts[JOB_STATE_COUNT], struct api_error *err)
{
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	for (int i = 0; i < JOB_STATE_COUNT; i++)
		counts[i] = 0;
	sqlite3_stmt *st = conn_stmt(c, "SELECT state, jobs FROM job_counts");
	enum api_code rc = st ? API_OK : db_fail(c, err, "counting jobs");
	while (st && sqlite3_step(st) == SQLITE_ROW) {
		enum job_state js;
		if (job_state_parse(col_text(st, 0), &js) == 0)
			counts[js] = sqlite3_column_int64(st, 1);
	}
	if (st)
		sqlite3_reset(st);
	store_reader_done(s, c);
	return rc;
}

int store_job_exists(struct store *s, long long id)
{
	struct api_error err = { 0 };
	struct conn *c = store_reader(s, &err);
	if (!c)
		return -1;
	sqlite3_stmt *st = conn_stmt(c, "SELECT 1 FROM jobs WHERE id = ?1");
	int rc = -1;
	if (st) {
		sqlite3_bind_int64(st, 1, id);
		int step = sqlite3_step(st);
		rc = step == SQLITE_ROW ? 1 : step == SQLITE_DONE ? 0 : -1;
		sqlite3_reset(st);
	}
	store_reader_done(s, c);
	return rc;
}

/* ---- cancel ---- */

struct cancel_op {
	const struct principal *who;
	long long id;
	json_t *job;
};

static enum api_code cancel_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct cancel_op *op = arg;
	sqlite3_stmt *st = conn_stmt(c, "SELECT user_id, state, attempt, cancel_requested FROM jobs WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "reading a job");
	sqlite3_bind_int64(st, 1, op->id);
	if (sqlite3_step(st) != SQLITE_ROW || !visible(op->who, sqlite3_column_int64(st, 0))) {
		sqlite3_reset(st);
		return api_fail(err, API_NOT_FOUND, "", "no job %lld", op->id);
	}
	enum job_state state = JOB_FAILED;
	job_state_parse(col_text(st, 1), &state);
	int attempt = sqlite3_column_int(st, 2), requested = sqlite3_column_int(st, 3);
	sqlite3_reset(st);
	enum api_code rc = API_OK;
	if (state == JOB_QUEUED) {
		rc = job_transition(c, op->id, JOB_QUEUED, JOB_CANCELLED, attempt, op->who->name, "cancel", err);
		store_after_commit(s, WAKE_LOG_READERS);
	} else if (state == JOB_RUNNING && !requested) {
		st = conn_stmt(c, "UPDATE jobs SET cancel_requested = 1 WHERE id = ?1");
		if (!st)
			return db_fail(c, err, "requesting cancel");
		sqlite3_bind_int64(st, 1, op->id);
		int step = sqlite3_step(st);
		sqlite3_reset(st);
		if (step != SQLITE_DONE)
			return db_fail(c, err, "requesting cancel");
		rc = job_event(c, op->id, JOB_RUNNING, JOB_RUNNING, attempt, op->who->name, "cancel requested", err);
	} else if (state != JOB_RUNNING) {
		return api_fail(err, API_NOT_CANCELLABLE, "", "job %lld is already %s", op->id, job_state_name(state));
	}
	if (rc != API_OK)
		return rc;
	op->job = job_load(s, c, op->id, 0, err);
	return op->job ? API_OK : API_INTERNAL;
}

enum api_code store_job_cancel(struct store *s, const struct principal *who, long long id, json_t **job,
			       struct api_error *err)
{
	struct cancel_op op = { .who = who, .id = id };
	enum api_code rc = store_write(s, cancel_run, &op, err);
	if (rc != API_OK) {
		json_decref(op.job);
		return rc;
	}
	*job = op.job;
	return API_OK;
}
