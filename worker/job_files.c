/*
 * job_files.c - checkpoint download, snapshots, uploads and directory removal, see job_files.h.
 * Snapshots exist because result.h5 is written in place by the solver and checkpoint.h5 is
 * replaced by rename: hashing and uploading a private copy keeps the checksum and the bytes sent
 * in agreement.
 */
#define _XOPEN_SOURCE 700
#include "job_files.h"

#include <errno.h>
#include <ftw.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

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

int job_files_snapshot(const char *src, const char *dst, char sha256[DIGEST_HEX_SIZE], long long *size)
{
	*size = 0;
	FILE *in = fopen(src, "rb");
	if (!in)
		return -1;
	FILE *out = fopen(dst, "wb");
	struct digest *d = digest_create();
	if (!out || !d) {
		int e = out ? ENOMEM : errno;
		fclose(in);
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
	fclose(in);
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
