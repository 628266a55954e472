/*
 * request_head_fuzz.c - libFuzzer target: the front door's request-head parser
 * (server/request_head.c), which reads every connection's first bytes before anything else does.
 *
 * The input is what a client sent. The parser must not read past it, and its answer must hold
 * together: an accepted head lies within the bytes given, its method and target point into them,
 * a refusal carries a 4xx or 5xx status and a message. The parser is also given each prefix that
 * ends at a line break, as a head arrives in pieces: a prefix must never be accepted with a size
 * beyond itself.
 */
#include "request_head.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void check(const char *buf, size_t n)
{
	struct request_head h;
	struct head_refusal why;
	memset(&why, 0, sizeof why);
	enum head_verdict v = request_head_parse(buf, n, &h, &why);
	if (v == HEAD_OK) {
		if (h.size == 0 || h.size > n)
			abort();
		if (h.method < buf || h.method + h.method_len > buf + h.size)
			abort();
		if (h.target < buf || h.target + h.target_len > buf + h.size)
			abort();
		if (h.bearer && (h.bearer < buf || h.bearer + h.bearer_len > buf + h.size))
			abort();
	} else if (v == HEAD_REFUSED) {
		if (why.status < 400 || why.status > 599 || why.message[0] == '\0')
			abort();
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	/* a copy of exactly size bytes, so AddressSanitizer sees any read past the end */
	char *buf = malloc(size ? size : 1);
	if (!buf)
		return 0;
	memcpy(buf, data, size);
	check(buf, size);
	for (size_t i = 0; i < size; i++)
		if (buf[i] == '\n')
			check(buf, i + 1);
	free(buf);
	return 0;
}
