/*
 * cli.h - what the commands of `poro` (cli/poro.c) share: the table of exit statuses, reporting a
 * failed request, requests with retries, option and argument parsing with getopt_long, JSON output,
 * and times. One file per group of commands: jobs.c (submit, wait, ls, show, cancel, rm), wait.c
 * (following a job to its end with a progress bar), logs.c, fetch.c, token.c.
 *
 * Every command gets its own argv whose argv[0] is "poro NAME", so getopt_long's own messages name
 * the command ("poro submit: unrecognized option '--wiat'") (subcommand.h). A command returns its
 * exit status.
 */
#ifndef PORO_CLI_H
#define PORO_CLI_H

#include <getopt.h>
#include <jansson.h>
#include <stdio.h>

#include "http_client.h"
#include "subcommand.h"

/* Exit statuses of poro, one table (STYLE rule 10): `poro --help` prints it, the README repeats it.
 *      name           status  meaning */
#define PORO_EXIT_MAP(X)                                                                                  \
	X(OK,            0, "success; for submit --wait, wait and logs -f: the job succeeded")              \
	X(ERROR,         1, "any other failure: the server refused or failed the request (a conflict, a "   \
			    "quota, a damaged stored file), or a local file could not be written")          \
	X(USAGE,         2, "bad command line or configuration (no server set, an unreadable config file)") \
	X(UNREACHABLE,   3, "the server cannot be reached: no answer, after retries")                       \
	X(AUTH,          4, "authentication: no token, or one that is unknown, revoked or of a role that "  \
			    "may not do this")                                                             \
	X(NOT_FOUND,     5, "no such job, file or token (another user's job is not found either)")          \
	X(INVALID_CASE,  6, "the case file cannot be read, or the server refused the case or a setting of " \
			    "the submission (every problem listed as JSON-pointer: message)")              \
	X(JOB_FAILED,    7, "the job failed (submit --wait, wait, logs -f)")                                \
	X(JOB_CANCELLED, 8, "the job was cancelled (submit --wait, wait, logs -f)")                           \
	X(REGRESSED,     9, "a benchmark run found a figure that regressed, failed or did not run (nightly "  \
			    "run, nightly show)")

enum poro_exit {
#define PORO_EXIT_ENUM(name, status, meaning) PORO_EXIT_##name = status,
	PORO_EXIT_MAP(PORO_EXIT_ENUM)
#undef PORO_EXIT_ENUM
};

/* Prints the table, one "  N  meaning" line per status, wrapped to fit 100 columns. */
void cli_print_exit_table(FILE *f);

/* ---- a command (subcommand.h) ---- */
/* `poro NAME --help`: the synopsis and the help on stdout; returns 0. */
int cli_help(const struct subcommand *cmd);
/* A refused command line: "poro NAME: <why>" (when fmt is not NULL: getopt has said it otherwise)
 * and where to look, on stderr; returns PORO_EXIT_USAGE. */
int cli_usage_error(const struct subcommand *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The command's positional arguments after option parsing: exactly want of them, else a usage error
 * naming what is missing or extra (what: e.g. "the job ID"). 0, or PORO_EXIT_USAGE. */
int cli_positional(const struct subcommand *cmd, int argc, char **argv, int want, const char *what);
/* A job id (1..10^18) or a token id: 0, or PORO_EXIT_USAGE after saying why. */
int cli_parse_id(const struct subcommand *cmd, const char *text, long long *id);
/* An option value as an integer in [lo, hi]: 0, or PORO_EXIT_USAGE after naming the option. */
int cli_parse_int(const struct subcommand *cmd, const char *option, const char *text, long long lo, long long hi,
		  long long *out);

/* ---- the server ---- */
/* The client every command uses, and the server's URL for messages: set by cli_connect(). */
extern struct http_client *cli_http;
extern const char *cli_server;
/* Reads the server and the token (client_config.h) and makes the client; a command calls it once
 * its command line is known good, so --help and usage errors need no server. 0, or the exit status
 * after saying why not. */
int cli_connect(void);
/* Releases the client; harmless when cli_connect() was not called or failed. */
void cli_disconnect(void);

/* The exit status a failed response stands for (status 0 and not local: unreachable; 401, 403:
 * auth; 404: not found; 413, 422: invalid case; anything else: error). */
int cli_exit_of(const struct http_response *r);
/* Prints a failed call ("poro: <message> (<code>, field <pointer>)", "poro: cannot reach ...") and
 * the problems of an invalid case, one "JSON-pointer: message" line each, pointers into the case
 * file; returns cli_exit_of(r). */
int cli_report(const struct http_response *r);
/* cli_report, then releases r: `return cli_fail(&r);`. */
int cli_fail(struct http_response *r);
/* A request repeated a few times while the server cannot be reached or answers 5xx, 408 or 429;
 * it must be safe to repeat (GET, or a POST with an idempotency key). Returns r->status. */
long cli_call(const char *method, const char *path, const json_t *body, const char *header,
	      struct http_response *r);
/* GET /v1/jobs/{id}: the job with its files, events and logs. */
long cli_get_job(long long id, struct http_response *r);

/* ---- jobs ---- */
/* 1 for succeeded, failed and cancelled. */
int cli_terminal(const char *state);
/* The exit status of a job that ended in state: OK, JOB_FAILED or JOB_CANCELLED. */
int cli_exit_of_state(const char *state);
/* A short phrase for why a queued job waits ("no live worker", ...), from its "waiting", or NULL. */
const char *cli_waiting_phrase(const json_t *job);
/* Seconds the job has run: its current attempt's start to its end, or to now while it runs; < 0
 * while it is queued (also when re-queued) or when it never started. */
double cli_job_elapsed(const json_t *job);

/* ---- output ---- */
/* v as indented JSON and a newline on stdout, as the server sent it; 0, or PORO_EXIT_ERROR when
 * stdout cannot be written. */
int cli_print_json(const json_t *v);
/* Seconds as "M:SS" or "H:MM:SS" into out[32]; "-" when negative. Returns out. */
const char *cli_duration(double seconds, char out[32]);
/* An RFC 3339 UTC time of the server ("2026-12-04T10:11:12.345Z") as seconds since the epoch, or -1. */
double cli_parse_time(const char *text);
/* Wall-clock time, seconds since the epoch. */
double cli_now(void);
/* Sleeps for seconds. */
void cli_sleep(double seconds);

/* ---- the commands (jobs.c, wait.c, logs.c, fetch.c, token.c) ---- */
int cmd_submit(const struct subcommand *self, int argc, char **argv);
int cmd_wait(const struct subcommand *self, int argc, char **argv);
int cmd_ls(const struct subcommand *self, int argc, char **argv);
int cmd_show(const struct subcommand *self, int argc, char **argv);
int cmd_cancel(const struct subcommand *self, int argc, char **argv);
int cmd_rm(const struct subcommand *self, int argc, char **argv);
int cmd_logs(const struct subcommand *self, int argc, char **argv);
int cmd_fetch(const struct subcommand *self, int argc, char **argv);
int cmd_token(const struct subcommand *self, int argc, char **argv);
int cmd_nightly(const struct subcommand *self, int argc, char **argv);   /* nightly.c */

/* Follows job id until it ends (wait.c): a progress bar on stderr when stdout and stderr are
 * terminals, else a line per state change and per tenth of progress; with json the final job on
 * stdout. Returns the exit status of its end (cli_exit_of_state) or of a failed request. */
int cli_wait_job(long long id, int json);

#endif
