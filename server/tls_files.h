/*
 * tls_files.h - the certificate and key of --tls-listen (docs/operations.md, "TLS"), read and
 * checked before the server starts, so a missing or wrong file stops it with a message naming the
 * file rather than with libmicrohttpd's or GnuTLS's generic failure.
 */
#ifndef PORO_TLS_FILES_H
#define PORO_TLS_FILES_H

#include <stddef.h>

#include "server.h"

/* With cfg->tls_listen set: reads cfg->tls_cert and cfg->tls_key (PEM, at most 1 MiB each) into
 * new strings *cert and *key (the caller frees them) and returns 0. Without it: *cert = *key =
 * NULL, 0, unless a certificate or key was given alone. -1 with a message naming the flag and the
 * file otherwise. */
int tls_files_load(const struct server_config *cfg, char **cert, char **key, char *msg, size_t msg_size);

#endif
