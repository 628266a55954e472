/*
 * client_config.h - where the service clients (poro, poro-worker, poro-load) find the server URL
 * and the token: the environment variables PORO_SERVER and PORO_TOKEN first, then the file
 * ~/.config/poro/config (or $XDG_CONFIG_HOME/poro/config) with lines `server = URL` and
 * `token = TOKEN`; blank lines and lines starting with '#' are ignored (docs/service.md §5).
 */
#ifndef PORO_CLIENT_CONFIG_H
#define PORO_CLIENT_CONFIG_H

#include <stddef.h>

struct client_config {
	char server[1024]; /* base URL, "" when not found */
	char token[512];   /* bearer token, "" when not found */
};

/* Fills cfg from the environment and the config file; values already set in cfg (from flags) are
 * kept. Returns 0, or -1 with a message in err when the file exists but cannot be read or has a
 * line it does not understand. A missing file is not an error. */
int client_config_load(struct client_config *cfg, char *err, size_t err_size);

#endif
