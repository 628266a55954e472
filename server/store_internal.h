/*
 * store_internal.h - what the store*.c files and migrations.c share: connections with a cache of
 * prepared statements, the write-request plumbing of the writer thread, and small SQL helpers.
 * Private to the store; nothing outside store*.c and migrations.c includes sqlite3.h.
 *
 * A write operation is a function run by the writer thread inside the group transaction (within
 * its own SAVEPOINT); it returns API_OK or an error recorded in its struct api_error, and then
 * its changes are rolled back alone. It may call store_after_commit() to ask for wake-ups that
 * happen only once the transaction is durable.
 */
#ifndef PORO_STORE_INTERNAL_H
#define PORO_STORE_INTERNAL_H

#include <sqlite3.h>

#include "store.h"

#define STMT_CACHE_MAX 128

struct conn {
	sqlite3 *db;
	int count;
	const char *sql[STMT_CACHE_MAX];      /* keys: static SQL text, compared by address */
	sqlite3_stmt *stmt[STMT_CACHE_MAX];
	struct conn *next;                    /* free list of the read pool */
};

enum { WAKE_CLAIMERS = 1, WAKE_LOG_READERS = 2 };

struct store {
	const struct server_config *cfg;
	struct server *srv;
	struct conn writer;                   /* used by the writer thread only */
	char path[SERVER_PATH_MAX];

	pthread_mutex_t lock;                 /* queue, done flags, read pool */
	pthread_cond_t queue_cv;              /* writer waits for work */
	pthread_cond_t done_cv;               /* requesters wait for their commit */
	struct write_op *head, *tail;
	int stopping;
	pthread_t thread;
	struct conn *readers;                 /* idle read connections */
	unsigned wake;                        /* WAKE_* asked by the running batch */

	void (*observe_commit)(void *cls, double seconds);
	void *observe_cls;

	struct list_stats list;               /* under lock: the cost of listings (store_job_list) */

	/* events rows written by the running batch, logged once it commits (store_events.c);
	 * the writer thread's alone */
	struct event_note *notes;
	int note_count, note_cap, notes_lost;
};

typedef enum api_code (*write_fn)(struct store *s, struct conn *c, void *arg, struct api_error *err);

/* Runs fn(arg) in the writer's group transaction and returns after COMMIT (or the error). */
enum api_code store_write(struct store *s, write_fn fn, void *arg, struct api_error *err);
/* After the batch's COMMIT has returned, on the writer thread and before the next batch:
 * committed is 1 when fn's changes are durable, 0 when they were rolled back (fn failed, or the
 * COMMIT did). For what fn did outside the database and must undo or finish. */
typedef void (*after_fn)(void *arg, int committed);
/* store_write, then after(arg, committed) (see after_fn) before returning. */
enum api_code store_write_then(struct store *s, write_fn fn, after_fn after, void *arg, struct api_error *err);
/* Asks for wake-ups after the current batch commits (writer thread only). */
void store_after_commit(struct store *s, unsigned wake);

/* Read connections from the pool; every reader returns its connection. NULL with err set on failure. */
struct conn *store_reader(struct store *s, struct api_error *err);
void store_reader_done(struct store *s, struct conn *c);

/* The cached statement for sql (a string literal), reset and with bindings cleared. */
sqlite3_stmt *conn_stmt(struct conn *c, const char *sql);
/* Executes SQL without results; SQLITE_OK or the error code. */
int conn_exec(struct conn *c, const char *sql);
/* Records a database failure as API_INTERNAL naming what was being done. */
enum api_code db_fail(struct conn *c, struct api_error *err, const char *what);
/* Opens and configures a connection (WAL, synchronous=FULL, busy timeout). */
int conn_open(struct conn *c, const char *path, int readonly, char *msg, size_t msg_size);
void conn_close(struct conn *c);

/* The log line of every events row (store_events.c). watch installs, on the writer's connection,
 * the TEMP trigger that notes each row (0, or -1 with msg set); mark is taken before a write
 * runs and rollback drops the notes after it when the write is rolled back; flush logs the
 * batch's notes when it committed, drops them when not; release frees them (store_close). */
int store_events_watch(struct store *s, char *msg, size_t msg_size);
int store_events_mark(const struct store *s);
void store_events_rollback(struct store *s, int mark);
void store_events_flush(struct store *s, int committed);
void store_events_release(struct store *s);

/* Migrations (migrations.c): applies every migration newer than the database's version in one
 * transaction; refuses a database newer than the binary. */
enum api_code migrations_apply(struct conn *c, struct api_error *err);

/* Text of a column, or NULL. */
const char *col_text(sqlite3_stmt *st, int i);
/* A column as JSON: string or null / integer or null / time (RFC 3339) or null. */
json_t *col_json_text(sqlite3_stmt *st, int i);
json_t *col_json_int(sqlite3_stmt *st, int i);
json_t *col_json_time(sqlite3_stmt *st, int i);

/* ---- shared job helpers (store_jobs.c) ---- */
/* SELECT list of a job row for job_from_row(), joined as "FROM jobs j JOIN users u ON u.id = j.user_id". */
#define JOB_COLUMNS "j.id, u.name, j.name, j.state, j.priority, j.threads, j.wall_time_seconds, j.attempt, " \
	"j.created_at, j.started_at, j.finished_at, j.case_sha256, j.solver_version, j.worker_host, " \
	"j.progress, j.message, j.cancel_requested, j.user_id, j.not_before, u.running, u.max_running, " \
	"j.batch, j.exclusive, j.case_title, j.memory_mb "
/* The job of a row of JOB_COLUMNS as JSON; s gives what "waiting" needs besides the row (the
 * default cap on running jobs, whether a worker is live). */
json_t *job_from_row(struct store *s, sqlite3_stmt *st);
/* The job as JSON (full: with files and events), read through c; NULL with err set if missing. */
json_t *job_load(struct store *s, struct conn *c, long long id, int full, struct api_error *err);
/* Moves a job from one state to another: updates the job, the owner's counters and writes the
 * event row (actor, attempt, detail). The caller has checked that the job is in `from`. */
enum api_code job_transition(struct conn *c, long long id, enum job_state from, enum job_state to, int attempt,
			     const char *actor, const char *detail, struct api_error *err);
/* Writes an event without a state change (e.g. cancel requested). */
enum api_code job_event(struct conn *c, long long id, enum job_state from, enum job_state to, int attempt,
			const char *actor, const char *detail, struct api_error *err);


/* ---- stored bytes (store_quota.c) ---- */
/* Adds delta bytes (negative: freed) to a job's stored_bytes and to its owner's. */
enum api_code stored_bytes_add(struct conn *c, long long job_id, long long delta, struct api_error *err);
/* API_QUOTA_EXCEEDED when adding bytes to user's stored bytes would pass its quota. */
enum api_code stored_quota_check(struct store *s, struct conn *c, long long user, long long bytes,
				 struct api_error *err);

/* ---- shared lease helpers (store_worker.c) ---- */
/* API_OK when (id, attempt) is the running lease held by who (attempt < 0: any current attempt);
 * *cancel gets cancel_requested and *started the claim time (either may be NULL). */
enum api_code lease_live(struct conn *c, const struct principal *who, long long id, int attempt, int *cancel,
			 long long *started, struct api_error *err);
/* Steps a statement that returns no rows and resets it. */
enum api_code step_done(struct conn *c, sqlite3_stmt *st, struct api_error *err, const char *what);
/* Infrastructure failure of (id, attempt) by actor: back to queued after the capped backoff, or
 * failed as lost when no attempts are left. *retried says which. */
enum api_code requeue_or_fail(struct store *s, struct conn *c, long long id, int attempt, const char *actor,
			      const char *why, int *retried, struct api_error *err);

#endif
