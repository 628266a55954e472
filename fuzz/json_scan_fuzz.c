/*
 * json_scan_fuzz.c - libFuzzer target: the streaming JSON check (common/json_scan.c) against
 * jansson, the parser the server runs after it.
 *
 * The server checks a JSON body while it streams in and, when json_scan accepts it, parses it with
 * jansson; it then takes a jansson syntax error to mean that memory ran out (docs/service.md §1
 * "Admission") and answers 503. So json_scan must never accept what jansson refuses, and what it
 * refuses as bad syntax jansson must refuse too, or a client's error would be answered as the
 * server's and retried forever. What jansson alone refuses (UTF-8, numbers beyond 64 bits, ...)
 * must be among the errors the server answers as the client's. Limits are not compared (jansson
 * has none but depth).
 *
 * NUL bytes are the one known difference, and harmless (below).
 *
 * The input's first byte picks where the body is cut into two feeds (a body arrives in pieces of
 * any size); the rest is the body. Each disagreement aborts with both verdicts.
 */
#include "json_scan.h"

#include <jansson.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size < 1)
		return 0;
	size_t cut = data[0];
	const char *body = (const char *)data + 1;
	size_t n = size - 1;
	if (cut > n)
		cut = n;
	/* limits no fuzzed body reaches, so only syntax is compared; depth stays under jansson's 2048 */
	struct json_limits lim = { .max_depth = 512, .max_values = 1LL << 40, .max_token_bytes = 1u << 30 };
	struct json_scan s;
	json_scan_init(&s, &lim);
	int ok = json_scan_feed(&s, body, cut) == 0 && json_scan_feed(&s, body + cut, n - cut) == 0 &&
		 json_scan_finish(&s) == 0;
	json_error_t jerr;
	memset(&jerr, 0, sizeof jerr);
	json_t *v = json_loadb(body, n, JSON_REJECT_DUPLICATES | JSON_DECODE_ANY, &jerr);
	/* What jansson refuses after json_scan accepted must be one of the client's errors the
	 * server knows (server/api_json.c, api_body_object: UTF-8, \u0000, duplicate keys, numbers
	 * beyond 64 bits, lone surrogates): any other refusal it answers 503 "no memory", which a
	 * client would retry for ever. The same test as there. */
	enum json_error_code code = json_error_code(&jerr);
	int clients = jerr.text[0] != '\0' &&
		      (code == json_error_invalid_utf8 || code == json_error_null_character ||
		       code == json_error_duplicate_key || code == json_error_numeric_overflow ||
		       (code == json_error_invalid_syntax && strncmp(jerr.text, "invalid Unicode", 15) == 0));
	if (ok && !v && !clients) {
		fprintf(stderr, "json_scan accepted what jansson refuses, not as a client's error: %s (line %d column %d)\n",
			jerr.text, jerr.line, jerr.column);
		abort();
	}
	/* The other way round only without NUL bytes: jansson lets a NUL end a number and reads
	 * "[1<NUL>]" as [1] (found by this target); json_scan refuses any NUL outside a string, as
	 * RFC 8259 does, and that refusal is the server's answer (400), so no harm comes of it. */
	if (!ok && s.verdict == JSON_SCAN_SYNTAX && v && !memchr(body, '\0', n)) {
		fprintf(stderr, "json_scan refused what jansson reads: %s\n", s.error);
		abort();
	}
	json_decref(v);
	return 0;
}
