/*
 * files.c - the artifact store on disk (docs/service.md §1): uploads by workers, downloads by
 * users and by workers resuming from a checkpoint.
 *
 * Files live at STATE/files/<job>/<attempt>/<name>. An upload is streamed to a temporary file
 * (".tmp-<name>-<random>") in that directory while its SHA-256 is computed; at the end the digest
 * is compared with X-Checksum-Sha256 (a mismatch discards the file: 400 checksum_mismatch), the
 * file is fsynced, and the writer thread renames it into place and commits its index row in one
 * write, only if the attempt still holds the lease (store_file_commit). A file without an index
 * row is never served. Names are checked before anything touches the disk (api_file_name).
 *
 * Downloads send X-Checksum-Sha256 and honour one HTTP byte range (206, or 416 when it starts past
 * the end); a list of ranges or a malformed one is ignored and the whole file sent, as RFC 9110
 * allows.
 */
#include "api.h"
#include "store.h"

#include "digest.h"
#include "fs.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define ATTEMPT_MAX 1000000
#define NAME_SIZE 129

struct upload {
	int fd;
	struct digest *digest;
	long long size, id;
	int attempt, committed;
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

void files_upload_begin(struct request *r)
{
	struct upload *u = calloc(1, sizeof *u);
	if (!u) {
		reply_fail(r, API_INTERNAL, "", "out of memory");
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
	if (checksum_header(r, u->expected))
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
	if (fs_make_dirs(dir) != 0 || digest_new_token(token) != 0) {
		reply_fail(r, API_INTERNAL, "", "cannot create '%s': %s", dir, strerror(errno));
		return;
	}
	snprintf(u->tmp, sizeof u->tmp, "%s/.tmp-%s-%.16s", dir, u->name, token + 5);
	snprintf(u->final, sizeof u->final, "%s/%s", dir, u->name);
	u->fd = open(u->tmp, O_WRONLY | O_CREAT | O_EXCL, 0644);
	u->digest = digest_create();
	if (u->fd < 0 || !u->digest)
		reply_fail(r, API_INTERNAL, "", "cannot create '%s': %s", u->tmp, strerror(errno));
}

int files_upload_data(struct request *r, const char *data, size_t size)
{
	struct upload *u = r->upload;
	digest_update(u->digest, data, size);
	u->size += (long long)size;
	while (size) {
		ssize_t n = write(u->fd, data, size);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0) {
			reply_fail(r, API_INTERNAL, "", "cannot write '%s': %s", u->name, strerror(errno));
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
	int synced = fsync(u->fd) == 0;
	close(u->fd);
	u->fd = -1;
	if (!synced) {
		reply_fail(r, API_INTERNAL, "", "cannot sync '%s': %s", u->name, strerror(errno));
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

/* ---- downloads ---- */

/* Parses a single "bytes=a-b" / "bytes=a-" / "bytes=-n" range: 1 and [*from, *to] when it
 * applies, 0 to send the whole file, -1 when it cannot be satisfied. */
static int parse_range(const char *h, long long size, long long *from, long long *to)
{
	if (!h || strncmp(h, "bytes=", 6) != 0 || strchr(h, ','))
		return 0;
	const char *p = h + 6;
	char *end;
	if (*p == '-') {
		long long n = strtoll(p + 1, &end, 10);
		if (*end || n <= 0 || p[1] < '0' || p[1] > '9')
			return n == 0 && !*end ? -1 : 0;
		*from = n >= size ? 0 : size - n;
		*to = size - 1;
		return size > 0 ? 1 : -1;
	}
	if (*p < '0' || *p > '9')
		return 0;
	*from = strtoll(p, &end, 10);
	if (*end != '-')
		return 0;
	if (end[1] == '\0') {
		*to = size - 1;
	} else {
		char *end2;
		*to = strtoll(end + 1, &end2, 10);
		if (*end2 || end[1] < '0' || end[1] > '9' || *to < *from)
			return 0;
		if (*to >= size)
			*to = size - 1;
	}
	return *from < size ? 1 : -1;
}

static void serve_file(struct request *r, long long id, int attempt, const char *name, long long size,
		       const char *sha256)
{
	char path[SERVER_PATH_MAX];
	snprintf(path, sizeof path, "%s/files/%lld/%d/%s", r->srv->cfg.state, id, attempt, name);
	int fd = open(path, O_RDONLY);
	if (fd < 0) {
		reply_fail(r, API_INTERNAL, "", "indexed file '%s' of job %lld cannot be opened: %s", name, id,
			   strerror(errno));
		return;
	}
	long long from = 0, to = size - 1;
	int ranged = parse_range(http_header(r, "Range"), size, &from, &to);
	char text[96];
	if (ranged < 0) {
		close(fd);
		snprintf(text, sizeof text, "bytes */%lld", size);
		reply_header(r, "Content-Range", text);
		reply_fail(r, API_RANGE, "Range", "range '%s' is outside the file's %lld bytes", http_header(r, "Range"),
			   size);
		return;
	}
	reply_fd(r, ranged ? 206 : 200, fd, from, ranged ? to - from + 1 : size);
	r->reply.content_type = "application/octet-stream";
	reply_header(r, "Accept-Ranges", "bytes");
	reply_header(r, "X-Checksum-Sha256", sha256);
	if (ranged) {
		snprintf(text, sizeof text, "bytes %lld-%lld/%lld", from, to, size);
		reply_header(r, "Content-Range", text);
	}
}

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
	serve_file(r, r->id, attempt, name, size, sha);
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
	serve_file(r, r->id, attempt, name, size, sha);
}
