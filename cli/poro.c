/*
 * poro.c - the user's command line for the job service (docs/service.md §3 "Users"):
 *
 *   poro submit CASE.json [--wait] [--json] [--priority N] [--threads N] [--wall-time S] [--memory-mb M]
 *                         [--name NAME] [--idempotency-key K]
 *   poro wait [--json] ID
 *   poro ls [--state S[,S...]] [--limit N] [--after ID] [--json]
 *   poro show [--json] ID
 *   poro logs [-f] ID
 *   poro cancel [--json] ID
 *   poro rm [--json] ID
 *   poro fetch ID [--out DIR] [--file NAME]...
 *   poro token ls [--json] | poro token revoke [--json] ID
 *   poro nightly run|show|compare|ls|report ...   (cli/poro/nightly.c)
 *   poro --help | --version
 *
 * This file holds the command table, the help and main(); the commands are in cli/poro/ (cli.h).
 * Options follow GNU habits through getopt_long: "--opt value" and "--opt=value", options before
 * or after the arguments, "--" ends them. The server URL and token come from PORO_SERVER and
 * PORO_TOKEN, else ~/.config/poro/config. Errors from the server print as "poro: <message>
 * (<code>, field <pointer>)". Exit statuses come from one table, PORO_EXIT_MAP in cli.h, which
 * --help prints.
 */
#define _GNU_SOURCE
#include <stdio.h>

#include "poro/cli.h"

#ifndef PORO_VERSION
#define PORO_VERSION "unknown"
#endif

static const struct subcommand COMMANDS[] = {
	{ "submit",
	  "submit CASE.json [--wait] [--json] [--priority N] [--threads N] [--wall-time S] [--memory-mb M]\n"
	  "                   [--name NAME] [--idempotency-key K]",
	  "Submits a case; prints the new job's id on stdout.\n"
	  "  -w, --wait               follow the job to its end (as poro wait) and exit with its outcome\n"
	  "  -j, --json               print the job as the API answers, instead of the id (with --wait,\n"
	  "                           the job as it ended)\n"
	  "  -p, --priority N         -100..100 (0): order among your own queued jobs, highest first\n"
	  "  -t, --threads N          1..256 (1): threads the solver may use, up to the server's limit\n"
	  "      --wall-time S        1..2592000 seconds (86400): the job fails when it runs longer\n"
	  "      --memory-mb M        0..16777216 MB (0, not stated): only a worker whose solvers may use\n"
	  "                           at least M MB takes the job (its --memory-limit-mb, a pilot's --mem)\n"
	  "  -n, --name NAME          a name shown by ls and show\n"
	  "      --idempotency-key K  a key of yours: the same key and case again give the same job\n"
	  "An invalid case is refused with every problem as 'JSON-pointer: message' (exit 6).\n",
	  cmd_submit },
	{ "wait", "wait [--json] ID",
	  "Follows a job to its end and exits with its outcome: 0 succeeded, 7 failed, 8 cancelled.\n"
	  "On a terminal, a progress bar with elapsed time and time left (a queued job: why it waits);\n"
	  "elsewhere a line per change of state and per tenth of progress, on stderr.\n"
	  "  -j, --json               print the job as it ended, as the API answers\n",
	  cmd_wait },
	{ "ls", "ls [--state S[,S...]] [--limit N] [--after ID] [--json]",
	  "Lists your jobs (an admin: every job), newest first, one page at a time: when more exist, it\n"
	  "says on stderr how to list the next page. ELAPSED is the run time of the current attempt;\n"
	  "WAITING says why a queued job waits (no live worker, your cap on running jobs, behind other\n"
	  "jobs, retry backoff).\n"
	  "  -s, --state S[,S...]     only jobs in these states: queued, running, succeeded, failed, cancelled\n"
	  "  -n, --limit N            1..1000 (100): jobs per page\n"
	  "      --after ID           the page after job ID (what the hint says)\n"
	  "  -j, --json               print the page as the API answers: {\"jobs\": [...], \"next_after\"}\n",
	  cmd_ls },
	{ "show", "show [--json] ID",
	  "Shows a job: its settings, state, why it waits, progress, files and events.\n"
	  "  -j, --json               print the job as the API answers\n",
	  cmd_show },
	{ "logs", "logs [-f] ID",
	  "Prints a job's log. With -f (--follow), follows it through every attempt until the job ends\n"
	  "and exits with the job's outcome: 0 succeeded, 7 failed, 8 cancelled.\n",
	  cmd_logs },
	{ "cancel", "cancel [--json] ID",
	  "Cancels a job: a queued one at once, a running one when its worker has stopped the solver.\n"
	  "  -j, --json               print the job after the cancel, as the API answers\n",
	  cmd_cancel },
	{ "rm", "rm [--json] ID",
	  "Deletes an ended job with its log and files, freeing its stored bytes.\n"
	  "  -j, --json               print what was deleted, as the API answers\n",
	  cmd_rm },
	{ "fetch", "fetch ID [--out DIR] [--file NAME]...",
	  "Downloads files of a job into DIR, each checked against the server's SHA-256. Without --file:\n"
	  "result.h5 and result.xdmf; of a job still running, the snapshot of result.h5 its worker\n"
	  "uploaded at the last checkpoint (partial, yet readable by any HDF5 reader).\n"
	  "  -o, --out DIR            where to write (.): created if missing\n"
	  "  -f, --file NAME          a file the job lists (poro show ID: checkpoint.h5, probes.json, ...),\n"
	  "                           or 'log' for the log text of its current attempt; repeatable\n",
	  cmd_fetch },
	{ "token", "token ls [--json] | token revoke [--json] ID",
	  "Lists your tokens (an admin: every token) by id and fingerprint, or revokes one: it is\n"
	  "refused from its next request on.\n"
	  "  -j, --json               print the tokens or the revoked token as the API answers\n",
	  cmd_token },
	{ "nightly",
	  "nightly run SUITE.json [--label L] [--commit C] [--only CASE]... [--junit FILE] [--html FILE] [--json]\n"
	  "                   | nightly show [ID] [--json] | nightly compare A B [--json]\n"
	  "                   | nightly ls [--suite S] [--limit N] [--json] | nightly report ID [--junit FILE] [--html FILE]\n"
	  "                   | nightly check SUITE.json [--out DIR] [--only CASE]...",
	  "Benchmark nightlies (docs/benchmarks.md). run submits a suite's cases as one batch of jobs (those\n"
	  "timed against history run alone on a worker), follows them with a progress bar, has the server\n"
	  "judge every figure (accuracy against its band, timing by a rank test against the same machine's\n"
	  "recent runs) and prints the verdicts; exit 0 when the run passed, 9 when a figure regressed,\n"
	  "failed or did not run. show prints a run (the latest without ID), compare two side by side (timings\n"
	  "of two machines are not compared), ls the runs, report writes a run's reports, check reads a\n"
	  "suite without a server and prints what run would submit.\n"
	  "  -l, --label L            the batch label of the run's jobs (default SUITE-TIME-RANDOM)\n"
	  "  -c, --commit C           what the run is of (default: git describe of the suite's checkout)\n"
	  "  -o, --only CASE          run (or check) only this case of the suite; repeatable\n"
	  "      --out DIR            check: write each case as it would be submitted into DIR/CASE.json\n"
	  "      --junit FILE         write the run's JUnit XML (any CI reads it)\n"
	  "      --html FILE          write a self-contained HTML report, one plot per figure over the runs\n"
	  "  -s, --suite S            ls: only the runs of suite S\n"
	  "  -n, --limit N            ls: 1..1000 (20) runs, newest first\n"
	  "  -j, --json               print the API's objects\n",
	  cmd_nightly },
};
#define COMMAND_COUNT ((int)(sizeof COMMANDS / sizeof COMMANDS[0]))

static int help(void)
{
	subcommand_list(stdout, "poro", COMMANDS, COMMAND_COUNT);
	printf("\nThe server and the token come from PORO_SERVER and PORO_TOKEN, else from\n"
	       "~/.config/poro/config (lines 'server = URL' and 'token = TOKEN').\n\nExit status:\n");
	cli_print_exit_table(stdout);
	return PORO_EXIT_OK;
}

int main(int argc, char **argv)
{
	int rc = subcommand_main("poro", PORO_VERSION, COMMANDS, COMMAND_COUNT, help, argc, argv);
	cli_disconnect();
	return rc;
}
