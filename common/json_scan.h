/*
 * json_scan.h - checks JSON text in one pass as it streams in, in constant memory: its syntax
 * (RFC 8259), its nesting depth, the number of values it holds and the length of each string and
 * number. The server runs it over request bodies while they arrive and over uploaded JSON files, so
 * a body whose tree would be too costly to build is refused before jansson allocates anything:
 * a tree costs memory in proportion to its values (tens of bytes each), not to its bytes.
 *
 * It does not decode: escapes and UTF-8 are checked by the parser that reads the text afterwards.
 * Keys count as values, since each costs the parser as much as a small string.
 *
 *     struct json_scan s;
 *     json_scan_init(&s, &(struct json_limits){ .max_depth = 64, .max_values = 200000,
 *                                              .max_token_bytes = 1 << 20 });
 *     if (json_scan_feed(&s, piece, n) != 0 || json_scan_finish(&s) != 0)
 *             refuse(s.error);
 */
#ifndef PORO_JSON_SCAN_H
#define PORO_JSON_SCAN_H

#include <stddef.h>

/* Deepest nesting the scanner can follow at all; json_limits.max_depth is capped to it. */
#define JSON_SCAN_DEPTH_MAX 512

struct json_limits {
	int max_depth;                /* arrays and objects nested, 1 for a flat array */
	long long max_values;         /* values and keys in the whole text */
	size_t max_token_bytes;       /* bytes of one string (without quotes) or number */
};

/* Which limit was broken, for callers that answer each differently. */
enum json_scan_verdict { JSON_SCAN_OK, JSON_SCAN_SYNTAX, JSON_SCAN_TOO_DEEP, JSON_SCAN_TOO_MANY,
			 JSON_SCAN_TOKEN_TOO_LONG };

struct json_scan {
	struct json_limits limits;
	enum json_scan_verdict verdict;
	int state;                    /* private: where in the grammar the next byte falls */
	int in_key;                   /* private: the string being read is an object's key */
	int hex;                      /* private: hex digits still due in a \u escape */
	int depth;
	const char *literal;          /* private: the rest of "true", "false" or "null" being read */
	long long values;
	size_t token;                 /* bytes of the current string or number */
	long long offset;             /* bytes consumed so far */
	long long line, column;       /* of the next byte, from 1, as jansson counts them */
	unsigned char kinds[JSON_SCAN_DEPTH_MAX / 8]; /* bit per level: 1 object, 0 array */
	char error[160];              /* what was wrong and at which byte, once verdict != OK */
};

void json_scan_init(struct json_scan *s, const struct json_limits *limits);

/* Takes the next size bytes of the text: 0 while everything so far is a valid beginning of one JSON
 * value within the limits, -1 at the first violation (verdict and error say which and where; later
 * calls return -1 at once). */
int json_scan_feed(struct json_scan *s, const char *data, size_t size);

/* At the end of the text: 0 when it was exactly one complete JSON value, -1 with error. */
int json_scan_finish(struct json_scan *s);

#endif
