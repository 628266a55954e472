/*
 * http_client.h - the HTTP client of the job service's worker, CLI and load generator
 * (docs/service.md §3). http_client.c is the one file through which libcurl enters PoroMPM.
 *
 * A struct http_client holds one curl handle, the server's base URL and a bearer token. Requests
 * reuse the handle, so consecutive calls share one keep-alive connection. A client belongs to one
 * thread at a time; use one client per thread. http_global_init() must run once before any thread
 * starts.
 *
 * Every call fills a struct http_response: the HTTP status (0 when no answer came: connection
 * refused, timeout, abort), the parsed JSON body when the answer is JSON, and for an error answer
 * the server's {"error": {"code", "message", "field"}} copied into code, error and field (the
 * whole error object stays in json, with "problems" of an invalid case). Calls
 * return the status, so `if (http_json(...) == 200)` reads naturally. Nothing here prints.
 */
#ifndef PORO_HTTP_CLIENT_H
#define PORO_HTTP_CLIENT_H

#include <jansson.h>
#include <stdatomic.h>

#include "digest.h"

/* Seconds allowed to establish a connection; the overall limit is per call. */
#define HTTP_CONNECT_TIMEOUT 5
/* A transfer without a timeout is abandoned when it moves under 1 byte/s for this many seconds. */
#define HTTP_STALL_SECONDS 60
/* Largest body kept in memory (JSON answers, error bodies). */
#define HTTP_MAX_BODY (64L << 20)

struct http_response {
	long status;                  /* HTTP status; 0 when no answer came */
	json_t *json;                 /* parsed JSON body or NULL; owned, see http_response_release */
	char sha256[DIGEST_HEX_SIZE]; /* the answer's X-Checksum-Sha256 header, "" when absent */
	char error[512];              /* why it failed: transport error or the server's message */
	char code[64];                /* the server's error.code, "" when none */
	char field[256];              /* the server's error.field, "" when none or null */
	int local;                    /* 1 when the call failed on this side (a file that cannot be
				       * opened, created or written, no memory): status 0, yet not for
				       * want of an answer */
	int tls_unverified;           /* 1 when the server's TLS certificate failed verification: a
				       * setting to fix (the CA file), not a failure to retry */
};

/* Called once per line of a streamed answer, without the newline; a last line without a newline
 * is passed at the end. Return 0 to go on, non-zero to stop the transfer. */
typedef int (*http_line_fn)(const char *line, size_t len, void *user);

/* Once per process before threads start; 0, or -1 when libcurl cannot initialise. */
int http_global_init(void);
void http_global_cleanup(void);

/* Once per process before threads start: https servers' certificates are verified against the
 * certificate authorities in the PEM file ca_file (copied), or the system's when NULL or "".
 * Verification is never switched off; a failed one is an error naming the file. */
void http_global_ca_file(const char *ca_file);

/* A client for server (base URL, e.g. "http://127.0.0.1:8080", a trailing slash is ignored) with
 * token (may be NULL or "" for /healthz). NULL when out of memory. */
struct http_client *http_client_create(const char *server, const char *token);
void http_client_destroy(struct http_client **c);

/* While *flag is non-zero every transfer of c stops at once with status 0 ("aborted"). flag may be
 * NULL; it must outlive c. Used to abandon a long-poll when the worker drains. */
void http_client_set_abort(struct http_client *c, const atomic_int *flag);

/* method on path ("/v1/jobs?..."), with body as the JSON request body (NULL: none) and extra_header
 * as one more "Name: value" header (NULL: none). timeout_seconds bounds the whole call (0: only the
 * stall limit). Returns r->status; r->json holds the parsed answer when it was JSON. */
long http_json(struct http_client *c, const char *method, const char *path, const json_t *body,
	       const char *extra_header, long timeout_seconds, struct http_response *r);

/* GET path into the file at dest (created or truncated), computing the SHA-256 of the bytes as they
 * arrive into sha256 and their count into size (either may be NULL). On any answer but 2xx the
 * file is removed and the error body is parsed into r. Returns r->status. */
long http_download(struct http_client *c, const char *path, const char *dest, char sha256[DIGEST_HEX_SIZE],
		   long long *size, struct http_response *r);

/* PUT the file at src to path with the header X-Checksum-Sha256: sha256 (the caller computed it,
 * normally with digest_file_hex). Returns r->status; r->json holds the answer. */
long http_upload(struct http_client *c, const char *path, const char *src, const char *sha256,
		 struct http_response *r);

/* GET path and pass the answer line by line to fn as it arrives (a followed log). No overall
 * timeout. On an answer other than 2xx, fn is not called and the error body is parsed into r.
 * *received (may be NULL) counts the bytes passed to fn, so a broken stream can be resumed.
 * Returns r->status (the status also when fn stopped the transfer). */
long http_stream_lines(struct http_client *c, const char *path, http_line_fn fn, void *user,
		       long long *received, struct http_response *r);

/* Frees r->json and clears r; r may be reused afterwards. */
void http_response_release(struct http_response *r);

/* 1 when the status is 2xx. */
int http_ok(const struct http_response *r);

/* 1 when repeating the same request may succeed: no answer (but for a TLS certificate that failed
 * verification), 5xx, 408 or 429. */
int http_transient(const struct http_response *r);

/* A one-line description of a failed call for messages: "message (code, field /x)" for server
 * errors, the transport error otherwise. Returns buf. */
const char *http_describe(const struct http_response *r, char *buf, size_t size);

#endif
