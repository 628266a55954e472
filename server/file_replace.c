/*
 * file_replace.c - putting an uploaded file in place (file_replace.h).
 *
 * Why this order. The index row and the file are two stores that no one operation changes
 * together, and a version of the same name and attempt replaces the old one at the same path
 * (the worker uploads result.h5 and checkpoint.h5 again at every checkpoint). Renaming the new
 * version over the old one inside the write and letting the write fail after it (a directory
 * fsync, the COMMIT's WAL fsync, a crash before the COMMIT is durable) left the new bytes on disk
 * with the old row: served as damaged, the old bytes gone. Renaming only after the COMMIT has the
 * mirror fault (a new row over the old bytes). So the old version stays under a second name until
 * the new row is durable:
 *
 *   1. (files.c) the upload is fsynced under its temporary name;
 *   2. in the write: lease check, quota, the new row (not yet durable);
 *   3. link final -> kept, fsync the directory (the old bytes now have a durable second name);
 *   4. rename tmp -> final, fsync the directory (the new bytes have the name, durably);
 *   5. COMMIT (the new row is durable);
 *   6. unlink kept (no fsync: a kept version that comes back after a power loss is one whose row
 *      has moved on, and the sweep removes it).
 * A failure in 3 or 4 undoes them before the write returns its error; a failed COMMIT undoes
 * them in file_replace_end (rename kept -> final, or unlink final when there was no old
 * version), before the next write. A crash anywhere leaves the row and the kept version in one
 * of the states the start-up sweep tells apart by the SHA-256 in the kept version's name: the
 * row still has it (5 did not happen), so the kept version goes back; or not (5 happened), so it
 * goes. The fsync in 3 matters: without it a power loss could keep the rename of 4 and not the
 * link, and the old bytes would be lost with their row still naming them.
 *
 * A first version (no row yet) has nothing to keep: a failure removes it, a crash may leave it
 * without a row, which is never served and is replaced by the next upload of the name.
 */
#include "file_replace.h"
#include "api.h"
#include "log.h"

#include "fs.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define SHA256_HEX 64

/* Puts final back as it was before file_replace_begin; keeps errno. */
static void undo(struct file_replace *f)
{
	int e = errno;
	if (f->kept[0] ? rename(f->kept, f->final) != 0 : unlink(f->final) != 0 && errno != ENOENT)
		log_say(LOG_PRIO_ERR,
			"cannot put back the old version of '%s': %s; it is served as damaged until the "
			"next start-up puts it back",
			f->final, strerror(errno));
	fs_sync_parents(f->final, 1);
	f->placed = 0;
	errno = e;
}

/* Removes the kept version if this call made it (one that existed before holds the row's bytes
 * and must stay); keeps errno. */
static void drop_new_link(struct file_replace *f, int linked)
{
	int e = errno;
	if (linked)
		unlink(f->kept);
	f->kept[0] = '\0';
	errno = e;
}

int file_replace_begin(struct file_replace *f, const char *tmp, const char *final, const char *old_sha256)
{
	f->tmp = tmp;
	f->final = final;
	f->kept[0] = '\0';
	f->placed = 0;
	int linked = 0;
	if (old_sha256) {
		const char *slash = strrchr(final, '/');
		int dir = slash ? (int)(slash - final) : 0;
		if (!slash || snprintf(f->kept, sizeof f->kept, "%.*s/%s%s-%s", dir, final, FILE_KEPT_PREFIX,
				       old_sha256, slash + 1) >= (int)sizeof f->kept) {
			f->kept[0] = '\0';
			errno = ENAMETOOLONG;
			return -1;
		}
		/* EEXIST: the version with this SHA-256 is kept already (an earlier undo could not
		 * rename it back); ENOENT: the row's file is gone, so there is nothing to keep */
		linked = link(final, f->kept) == 0;
		if (!linked && errno != EEXIST) {
			if (errno != ENOENT)
				return -1;
			f->kept[0] = '\0';
		}
		if (f->kept[0] && fs_sync_parents(f->kept, 1) != 0) {
			drop_new_link(f, linked);
			return -1;
		}
	}
	if (rename(tmp, final) != 0) {
		drop_new_link(f, linked);
		return -1;
	}
	f->placed = 1;
	if (fs_sync_parents(final, 1) != 0) {
		undo(f);
		return -1;
	}
	return 0;
}

void file_replace_end(struct file_replace *f, int committed)
{
	if (!f->placed)
		return;
	if (!committed)
		undo(f);
	else if (f->kept[0])
		unlink(f->kept);
	f->placed = 0;
}

int file_replace_kept_name(const char *entry, char sha256[65], char name[129])
{
	size_t prefix = strlen(FILE_KEPT_PREFIX);
	if (strncmp(entry, FILE_KEPT_PREFIX, prefix) != 0 || strlen(entry) < prefix + SHA256_HEX + 2 ||
	    entry[prefix + SHA256_HEX] != '-')
		return 0;
	for (size_t i = 0; i < SHA256_HEX; i++) {
		char c = entry[prefix + i];
		if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f')))
			return 0;
		sha256[i] = c;
	}
	sha256[SHA256_HEX] = '\0';
	const char *rest = entry + prefix + SHA256_HEX + 1;
	if (strlen(rest) > 128 || !api_file_name_valid(rest))
		return 0;
	snprintf(name, 129, "%s", rest);
	return 1;
}
