/*
 * store_jobs.c - jobs as users see them (store.h): submit with idempotency keys and the queued
 * cap, get, list, cancel, counts; and the helpers every job write shares: job_transition(), the
 * one place a job changes state, which also keeps the owner's queued/running counters and writes
 * the event row, and the JSON form of a job (docs/service.md §3).
 *
 * Visibility: a user sees only its own jobs, an admin every job; another user's job is reported
 * exactly like a missing one (API_NOT_FOUND), so ids reveal nothing.
 */
#include "store_internal.h"

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

json_t *job_from_row(sqlite3_stmt *st)
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
	return json_pack("{s:I, s:o, s:o, s:o, s:i, s:i, s:i, s:i, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:b}",
			 "id", (json_int_t)sqlite3_column_int64(st, 0), "user", col_json_text(st, 1),
			 "name", col_json_text(st, 2), "state", col_json_text(st, 3),
			 "priority", sqlite3_column_int(st, 4), "threads", sqlite3_column_int(st, 5),
			 "wall_time_seconds", sqlite3_column_int(st, 6), "attempt", sqlite3_column_int(st, 7),
			 "created_at", col_json_time(st, 8), "started_at", col_json_time(st, 9),
			 "finished_at", col_json_time(st, 10), "case_sha256", col_json_text(st, 11),
			 "solver_version", col_json_text(st, 12), "worker_host", col_json_text(st, 13),
			 "progress", progress, "message", col_json_text(st, 15),
			 "cancel_requested", sqlite3_column_int(st, 16));
}

static const char SQL_JOB[] = "SELECT " JOB_COLUMNS "FROM jobs j JOIN users u ON u.id = j.user_id WHERE j.id = ?1";
static const char SQL_FILES[] =
	"SELECT name, size, sha256, attempt FROM files WHERE job_id = ?1 ORDER BY attempt, name";
static const char SQL_EVENTS[] =
	"SELECT at, from_state, to_state, attempt, actor, detail FROM events WHERE job_id = ?1 ORDER BY id";

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
	return API_OK;
}

/* Loads a job; *owner gets its user id (for visibility checks). */
static json_t *job_load_owner(struct conn *c, long long id, int full, long long *owner, struct api_error *err)
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
	json_t *job = job_from_row(st);
	if (owner)
		*owner = sqlite3_column_int64(st, 17);
	sqlite3_reset(st);
	if (full && add_details(c, id, job, err) != API_OK) {
		json_decref(job);
		return NULL;
	}
	return job;
}

json_t *job_load(struct conn *c, long long id, int full, struct api_error *err)
{
	return job_load_owner(c, id, full, NULL, err);
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
	return job_event(c, id, from, to, attempt, actor, detail, err);
}

/* ---- submit ---- */

struct submit_op {
	const struct job_submit *in;
	json_t *job;
	int created;
};

static enum api_code existing_key(struct conn *c, struct submit_op *op, int *found, struct api_error *err)
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
	op->job = job_load(c, id, 0, err);
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

static enum api_code submit_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct submit_op *op = arg;
	const struct job_submit *in = op->in;
	enum api_code rc;
	if (in->idempotency_key) {
		int found;
		if ((rc = existing_key(c, op, &found, err)) != API_OK || found)
			return rc;
	}
	if ((rc = check_quota(s, c, in->who->user_id, err)) != API_OK)
		return rc;
	sqlite3_stmt *st = conn_stmt(c, "INSERT INTO jobs (user_id, name, state, priority, threads, wall_time_seconds,"
					" case_json, case_sha256, created_at, queued_at)"
					" VALUES (?1, ?2, 'queued', ?3, ?4, ?5, ?6, ?7, ?8, ?8)");
	if (!st)
		return db_fail(c, err, "preparing a job insert");
	sqlite3_bind_int64(st, 1, in->who->user_id);
	if (in->name)
		sqlite3_bind_text(st, 2, in->name, -1, SQLITE_STATIC);
	sqlite3_bind_int(st, 3, in->priority);
	sqlite3_bind_int(st, 4, in->threads);
	sqlite3_bind_int(st, 5, in->wall_time_seconds);
	sqlite3_bind_text(st, 6, in->case_json, -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 7, in->case_sha256, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 8, now_ms());
	int step = sqlite3_step(st);
	sqlite3_reset(st);
	if (step != SQLITE_DONE)
		return db_fail(c, err, "inserting a job");
	long long id = sqlite3_last_insert_rowid(c->db);
	st = conn_stmt(c, "UPDATE users SET queued = queued + 1 WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "preparing a counter update");
	sqlite3_bind_int64(st, 1, in->who->user_id);
	step = sqlite3_step(st);
	sqlite3_reset(st);
	if (step != SQLITE_DONE)
		return db_fail(c, err, "counting a queued job");
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
	op->job = job_load(c, id, 0, err);
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

/* ---- get, list, counts ---- */

enum api_code store_job_get(struct store *s, const struct principal *who, long long id, int full, json_t **job,
			    struct api_error *err)
{
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	conn_exec(c, "BEGIN"); /* one snapshot for the job, its files and its events */
	long long owner = 0;
	*job = job_load_owner(c, id, full, &owner, err);
	store_reader_done(s, c);
	if (*job && !visible(who, owner)) {
		json_decref(*job);
		*job = NULL;
		return api_fail(err, API_NOT_FOUND, "", "no job %lld", id);
	}
	return *job ? API_OK : err->code;
}

enum api_code store_job_list(struct store *s, const struct principal *who, unsigned states, int limit,
			     long long after, json_t **page, struct api_error *err)
{
	static const char sql[] =
		"SELECT " JOB_COLUMNS "FROM jobs j JOIN users u ON u.id = j.user_id"
		" WHERE (?1 = 0 OR j.user_id = ?1) AND (?2 = 0 OR j.id < ?2)"
		" AND (?3 = 0 OR (?3 & CASE j.state WHEN 'queued' THEN 1 WHEN 'running' THEN 2"
		" WHEN 'succeeded' THEN 4 WHEN 'failed' THEN 8 ELSE 16 END) != 0)"
		" ORDER BY j.id DESC LIMIT ?4";
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	sqlite3_stmt *st = conn_stmt(c, sql);
	if (!st) {
		enum api_code rc = db_fail(c, err, "listing jobs");
		store_reader_done(s, c);
		return rc;
	}
	sqlite3_bind_int64(st, 1, who->role == ROLE_ADMIN ? 0 : who->user_id);
	sqlite3_bind_int64(st, 2, after);
	sqlite3_bind_int(st, 3, (int)states);
	sqlite3_bind_int(st, 4, limit + 1);
	json_t *jobs = json_array();
	long long last = 0;
	int n = 0, more = 0;
	while (sqlite3_step(st) == SQLITE_ROW) {
		if (n == limit) {
			more = 1;
			break;
		}
		json_array_append_new(jobs, job_from_row(st));
		last = sqlite3_column_int64(st, 0);
		n++;
	}
	sqlite3_reset(st);
	store_reader_done(s, c);
	*page = json_pack("{s:o, s:o}", "jobs", jobs, "next_after", more ? json_integer(last) : json_null());
	return API_OK;
}

enum api_code store_job_counts(struct store *s, long long counts[JOB_STATE_COUNT], struct api_error *err)
{
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	for (int i = 0; i < JOB_STATE_COUNT; i++)
		counts[i] = 0;
	sqlite3_stmt *st = conn_stmt(c, "SELECT state, count(*) FROM jobs GROUP BY state");
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
	op->job = job_load(c, op->id, 0, err);
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
