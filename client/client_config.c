/*
 * client_config.c - reads PORO_SERVER / PORO_TOKEN and the `name = value` config file, see
 * client_config.h. Unknown names are refused so a typo ("tokn = ...") is reported, not ignored.
 */
#include "client_config.h"

#include <ctype.h>
#include <arpa/inet.h>
#include <errno.h>
#include <netdb.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char *trim(char *s)
{
	while (isspace((unsigned char)*s))
		s++;
	size_t n = strlen(s);
	while (n > 0 && isspace((unsigned char)s[n - 1]))
		s[--n] = '\0';
	return s;
}

static void set_if_empty(char *dst, size_t size, const char *value)
{
	if (!dst[0] && value && *value)
		snprintf(dst, size, "%s", value);
}

static int config_path(char *path, size_t size)
{
	const char *xdg = getenv("XDG_CONFIG_HOME");
	const char *home = getenv("HOME");
	if (xdg && *xdg)
		return snprintf(path, size, "%s/poro/config", xdg) < (int)size ? 0 : -1;
	if (home && *home)
		return snprintf(path, size, "%s/.config/poro/config", home) < (int)size ? 0 : -1;
	return -1;
}

int client_config_load(struct client_config *cfg, char *err, size_t err_size)
{
	set_if_empty(cfg->server, sizeof cfg->server, getenv("PORO_SERVER"));
	set_if_empty(cfg->token, sizeof cfg->token, getenv("PORO_TOKEN"));
	set_if_empty(cfg->ca_file, sizeof cfg->ca_file, getenv("PORO_CA_FILE"));
	const char *plain = getenv("PORO_ALLOW_PLAIN_HTTP");
	if (plain && (!strcmp(plain, "1") || !strcmp(plain, "yes")))
		cfg->allow_plain_http = 1;
	if (cfg->server[0] && cfg->token[0])
		return 0;
	char path[1024];
	if (config_path(path, sizeof path) < 0)
		return 0;
	FILE *f = fopen(path, "r");
	if (!f) {
		if (errno == ENOENT)
			return 0;
		snprintf(err, err_size, "cannot read '%s': %s", path, strerror(errno));
		return -1;
	}
	char line[2048];
	int lineno = 0, status = 0;
	while (fgets(line, sizeof line, f)) {
		lineno++;
		char *s = trim(line);
		if (!*s || *s == '#')
			continue;
		char *eq = strchr(s, '=');
		if (!eq) {
			snprintf(err, err_size, "'%s' line %d: expected 'name = value'", path, lineno);
			status = -1;
			break;
		}
		*eq = '\0';
		char *name = trim(s), *value = trim(eq + 1);
		if (!strcmp(name, "server")) {
			set_if_empty(cfg->server, sizeof cfg->server, value);
		} else if (!strcmp(name, "token")) {
			set_if_empty(cfg->token, sizeof cfg->token, value);
		} else if (!strcmp(name, "ca_file")) {
			set_if_empty(cfg->ca_file, sizeof cfg->ca_file, value);
		} else if (!strcmp(name, "allow_plain_http") && (!strcmp(value, "yes") || !strcmp(value, "no"))) {
			cfg->allow_plain_http |= !strcmp(value, "yes");
		} else {
			snprintf(err, err_size, "'%s' line %d: unknown setting '%s'", path, lineno, name);
			status = -1;
			break;
		}
	}
	fclose(f);
	return status;
}

/* 1 when every address host resolves to is loopback. */
static int loopback_only(const char *host)
{
	struct addrinfo hints = { .ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM };
	struct addrinfo *ai = NULL;
	if (getaddrinfo(host, NULL, &hints, &ai) != 0)
		return 0;
	int all = ai != NULL;
	for (struct addrinfo *a = ai; a; a = a->ai_next) {
		if (a->ai_family == AF_INET)
			all &= (ntohl(((struct sockaddr_in *)(void *)a->ai_addr)->sin_addr.s_addr) >> 24) == 127;
		else if (a->ai_family == AF_INET6)
			all &= IN6_IS_ADDR_LOOPBACK(&((struct sockaddr_in6 *)(void *)a->ai_addr)->sin6_addr);
		else
			all = 0;
	}
	freeaddrinfo(ai);
	return all;
}

int client_config_check_server(const struct client_config *cfg, char *err, size_t err_size)
{
	const char *url = cfg->server;
	int tls = !strncmp(url, "https://", 8);
	if (!tls && strncmp(url, "http://", 7)) {
		snprintf(err, err_size, "server URL '%s' must start with http:// or https://", url);
		return -1;
	}
	if (cfg->ca_file[0] && access(cfg->ca_file, R_OK) != 0) {
		snprintf(err, err_size, "cannot read the CA file '%s': %s", cfg->ca_file, strerror(errno));
		return -1;
	}
	if (tls || cfg->allow_plain_http)
		return 0;
	/* the host: between "http://" and the port, path or end; "[v6]" unbracketed */
	const char *h = url + 7;
	char host[256];
	size_t n;
	if (*h == '[') {
		n = strcspn(++h, "]");
	} else {
		n = strcspn(h, ":/?#");
	}
	if (n == 0 || n >= sizeof host) {
		snprintf(err, err_size, "server URL '%s' has no host", url);
		return -1;
	}
	memcpy(host, h, n);
	host[n] = '\0';
	if (loopback_only(host))
		return 0;
	snprintf(err, err_size, "refusing plain HTTP to '%s', which is not a loopback address: the token would cross "
		 "the network in clear text; use an https:// URL (with PORO_CA_FILE or --ca-file for the server's "
		 "certificate authority), or set PORO_ALLOW_PLAIN_HTTP=1 to send it anyway", host);
	return -1;
}
