/*
 * state_dir.h - the server's state directory (docs/service.md §5): one server at a time, private
 * to the account that runs it, and the file-system checks of /healthz.
 *
 * Ownership is an exclusive flock(2) on STATE/server.lock held for the life of the process (the
 * kernel drops it when the process dies, however it dies, so a crash never leaves a stale lock),
 * with the holder's pid written into the file for the message a second server prints. The lock
 * is taken before the database is opened. `poro-server token ...` does not take it: those
 * commands write through SQLite's own locking, which serialises them with the running server.
 */
#ifndef PORO_STATE_DIR_H
#define PORO_STATE_DIR_H

#include <stddef.h>

#include "server.h"

/* The lock file inside the state directory. */
#define STATE_DIR_LOCK_NAME "server.lock"

/* Takes the exclusive lock on STATE/server.lock and writes this process's pid into it. Returns
 * the descriptor, which must stay open for as long as the server runs (closing it releases the
 * lock), or -1 with a message in msg: "state directory 'STATE' is in use by poro-server pid N"
 * when another server holds it. */
int state_dir_lock(const char *state, char *msg, size_t msg_size);

/* Creates cfg->state (and its parents) if missing and opens the database STATE/poro.db with
 * store_open (store.h); 0, or -1 with a message in msg. */
int state_dir_open_store(const struct server_config *cfg, struct server *srv, struct store **store, char *msg,
			 size_t msg_size);

/* Takes group and other permissions away from what an older run (or a server started under a
 * permissive umask) left: 0700 on the state directory and every directory under files/, owner
 * bits only on poro.db, its -wal and -shm, server.url, the lock and every file under files/.
 * Symbolic links are not followed. What cannot be changed is printed as a warning on stderr; the
 * count of such failures is returned. */
int state_dir_restrict(const char *state);

/* Bytes an unprivileged writer may still allocate on the file system holding the state
 * directory, or -1 with errno set. */
long long state_dir_free_bytes(const char *state);

/* Creates STATE/files/.healthz, writes and fsyncs a line, removes it: 0, or -1 with a message
 * naming what failed (the message names no absolute path: /healthz answers without a token). */
int state_dir_probe_files(const char *state, char *msg, size_t msg_size);

#endif
