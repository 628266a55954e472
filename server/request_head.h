/*
 * request_head.h - the request line and header fields of an HTTP/1.x request, checked before
 * libmicrohttpd sees them (the front door, front_door.c). Whatever libmicrohttpd would refuse
 * itself, with a body of HTML and no hook to change it, is refused here first with the API's JSON
 * error: a head that is too large, a malformed request line or field, a version other than
 * HTTP/1.x, HTTP/1.1 without Host, a bad Content-Length, a transfer coding other than chunked.
 * The check is stricter than libmicrohttpd (no obsolete line folding, one space between the parts
 * of the request line), never looser, so anything it lets through libmicrohttpd accepts too.
 *
 * It also picks out what the front door needs to place the connection: the method, the target and
 * the bearer token, pointing into the caller's buffer.
 */
#ifndef PORO_REQUEST_HEAD_H
#define PORO_REQUEST_HEAD_H

#include <stddef.h>

#include "server.h"

#define REQUEST_HEAD_MAX 16384     /* bytes of request line and fields, the blank line included */
#define REQUEST_TARGET_MAX 8192    /* bytes of the request target */
#define REQUEST_FIELDS_MAX 100     /* header fields */

struct request_head {
	const char *method, *target, *bearer;   /* into the buffer; bearer NULL without one */
	size_t method_len, target_len, bearer_len;
	int minor;                      /* HTTP/1.minor */
	long long content_length;       /* -1 when absent */
	int chunked;
	size_t size;                    /* bytes of the head, through its blank line */
};

/* Why a head was refused: the HTTP status, the API code and a message for the JSON error. */
struct head_refusal {
	int status;
	enum api_code code;
	char message[200];
};

enum head_verdict { HEAD_INCOMPLETE, HEAD_OK, HEAD_REFUSED };

/* Looks at the first n bytes a client sent. HEAD_INCOMPLETE while the head has not ended and may
 * still fit in REQUEST_HEAD_MAX; HEAD_OK with h filled; HEAD_REFUSED with why filled. */
enum head_verdict request_head_parse(const char *buf, size_t n, struct request_head *h, struct head_refusal *why);

#endif
