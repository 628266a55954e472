/*
 * cli.c - the pieces every poro command uses (cli.h): the exit table, help and usage errors,
 * argument parsing, reporting failed requests with the right exit status, requests with retries,
 * JSON output and times.
 */
#define _GNU_SOURCE
#include "cli.h"

#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "client_config.h"
#include "json_get.h"

/* Retries of a request that got no answer (or 5xx, 408, 429), and the first delay, seconds. */
#define CLI_RETRIES 3
#define CLI_RETRY_FIRST 0.5
/* Seconds one JSON request may take. */
#define CLI_REQUEST_SECONDS 60
/* Width the exit table is wrapped to. */
#define CLI_TABLE_WIDTH 100
#define CLI_ID_MAX 1000000000000000000LL

struct http_client *cli_http;
const char *cli_server = "";
static struct client_config config;
static int curl_ready;

static const struct {
	int status;
	const char *meaning;
} EXITS[] = {
#define PORO_EXIT_ROW(name, status, meaning) { status, meaning },
	PORO_EXIT_MAP(PORO_EXIT_ROW)
#undef PORO_EXIT_ROW
};

void cli_print_exit_table(FILE *f)
{
	const int indent = 6;
	for (size_t i = 0; i < sizeof EXITS / sizeof EXITS[0]; i++) {
		fprintf(f, "  %-3d ", EXITS[i].status);
		const char *p = EXITS[i].meaning;
		int col = indent;
		while (*p) {   /* word by word, wrapped under the text */
			size_t n = strcspn(p, " ");
			if (col > indent && col + 1 + (int)n > CLI_TABLE_WIDTH) {
				fprintf(f, "\n%*s", indent, "");
				col = indent;
			} else if (col > indent) {
				fputc(' ', f);
				col++;
			}
			fprintf(f, "%.*s", (int)n, p);
			col += (int)n;
			p += n;
			p += strspn(p, " ");
		}
		fputc('\n', f);
	}
}

int cli_help(const struct subcommand *cmd)
{
	return subcommand_help("poro", cmd);
}

int cli_usage_error(const struct subcommand *cmd, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	subcommand_vusage_error("poro", cmd, fmt, ap);
	va_end(ap);
	return PORO_EXIT_USAGE;
}

int cli_positional(const struct subcommand *cmd, int argc, char **argv, int want, const char *what)
{
	return subcommand_positional("poro", cmd, argc, argv, want, what) ? PORO_EXIT_USAGE : 0;
}

static int parse_ll(const char *text, long long lo, long long hi, long long *out)
{
	char *end;
	errno = 0;
	long long v = strtoll(text, &end, 10);
	if (errno || end == text || *end || v < lo || v > hi)
		return -1;
	*out = v;
	return 0;
}

int cli_parse_id(const struct subcommand *cmd, const char *text, long long *id)
{
	if (parse_ll(text, 1, CLI_ID_MAX, id) == 0)
		return 0;
	return cli_usage_error(cmd, "'%s' is not an id (a whole number from 1)", text);
}

int cli_parse_int(const struct subcommand *cmd, const char *option, const char *text, long long lo, long long hi,
		  long long *out)
{
	if (parse_ll(text, lo, hi, out) == 0)
		return 0;
	return cli_usage_error(cmd, "%s needs a whole number in %lld..%lld, got '%s'", option, lo, hi, text);
}

/* ---- requests ---- */

int cli_connect(void)
{
	char err[1200] = "";
	if (client_config_load(&config, err, sizeof err) < 0) {
		fprintf(stderr, "poro: %s\n", err);
		return PORO_EXIT_USAGE;
	}
	if (!config.server[0]) {
		fprintf(stderr, "poro: no server: set PORO_SERVER or 'server = URL' in ~/.config/poro/config\n");
		return PORO_EXIT_USAGE;
	}
	if (client_config_check_server(&config, err, sizeof err) != 0) {
		fprintf(stderr, "poro: %s\n", err);
		return PORO_EXIT_USAGE;
	}
	curl_ready = http_global_init() == 0;
	http_global_ca_file(config.ca_file);
	if (!curl_ready || !(cli_http = http_client_create(config.server, config.token))) {
		fprintf(stderr, "poro: cannot initialise the HTTP client\n");
		return PORO_EXIT_ERROR;
	}
	cli_server = config.server;
	return 0;
}

void cli_disconnect(void)
{
	http_client_destroy(&cli_http);
	if (curl_ready)
		http_global_cleanup();
	curl_ready = 0;
}

int cli_exit_of(const struct http_response *r)
{
	if (r->status == 0)
		return r->local ? PORO_EXIT_ERROR : PORO_EXIT_UNREACHABLE;
	if (r->status == 401 || r->status == 403)
		return PORO_EXIT_AUTH;
	if (r->status == 404)
		return PORO_EXIT_NOT_FOUND;
	if (r->status == 413 || r->status == 422)
		return PORO_EXIT_INVALID_CASE;
	return PORO_EXIT_ERROR;
}

/* A problem's field is a pointer into the request body, "/case/grid/cell_size"; the user's file is
 * the case itself, so its pointer is "/grid/cell_size" (what poro-solve validate prints). */
static const char *case_pointer(const char *field)
{
	if (strncmp(field, "/case", 5) == 0 && (field[5] == '/' || field[5] == '\0'))
		return field[5] ? field + 5 : "/";
	return field;
}

int cli_report(const struct http_response *r)
{
	if (r->status == 0 && !r->local)
		fprintf(stderr, "poro: cannot reach '%s': %s\n", cli_server, r->error);
	else if (r->code[0] && r->field[0])
		fprintf(stderr, "poro: %s (%s, field %s)\n", r->error, r->code, r->field);
	else if (r->code[0])
		fprintf(stderr, "poro: %s (%s)\n", r->error, r->code);
	else
		fprintf(stderr, "poro: %s\n", r->error);
	size_t i;
	json_t *p;
	json_array_foreach(json_object_get(json_object_get(r->json, "error"), "problems"), i, p)
		fprintf(stderr, "%s: %s\n", case_pointer(json_get_str(p, "field", "?")), json_get_str(p, "message", "?"));
	return cli_exit_of(r);
}

int cli_fail(struct http_response *r)
{
	int rc = cli_report(r);
	http_response_release(r);
	return rc;
}

long cli_call(const char *method, const char *path, const json_t *body, const char *header, struct http_response *r)
{
	double wait = CLI_RETRY_FIRST;
	for (int i = 0;; i++) {
		http_json(cli_http, method, path, body, header, CLI_REQUEST_SECONDS, r);
		if (r->local || !http_transient(r) || i == CLI_RETRIES)
			return r->status;
		http_response_release(r);
		cli_sleep(wait);
		wait *= 2;
	}
}

long cli_get_job(long long id, struct http_response *r)
{
	char path[64];
	snprintf(path, sizeof path, "/v1/jobs/%lld", id);
	return cli_call("GET", path, NULL, NULL, r);
}

/* ---- jobs ---- */

int cli_terminal(const char *state)
{
	return !strcmp(state, "succeeded") || !strcmp(state, "failed") || !strcmp(state, "cancelled");
}

int cli_exit_of_state(const char *state)
{
	return !strcmp(state, "succeeded") ? PORO_EXIT_OK :
	       !strcmp(state, "cancelled") ? PORO_EXIT_JOB_CANCELLED : PORO_EXIT_JOB_FAILED;
}

const char *cli_waiting_phrase(const json_t *job)
{
	static const struct {
		const char *reason, *phrase;
	} PHRASES[] = {
		{ "no_worker", "no live worker" },
		{ "user_running_cap", "your cap on running jobs" },
		{ "starting", "starting" },
		{ "behind_other_jobs", "behind other jobs" },
		{ "retry_backoff", "retry backoff" },
	};
	const char *reason = json_get_str(json_object_get(job, "waiting"), "reason", NULL);
	if (!reason)
		return NULL;
	for (size_t i = 0; i < sizeof PHRASES / sizeof PHRASES[0]; i++)
		if (!strcmp(reason, PHRASES[i].reason))
			return PHRASES[i].phrase;
	return reason;   /* a reason newer than this client: as the server names it */
}

double cli_job_elapsed(const json_t *job)
{
	double start = cli_parse_time(json_get_str(job, "started_at", NULL));
	if (start < 0 || !strcmp(json_get_str(job, "state", ""), "queued"))   /* a re-queued job keeps its last start */
		return -1;
	double end = cli_parse_time(json_get_str(job, "finished_at", NULL));
	if (end < 0)
		end = cli_now();
	return end > start ? end - start : 0;   /* clocks of two hosts may differ a little */
}

/* ---- output and times ---- */

int cli_print_json(const json_t *v)
{
	if (json_dumpf(v, stdout, JSON_INDENT(2)) != 0 || putchar('\n') == EOF || fflush(stdout) != 0) {
		fprintf(stderr, "poro: cannot write the answer to stdout: %s\n", strerror(errno));
		return PORO_EXIT_ERROR;
	}
	return PORO_EXIT_OK;
}

const char *cli_duration(double seconds, char out[32])
{
	if (seconds < 0) {
		snprintf(out, 32, "-");
		return out;
	}
	long long s = (long long)(seconds + 0.5);
	if (s >= 3600)
		snprintf(out, 32, "%lld:%02lld:%02lld", s / 3600, s / 60 % 60, s % 60);
	else
		snprintf(out, 32, "%lld:%02lld", s / 60, s % 60);
	return out;
}

double cli_parse_time(const char *text)
{
	struct tm tm = { 0 };
	int ms = 0, n = 0;
	if (!text || sscanf(text, "%4d-%2d-%2dT%2d:%2d:%2d%n", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour,
			    &tm.tm_min, &tm.tm_sec, &n) != 6)
		return -1;
	if (text[n] == '.')
		sscanf(text + n, ".%3d", &ms);
	tm.tm_year -= 1900;
	tm.tm_mon -= 1;
	time_t t = timegm(&tm);
	return t == (time_t)-1 ? -1 : (double)t + 1e-3 * ms;
}

double cli_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_REALTIME, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cli_sleep(double seconds)
{
	struct timespec ts = { (time_t)seconds, (long)((seconds - (double)(time_t)seconds) * 1e9) };
	nanosleep(&ts, NULL);
}
