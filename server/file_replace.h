/*
 * file_replace.h - putting an uploaded file in place under STATE/files/<job>/<attempt>/<name> so
 * that the file index and the disk agree whatever fails (file_replace.c, docs/service.md §1).
 *
 * The invariant: every committed index row describes the bytes at its path (size and SHA-256).
 * A file without a row may exist (it is never served). To hold it while a new version replaces
 * an old one, the old version is kept under a second name in the same directory,
 * ".old-<SHA-256 of the old row>-<name>", durable before the new one takes the name and removed
 * only once the new row has committed. Whatever fails before that commit puts it back; whatever a
 * crash or a power loss interrupts, the start-up sweep (file_sweep.c) finishes: a kept version
 * whose SHA-256 is still its row's goes back to its name, any other is removed.
 */
#ifndef PORO_FILE_REPLACE_H
#define PORO_FILE_REPLACE_H

#include "server.h"

#define FILE_KEPT_PREFIX ".old-"

struct file_replace {
	const char *tmp, *final;          /* the fsynced upload and its name in place */
	char kept[SERVER_PATH_MAX + 256]; /* the old version's second name; "" when there is none */
	int placed;                       /* tmp was renamed to final and not yet undone */
};

/* Moves tmp (already fsynced) to final in the same directory, keeping the version at final that
 * the index row with old_sha256 describes (NULL: no row) as f->kept, and fsyncs the directory
 * after each step. Returns 0, or -1 with errno after putting final back as it was. Run it last
 * in the write that indexes the new version, then call file_replace_end once that write's
 * COMMIT has returned. */
int file_replace_begin(struct file_replace *f, const char *tmp, const char *final, const char *old_sha256);

/* committed: the new row is durable, so the kept version is removed. Otherwise the old version
 * goes back to its name (or final is removed when there was none). Does nothing unless
 * file_replace_begin placed the file. */
void file_replace_end(struct file_replace *f, int committed);

/* 1 when entry (a name in an attempt directory) is a kept version: its row's SHA-256 into
 * sha256 and the name it was kept for into name (a valid file name, api_file_name_valid); else 0. */
int file_replace_kept_name(const char *entry, char sha256[65], char name[129]);

#endif
