/*
 * frames.c - the field viewer's frames (docs/web.md, "Frames"): GET /v1/jobs/{id}/frames answers
 * the index frames.json and GET /v1/jobs/{id}/frames/{frame} one frame's points, a byte range of
 * frames.bin. Both files come from the worker, which extracts them from each result.h5 it uploads
 * with `poro-solve probes --frames` in a child process (solver/output/frames_export.h): the server
 * never opens a result file and does not link HDF5 (docs/service.md §1), and a view costs it a
 * range read, not an extraction.
 *
 * The index read here is the newest attempt's (A); its frame's range is served from the frames.bin
 * of attempt A. Within an attempt frames.bin is uploaded before frames.json and only ever grows at
 * its end, so an index's ranges lie in any frames.bin of its attempt as new or newer; the range is
 * checked against the stored size all the same. The index is checked like any stored file before
 * it is parsed (its size and SHA-256 against its row, at most FRAMES_INDEX_MAX bytes) and parsed
 * by jansson with its offsets checked; frames.bin's size is checked against its row, as for any
 * ranged download (files_serve.c).
 */
#include "api.h"
#include "store.h"

#include "digest.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define FRAMES_INDEX "frames.json"
#define FRAMES_BIN "frames.bin"
#define FRAMES_INDEX_MAX (64LL << 20) /* bytes: about 200,000 frames */

void frames_index(struct request *r)
{
	files_serve_newest(r, FRAMES_INDEX, "frames");
}

/* Opens a stored file of (job, attempt) whose size on disk is its row's: the descriptor, or -1
 * after replying (500 stored_file_damaged naming what differs). */
static int open_stored(struct request *r, int attempt, const char *name, long long size)
{
	char path[SERVER_PATH_MAX];
	snprintf(path, sizeof path, "%s/files/%lld/%d/%s", r->srv->cfg.state, r->id, attempt, name);
	int fd = open(path, O_RDONLY | O_CLOEXEC);
	struct stat st;
	if (fd < 0 || fstat(fd, &st) != 0) {
		int e = errno;
		if (fd >= 0)
			close(fd);
		reply_fail(r, API_INTERNAL, "", "indexed file '%s' of job %lld cannot be opened: %s", name, r->id, strerror(e));
		return -1;
	}
	if ((long long)st.st_size != size) {
		close(fd);
		reply_fail(r, API_STORED_FILE_DAMAGED, "", "the server's copy of '%s' of job %lld (attempt %d) is damaged: "
			   "it has %lld bytes on disk but %lld were stored", name, r->id, attempt, (long long)st.st_size, size);
		return -1;
	}
	return fd;
}

/* The index of attempt, checked against its row and parsed; NULL after replying. */
static json_t *load_index(struct request *r, int attempt, long long size, const char *sha)
{
	if (size > FRAMES_INDEX_MAX) {
		reply_fail(r, API_INTERNAL, "", "the frames' index of job %lld has %lld bytes, more than this server reads "
			   "(%lld)", r->id, size, FRAMES_INDEX_MAX);
		return NULL;
	}
	int fd = open_stored(r, attempt, FRAMES_INDEX, size);
	if (fd < 0)
		return NULL;
	char *text = malloc((size_t)size + 1);
	long long got = 0;
	while (text && got < size) {
		ssize_t n = pread(fd, text + got, (size_t)(size - got), (off_t)got);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0)
			break;
		got += n;
	}
	close(fd);
	if (!text) {
		reply_fail(r, API_UNAVAILABLE, "", "no memory for the frames' index: retry later");
		return NULL;
	}
	char got_sha[DIGEST_HEX_SIZE];
	digest_hex(text, (size_t)got, got_sha);
	if (got != size || !digest_hex_equal(got_sha, sha)) {
		free(text);
		reply_fail(r, API_STORED_FILE_DAMAGED, "", "the server's copy of 'frames.json' of job %lld (attempt %d) is "
			   "damaged: it differs from what was stored", r->id, attempt);
		return NULL;
	}
	json_error_t jerr;
	json_t *index = json_loadb(text, (size_t)size, 0, &jerr);
	free(text);
	if (!json_is_object(index)) {
		json_decref(index);
		reply_fail(r, API_INTERNAL, "", "the frames' index of job %lld (attempt %d) is not a JSON object", r->id,
			   attempt);
		return NULL;
	}
	return index;
}

/* Frame number n's byte range in the index: 0, or -1 after replying. */
static int frame_range(struct request *r, json_t *index, long long n, long long *offset, long long *length,
		       double *time)
{
	json_t *frames = json_object_get(index, "frames");
	json_t *f = json_is_array(frames) && n < (long long)json_array_size(frames) ? json_array_get(frames, (size_t)n)
										     : NULL;
	if (!f) {
		reply_fail(r, API_NOT_FOUND, "", "job %lld has no frame %lld (it has %zu)", r->id, n,
			   json_is_array(frames) ? json_array_size(frames) : 0);
		return -1;
	}
	json_t *o = json_object_get(f, "offset"), *l = json_object_get(f, "length");
	*offset = json_integer_value(o);
	*length = json_integer_value(l);
	*time = json_number_value(json_object_get(f, "time"));
	if (!json_is_integer(o) || !json_is_integer(l) || *offset < 0 || *length < 0) {
		reply_fail(r, API_INTERNAL, "", "the frames' index of job %lld has no valid range for frame %lld", r->id, n);
		return -1;
	}
	return 0;
}

void frames_get(struct request *r)
{
	if (api_job_visible(r))
		return;
	long long n = strtoll(r->name, NULL, 10); /* digits only: the route matched {frame} */
	int attempt, bin_attempt;
	long long size, bin_size, offset, length;
	double time;
	char sha[DIGEST_HEX_SIZE], bin_sha[DIGEST_HEX_SIZE];
	struct api_error err = { 0 };
	if (store_file_find(r->srv->store, r->id, FRAMES_INDEX, -1, &attempt, &size, sha, &err) != API_OK) {
		if (err.code == API_NOT_FOUND)
			reply_fail(r, API_NOT_FOUND, "", "job %lld has no frames yet: no attempt has uploaded frames.json", r->id);
		else
			reply_error(r, &err);
		return;
	}
	json_t *index = load_index(r, attempt, size, sha);
	if (!index)
		return;
	int bad = frame_range(r, index, n, &offset, &length, &time);
	json_decref(index);
	if (bad)
		return;
	if (store_file_find(r->srv->store, r->id, FRAMES_BIN, attempt, &bin_attempt, &bin_size, bin_sha, &err) != API_OK ||
	    bin_attempt != attempt || offset + length > bin_size) {
		api_error_release(&err);
		reply_fail(r, API_NOT_FOUND, "", "the points of frame %lld of job %lld (attempt %d) are not stored yet", n,
			   r->id, attempt);
		return;
	}
	int fd = open_stored(r, attempt, FRAMES_BIN, bin_size);
	if (fd < 0)
		return;
	reply_fd(r, 200, fd, offset, length);
	r->reply.content_type = "application/octet-stream";
	char text[64];
	snprintf(text, sizeof text, "%d", attempt);
	reply_header(r, "X-Frames-Attempt", text);
	snprintf(text, sizeof text, "%.17g", time);
	reply_header(r, "X-Frame-Time", text);
	reply_header(r, "Cache-Control", "no-cache");
}
