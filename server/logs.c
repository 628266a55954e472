/*
 * logs.c - reading a job's log (GET /v1/jobs/{id}/log): the text of one attempt from an offset,
 * streamed (chunked) with bounded memory per reader; without follow the stream ends at the end
 * offset the log had when the request came (X-Log-Next-Offset), with follow=1 it delivers new
 * chunks as workers append them and ends when the attempt ends (finish, expiry, cancel) or the
 * server stops.
 *
 * Each call of the stream callback reads at most LOG_READ_BLOCK bytes of whole chunks through a
 * read connection of the pool (store_log_read) and hands them out, so a reader holds one block,
 * whatever the log's size. Where the read reaches bytes the cap dropped (store_worker.c), one
 * marker line stands in their place, naming the dropped offsets A..B this reader skipped:
 *   [poro-server: log bytes A..B of attempt N were dropped: an attempt keeps its first X and last Y (--max-log-bytes)]
 * and the stream goes on with the bytes from offset B. Offsets stay log offsets: a client that
 * resumes by counting bytes takes B as the offset after the marker line (cli/poro.c does), since
 * the marker's own bytes are not log bytes.
 *
 * A follower blocks only its own connection thread (one thread per connection). It waits on
 * srv->log_cv, which the writer broadcasts after committing a log chunk or the end of an attempt,
 * and re-reads at least once a second; the sequence number read before each read makes a
 * wake-up between the read and the wait impossible to miss.
 */
#include "api.h"
#include "store.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define ATTEMPT_MAX 1000000
#define OFFSET_MAX (1LL << 50)
#define FOLLOW_POLL_MS 1000
#define LOG_READ_BLOCK (256 * 1024)   /* bytes of chunks one callback reads from the store */
#define MARKER_MAX 320
#define MIB (1LL << 20)

struct log_reader {
	struct server *srv;
	long long id;
	int attempt;
	long long pos;            /* log offset of the next byte to read */
	long long until;          /* without follow: the end offset when the request came; -1 following */
	struct log_block block;   /* text read, sent up to `sent` */
	size_t sent;
	char marker[MARKER_MAX];  /* a marker line waiting to go out before the block */
	size_t marker_size, marker_sent;
};

static void reader_free(void *cls)
{
	struct log_reader *lr = cls;
	log_block_release(&lr->block);
	free(lr);
}

static void wait_for_chunk(struct server *srv, unsigned long long seq)
{
	long long until = now_ms() + FOLLOW_POLL_MS;
	struct timespec ts = { .tv_sec = (time_t)(until / 1000), .tv_nsec = (long)(until % 1000) * 1000000L };
	pthread_mutex_lock(&srv->wake_lock);
	int rc = 0;
	while (srv->log_seq == seq && !srv->stopping && rc != ETIMEDOUT)
		rc = pthread_cond_timedwait(&srv->log_cv, &srv->wake_lock, &ts);
	pthread_mutex_unlock(&srv->wake_lock);
}

static void format_size(long long bytes, char out[32])
{
	if (bytes % MIB == 0)
		snprintf(out, 32, "%lld MiB", bytes / MIB);
	else
		snprintf(out, 32, "%lld bytes", bytes);
}

/* The marker line for the dropped offsets [from, to). */
static void marker_set(struct log_reader *lr, long long from, long long to)
{
	long long cap = lr->srv->cfg.max_log_bytes;
	char head[32], tail[32];
	format_size(cap / 2, head);
	format_size(cap - cap / 2, tail);
	int n = snprintf(lr->marker, sizeof lr->marker,
			 "[poro-server: log bytes %lld..%lld of attempt %d were dropped: an attempt keeps its first %s"
			 " and last %s (--max-log-bytes)]\n", from, to, lr->attempt, head, tail);
	lr->marker_size = n > 0 && (size_t)n < sizeof lr->marker ? (size_t)n : 0;
	lr->marker_sent = 0;
}

/* Reads the next block (and the marker before it, if it starts past pos); 1 when there is
 * something to send, 0 at the end of the stream, -1 on a database error. */
static int reader_fill(struct log_reader *lr)
{
	for (;;) {
		if (lr->until >= 0 && lr->pos >= lr->until)
			return 0;
		struct server *srv = lr->srv;
		pthread_mutex_lock(&srv->wake_lock);
		unsigned long long seq = srv->log_seq;
		pthread_mutex_unlock(&srv->wake_lock);
		struct api_error err = { 0 };
		if (store_log_read(srv->store, lr->id, lr->attempt, lr->pos, lr->until, LOG_READ_BLOCK, &lr->block,
				   &err) != API_OK)
			return -1;
		lr->sent = 0;
		long long at = lr->block.at;
		if (lr->block.size == 0 && lr->until >= 0)
			at = lr->until; /* everything up to the end asked for was dropped meanwhile */
		if (at > lr->pos)
			marker_set(lr, lr->pos, at);
		lr->pos = at + (long long)lr->block.size;
		if (lr->marker_size || lr->block.size)
			return 1;
		if (lr->until >= 0 || !lr->block.live || srv->stopping)
			return 0;
		wait_for_chunk(srv, seq);
	}
}

static ssize_t reader_stream(void *cls, uint64_t pos, char *out, size_t max)
{
	struct log_reader *lr = cls;
	if (lr->marker_sent == lr->marker_size && lr->sent == lr->block.size) {
		lr->marker_size = lr->marker_sent = 0;
		int rc = reader_fill(lr);
		if (rc <= 0)
			return rc < 0 ? HTTP_STREAM_ERROR : HTTP_STREAM_END;
	}
	const char *from = lr->marker + lr->marker_sent;
	size_t left = lr->marker_size - lr->marker_sent;
	if (left == 0) {
		from = lr->block.text + lr->sent;
		left = lr->block.size - lr->sent;
	}
	size_t n = left < max ? left : max;
	memcpy(out, from, n);
	if (lr->marker_sent < lr->marker_size)
		lr->marker_sent += n;
	else
		lr->sent += n;
	return (ssize_t)n;
}

void logs_get(struct request *r)
{
	if (api_job_visible(r))
		return;
	long long attempt, offset, follow;
	if (api_query_int(r, "attempt", 0, ATTEMPT_MAX, -1, &attempt) ||
	    api_query_int(r, "offset", 0, OFFSET_MAX, 0, &offset) || api_query_int(r, "follow", 0, 1, 0, &follow))
		return;
	struct log_info info;
	struct api_error err = { 0 };
	if (store_log_info(r->srv->store, r->id, (int)attempt, &info, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	struct log_reader *lr = calloc(1, sizeof *lr);
	if (!lr) {
		reply_fail(r, API_UNAVAILABLE, "", "out of memory: retry later");
		return;
	}
	*lr = (struct log_reader){ .srv = r->srv, .id = r->id, .attempt = info.attempt, .pos = offset,
				   .until = follow ? -1 : (info.end > offset ? info.end : offset) };
	char value[32];
	snprintf(value, sizeof value, "%d", info.attempt);
	reply_header(r, "X-Log-Attempt", value);
	snprintf(value, sizeof value, "%lld", info.dropped_to - info.dropped_from);
	reply_header(r, "X-Log-Dropped-Bytes", value);
	if (!follow) {
		snprintf(value, sizeof value, "%lld", lr->until);
		reply_header(r, "X-Log-Next-Offset", value);
	}
	reply_stream(r, 200, "text/plain; charset=utf-8", reader_stream, lr, reader_free);
}
