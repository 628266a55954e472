/*
 * log_pump.c - the solver-output thread, see log_pump.h. The thread blocks in read(); everything it
 * shares with the job's thread is under p->lock. Lines are handled whole so that a chunk boundary
 * never splits a UTF-8 sequence and the parsers see complete reports.
 */
#include "log_pump.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Replaces every byte that is not part of a well-formed UTF-8 sequence by '?', in place. */
static void utf8_sanitize(char *s, size_t n)
{
	size_t i = 0;
	while (i < n) {
		unsigned char c = (unsigned char)s[i];
		size_t len = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
		int ok = len > 0 && i + len <= n && !(c == 0xc0 || c == 0xc1 || c > 0xf4);
		for (size_t k = 1; ok && k < len; k++)
			ok = ((unsigned char)s[i + k] & 0xc0) == 0x80;
		if (len == 1 && c == 0)
			ok = 0;
		if (!ok) {
			s[i++] = '?';
			continue;
		}
		i += len;
	}
}

/* Parses one complete line (without its newline) into the pump's state; under the lock. */
static void parse_line(struct log_pump *p, const char *line, size_t n)
{
	long step, total;
	double t, wall, us;
	if (sscanf(line, "step %ld/%ld t = %lf s wall = %lf s %lf us per material-point step", &step, &total,
		   &t, &wall, &us) == 5) {
		p->progress = (struct log_progress){1, step, total, t, us};
		return;
	}
	if (!strncmp(line, "checkpoint step=", 16)) {
		p->checkpoints++;
		return;
	}
	if (!strncmp(line, "poro-solve: ", 12)) {
		snprintf(p->error, sizeof p->error, "%.*s", (int)(n < LOG_PUMP_ERROR_MAX ? n : LOG_PUMP_ERROR_MAX),
			 line);
		return;
	}
	size_t have = strlen(p->error);
	if (have > 0 && n > 0 && have + 2 < LOG_PUMP_ERROR_MAX)
		snprintf(p->error + have, sizeof p->error - have, "; %.*s", (int)n, line);
}

/* Appends one line (with its newline, if it had one) to the unsent text. */
static void take_line(struct log_pump *p, char *line, size_t n)
{
	utf8_sanitize(line, n);
	if (p->file) {
		fwrite(line, 1, n, p->file);
		fflush(p->file);
	}
	pthread_mutex_lock(&p->lock);
	if (p->len + n > p->cap) {
		size_t cap = p->cap ? p->cap : 65536;
		while (cap < p->len + n)
			cap *= 2;
		char *q = realloc(p->text, cap);
		if (!q) {
			/* Out of memory: the line is lost from the remote log but the offsets stay true. */
			pthread_mutex_unlock(&p->lock);
			return;
		}
		p->text = q;
		p->cap = cap;
	}
	memcpy(p->text + p->len, line, n);
	p->len += n;
	p->total += (long long)n;
	size_t body = n > 0 && line[n - 1] == '\n' ? n - 1 : n;
	char saved = line[body];
	line[body] = '\0';
	parse_line(p, line, body);
	line[body] = saved;
	pthread_mutex_unlock(&p->lock);
}

static void *pump_main(void *arg)
{
	struct log_pump *p = arg;
	char buf[16384];
	for (;;) {
		ssize_t got = read(p->fd, buf, sizeof buf);
		if (got < 0 && errno == EINTR)
			continue;
		if (got <= 0)
			break;
		for (ssize_t i = 0; i < got; i++) {
			p->partial[p->partial_len++] = buf[i];
			if (buf[i] == '\n' || p->partial_len == sizeof p->partial) {
				take_line(p, p->partial, p->partial_len);
				p->partial_len = 0;
			}
		}
	}
	if (p->partial_len > 0) {
		/* a last line without a newline gets one, so the remote log ends cleanly */
		p->partial[p->partial_len++] = '\n'; /* room is left: full lines were taken above */
		take_line(p, p->partial, p->partial_len);
		p->partial_len = 0;
	}
	close(p->fd);
	pthread_mutex_lock(&p->lock);
	p->eof = 1;
	pthread_mutex_unlock(&p->lock);
	return NULL;
}

int log_pump_start(struct log_pump *p, int fd, const char *log_path)
{
	memset(p, 0, sizeof *p);
	p->fd = fd;
	p->file = log_path ? fopen(log_path, "w") : NULL;
	pthread_mutex_init(&p->lock, NULL);
	int rc = pthread_create(&p->thread, NULL, pump_main, p);
	if (rc) {
		if (p->file)
			fclose(p->file);
		pthread_mutex_destroy(&p->lock);
		errno = rc;
		return -1;
	}
	return 0;
}

void log_pump_release(struct log_pump *p)
{
	pthread_join(p->thread, NULL);
	if (p->file)
		fclose(p->file);
	pthread_mutex_destroy(&p->lock);
	free(p->text);
	p->text = NULL;
	p->len = p->cap = 0;
}

size_t log_pump_peek(struct log_pump *p, char *dst, size_t max, long long *offset)
{
	pthread_mutex_lock(&p->lock);
	size_t n = p->len < max ? p->len : max;
	if (n < p->len) {
		/* cut after the last newline inside the window, if there is one */
		size_t k = n;
		while (k > 0 && p->text[k - 1] != '\n')
			k--;
		if (k > 0)
			n = k;
	}
	memcpy(dst, p->text, n);
	*offset = p->acked;
	pthread_mutex_unlock(&p->lock);
	return n;
}

void log_pump_ack(struct log_pump *p, long long offset)
{
	pthread_mutex_lock(&p->lock);
	if (offset > p->acked && offset <= p->total) {
		size_t drop = (size_t)(offset - p->acked);
		memmove(p->text, p->text + drop, p->len - drop);
		p->len -= drop;
		p->acked = offset;
	}
	pthread_mutex_unlock(&p->lock);
}

long long log_pump_unsent(struct log_pump *p, int *eof)
{
	pthread_mutex_lock(&p->lock);
	long long n = (long long)p->len;
	if (eof)
		*eof = p->eof;
	pthread_mutex_unlock(&p->lock);
	return n;
}

struct log_progress log_pump_progress(struct log_pump *p)
{
	pthread_mutex_lock(&p->lock);
	struct log_progress g = p->progress;
	pthread_mutex_unlock(&p->lock);
	return g;
}

int log_pump_checkpoints(struct log_pump *p)
{
	pthread_mutex_lock(&p->lock);
	int n = p->checkpoints;
	pthread_mutex_unlock(&p->lock);
	return n;
}

void log_pump_error(struct log_pump *p, char *dst, size_t size)
{
	pthread_mutex_lock(&p->lock);
	snprintf(dst, size, "%s", p->error);
	pthread_mutex_unlock(&p->lock);
}
