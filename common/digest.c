/*
 * digest.c - SHA-256 through OpenSSL's EVP interface, tokens from getrandom(2). See digest.h.
 */
#define _GNU_SOURCE
#include "digest.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>

#include <openssl/evp.h>

struct digest {
	EVP_MD_CTX *ctx;
};

struct digest *digest_create(void)
{
	struct digest *d = calloc(1, sizeof *d);
	if (!d)
		return NULL;
	d->ctx = EVP_MD_CTX_new();
	if (!d->ctx || EVP_DigestInit_ex(d->ctx, EVP_sha256(), NULL) != 1) {
		EVP_MD_CTX_free(d->ctx);
		free(d);
		return NULL;
	}
	return d;
}

void digest_update(struct digest *d, const void *data, size_t size)
{
	EVP_DigestUpdate(d->ctx, data, size);
}

static void to_hex(const unsigned char *raw, unsigned n, char *hex)
{
	static const char digits[] = "0123456789abcdef";
	for (unsigned i = 0; i < n; i++) {
		hex[2 * i] = digits[raw[i] >> 4];
		hex[2 * i + 1] = digits[raw[i] & 15];
	}
	hex[2 * n] = '\0';
}

void digest_final_hex(struct digest *d, char hex[DIGEST_HEX_SIZE])
{
	unsigned char raw[EVP_MAX_MD_SIZE];
	unsigned n = 0;
	EVP_DigestFinal_ex(d->ctx, raw, &n);
	to_hex(raw, n, hex);
	EVP_DigestInit_ex(d->ctx, EVP_sha256(), NULL);
}

void digest_destroy(struct digest **d)
{
	if (!d || !*d)
		return;
	EVP_MD_CTX_free((*d)->ctx);
	free(*d);
	*d = NULL;
}

void digest_hex(const void *data, size_t size, char hex[DIGEST_HEX_SIZE])
{
	unsigned char raw[EVP_MAX_MD_SIZE];
	unsigned n = 0;
	EVP_Digest(data, size, raw, &n, EVP_sha256(), NULL);
	to_hex(raw, n, hex);
}

int digest_file_hex(const char *path, char hex[DIGEST_HEX_SIZE], long long *size)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return -1;
	struct digest *d = digest_create();
	if (!d) {
		fclose(f);
		errno = ENOMEM;
		return -1;
	}
	unsigned char buf[1 << 16];
	long long total = 0;
	size_t got;
	while ((got = fread(buf, 1, sizeof buf, f)) > 0) {
		digest_update(d, buf, got);
		total += (long long)got;
	}
	int failed = ferror(f);
	fclose(f);
	digest_final_hex(d, hex);
	digest_destroy(&d);
	if (failed) {
		errno = EIO;
		return -1;
	}
	if (size)
		*size = total;
	return 0;
}

int digest_new_token(char out[DIGEST_TOKEN_SIZE])
{
	static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
	unsigned char raw[32];
	if (getrandom(raw, sizeof raw, 0) != (ssize_t)sizeof raw)
		return -1;
	memcpy(out, "poro_", 5);
	/* 256 bits as 43 six-bit groups (the last one padded with zero bits) */
	for (int i = 0; i < 43; i++) {
		int bit = 6 * i, byte = bit / 8, shift = bit % 8;
		unsigned v = (unsigned)raw[byte] << 8 | (byte + 1 < 32 ? raw[byte + 1] : 0);
		out[5 + i] = alphabet[(v >> (10 - shift)) & 63];
	}
	out[48] = '\0';
	return 0;
}

int digest_hex_equal(const char *a, const char *b)
{
	size_t na = strlen(a), nb = strlen(b);
	unsigned diff = na != nb;
	for (size_t i = 0; i < na && i < nb; i++)
		diff |= (unsigned)(a[i] ^ b[i]);
	return diff == 0;
}
