/*
 * client_config.c - reads PORO_SERVER / PORO_TOKEN and the `name = value` config file, see
 * client_config.h. Unknown names are refused so a typo ("tokn = ...") is reported, not ignored.
 */
#include "client_config.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
		} else {
			snprintf(err, err_size, "'%s' line %d: unknown setting '%s'", path, lineno, name);
			status = -1;
			break;
		}
	}
	fclose(f);
	return status;
}
