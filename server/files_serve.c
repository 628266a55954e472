/*
 * files_serve.c - sending a stored file (docs/service.md §3, "Stored files"): user downloads,
 * worker checkpoint downloads and the probes route all come through files_serve(), which checks
 * the copy on disk against its index row before and while it is sent.
 *
 * A stored file is immutable once indexed, so a copy that differs from its row was damaged on
 * disk (truncation, bit rot, a hand edit). What is checked, and when:
 *   - every request: the open file's size (fstat) against the indexed size; a difference is 500
 *     stored_file_damaged at once, before any header is sent, so a client never waits on bytes
 *     that do not exist (libmicrohttpd is never handed a length longer than the file);
 *   - a whole-file download of at most VERIFY_BEFORE_MAX bytes: its SHA-256 is computed before
 *     the answer, a mismatch is the same error at once;
 *   - a larger whole-file download: hashed while it is sent (checked_read); the last block is
 *     held back until the digest is known and, if it does not match, the connection is closed
 *     instead, so the client sees a short body (Content-Length is always sent) and never a
 *     complete damaged file;
 *   - a ranged request: the size check only (hashing the whole file for every range would cost a
 *     full read per request).
 * Each damaged file found is written to stderr once, and remembered (damaged_*: up to
 * DAMAGED_REMEMBERED files, keyed by the copy's inode, size and modification time) so that later
 * requests for the same copy get the error at once, including those for large files whose first
 * download could only be broken off; a copy replaced by an operator has another key and is
 * checked afresh.
 *
 * Ranges: one HTTP byte range is honoured (206, or 416 when it starts past the end); a list of
 * ranges or a malformed one is ignored and the whole file sent, as RFC 9110 allows.
 */
#include "api.h"
#include "log.h"
#include "store.h"

#include "digest.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define VERIFY_BEFORE_MAX (64LL << 20) /* bytes: whole downloads up to this are hashed before answering */
#define VERIFY_BLOCK (1 << 16)         /* bytes read at a time while hashing before answering */
#define DAMAGED_REMEMBERED 64          /* damaged copies remembered; older ones are checked again */
#define DAMAGE_TEXT_MAX 320

/* Which copy on disk: a file replaced on disk is another copy. */
struct copy_key {
	long long id;
	int attempt;
	char name[129];
	dev_t dev;
	ino_t ino;
	long long size, mtime_ns;
};

static struct {
	pthread_mutex_t lock;
	struct copy_key key[DAMAGED_REMEMBERED];
	char what[DAMAGED_REMEMBERED][DAMAGE_TEXT_MAX];
	int count, next;
} damaged = { .lock = PTHREAD_MUTEX_INITIALIZER };

static int key_equal(const struct copy_key *a, const struct copy_key *b)
{
	return a->id == b->id && a->attempt == b->attempt && a->dev == b->dev && a->ino == b->ino &&
	       a->size == b->size && a->mtime_ns == b->mtime_ns && strcmp(a->name, b->name) == 0;
}

/* What was found wrong with this copy before, into what; 1 if it is remembered, else 0. */
static int damaged_recall(const struct copy_key *k, char what[DAMAGE_TEXT_MAX])
{
	int found = 0;
	pthread_mutex_lock(&damaged.lock);
	for (int i = 0; i < damaged.count && !found; i++) {
		if (key_equal(&damaged.key[i], k)) {
			memcpy(what, damaged.what[i], DAMAGE_TEXT_MAX);
			found = 1;
		}
	}
	pthread_mutex_unlock(&damaged.lock);
	return found;
}

/* Remembers a damaged copy and writes the one stderr line for it (unless already remembered: two
 * requests may find the same damage at once). */
static void damaged_record(const struct copy_key *k, const char *what)
{
	char seen[DAMAGE_TEXT_MAX];
	if (damaged_recall(k, seen))
		return;
	pthread_mutex_lock(&damaged.lock);
	int i = damaged.next;
	damaged.key[i] = *k;
	snprintf(damaged.what[i], DAMAGE_TEXT_MAX, "%s", what);
	damaged.next = (i + 1) % DAMAGED_REMEMBERED;
	if (damaged.count < DAMAGED_REMEMBERED)
		damaged.count++;
	pthread_mutex_unlock(&damaged.lock);
	log_say(LOG_PRIO_ERR, "damaged stored file: job %lld attempt %d '%s': %s", k->id, k->attempt, k->name, what);
}

static void reply_damaged(struct request *r, const struct copy_key *k, const char *what)
{
	reply_fail(r, API_STORED_FILE_DAMAGED, "",
		   "the server's copy of '%s' of job %lld (attempt %d) is damaged: %s; it cannot be served until an "
		   "operator restores it", k->name, k->id, k->attempt, what);
}

/* ---- hashing ---- */

/* SHA-256 of the first size bytes of fd into hex; 0, or an errno value (EIO when the file ends
 * early: it was cut while being read). */
static int hash_fd(int fd, long long size, char hex[DIGEST_HEX_SIZE])
{
	struct digest *d = digest_create();
	char *buf = malloc(VERIFY_BLOCK);
	long long pos = 0;
	int e = d && buf ? 0 : ENOMEM;
	while (!e && pos < size) {
		size_t want = size - pos < VERIFY_BLOCK ? (size_t)(size - pos) : VERIFY_BLOCK;
		ssize_t n = pread(fd, buf, want, (off_t)pos);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0) {
			e = n < 0 ? errno : EIO;
			break;
		}
		digest_update(d, buf, (size_t)n);
		pos += n;
	}
	if (d)
		digest_final_hex(d, hex);
	digest_destroy(&d);
	free(buf);
	return e;
}

/* A large whole-file download, hashed as it goes out (see the top of this file). */
struct checked_stream {
	int fd;
	long long size, next;
	struct digest *digest;
	char expected[DIGEST_HEX_SIZE];
	struct copy_key key;
};

static ssize_t checked_read(void *cls, uint64_t pos, char *buf, size_t max)
{
	struct checked_stream *c = cls;
	char what[DAMAGE_TEXT_MAX];
	if ((long long)pos != c->next)  /* libmicrohttpd reads in order; anything else cannot be checked */
		return HTTP_STREAM_ERROR;
	if (c->next >= c->size)
		return HTTP_STREAM_END;
	size_t want = c->size - c->next < (long long)max ? (size_t)(c->size - c->next) : max;
	ssize_t n;
	do
		n = pread(c->fd, buf, want, (off_t)c->next);
	while (n < 0 && errno == EINTR);
	if (n <= 0) {
		snprintf(what, sizeof what, "it ended at byte %lld of the %lld stored while it was being sent", c->next,
			 c->size);
		damaged_record(&c->key, what);
		return HTTP_STREAM_ERROR;
	}
	digest_update(c->digest, buf, (size_t)n);
	c->next += n;
	if (c->next == c->size) {   /* the last block goes out only if the whole file is right */
		char got[DIGEST_HEX_SIZE];
		digest_final_hex(c->digest, got);
		if (!digest_hex_equal(got, c->expected)) {
			snprintf(what, sizeof what, "its %lld bytes have SHA-256 %s, the stored file had %s", c->size, got,
				 c->expected);
			damaged_record(&c->key, what);
			return HTTP_STREAM_ERROR;
		}
	}
	return n;
}

static void checked_free(void *cls)
{
	struct checked_stream *c = cls;
	close(c->fd);
	digest_destroy(&c->digest);
	free(c);
}

/* ---- ranges ---- */

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

/* ---- serving ---- */

/* The whole file, checked as the top of this file says; fd is handed on or closed. */
static void serve_whole(struct request *r, int fd, const struct copy_key *k, const char *sha256)
{
	if (k->size > VERIFY_BEFORE_MAX) {
		struct checked_stream *c = calloc(1, sizeof *c);
		if (!c || !(c->digest = digest_create())) {
			free(c);
			close(fd);
			reply_fail(r, API_UNAVAILABLE, "", "out of memory: retry later");
			return;
		}
		c->fd = fd;
		c->size = k->size;
		c->key = *k;
		snprintf(c->expected, sizeof c->expected, "%s", sha256);
		reply_stream_sized(r, 200, NULL, k->size, checked_read, c, checked_free);
		return;
	}
	char got[DIGEST_HEX_SIZE], what[DAMAGE_TEXT_MAX];
	int e = hash_fd(fd, k->size, got);
	if (e) {
		close(fd);
		reply_fail(r, API_INTERNAL, "", "cannot read the stored file '%s' of job %lld: %s", k->name, k->id,
			   strerror(e));
		return;
	}
	if (!digest_hex_equal(got, sha256)) {
		close(fd);
		snprintf(what, sizeof what, "its %lld bytes have SHA-256 %s, the stored file had %s", k->size, got, sha256);
		damaged_record(k, what);
		reply_damaged(r, k, what);
		return;
	}
	reply_fd(r, 200, fd, 0, k->size);
}

void files_serve(struct request *r, const struct stored_file *f, const char *content_type)
{
	char path[SERVER_PATH_MAX], what[DAMAGE_TEXT_MAX];
	snprintf(path, sizeof path, "%s/files/%lld/%d/%s", r->srv->cfg.state, f->id, f->attempt, f->name);
	int fd = open(path, O_RDONLY);
	struct stat st;
	if (fd < 0 || fstat(fd, &st) != 0) {
		int e = errno;
		if (fd >= 0)
			close(fd);
		reply_fail(r, API_INTERNAL, "", "indexed file '%s' of job %lld cannot be opened: %s", f->name, f->id,
			   strerror(e));
		return;
	}
	struct copy_key k = { .id = f->id, .attempt = f->attempt, .dev = st.st_dev, .ino = st.st_ino,
			      .size = (long long)st.st_size,
			      .mtime_ns = (long long)st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec };
	snprintf(k.name, sizeof k.name, "%s", f->name);
	int known = damaged_recall(&k, what);
	if (!known && k.size != f->size) {
		snprintf(what, sizeof what, "it has %lld bytes on disk but %lld were stored", k.size, f->size);
		damaged_record(&k, what);
		known = 1;
	}
	if (known) {
		close(fd);
		reply_damaged(r, &k, what);
		return;
	}
	long long from = 0, to = f->size - 1;
	const char *range = http_header(r, "Range");
	int ranged = parse_range(range, f->size, &from, &to);
	char text[96];
	if (ranged < 0) {
		close(fd);
		snprintf(text, sizeof text, "bytes */%lld", f->size);
		reply_header(r, "Content-Range", text);
		reply_fail(r, API_RANGE, "Range", "range '%s' is outside the file's %lld bytes", range, f->size);
		return;
	}
	if (ranged) {
		reply_fd(r, 206, fd, from, to - from + 1);
		snprintf(text, sizeof text, "bytes %lld-%lld/%lld", from, to, f->size);
		reply_header(r, "Content-Range", text);
	} else {
		serve_whole(r, fd, &k, f->sha256);
		if (r->reply.status != 200)
			return;
	}
	r->reply.content_type = content_type;
	reply_header(r, "Accept-Ranges", "bytes");
	reply_header(r, "X-Checksum-Sha256", f->sha256);
}

void files_serve_newest(struct request *r, const char *name, const char *what)
{
	if (api_job_visible(r))
		return;
	int attempt;
	long long size;
	char sha[DIGEST_HEX_SIZE];
	struct api_error err = { 0 };
	if (store_file_find(r->srv->store, r->id, name, -1, &attempt, &size, sha, &err) != API_OK) {
		if (err.code != API_NOT_FOUND) {
			reply_error(r, &err);
			return;
		}
		reply_fail(r, API_NOT_FOUND, "", "job %lld has no %s yet: no attempt has uploaded %s", r->id, what, name);
		return;
	}
	files_serve(r, &(struct stored_file){ r->id, attempt, name, size, sha }, "application/json");
}
