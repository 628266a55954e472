/*
 * fs.h - small file-system helpers shared by the server, the worker and the CLI.
 */
#ifndef PORO_FS_H
#define PORO_FS_H

/* mkdir -p: creates path and its missing parents with mode 0755. Returns 0, or -1 with errno set
 * (ENAMETOOLONG for a path of 4096 bytes or more). */
int fs_make_dirs(const char *path);

#endif
