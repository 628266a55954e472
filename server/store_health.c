/*
 * store_health.c - the write probe of /healthz (store.h): one row of table health is rewritten
 * with the time and a count of rewrites, through the writer thread like every other write, so
 * the probe fails exactly when a submission would (a full disk, a file-size limit on the WAL, a
 * read-only file system, a writer stuck behind another process's lock). The caller bounds how
 * often it runs (admin_api.c caches the answer).
 */
#include "store_internal.h"

static enum api_code health_write_run(struct store *s, struct conn *c, void *arg, struct api_error *err)
{
	sqlite3_stmt *st = conn_stmt(c, "INSERT INTO health (id, checked_at, writes) VALUES (1, ?1, 1)"
					" ON CONFLICT (id) DO UPDATE SET checked_at = ?1, writes = writes + 1");
	if (!st)
		return db_fail(c, err, "preparing the health write");
	sqlite3_bind_int64(st, 1, now_ms());
	return step_done(c, st, err, "writing the health row");
}

enum api_code store_health_write(struct store *s, struct api_error *err)
{
	return store_write(s, health_write_run, NULL, err);
}
