/*
 * store_search.c - what the dashboard reads beyond store_jobs.c (store.h): the job search with
 * filters on owner, states, creation time, the job's name and the case's title, newest or oldest
 * first; a job's case text; the running jobs and the queue per user for the admin view.
 *
 * The search is one index range scan in id order, LIMITed to limit + 1 rows, like every listing.
 * The index is a covering one of migration 5, named with INDEXED BY so the plan cannot drift with
 * the table's statistics: jobs_user_search (user_id, id, state, created_at, name, case_title) when
 * the owner is known (a user, or an admin's user= filter), jobs_search (id, state, created_at,
 * user_id, name, case_title) for an admin's search over everyone. SQLite evaluates the filters on
 * the index entry and seeks the job's row (with its case text, a kilobyte or more) only for a row
 * that passes (a deferred seek), so a search that matches nothing reads index entries of some
 * tens of bytes each and nothing else: at 100,000 jobs a few megabytes (bench/web.sh prints the
 * time). The text filters are substrings in any case of ASCII letters: LIKE '%text%' (SQLite's LIKE
 * ignores the case of ASCII letters and allocates nothing per row, where lower() would copy each
 * string), with '%', '_' and '\' of the text escaped, so they are plain characters.
 */
#include "store_internal.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SEARCH_SQL_MAX 2048

static void add(char *sql, const char *text)
{
	size_t n = strlen(sql);
	snprintf(sql + n, SEARCH_SQL_MAX - n, "%s", text);
}

/* The statement's text: parameters ?1 owner id, ?2 id bound, ?3 limit, ?4 name, ?5 title,
 * ?6 created from, ?7 created to. Built from fixed pieces only; every value is bound. */
static void search_sql(const struct job_search *q, int by_user, char sql[SEARCH_SQL_MAX])
{
	snprintf(sql, SEARCH_SQL_MAX, "SELECT " JOB_COLUMNS "FROM jobs j INDEXED BY %s JOIN users u ON u.id = j.user_id WHERE ",
		 by_user ? "jobs_user_search" : "jobs_search");
	add(sql, by_user ? "j.user_id = ?1" : "?1 = ?1");
	add(sql, q->oldest_first ? " AND j.id > ?2" : " AND j.id < ?2");
	if (q->states) {
		add(sql, " AND j.state IN (");
		int first = 1;
		for (int i = 0; i < JOB_STATE_COUNT; i++) {
			if (!(q->states & (1u << i)))
				continue;
			add(sql, first ? "'" : ", '");
			add(sql, job_state_name((enum job_state)i));
			add(sql, "'");
			first = 0;
		}
		add(sql, ")");
	}
	if (q->name)
		add(sql, " AND j.name LIKE ?4 ESCAPE '\\'");
	if (q->title)
		add(sql, " AND j.case_title LIKE ?5 ESCAPE '\\'");
	if (q->created_from)
		add(sql, " AND j.created_at >= ?6");
	if (q->created_to)
		add(sql, " AND j.created_at <= ?7");
	add(sql, q->oldest_first ? " ORDER BY j.id ASC LIMIT ?3" : " ORDER BY j.id DESC LIMIT ?3");
}

/* '%text%' for LIKE, with the text's '%', '_' and '\' escaped by '\'; NULL when out of memory. */
static char *like_pattern(const char *text)
{
	size_t n = strlen(text);
	char *p = malloc(2 * n + 3), *o = p;
	if (!p)
		return NULL;
	*o++ = '%';
	for (const char *t = text; *t; t++) {
		if (*t == '%' || *t == '_' || *t == '\\')
			*o++ = '\\';
		*o++ = *t;
	}
	*o++ = '%';
	*o = '\0';
	return p;
}

/* The owner's id: the principal's own for a user; for an admin the user= filter's, 0 for all.
 * -1 when the filter names nobody the principal may see (the page is then empty). */
static long long search_owner(struct conn *c, const struct principal *who, const char *user)
{
	if (who->role != ROLE_ADMIN)
		return user && strcmp(user, who->name) ? -1 : who->user_id;
	if (!user)
		return 0;
	sqlite3_stmt *st = conn_stmt(c, "SELECT id FROM users WHERE name = ?1");
	if (!st)
		return -1;
	sqlite3_bind_text(st, 1, user, -1, SQLITE_STATIC);
	long long id = sqlite3_step(st) == SQLITE_ROW ? sqlite3_column_int64(st, 0) : -1;
	sqlite3_reset(st);
	return id;
}

enum api_code store_job_search(struct store *s, const struct principal *who, const struct job_search *q,
			       json_t **page, struct api_error *err)
{
	*page = NULL;
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	json_t *jobs = json_array();
	long long owner = search_owner(c, who, q->user), last = 0;
	int more = 0;
	enum api_code rc = API_OK;
	if (owner >= 0) {
		/* the statement differs by filter: prepared for this request, not from the cache */
		char sql[SEARCH_SQL_MAX];
		search_sql(q, owner > 0, sql);
		sqlite3_stmt *st = NULL;
		if (sqlite3_prepare_v2(c->db, sql, -1, &st, NULL) != SQLITE_OK) {
			rc = db_fail(c, err, "searching jobs");
		} else {
			sqlite3_bind_int64(st, 1, owner);
			sqlite3_bind_int64(st, 2, q->after > 0 ? q->after : q->oldest_first ? 0 : LLONG_MAX);
			sqlite3_bind_int(st, 3, q->limit + 1);
			if (q->name)
				sqlite3_bind_text(st, 4, like_pattern(q->name), -1, free);
			if (q->title)
				sqlite3_bind_text(st, 5, like_pattern(q->title), -1, free);
			sqlite3_bind_int64(st, 6, q->created_from);
			sqlite3_bind_int64(st, 7, q->created_to);
			int n = 0, step;
			while ((step = sqlite3_step(st)) == SQLITE_ROW) {
				if (n == q->limit) {
					more = 1;
					break;
				}
				json_array_append_new(jobs, job_from_row(s, st));
				last = sqlite3_column_int64(st, 0);
				n++;
			}
			if (step != SQLITE_ROW && step != SQLITE_DONE)
				rc = db_fail(c, err, "searching jobs");
			sqlite3_finalize(st);
		}
	}
	store_reader_done(s, c);
	if (rc != API_OK) {
		json_decref(jobs);
		return rc;
	}
	*page = json_pack("{s:o, s:o}", "jobs", jobs, "next_after", more ? json_integer(last) : json_null());
	return API_OK;
}

enum api_code store_job_case(struct store *s, const struct principal *who, long long id, char **text,
			     struct api_error *err)
{
	*text = NULL;
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	sqlite3_stmt *st = conn_stmt(c, "SELECT user_id, case_json FROM jobs WHERE id = ?1");
	enum api_code rc = API_OK;
	if (!st) {
		rc = db_fail(c, err, "reading a case");
	} else {
		sqlite3_bind_int64(st, 1, id);
		if (sqlite3_step(st) != SQLITE_ROW ||
		    (who->role != ROLE_ADMIN && sqlite3_column_int64(st, 0) != who->user_id))
			rc = api_fail(err, API_NOT_FOUND, "", "no job %lld", id);
		else if (!(*text = strdup(col_text(st, 1) ? col_text(st, 1) : "{}")))
			rc = api_fail(err, API_UNAVAILABLE, "", "no memory for the case of job %lld: retry later", id);
		sqlite3_reset(st);
	}
	store_reader_done(s, c);
	return rc;
}

/* The running jobs (jobs_state_id: a range scan of the running state alone). */
static enum api_code overview_running(struct store *s, struct conn *c, json_t *running, struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "SELECT " JOB_COLUMNS ", j.worker FROM jobs j JOIN users u ON u.id = j.user_id"
					" WHERE j.state = 'running' ORDER BY j.id");
	if (!st)
		return db_fail(c, err, "reading the running jobs");
	while (sqlite3_step(st) == SQLITE_ROW) {
		json_t *job = job_from_row(s, st);
		json_object_set_new(job, "worker", col_json_text(st, 24));
		json_array_append_new(running, job);
	}
	sqlite3_reset(st);
	return API_OK;
}

/* The users with queued or running jobs, from their counters (no scan of jobs). */
static enum api_code overview_queue(struct store *s, struct conn *c, json_t *queue, struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "SELECT name, queued, running, coalesce(max_queued, ?1), coalesce(max_running, ?2)"
					" FROM users WHERE queued > 0 OR running > 0 ORDER BY queued + running DESC, name");
	if (!st)
		return db_fail(c, err, "reading the queue");
	sqlite3_bind_int(st, 1, s->cfg->user_max_queued);
	sqlite3_bind_int(st, 2, s->cfg->user_max_running);
	while (sqlite3_step(st) == SQLITE_ROW)
		json_array_append_new(queue, json_pack("{s:o, s:I, s:I, s:I, s:I}", "user", col_json_text(st, 0), "queued",
						       (json_int_t)sqlite3_column_int64(st, 1), "running",
						       (json_int_t)sqlite3_column_int64(st, 2), "max_queued",
						       (json_int_t)sqlite3_column_int64(st, 3), "max_running",
						       (json_int_t)sqlite3_column_int64(st, 4)));
	sqlite3_reset(st);
	return API_OK;
}

enum api_code store_admin_overview(struct store *s, json_t **out, struct api_error *err)
{
	*out = NULL;
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	conn_exec(c, "BEGIN"); /* one snapshot for both lists */
	json_t *running = json_array(), *queue = json_array();
	enum api_code rc = overview_running(s, c, running, err);
	if (rc == API_OK)
		rc = overview_queue(s, c, queue, err);
	store_reader_done(s, c);
	if (rc != API_OK) {
		json_decref(running);
		json_decref(queue);
		return rc;
	}
	*out = json_pack("{s:o, s:o}", "running", running, "queue", queue);
	return API_OK;
}
