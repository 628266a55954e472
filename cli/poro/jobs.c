/*
 * jobs.c - the commands on jobs (cli.h): submit, wait, ls, show, cancel, rm. With --json each prints
 * the API's object as the server sent it (docs/service.md §3): submit the job (with --wait the job
 * as it ended), ls one page {"jobs", "next_after"}, show and wait the job with its files, events
 * and logs, cancel the job after the cancel, rm what was deleted.
 *
 * A submission always carries an Idempotency-Key (a random one unless --idempotency-key), so a
 * submission whose answer was lost is retried without creating a second job.
 */
#define _GNU_SOURCE
#include "cli.h"

#include <limits.h>
#include <string.h>

#include "digest.h"
#include "json_get.h"

#define PRIORITY_MIN -100
#define PRIORITY_MAX 100
#define THREADS_MAX 256
#define WALL_TIME_MAX 2592000
#define MEMORY_MB_MAX (1LL << 24)   /* the server's JOB_MEMORY_MB_MAX */
#define LIST_LIMIT_MAX 1000
#define LIST_LIMIT_DEFAULT 100

/* ---- submit ---------------------------------------------------------------------------------- */

/* What submit was asked for besides the case. */
struct submit_options {
	int wait, json;
	long long priority, threads, wall;    /* 0 threads or wall: the server's default */
	long long memory_mb;                  /* 0: not stated */
	int have_priority;
	const char *name, *key;
};

/* The request body: the case file as "case" and the options; NULL after saying why (*rc set). */
static json_t *submission(const char *file, const struct submit_options *o, int *rc)
{
	json_error_t jerr;
	json_t *spec = json_load_file(file, 0, &jerr);
	if (!spec) {
		if (jerr.line > 0)
			fprintf(stderr, "poro: '%s' is not JSON: line %d column %d: %s\n", file, jerr.line, jerr.column,
				jerr.text);
		else
			fprintf(stderr, "poro: cannot read '%s': %s\n", file, jerr.text);
		*rc = PORO_EXIT_INVALID_CASE;
		return NULL;
	}
	json_t *body = json_pack("{s:o}", "case", spec);
	if (o->have_priority)
		json_object_set_new(body, "priority", json_integer(o->priority));
	if (o->threads)
		json_object_set_new(body, "threads", json_integer(o->threads));
	if (o->wall)
		json_object_set_new(body, "wall_time_seconds", json_integer(o->wall));
	if (o->memory_mb)
		json_object_set_new(body, "memory_mb", json_integer(o->memory_mb));
	if (o->name)
		json_object_set_new(body, "name", json_string(o->name));
	return body;
}

int cmd_submit(const struct subcommand *self, int argc, char **argv)
{
	static const struct option opts[] = {
		{ "wait", no_argument, NULL, 'w' },       { "json", no_argument, NULL, 'j' },
		{ "priority", required_argument, NULL, 'p' }, { "threads", required_argument, NULL, 't' },
		{ "wall-time", required_argument, NULL, 'W' }, { "memory-mb", required_argument, NULL, 'M' },
		{ "name", required_argument, NULL, 'n' },
		{ "idempotency-key", required_argument, NULL, 'k' }, { "help", no_argument, NULL, 'h' },
		{ NULL, 0, NULL, 0 }
	};
	struct submit_options o = { 0 };
	int c, rc;
	while ((c = getopt_long(argc, argv, "hwjp:t:n:", opts, NULL)) != -1) {
		switch (c) {
		case 'h': return cli_help(self);
		case 'w': o.wait = 1; break;
		case 'j': o.json = 1; break;
		case 'p':
			if ((rc = cli_parse_int(self, "--priority", optarg, PRIORITY_MIN, PRIORITY_MAX, &o.priority)))
				return rc;
			o.have_priority = 1;
			break;
		case 't':
			if ((rc = cli_parse_int(self, "--threads", optarg, 1, THREADS_MAX, &o.threads)))
				return rc;
			break;
		case 'W':
			if ((rc = cli_parse_int(self, "--wall-time", optarg, 1, WALL_TIME_MAX, &o.wall)))
				return rc;
			break;
		case 'M':
			if ((rc = cli_parse_int(self, "--memory-mb", optarg, 0, MEMORY_MB_MAX, &o.memory_mb)))
				return rc;
			break;
		case 'n': o.name = optarg; break;
		case 'k': o.key = optarg; break;
		default: return cli_usage_error(self, NULL);
		}
	}
	if ((rc = cli_positional(self, argc, argv, 1, "the case file CASE.json")) || (rc = cli_connect()))
		return rc;
	const char *file = argv[optind];
	json_t *body = submission(file, &o, &rc);
	if (!body)
		return rc;
	char token[DIGEST_TOKEN_SIZE], header[300];
	const char *key = o.key;
	if (!key) {
		if (digest_new_token(token) < 0) {
			fprintf(stderr, "poro: no randomness for an idempotency key\n");
			json_decref(body);
			return PORO_EXIT_ERROR;
		}
		key = token + 5; /* without the "poro_" prefix of tokens */
	}
	snprintf(header, sizeof header, "Idempotency-Key: %s", key);
	struct http_response r;
	long status = cli_call("POST", "/v1/jobs", body, header, &r);
	json_decref(body);
	if (status != 200 && status != 201)
		return cli_fail(&r);
	long long id = json_get_int(r.json, "id", -1);
	if (o.json && !o.wait)
		rc = cli_print_json(r.json);
	else if (!o.json)
		rc = printf("%lld\n", id) < 0 || fflush(stdout) != 0 ? PORO_EXIT_ERROR : PORO_EXIT_OK;
	const char *reason = json_get_str(json_object_get(r.json, "waiting"), "reason", "");
	if (!o.wait && !strcmp(reason, "no_worker"))   /* what a new user would otherwise wonder about */
		fprintf(stderr, "poro: job %lld waits: %s\n", id,
			json_get_str(json_object_get(r.json, "waiting"), "message", ""));
	http_response_release(&r);
	return o.wait && rc == PORO_EXIT_OK ? cli_wait_job(id, o.json) : rc;
}

/* ---- wait, show, cancel, rm: one job id and --json ---------------------------------------------- */

/* Parses "[--json] ID": 0, or the exit status of a refused command line (0 as well for --help,
 * with *done set). */
static int id_and_json(const struct subcommand *self, int argc, char **argv, long long *id, int *json, int *done)
{
	static const struct option opts[] = {
		{ "json", no_argument, NULL, 'j' }, { "help", no_argument, NULL, 'h' }, { NULL, 0, NULL, 0 }
	};
	int c, rc;
	*json = *done = 0;
	while ((c = getopt_long(argc, argv, "hj", opts, NULL)) != -1) {
		if (c == 'h') {
			*done = 1;
			return cli_help(self);
		}
		if (c != 'j')
			return cli_usage_error(self, NULL);
		*json = 1;
	}
	if ((rc = cli_positional(self, argc, argv, 1, "the job ID")) || (rc = cli_parse_id(self, argv[optind], id)))
		return rc;
	return cli_connect();
}

int cmd_wait(const struct subcommand *self, int argc, char **argv)
{
	long long id;
	int json, done, rc = id_and_json(self, argc, argv, &id, &json, &done);
	return rc || done ? rc : cli_wait_job(id, json);
}

static void show_field(const char *label, const char *value)
{
	printf("%-18s %s\n", label, value && *value ? value : "-");
}

static void show_job(const json_t *j)
{
	char buf[256], d[32];
	snprintf(buf, sizeof buf, "%lld", json_get_int(j, "id", -1));
	show_field("id", buf);
	show_field("name", json_get_str(j, "name", NULL));
	show_field("user", json_get_str(j, "user", NULL));
	show_field("state", json_get_str(j, "state", NULL));
	const json_t *waiting = json_object_get(j, "waiting");
	if (json_is_object(waiting))
		show_field("waiting", json_get_str(waiting, "message", NULL));
	snprintf(buf, sizeof buf, "%lld", json_get_int(j, "priority", 0));
	show_field("priority", buf);
	snprintf(buf, sizeof buf, "%lld", json_get_int(j, "threads", 1));
	show_field("threads", buf);
	snprintf(buf, sizeof buf, "%lld s", json_get_int(j, "wall_time_seconds", 0));
	show_field("wall time", buf);
	long long memory_mb = json_get_int(j, "memory_mb", 0);
	snprintf(buf, sizeof buf, "%lld MB", memory_mb);
	show_field("memory", memory_mb > 0 ? buf : "not stated");
	snprintf(buf, sizeof buf, "%lld", json_get_int(j, "attempt", 0));
	show_field("attempt", buf);
	show_field("created", json_get_str(j, "created_at", NULL));
	show_field("started", json_get_str(j, "started_at", NULL));
	show_field("finished", json_get_str(j, "finished_at", NULL));
	show_field("elapsed", cli_duration(cli_job_elapsed(j), d));
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
}

/* The one job request of show, cancel and rm: method on the path fmt makes of the id, the answer
 * printed by human(), or as JSON. */
static int one_job(const struct subcommand *self, int argc, char **argv, const char *method, const char *fmt,
		   void (*human)(long long id, const json_t *answer))
{
	long long id;
	int json, done, rc = id_and_json(self, argc, argv, &id, &json, &done);
	if (rc || done)
		return rc;
	char path[64];
	snprintf(path, sizeof path, fmt, id);
	struct http_response r;
	if (cli_call(method, path, NULL, NULL, &r) != 200)
		return cli_fail(&r);
	if (json)
		rc = cli_print_json(r.json);
	else
		human(id, r.json);
	http_response_release(&r);
	return rc;
}

static void show_human(long long id, const json_t *job)
{
	(void)id;
	show_job(job);
}

int cmd_show(const struct subcommand *self, int argc, char **argv)
{
	return one_job(self, argc, argv, "GET", "/v1/jobs/%lld", show_human);
}

static void cancel_human(long long id, const json_t *job)
{
	const char *state = json_get_str(job, "state", "?");
	if (!strcmp(state, "cancelled"))
		printf("job %lld cancelled\n", id);
	else
		printf("job %lld %s, cancel requested\n", id, state);
}

int cmd_cancel(const struct subcommand *self, int argc, char **argv)
{
	return one_job(self, argc, argv, "POST", "/v1/jobs/%lld/cancel", cancel_human);
}

static void rm_human(long long id, const json_t *d)
{
	printf("job %lld removed: %lld bytes freed (%lld files, %lld log chunks, %lld events)\n", id,
	       json_get_int(d, "freed_bytes", 0), json_get_int(d, "files", 0), json_get_int(d, "log_chunks", 0),
	       json_get_int(d, "events", 0));
}

int cmd_rm(const struct subcommand *self, int argc, char **argv)
{
	return one_job(self, argc, argv, "DELETE", "/v1/jobs/%lld", rm_human);
}

/* ---- ls -------------------------------------------------------------------------------------- */

static void ls_row(const json_t *job)
{
	const json_t *p = json_object_get(job, "progress");
	const char *state = json_get_str(job, "state", "?");
	char progress[16] = "-", elapsed[32];
	if (json_is_object(p))
		snprintf(progress, sizeof progress, "%.0f%%", 100 * json_get_real(p, "fraction", 0));
	else if (!strcmp(state, "succeeded"))
		snprintf(progress, sizeof progress, "100%%");
	const char *name = json_get_str(job, "name", NULL), *why = cli_waiting_phrase(job);
	if (!why && json_get_bool(job, "cancel_requested", 0) && !cli_terminal(state))
		why = "cancel requested";
	printf("%-8lld %-10s %-12.12s %-20.20s %4lld %7lld %8s %9s  %-24s  %s\n", json_get_int(job, "id", -1), state,
	       json_get_str(job, "user", "-"), name && *name ? name : "-", json_get_int(job, "priority", 0),
	       json_get_int(job, "attempt", 0), progress, cli_duration(cli_job_elapsed(job), elapsed),
	       json_get_str(job, "created_at", "-"), why ? why : "-");
}

int cmd_ls(const struct subcommand *self, int argc, char **argv)
{
	static const struct option opts[] = {
		{ "state", required_argument, NULL, 's' }, { "limit", required_argument, NULL, 'n' },
		{ "after", required_argument, NULL, 'a' }, { "json", no_argument, NULL, 'j' },
		{ "help", no_argument, NULL, 'h' },        { NULL, 0, NULL, 0 }
	};
	const char *state = NULL;
	long long limit = LIST_LIMIT_DEFAULT, after = 0;
	int json = 0, c, rc;
	while ((c = getopt_long(argc, argv, "hjs:n:", opts, NULL)) != -1) {
		switch (c) {
		case 'h': return cli_help(self);
		case 'j': json = 1; break;
		case 's': state = optarg; break;
		case 'n':
			if ((rc = cli_parse_int(self, "--limit", optarg, 1, LIST_LIMIT_MAX, &limit)))
				return rc;
			break;
		case 'a':
			if ((rc = cli_parse_id(self, optarg, &after)))
				return rc;
			break;
		default: return cli_usage_error(self, NULL);
		}
	}
	if ((rc = cli_positional(self, argc, argv, 0, "")))
		return rc;
	if (state && (!*state || strlen(state) > 200 || strspn(state, "abcdefghijklmnopqrstuvwxyz,") != strlen(state)))
		return cli_usage_error(self, "--state: '%s' is not a comma-separated list of queued, running, "
					     "succeeded, failed, cancelled", state);
	if ((rc = cli_connect()))
		return rc;
	char path[512];
	int n = snprintf(path, sizeof path, "/v1/jobs?limit=%lld", limit);
	if (state)
		n += snprintf(path + n, sizeof path - (size_t)n, "&state=%s", state);
	if (after)
		snprintf(path + n, sizeof path - (size_t)n, "&after=%lld", after);
	struct http_response r;
	if (cli_call("GET", path, NULL, NULL, &r) != 200)
		return cli_fail(&r);
	if (json) {
		rc = cli_print_json(r.json);
		http_response_release(&r);
		return rc;
	}
	printf("%-8s %-10s %-12s %-20s %4s %7s %8s %9s  %-24s  %s\n", "ID", "STATE", "USER", "NAME", "PRI", "ATTEMPT",
	       "PROGRESS", "ELAPSED", "CREATED", "WAITING");
	size_t i;
	json_t *job;
	json_array_foreach(json_object_get(r.json, "jobs"), i, job)
		ls_row(job);
	fflush(stdout);
	long long next = json_get_int(r.json, "next_after", 0);
	if (next > 0) {   /* on stderr: the table on stdout stays a table */
		fprintf(stderr, "poro: more jobs: poro ls --after %lld", next);
		if (state)
			fprintf(stderr, " --state %s", state);
		if (limit != LIST_LIMIT_DEFAULT)
			fprintf(stderr, " --limit %lld", limit);
		fputc('\n', stderr);
	}
	http_response_release(&r);
	return PORO_EXIT_OK;
}
