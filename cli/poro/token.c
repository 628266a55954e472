/*
 * token.c - `poro token ls [--json]` and `poro token revoke [--json] ID` (cli.h, docs/service.md §3
 * "Operators"): the caller's tokens (an admin's lists every token), by id and fingerprint, never
 * the token itself. ls reads every page; with --json it prints them as one page,
 * {"tokens": [...], "next_after": null}.
 */
#define _GNU_SOURCE
#include "cli.h"

#include <string.h>

#include "json_get.h"

#define TOKEN_PAGE 1000

static void token_row(const json_t *t)
{
	const char *label = json_get_str(t, "label", NULL), *revoked = json_get_str(t, "revoked_at", NULL);
	const char *used = json_get_str(t, "last_used_at", NULL);
	printf("%-6lld %-12.12s %-7s %-11s %-24s %-24s %-24s %s\n", json_get_int(t, "id", -1),
	       json_get_str(t, "user", "-"), json_get_str(t, "role", "-"), json_get_str(t, "fingerprint", "-"),
	       json_get_str(t, "created_at", "-"), used ? used : "-", revoked ? revoked : "-", label ? label : "-");
}

/* Every page of GET /v1/tokens into one array. */
static int token_ls(int json)
{
	json_t *all = json_array();
	long long after = 0;
	do {
		char path[96];
		snprintf(path, sizeof path, "/v1/tokens?limit=%d", TOKEN_PAGE);
		if (after)
			snprintf(path, sizeof path, "/v1/tokens?limit=%d&after=%lld", TOKEN_PAGE, after);
		struct http_response r;
		if (cli_call("GET", path, NULL, NULL, &r) != 200) {
			json_decref(all);
			return cli_fail(&r);
		}
		json_array_extend(all, json_object_get(r.json, "tokens"));
		after = json_get_int(r.json, "next_after", 0);
		http_response_release(&r);
	} while (after > 0);
	int rc = PORO_EXIT_OK;
	if (json) {
		json_t *page = json_pack("{s:O, s:n}", "tokens", all, "next_after");
		rc = cli_print_json(page);
		json_decref(page);
	} else {
		printf("%-6s %-12s %-7s %-11s %-24s %-24s %-24s %s\n", "ID", "USER", "ROLE", "FINGERPRINT", "CREATED",
		       "LAST USED", "REVOKED", "LABEL");
		size_t i;
		json_t *t;
		json_array_foreach(all, i, t)
			token_row(t);
	}
	json_decref(all);
	return rc;
}

static int token_revoke(long long id, int json)
{
	char path[64];
	snprintf(path, sizeof path, "/v1/tokens/%lld", id);
	struct http_response r;
	if (cli_call("DELETE", path, NULL, NULL, &r) != 200)
		return cli_fail(&r);
	int rc = PORO_EXIT_OK;
	if (json)
		rc = cli_print_json(r.json);
	else
		printf("token %lld of '%s' (fingerprint %s) revoked at %s\n", id, json_get_str(r.json, "user", "?"),
		       json_get_str(r.json, "fingerprint", "?"), json_get_str(r.json, "revoked_at", "?"));
	http_response_release(&r);
	return rc;
}

int cmd_token(const struct subcommand *self, int argc, char **argv)
{
	static const struct option opts[] = {
		{ "json", no_argument, NULL, 'j' }, { "help", no_argument, NULL, 'h' }, { NULL, 0, NULL, 0 }
	};
	int json = 0, c, rc;
	while ((c = getopt_long(argc, argv, "hj", opts, NULL)) != -1) {
		if (c == 'h')
			return cli_help(self);
		if (c != 'j')
			return cli_usage_error(self, NULL);
		json = 1;
	}
	const char *what = optind < argc ? argv[optind] : NULL;
	if (!what)
		return cli_usage_error(self, "missing ls or revoke");
	if (!strcmp(what, "ls")) {
		optind++;
		return (rc = cli_positional(self, argc, argv, 0, "")) || (rc = cli_connect()) ? rc : token_ls(json);
	}
	if (strcmp(what, "revoke"))
		return cli_usage_error(self, "unknown token command '%s': ls or revoke", what);
	optind++;
	long long id;
	if ((rc = cli_positional(self, argc, argv, 1, "the token ID")) || (rc = cli_parse_id(self, argv[optind], &id)) ||
	    (rc = cli_connect()))
		return rc;
	return token_revoke(id, json);
}
