/*
 * token_cli.c - `poro-server token create|list|revoke` (token_cli.h):
 *
 *   poro-server token create --state DIR --user NAME --role user|worker|admin [--label TEXT]
 *   poro-server token list   --state DIR
 *   poro-server token revoke --state DIR --id N
 *
 * Options as getopt_long reads them: --state=DIR and --state DIR are the same.
 *
 * create prints the new token and nothing else on stdout (scripts capture it); it is the only
 * place, with the answer of POST /v1/tokens, where a token is ever shown. list shows each token's
 * id, user, role, fingerprint (TOKEN_FINGERPRINT_HEX hex digits of its SHA-256), times and label.
 * revoke takes effect on the running server's next request with that token (it reads the token
 * row on every request).
 */
#include "token_cli.h"
#include "state_dir.h"
#include "store.h"

#include "digest.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LABEL_MAX 128
#define LIST_PAGE 1000

struct token_args {
	struct server_config cfg;
	const char *user, *role, *label, *id;
};

static int token_usage(void)
{
	fprintf(stderr,
		"usage: poro-server token create --state=DIR --user=NAME --role=user|worker|admin [--label=TEXT]\n"
		"       poro-server token list --state=DIR\n"
		"       poro-server token revoke --state=DIR --id=N\n");
	return 2;
}

enum { ARG_STATE = 256, ARG_USER, ARG_ROLE, ARG_LABEL, ARG_ID };
static const struct option TOKEN_OPTIONS[] = {
	{ "state", required_argument, NULL, ARG_STATE }, { "user", required_argument, NULL, ARG_USER },
	{ "role", required_argument, NULL, ARG_ROLE },   { "label", required_argument, NULL, ARG_LABEL },
	{ "id", required_argument, NULL, ARG_ID },       { NULL, 0, NULL, 0 },
};

/* Reads the options after the subcommand (argv[2]) with getopt_long: --name=value or --name
 * value; the subcommand checks which it needs. */
static int parse_token_args(int argc, char **argv, struct token_args *a)
{
	int opt;
	opterr = 0;
	optind = 0;
	/* getopt sees argv[2..]: the subcommand stands where a program's name would */
	while ((opt = getopt_long(argc - 2, argv + 2, ":", TOKEN_OPTIONS, NULL)) != -1) {
		switch (opt) {
		case ARG_STATE:
			if (strlen(optarg) >= sizeof a->cfg.state) {
				fprintf(stderr, "poro-server: token %s: --state is too long\n", argv[2]);
				return -1;
			}
			snprintf(a->cfg.state, sizeof a->cfg.state, "%s", optarg);
			break;
		case ARG_USER: a->user = optarg; break;
		case ARG_ROLE: a->role = optarg; break;
		case ARG_LABEL: a->label = optarg; break;
		case ARG_ID: a->id = optarg; break;
		case ':':
			fprintf(stderr, "poro-server: token %s: '%s' needs a value\n", argv[2], argv[2 + optind - 1]);
			return -1;
		default:
			fprintf(stderr, "poro-server: token %s: unknown argument '%s'\n", argv[2],
				argv[2 + optind - 1]);
			return -1;
		}
	}
	if (optind < argc - 2) {
		fprintf(stderr, "poro-server: token %s: unexpected argument '%s'\n", argv[2], argv[2 + optind]);
		return -1;
	}
	return 0;
}

static int open_or_say(struct token_args *a, struct store **store)
{
	char msg[SERVER_MESSAGE_MAX];
	if (state_dir_open_store(&a->cfg, NULL, store, msg, sizeof msg) != 0) {
		fprintf(stderr, "poro-server: %s\n", msg);
		return -1;
	}
	return 0;
}

/* A label is shown in listings: printable text of 1..LABEL_MAX bytes. */
static int valid_label(const char *label)
{
	size_t n = strlen(label);
	for (size_t i = 0; i < n; i++)
		if ((unsigned char)label[i] < 0x20 || label[i] == 0x7f)
			return 0;
	return n > 0 && n <= LABEL_MAX;
}

static int token_create(struct token_args *a)
{
	enum role role;
	if (!a->user || !a->user[0] || strlen(a->user) > SERVER_NAME_MAX || !a->role || role_parse(a->role, &role) != 0 ||
	    a->id) {
		fprintf(stderr, "poro-server: token create needs --user NAME and --role user|worker|admin\n");
		return 2;
	}
	if (a->label && !valid_label(a->label)) {
		fprintf(stderr, "poro-server: token create: --label must be 1-%d bytes of printable text\n", LABEL_MAX);
		return 2;
	}
	struct store *store = NULL;
	if (open_or_say(a, &store) != 0)
		return 1;
	char token[DIGEST_TOKEN_SIZE], hash[DIGEST_HEX_SIZE];
	struct api_error err = { 0 };
	int rc = 0;
	if (digest_new_token(token) != 0) {
		fprintf(stderr, "poro-server: no randomness available for a token\n");
		rc = 1;
	} else {
		digest_hex(token, strlen(token), hash);
		if (store_token_add(store, a->user, (int)role, hash, a->label, NULL, &err) != API_OK) {
			fprintf(stderr, "poro-server: cannot create a token for '%s': %s\n", a->user, err.message);
			rc = 1;
		}
	}
	store_close(&store);
	if (rc == 0)
		printf("%s\n", token);
	return rc;
}

static const char *text_or_dash(const json_t *v)
{
	return json_is_string(v) ? json_string_value(v) : "-";
}

static void print_token(const json_t *t)
{
	printf("%-6lld %-16s %-7s %-11s %-24s %-24s %-24s %s\n", (long long)json_integer_value(json_object_get(t, "id")),
	       text_or_dash(json_object_get(t, "user")), text_or_dash(json_object_get(t, "role")),
	       text_or_dash(json_object_get(t, "fingerprint")), text_or_dash(json_object_get(t, "created_at")),
	       text_or_dash(json_object_get(t, "last_used_at")), text_or_dash(json_object_get(t, "revoked_at")),
	       text_or_dash(json_object_get(t, "label")));
}

static int token_list(struct token_args *a)
{
	if (a->user || a->role || a->label || a->id)
		return token_usage();
	struct store *store = NULL;
	if (open_or_say(a, &store) != 0)
		return 1;
	printf("%-6s %-16s %-7s %-11s %-24s %-24s %-24s %s\n", "ID", "USER", "ROLE", "FINGERPRINT", "CREATED",
	       "LAST USED", "REVOKED", "LABEL");
	long long after = 0;
	int rc = 0;
	do {
		json_t *page = NULL;
		struct api_error err = { 0 };
		if (store_token_list(store, NULL, LIST_PAGE, after, &page, &err) != API_OK) {
			fprintf(stderr, "poro-server: cannot list tokens: %s\n", err.message);
			rc = 1;
			break;
		}
		size_t i;
		json_t *t;
		json_array_foreach(json_object_get(page, "tokens"), i, t)
			print_token(t);
		json_t *next = json_object_get(page, "next_after");
		after = json_is_integer(next) ? (long long)json_integer_value(next) : 0;
		json_decref(page);
	} while (after > 0);
	store_close(&store);
	return rc;
}

static int token_revoke(struct token_args *a)
{
	char *end = NULL;
	long long id = a->id ? strtoll(a->id, &end, 10) : 0;
	if (!a->id || *end || id <= 0 || a->user || a->role || a->label) {
		fprintf(stderr, "poro-server: token revoke needs --id N (a token id from 'token list')\n");
		return 2;
	}
	struct store *store = NULL;
	if (open_or_say(a, &store) != 0)
		return 1;
	json_t *token = NULL;
	struct api_error err = { 0 };
	int rc = 0;
	if (store_token_revoke(store, NULL, id, &token, &err) != API_OK) {
		fprintf(stderr, "poro-server: cannot revoke token %lld: %s\n", id, err.message);
		rc = 1;
	} else {
		printf("token %lld of '%s' (fingerprint %s) revoked at %s\n", id, text_or_dash(json_object_get(token, "user")),
		       text_or_dash(json_object_get(token, "fingerprint")), text_or_dash(json_object_get(token, "revoked_at")));
		json_decref(token);
	}
	store_close(&store);
	return rc;
}

int token_command(int argc, char **argv, const struct server_config *defaults)
{
	struct token_args a = { .cfg = *defaults };
	if (argc < 3 || parse_token_args(argc, argv, &a) != 0)
		return token_usage();
	if (strcmp(argv[2], "create") == 0)
		return token_create(&a);
	if (strcmp(argv[2], "list") == 0)
		return token_list(&a);
	if (strcmp(argv[2], "revoke") == 0)
		return token_revoke(&a);
	return token_usage();
}
