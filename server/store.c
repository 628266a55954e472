/*
 * store.c - the database's connections and its writer thread (store.h, docs/service.md §1).
 *
 * Group commit: handlers append a write request to a queue and wait. The writer takes every
 * queued request (at most cfg->group_commit_max), runs them inside one BEGIN IMMEDIATE ... COMMIT,
 * each within its own SAVEPOINT so a failing request is rolled back alone, and only after COMMIT
 * has returned marks them done. With journal_mode=WAL and synchronous=FULL, COMMIT returning means
 * the WAL frame is fsynced: nothing is acknowledged before it is durable, and many concurrent
 * submissions share one fsync. If COMMIT itself fails every request of the batch fails.
 *
 * Reads use a pool of read-only connections, opened on demand and reused (WAL readers never block
 * the writer). Each connection caches its prepared statements, keyed by the SQL literal's address.
 */
#include "store_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define BUSY_TIMEOUT_MS 10000   /* another process (token create) may hold the write lock briefly */

struct write_op {
	write_fn fn;
	after_fn after; /* NULL, or run once the batch's COMMIT has returned */
	void *arg;
	struct api_error *err;
	enum api_code status;
	int done;
	struct write_op *next;
};

int conn_open(struct conn *c, const char *path, int readonly, char *msg, size_t msg_size)
{
	memset(c, 0, sizeof *c);
	int flags = readonly ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
	flags |= SQLITE_OPEN_NOMUTEX;
	if (sqlite3_open_v2(path, &c->db, flags, NULL) != SQLITE_OK) {
		snprintf(msg, msg_size, "cannot open database '%s': %s", path,
			 c->db ? sqlite3_errmsg(c->db) : "out of memory");
		sqlite3_close(c->db);
		c->db = NULL;
		return -1;
	}
	sqlite3_busy_timeout(c->db, BUSY_TIMEOUT_MS);
	const char *setup = readonly ? "PRAGMA foreign_keys=ON"
				     : "PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL; PRAGMA foreign_keys=ON";
	if (sqlite3_exec(c->db, setup, NULL, NULL, NULL) != SQLITE_OK) {
		snprintf(msg, msg_size, "cannot configure database '%s': %s", path, sqlite3_errmsg(c->db));
		sqlite3_close(c->db);
		c->db = NULL;
		return -1;
	}
	return 0;
}

void conn_close(struct conn *c)
{
	for (int i = 0; i < c->count; i++)
		sqlite3_finalize(c->stmt[i]);
	c->count = 0;
	sqlite3_close(c->db);
	c->db = NULL;
}

sqlite3_stmt *conn_stmt(struct conn *c, const char *sql)
{
	for (int i = 0; i < c->count; i++)
		if (c->sql[i] == sql) {
			sqlite3_reset(c->stmt[i]);
			sqlite3_clear_bindings(c->stmt[i]);
			return c->stmt[i];
		}
	sqlite3_stmt *st = NULL;
	if (sqlite3_prepare_v3(c->db, sql, -1, SQLITE_PREPARE_PERSISTENT, &st, NULL) != SQLITE_OK)
		return NULL;
	if (c->count < STMT_CACHE_MAX) {
		c->sql[c->count] = sql;
		c->stmt[c->count++] = st;
	}
	/* A full cache would leak st; STMT_CACHE_MAX exceeds the number of distinct statements. */
	return st;
}

int conn_exec(struct conn *c, const char *sql)
{
	return sqlite3_exec(c->db, sql, NULL, NULL, NULL);
}

enum api_code db_fail(struct conn *c, struct api_error *err, const char *what)
{
	/* Out of memory, a full disk and an I/O error are the server's passing state, not a fault of
	 * the request: 503 (507 for the disk), retry later. The transaction was rolled back, so nothing
	 * was acknowledged, and the next write tries the disk again (docs/hardening.md). */
	int rc = sqlite3_extended_errcode(c->db);
	if ((rc & 0xff) == SQLITE_FULL)
		return api_fail(err, API_INSUFFICIENT_STORAGE, "",
				"the server's disk is full: database error while %s: %s: retry later", what,
				sqlite3_errmsg(c->db));
	if ((rc & 0xff) == SQLITE_IOERR)
		return api_fail(err, API_UNAVAILABLE, "", "the server's storage failed: database error while %s: %s: retry later",
				what, sqlite3_errmsg(c->db));
	enum api_code code = rc == SQLITE_NOMEM ? API_UNAVAILABLE : API_INTERNAL;
	return api_fail(err, code, "", "database error while %s: %s", what, sqlite3_errmsg(c->db));
}

const char *col_text(sqlite3_stmt *st, int i)
{
	return (const char *)sqlite3_column_text(st, i);
}

json_t *col_json_text(sqlite3_stmt *st, int i)
{
	const char *t = col_text(st, i);
	return t ? json_string(t) : json_null();
}

json_t *col_json_int(sqlite3_stmt *st, int i)
{
	if (sqlite3_column_type(st, i) == SQLITE_NULL)
		return json_null();
	return json_integer(sqlite3_column_int64(st, i));
}

json_t *col_json_time(sqlite3_stmt *st, int i)
{
	if (sqlite3_column_type(st, i) == SQLITE_NULL)
		return json_null();
	char text[32];
	format_time(sqlite3_column_int64(st, i), text);
	return json_string(text);
}

/* ---- the writer ---- */

static double seconds_since(const struct timespec *t0)
{
	struct timespec t1;
	clock_gettime(CLOCK_MONOTONIC, &t1);
	return (double)(t1.tv_sec - t0->tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0->tv_nsec);
}

/* The after functions of a batch, last op first: undoing in reverse order puts back what each op
 * found, when two ops of one batch changed the same thing (two versions of one file). */
static void run_after(struct write_op *op)
{
	if (!op)
		return;
	run_after(op->next);
	if (op->after)
		op->after(op->arg, op->status == API_OK);
}

static void run_batch(struct store *s, struct write_op *batch)
{
	struct conn *c = &s->writer;
	struct timespec t0;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	s->wake = 0;
	if (conn_exec(c, "BEGIN IMMEDIATE") != SQLITE_OK) {
		for (struct write_op *op = batch; op; op = op->next)
			op->status = db_fail(c, op->err, "beginning a transaction");
		return;
	}
	for (struct write_op *op = batch; op; op = op->next) {
		if (conn_exec(c, "SAVEPOINT op") != SQLITE_OK) {
			op->status = db_fail(c, op->err, "opening a savepoint");
			continue;
		}
		int mark = store_events_mark(s);
		op->status = op->fn(s, c, op->arg, op->err);
		if (op->status != API_OK) {
			conn_exec(c, "ROLLBACK TO op");
			store_events_rollback(s, mark);
		}
		conn_exec(c, "RELEASE op");
	}
	int committed = conn_exec(c, "COMMIT") == SQLITE_OK;
	if (!committed) {
		struct api_error e = { 0 };
		db_fail(c, &e, "committing");
		conn_exec(c, "ROLLBACK");
		s->wake = 0;
		for (struct write_op *op = batch; op; op = op->next)
			if (op->status == API_OK)
				op->status = api_fail(op->err, e.code, "", "%s", e.message);
	}
	store_events_flush(s, committed);
	run_after(batch);
	if (s->observe_commit)
		s->observe_commit(s->observe_cls, seconds_since(&t0));
}

static void *writer_main(void *arg)
{
	struct store *s = arg;
	int max = s->cfg->group_commit_max > 0 ? s->cfg->group_commit_max : 1;
	pthread_mutex_lock(&s->lock);
	for (;;) {
		while (!s->head && !s->stopping)
			pthread_cond_wait(&s->queue_cv, &s->lock);
		if (!s->head)
			break;
		struct write_op *batch = s->head, *last = s->head;
		for (int n = 1; n < max && last->next; n++)
			last = last->next;
		s->head = last->next;
		if (!s->head)
			s->tail = NULL;
		last->next = NULL;
		pthread_mutex_unlock(&s->lock);

		run_batch(s, batch);
		unsigned wake = s->wake;
		if (s->srv && (wake & WAKE_CLAIMERS))
			server_wake_claimers(s->srv);
		if (s->srv && (wake & WAKE_LOG_READERS))
			server_wake_log_readers(s->srv);

		pthread_mutex_lock(&s->lock);
		/* op->next is read before done is set: the requester frees op once it sees done. */
		for (struct write_op *op = batch, *next; op; op = next) {
			next = op->next;
			op->done = 1;
		}
		pthread_cond_broadcast(&s->done_cv);
	}
	pthread_mutex_unlock(&s->lock);
	return NULL;
}

enum api_code store_write(struct store *s, write_fn fn, void *arg, struct api_error *err)
{
	return store_write_then(s, fn, NULL, arg, err);
}

enum api_code store_write_then(struct store *s, write_fn fn, after_fn after, void *arg, struct api_error *err)
{
	struct write_op op = { .fn = fn, .after = after, .arg = arg, .err = err, .status = API_INTERNAL };
	pthread_mutex_lock(&s->lock);
	if (s->stopping) {
		pthread_mutex_unlock(&s->lock);
		return api_fail(err, API_UNAVAILABLE, "", "server is shutting down");
	}
	if (s->tail)
		s->tail->next = &op;
	else
		s->head = &op;
	s->tail = &op;
	pthread_cond_signal(&s->queue_cv);
	while (!op.done)
		pthread_cond_wait(&s->done_cv, &s->lock);
	pthread_mutex_unlock(&s->lock);
	return op.status;
}

void store_after_commit(struct store *s, unsigned wake)
{
	s->wake |= wake;
}

void store_set_commit_observer(struct store *s, void (*observe)(void *cls, double seconds), void *cls)
{
	s->observe_commit = observe;
	s->observe_cls = cls;
}

/* ---- readers ---- */

struct conn *store_reader(struct store *s, struct api_error *err)
{
	pthread_mutex_lock(&s->lock);
	struct conn *c = s->readers;
	if (c)
		s->readers = c->next;
	pthread_mutex_unlock(&s->lock);
	if (c)
		return c;
	c = malloc(sizeof *c);
	char msg[SERVER_MESSAGE_MAX];
	if (!c || conn_open(c, s->path, 1, msg, sizeof msg) != 0) {
		if (c)
			api_fail(err, API_INTERNAL, "", "%s", msg);
		else
			api_fail(err, API_UNAVAILABLE, "", "out of memory: retry later");
		free(c);
		return NULL;
	}
	return c;
}

void store_reader_done(struct store *s, struct conn *c)
{
	if (!c)
		return;
	if (!sqlite3_get_autocommit(c->db))
		conn_exec(c, "ROLLBACK"); /* ends the read transaction the reader opened */
	pthread_mutex_lock(&s->lock);
	c->next = s->readers;
	s->readers = c;
	pthread_mutex_unlock(&s->lock);
}

int store_ping(struct store *s)
{
	struct api_error err = { 0 };
	struct conn *c = store_reader(s, &err);
	if (!c)
		return -1;
	sqlite3_stmt *st = conn_stmt(c, "SELECT count(*) FROM schema_migrations");
	int ok = st && sqlite3_step(st) == SQLITE_ROW;
	if (st)
		sqlite3_reset(st);
	store_reader_done(s, c);
	return ok ? 0 : -1;
}

/* ---- open and close ---- */

enum api_code store_open(struct store **out, const char *path, const struct server_config *cfg,
			 struct server *srv, struct api_error *err)
{
	*out = NULL;
	struct store *s = calloc(1, sizeof *s);
	if (!s)
		return api_fail(err, API_INTERNAL, "", "out of memory");
	s->cfg = cfg;
	s->srv = srv;
	snprintf(s->path, sizeof s->path, "%s", path);
	char msg[SERVER_MESSAGE_MAX];
	if (conn_open(&s->writer, path, 0, msg, sizeof msg) != 0) {
		free(s);
		return api_fail(err, API_INTERNAL, "", "%s", msg);
	}
	enum api_code rc = migrations_apply(&s->writer, err);
	if (rc == API_OK && store_events_watch(s, msg, sizeof msg) != 0)
		rc = api_fail(err, API_INTERNAL, "", "%s", msg);
	if (rc != API_OK) {
		conn_close(&s->writer);
		free(s);
		return rc;
	}
	pthread_mutex_init(&s->lock, NULL);
	pthread_cond_init(&s->queue_cv, NULL);
	pthread_cond_init(&s->done_cv, NULL);
	if (pthread_create(&s->thread, NULL, writer_main, s) != 0) {
		conn_close(&s->writer);
		free(s);
		return api_fail(err, API_INTERNAL, "", "cannot start the database writer thread");
	}
	*out = s;
	return API_OK;
}

void store_close(struct store **sp)
{
	struct store *s = sp ? *sp : NULL;
	if (!s)
		return;
	pthread_mutex_lock(&s->lock);
	s->stopping = 1;
	pthread_cond_signal(&s->queue_cv);
	pthread_mutex_unlock(&s->lock);
	pthread_join(s->thread, NULL);
	while (s->readers) {
		struct conn *c = s->readers;
		s->readers = c->next;
		conn_close(c);
		free(c);
	}
	/* The last connection to close checkpoints the WAL into the database file. */
	conn_close(&s->writer);
	store_events_release(s);
	pthread_mutex_destroy(&s->lock);
	pthread_cond_destroy(&s->queue_cv);
	pthread_cond_destroy(&s->done_cv);
	free(s);
	*sp = NULL;
}
