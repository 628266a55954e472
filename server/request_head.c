/*
 * request_head.c - the check of a request's head before libmicrohttpd parses it (request_head.h),
 * after RFC 9112 §2-§6: a request line "METHOD SP TARGET SP HTTP/1.x", then fields "name: value",
 * each line ended by CRLF or a bare LF (as libmicrohttpd accepts), then an empty line.
 */
#include "request_head.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

/* tchar of RFC 9110 §5.6.2: the characters of methods and field names. */
static int is_tchar(unsigned char c)
{
	return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
	       (c && strchr("!#$%&'*+-.^_`|~", c));
}

static enum head_verdict refuse(struct head_refusal *why, int status, enum api_code code, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));

static enum head_verdict refuse(struct head_refusal *why, int status, enum api_code code, const char *fmt, ...)
{
	why->status = status;
	why->code = code;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(why->message, sizeof why->message, fmt, ap);
	va_end(ap);
	return HEAD_REFUSED;
}

static enum head_verdict malformed(struct head_refusal *why, const char *what)
{
	return refuse(why, 400, API_MALFORMED_REQUEST, "malformed HTTP request: %s", what);
}

/* The end of the line starting at p (its LF) within end, or NULL. */
static const char *line_end(const char *p, const char *end)
{
	return memchr(p, '\n', (size_t)(end - p));
}

/* The length of a line without its CR LF or LF. */
static size_t line_length(const char *p, const char *lf)
{
	size_t n = (size_t)(lf - p);
	return n && p[n - 1] == '\r' ? n - 1 : n;
}

static enum head_verdict request_line(const char *p, size_t n, struct request_head *h, struct head_refusal *why)
{
	const char *sp1 = memchr(p, ' ', n);
	if (!sp1 || sp1 == p)
		return malformed(why, "the request line has no method");
	for (const char *c = p; c < sp1; c++)
		if (!is_tchar((unsigned char)*c))
			return malformed(why, "the method holds a character outside RFC 9110's token");
	const char *rest = sp1 + 1, *stop = p + n;
	const char *sp2 = memchr(rest, ' ', (size_t)(stop - rest));
	if (!sp2 || sp2 == rest)
		return malformed(why, "the request line is not 'METHOD TARGET HTTP/1.x'");
	if ((size_t)(sp2 - rest) > REQUEST_TARGET_MAX)
		return refuse(why, 414, API_URI_TOO_LONG, "request target longer than %d bytes", REQUEST_TARGET_MAX);
	for (const char *c = rest; c < sp2; c++)
		if ((unsigned char)*c <= 0x20 || (unsigned char)*c >= 0x7f)
			return malformed(why, "the request target holds a space, a control or a non-ASCII byte");
	const char *version = sp2 + 1;
	size_t vn = (size_t)(stop - version);
	if (vn != 8 || memcmp(version, "HTTP/", 5) != 0 || version[6] != '.' || version[5] < '0' || version[5] > '9' ||
	    version[7] < '0' || version[7] > '9')
		return malformed(why, "the request line does not end in HTTP/<digit>.<digit>");
	if (version[5] != '1')
		return refuse(why, 505, API_VERSION_NOT_SUPPORTED, "HTTP version '%.8s' is not supported: use HTTP/1.1",
			      version);
	h->method = p;
	h->method_len = (size_t)(sp1 - p);
	h->target = rest;
	h->target_len = (size_t)(sp2 - rest);
	h->minor = version[7] - '0';
	return HEAD_OK;
}

static int field_is(const char *name, size_t len, const char *want)
{
	return len == strlen(want) && strncasecmp(name, want, len) == 0;
}

/* One "name: value" line: checks it and records what the head needs. */
static enum head_verdict field(const char *p, size_t n, struct request_head *h, int *hosts, struct head_refusal *why)
{
	const char *colon = memchr(p, ':', n);
	if (p[0] == ' ' || p[0] == '\t')
		return malformed(why, "a header field is folded onto a second line (obsolete, RFC 9112 §5.2)");
	if (!colon || colon == p)
		return malformed(why, "a header line has no 'name:'");
	for (const char *c = p; c < colon; c++)
		if (!is_tchar((unsigned char)*c))
			return malformed(why, "a header field name holds a character outside RFC 9110's token");
	const char *v = colon + 1, *end = p + n;
	for (const char *c = v; c < end; c++)
		if (((unsigned char)*c < 0x20 && *c != '\t') || (unsigned char)*c == 0x7f)
			return malformed(why, "a header field value holds a control character");
	while (v < end && (*v == ' ' || *v == '\t'))
		v++;
	while (end > v && (end[-1] == ' ' || end[-1] == '\t'))
		end--;
	size_t name_len = (size_t)(colon - p), vlen = (size_t)(end - v);
	if (field_is(p, name_len, "Host")) {
		(*hosts)++;
	} else if (field_is(p, name_len, "Content-Length")) {
		long long value = 0;
		if (vlen == 0 || vlen > 18)
			return vlen > 18 ? refuse(why, 413, API_TOO_LARGE, "Content-Length of %zu digits is beyond any limit", vlen)
					 : malformed(why, "Content-Length is empty");
		for (size_t i = 0; i < vlen; i++) {
			if (v[i] < '0' || v[i] > '9')
				return malformed(why, "Content-Length is not a decimal number");
			value = 10 * value + (v[i] - '0');
		}
		if (h->content_length >= 0 && h->content_length != value)
			return malformed(why, "two Content-Length fields disagree");
		h->content_length = value;
	} else if (field_is(p, name_len, "Transfer-Encoding")) {
		if (vlen != 7 || strncasecmp(v, "chunked", 7) != 0)
			return refuse(why, 501, API_NOT_IMPLEMENTED,
				      "transfer coding '%.*s' is not supported: send Content-Length or 'chunked'",
				      (int)(vlen < 40 ? vlen : 40), v);
		h->chunked = 1;
	} else if (field_is(p, name_len, "Authorization") && vlen > 7 && strncasecmp(v, "Bearer ", 7) == 0) {
		h->bearer = v + 7;
		h->bearer_len = vlen - 7;
	}
	return HEAD_OK;
}

enum head_verdict request_head_parse(const char *buf, size_t n, struct request_head *h, struct head_refusal *why)
{
	memset(h, 0, sizeof *h);
	h->content_length = -1;
	const char *p = buf, *end = buf + (n < REQUEST_HEAD_MAX ? n : REQUEST_HEAD_MAX);
	while (p < end && (*p == '\r' || *p == '\n')) /* empty lines before the request line (RFC 9112 §2.2) */
		p++;
	const char *lf = line_end(p, end);
	if (!lf)
		return n >= REQUEST_HEAD_MAX ? refuse(why, 414, API_URI_TOO_LONG, "request line longer than %d bytes",
						      REQUEST_HEAD_MAX)
					     : HEAD_INCOMPLETE;
	enum head_verdict v = request_line(p, line_length(p, lf), h, why);
	if (v != HEAD_OK)
		return v;
	int hosts = 0, fields = 0;
	for (p = lf + 1;; p = lf + 1) {
		lf = line_end(p, end);
		if (!lf)
			return n >= REQUEST_HEAD_MAX
				       ? refuse(why, 431, API_HEADERS_TOO_LARGE, "request head larger than %d bytes",
						REQUEST_HEAD_MAX)
				       : HEAD_INCOMPLETE;
		size_t len = line_length(p, lf);
		if (len == 0)
			break;
		if (++fields > REQUEST_FIELDS_MAX)
			return refuse(why, 431, API_HEADERS_TOO_LARGE, "more than %d header fields", REQUEST_FIELDS_MAX);
		if ((v = field(p, len, h, &hosts, why)) != HEAD_OK)
			return v;
	}
	h->size = (size_t)(lf + 1 - buf);
	if (h->minor >= 1 && hosts != 1)
		return malformed(why, hosts ? "more than one Host field" : "HTTP/1.1 request without a Host field");
	if (h->chunked && h->content_length >= 0)
		return malformed(why, "both Content-Length and Transfer-Encoding");
	if (h->chunked && h->minor == 0)
		return malformed(why, "Transfer-Encoding in an HTTP/1.0 request");
	return HEAD_OK;
}
