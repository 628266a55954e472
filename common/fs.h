/*
 * fs.h - small file-system helpers shared by the server, the worker and the CLI.
 */
#ifndef PORO_FS_H
#define PORO_FS_H

/* mkdir -p: creates path and its missing parents with mode 0755. Returns 0, or -1 with errno set
 * (ENAMETOOLONG for a path of 4096 bytes or more). */
int fs_make_dirs(const char *path);

/* Makes the entries leading to path durable: fsyncs the directory that holds path, the one that
 * holds that directory, and so on, `levels` directories in all. A new directory's entry in its
 * parent survives a power loss only once the parent is fsynced (POSIX promises no more; ext4's
 * ordering hides it, other file systems do not), so a file stored under directories that
 * fs_make_dirs() created is durable only after this as well as its own fsync and its
 * directory's. Returns 0, or -1 with errno set by open or fsync. */
int fs_sync_parents(const char *path, int levels);

#endif
