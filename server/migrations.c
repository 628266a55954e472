/*
 * migrations.c - the versioned database schema of poro-server.
 *
 * MIGRATIONS is an ordered list; migration i (1-based) brings the schema from version i - 1 to i.
 * The table schema_migrations records each applied version with its time. On open, every
 * migration newer than the database is applied in one transaction, so a crash mid-way leaves the
 * old version intact. A database whose version is newer than the binary knows is refused: an old
 * binary must not write into a schema it does not understand. Append new migrations at the end;
 * never edit one that has shipped.
 *
 * Times are milliseconds since the epoch (INTEGER). users.queued and users.running are counters
 * kept by job_transition() (store_jobs.c) so that quota checks and fair share need no scans;
 * job_counts (per state), jobs.stored_bytes and users.stored_bytes (store_quota.c) and
 * log_attempts (store_worker.c) are kept the same way, in the writes that change what they count.
 */
#include "store_internal.h"

#include <stdio.h>

static const char *const MIGRATIONS[] = {
	/* 1: users, tokens, jobs, events, idempotency keys, log chunks, file index */
	"CREATE TABLE users ("
	"  id INTEGER PRIMARY KEY,"
	"  name TEXT NOT NULL UNIQUE,"
	"  role TEXT NOT NULL CHECK (role IN ('user', 'worker', 'admin')),"
	"  max_queued INTEGER,"            /* NULL: the server default */
	"  max_running INTEGER,"
	"  queued INTEGER NOT NULL DEFAULT 0,"
	"  running INTEGER NOT NULL DEFAULT 0,"
	"  last_claim_seq INTEGER NOT NULL DEFAULT 0," /* round robin among users with equal running */
	"  created_at INTEGER NOT NULL);"
	"CREATE TABLE tokens ("
	"  sha256 TEXT PRIMARY KEY,"
	"  user_id INTEGER NOT NULL REFERENCES users(id),"
	"  created_at INTEGER NOT NULL) WITHOUT ROWID;"
	"CREATE TABLE jobs ("
	"  id INTEGER PRIMARY KEY,"
	"  user_id INTEGER NOT NULL REFERENCES users(id),"
	"  name TEXT,"
	"  state TEXT NOT NULL,"
	"  priority INTEGER NOT NULL,"
	"  threads INTEGER NOT NULL,"
	"  wall_time_seconds INTEGER NOT NULL,"
	"  attempt INTEGER NOT NULL DEFAULT 0,"
	"  case_json TEXT NOT NULL,"
	"  case_sha256 TEXT NOT NULL,"
	"  created_at INTEGER NOT NULL,"
	"  queued_at INTEGER NOT NULL,"      /* last time it entered queued, for claim latency */
	"  not_before INTEGER NOT NULL DEFAULT 0,"
	"  started_at INTEGER,"              /* claim of the current attempt */
	"  finished_at INTEGER,"
	"  lease_expires_at INTEGER,"
	"  worker TEXT,"                     /* worker id ("host:pid") of the current lease */
	"  lease_user_id INTEGER,"           /* the worker token's user holding the lease */
	"  worker_host TEXT,"
	"  solver_version TEXT,"
	"  progress TEXT,"
	"  message TEXT,"
	"  exit_code INTEGER,"
	"  cancel_requested INTEGER NOT NULL DEFAULT 0);"
	"CREATE INDEX jobs_claim ON jobs (user_id, state, priority DESC, id);"
	"CREATE INDEX jobs_state ON jobs (state, lease_expires_at);"
	"CREATE TABLE events ("
	"  id INTEGER PRIMARY KEY,"
	"  job_id INTEGER NOT NULL REFERENCES jobs(id),"
	"  at INTEGER NOT NULL,"
	"  from_state TEXT,"
	"  to_state TEXT NOT NULL,"
	"  attempt INTEGER NOT NULL,"
	"  actor TEXT NOT NULL,"
	"  detail TEXT);"
	"CREATE INDEX events_job ON events (job_id, id);"
	"CREATE TABLE idempotency ("
	"  user_id INTEGER NOT NULL,"
	"  key TEXT NOT NULL,"
	"  body_sha256 TEXT NOT NULL,"
	"  job_id INTEGER NOT NULL REFERENCES jobs(id),"
	"  PRIMARY KEY (user_id, key)) WITHOUT ROWID;"
	"CREATE TABLE log_chunks ("
	"  job_id INTEGER NOT NULL REFERENCES jobs(id),"
	"  attempt INTEGER NOT NULL,"
	"  offset INTEGER NOT NULL,"
	"  text BLOB NOT NULL,"
	"  PRIMARY KEY (job_id, attempt, offset)) WITHOUT ROWID;"
	"CREATE TABLE files ("
	"  job_id INTEGER NOT NULL REFERENCES jobs(id),"
	"  attempt INTEGER NOT NULL,"
	"  name TEXT NOT NULL,"
	"  size INTEGER NOT NULL,"
	"  sha256 TEXT NOT NULL,"
	"  created_at INTEGER NOT NULL,"
	"  PRIMARY KEY (job_id, name, attempt)) WITHOUT ROWID;",

	/* 2: listing at any depth and size (an index per listing shape, so every page is a range
	 * scan), the log cap's bookkeeping per attempt, stored bytes per job and user with an
	 * optional per-user quota, job counts per state for /metrics, an index to delete a job's
	 * idempotency keys, and job ids that are never reused once a job is deleted */
	"CREATE INDEX jobs_user ON jobs (user_id, id);"
	"CREATE INDEX jobs_user_state ON jobs (user_id, state, id);"
	"CREATE INDEX jobs_state_id ON jobs (state, id);"
	"CREATE INDEX idempotency_job ON idempotency (job_id);"
	"CREATE TABLE log_attempts ("
	"  job_id INTEGER NOT NULL REFERENCES jobs(id),"
	"  attempt INTEGER NOT NULL,"
	"  end_offset INTEGER NOT NULL,"     /* just past the last byte appended: the next chunk's offset */
	"  dropped_from INTEGER NOT NULL DEFAULT 0," /* chunks in [dropped_from, dropped_to) were deleted */
	"  dropped_to INTEGER NOT NULL DEFAULT 0,"
	"  PRIMARY KEY (job_id, attempt)) WITHOUT ROWID;"
	"INSERT INTO log_attempts (job_id, attempt, end_offset)"
	"  SELECT job_id, attempt, max(offset + length(text)) FROM log_chunks GROUP BY job_id, attempt;"
	"ALTER TABLE users ADD COLUMN stored_bytes INTEGER NOT NULL DEFAULT 0;"
	"ALTER TABLE users ADD COLUMN max_stored_bytes INTEGER;" /* NULL: the server default */
	"ALTER TABLE jobs ADD COLUMN stored_bytes INTEGER NOT NULL DEFAULT 0;" /* case + log + files */
	"UPDATE jobs SET stored_bytes = length(CAST(case_json AS BLOB))"
	"  + coalesce((SELECT sum(length(l.text)) FROM log_chunks l WHERE l.job_id = jobs.id), 0)"
	"  + coalesce((SELECT sum(f.size) FROM files f WHERE f.job_id = jobs.id), 0);"
	"UPDATE users SET stored_bytes = coalesce((SELECT sum(j.stored_bytes) FROM jobs j WHERE j.user_id = users.id), 0);"
	"CREATE TABLE job_counts (state TEXT PRIMARY KEY, jobs INTEGER NOT NULL) WITHOUT ROWID;"
	"INSERT INTO job_counts (state, jobs) SELECT s.state, (SELECT count(*) FROM jobs j WHERE j.state = s.state)"
	"  FROM (SELECT 'queued' AS state UNION ALL SELECT 'running' UNION ALL SELECT 'succeeded'"
	"        UNION ALL SELECT 'failed' UNION ALL SELECT 'cancelled') s;"
	"CREATE TABLE counters (name TEXT PRIMARY KEY, value INTEGER NOT NULL) WITHOUT ROWID;"
	"INSERT INTO counters (name, value) VALUES ('job_id', coalesce((SELECT max(id) FROM jobs), 0));",

	/* 3: tokens get an integer id (what listing shows and revoking names; the token itself is
	 * never shown again), last_used_at (updated at most once a minute per token), revoked_at (a
	 * revoked token is refused on its next request) and an optional label; the SHA-256 stays the
	 * lookup key (now a unique index). The one-row table health is what /healthz rewrites to prove
	 * that a write still commits; writes counts those rewrites. */
	"CREATE TABLE tokens_v2 ("
	"  id INTEGER PRIMARY KEY,"
	"  sha256 TEXT NOT NULL UNIQUE,"
	"  user_id INTEGER NOT NULL REFERENCES users(id),"
	"  label TEXT,"
	"  created_at INTEGER NOT NULL,"
	"  last_used_at INTEGER,"
	"  revoked_at INTEGER);"
	"INSERT INTO tokens_v2 (sha256, user_id, created_at)"
	"  SELECT sha256, user_id, created_at FROM tokens ORDER BY created_at, sha256;"
	"DROP TABLE tokens;"
	"ALTER TABLE tokens_v2 RENAME TO tokens;"
	"CREATE INDEX tokens_user ON tokens (user_id, id);"
	"CREATE TABLE health ("
	"  id INTEGER PRIMARY KEY CHECK (id = 1),"
	"  checked_at INTEGER NOT NULL,"
	"  writes INTEGER NOT NULL);",

	/* 4: benchmark nightlies (docs/benchmarks.md). A job may carry the label of the benchmark run
	 * it belongs to (batch) and ask to run alone on its worker (exclusive). A benchmark run is
	 * the plan its client submitted (cases, their jobs, each figure's check) and, once finished,
	 * one row per figure: the samples its jobs reported, the machine fingerprint they were
	 * measured on, and the verdict. benchmark_figures carries the suite, so that a figure's
	 * series on one machine, and a timing figure's history, is one range of benchmark_series. */
	"ALTER TABLE jobs ADD COLUMN batch TEXT;"
	"ALTER TABLE jobs ADD COLUMN exclusive INTEGER NOT NULL DEFAULT 0;"
	"CREATE INDEX jobs_batch ON jobs (batch, id) WHERE batch IS NOT NULL;"
	"CREATE TABLE benchmark_runs ("
	"  id INTEGER PRIMARY KEY,"
	"  user_id INTEGER NOT NULL REFERENCES users(id),"
	"  suite TEXT NOT NULL,"
	"  label TEXT NOT NULL UNIQUE,"          /* the batch label of its jobs */
	"  commit_id TEXT NOT NULL,"             /* git describe of the submitting checkout */
	"  client_host TEXT,"
	"  solver_version TEXT,"                 /* what the jobs reported */
	"  machine TEXT,"                        /* JSON: the machine of its timings */
	"  fingerprint TEXT,"
	"  state TEXT NOT NULL CHECK (state IN ('running', 'passed', 'regressed', 'failed')),"
	"  plan TEXT NOT NULL,"                  /* JSON, as checked at creation */
	"  summary TEXT,"                        /* JSON: figures per verdict */
	"  created_at INTEGER NOT NULL,"
	"  finished_at INTEGER);"
	"CREATE INDEX benchmark_runs_suite ON benchmark_runs (suite, id);"
	"CREATE TABLE benchmark_figures ("
	"  run_id INTEGER NOT NULL REFERENCES benchmark_runs(id),"
	"  figure TEXT NOT NULL,"                /* CASE/KIND */
	"  suite TEXT NOT NULL,"
	"  kind TEXT NOT NULL,"
	"  class TEXT NOT NULL,"                 /* accuracy | timing | count */
	"  check_kind TEXT NOT NULL,"            /* band | history | none */
	"  unit TEXT NOT NULL,"
	"  case_sha256 TEXT,"
	"  fingerprint TEXT,"                    /* of the machine its samples were measured on */
	"  samples TEXT NOT NULL,"               /* JSON array of numbers */
	"  median REAL,"
	"  band_min REAL,"
	"  band_max REAL,"
	"  status TEXT NOT NULL,"                /* regression.h's verdicts */
	"  detail TEXT,"
	"  stats TEXT,"                          /* JSON: the rank test's figures */
	"  PRIMARY KEY (run_id, figure)) WITHOUT ROWID;"
	"CREATE INDEX benchmark_series ON benchmark_figures (suite, figure, fingerprint, run_id);",
	/* 5: the dashboard's job search (store_search.c): the case's title beside the job, kept at
	 * submission, and two covering indexes, so that a filter on state, dates, the job's name or
	 * the case's title reads index entries alone, never a job's case text */
	"ALTER TABLE jobs ADD COLUMN case_title TEXT;"
	"UPDATE jobs SET case_title = json_extract(case_json, '$.title') WHERE json_valid(case_json);"
	"CREATE INDEX jobs_user_search ON jobs (user_id, id, state, created_at, name, case_title);"
	"CREATE INDEX jobs_search ON jobs (id, state, created_at, user_id, name, case_title);",
	/* 6: the memory a job needs, MB (docs/service.md, "Memory"): a claim that states the memory
	 * its solver may use (max_memory_mb) is given only jobs that fit. 0 is "not stated", what
	 * every job stored before asked for, so they stay claimable by any worker as before. No
	 * index: the claim reads it from the rows its indexes already find. */
	"ALTER TABLE jobs ADD COLUMN memory_mb INTEGER NOT NULL DEFAULT 0;",
};

#define MIGRATION_COUNT ((int)(sizeof MIGRATIONS / sizeof MIGRATIONS[0]))

static enum api_code current_version(struct conn *c, int *version, struct api_error *err)
{
	if (conn_exec(c, "CREATE TABLE IF NOT EXISTS schema_migrations ("
			 " version INTEGER PRIMARY KEY, applied_at INTEGER NOT NULL)") != SQLITE_OK)
		return db_fail(c, err, "creating schema_migrations");
	sqlite3_stmt *st = NULL;
	if (sqlite3_prepare_v2(c->db, "SELECT coalesce(max(version), 0) FROM schema_migrations", -1, &st, NULL)
	    != SQLITE_OK)
		return db_fail(c, err, "reading the schema version");
	int rc = sqlite3_step(st);
	*version = rc == SQLITE_ROW ? sqlite3_column_int(st, 0) : -1;
	sqlite3_finalize(st);
	if (*version < 0)
		return db_fail(c, err, "reading the schema version");
	return API_OK;
}

enum api_code migrations_apply(struct conn *c, struct api_error *err)
{
	if (conn_exec(c, "BEGIN IMMEDIATE") != SQLITE_OK)
		return db_fail(c, err, "locking the database for migrations");
	int version = 0;
	enum api_code rc = current_version(c, &version, err);
	if (rc == API_OK && version > MIGRATION_COUNT)
		rc = api_fail(err, API_INTERNAL, "",
			      "database schema version %d is newer than this poro-server knows (%d): "
			      "use a newer poro-server", version, MIGRATION_COUNT);
	for (int v = version + 1; rc == API_OK && v <= MIGRATION_COUNT; v++) {
		char *msg = NULL;
		if (sqlite3_exec(c->db, MIGRATIONS[v - 1], NULL, NULL, &msg) != SQLITE_OK) {
			rc = api_fail(err, API_INTERNAL, "", "migration %d failed: %s", v, msg ? msg : "?");
			sqlite3_free(msg);
			break;
		}
		char sql[128];
		snprintf(sql, sizeof sql, "INSERT INTO schema_migrations (version, applied_at) VALUES (%d, %lld)", v,
			 now_ms());
		if (conn_exec(c, sql) != SQLITE_OK)
			rc = db_fail(c, err, "recording a migration");
	}
	if (rc != API_OK) {
		conn_exec(c, "ROLLBACK");
		return rc;
	}
	if (conn_exec(c, "COMMIT") != SQLITE_OK)
		return db_fail(c, err, "committing migrations");
	return API_OK;
}
