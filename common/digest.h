/*
 * digest.h - SHA-256 and random tokens for the service (server, worker, CLI). The one file through
 * which OpenSSL's libcrypto enters PoroMPM (libcurl4-openssl-dev already brings it in).
 *
 * Hex digests are 64 lower-case characters plus the terminating NUL (DIGEST_HEX_SIZE).
 */
#ifndef PORO_DIGEST_H
#define PORO_DIGEST_H

#include <stddef.h>

#define DIGEST_SIZE 32
#define DIGEST_HEX_SIZE (2 * DIGEST_SIZE + 1)

/* Incremental SHA-256 for streamed uploads and downloads. */
struct digest;
struct digest *digest_create(void);            /* NULL when out of memory */
void digest_update(struct digest *d, const void *data, size_t size);
void digest_final_hex(struct digest *d, char hex[DIGEST_HEX_SIZE]);  /* d may be reused after init */
void digest_destroy(struct digest **d);

/* One-shot SHA-256 of a buffer, as hex. */
void digest_hex(const void *data, size_t size, char hex[DIGEST_HEX_SIZE]);

/* SHA-256 of a whole file as hex, and its size. Returns 0, or -1 with errno set. */
int digest_file_hex(const char *path, char hex[DIGEST_HEX_SIZE], long long *size);

/* A new bearer token: "poro_" followed by 43 URL-safe base64 characters of 256 random bits from the
 * kernel. out must hold DIGEST_TOKEN_SIZE bytes. Returns 0, or -1 if no randomness was available. */
#define DIGEST_TOKEN_SIZE 49
int digest_new_token(char out[DIGEST_TOKEN_SIZE]);

/* 1 if two hex digests are equal, compared in constant time. */
int digest_hex_equal(const char *a, const char *b);

#endif
