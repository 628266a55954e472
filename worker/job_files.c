/*
 * job_files.c - checkpoint download, snapshots, uploads and directory removal, see job_files.h.
 * Snapshots exist because result.h5 is written in place by the solver and checkpoint.h5 is
 * replaced by rename: hashing and uploading a private copy keeps the checksum and the bytes sent
 * in agreement. A copy of result.h5 is also what users download from a running job (poro fetch),
 * so it is taken while the solver is not writing the file: then it holds the file as a killed run
 * would leave it, every frame flushed before the copy readable (solver/output/output.c).
 */
#define _XOPEN_SOURCE 700
#include "job_files.h"

#include <errno.h>
#include <ftw.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* A snapshot of a file written in place is taken only while the file stands still: its size and
 * modification time the same before and after the copy, and the modification time at least
 * SNAPSHOT_QUIET_SECONDS old when the copy starts (file times come from a coarse clock, so a write
 * within the same tick as the last one would not move them). At most SNAPSHOT_TRIES tries. */
#define SNAPSHOT_QUIET_SECONDS 0.1
#define SNAPSHOT_TRIES 4

/* GET one file of the job into dest; 0 ok, 1 retry, -1 refused, 2 not on the server. */
static int fetch_one(struct http_client *c, long long id, int attempt, const char *name, const char *dest,
		     const char *want, char *err, size_t err_size)
{
	char path[512], sha[DIGEST_HEX_SIZE], why[700];
	snprintf(path, sizeof path, "/v1/worker/jobs/%lld/files/%s?attempt=%d", id, name, attempt);
	struct http_response r;
	long long size = 0;
	http_download(c, path, dest, sha, &size, &r);
	int rc = 0;
	if (r.status == 404 && !want) {
		rc = 2;
	} else if (!http_ok(&r)) {
		snprintf(err, err_size, "cannot download '%s': %s", name, http_describe(&r, why, sizeof why));
		rc = http_transient(&r) ? 1 : -1;
	} else if ((want && !digest_hex_equal(sha, want)) || (r.sha256[0] && !digest_hex_equal(sha, r.sha256))) {
		snprintf(err, err_size, "download of '%s' has SHA-256 %s, expected %s", name, sha,
			 want ? want : r.sha256);
		remove(dest);
		rc = 1;
	}
	http_response_release(&r);
	return rc;
}

int job_files_fetch_resume(struct http_client *c, long long id, int attempt, const char *out_dir,
			   const char *want_sha256, char *err, size_t err_size)
{
	char dest[4200];
	snprintf(dest, sizeof dest, "%s/checkpoint.h5", out_dir);
	int rc = fetch_one(c, id, attempt, "checkpoint.h5", dest, want_sha256, err, err_size);
	if (rc != 0)
		return rc == 2 ? -1 : rc;
	snprintf(dest, sizeof dest, "%s/result.h5", out_dir);
	rc = fetch_one(c, id, attempt, "result.h5", dest, NULL, err, err_size);
	return rc == 2 ? 0 : rc;
}

/* Copies the open file in to dst once, hashing it; 0, or -1 with errno. */
static int copy_once(FILE *in, const char *dst, char sha256[DIGEST_HEX_SIZE], long long *size)
{
	*size = 0;
	FILE *out = fopen(dst, "wb");
	struct digest *d = digest_create();
	if (!out || !d) {
		int e = out ? ENOMEM : errno;
		if (out)
			fclose(out);
		digest_destroy(&d);
		errno = e;
		return -1;
	}
	char buf[1 << 16];
	size_t got;
	int failed = 0;
	while ((got = fread(buf, 1, sizeof buf, in)) > 0) {
		digest_update(d, buf, got);
		*size += (long long)got;
		if (fwrite(buf, 1, got, out) != got) {
			failed = 1;
			break;
		}
	}
	failed |= ferror(in);
	int e = errno;
	failed |= fclose(out) != 0;
	digest_final_hex(d, sha256);
	digest_destroy(&d);
	if (failed) {
		remove(dst);
		errno = e ? e : EIO;
		return -1;
	}
	return 0;
}

static int same_version(const struct stat *a, const struct stat *b)
{
	return a->st_size == b->st_size && a->st_mtim.tv_sec == b->st_mtim.tv_sec &&
	       a->st_mtim.tv_nsec == b->st_mtim.tv_nsec;
}

static double wall_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_REALTIME, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int job_files_snapshot(const char *src, const char *dst, char sha256[DIGEST_HEX_SIZE], long long *size)
{
	*size = 0;
	for (int tries = 1;; tries++) {
		FILE *in = fopen(src, "rb");
		struct stat before, after;
		if (!in)
			return -1;
		if (fstat(fileno(in), &before) < 0) {
			int e = errno;
			fclose(in);
			errno = e;
			return -1;
		}
		double age = wall_seconds() - ((double)before.st_mtim.tv_sec + 1e-9 * (double)before.st_mtim.tv_nsec);
		if (age >= 0 && age < SNAPSHOT_QUIET_SECONDS && tries < SNAPSHOT_TRIES) {
			/* just written: a write still going on might not move the coarse file time */
			fclose(in);
			double wait = SNAPSHOT_QUIET_SECONDS - age;
			struct timespec ts = { 0, (long)(wait * 1e9) };
			nanosleep(&ts, NULL);
			continue;
		}
		int rc = copy_once(in, dst, sha256, size);
		int e = errno, stable = rc == 0 && fstat(fileno(in), &after) == 0 && same_version(&before, &after);
		fclose(in);
		if (rc < 0) {
			errno = e;
			return -1;
		}
		/* a file that never stood still: the last copy, as good as any copy taken without looking */
		if (stable || tries >= SNAPSHOT_TRIES)
			return 0;
	}
}

long job_files_upload(struct http_client *c, long long id, int attempt, const char *name, const char *path,
		      const char *sha256, struct http_response *r)
{
	char url[512];
	snprintf(url, sizeof url, "/v1/worker/jobs/%lld/files/%s?attempt=%d", id, name, attempt);
	return http_upload(c, url, path, sha256, r);
}

static int remove_entry(const char *path, const struct stat *st, int type, struct FTW *ftw)
{
	(void)st;
	(void)type;
	(void)ftw;
	remove(path);
	return 0;
}

int job_files_remove_tree(const char *dir)
{
	return nftw(dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}
