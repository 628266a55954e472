/*
 * files.c - the artifact store on disk (docs/service.md §1): uploads by workers, downloads by
 * users and by workers resuming from a checkpoint.
 *
 * Files live at STATE/files/<job>/<attempt>/<name>. An upload is streamed to a temporary file
 * (".tmp-<name>-<random>") in that directory while its SHA-256 is computed; at the end the digest
 * is compared with X-Checksum-Sha256 (a mismatch discards the file: 400 checksum_mismatch), the
 * file is fsynced, and the writer thread renames it into place and commits its index row in one
 * write, only if the attempt still holds the lease (store_file_commit; the order that keeps the
 * row and the disk in agreement when that write fails is file_replace.c's). A file without an
 * index row is never served. Names are checked before anything touches the disk (api_file_name).
 *
 * probes.json, frames.json and metrics.json are the files whose content the server checks:
 * probes.json and frames.json are served as the answers of GET /v1/jobs/{id}/probes and
 * GET /v1/jobs/{id}/frames (frames.c reads the latter's ranges), metrics.json is read by benchmark
 * runs (bench_metrics.c), so each must be one JSON object. json_scan checks it while it streams in, in
 * constant memory, within JSON_FILE_MAX_BYTES (or --max-upload-bytes when smaller), a nesting depth
 * and a token length; a file that fails is 422 invalid_json_file naming the line and column, and
 * is not stored. The server never parses result files (docs/service.md §3, "Probes").
 *
 * Downloads (files_serve.c) send X-Checksum-Sha256, honour one byte range and check the copy on
 * disk against its index row.
 */
#include "api.h"
#include "store.h"

#include "digest.h"
#include "fs.h"
#include "json_scan.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define ATTEMPT_MAX 1000000
#define NAME_SIZE 129
/* the files checked as JSON objects while they stream in */
static const char *const JSON_FILE_NAMES[] = { "probes.json", "frames.json", "metrics.json", NULL };
#define JSON_FILE_MAX_BYTES (256LL << 20) /* bytes: 3 probes of 2 million steps (120 bytes a step) */
#define JSON_FILE_DEPTH_MAX 16            /* the probes document nests 4 deep */
#define JSON_FILE_TOKEN_MAX 4096          /* bytes of one string or number */

struct upload {
	int fd;
	struct digest *digest;
	long long size, id, limit;
	int attempt, committed;
	int json;                     /* a JSON file: scan holds the check so far */
	int json_started;             /* its first non-blank byte has been seen */
	struct json_scan scan;
	char name[NAME_SIZE];
	char expected[DIGEST_HEX_SIZE];
	char tmp[SERVER_PATH_MAX + 256], final[SERVER_PATH_MAX + 256];
};

static int checksum_header(struct request *r, char out[DIGEST_HEX_SIZE])
{
	const char *h = http_header(r, "X-Checksum-Sha256");
	int ok = h && strlen(h) == DIGEST_HEX_SIZE - 1;
	for (int i = 0; ok && i < DIGEST_HEX_SIZE - 1; i++) {
		char c = h[i];
		ok = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
		out[i] = (char)(c >= 'A' && c <= 'F' ? c - 'A' + 'a' : c);
	}
	out[DIGEST_HEX_SIZE - 1] = '\0';
	if (!ok)
		reply_fail(r, API_INVALID_HEADER, "X-Checksum-Sha256",
			   "X-Checksum-Sha256 must be the 64 hex digits of the body's SHA-256");
	return ok ? 0 : -1;
}

/* A file the server serves as JSON is checked as it arrives: 0, or -1 after replying 413. */
static int json_file_begin(struct request *r, struct upload *u)
{
	int json = 0;
	for (const char *const *n = JSON_FILE_NAMES; *n && !json; n++)
		json = strcmp(u->name, *n) == 0;
	if (!json)
		return 0;
	u->json = 1;
	u->limit = JSON_FILE_MAX_BYTES < r->srv->cfg.max_upload_bytes ? JSON_FILE_MAX_BYTES : r->srv->cfg.max_upload_bytes;
	json_scan_init(&u->scan, &(struct json_limits){ .max_depth = JSON_FILE_DEPTH_MAX, .max_values = u->limit,
							 .max_token_bytes = JSON_FILE_TOKEN_MAX });
	if (r->content_length > u->limit) {
		reply_fail(r, API_TOO_LARGE, "", "'%s' of %lld bytes exceeds the limit of %lld bytes for JSON files",
			   u->name, r->content_length, u->limit);
		return -1;
	}
	return 0;
}

/* The next piece of a JSON file: 0, or -1 after replying 422 (or 413 past the limit). */
static int json_file_feed(struct request *r, struct upload *u, const char *data, size_t size)
{
	if (u->size > u->limit) {
		reply_fail(r, API_TOO_LARGE, "", "'%s' exceeds the limit of %lld bytes for JSON files", u->name, u->limit);
		return -1;
	}
	for (size_t i = 0; !u->json_started && i < size; i++) {
		unsigned char c = (unsigned char)data[i];
		if (c == ' ' || c == '\t' || c == '\n' || c == '\r')
			continue;
		u->json_started = 1;
		if (c != '{') {
			reply_fail(r, API_INVALID_JSON_FILE, "", "'%s' must be a JSON object: byte %lld is 0x%02x, not '{'",
				   u->name, u->size - (long long)size + (long long)i, c);
			return -1;
		}
	}
	if (json_scan_feed(&u->scan, data, size) != 0) {
		reply_fail(r, API_INVALID_JSON_FILE, "", "'%s' is not a valid JSON file: %s", u->name, u->scan.error);
		return -1;
	}
	return 0;
}

void files_upload_begin(struct request *r)
{
	struct upload *u = calloc(1, sizeof *u);
	if (!u) {
		reply_fail(r, API_UNAVAILABLE, "", "out of memory: retry later");
		return;
	}
	u->fd = -1;
	r->upload = u;
	long long attempt;
	if (api_file_name(r, r->name, u->name) || api_query_int(r, "attempt", 1, ATTEMPT_MAX, 0, &attempt))
		return;
	if (attempt == 0) {
		reply_fail(r, API_INVALID_PARAMETER, "attempt", "query parameter 'attempt' is required");
		return;
	}
	if (checksum_header(r, u->expected) || json_file_begin(r, u))
		return;
	u->id = r->id;
	u->attempt = (int)attempt;
	struct api_error err = { 0 };
	if (store_lease_check(r->srv->store, &r->who, r->id, u->attempt, NULL, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	char dir[SERVER_PATH_MAX], token[DIGEST_TOKEN_SIZE];
	snprintf(dir, sizeof dir, "%s/files/%lld/%d", r->srv->cfg.state, r->id, u->attempt);
	/* files/JOB and files/JOB/ATTEMPT must be durable before an index row names a file in them
	 * (tests/fault/power_loss_test.sh lost every upload of a power cut without this) */
	if (fs_make_dirs(dir) != 0 || fs_sync_parents(dir, 2) != 0) {
		reply_fail(r, api_storage_code(errno), "", "cannot create the directory of '%s': %s", u->name, strerror(errno));
		return;
	}
	if (digest_new_token(token) != 0) {
		reply_fail(r, API_INTERNAL, "", "no randomness for a temporary name of '%s'", u->name);
		return;
	}
	snprintf(u->tmp, sizeof u->tmp, "%s/.tmp-%s-%.16s", dir, u->name, token + 5);
	snprintf(u->final, sizeof u->final, "%s/%s", dir, u->name);
	u->fd = open(u->tmp, O_WRONLY | O_CREAT | O_EXCL, 0644);
	u->digest = digest_create();
	if (u->fd < 0)
		reply_fail(r, api_storage_code(errno), "", "cannot create a file for '%s': %s", u->name, strerror(errno));
	else if (!u->digest)
		reply_fail(r, API_UNAVAILABLE, "", "no memory to receive '%s'", u->name);
}

int files_upload_data(struct request *r, const char *data, size_t size)
{
	struct upload *u = r->upload;
	digest_update(u->digest, data, size);
	u->size += (long long)size;
	if (u->json && json_file_feed(r, u, data, size))
		return -1;
	while (size) {
		ssize_t n = write(u->fd, data, size);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0) {
			reply_fail(r, api_storage_code(n < 0 ? errno : ENOSPC), "", "cannot write '%s': %s", u->name,
				   strerror(n < 0 ? errno : ENOSPC));
			return -1;
		}
		data += n;
		size -= (size_t)n;
	}
	return 0;
}

void files_upload_end(struct request *r)
{
	struct upload *u = r->upload;
	char got[DIGEST_HEX_SIZE];
	digest_final_hex(u->digest, got);
	if (!digest_hex_equal(got, u->expected)) {
		reply_fail(r, API_CHECKSUM_MISMATCH, "X-Checksum-Sha256",
			   "body of %lld bytes has SHA-256 %s, the header says %s", u->size, got, u->expected);
		return; /* files_upload_abort removes the temporary file */
	}
	if (u->json && (!u->json_started || json_scan_finish(&u->scan) != 0)) {
		reply_fail(r, API_INVALID_JSON_FILE, "", "'%s' is not a valid JSON file: %s", u->name,
			   u->json_started ? u->scan.error : "it is empty");
		return;
	}
	int synced = fsync(u->fd) == 0;
	int e = errno;
	close(u->fd);
	u->fd = -1;
	if (!synced) {
		reply_fail(r, api_storage_code(e), "", "cannot sync '%s': %s", u->name, strerror(e));
		return;
	}
	struct api_error err = { 0 };
	if (store_file_commit(r->srv->store, &r->who, u->id, u->attempt, u->name, u->size, got, u->tmp, u->final,
			      &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	u->committed = 1;
	reply_json(r, 201, json_pack("{s:s, s:I, s:s}", "name", u->name, "size", (json_int_t)u->size, "sha256", got));
}

void files_upload_abort(struct request *r)
{
	struct upload *u = r->upload;
	if (!u)
		return;
	if (u->fd >= 0)
		close(u->fd);
	if (!u->committed && u->tmp[0])
		unlink(u->tmp);
	digest_destroy(&u->digest);
	free(u);
	r->upload = NULL;
}

/* ---- downloads (checked in files_serve.c) ---- */

void files_get(struct request *r)
{
	char name[NAME_SIZE], sha[DIGEST_HEX_SIZE];
	if (api_job_visible(r))
		return;
	if (api_file_name(r, r->name, name))
		return;
	int attempt;
	long long size;
	struct api_error err = { 0 };
	if (store_file_find(r->srv->store, r->id, name, -1, &attempt, &size, sha, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	files_serve(r, &(struct stored_file){ r->id, attempt, name, size, sha }, "application/octet-stream");
}

void worker_file_get(struct request *r)
{
	char name[NAME_SIZE], sha[DIGEST_HEX_SIZE];
	if (api_file_name(r, r->name, name))
		return;
	int current = 0, attempt;
	long long size;
	struct api_error err = { 0 };
	if (store_lease_check(r->srv->store, &r->who, r->id, -1, &current, &err) != API_OK ||
	    store_file_find(r->srv->store, r->id, name, current, &attempt, &size, sha, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	files_serve(r, &(struct stored_file){ r->id, attempt, name, size, sha }, "application/octet-stream");
}
