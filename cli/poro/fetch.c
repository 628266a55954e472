/*
 * fetch.c - `poro fetch ID [--out DIR] [--file NAME]...` (cli.h): files of a job into DIR, each
 * written to NAME.part, checked against the SHA-256 the server sent with it, then renamed, so a
 * file in DIR is always whole.
 *
 * Without --file: result.h5 and result.xdmf. A job that has not ended has no result.xdmf yet, but
 * its worker uploads a snapshot of result.h5 with every checkpoint (docs/service.md §2,
 * "Checkpoints and resume"), taken while the solver does not write it, so it holds every frame
 * written up to then and opens with any HDF5 reader; the server serves the newest. fetch then gets
 * that result.h5 and says it is partial. With --file, any file the job lists (`poro show ID`:
 * checkpoint.h5, probes.json, ...), and "log": the log text of the current attempt, as DIR/log.
 */
#define _GNU_SOURCE
#include "cli.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>

#include "digest.h"
#include "json_get.h"

#define FILE_NAME_MAX 128
#define FILES_MAX 32
/* --file NAME for the log text rather than a stored file. */
#define LOG_NAME "log"

/* The server's rule for file names (api_file_name_valid): ^[A-Za-z0-9][A-Za-z0-9._-]{0,127}$, no "..". */
static int file_name_valid(const char *name)
{
	size_t n = strlen(name);
	if (n == 0 || n > FILE_NAME_MAX || strstr(name, ".."))
		return 0;
	for (size_t i = 0; i < n; i++) {
		char c = name[i];
		int alnum = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
		if (!alnum && (i == 0 || (c != '.' && c != '_' && c != '-')))
			return 0;
	}
	return 1;
}

/* The newest listed version of file name: its entry, or NULL. */
static const json_t *listed(const json_t *job, const char *name)
{
	const json_t *best = NULL;
	size_t i;
	json_t *f;
	json_array_foreach(json_object_get(job, "files"), i, f)
		if (!strcmp(json_get_str(f, "name", ""), name) &&
		    (!best || json_get_int(f, "attempt", 0) >= json_get_int(best, "attempt", 0)))
			best = f;
	return best;
}

/* "poro: job 12 has no file 'x' (its files: a, b, log)". */
static int no_such_file(long long id, const json_t *job, const char *name)
{
	fprintf(stderr, "poro: job %lld has no file '%s' (its files: ", id, name);
	size_t i;
	json_t *f;
	json_array_foreach(json_object_get(job, "files"), i, f)
	{
		const char *n = json_get_str(f, "name", "?");
		if (listed(job, n) == f)   /* each name once */
			fprintf(stderr, "%s, ", n);
	}
	fprintf(stderr, "%s)\n", LOG_NAME);
	return PORO_EXIT_NOT_FOUND;
}

/* Downloads path of the server into dir/name through dir/name.part; want is the SHA-256 expected
 * when the answer carries none (NULL: take what came). */
static int download(const char *path, const char *dir, const char *name, const char *want)
{
	char part[4200], dest[4200], sha[DIGEST_HEX_SIZE];
	snprintf(part, sizeof part, "%s/%s.part", dir, name);
	snprintf(dest, sizeof dest, "%s/%s", dir, name);
	struct http_response r;
	long long size = 0;
	http_download(cli_http, path, part, sha, &size, &r);
	if (r.status == 0 && !r.local) {
		/* broken off mid-way: asked again, a server that cut a damaged file says so at once */
		http_response_release(&r);
		http_download(cli_http, path, part, sha, &size, &r);
	}
	if (!http_ok(&r))
		return cli_fail(&r);
	/* the server's checksum of what it sent: for a running job the listing may be older already */
	const char *expected = r.sha256[0] ? r.sha256 : want;
	if (expected && !digest_hex_equal(sha, expected)) {
		remove(part);
		fprintf(stderr, "poro: '%s' arrived with SHA-256 %s but the server has %s; removed\n", name, sha, expected);
		http_response_release(&r);
		return PORO_EXIT_ERROR;
	}
	http_response_release(&r);
	if (rename(part, dest) < 0) {
		fprintf(stderr, "poro: cannot rename '%s' to '%s': %s\n", part, dest, strerror(errno));
		remove(part);
		return PORO_EXIT_ERROR;
	}
	printf("%s  %lld bytes  sha256 %s\n", dest, size, sha);
	fflush(stdout);
	return PORO_EXIT_OK;
}

static int fetch_one(long long id, const json_t *job, const char *name, const char *dir)
{
	char path[256];
	if (!strcmp(name, LOG_NAME)) {
		snprintf(path, sizeof path, "/v1/jobs/%lld/log", id);
		return download(path, dir, name, NULL);
	}
	const json_t *f = listed(job, name);
	if (!f)
		return no_such_file(id, job, name);
	snprintf(path, sizeof path, "/v1/jobs/%lld/files/%s", id, name);
	return download(path, dir, name, json_get_str(f, "sha256", NULL));
}

/* Without --file: result.h5 and result.xdmf of an ended job; of a job still going, the snapshot
 * of result.h5 there is, said to be partial. */
static int fetch_result(long long id, const json_t *job, const char *dir)
{
	const char *state = json_get_str(job, "state", "?");
	if (cli_terminal(state)) {
		int rc = fetch_one(id, job, "result.h5", dir), rc2 = fetch_one(id, job, "result.xdmf", dir);
		return rc ? rc : rc2;
	}
	const json_t *f = listed(job, "result.h5");
	if (!f) {
		fprintf(stderr, "poro: job %lld is %s and has no result.h5 yet: its worker uploads one with every "
			"checkpoint\n", id, state);
		return PORO_EXIT_NOT_FOUND;
	}
	int rc = fetch_one(id, job, "result.h5", dir);
	if (rc == PORO_EXIT_OK)
		fprintf(stderr, "poro: job %lld is %s: result.h5 is partial, the snapshot of attempt %lld at its "
			"last checkpoint; fetch again once the job has ended for the whole result\n", id, state,
			json_get_int(f, "attempt", 0));
	return rc;
}

int cmd_fetch(const struct subcommand *self, int argc, char **argv)
{
	static const struct option opts[] = {
		{ "out", required_argument, NULL, 'o' }, { "file", required_argument, NULL, 'f' },
		{ "help", no_argument, NULL, 'h' },      { NULL, 0, NULL, 0 }
	};
	const char *dir = ".", *names[FILES_MAX];
	int count = 0, c, rc;
	long long id;
	while ((c = getopt_long(argc, argv, "ho:f:", opts, NULL)) != -1) {
		switch (c) {
		case 'h': return cli_help(self);
		case 'o': dir = optarg; break;
		case 'f':
			if (!file_name_valid(optarg))
				return cli_usage_error(self, "--file: '%s' is not a file name: names match "
							     "^[A-Za-z0-9][A-Za-z0-9._-]{0,127}$ without '..'", optarg);
			if (count == FILES_MAX)
				return cli_usage_error(self, "--file: at most %d files at once", FILES_MAX);
			names[count++] = optarg;
			break;
		default: return cli_usage_error(self, NULL);
		}
	}
	if ((rc = cli_positional(self, argc, argv, 1, "the job ID")) || (rc = cli_parse_id(self, argv[optind], &id)) ||
	    (rc = cli_connect()))
		return rc;
	if (mkdir(dir, 0755) < 0 && errno != EEXIST) {
		fprintf(stderr, "poro: cannot create '%s': %s\n", dir, strerror(errno));
		return PORO_EXIT_ERROR;
	}
	struct http_response r;
	if (cli_get_job(id, &r) != 200)
		return cli_fail(&r);
	rc = count ? PORO_EXIT_OK : fetch_result(id, r.json, dir);
	for (int i = 0; i < count; i++) {   /* every file is tried; the first failure gives the status */
		int one = fetch_one(id, r.json, names[i], dir);
		rc = rc ? rc : one;
	}
	http_response_release(&r);
	return rc;
}
