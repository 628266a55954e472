/*
 * backup_cli.h - `poro-server backup` and `poro-server restore` (docs/operations.md):
 *
 *   poro-server backup  --state=DIR --out=FILE    while the server runs, or not
 *   poro-server restore --state=DIR --from=FILE   with the server stopped
 *
 * backup writes a consistent, integrity-checked copy of STATE/poro.db (store_backup.h) and says
 * what it holds on stdout. restore takes the state directory's lock (so it refuses while a server
 * runs on it), checks the backup and puts it in place of STATE/poro.db.
 */
#ifndef PORO_BACKUP_CLI_H
#define PORO_BACKUP_CLI_H

/* Runs `poro-server backup|restore ...` (argv[1] is the command). Returns the exit status: 0,
 * 1 when the copy failed, 2 for a bad command line. */
int backup_command(int argc, char **argv, const char *default_state);

#endif
