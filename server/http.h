/*
 * http.h - requests and replies as the API handlers see them. http.c is the only file that
 * includes microhttpd.h: it routes, authenticates, enforces body limits and per-token limits, and
 * turns a struct reply into a libmicrohttpd response. Connections reach it through the front door
 * (front_door.h), which checks each request head before libmicrohttpd parses it.
 *
 * A handler gets a struct request whose route, principal and path parameters are set and whose
 * body (for JSON routes) has been read completely within --max-body-bytes. It fills req->reply
 * through the reply_* functions; a handler that sets nothing answers 500. Streaming uploads
 * (PUT of files) use the three upload callbacks of their route instead of a body.
 */
#ifndef PORO_HTTP_H
#define PORO_HTTP_H

#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

#include "server.h"

#define HTTP_HEADERS_MAX 8
#define HTTP_STREAM_END ((ssize_t)-1)     /* a stream callback's "no more data" */
#define HTTP_STREAM_ERROR ((ssize_t)-2)   /* a stream callback's "abort the connection" */

/* Produces up to max bytes at pos into buf; returns the count, HTTP_STREAM_END or HTTP_STREAM_ERROR. */
typedef ssize_t (*stream_fn)(void *cls, uint64_t pos, char *buf, size_t max);

struct reply {
	int status;                       /* 0 until a reply is set */
	char *body;                       /* owned, malloc'ed */
	size_t size;
	const char *content_type;
	int fd;                           /* file reply: open descriptor (owned), or -1 */
	long long fd_offset, fd_size;
	stream_fn stream;                 /* streamed reply (chunked unless stream_length > 0) */
	long long stream_length;          /* > 0: the stream's exact length in bytes (Content-Length) */
	void *stream_cls;
	void (*stream_free)(void *cls);
	int header_count;
	char *headers[HTTP_HEADERS_MAX][2]; /* owned copies */
};

struct request {
	struct server *srv;
	void *connection;                 /* struct MHD_Connection, for http.c */
	const char *method, *url;
	const struct route *route;
	struct principal who;
	long long id;                     /* {id} of the path, or 0 */
	char *name;                       /* {name} of the path (raw, percent-encoded), or NULL */
	char *body;                       /* whole request body, NUL-terminated (JSON routes) */
	size_t body_size;
	long long content_length;         /* -1 when not given (chunked) */
	void *upload;                     /* an upload handler's state */
	struct reply reply;
};

/* 1 if the client has closed its connection (a long-poll whose worker went away must not take a
 * job), 0 while it is open. */
int http_client_gone(struct request *r);

/* A submission's costly part (building its tree, validating its case) runs between these, at most
 * --max-concurrent-submissions at once (request_gate.h): 0 when it may start, -1 after replying 503
 * when none ended within SUBMISSION_WAIT_SECONDS. Every 0 is followed by one leave. */
int http_submission_enter(struct request *r);
void http_submission_leave(struct request *r);

/* A request header, or NULL. */
const char *http_header(struct request *r, const char *name);
/* A query parameter, percent-decoded into out: 1 if present, 0 if absent, -1 if it does not
 * decode (bad escape, NUL byte) or does not fit. */
int http_query(struct request *r, const char *name, char *out, size_t size);
/* Percent-decodes src into out (at most size - 1 bytes); -1 on a bad escape, a NUL or overflow. */
int http_decode(const char *src, char *out, size_t size);

/* Replies: JSON (steals the reference), error record (its problems are released), text, a file
 * range, a stream. */
void reply_json(struct request *r, int status, json_t *body);
void reply_error(struct request *r, struct api_error *err);
/* Shorthand: records the error in a local record and replies with it; returns the code. */
enum api_code reply_fail(struct request *r, enum api_code code, const char *field, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
void reply_text(struct request *r, int status, const char *content_type, char *owned_text, size_t size);
void reply_fd(struct request *r, int status, int fd, long long offset, long long size);
void reply_stream(struct request *r, int status, const char *content_type, stream_fn fn, void *cls,
		  void (*free_cls)(void *cls));
/* A stream of exactly length bytes, sent with Content-Length: a stream that fails before its end
 * leaves the client a short body it can tell from a whole one. */
void reply_stream_sized(struct request *r, int status, const char *content_type, long long length, stream_fn fn,
			void *cls, void (*free_cls)(void *cls));
void reply_header(struct request *r, const char *name, const char *value);

/* What a route's request body may be (docs/service.md §3 "Limits"): each kind has its own largest
 * size and, for JSON, its own limits on nesting, values and token length, checked while the body
 * streams in (common/json_scan.h) so that no tree is built of a body that breaks them. */
enum body_kind {
	BODY_SMALL,      /* small JSON objects (claims, heartbeats, finishes, users, tokens) or none */
	BODY_LOG,        /* a log chunk: a few keys, one long string */
	BODY_CASE,       /* a submission: a case spec of many values */
	BODY_UPLOAD,     /* raw bytes streamed to the route's upload callbacks */
};

/* A route: method, path pattern ("/v1/jobs/{id}/files/{name}"; {name} as the last element takes
 * the rest of the path, slashes included, so hostile names reach the handler and are refused
 * there), the roles allowed, the body it takes, and either a handler or the upload callbacks.
 * Every GET route answers HEAD too. */
typedef void (*handler_fn)(struct request *r);
struct route {
	const char *method;
	const char *pattern;
	unsigned roles;                   /* ROLE_* mask; 0 = no token needed */
	enum body_kind body;
	handler_fn handle;
	/* Streaming body (PUT): begin may reply to refuse before any byte is read; data gets each
	 * piece (returns 0, or -1 after replying: the rest of the body is discarded); end replies;
	 * abort frees the state when the request ends in any way (always called if begin ran). */
	void (*upload_begin)(struct request *r);
	int (*upload_data)(struct request *r, const char *data, size_t size);
	void (*upload_end)(struct request *r);
	void (*upload_abort)(struct request *r);
};

/* Starts the HTTP engine (one thread per connection) and the front door that listens on
 * cfg->listen (port 0 picks one) and admits connections into it (front_door.h). The actual URL is
 * written into url. Returns an opaque server, or NULL with msg set. */
void *http_start(struct server *srv, char *url, size_t url_size, char *msg, size_t msg_size);
/* Stops accepting new connections (in-flight requests go on). */
void http_quiesce(void *http);
/* "https://HOST:PORT" of --tls-listen (port as bound), or "" without it. */
const char *http_tls_url(void *http);
/* Waits for every connection thread and stops; frees what http_start made. */
void http_stop(void *http);

#endif
