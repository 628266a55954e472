/*
 * token_cli.h - `poro-server token create|list|revoke`: token set-up and management on the
 * database file itself, without a running server (docs/service.md §3). These commands may run
 * while the server runs: they write through SQLite's own locking, and take no state-directory
 * lock (state_dir.h).
 */
#ifndef PORO_TOKEN_CLI_H
#define PORO_TOKEN_CLI_H

#include "server.h"

/* Runs `poro-server token SUBCOMMAND ...` (argv[1] is "token"); defaults are the server's
 * configuration defaults. Prints what it did (a new token on stdout, nothing else there) or why
 * not, and returns the exit status: 0, 1 when the database refused, 2 for a bad command line. */
int token_command(int argc, char **argv, const struct server_config *defaults);

#endif
