/*
 * store_bench.c - benchmark runs in the database (store.h, bench.h; migration 4 of migrations.c).
 *
 * benchmark_runs holds a run's plan and, once finished, its state, machine and summary;
 * benchmark_figures one row per figure of a finished run. Reads of a figure's series and of a
 * timing figure's history are one range of the index benchmark_series (suite, figure,
 * fingerprint, run_id), newest first, stopped after the rows asked for: their cost does not grow
 * with the number of runs stored.
 */
#include "store_internal.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RUN_COLUMNS "r.id, r.suite, r.label, r.commit_id, u.name, r.client_host, r.state, r.solver_version, " \
	"r.machine, r.fingerprint, r.summary, r.created_at, r.finished_at, r.user_id, r.plan "
#define RUN_FROM "FROM benchmark_runs r JOIN users u ON u.id = r.user_id "

/* A stored JSON text as a tree (null when absent or not JSON). */
static json_t *col_json_doc(sqlite3_stmt *st, int i)
{
	const char *t = col_text(st, i);
	json_t *v = t ? json_loads(t, 0, NULL) : NULL;
	return v ? v : json_null();
}

/* A REAL column, or null. */
static json_t *col_json_real(sqlite3_stmt *st, int i)
{
	return sqlite3_column_type(st, i) == SQLITE_NULL ? json_null() : json_real(sqlite3_column_double(st, i));
}

/* The run of a row of RUN_COLUMNS; full adds its settings and cases from the plan. */
static json_t *run_from_row(sqlite3_stmt *st, int full)
{
	json_t *run = json_pack("{s:I, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o}",
				"id", (json_int_t)sqlite3_column_int64(st, 0), "suite", col_json_text(st, 1),
				"label", col_json_text(st, 2), "commit", col_json_text(st, 3), "user", col_json_text(st, 4),
				"client_host", col_json_text(st, 5), "state", col_json_text(st, 6),
				"solver_version", col_json_text(st, 7), "machine", col_json_doc(st, 8),
				"fingerprint", col_json_text(st, 9), "summary", col_json_doc(st, 10),
				"created_at", col_json_time(st, 11), "finished_at", col_json_time(st, 12));
	if (run && full) {
		json_t *plan = col_json_doc(st, 14);
		json_object_set(run, "settings", json_object_get(plan, "settings"));
		json_object_set(run, "cases", json_object_get(plan, "cases"));
		json_decref(plan);
	}
	return run;
}

/* ---- create ---- */

struct create_op {
	const struct principal *who;
	const char *suite, *label, *commit, *host;
	char *plan;
	long long id;
};

static enum api_code create_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct create_op *op = arg;
	sqlite3_stmt *st = conn_stmt(c, "SELECT id FROM benchmark_runs WHERE label = ?1");
	if (!st)
		return db_fail(c, err, "reading benchmark runs");
	sqlite3_bind_text(st, 1, op->label, -1, SQLITE_STATIC);
	int taken = sqlite3_step(st) == SQLITE_ROW;
	long long other = taken ? sqlite3_column_int64(st, 0) : 0;
	sqlite3_reset(st);
	if (taken)
		return api_fail(err, API_ALREADY_EXISTS, "/label", "benchmark run %lld already has the label '%s'", other,
				op->label);
	st = conn_stmt(c, "INSERT INTO benchmark_runs (user_id, suite, label, commit_id, client_host, state, plan,"
			  " created_at) VALUES (?1, ?2, ?3, ?4, ?5, 'running', ?6, ?7) RETURNING id");
	if (!st)
		return db_fail(c, err, "preparing a benchmark run");
	sqlite3_bind_int64(st, 1, op->who->user_id);
	sqlite3_bind_text(st, 2, op->suite, -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 3, op->label, -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 4, op->commit, -1, SQLITE_STATIC);
	if (op->host)
		sqlite3_bind_text(st, 5, op->host, -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 6, op->plan, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 7, now_ms());
	int rc = sqlite3_step(st);
	op->id = rc == SQLITE_ROW ? sqlite3_column_int64(st, 0) : 0;
	if (rc == SQLITE_ROW)
		rc = sqlite3_step(st); /* a RETURNING statement completes on the step that returns DONE */
	sqlite3_reset(st);
	return rc == SQLITE_DONE && op->id > 0 ? API_OK : db_fail(c, err, "storing a benchmark run");
}

enum api_code store_bench_create(struct store *s, const struct principal *who, const char *suite, const char *label,
				 const char *commit, const char *host, const json_t *plan, json_t **run,
				 struct api_error *err)
{
	struct create_op op = { .who = who, .suite = suite, .label = label, .commit = commit, .host = host,
				.plan = json_dumps(plan, JSON_COMPACT) };
	*run = NULL;
	if (!op.plan)
		return api_fail(err, API_UNAVAILABLE, "", "no memory to store the benchmark run: retry later");
	enum api_code rc = store_write(s, create_run, &op, err);
	free(op.plan);
	return rc == API_OK ? store_bench_get(s, op.id, 1, run, NULL, err) : rc;
}

/* ---- read ---- */

static const char SQL_FIGURES[] =
	"SELECT figure, kind, class, check_kind, unit, case_sha256, fingerprint, samples, median, band_min, band_max,"
	" status, detail, stats FROM benchmark_figures WHERE run_id = ?1 ORDER BY figure";

static json_t *figure_from_row(sqlite3_stmt *st)
{
	const char *figure = col_text(st, 0), *slash = figure ? strchr(figure, '/') : NULL;
	json_t *band = json_null();
	if (!strcmp(col_text(st, 3), "band")) {
		json_decref(band);
		band = json_pack("[o, o]", col_json_real(st, 9), col_json_real(st, 10));
	}
	return json_pack("{s:o, s:s%, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o}",
			 "figure", col_json_text(st, 0), "case", figure ? figure : "",
			 slash ? (size_t)(slash - figure) : 0, "kind", col_json_text(st, 1), "class",
			 col_json_text(st, 2), "check", col_json_text(st, 3), "unit", col_json_text(st, 4),
			 "case_sha256", col_json_text(st, 5), "machine", col_json_text(st, 6), "samples",
			 col_json_doc(st, 7), "median", col_json_real(st, 8), "band", band, "status",
			 col_json_text(st, 11), "detail", col_json_text(st, 12), "stats", col_json_doc(st, 13));
}

enum api_code store_bench_get(struct store *s, long long id, int full, json_t **run, long long *owner,
			      struct api_error *err)
{
	*run = NULL;
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	conn_exec(c, "BEGIN"); /* the run and its figures from one snapshot */
	enum api_code rc = API_OK;
	sqlite3_stmt *st = conn_stmt(c, "SELECT " RUN_COLUMNS RUN_FROM "WHERE r.id = ?1");
	if (!st) {
		rc = db_fail(c, err, "reading a benchmark run");
	} else {
		sqlite3_bind_int64(st, 1, id);
		if (sqlite3_step(st) == SQLITE_ROW) {
			*run = run_from_row(st, full);
			if (owner)
				*owner = sqlite3_column_int64(st, 13);
		} else {
			rc = api_fail(err, API_NOT_FOUND, "", "no benchmark run %lld", id);
		}
		sqlite3_reset(st);
	}
	if (rc == API_OK && full) {
		json_t *figures = json_array();
		json_object_set_new(*run, "figures", figures);
		if (!(st = conn_stmt(c, SQL_FIGURES))) {
			rc = db_fail(c, err, "reading benchmark figures");
		} else {
			sqlite3_bind_int64(st, 1, id);
			while (sqlite3_step(st) == SQLITE_ROW)
				json_array_append_new(figures, figure_from_row(st));
			sqlite3_reset(st);
		}
	}
	store_reader_done(s, c);
	if (rc != API_OK) {
		json_decref(*run);
		*run = NULL;
	}
	return rc;
}

static const char SQL_LIST_ALL[] = "SELECT " RUN_COLUMNS RUN_FROM "WHERE r.id < ?2 AND ?1 IS NULL"
				   " ORDER BY r.id DESC LIMIT ?3";
static const char SQL_LIST_SUITE[] = "SELECT " RUN_COLUMNS RUN_FROM "WHERE r.suite = ?1 AND r.id < ?2"
				     " ORDER BY r.id DESC LIMIT ?3";

enum api_code store_bench_list(struct store *s, const char *suite, int limit, long long after, json_t **page,
			       struct api_error *err)
{
	*page = NULL;
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	sqlite3_stmt *st = conn_stmt(c, suite ? SQL_LIST_SUITE : SQL_LIST_ALL);
	if (!st) {
		enum api_code rc = db_fail(c, err, "listing benchmark runs");
		store_reader_done(s, c);
		return rc;
	}
	if (suite)
		sqlite3_bind_text(st, 1, suite, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 2, after > 0 ? after : LLONG_MAX);
	sqlite3_bind_int(st, 3, limit + 1);
	json_t *runs = json_array();
	long long last = 0;
	int n = 0, more = 0;
	while (sqlite3_step(st) == SQLITE_ROW) {
		if (n == limit) {
			more = 1;
			break;
		}
		json_array_append_new(runs, run_from_row(st, 0));
		last = sqlite3_column_int64(st, 0);
		n++;
	}
	sqlite3_reset(st);
	store_reader_done(s, c);
	*page = json_pack("{s:o, s:o}", "runs", runs, "next_after", more ? json_integer(last) : json_null());
	return API_OK;
}

#define SERIES_SELECT "SELECT f.run_id, r.label, r.commit_id, r.created_at, r.solver_version, f.fingerprint," \
	" f.samples, f.median, f.status, f.check_kind, f.band_min, f.band_max FROM benchmark_figures f" \
	" JOIN benchmark_runs r ON r.id = f.run_id WHERE f.suite = ?1 AND f.figure = ?2 "
static const char SQL_SERIES_ANY[] = SERIES_SELECT "AND ?3 IS NULL ORDER BY f.run_id DESC LIMIT ?4";
static const char SQL_SERIES_MACHINE[] = SERIES_SELECT "AND f.fingerprint = ?3 ORDER BY f.run_id DESC LIMIT ?4";

enum api_code store_bench_series(struct store *s, const char *suite, const char *figure, const char *fingerprint,
				 int limit, json_t **points, struct api_error *err)
{
	*points = NULL;
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	sqlite3_stmt *st = conn_stmt(c, fingerprint ? SQL_SERIES_MACHINE : SQL_SERIES_ANY);
	if (!st) {
		enum api_code rc = db_fail(c, err, "reading a benchmark series");
		store_reader_done(s, c);
		return rc;
	}
	sqlite3_bind_text(st, 1, suite, -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 2, figure, -1, SQLITE_STATIC);
	if (fingerprint)
		sqlite3_bind_text(st, 3, fingerprint, -1, SQLITE_STATIC);
	sqlite3_bind_int(st, 4, limit);
	json_t *list = json_array();
	while (sqlite3_step(st) == SQLITE_ROW) {
		json_t *band = !strcmp(col_text(st, 9), "band") ? json_pack("[o, o]", col_json_real(st, 10),
									    col_json_real(st, 11)) : json_null();
		json_array_insert_new(list, 0, json_pack("{s:I, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o}",
							 "run", (json_int_t)sqlite3_column_int64(st, 0), "label",
							 col_json_text(st, 1), "commit", col_json_text(st, 2),
							 "created_at", col_json_time(st, 3), "solver_version",
							 col_json_text(st, 4), "machine", col_json_text(st, 5),
							 "samples", col_json_doc(st, 6), "median", col_json_real(st, 7),
							 "status", col_json_text(st, 8), "band", band));
	}
	sqlite3_reset(st);
	store_reader_done(s, c);
	*points = list;
	return API_OK;
}

enum api_code store_bench_history(struct store *s, const char *suite, const char *figure, const char *fingerprint,
				  const char *case_sha256, long long before_id, int runs, double **samples, int *count,
				  int *run_count, struct api_error *err)
{
	*samples = NULL;
	*count = *run_count = 0;
	struct conn *c = store_reader(s, err);
	if (!c)
		return API_INTERNAL;
	/* the samples of every verdict but failed and did_not_run, which have none */
	sqlite3_stmt *st = conn_stmt(c, "SELECT samples FROM benchmark_figures WHERE suite = ?1 AND figure = ?2"
					" AND fingerprint = ?3 AND run_id < ?4 AND case_sha256 IS ?5"
					" AND status NOT IN ('failed', 'did_not_run') ORDER BY run_id DESC LIMIT ?6");
	if (!st) {
		enum api_code rc = db_fail(c, err, "reading a benchmark history");
		store_reader_done(s, c);
		return rc;
	}
	sqlite3_bind_text(st, 1, suite, -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 2, figure, -1, SQLITE_STATIC);
	sqlite3_bind_text(st, 3, fingerprint, -1, SQLITE_STATIC);
	sqlite3_bind_int64(st, 4, before_id);
	if (case_sha256)
		sqlite3_bind_text(st, 5, case_sha256, -1, SQLITE_STATIC);
	sqlite3_bind_int(st, 6, runs);
	size_t cap = 0;
	enum api_code rc = API_OK;
	while (rc == API_OK && sqlite3_step(st) == SQLITE_ROW) {
		json_t *list = col_json_doc(st, 0), *v;
		size_t i;
		(*run_count)++;
		json_array_foreach(list, i, v) {
			if (!json_is_number(v))
				continue;
			if ((size_t)*count == cap) {
				double *grown = realloc(*samples, sizeof **samples * (cap = cap ? 2 * cap : 64));
				if (!grown) {
					rc = api_fail(err, API_UNAVAILABLE, "", "no memory for a benchmark history");
					break;
				}
				*samples = grown;
			}
			(*samples)[(*count)++] = json_number_value(v);
		}
		json_decref(list);
	}
	sqlite3_reset(st);
	store_reader_done(s, c);
	if (rc != API_OK) {
		free(*samples);
		*samples = NULL;
		*count = 0;
	}
	return rc;
}

/* ---- finish ---- */

struct finish_op {
	long long id;
	const json_t *result;
	int changed;
};

/* A JSON member as stored text (compact), or NULL for null or absent; the caller frees it. */
static char *member_text(const json_t *obj, const char *key)
{
	const json_t *v = json_object_get(obj, key);
	return v && !json_is_null(v) ? json_dumps(v, JSON_COMPACT | JSON_ENCODE_ANY) : NULL;
}

static void bind_text_or_null(sqlite3_stmt *st, int i, const char *text)
{
	if (text)
		sqlite3_bind_text(st, i, text, -1, SQLITE_TRANSIENT);
}

static void bind_real_or_null(sqlite3_stmt *st, int i, const json_t *v)
{
	if (json_is_number(v) && isfinite(json_number_value(v)))
		sqlite3_bind_double(st, i, json_number_value(v));
}

static enum api_code insert_figure(struct conn *c, long long run, const char *suite, const json_t *f,
				   struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "INSERT INTO benchmark_figures (run_id, figure, suite, kind, class, check_kind,"
					" unit, case_sha256, fingerprint, samples, median, band_min, band_max, status,"
					" detail, stats) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13,"
					" ?14, ?15, ?16)");
	if (!st)
		return db_fail(c, err, "preparing a benchmark figure");
	char *samples = member_text(f, "samples"), *stats = member_text(f, "stats");
	const json_t *band = json_object_get(f, "band");
	sqlite3_bind_int64(st, 1, run);
	sqlite3_bind_text(st, 2, json_string_value(json_object_get(f, "figure")), -1, SQLITE_TRANSIENT);
	sqlite3_bind_text(st, 3, suite, -1, SQLITE_TRANSIENT);
	static const char *const text_keys[] = { "kind", "class", "check", "unit", "case_sha256", "machine" };
	for (int i = 0; i < 6; i++)
		bind_text_or_null(st, 4 + i, json_string_value(json_object_get(f, text_keys[i])));
	sqlite3_bind_text(st, 10, samples ? samples : "[]", -1, SQLITE_TRANSIENT);
	bind_real_or_null(st, 11, json_object_get(f, "median"));
	bind_real_or_null(st, 12, json_array_get(band, 0));
	bind_real_or_null(st, 13, json_array_get(band, 1));
	sqlite3_bind_text(st, 14, json_string_value(json_object_get(f, "status")), -1, SQLITE_TRANSIENT);
	bind_text_or_null(st, 15, json_string_value(json_object_get(f, "detail")));
	bind_text_or_null(st, 16, stats);
	free(samples);
	free(stats);
	return step_done(c, st, err, "storing a benchmark figure");
}

static enum api_code finish_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	struct finish_op *op = arg;
	sqlite3_stmt *st = conn_stmt(c, "SELECT state, suite FROM benchmark_runs WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "reading a benchmark run");
	sqlite3_bind_int64(st, 1, op->id);
	if (sqlite3_step(st) != SQLITE_ROW) {
		sqlite3_reset(st);
		return api_fail(err, API_NOT_FOUND, "", "no benchmark run %lld", op->id);
	}
	int running = !strcmp(col_text(st, 0), "running");
	char suite[128];
	snprintf(suite, sizeof suite, "%s", col_text(st, 1));
	sqlite3_reset(st);
	if (!running)
		return API_OK;   /* finished meanwhile, by another request: its result stands */
	const json_t *r = op->result, *f;
	size_t i;
	enum api_code rc = API_OK;
	json_array_foreach(json_object_get(r, "figures"), i, f) {
		if ((rc = insert_figure(c, op->id, suite, f, err)) != API_OK)
			return rc;
	}
	st = conn_stmt(c, "UPDATE benchmark_runs SET state = ?2, solver_version = ?3, machine = ?4, fingerprint = ?5,"
			  " summary = ?6, finished_at = ?7 WHERE id = ?1");
	if (!st)
		return db_fail(c, err, "preparing a benchmark run's end");
	char *machine = member_text(r, "machine"), *summary = member_text(r, "summary");
	sqlite3_bind_int64(st, 1, op->id);
	sqlite3_bind_text(st, 2, json_string_value(json_object_get(r, "state")), -1, SQLITE_TRANSIENT);
	bind_text_or_null(st, 3, json_string_value(json_object_get(r, "solver_version")));
	bind_text_or_null(st, 4, machine);
	bind_text_or_null(st, 5, json_string_value(json_object_get(r, "fingerprint")));
	bind_text_or_null(st, 6, summary);
	sqlite3_bind_int64(st, 7, now_ms());
	free(machine);
	free(summary);
	if ((rc = step_done(c, st, err, "ending a benchmark run")) == API_OK)
		op->changed = 1;
	return rc;
}

enum api_code store_bench_finish(struct store *s, long long id, const json_t *result, int *changed,
				 struct api_error *err)
{
	struct finish_op op = { .id = id, .result = result };
	enum api_code rc = store_write(s, finish_run, &op, err);
	*changed = op.changed;
	return rc;
}
