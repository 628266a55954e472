/*
 * backup_cli.c - the command lines of `poro-server backup` and `poro-server restore`
 * (backup_cli.h); the copying is store_backup.c's.
 */
#include "backup_cli.h"
#include "state_dir.h"
#include "store_backup.h"

#include <getopt.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define CLI_PATH_MAX 4352
#define CLI_MESSAGE_MAX 4608

static int backup_usage(const char *why)
{
	if (why)
		fprintf(stderr, "poro-server: %s\n", why);
	fprintf(stderr, "usage: poro-server backup --state=DIR --out=FILE\n"
			"       poro-server restore --state=DIR --from=FILE   (with the server stopped)\n");
	return 2;
}

int backup_command(int argc, char **argv, const char *default_state)
{
	enum { ARG_STATE = 256, ARG_OUT, ARG_FROM };
	static const struct option opts[] = {
		{ "state", required_argument, NULL, ARG_STATE }, { "out", required_argument, NULL, ARG_OUT },
		{ "from", required_argument, NULL, ARG_FROM },   { NULL, 0, NULL, 0 },
	};
	const char *command = argv[1], *state = default_state, *out = NULL, *from = NULL;
	int restore = strcmp(command, "restore") == 0, opt;
	opterr = 0;
	optind = 0;
	/* getopt sees argv[1..]: the command stands where a program's name would */
	while ((opt = getopt_long(argc - 1, argv + 1, ":", opts, NULL)) != -1) {
		if (opt == ARG_STATE)
			state = optarg;
		else if (opt == ARG_OUT && !restore)
			out = optarg;
		else if (opt == ARG_FROM && restore)
			from = optarg;
		else
			return backup_usage(opt == ':' ? "an option needs a value" : "unknown or misplaced option");
	}
	if (optind < argc - 1)
		return backup_usage("unexpected argument");
	if (restore ? !from || !from[0] : !out || !out[0])
		return backup_usage(restore ? "restore needs --from FILE" : "backup needs --out FILE");
	char db[CLI_PATH_MAX], msg[CLI_MESSAGE_MAX];
	snprintf(db, sizeof db, "%s/poro.db", state);
	struct backup_info info;
	if (!restore) {
		if (store_backup(db, out, &info, msg, sizeof msg) != 0) {
			fprintf(stderr, "poro-server: backup failed: %s\n", msg);
			return 1;
		}
		printf("backup of '%s' written to '%s': %lld bytes, integrity ok, %lld jobs (ids up to %lld)\n", db,
		       out, info.bytes, info.jobs, info.max_job);
		return 0;
	}
	int lock = state_dir_lock(state, msg, sizeof msg);
	if (lock < 0) {
		fprintf(stderr, "poro-server: cannot restore while the server runs: %s\n", msg);
		return 1;
	}
	int rc = store_restore(from, db, &info, msg, sizeof msg);
	close(lock);
	if (rc != 0) {
		fprintf(stderr, "poro-server: restore failed: %s\n", msg);
		return 1;
	}
	printf("restored '%s' from '%s': %lld bytes, integrity ok, %lld jobs (ids up to %lld)\n", db, from, info.bytes,
	       info.jobs, info.max_job);
	return 0;
}
