/*
 * store.h - the server's SQLite database (docs/service.md §1): jobs, attempts, events, log chunks,
 * the artifact index, users and tokens. SQLite enters poro-server only through store*.c and
 * migrations.c.
 *
 * Writes. One writer thread owns the only read-write connection. Every write function below
 * enqueues a request and blocks until the writer has run it inside a shared BEGIN IMMEDIATE ...
 * COMMIT (group commit, each request in its own SAVEPOINT so a failing one rolls back alone) and
 * COMMIT has returned. The database runs in WAL mode with synchronous=FULL, so when a write
 * function returns API_OK its effect survives kill -9 and power loss: callers may acknowledge.
 *
 * Reads use a pool of read-only connections, one per concurrent reader, opened once and reused.
 *
 * Every function returns API_OK or an error code recorded in err (server.h). JSON results are new
 * references the caller owns (json_decref). Times are milliseconds since the epoch.
 */
#ifndef PORO_STORE_H
#define PORO_STORE_H

#include "server.h"

/* Opens (creating if needed) the database at path, applies pending migrations (migrations.c),
 * refuses a database newer than this binary, and starts the writer thread. Limits come from cfg
 * (default caps, lease, attempts); cfg must outlive the store. srv may be NULL (token create):
 * it is used to wake long-polls after commits. */
enum api_code store_open(struct store **s, const char *path, const struct server_config *cfg,
			 struct server *srv, struct api_error *err);
/* Finishes queued writes, stops the writer, checkpoints and closes every connection; accepts NULL. */
void store_close(struct store **s);
/* 0 when a read of the database works (for /healthz). */
int store_ping(struct store *s);

/* 0 when a write commits: the one row of table health is rewritten through the writer thread
 * (store_health.c, for /healthz); API_INTERNAL with the database's reason otherwise. */
enum api_code store_health_write(struct store *s, struct api_error *err);

/* ---- users and tokens (store_users.c) ---- */
/* A token's last_used_at is rewritten at most this often, so authentication costs a write once a
 * minute per token rather than once a request. */
#define TOKEN_TOUCH_INTERVAL_MS 60000
/* Hex digits of a token's SHA-256 shown as its fingerprint: enough to tell tokens apart, far too
 * few to look one up. */
#define TOKEN_FINGERPRINT_HEX 8
/* The principal owning a token, by the token's SHA-256 hex. API_UNAUTHORIZED when unknown or
 * revoked (read on every request: a revocation holds from the next request on). */
enum api_code store_auth(struct store *s, const char *token_sha256, struct principal *who, struct api_error *err);
/* The same check with reads only (never a write, so it never waits on the disk): for the front
 * door, which must not stall every connection behind one fsync. */
enum api_code store_auth_peek(struct store *s, const char *token_sha256, struct principal *who,
			      struct api_error *err);
/* Creates a user; max_queued / max_running < 0 mean "the server default". API_ALREADY_EXISTS. */
enum api_code store_user_create(struct store *s, const char *name, enum role role, int max_queued,
				int max_running, json_t **user, struct api_error *err);
/* Stores a token hash for a user, with an optional label (NULL for none); with create_role > 0
 * the user is created first if missing. *token (may be NULL) gets the token as listed. */
enum api_code store_token_add(struct store *s, const char *user, int create_role, const char *token_sha256,
			      const char *label, json_t **token, struct api_error *err);
/* Tokens newest first, as {"tokens": [{"id", "user", "role", "label", "created_at", "last_used_at",
 * "revoked_at", "fingerprint"}], "next_after": ID or null}: every token for an admin or for who ==
 * NULL (the offline `poro-server token list`), else the principal's own. after = 0 for the first
 * page. Neither the token nor its whole hash is ever part of the answer. */
enum api_code store_token_list(struct store *s, const struct principal *who, int limit, long long after,
			       json_t **page, struct api_error *err);
/* Revokes token id (admin, who == NULL, or the token's own user; another user's token is
 * API_NOT_FOUND, as a missing one); revoking a revoked token changes nothing. *token gets it. */
enum api_code store_token_revoke(struct store *s, const struct principal *who, long long id, json_t **token,
				 struct api_error *err);

/* ---- jobs, user side (store_jobs.c) ---- */
struct job_submit {
	const struct principal *who;
	const char *idempotency_key;  /* or NULL */
	const char *body_sha256;      /* canonical request body, for the idempotency comparison */
	const char *case_json;        /* canonical case text */
	const char *case_sha256;
	const char *name;             /* or NULL */
	const char *case_title;       /* the case's "title", or NULL */
	int priority, threads, wall_time_seconds;
	long long memory_mb;          /* memory the job needs, MB; 0: not stated */
	const char *batch;            /* the benchmark run's label, or NULL (jobs_submit.h) */
	int exclusive;                /* 1: runs alone on its worker */
};
/* Stores a queued job and its "submitted" event. *created is 1 for a new job, 0 when the
 * idempotency key returned an existing one. API_IDEMPOTENCY_CONFLICT; API_QUOTA_EXCEEDED when the
 * user has its cap of queued jobs, or when the case text would take the user's stored bytes past
 * its quota (users.max_stored_bytes, else cfg->user_max_stored_bytes; 0 = none). */
enum api_code store_job_submit(struct store *s, const struct job_submit *in, json_t **job, int *created,
			       struct api_error *err);
/* A job the principal may see (its own; every job for admins), with files and events when full. */
enum api_code store_job_get(struct store *s, const struct principal *who, long long id, int full, json_t **job,
			    struct api_error *err);
/* Newest first; states is a bit mask of JOB_STATE_* (0 = all); after = 0 for the first page. Every
 * combination is an index range scan that stops after limit + 1 rows, without a sort. */
enum api_code store_job_list(struct store *s, const struct principal *who, unsigned states, int limit,
			     long long after, json_t **page, struct api_error *err);
/* The dashboard's search (store_search.c): the filters of GET /v1/jobs beyond state, limit and
 * after. Strings are NULL when not given; times are ms since the epoch, 0 when not given. */
struct job_search {
	unsigned states;              /* JOB_STATE_* bit mask, 0 = all */
	const char *user;             /* the owner's name (admins; a user sees only its own jobs) */
	const char *name;             /* a substring of the job's name, any case */
	const char *title;            /* a substring of the case's title, any case */
	long long created_from, created_to; /* created_at in [from, to], ms */
	int oldest_first;             /* 1: ascending ids (after = the last id of the previous page) */
	int limit;
	long long after;
};
/* A page of jobs by a search, as store_job_list's; each page reads one covering index range
 * (jobs_user_search for a user, jobs_search for an admin's search of every user), the filters
 * evaluated on index entries, so a job's case text is never read for a row that is not shown. */
enum api_code store_job_search(struct store *s, const struct principal *who, const struct job_search *q,
			       json_t **page, struct api_error *err);
/* The case text of a job the principal may see, as stored (canonical JSON); the caller frees it. */
enum api_code store_job_case(struct store *s, const struct principal *who, long long id, char **text,
			     struct api_error *err);
/* For the admin view: {"running": [job...]} the running jobs, and "queue": [{"user", "queued",
 * "running", "max_queued", "max_running"}] the users with queued or running jobs. */
enum api_code store_admin_overview(struct store *s, json_t **out, struct api_error *err);
/* Cancels a queued job now, or requests cancel of a running one. API_NOT_CANCELLABLE. */
enum api_code store_job_cancel(struct store *s, const struct principal *who, long long id, json_t **job,
			       struct api_error *err);
/* What deleting a job freed: its stored bytes (case, log text, files) and the rows removed. */
struct job_freed {
	long long bytes, files, log_chunks, events, idempotency_keys;
};
/* Deletes a job in a terminal state with its log, file index rows, idempotency keys and events,
 * and subtracts its bytes from its owner's (store_delete.c). The caller removes the files on disk
 * after this returns API_OK. API_NOT_FOUND (also for another user's job), API_NOT_DELETABLE for a
 * queued or running job. */
enum api_code store_job_delete(struct store *s, const struct principal *who, long long id, struct job_freed *freed,
			       struct api_error *err);
/* 1 when a job with this id exists, 0 when not, -1 when the database cannot say. */
int store_job_exists(struct store *s, long long id);

/* What listings cost, summed over every store_job_list since start: SQLite VM steps, steps of
 * full table scans and sorts (sqlite3_stmt_status), for /metrics. */
struct list_stats {
	unsigned long long requests, vm_steps, fullscan_steps, sorts;
};
void store_list_stats(struct store *s, struct list_stats *out);

/* Sets a user's own cap on stored bytes (< 0: back to the server default). API_INVALID_REQUEST for
 * an unknown user. */
enum api_code store_user_set_max_stored(struct store *s, const char *name, long long max_stored_bytes,
					struct api_error *err);

#define JOB_STATE_MAP(X) X(QUEUED, "queued") X(RUNNING, "running") X(SUCCEEDED, "succeeded") \
	X(FAILED, "failed") X(CANCELLED, "cancelled")
enum job_state {
#define JOB_STATE_ENUM(c, n) JOB_##c,
	JOB_STATE_MAP(JOB_STATE_ENUM)
#undef JOB_STATE_ENUM
	JOB_STATE_COUNT
};
const char *job_state_name(enum job_state st);
int job_state_parse(const char *name, enum job_state *st);   /* 0, or -1 */
/* Jobs per state, for /metrics (kept as counters: no scan). */
enum api_code store_job_counts(struct store *s, long long counts[JOB_STATE_COUNT], struct api_error *err);

/* ---- jobs, worker side (store_worker.c) ----
 * A lease is (job, attempt) held by one worker token's user (who). Every worker write checks it
 * in the writer thread: a job that is not running, or whose attempt is another, is
 * API_STALE_ATTEMPT; a job leased by another worker user, or missing, is API_NOT_FOUND. */
struct job_claim {
	const struct principal *who;
	const char *worker, *host;
	int exclusive_ok;             /* the worker runs nothing now: it may take an exclusive job */
	long long seconds_left;       /* only jobs whose wall_time_seconds fit this (a pilot's allocation); -1: any */
	long long max_threads;        /* only jobs asking for at most this many threads; 0: any */
	long long max_memory_mb;      /* only jobs asking for at most this much memory, MB; 0: any */
	long long claim_latency_ms;   /* out: submit (or requeue) to claim */
};
/* Leases the next job by fair share (docs/service.md §2) among those that fit in->seconds_left,
 * in->max_threads and in->max_memory_mb, leaving exclusive jobs to claims with exclusive_ok;
 * *job is NULL when none is claimable. */
enum api_code store_claim(struct store *s, struct job_claim *in, json_t **job, struct api_error *err);
/* Renews the lease of (id, attempt); progress (object or NULL) and solver_version (or NULL) are
 * recorded. *cancel is 1 when a cancel was requested. */
enum api_code store_heartbeat(struct store *s, const struct principal *who, long long id, int attempt,
			      json_t *progress, const char *solver_version, int *cancel, long long *lease_expires_ms,
			      struct api_error *err);
/* Appends text at offset of (id, attempt)'s log; idempotent by offset; API_LOG_GAP. When the
 * attempt's stored text would exceed cfg->max_log_bytes, the chunks between its first and last
 * half are deleted in the same write (store_worker.c says how). API_TOO_LARGE for a chunk over
 * 1 MiB. */
enum api_code store_log_append(struct store *s, const struct principal *who, long long id, int attempt,
			       long long offset, const char *text, size_t size, long long *next_offset,
			       struct api_error *err);
/* An attempt's log as it stands: the attempt (a negative one asked for means the job's current
 * attempt), whether it is still live, its end offset (the bytes ever appended) and the range
 * [dropped_from, dropped_to) whose chunks were dropped (equal when none). */
struct log_info {
	int attempt, live;
	long long end, dropped_from, dropped_to;
};
/* API_NOT_FOUND for a missing job; visibility is the caller's check. */
enum api_code store_log_info(struct store *s, long long id, int attempt, struct log_info *info,
			     struct api_error *err);
/* A piece of stored log text: text[0..size) holds the bytes from offset at on, where at is the
 * offset asked for, or the start of the next stored chunk when that offset was dropped (so at >
 * the offset asked for says "bytes offset..at were dropped"). The buffer (text, cap) belongs to
 * the caller, is reused by the next read and freed by log_block_release. */
struct log_block {
	char *text;
	size_t size, cap;
	long long at;
	long long end;                /* the attempt's end offset at the time of the read */
	int live;                     /* the attempt was still live at the time of the read */
};
/* Reads contiguous text of (id, attempt >= 1) from offset, stopping before offset until (< 0: no
 * limit), at a dropped range, or once about max bytes are read (whole chunks: at most max plus
 * one chunk, since a chunk is never split across reads). One read connection of the pool, taken
 * and given back within the call. */
enum api_code store_log_read(struct store *s, long long id, int attempt, long long offset, long long until,
			     size_t max, struct log_block *b, struct api_error *err);
void log_block_release(struct log_block *b);
/* Read-only lease check before an upload starts; attempt < 0 accepts the current attempt. */
enum api_code store_lease_check(struct store *s, const struct principal *who, long long id, int attempt,
				int *current_attempt, struct api_error *err);
/* Renames tmp_path to final_path and indexes the file, in one write, only if (id, attempt) still
 * holds the lease; the rename happens in the writer so a stale attempt can never replace a file.
 * When the write fails, before or at its COMMIT, the file at final_path is the one the index
 * still describes (the old version is kept until the new row is durable, file_replace.h).
 * The file's size counts towards its job's and owner's stored bytes (a new version of the same
 * name and attempt replaces the old one's size). */
enum api_code store_file_commit(struct store *s, const struct principal *who, long long id, int attempt,
				const char *name, long long size, const char *sha256, const char *tmp_path,
				const char *final_path, struct api_error *err);
/* The newest indexed version of a file of a job with attempt <= max_attempt (any when < 0). */
enum api_code store_file_find(struct store *s, long long id, const char *name, int max_attempt, int *attempt,
			      long long *size, char sha256[65], struct api_error *err);
/* A file a finishing worker declares it stored for the attempt. */
struct finish_artifact {
	const char *name;
	long long size;             /* bytes */
	const char *sha256;         /* 64 lower-case hex digits */
};
/* Ends (id, attempt) with outcome succeeded | failed | cancelled | infrastructure; exit_code < 0
 * for none. *duration_ms gets claim-to-finish time. "succeeded" needs result.h5 among the declared
 * artifacts and every one indexed for (id, attempt) with its size and SHA-256: else
 * API_ARTIFACT_MISSING naming the first that is not, and nothing changes. */
enum api_code store_finish(struct store *s, const struct principal *who, long long id, int attempt,
			   const char *worker, const char *outcome, const char *message, int exit_code,
			   const char *solver_version, const struct finish_artifact *artifacts, int artifact_count,
			   json_t **job, long long *duration_ms, struct api_error *err);

/* Reaper (once a second): expired leases back to queued (or failed / cancelled), wall-time
 * overruns failed. Counts what it did. */
struct reap_counts { int expired, retried, lost, cancelled, overrun; };
enum api_code store_reap(struct store *s, struct reap_counts *counts, struct api_error *err);

/* ---- benchmark runs (store_bench.c; bench.h says what they are) ----
 * A run as JSON: {"id", "suite", "label", "commit", "user", "client_host", "state", "solver_version",
 * "machine", "fingerprint", "summary", "created_at", "finished_at"} and, when full, "settings",
 * "cases" (the plan's) and "figures" (one row each once finished: {"figure", "case", "kind",
 * "class", "check", "unit", "case_sha256", "machine", "samples", "median", "band", "status",
 * "detail", "stats"}). Every user may read every run: they are about the solver, not a user's
 * work. */
/* Stores a new running run; API_ALREADY_EXISTS when its label is taken. */
enum api_code store_bench_create(struct store *s, const struct principal *who, const char *suite, const char *label,
				 const char *commit, const char *host, const json_t *plan, json_t **run,
				 struct api_error *err);
/* A run (full: with its plan and figures); *owner (may be NULL) its user's id. API_NOT_FOUND. */
enum api_code store_bench_get(struct store *s, long long id, int full, json_t **run, long long *owner,
			      struct api_error *err);
/* Runs newest first, of one suite or (suite NULL) all: {"runs": [...], "next_after": ID or null}. */
enum api_code store_bench_list(struct store *s, const char *suite, int limit, long long after, json_t **page,
			       struct api_error *err);
/* The latest limit rows of a figure in a suite, on one machine fingerprint (NULL: every machine),
 * oldest first: [{"run", "label", "commit", "created_at", "solver_version", "machine", "samples",
 * "median", "status", "band"}]. */
enum api_code store_bench_series(struct store *s, const char *suite, const char *figure, const char *fingerprint,
				 int limit, json_t **points, struct api_error *err);
/* A timing figure's history: the samples of figure in suite on fingerprint for the same case text,
 * from the latest `runs` runs before run before_id that measured it (*samples malloc'd, *count
 * values from *run_count runs). */
enum api_code store_bench_history(struct store *s, const char *suite, const char *figure, const char *fingerprint,
				  const char *case_sha256, long long before_id, int runs, double **samples, int *count,
				  int *run_count, struct api_error *err);
/* Ends a running run with result {"state", "solver_version", "machine", "fingerprint", "summary",
 * "figures": [rows as above]}; a run that is no longer running is left as it is (*changed 0). */
enum api_code store_bench_finish(struct store *s, long long id, const json_t *result, int *changed,
				 struct api_error *err);

/* Seconds of writer transactions, for the poro_commit_seconds histogram (set by the writer). */
void store_set_commit_observer(struct store *s, void (*observe)(void *cls, double seconds), void *cls);

#endif
