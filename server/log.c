/*
 * log.c - poro-server's log lines in logfmt, to stderr and (request lines) to --access-log
 * (log.h).
 *
 * Why logfmt and not JSON lines: the same line is read by people (the terminal of `make run`,
 * `journalctl -u poro-server`, which shows the message as it is) and by log tools (Loki, Vector,
 * lnav and hl parse logfmt; journalctl -o json wraps a line in MESSAGE either way). A logfmt line
 * reads like a sentence of fields; a JSON line needs a tool before a person can read it, and
 * after the journal's "<6>" prefix is stripped both carry the same fields.
 *
 * Quoting: a value is bare when it is non-empty and holds no space, '"', '=', '\' or control
 * character; else it is quoted, with '"' and '\' escaped and control characters written as
 * \n, \r, \t or \u00XX. Bytes of 0x80 and above pass as they are (UTF-8 stays readable).
 */
#define _GNU_SOURCE /* struct iovec in sys/uio.h with -std=c11 */
#include "log.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <time.h>
#include <unistd.h>

#define ELLIPSIS "..."

static int journal; /* stderr is the journal: "<N>" prefixes, no time */
static int access_fd = -1;

/* JOURNAL_STREAM is "DEVICE:INODE" of the stream systemd connected to stdout and stderr; it is
 * stderr only when both numbers match stderr's (a child whose stderr was redirected inherits the
 * variable, sd_journal_stream_fd(3)). */
static int stderr_is_journal(void)
{
	const char *v = getenv("JOURNAL_STREAM");
	unsigned long long dev, ino;
	struct stat st;
	if (!v || sscanf(v, "%llu:%llu", &dev, &ino) != 2 || fstat(STDERR_FILENO, &st) != 0)
		return 0;
	return (unsigned long long)st.st_dev == dev && (unsigned long long)st.st_ino == ino;
}

void log_setup(void)
{
	journal = stderr_is_journal();
}

void log_set_access_fd(int fd)
{
	access_fd = fd;
}

static const char *level_name(enum log_priority p)
{
	switch (p) {
	case LOG_PRIO_ERR: return "error";
	case LOG_PRIO_WARNING: return "warning";
	case LOG_PRIO_NOTICE: return "notice";
	default: return "info";
	}
}

/* Room kept at the end of a line for a cut value: its '"', "..." and closing '"'. */
#define TAIL_ROOM (sizeof ELLIPSIS + 2)

static void put_raw(struct log_line *l, const char *s, size_t n)
{
	if (l->size + n > sizeof l->text - TAIL_ROOM) {
		l->full = 1;
		return;
	}
	memcpy(l->text + l->size, s, n);
	l->size += n;
}

static int needs_quotes(const char *v)
{
	if (!*v)
		return 1;
	for (const unsigned char *p = (const unsigned char *)v; *p; p++)
		if (*p <= ' ' || *p == '"' || *p == '=' || *p == '\\' || *p == 0x7f)
			return 1;
	return 0;
}

/* c as it stands inside quotes, into buf[8]; returns its length */
static size_t escape(unsigned char c, char *buf)
{
	switch (c) {
	case '"':
	case '\\':
		buf[0] = '\\';
		buf[1] = (char)c;
		return 2;
	case '\n': memcpy(buf, "\\n", 2); return 2;
	case '\r': memcpy(buf, "\\r", 2); return 2;
	case '\t': memcpy(buf, "\\t", 2); return 2;
	default:
		if (c < ' ' || c == 0x7f)
			return (size_t)snprintf(buf, 8, "\\u%04x", c);
		buf[0] = (char)c;
		return 1;
	}
}

/* A quoted value, cut with "..." where the line ends. Called with at least TAIL_ROOM bytes left,
 * which always hold the opening quote, "..." and the closing quote. */
static void put_quoted(struct log_line *l, const char *v)
{
	size_t limit = sizeof l->text - (sizeof ELLIPSIS - 1) - 1; /* what a cut leaves for "..." and '"' */
	l->text[l->size++] = '"';
	for (const unsigned char *p = (const unsigned char *)v; *p; p++) {
		char buf[8];
		size_t n = escape(*p, buf);
		if (l->size + n > limit) {
			if ((*p & 0xc0) == 0x80) { /* cut inside a UTF-8 sequence: drop its first bytes too */
				while (((unsigned char)l->text[l->size - 1] & 0xc0) == 0x80)
					l->size--;
				if ((unsigned char)l->text[l->size - 1] >= 0xc0)
					l->size--;
			}
			memcpy(l->text + l->size, ELLIPSIS, sizeof ELLIPSIS - 1);
			l->size += sizeof ELLIPSIS - 1;
			l->full = 1;
			break;
		}
		memcpy(l->text + l->size, buf, n);
		l->size += n;
	}
	l->text[l->size++] = '"';
}

void log_line_str(struct log_line *l, const char *key, const char *value)
{
	if (!value || l->full)
		return;
	size_t before = l->size;
	if (l->size)
		put_raw(l, " ", 1);
	put_raw(l, key, strlen(key));
	put_raw(l, "=", 1);
	if (l->full) { /* not even the key fits: the field is left out */
		l->size = before;
		return;
	}
	size_t n = strlen(value);
	if (!needs_quotes(value) && l->size + n <= sizeof l->text - TAIL_ROOM) {
		memcpy(l->text + l->size, value, n);
		l->size += n;
		return;
	}
	put_quoted(l, value);
}

void log_line_int(struct log_line *l, const char *key, long long value)
{
	char text[24];
	snprintf(text, sizeof text, "%lld", value);
	log_line_str(l, key, text);
}

void log_line_ms(struct log_line *l, const char *key, double ms)
{
	char text[32];
	snprintf(text, sizeof text, "%.3f", ms);
	log_line_str(l, key, text);
}

void log_line_begin(struct log_line *l, enum log_priority priority, const char *msg)
{
	l->priority = priority;
	l->access = 0;
	l->full = 0;
	l->size = 0;
	log_line_str(l, "level", level_name(priority));
	log_line_str(l, "msg", msg);
}

void log_line_begin_request(struct log_line *l, enum log_priority priority)
{
	log_line_begin(l, priority, "request");
	l->access = 1;
}

/* "time=2026-12-07T11:33:00.123Z " */
static size_t time_prefix(char *out, size_t size)
{
	struct timespec ts;
	struct tm tm;
	clock_gettime(CLOCK_REALTIME, &ts);
	gmtime_r(&ts.tv_sec, &tm);
	char date[24];
	strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%S", &tm);
	int n = snprintf(out, size, "time=%s.%03ldZ ", date, ts.tv_nsec / 1000000);
	return n > 0 && (size_t)n < size ? (size_t)n : 0;
}

/* prefix, text, newline in one writev: one line, never mixed with another thread's */
static void write_line(int fd, const char *prefix, size_t prefix_size, const struct log_line *l)
{
	struct iovec iov[3] = {
		{ (void *)prefix, prefix_size },
		{ (void *)l->text, l->size },
		{ "\n", 1 },
	};
	if (writev(fd, iov, 3) < 0) {
		/* a lost log line must not fail what was being logged */
	}
}

void log_line_end(struct log_line *l)
{
	char stamp[48], prio[8];
	size_t stamp_size = time_prefix(stamp, sizeof stamp);
	if (journal) {
		int n = snprintf(prio, sizeof prio, "<%d>", (int)l->priority);
		write_line(STDERR_FILENO, prio, (size_t)n, l);
	} else {
		write_line(STDERR_FILENO, stamp, stamp_size, l);
	}
	if (l->access && access_fd >= 0)
		write_line(access_fd, stamp, stamp_size, l);
}

void log_say(enum log_priority priority, const char *fmt, ...)
{
	char msg[LOG_LINE_MAX];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	struct log_line l;
	log_line_begin(&l, priority, msg);
	log_line_end(&l);
}
