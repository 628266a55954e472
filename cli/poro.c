/*
 * poro.c - the user's command line for the job service (docs/service.md §3 "Users"):
 *
 *   poro submit CASE.json [--wait] [--priority N] [--threads N] [--wall-time S] [--name NAME]
 *                         [--idempotency-key K]
 *   poro ls [--state S[,S]] [--limit N]
 *   poro show ID
 *   poro logs [-f] ID
 *   poro cancel ID
 *   poro rm ID                  (a finished job and everything stored for it)
 *   poro fetch ID [--out DIR]
 *   poro token ls
 *   poro token revoke ID
 *
 * The server URL and token come from PORO_SERVER and PORO_TOKEN, else ~/.config/poro/config.
 * A submission always carries an Idempotency-Key (a random one unless --idempotency-key), so a
 * submission whose answer was lost is retried without creating a second job. Errors from the
 * server print as "poro: <message> (<code>, field <pointer>)". Exit status: 0 success; 1 a failed
 * request, or with --wait a job that failed or was cancelled; 2 a bad command line.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "client_config.h"
#include "digest.h"
#include "http_client.h"
#include "json_get.h"

/* Retries of a submission or status poll that got no answer, and the first delay, seconds. */
#define PORO_RETRIES 3
#define PORO_RETRY_FIRST 0.5
/* Seconds between status polls while waiting for a job. */
#define PORO_POLL 1.0
#define PORO_BAR_WIDTH 30

static struct http_client *http;
static struct client_config cfg;

static int usage(void)
{
	fprintf(stderr,
		"usage: poro submit CASE.json [--wait] [--priority N] [--threads N] [--wall-time S] [--name NAME]\n"
		"                             [--idempotency-key K]\n"
		"       poro ls [--state S[,S...]] [--limit N]\n"
		"       poro show ID\n"
		"       poro logs [-f] ID\n"
		"       poro cancel ID\n"
		"       poro rm ID\n"
		"       poro fetch ID [--out DIR]\n"
		"       poro token ls | poro token revoke ID\n"
		"server and token from PORO_SERVER and PORO_TOKEN, else ~/.config/poro/config\n");
	return 2;
}

static void sleep_s(double s)
{
	struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
	nanosleep(&ts, NULL);
}

/* Prints a failed call and returns 1. */
static int report(const struct http_response *r)
{
	if (r->status == 0)
		fprintf(stderr, "poro: cannot reach '%s': %s\n", cfg.server, r->error);
	else if (r->code[0] && r->field[0])
		fprintf(stderr, "poro: %s (%s, field %s)\n", r->error, r->code, r->field);
	else if (r->code[0])
		fprintf(stderr, "poro: %s (%s)\n", r->error, r->code);
	else
		fprintf(stderr, "poro: %s\n", r->error);
	return 1;
}

/* Reports a failed response, releases it and gives the exit status: `return fail(&r);`. */
static int fail(struct http_response *r)
{
	int rc = report(r);
	http_response_release(r);
	return rc;
}

/* GET or POST with a few retries while the server cannot be reached; the request must be safe
 * to repeat (GET, or POST with an idempotency key). */
static long call(const char *method, const char *path, const json_t *body, const char *header,
		 struct http_response *r)
{
	double wait = PORO_RETRY_FIRST;
	for (int i = 0;; i++) {
		http_json(http, method, path, body, header, 60, r);
		if (!http_transient(r) || i == PORO_RETRIES)
			return r->status;
		http_response_release(r);
		sleep_s(wait);
		wait *= 2;
	}
}

/* GET /v1/jobs/{id}: the job, with its files and events. */
static long get_job(long long id, struct http_response *r)
{
	char path[64];
	snprintf(path, sizeof path, "/v1/jobs/%lld", id);
	return call("GET", path, NULL, NULL, r);
}

static int parse_id(const char *s, long long *id)
{
	char *end;
	errno = 0;
	long long v = strtoll(s, &end, 10);
	if (errno || *end || end == s || v < 0) {
		fprintf(stderr, "poro: '%s' is not a job id\n", s);
		return -1;
	}
	*id = v;
	return 0;
}

static int parse_int(const char *flag, const char *s, long long lo, long long hi, long long *out)
{
	char *end;
	errno = 0;
	long long v = strtoll(s ? s : "", &end, 10);
	if (!s || errno || *end || end == s || v < lo || v > hi) {
		fprintf(stderr, "poro: %s needs an integer in %lld..%lld\n", flag, lo, hi);
		return -1;
	}
	*out = v;
	return 0;
}

static int terminal(const char *state)
{
	return !strcmp(state, "succeeded") || !strcmp(state, "failed") || !strcmp(state, "cancelled");
}

/* ---- waiting with a progress bar -------------------------------------------------------------- */

static void draw_progress(long long id, const json_t *job, int tty, int *last_decile, char *last_state)
{
	const char *state = json_get_str(job, "state", "?");
	const json_t *p = json_object_get(job, "progress");
	double fraction = json_get_real(p, "fraction", 0);
	long long step = json_get_int(p, "step", 0);
	double t = json_get_real(p, "time", 0);
	if (tty) {
		char bar[PORO_BAR_WIDTH + 1];
		int filled = (int)(fraction * PORO_BAR_WIDTH + 0.5);
		for (int i = 0; i < PORO_BAR_WIDTH; i++)
			bar[i] = i < filled ? '#' : '.';
		bar[PORO_BAR_WIDTH] = '\0';
		fprintf(stderr, "\rjob %lld %-9s [%s] %3.0f%%  step %lld  t = %.4g s   ", id, state, bar, 100 * fraction,
			step, t);
		fflush(stderr);
		return;
	}
	int decile = (int)(fraction * 10);
	if (strcmp(state, last_state) || decile > *last_decile) {
		if (json_is_object(p))
			fprintf(stderr, "job %lld %s: %.0f%%, step %lld, t = %.4g s\n", id, state, 100 * fraction, step, t);
		else
			fprintf(stderr, "job %lld %s\n", id, state);
		*last_decile = decile;
		snprintf(last_state, 32, "%s", state);
	}
}

static int wait_job(long long id)
{
	char last_state[32] = "";
	int tty = isatty(2), last_decile = -1;
	for (;;) {
		struct http_response r;
		if (get_job(id, &r) != 200) {
			if (tty)
				fputc('\n', stderr);
			return fail(&r);
		}
		const char *state = json_get_str(r.json, "state", "?");
		if (tty || !terminal(state))   /* the final state gets its own line below */
			draw_progress(id, r.json, tty, &last_decile, last_state);
		if (terminal(state)) {
			if (tty)
				fputc('\n', stderr);
			const char *message = json_get_str(r.json, "message", "");
			int ok = !strcmp(state, "succeeded");
			fprintf(stderr, "job %lld %s%s%s\n", id, state, message && *message ? ": " : "", message ? message : "");
			http_response_release(&r);
			return ok ? 0 : 1;
		}
		http_response_release(&r);
		sleep_s(PORO_POLL);
	}
}

/* ---- commands ----------------------------------------------------------------------------------- */

static int cmd_submit(int argc, char **argv)
{
	const char *file = NULL, *name = NULL, *key = NULL;
	long long priority = 0, threads = 0, wall = 0;
	int wait = 0, have_priority = 0;
	for (int i = 0; i < argc; i++) {
		const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
		if (!strcmp(a, "--wait"))
			wait = 1;
		else if (!strcmp(a, "--priority") && ++i && !parse_int(a, v, -100, 100, &priority))
			have_priority = 1;
		else if (!strcmp(a, "--threads") && ++i && !parse_int(a, v, 1, 256, &threads))
			;
		else if (!strcmp(a, "--wall-time") && ++i && !parse_int(a, v, 1, 2592000, &wall))
			;
		else if (!strcmp(a, "--name") && v && ++i)
			name = v;
		else if (!strcmp(a, "--idempotency-key") && v && ++i)
			key = v;
		else if (a[0] != '-' && !file)
			file = a;
		else
			return usage();
	}
	if (!file)
		return usage();
	json_error_t jerr;
	json_t *spec = json_load_file(file, 0, &jerr);
	if (!spec) {
		fprintf(stderr, "poro: cannot read '%s': %s (line %d)\n", file, jerr.text, jerr.line);
		return 1;
	}
	json_t *body = json_pack("{s:o}", "case", spec);
	if (have_priority)
		json_object_set_new(body, "priority", json_integer(priority));
	if (threads)
		json_object_set_new(body, "threads", json_integer(threads));
	if (wall)
		json_object_set_new(body, "wall_time_seconds", json_integer(wall));
	if (name)
		json_object_set_new(body, "name", json_string(name));
	char token[DIGEST_TOKEN_SIZE], header[300];
	if (!key) {
		if (digest_new_token(token) < 0) {
			fprintf(stderr, "poro: no randomness for an idempotency key\n");
			json_decref(body);
			return 1;
		}
		key = token + 5; /* without the "poro_" prefix of tokens */
	}
	snprintf(header, sizeof header, "Idempotency-Key: %s", key);
	struct http_response r;
	long status = call("POST", "/v1/jobs", body, header, &r);
	json_decref(body);
	if (status != 200 && status != 201) {
		int rc = report(&r);
		const json_t *problems = json_object_get(r.json, "problems");
		size_t i;
		json_t *p;
		json_array_foreach(problems, i, p)
			fprintf(stderr, "  %s: %s\n", json_get_str(p, "field", "?"), json_get_str(p, "message", "?"));
		http_response_release(&r);
		return rc;
	}
	long long id = json_get_int(r.json, "id", -1);
	printf("%lld\n", id);
	fflush(stdout);
	http_response_release(&r);
	return wait ? wait_job(id) : 0;
}

static int cmd_ls(int argc, char **argv)
{
	const char *state = NULL;
	long long limit = 100;
	for (int i = 0; i < argc; i++) {
		const char *v = i + 1 < argc ? argv[i + 1] : NULL;
		if (!strcmp(argv[i], "--state") && v)
			state = argv[++i];
		else if (!strcmp(argv[i], "--limit") && !parse_int("--limit", v, 1, 1000, &limit))
			i++;
		else
			return usage();
	}
	if (state && (strlen(state) > 200 || strspn(state, "abcdefghijklmnopqrstuvwxyz_,") != strlen(state))) {
		fprintf(stderr, "poro: '%s' is not a list of states\n", state);
		return 2;
	}
	char path[512];
	snprintf(path, sizeof path, "/v1/jobs?limit=%lld%s%s", limit, state ? "&state=" : "", state ? state : "");
	struct http_response r;
	if (call("GET", path, NULL, NULL, &r) != 200)
		return fail(&r);
	printf("%-8s %-10s %-12s %-24s %4s %7s %8s  %s\n", "ID", "STATE", "USER", "NAME", "PRI", "ATTEMPT", "PROGRESS",
	       "CREATED");
	size_t i;
	json_t *job;
	json_array_foreach(json_object_get(r.json, "jobs"), i, job)
	{
		const json_t *p = json_object_get(job, "progress");
		char progress[16] = "-";
		if (json_is_object(p))
			snprintf(progress, sizeof progress, "%.0f%%", 100 * json_get_real(p, "fraction", 0));
		const char *name = json_get_str(job, "name", NULL);
		printf("%-8lld %-10s %-12.12s %-24.24s %4lld %7lld %8s  %s\n", json_get_int(job, "id", -1),
		       json_get_str(job, "state", "?"), json_get_str(job, "user", "-"), name && *name ? name : "-",
		       json_get_int(job, "priority", 0), json_get_int(job, "attempt", 0), progress,
		       json_get_str(job, "created_at", "-"));
	}
	http_response_release(&r);
	return 0;
}

static void show_field(const char *label, const char *value)
{
	printf("%-18s %s\n", label, value && *value ? value : "-");
}

static int cmd_show(int argc, char **argv)
{
	long long id;
	if (argc != 1 || parse_id(argv[0], &id) < 0)
		return usage();
	char buf[256];
	struct http_response r;
	if (get_job(id, &r) != 200)
		return fail(&r);
	const json_t *j = r.json;
	snprintf(buf, sizeof buf, "%lld", json_get_int(j, "id", -1));
	show_field("id", buf);
	show_field("name", json_get_str(j, "name", NULL));
	show_field("user", json_get_str(j, "user", NULL));
	show_field("state", json_get_str(j, "state", NULL));
	snprintf(buf, sizeof buf, "%lld", json_get_int(j, "priority", 0));
	show_field("priority", buf);
	snprintf(buf, sizeof buf, "%lld", json_get_int(j, "threads", 1));
	show_field("threads", buf);
	snprintf(buf, sizeof buf, "%lld s", json_get_int(j, "wall_time_seconds", 0));
	show_field("wall time", buf);
	snprintf(buf, sizeof buf, "%lld", json_get_int(j, "attempt", 0));
	show_field("attempt", buf);
	show_field("created", json_get_str(j, "created_at", NULL));
	show_field("started", json_get_str(j, "started_at", NULL));
	show_field("finished", json_get_str(j, "finished_at", NULL));
	show_field("worker", json_get_str(j, "worker_host", NULL));
	show_field("solver", json_get_str(j, "solver_version", NULL));
	show_field("case sha256", json_get_str(j, "case_sha256", NULL));
	const json_t *p = json_object_get(j, "progress");
	if (json_is_object(p)) {
		snprintf(buf, sizeof buf, "%.1f%%, step %lld, t = %.6g s, %.3g us per material-point step",
			 100 * json_get_real(p, "fraction", 0), json_get_int(p, "step", 0), json_get_real(p, "time", 0),
			 json_get_real(p, "us_per_mp_step", 0));
		show_field("progress", buf);
	} else {
		show_field("progress", NULL);
	}
	show_field("message", json_get_str(j, "message", NULL));
	show_field("cancel requested", json_get_bool(j, "cancel_requested", 0) ? "yes" : "no");
	size_t i;
	json_t *e;
	printf("\nfiles:\n");
	json_array_foreach(json_object_get(j, "files"), i, e)
		printf("  %-20s %12lld bytes  attempt %-3lld sha256 %s\n", json_get_str(e, "name", "?"),
		       json_get_int(e, "size", 0), json_get_int(e, "attempt", 0), json_get_str(e, "sha256", "?"));
	printf("\nevents:\n");
	json_array_foreach(json_object_get(j, "events"), i, e)
	{
		const char *detail = json_get_str(e, "detail", "");
		printf("  %s  %-9s -> %-10s attempt %-3lld %-16s %s\n", json_get_str(e, "at", "?"),
		       json_get_str(e, "from", "-"), json_get_str(e, "to", "-"), json_get_int(e, "attempt", 0),
		       json_get_str(e, "actor", "-"), detail ? detail : "");
	}
	http_response_release(&r);
	return 0;
}

static int print_line(const char *line, size_t len, void *user)
{
	(void)user;
	fwrite(line, 1, len, stdout);
	putchar('\n');
	fflush(stdout);
	return 0;
}

/* Fetches the job's state and attempt; 0, or 1 after reporting an error. */
static int job_state(long long id, char *state, size_t size, long long *attempt)
{
	struct http_response r;
	if (get_job(id, &r) != 200)
		return fail(&r);
	snprintf(state, size, "%s", json_get_str(r.json, "state", "?"));
	*attempt = json_get_int(r.json, "attempt", 0);
	http_response_release(&r);
	return 0;
}

/* Where a follower is in the log. Bytes received are not log bytes once the server put a marker
 * line in place of dropped bytes (docs/service.md §3, "Log cap"): the marker names the dropped
 * offsets A..B, and the bytes after it continue at log offset B. A line counts as the marker only
 * when A is the log offset at which the marker text starts, so a solver line that merely looks like
 * one does not move the offset. */
#define LOG_MARKER_PREFIX "[poro-server: log bytes "
#define LOG_MARKER_MAX 400

struct log_place {
	long long start;          /* log offset the stream began at */
	long long seen;           /* stream bytes of the lines passed so far, newlines included */
	long long marker_log;     /* log offset after the last marker line, or -1 */
	long long marker_stream;  /* stream bytes up to the end of that marker line */
};

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

/* Follows the log of every attempt until the job ends; a broken stream resumes at its offset. */
static int follow_log(long long id)
{
	char state[32], path[160];
	long long attempt, followed = -1, offset = 0;
	for (;;) {
		if (job_state(id, state, sizeof state, &attempt))
			return 1;
		if (attempt == 0 && terminal(state))
			return 0; /* ended without ever running: there is no log */
		if (attempt != followed && !strcmp(state, "queued") && attempt >= followed) {
			/* not running yet (or re-queued): nothing new to follow */
			sleep_s(PORO_POLL);
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
		long status = http_stream_lines(http, path, follow_line, &place, &got, &r);
		offset = place_offset(&place, got);
		if (status != 0 && !http_ok(&r))
			return fail(&r);
		http_response_release(&r);
		if (job_state(id, state, sizeof state, &attempt))
			return 1;
		if (terminal(state) && attempt == followed && status != 0)
			return 0;
		if (status == 0 || attempt == followed)
			sleep_s(PORO_POLL);
	}
}

static int cmd_logs(int argc, char **argv)
{
	int follow = 0;
	long long id = -1;
	for (int i = 0; i < argc; i++) {
		if (!strcmp(argv[i], "-f") || !strcmp(argv[i], "--follow"))
			follow = 1;
		else if (id >= 0 || parse_id(argv[i], &id) < 0)
			return usage();
	}
	if (id < 0)
		return usage();
	if (follow)
		return follow_log(id);
	char path[64];
	snprintf(path, sizeof path, "/v1/jobs/%lld/log", id);
	struct http_response r;
	http_stream_lines(http, path, print_line, NULL, NULL, &r);
	int rc = http_ok(&r) ? 0 : report(&r);
	http_response_release(&r);
	return rc;
}

/* The one argument ID of a command, sent as method to the path fmt makes of it: 0 with the 200
 * answer in r, else the exit status after reporting (2 for a bad command line). */
static int job_request(int argc, char **argv, const char *method, const char *fmt, long long *id,
		       struct http_response *r)
{
	if (argc != 1 || parse_id(argv[0], id) < 0)
		return usage();
	char path[64];
	snprintf(path, sizeof path, fmt, *id);
	if (call(method, path, NULL, NULL, r) != 200)
		return fail(r);
	return 0;
}

static int cmd_cancel(int argc, char **argv)
{
	long long id;
	struct http_response r;
	int rc = job_request(argc, argv, "POST", "/v1/jobs/%lld/cancel", &id, &r);
	if (rc)
		return rc;
	const char *state = json_get_str(r.json, "state", "?");
	if (!strcmp(state, "cancelled"))
		printf("job %lld cancelled\n", id);
	else
		printf("job %lld %s, cancel requested\n", id, state);
	http_response_release(&r);
	return 0;
}

static int cmd_rm(int argc, char **argv)
{
	long long id;
	struct http_response r;
	int rc = job_request(argc, argv, "DELETE", "/v1/jobs/%lld", &id, &r);
	if (rc)
		return rc;
	printf("job %lld removed: %lld bytes freed (%lld files, %lld log chunks, %lld events)\n", id,
	       json_get_int(r.json, "freed_bytes", 0), json_get_int(r.json, "files", 0),
	       json_get_int(r.json, "log_chunks", 0), json_get_int(r.json, "events", 0));
	http_response_release(&r);
	return 0;
}

/* The newest listed file called name: its SHA-256, or NULL. */
static const char *listed_sha(const json_t *job, const char *name)
{
	const char *sha = NULL;
	long long best = -1;
	size_t i;
	json_t *f;
	json_array_foreach(json_object_get(job, "files"), i, f)
	{
		if (strcmp(json_get_str(f, "name", ""), name) || json_get_int(f, "attempt", 0) < best)
			continue;
		best = json_get_int(f, "attempt", 0);
		sha = json_get_str(f, "sha256", NULL);
	}
	return sha;
}

static int fetch_file(long long id, const json_t *job, const char *name, const char *dir)
{
	const char *want = listed_sha(job, name);
	if (!want) {
		fprintf(stderr, "poro: job %lld has no file '%s'\n", id, name);
		return 1;
	}
	char path[160], part[4200], dest[4200], sha[DIGEST_HEX_SIZE];
	snprintf(path, sizeof path, "/v1/jobs/%lld/files/%s", id, name);
	snprintf(part, sizeof part, "%s/%s.part", dir, name);
	snprintf(dest, sizeof dest, "%s/%s", dir, name);
	struct http_response r;
	long long size = 0;
	http_download(http, path, part, sha, &size, &r);
	if (r.status == 0) {
		/* broken off mid-way: asked again, a server that cut a damaged file says so at once */
		http_response_release(&r);
		http_download(http, path, part, sha, &size, &r);
	}
	if (!http_ok(&r))
		return fail(&r);
	http_response_release(&r);
	if (!digest_hex_equal(sha, want)) {
		remove(part);
		fprintf(stderr, "poro: '%s' arrived with SHA-256 %s but the server lists %s; removed\n", name, sha, want);
		return 1;
	}
	if (rename(part, dest) < 0) {
		fprintf(stderr, "poro: cannot rename '%s' to '%s': %s\n", part, dest, strerror(errno));
		remove(part);
		return 1;
	}
	printf("%s  %lld bytes  sha256 %s\n", dest, size, sha);
	return 0;
}

static int cmd_fetch(int argc, char **argv)
{
	long long id = -1;
	const char *dir = ".";
	for (int i = 0; i < argc; i++) {
		if (!strcmp(argv[i], "--out") && i + 1 < argc)
			dir = argv[++i];
		else if (id >= 0 || parse_id(argv[i], &id) < 0)
			return usage();
	}
	if (id < 0)
		return usage();
	if (mkdir(dir, 0755) < 0 && errno != EEXIST) {
		fprintf(stderr, "poro: cannot create '%s': %s\n", dir, strerror(errno));
		return 1;
	}
	struct http_response r;
	if (get_job(id, &r) != 200)
		return fail(&r);
	int rc = fetch_file(id, r.json, "result.h5", dir);
	rc |= fetch_file(id, r.json, "result.xdmf", dir);
	http_response_release(&r);
	return rc;
}

/* ---- tokens ------------------------------------------------------------------------------------ */

static void print_token_row(const json_t *t)
{
	const char *label = json_get_str(t, "label", NULL), *revoked = json_get_str(t, "revoked_at", NULL);
	const char *used = json_get_str(t, "last_used_at", NULL);
	printf("%-6lld %-12.12s %-7s %-11s %-24s %-24s %-24s %s\n", json_get_int(t, "id", -1),
	       json_get_str(t, "user", "-"), json_get_str(t, "role", "-"), json_get_str(t, "fingerprint", "-"),
	       json_get_str(t, "created_at", "-"), used ? used : "-", revoked ? revoked : "-", label ? label : "-");
}

/* poro token ls: every page of GET /v1/tokens (the caller's own tokens; an admin sees all). */
static int token_ls(void)
{
	printf("%-6s %-12s %-7s %-11s %-24s %-24s %-24s %s\n", "ID", "USER", "ROLE", "FINGERPRINT", "CREATED",
	       "LAST USED", "REVOKED", "LABEL");
	long long after = 0;
	do {
		char path[96] = "/v1/tokens?limit=1000";
		if (after)
			snprintf(path, sizeof path, "/v1/tokens?limit=1000&after=%lld", after);
		struct http_response r;
		if (call("GET", path, NULL, NULL, &r) != 200)
			return fail(&r);
		size_t i;
		json_t *t;
		json_array_foreach(json_object_get(r.json, "tokens"), i, t)
			print_token_row(t);
		after = json_get_int(r.json, "next_after", 0);
		http_response_release(&r);
	} while (after > 0);
	return 0;
}

static int cmd_token(int argc, char **argv)
{
	if (argc == 1 && !strcmp(argv[0], "ls"))
		return token_ls();
	long long id;
	if (argc != 2 || strcmp(argv[0], "revoke"))
		return usage();
	if (parse_int("token revoke", argv[1], 1, LLONG_MAX, &id) < 0)
		return 2;
	char path[64];
	snprintf(path, sizeof path, "/v1/tokens/%lld", id);
	struct http_response r;
	if (call("DELETE", path, NULL, NULL, &r) != 200)
		return fail(&r);
	printf("token %lld of '%s' (fingerprint %s) revoked at %s\n", id, json_get_str(r.json, "user", "?"),
	       json_get_str(r.json, "fingerprint", "?"), json_get_str(r.json, "revoked_at", "?"));
	http_response_release(&r);
	return 0;
}

int main(int argc, char **argv)
{
	if (argc < 2)
		return usage();
	if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
		usage();
		return 0;
	}
	char err[1200] = "";
	if (client_config_load(&cfg, err, sizeof err) < 0) {
		fprintf(stderr, "poro: %s\n", err);
		return 2;
	}
	if (!cfg.server[0]) {
		fprintf(stderr, "poro: no server: set PORO_SERVER or 'server = URL' in ~/.config/poro/config\n");
		return 2;
	}
	if (http_global_init() < 0 || !(http = http_client_create(cfg.server, cfg.token))) {
		fprintf(stderr, "poro: cannot initialise the HTTP client\n");
		return 1;
	}
	const char *cmd = argv[1];
	int n = argc - 2;
	char **rest = argv + 2;
	int rc;
	if (!strcmp(cmd, "submit"))
		rc = cmd_submit(n, rest);
	else if (!strcmp(cmd, "ls"))
		rc = cmd_ls(n, rest);
	else if (!strcmp(cmd, "show"))
		rc = cmd_show(n, rest);
	else if (!strcmp(cmd, "logs"))
		rc = cmd_logs(n, rest);
	else if (!strcmp(cmd, "cancel"))
		rc = cmd_cancel(n, rest);
	else if (!strcmp(cmd, "rm"))
		rc = cmd_rm(n, rest);
	else if (!strcmp(cmd, "fetch"))
		rc = cmd_fetch(n, rest);
	else if (!strcmp(cmd, "token"))
		rc = cmd_token(n, rest);
	else
		rc = usage();
	http_client_destroy(&http);
	http_global_cleanup();
	return rc;
}
