/*
 * wait.c - following a job to its end (cli.h, cli_wait_job): `poro wait ID` and `poro submit
 * --wait`. The job is polled once a second. On a terminal (stdout and stderr both terminals) one
 * line on stderr is redrawn in place:
 *
 *     job 12 running [##########..........]  50%  0:12 elapsed  ~0:12 left  step 250
 *
 * fitted to the terminal's width (TIOCGWINSZ on stderr, else COLUMNS, else 80) so that it never
 * wraps: parts are dropped from the right end (step, time left, elapsed) before the bar shrinks
 * below BAR_MIN, and the line stays one column short of the width (a character in the last column
 * makes some terminals wrap). A queued job shows why it waits. A job that succeeds ends at 100%.
 * Elsewhere (a pipe, a file, a script capturing stdout) no bar: a line per change of state or of
 * the reason it waits, and per tenth of progress.
 *
 * Elapsed time is the current attempt's, from its started_at (the server's clock, which is the
 * client's on one host, and close to it elsewhere). Time left is extrapolated from the progress
 * seen since this command first saw the attempt running, so it needs two polls with progress
 * and it is not fooled by an attempt that resumed from a checkpoint part of the way in.
 */
#define _GNU_SOURCE
#include "cli.h"

#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#include "json_get.h"

/* Seconds between polls of the job. */
#define POLL_SECONDS 1.0
/* The bar's width between its brackets: at least, at most. */
#define BAR_MIN 10
#define BAR_MAX 40
/* Width assumed when neither the terminal nor COLUMNS says. */
#define COLUMNS_DEFAULT 80
#define LINE_MAX_BYTES 512

/* What the poller remembers between polls. */
struct watch {
	int bar;                      /* draw the bar (stdout and stderr are terminals) */
	char state[32];               /* last state shown in a line (no bar) */
	char reason[48];              /* last waiting reason shown in a line (no bar) */
	int tenth;                    /* last tenth of progress shown in a line (no bar) */
	long long attempt;            /* attempt the rate below belongs to, -1 none */
	double t0, f0;                /* first progress seen of that attempt: monotonic s, fraction */
};

static double monotonic(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Columns of the terminal on fd, else COLUMNS, else the default. */
static int terminal_columns(int fd)
{
	struct winsize ws;
	if (ioctl(fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0)
		return ws.ws_col;
	const char *env = getenv("COLUMNS");
	char *end;
	long n = env ? strtol(env, &end, 10) : 0;
	return env && *env && !*end && n > 0 && n < 10000 ? (int)n : COLUMNS_DEFAULT;
}

/* Seconds left, from the progress since the attempt was first seen running; < 0 when unknown. */
static double time_left(struct watch *w, long long attempt, double fraction)
{
	double now = monotonic();
	if (attempt != w->attempt) {
		w->attempt = attempt;
		w->t0 = now;
		w->f0 = fraction;
		return -1;
	}
	if (fraction <= w->f0 || now <= w->t0)
		return -1;
	return (1 - fraction) * (now - w->t0) / (fraction - w->f0);
}

/* Appends text to line[size] at *len, when it fits. */
static void put(char *line, size_t size, size_t *len, const char *text)
{
	size_t n = strlen(text);
	if (*len + n < size) {
		memcpy(line + *len, text, n + 1);
		*len += n;
	}
}

/* The bar line of a running (or just finished) job in at most width - 1 columns. */
static void bar_line(char *line, size_t size, int width, long long id, const char *state, double fraction,
		     const char *extras[], int extra_count)
{
	char head[64], pct[16];
	snprintf(head, sizeof head, "job %lld %-9s ", id, state);   /* succeeded and cancelled are the longest */
	snprintf(pct, sizeof pct, " %3.0f%%", 100 * fraction);
	int room = width - 1, fixed = (int)(strlen(head) + strlen(pct)) + 2;
	int used = 0, keep = extra_count;
	for (int i = 0; i < extra_count; i++)
		used += (int)strlen(extras[i]);
	while (keep > 0 && fixed + used + BAR_MIN > room)   /* drop the least useful first */
		used -= (int)strlen(extras[--keep]);
	int bar = room - fixed - used;
	if (bar > BAR_MAX)
		bar = BAR_MAX;
	size_t len = 0;
	line[0] = '\0';
	put(line, size, &len, head);
	if (bar >= BAR_MIN) {
		char cells[BAR_MAX + 3];
		int filled = (int)(fraction * bar + 0.5);
		cells[0] = '[';
		for (int i = 0; i < bar; i++)
			cells[1 + i] = i < filled ? '#' : '.';
		cells[bar + 1] = ']';
		cells[bar + 2] = '\0';
		put(line, size, &len, cells);
	}
	put(line, size, &len, pct);
	for (int i = 0; i < keep; i++)
		put(line, size, &len, extras[i]);
	while (len > 0 && line[len - 1] == ' ')   /* the caller pads to the width anyway */
		line[--len] = '\0';
	if ((int)len > room)   /* a terminal narrower than the head and the percentage */
		line[room > 0 ? room : 0] = '\0';
}

/* The parts after the percentage, in the order they are given up on a narrow terminal: elapsed,
 * time left, step. Each has a fixed width, blank while unknown, so the bar keeps its length from
 * one poll to the next. The step is left out once the job has ended (its last report may be
 * older than its end). */
static int extras_of(const json_t *job, double left, int going, char bufs[3][48], const char *extras[3])
{
	enum { ELAPSED_WIDTH = 17, LEFT_WIDTH = 15, STEP_WIDTH = 17 };   /* "  1:23:45 elapsed" ... */
	char d[32], text[48];
	double elapsed = cli_job_elapsed(job);
	const json_t *p = json_object_get(job, "progress");
	snprintf(text, sizeof text, "  %s elapsed", cli_duration(elapsed, d));
	snprintf(bufs[0], 48, "%-*s", ELAPSED_WIDTH, elapsed >= 0 ? text : "");
	snprintf(text, sizeof text, "  ~%s left", cli_duration(left, d));
	snprintf(bufs[1], 48, "%-*s", LEFT_WIDTH, left >= 0 ? text : "");
	snprintf(text, sizeof text, "  step %lld", json_get_int(p, "step", 0));
	snprintf(bufs[2], 48, "%-*s", STEP_WIDTH, json_is_object(p) && going ? text : ""); /* a step of the end is not known */
	for (int i = 0; i < 3; i++)
		extras[i] = bufs[i];
	return 3;
}

/* Draws the bar line of job on stderr (fraction forced to 1 for a success). */
static void draw_bar(struct watch *w, long long id, const json_t *job)
{
	const char *state = json_get_str(job, "state", "?");
	int width = terminal_columns(STDERR_FILENO);
	char line[LINE_MAX_BYTES];
	if (!strcmp(state, "queued")) {
		char d[32];
		const char *why = cli_waiting_phrase(job);
		double created = cli_parse_time(json_get_str(job, "created_at", NULL));
		snprintf(line, sizeof line, "job %lld queued%s%s (%s)", id, why ? ": " : "", why ? why : "",
			 cli_duration(created >= 0 ? cli_now() - created : -1, d));
		if ((int)strlen(line) > width - 1)
			line[width > 1 ? width - 1 : 0] = '\0';
	} else {
		const json_t *p = json_object_get(job, "progress");
		double fraction = !strcmp(state, "succeeded") ? 1 : json_get_real(p, "fraction", 0);
		fraction = fraction < 0 ? 0 : fraction > 1 ? 1 : fraction;
		int going = !cli_terminal(state);
		double left = json_is_object(p) && going ? time_left(w, json_get_int(job, "attempt", 0), fraction) : -1;
		char bufs[3][48];
		const char *extras[3];
		int n = extras_of(job, left, going, bufs, extras);
		bar_line(line, sizeof line, width, id, state, fraction, extras, n);
	}
	/* overwrite the previous line whole: pad with spaces up to the last usable column */
	fprintf(stderr, "\r%-*s", width - 1 > 0 ? width - 1 : 0, line);
	fflush(stderr);
}

/* Without a bar: a line when the state or the reason it waits changes, or progress passes a tenth. */
static void draw_line(struct watch *w, long long id, const json_t *job)
{
	const char *state = json_get_str(job, "state", "?");
	const json_t *waiting = json_object_get(job, "waiting");
	const char *reason = json_get_str(waiting, "reason", "");
	const json_t *p = json_object_get(job, "progress");
	double fraction = json_get_real(p, "fraction", 0);
	int tenth = (int)(fraction * 10);
	/* every poll with progress counts for the rate, printed or not */
	double left = json_is_object(p) ? time_left(w, json_get_int(job, "attempt", 0), fraction) : -1;
	if (!strcmp(state, w->state) && !strcmp(reason, w->reason) && tenth <= w->tenth)
		return;
	if (!strcmp(state, "queued")) {
		fprintf(stderr, "job %lld queued%s%s\n", id, *reason ? ": " : "",
			json_get_str(waiting, "message", ""));
	} else if (json_is_object(p)) {
		char e[32], l[32];
		fprintf(stderr, "job %lld %s: %.0f%%, step %lld, t = %.4g s, %s elapsed%s%s%s\n", id, state,
			100 * fraction, json_get_int(p, "step", 0), json_get_real(p, "time", 0),
			cli_duration(cli_job_elapsed(job), e), left >= 0 ? ", ~" : "", left >= 0 ? cli_duration(left, l) : "",
			left >= 0 ? " left" : "");
	} else {
		fprintf(stderr, "job %lld %s\n", id, state);
	}
	snprintf(w->state, sizeof w->state, "%s", state);
	snprintf(w->reason, sizeof w->reason, "%s", reason);
	w->tenth = tenth;
}

/* The last words: "job 12 succeeded in 0:07", or the state with the job's message. */
static void say_end(long long id, const json_t *job)
{
	char d[32];
	const char *state = json_get_str(job, "state", "?"), *message = json_get_str(job, "message", NULL);
	double elapsed = cli_job_elapsed(job);
	fprintf(stderr, "job %lld %s", id, state);
	if (elapsed >= 0)
		fprintf(stderr, " after %s", cli_duration(elapsed, d));
	if (message && *message)
		fprintf(stderr, ": %s", message);
	fputc('\n', stderr);
}

int cli_wait_job(long long id, int json)
{
	struct watch w = { .bar = isatty(STDOUT_FILENO) && isatty(STDERR_FILENO), .tenth = -1, .attempt = -1 };
	for (;;) {
		struct http_response r;
		if (cli_get_job(id, &r) != 200) {
			if (w.bar)
				fputc('\n', stderr);
			return cli_fail(&r);
		}
		const char *state = json_get_str(r.json, "state", "?");
		int done = cli_terminal(state);
		if (w.bar)
			draw_bar(&w, id, r.json);
		else if (!done)
			draw_line(&w, id, r.json);
		if (done) {
			if (w.bar)
				fputc('\n', stderr);
			say_end(id, r.json);
			int rc = cli_exit_of_state(state);
			if (json && cli_print_json(r.json) != PORO_EXIT_OK)
				rc = PORO_EXIT_ERROR;
			http_response_release(&r);
			return rc;
		}
		http_response_release(&r);
		cli_sleep(POLL_SECONDS);
	}
}
