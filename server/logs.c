/*
 * logs.c - reading a job's log (GET /v1/jobs/{id}/log): the text of one attempt from an offset,
 * or with follow=1 a chunked stream that delivers new chunks as workers append them and ends when
 * the attempt ends (finish, expiry, cancel) or the server stops.
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

struct follow {
	struct server *srv;
	long long id, offset;
	int attempt;
	char *buf;                /* text read but not yet sent */
	size_t size, sent;
};

static void follow_free(void *cls)
{
	struct follow *f = cls;
	free(f->buf);
	free(f);
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

static ssize_t follow_read(void *cls, uint64_t pos, char *out, size_t max)
{
	struct follow *f = cls;
	while (f->sent == f->size) {
		free(f->buf);
		f->buf = NULL;
		f->size = f->sent = 0;
		pthread_mutex_lock(&f->srv->wake_lock);
		unsigned long long seq = f->srv->log_seq;
		pthread_mutex_unlock(&f->srv->wake_lock);
		int live = 0;
		struct api_error err = { 0 };
		if (store_log_read(f->srv->store, f->id, &f->attempt, f->offset, &f->buf, &f->size, &live, &err) != API_OK)
			return HTTP_STREAM_ERROR;
		f->offset += (long long)f->size;
		if (f->size)
			break;
		if (!live || f->srv->stopping)
			return HTTP_STREAM_END;
		wait_for_chunk(f->srv, seq);
	}
	size_t n = f->size - f->sent < max ? f->size - f->sent : max;
	memcpy(out, f->buf + f->sent, n);
	f->sent += n;
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
	int at = (int)attempt;
	if (follow) {
		struct follow *f = calloc(1, sizeof *f);
		if (!f) {
			reply_fail(r, API_INTERNAL, "", "out of memory");
			return;
		}
		*f = (struct follow){ .srv = r->srv, .id = r->id, .offset = offset, .attempt = at };
		reply_stream(r, 200, "text/plain; charset=utf-8", follow_read, f, follow_free);
		return;
	}
	char *text = NULL;
	size_t size = 0;
	int live = 0;
	struct api_error err = { 0 };
	if (store_log_read(r->srv->store, r->id, &at, offset, &text, &size, &live, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	char value[32];
	snprintf(value, sizeof value, "%d", at);
	reply_header(r, "X-Log-Attempt", value);
	snprintf(value, sizeof value, "%lld", offset + (long long)size);
	reply_header(r, "X-Log-Next-Offset", value);
	reply_text(r, 200, "text/plain; charset=utf-8", text, size);
}
