/*
 * file_sweep.c - removing files of the artifact store that nothing owns (file_sweep.h).
 *
 * files.c streams an upload to STATE/files/<job>/<attempt>/.tmp-<name>-<random> and renames it
 * into place when it is complete; it unlinks the temporary file when the request ends any other
 * way (a refused or broken upload, a client that disconnects: libmicrohttpd then ends the
 * request, and files_upload_abort runs). Only a server that stops without ending its requests
 * (kill -9, power loss) leaves one behind, so the sweep runs once at start-up, before the first
 * request, when no upload can be in flight. A replacement cut short the same way leaves the old
 * version kept under ".old-<SHA-256>-<name>" (file_replace.h); the sweep puts it back when its
 * row still names it and removes it otherwise, so every row again describes its file. It also removes the directory of a job the database
 * does not hold: DELETE /v1/jobs/{id} commits the deletion first and removes the files after,
 * so a crash in between leaves such a directory (job ids are never reused, so it belongs to no
 * one).
 *
 * The walk is bounded by the layout: STATE/files, its job directories, their attempt
 * directories, and the files in those; entries that are not decimal numbers at the first two
 * levels are left alone, and no symbolic link is followed (fstatat/openat with NOFOLLOW).
 */
#include "file_sweep.h"
#include "file_replace.h"
#include "server.h"
#include "store.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define TMP_PREFIX ".tmp-"   /* files.c's temporary upload names */
#define JOB_DEPTH 2          /* a job directory holds attempt directories, which hold files */

/* 1 when name is a decimal number as files.c names job and attempt directories. */
static int numeric(const char *name, long long *value)
{
	long long v = 0;
	size_t n = strlen(name);
	if (n == 0 || n > 18 || name[0] == '0')
		return 0;
	for (size_t i = 0; i < n; i++) {
		if (name[i] < '0' || name[i] > '9')
			return 0;
		v = 10 * v + (name[i] - '0');
	}
	*value = v;
	return 1;
}

static DIR *open_dir_at(int parent, const char *name)
{
	int fd = openat(parent, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
	if (fd < 0)
		return NULL;
	DIR *d = fdopendir(fd);
	if (!d)
		close(fd);
	return d;
}

/* Removes name under parent: a file, or a directory with at most depth levels below it. Adds the
 * bytes of the regular files removed. 0, or -1 with errno (the rest is still tried). */
static int remove_tree(int parent, const char *name, int depth, long long *bytes)
{
	struct stat st;
	if (fstatat(parent, name, &st, AT_SYMLINK_NOFOLLOW) != 0)
		return errno == ENOENT ? 0 : -1;
	if (!S_ISDIR(st.st_mode)) {
		if (unlinkat(parent, name, 0) != 0)
			return errno == ENOENT ? 0 : -1;
		if (S_ISREG(st.st_mode))
			*bytes += (long long)st.st_size;
		return 0;
	}
	int rc = 0;
	DIR *d = depth > 0 ? open_dir_at(parent, name) : NULL;
	if (d) {
		struct dirent *e;
		while ((e = readdir(d)))
			if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") &&
			    remove_tree(dirfd(d), e->d_name, depth - 1, bytes) != 0)
				rc = -1;
		closedir(d);
	}
	if (unlinkat(parent, name, AT_REMOVEDIR) != 0 && errno != ENOENT)
		rc = -1;
	return rc;
}

/* A kept old version (file_replace.h) in attempt directory dir of job id: back to its name when
 * its row still has its SHA-256 (the new version's row never committed), else removed. */
static void settle_kept(struct store *store, long long id, long long attempt, int dir, const char *entry,
			struct sweep_counts *counts)
{
	char sha[65], name[129], row_sha[65];
	int row_attempt = 0;
	long long size;
	struct api_error err = { 0 };
	if (!file_replace_kept_name(entry, sha, name))
		return;
	enum api_code rc = store_file_find(store, id, name, (int)attempt, &row_attempt, &size, row_sha, &err);
	if (rc != API_OK && rc != API_NOT_FOUND)
		return; /* cannot tell: left for the next start-up */
	if (rc == API_OK && row_attempt == attempt && strcmp(row_sha, sha) == 0) {
		if (renameat(dir, entry, dir, name) == 0 && fsync(dir) == 0)
			counts->kept_restored++;
	} else if (unlinkat(dir, entry, 0) == 0) {
		counts->kept_dropped++;
	}
}

/* Removes the temporary upload files in the attempt directories of job directory name, and
 * settles the old versions kept by replacements that did not finish. */
static void sweep_tmp(int files_fd, const char *name, long long id, struct store *store, struct sweep_counts *counts)
{
	DIR *job = open_dir_at(files_fd, name);
	if (!job)
		return;
	struct dirent *a;
	long long number;
	while ((a = readdir(job))) {
		DIR *attempt = numeric(a->d_name, &number) ? open_dir_at(dirfd(job), a->d_name) : NULL;
		if (!attempt)
			continue;
		struct dirent *f;
		struct stat st;
		while ((f = readdir(attempt)))
			if (strncmp(f->d_name, FILE_KEPT_PREFIX, strlen(FILE_KEPT_PREFIX)) == 0)
				settle_kept(store, id, number, dirfd(attempt), f->d_name, counts);
			else if (strncmp(f->d_name, TMP_PREFIX, strlen(TMP_PREFIX)) == 0 &&
				 fstatat(dirfd(attempt), f->d_name, &st, AT_SYMLINK_NOFOLLOW) == 0 &&
				 S_ISREG(st.st_mode) && unlinkat(dirfd(attempt), f->d_name, 0) == 0) {
				counts->tmp_files++;
				counts->tmp_bytes += (long long)st.st_size;
			}
		closedir(attempt);
	}
	closedir(job);
}

int file_sweep_startup(const char *state, struct store *store, struct sweep_counts *counts)
{
	memset(counts, 0, sizeof *counts);
	char path[SERVER_PATH_MAX];
	snprintf(path, sizeof path, "%s/files", state);
	DIR *files = open_dir_at(AT_FDCWD, path);
	if (!files)
		return errno == ENOENT ? 0 : -1;
	struct dirent *e;
	long long id;
	while ((e = readdir(files))) {
		if (!numeric(e->d_name, &id))
			continue;
		int exists = store_job_exists(store, id);
		if (exists == 0) {
			long long bytes = 0;
			if (remove_tree(dirfd(files), e->d_name, JOB_DEPTH, &bytes) == 0)
				counts->job_dirs++;
			counts->job_bytes += bytes;
		} else if (exists > 0) {
			sweep_tmp(dirfd(files), e->d_name, id, store, counts);
		}
	}
	closedir(files);
	return 0;
}

int file_sweep_job(const char *state, long long id, long long *bytes)
{
	*bytes = 0;
	char path[SERVER_PATH_MAX], name[32];
	snprintf(path, sizeof path, "%s/files", state);
	snprintf(name, sizeof name, "%lld", id);
	DIR *files = open_dir_at(AT_FDCWD, path);
	if (!files)
		return errno == ENOENT ? 0 : -1;
	int rc = remove_tree(dirfd(files), name, JOB_DEPTH, bytes);
	int saved = errno;
	closedir(files);
	errno = saved;
	return rc;
}
