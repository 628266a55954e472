/*
 * tls_files.c - reading and checking the PEM files of --tls-listen (tls_files.h). The contents
 * are checked only for their PEM armour here; GnuTLS parses them when the listener starts.
 */
#include "tls_files.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PEM_MAX_BYTES (1L << 20)

static char *read_pem(const char *path, const char *flag, const char *armour, char *msg, size_t msg_size)
{
	FILE *f = fopen(path, "r");
	if (!f) {
		snprintf(msg, msg_size, "cannot read %s '%s': %s", flag, path, strerror(errno));
		return NULL;
	}
	char *text = malloc(PEM_MAX_BYTES + 1);
	size_t n = text ? fread(text, 1, PEM_MAX_BYTES + 1, f) : 0;
	int failed = ferror(f);
	fclose(f);
	if (!text || failed || n > PEM_MAX_BYTES) {
		snprintf(msg, msg_size, "cannot read %s '%s': %s", flag, path,
			 !text ? "out of memory" : failed ? "read error" : "larger than 1 MiB");
		free(text);
		return NULL;
	}
	text[n] = '\0';
	if (!strstr(text, "-----BEGIN ") || !strstr(text, armour)) {
		snprintf(msg, msg_size, "%s '%s' is not a PEM file holding a %s", flag, path, armour);
		free(text);
		return NULL;
	}
	return text;
}

int tls_files_load(const struct server_config *cfg, char **cert, char **key, char *msg, size_t msg_size)
{
	*cert = *key = NULL;
	if (!cfg->tls_listen[0]) {
		if (!cfg->tls_cert[0] && !cfg->tls_key[0])
			return 0;
		snprintf(msg, msg_size, "--tls-cert and --tls-key need --tls-listen HOST:PORT");
		return -1;
	}
	if (!cfg->tls_cert[0] || !cfg->tls_key[0]) {
		snprintf(msg, msg_size, "--tls-listen needs both --tls-cert FILE and --tls-key FILE");
		return -1;
	}
	if (!(*cert = read_pem(cfg->tls_cert, "--tls-cert", "CERTIFICATE", msg, msg_size)))
		return -1;
	if (!(*key = read_pem(cfg->tls_key, "--tls-key", "PRIVATE KEY", msg, msg_size))) {
		free(*cert);
		*cert = NULL;
		return -1;
	}
	return 0;
}
