/*
 * store_backup.h - online backup and restore of the server's database (docs/operations.md).
 *
 * A backup is one consistent snapshot of STATE/poro.db taken while the server runs: SQLite's
 * backup API copies every page within one read transaction, which in WAL mode never blocks the
 * server's writer, so submissions go on being acknowledged while it runs, and every write
 * committed before the copy began is in it. The copy is a single self-contained file (rollback
 * journal mode, no -wal beside it), checked with PRAGMA integrity_check, fsynced and renamed into
 * place, so a backup file either is whole and checked or does not exist.
 */
#ifndef PORO_STORE_BACKUP_H
#define PORO_STORE_BACKUP_H

#include <stddef.h>

/* What a backup or restore copied. */
struct backup_info {
	long long pages, bytes;   /* of the copy */
	long long jobs, max_job;  /* rows of table jobs and the largest job id in the copy */
};

/* Copies the database at db_path (opened read-only, in use by a running server or not) to out,
 * through a temporary file beside out: 0, or -1 with a message naming what failed. out must not
 * exist (a backup never overwrites one). */
int store_backup(const char *db_path, const char *out, struct backup_info *info, char *msg, size_t msg_size);

/* Checks the backup file from (integrity_check and a jobs table) and copies it to db_path through
 * a temporary file, removing db_path's -wal and -shm: the caller holds the state directory's lock,
 * so no server has the database open. 0, or -1 with a message. */
int store_restore(const char *from, const char *db_path, struct backup_info *info, char *msg, size_t msg_size);

#endif
