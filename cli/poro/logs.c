/*
 * logs.c - `poro logs [-f] ID` (cli.h): a job's log as it stands, or followed (-f) through every
 * attempt until the job ends, exiting with the job's outcome (0 succeeded, 7 failed, 8 cancelled,
 * cli.h), as `poro wait` does. A broken stream resumes at the log offset it reached.
 *
 * Where a follower is in the log: bytes received are not log bytes once the server put a marker
 * line in place of dropped bytes (docs/service.md §2, "Logs"): the marker names the dropped
 * offsets A..B, and the bytes after it continue at log offset B. A line counts as the marker only
 * when A is the log offset at which the marker text starts, so a solver line that merely looks like
 * one does not move the offset.
 */
#define _GNU_SOURCE
#include "cli.h"

#include <string.h>

#include "json_get.h"

#define LOG_MARKER_PREFIX "[poro-server: log bytes "
#define LOG_MARKER_MAX 400
/* Seconds between looks at a job whose log cannot be followed yet (queued, re-queued). */
#define LOG_POLL_SECONDS 1.0

struct log_place {
	long long start;          /* log offset the stream began at */
	long long seen;           /* stream bytes of the lines passed so far, newlines included */
	long long marker_log;     /* log offset after the last marker line, or -1 */
	long long marker_stream;  /* stream bytes up to the end of that marker line */
};

static int print_line(const char *line, size_t len, void *user)
{
	(void)user;
	fwrite(line, 1, len, stdout);
	putchar('\n');
	fflush(stdout);
	return 0;
}

/* The log offset reached after stream bytes of the current stream. */
static long long place_offset(const struct log_place *p, long long stream_bytes)
{
	return p->marker_log >= 0 ? p->marker_log + (stream_bytes - p->marker_stream) : p->start + stream_bytes;
}

static int follow_line(const char *line, size_t len, void *user)
{
	struct log_place *p = user;
	const char *m = memmem(line, len, LOG_MARKER_PREFIX, strlen(LOG_MARKER_PREFIX));
	if (m) {
		char text[LOG_MARKER_MAX];
		size_t n = len - (size_t)(m - line) < sizeof text - 1 ? len - (size_t)(m - line) : sizeof text - 1;
		memcpy(text, m, n);
		text[n] = '\0';
		long long from, to;
		if (sscanf(text + strlen(LOG_MARKER_PREFIX), "%lld..%lld", &from, &to) == 2 &&
		    from == place_offset(p, p->seen) + (m - line) && to >= from) {
			p->marker_log = to;
			p->marker_stream = p->seen + (long long)len + 1;
		}
	}
	p->seen += (long long)len + 1;
	return print_line(line, len, NULL);
}

/* The job's state and attempt: 0, or the exit status after reporting a failed request. */
static int job_state(long long id, char *state, size_t size, long long *attempt)
{
	struct http_response r;
	if (cli_get_job(id, &r) != 200)
		return cli_fail(&r);
	snprintf(state, size, "%s", json_get_str(r.json, "state", "?"));
	*attempt = json_get_int(r.json, "attempt", 0);
	http_response_release(&r);
	return 0;
}

/* Follows the log of every attempt until the job ends; returns the exit status of its end. */
static int follow_log(long long id)
{
	char state[32], path[160];
	long long attempt, followed = -1, offset = 0;
	int rc;
	for (;;) {
		if ((rc = job_state(id, state, sizeof state, &attempt)))
			return rc;
		if (attempt == 0 && cli_terminal(state))
			return cli_exit_of_state(state); /* ended without ever running: there is no log */
		if (attempt != followed && !strcmp(state, "queued") && attempt >= followed) {
			/* not running yet (or re-queued): nothing new to follow */
			cli_sleep(LOG_POLL_SECONDS);
			continue;
		}
		if (attempt != followed) {
			if (followed >= 0)
				fprintf(stderr, "poro: job %lld attempt %lld\n", id, attempt);
			followed = attempt;
			offset = 0;
		}
		snprintf(path, sizeof path, "/v1/jobs/%lld/log?attempt=%lld&offset=%lld&follow=1", id, attempt, offset);
		struct http_response r;
		struct log_place place = { .start = offset, .marker_log = -1 };
		long long got = 0;
		long status = http_stream_lines(cli_http, path, follow_line, &place, &got, &r);
		offset = place_offset(&place, got);
		if (status != 0 && !http_ok(&r))
			return cli_fail(&r);
		http_response_release(&r);
		if ((rc = job_state(id, state, sizeof state, &attempt)))
			return rc;
		if (cli_terminal(state) && attempt == followed && status != 0)
			return cli_exit_of_state(state);
		if (status == 0 || attempt == followed)
			cli_sleep(LOG_POLL_SECONDS);
	}
}

int cmd_logs(const struct subcommand *self, int argc, char **argv)
{
	static const struct option opts[] = {
		{ "follow", no_argument, NULL, 'f' }, { "help", no_argument, NULL, 'h' }, { NULL, 0, NULL, 0 }
	};
	int follow = 0, c, rc;
	while ((c = getopt_long(argc, argv, "hf", opts, NULL)) != -1) {
		if (c == 'h')
			return cli_help(self);
		if (c != 'f')
			return cli_usage_error(self, NULL);
		follow = 1;
	}
	long long id;
	if ((rc = cli_positional(self, argc, argv, 1, "the job ID")) || (rc = cli_parse_id(self, argv[optind], &id)) ||
	    (rc = cli_connect()))
		return rc;
	if (follow)
		return follow_log(id);
	char path[64];
	snprintf(path, sizeof path, "/v1/jobs/%lld/log", id);
	struct http_response r;
	http_stream_lines(cli_http, path, print_line, NULL, NULL, &r);
	rc = http_ok(&r) ? PORO_EXIT_OK : cli_report(&r);
	http_response_release(&r);
	return rc;
}
