/*
 * job_files.h - the files a job moves: the checkpoint and result downloaded to resume an earlier
 * attempt, snapshots of result files taken while the solver may still be writing them, their
 * checksummed uploads, and the removal of a job's directory.
 */
#ifndef PORO_JOB_FILES_H
#define PORO_JOB_FILES_H

#include <stddef.h>

#include "digest.h"
#include "http_client.h"

/* Downloads checkpoint.h5, which must have the SHA-256 want_sha256, and result.h5 if the server
 * holds one (checked against its X-Checksum-Sha256 header), into out_dir. Returns 0; 1 when a
 * retry may succeed; -1 when not (a checksum mismatch, a refusal). err says what failed. */
int job_files_fetch_resume(struct http_client *c, long long id, int attempt, const char *out_dir,
			   const char *want_sha256, char *err, size_t err_size);

/* Copies src to dst (replaced), computing the copy's SHA-256 and size in bytes, at a moment when
 * src is not being written (its size and modification time unchanged across the copy, and not
 * modified within the last 0.1 s; a file that keeps changing gets its fourth copy as it is).
 * Blocks for about 0.1 s after a fresh write. 0, or -1 with errno (ENOENT when src does not exist). */
int job_files_snapshot(const char *src, const char *dst, char sha256[DIGEST_HEX_SIZE], long long *size);

/* PUT /v1/worker/jobs/{id}/files/{name}?attempt=A from path with its SHA-256. Returns r->status. */
long job_files_upload(struct http_client *c, long long id, int attempt, const char *name, const char *path,
		      const char *sha256, struct http_response *r);

/* Removes dir and everything below it, not following symbolic links. 0 or -1. */
int job_files_remove_tree(const char *dir);

#endif
