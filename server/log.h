/*
 * log.h - the one way poro-server writes its log (docs/service.md §8 "The server's log"): every
 * line, whether a request, a job's change of state or a message, is one line of logfmt
 * (`key=value` pairs separated by spaces, a value quoted when it holds a space, a quote, an
 * equals sign or a control character), written with one write(2) so lines of concurrent threads
 * never interleave.
 *
 *   level=info msg=request method=GET route=/v1/jobs/{id} status=200 duration_ms=0.412 user=alice client=127.0.0.1
 *   level=info msg=job_state job=12 from=queued to=running attempt=1 worker=node3:4711 actor=node3:4711 reason="claimed on host 'node3'"
 *   level=warning msg="cannot make '/var/lib/poro/poro.db' private to its owner: Operation not permitted"
 *
 * When stderr is the systemd journal (JOURNAL_STREAM names stderr's device and inode,
 * systemd.exec(5)), each line starts with the sd-daemon(3) priority prefix ("<6>" for info), so
 * journalctl -p filters by level, and carries no time (the journal stamps every line). Otherwise
 * each line starts with time=RFC-3339-UTC. Request lines are also appended to --access-log when it
 * is set, with their time and without a prefix.
 *
 * What is never logged: a token, a request's query string or its raw path (a request is named by
 * its route pattern), a request body. Callers pass only values that hold none of these.
 * Messages follow STYLE rule 13 (lower case, what failed first); the gateway adds no
 * "poro-server:" prefix, the journal and the time stamp say where and when.
 */
#ifndef PORO_LOG_H
#define PORO_LOG_H

#include <stddef.h>

/* Priorities of syslog(3) and sd-daemon(3), the ones the server uses. */
enum log_priority {
	LOG_PRIO_ERR = 3,
	LOG_PRIO_WARNING = 4,
	LOG_PRIO_NOTICE = 5,
	LOG_PRIO_INFO = 6,
};

/* Longest line, bytes: a value that would pass it is cut and ends in "..." (still quoted), and
 * the fields after it are dropped. A job's reason (a solver's error lines) is the long one. */
#define LOG_LINE_MAX 4096

/* A line being built on the stack; nothing is allocated, so logging works when memory ran out. */
struct log_line {
	int priority;
	int access; /* a request line: also to --access-log */
	int full;   /* a value was cut: add nothing more */
	size_t size;
	char text[LOG_LINE_MAX]; /* "level=... msg=... key=value ...", no newline */
};

/* Reads JOURNAL_STREAM: called once, first thing, before any thread logs. Without it lines are
 * plain (time=...). */
void log_setup(void);
/* Request lines also go to fd (--access-log; -1 for none; not owned). Set before threads start. */
void log_set_access_fd(int fd);

/* Starts a line: level=NAME msg=MSG (MSG quoted when it needs to be). */
void log_line_begin(struct log_line *l, enum log_priority priority, const char *msg);
/* Starts a request line (msg=request), which log_line_end also appends to --access-log. */
void log_line_begin_request(struct log_line *l, enum log_priority priority);
/* Adds key=value; a NULL value adds nothing. */
void log_line_str(struct log_line *l, const char *key, const char *value);
void log_line_int(struct log_line *l, const char *key, long long value);
/* Adds key=value with three decimals (milliseconds). */
void log_line_ms(struct log_line *l, const char *key, double ms);
/* Writes the line. */
void log_line_end(struct log_line *l);

/* A message line: level=NAME msg="TEXT" with TEXT formatted by printf. */
void log_say(enum log_priority priority, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
