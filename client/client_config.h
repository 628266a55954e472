/*
 * client_config.h - where the service clients (poro, poro-worker, poro-load) find the server URL
 * and the token: the environment variables PORO_SERVER and PORO_TOKEN first, then the file
 * ~/.config/poro/config (or $XDG_CONFIG_HOME/poro/config) with lines `server = URL` and
 * `token = TOKEN`; blank lines and lines starting with '#' are ignored (docs/service.md §5).
 *
 * TLS (docs/operations.md, "TLS"): PORO_CA_FILE or `ca_file = PATH` names the PEM file of the
 * certificate authorities an https server's certificate is verified against (else the system's);
 * PORO_ALLOW_PLAIN_HTTP=1 or `allow_plain_http = yes` lets an http:// URL name a host that is not
 * loopback, which is otherwise refused: the token would cross the network in clear text.
 */
#ifndef PORO_CLIENT_CONFIG_H
#define PORO_CLIENT_CONFIG_H

#include <stddef.h>

struct client_config {
	char server[1024]; /* base URL, "" when not found */
	char token[512];   /* bearer token, "" when not found */
	char ca_file[1024]; /* PEM certificate authorities for https, "" for the system's */
	int allow_plain_http; /* 1: http:// to a host that is not loopback is allowed */
};

/* Fills cfg from the environment and the config file; values already set in cfg (from flags) are
 * kept. Returns 0, or -1 with a message in err when the file exists but cannot be read or has a
 * line it does not understand. A missing file is not an error. */
int client_config_load(struct client_config *cfg, char *err, size_t err_size);

/* Checks cfg->server before any request: an http or https URL; http only to a loopback host
 * (127.0.0.0/8, ::1, a name resolving only to those) unless cfg->allow_plain_http; a ca_file that
 * can be read. 0, or -1 with a message in err saying what is wrong and how to fix it. */
int client_config_check_server(const struct client_config *cfg, char *err, size_t err_size);

#endif
