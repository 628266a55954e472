/*
 * store_backup.c - online backup and restore of the database with SQLite's backup API
 * (store_backup.h).
 *
 * Why one sqlite3_backup_step(-1) and not many small steps: between steps SQLite drops the read
 * transaction, and a write by another process (the running server) then restarts the copy from
 * the first page, so under a steady load of submissions a stepped backup might never finish. One
 * step copies every page inside one read transaction: a consistent snapshot as of its start. In
 * WAL mode a reader never blocks the writer; the cost is that the WAL cannot be checkpointed past
 * the snapshot while the copy runs, so it grows by what the server writes meanwhile.
 */
#include "store_backup.h"

#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <sqlite3.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define BACKUP_BUSY_TIMEOUT_MS 10000   /* the server's checkpoint may hold a lock briefly */
#define BACKUP_PATH_MAX 4352

static int fail(char *msg, size_t msg_size, sqlite3 *db, const char *what, const char *path)
{
	snprintf(msg, msg_size, "%s '%s': %s", what, path, db ? sqlite3_errmsg(db) : strerror(errno));
	return -1;
}

/* fsyncs a file, or a directory so that a rename in it is durable. */
static int sync_path(const char *path, int directory)
{
	int fd = open(path, (directory ? O_RDONLY | O_DIRECTORY : O_RDWR) | O_CLOEXEC);
	if (fd < 0)
		return -1;
	int rc = fsync(fd);
	close(fd);
	return rc;
}

static int sync_parent(const char *path)
{
	char copy[BACKUP_PATH_MAX];
	snprintf(copy, sizeof copy, "%s", path);
	return sync_path(dirname(copy), 1);
}

/* PRAGMA integrity_check says "ok", and the copy holds the jobs table: counts go to info. */
static int check_copy(sqlite3 *db, const char *path, struct backup_info *info, char *msg, size_t msg_size)
{
	sqlite3_stmt *st = NULL;
	if (sqlite3_prepare_v2(db, "PRAGMA integrity_check", -1, &st, NULL) != SQLITE_OK)
		return fail(msg, msg_size, db, "cannot check", path);
	int rc = sqlite3_step(st);
	const char *verdict = rc == SQLITE_ROW ? (const char *)sqlite3_column_text(st, 0) : NULL;
	if (!verdict || strcmp(verdict, "ok") != 0) {
		snprintf(msg, msg_size, "integrity check of '%s' failed: %s", path,
			 verdict ? verdict : sqlite3_errmsg(db));
		sqlite3_finalize(st);
		return -1;
	}
	sqlite3_finalize(st);
	if (sqlite3_prepare_v2(db, "SELECT count(*), coalesce(max(id), 0) FROM jobs", -1, &st, NULL) != SQLITE_OK) {
		snprintf(msg, msg_size, "'%s' is not a poro-server database: %s", path, sqlite3_errmsg(db));
		return -1;
	}
	if (sqlite3_step(st) == SQLITE_ROW) {
		info->jobs = sqlite3_column_int64(st, 0);
		info->max_job = sqlite3_column_int64(st, 1);
	}
	sqlite3_finalize(st);
	sqlite3_int64 pages = 0, page_size = 0;
	if (sqlite3_prepare_v2(db, "SELECT page_count, page_size FROM pragma_page_count, pragma_page_size", -1, &st,
			       NULL) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW) {
		pages = sqlite3_column_int64(st, 0);
		page_size = sqlite3_column_int64(st, 1);
	}
	sqlite3_finalize(st);
	info->pages = pages;
	info->bytes = pages * page_size;
	return 0;
}

/* Copies every page of from_path to the new file to_path in one step (see the top of the file),
 * leaves the copy in rollback-journal mode (one file), checks it and fsyncs it. */
static int copy_database(const char *from_path, const char *to_path, struct backup_info *info, char *msg,
			 size_t msg_size)
{
	sqlite3 *src = NULL, *dst = NULL;
	int rc = -1;
	if (sqlite3_open_v2(from_path, &src, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK) {
		fail(msg, msg_size, src, "cannot open database", from_path);
		goto out;
	}
	sqlite3_busy_timeout(src, BACKUP_BUSY_TIMEOUT_MS);
	if (sqlite3_open_v2(to_path, &dst, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, NULL) != SQLITE_OK) {
		fail(msg, msg_size, dst, "cannot create", to_path);
		goto out;
	}
	sqlite3_busy_timeout(dst, BACKUP_BUSY_TIMEOUT_MS);
	sqlite3_backup *b = sqlite3_backup_init(dst, "main", src, "main");
	if (!b) {
		fail(msg, msg_size, dst, "cannot start the copy to", to_path);
		goto out;
	}
	int step = sqlite3_backup_step(b, -1);
	sqlite3_backup_finish(b);
	if (step != SQLITE_DONE) {
		snprintf(msg, msg_size, "cannot copy '%s' to '%s': %s", from_path, to_path, sqlite3_errstr(step));
		goto out;
	}
	/* the copy keeps the source's WAL flag in its header: make it one self-contained file */
	if (sqlite3_exec(dst, "PRAGMA journal_mode=DELETE", NULL, NULL, NULL) != SQLITE_OK) {
		fail(msg, msg_size, dst, "cannot set the journal mode of", to_path);
		goto out;
	}
	if (check_copy(dst, to_path, info, msg, msg_size) != 0)
		goto out;
	rc = 0;
out:
	sqlite3_close(src);
	if (sqlite3_close(dst) != SQLITE_OK && rc == 0)
		rc = fail(msg, msg_size, dst, "cannot close", to_path);
	if (rc == 0 && sync_path(to_path, 0) != 0)
		rc = fail(msg, msg_size, NULL, "cannot sync", to_path);
	return rc;
}

int store_backup(const char *db_path, const char *out, struct backup_info *info, char *msg, size_t msg_size)
{
	char tmp[BACKUP_PATH_MAX];
	struct stat st;
	memset(info, 0, sizeof *info);
	if (stat(db_path, &st) != 0)
		return fail(msg, msg_size, NULL, "no database at", db_path);
	if (lstat(out, &st) == 0) {
		snprintf(msg, msg_size, "'%s' exists: a backup never overwrites a file", out);
		return -1;
	}
	snprintf(tmp, sizeof tmp, "%s.tmp-%ld", out, (long)getpid());
	unlink(tmp);
	if (copy_database(db_path, tmp, info, msg, msg_size) != 0) {
		unlink(tmp);
		return -1;
	}
	/* link(2), unlike rename, refuses to replace a file that appeared meanwhile */
	if (link(tmp, out) != 0) {
		fail(msg, msg_size, NULL, "cannot create", out);
		unlink(tmp);
		return -1;
	}
	unlink(tmp);
	if (sync_parent(out) != 0)
		return fail(msg, msg_size, NULL, "cannot sync the directory of", out);
	return 0;
}

int store_restore(const char *from, const char *db_path, struct backup_info *info, char *msg, size_t msg_size)
{
	char tmp[BACKUP_PATH_MAX], side[BACKUP_PATH_MAX];
	memset(info, 0, sizeof *info);
	if (access(from, R_OK) != 0)
		return fail(msg, msg_size, NULL, "cannot read backup", from);
	snprintf(tmp, sizeof tmp, "%s.restore-%ld", db_path, (long)getpid());
	unlink(tmp);
	if (copy_database(from, tmp, info, msg, msg_size) != 0) {
		unlink(tmp);
		return -1;
	}
	/* the old database's WAL would be replayed over the restored file: it goes first */
	static const char *const SIDE_FILES[] = { "-wal", "-shm", "-journal" };
	for (size_t i = 0; i < sizeof SIDE_FILES / sizeof SIDE_FILES[0]; i++) {
		snprintf(side, sizeof side, "%s%s", db_path, SIDE_FILES[i]);
		if (unlink(side) != 0 && errno != ENOENT) {
			unlink(tmp);
			return fail(msg, msg_size, NULL, "cannot remove", side);
		}
	}
	if (rename(tmp, db_path) != 0) {
		fail(msg, msg_size, NULL, "cannot replace", db_path);
		unlink(tmp);
		return -1;
	}
	if (sync_parent(db_path) != 0)
		return fail(msg, msg_size, NULL, "cannot sync the directory of", db_path);
	return 0;
}
