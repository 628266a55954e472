/*
 * http.c - the HTTP engine on libmicrohttpd (the only file that includes microhttpd.h): the route
 * table, authentication and roles, request-body limits, per-token limits, and replies (http.h).
 *
 * Threads: MHD_USE_THREAD_PER_CONNECTION, so a long-poll claim or a followed log blocks only its
 * own connection. libmicrohttpd has no listening socket of its own: the front door
 * (front_door.h) accepts connections, waits for and checks each first request head, and hands the
 * connection over with MHD_add_connection; libmicrohttpd's connection hooks keep the front door
 * told of each connection's state, so it can time out idle ones and slow bodies.
 *
 * A request goes through: route match (404, or 405 with Allow; HEAD is taken as GET), bearer token
 * (401 with WWW-Authenticate), role (403), the token's requests in progress (429), Content-Length
 * against the route's limit (413 before any byte of the body is read), then the body is
 * accumulated (JSON routes: the limit enforced again while streaming chunked bodies, and the JSON
 * checked while it streams, common/json_scan.h; a body that breaks either is discarded to its end
 * and answered 413 or 400) or streamed to the route's upload callbacks, and finally the handler
 * runs (a submission's parsing and validation take their turn, request_gate.h).
 *
 * The URL is not unescaped by libmicrohttpd (UNESCAPE_CALLBACK is the identity): path elements
 * and query values are decoded here and in handlers, one element at a time, so an encoded slash
 * or NUL can never change how a path splits.
 *
 * Out of memory: a request that cannot get memory for its body, its tree or its answer is answered
 * 503 unavailable (the answer to that is a static text), never a crash; the store's writes are
 * transactions, so a failed one leaves nothing half done.
 */
#include "api.h"
#include "bench.h"
#include "front_door.h"
#include "http.h"
#include "listen_socket.h"
#include "log.h"
#include "metrics.h"
#include "request_gate.h"
#include "store.h"
#include "tls_files.h"

#include "digest.h"
#include "json_scan.h"

#include <microhttpd.h>
#include <errno.h>
#include <netdb.h>
#include <malloc.h>
#include <stdarg.h>
#include <stdio.h>
#include <time.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#define USER_ROLES (ROLE_USER | ROLE_ADMIN)
#define DRAIN_FACTOR 4                    /* upload bytes discarded after a 413 before closing: x limit */
#define CONNECTION_TIMEOUT_SECONDS 60     /* libmicrohttpd's own limit on a silent connection */
#define CONNECTION_MEMORY 65536           /* libmicrohttpd's per-connection pool: holds a head of
					   * REQUEST_HEAD_MAX with room to spare */
#define THREAD_STACK_BYTES (2u << 20)     /* per connection thread; enough for the deepest handler */
#define STREAM_BLOCK 16384
#define TLS_LISTEN_BACKLOG 1024           /* the kernel's queue of the HTTPS listener */
#define TRIM_AFTER_BYTES (1 << 20)        /* a JSON body this large: return freed memory to the system */

/* The body limits of each kind of route (enum body_kind); --max-body-bytes caps the JSON ones. */
#define SMALL_BODY_MAX (64 * 1024)
#define LOG_BODY_MAX (2 * 1024 * 1024)    /* a worker's 256 KiB chunk, JSON-escaped at worst 6 times */
static const struct json_limits SMALL_JSON = { .max_depth = 16, .max_values = 4096, .max_token_bytes = 16384 };
static const struct json_limits LOG_JSON = { .max_depth = 4, .max_values = 16, .max_token_bytes = LOG_BODY_MAX };
#define CASE_DEPTH_MAX 32                 /* a case nests about 6 deep */
#define CASE_TOKEN_MAX 65536              /* names, titles, units: far below */

static const struct route ROUTES[] = {
	{ "POST", "/v1/jobs", USER_ROLES, BODY_CASE, jobs_submit, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs", USER_ROLES, BODY_SMALL, jobs_list, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs/{id}", USER_ROLES, BODY_SMALL, jobs_show, 0, 0, 0, 0 },
	{ "DELETE", "/v1/jobs/{id}", USER_ROLES, BODY_SMALL, jobs_delete, 0, 0, 0, 0 },
	{ "POST", "/v1/jobs/{id}/cancel", USER_ROLES, BODY_SMALL, jobs_cancel, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs/{id}/log", USER_ROLES, BODY_SMALL, logs_get, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs/{id}/files/{name}", USER_ROLES, BODY_SMALL, files_get, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs/{id}/probes", USER_ROLES, BODY_SMALL, jobs_probes, 0, 0, 0, 0 },
	{ "POST", "/v1/worker/claim", ROLE_WORKER, BODY_SMALL, worker_claim, 0, 0, 0, 0 },
	{ "POST", "/v1/worker/jobs/{id}/heartbeat", ROLE_WORKER, BODY_SMALL, worker_heartbeat, 0, 0, 0, 0 },
	{ "POST", "/v1/worker/jobs/{id}/log", ROLE_WORKER, BODY_LOG, worker_log, 0, 0, 0, 0 },
	{ "POST", "/v1/worker/jobs/{id}/finish", ROLE_WORKER, BODY_SMALL, worker_finish, 0, 0, 0, 0 },
	{ "PUT", "/v1/worker/jobs/{id}/files/{name}", ROLE_WORKER, BODY_UPLOAD, NULL, files_upload_begin,
	  files_upload_data, files_upload_end, files_upload_abort },
	{ "GET", "/v1/worker/jobs/{id}/files/{name}", ROLE_WORKER, BODY_SMALL, worker_file_get, 0, 0, 0, 0 },
	{ "GET", "/healthz", 0, BODY_SMALL, admin_healthz, 0, 0, 0, 0 },
	{ "GET", "/metrics", ROLE_WORKER | ROLE_ADMIN, BODY_SMALL, admin_metrics, 0, 0, 0, 0 },
	{ "POST", "/v1/users", ROLE_ADMIN, BODY_SMALL, admin_users_create, 0, 0, 0, 0 },
	{ "POST", "/v1/tokens", ROLE_ADMIN, BODY_SMALL, admin_tokens_create, 0, 0, 0, 0 },
	{ "GET", "/v1/tokens", USER_ROLES, BODY_SMALL, admin_tokens_list, 0, 0, 0, 0 },
	{ "DELETE", "/v1/tokens/{id}", USER_ROLES, BODY_SMALL, admin_tokens_revoke, 0, 0, 0, 0 },
	/* the dashboard (docs/web.md): its static files, and what its pages read */
	{ "GET", "/", 0, BODY_SMALL, web_index, 0, 0, 0, 0 },
	{ "GET", "/web/{name}", 0, BODY_SMALL, web_file, 0, 0, 0, 0 },
	{ "POST", "/v1/cases/validate", USER_ROLES, BODY_CASE, jobs_validate, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs/{id}/case", USER_ROLES, BODY_SMALL, web_job_case, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs/{id}/frames", USER_ROLES, BODY_SMALL, frames_index, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs/{id}/frames/{frame}", USER_ROLES, BODY_SMALL, frames_get, 0, 0, 0, 0 },
	{ "GET", "/v1/admin/workers", ROLE_ADMIN, BODY_SMALL, web_admin_workers, 0, 0, 0, 0 },
	/* benchmark runs (bench.h): a plan names up to 500 cases, so it may be larger than a small body */
	{ "POST", "/v1/benchmarks", USER_ROLES, BODY_CASE, bench_create, 0, 0, 0, 0 },
	{ "GET", "/v1/benchmarks", USER_ROLES, BODY_SMALL, bench_list, 0, 0, 0, 0 },
	{ "GET", "/v1/benchmarks/series", USER_ROLES, BODY_SMALL, bench_series, 0, 0, 0, 0 },
	{ "GET", "/v1/benchmarks/{id}", USER_ROLES, BODY_SMALL, bench_show, 0, 0, 0, 0 },
	{ "POST", "/v1/benchmarks/{id}/finish", USER_ROLES, BODY_SMALL, bench_finish, 0, 0, 0, 0 },
};
#define ROUTE_COUNT (sizeof ROUTES / sizeof ROUTES[0])

/* What http_start makes: the engine, its front door and the per-token limits. */
struct http {
	struct server *srv;
	struct MHD_Daemon *daemon;
	struct front_door *door;
	struct request_gate *gate;
	struct MHD_Daemon *tls_daemon;  /* --tls-listen, or NULL */
	char *tls_cert, *tls_key;       /* PEM texts, kept while tls_daemon runs */
	char tls_url[300];              /* "https://HOST:PORT", "" without --tls-listen */
};

/* Per-request state beyond struct request. */
struct exchange {
	struct request req;
	struct http *http;
	struct door_conn *door;       /* the front door's record of the connection, or NULL */
	int queued;                   /* a response was queued */
	int refused;                  /* replied before the body: discard what comes */
	int too_large;
	int out_of_memory;            /* the body could not be kept: discard the rest, answer 503 */
	int upload_failed;            /* upload_data replied: discard the rest */
	int upload_started;
	int token_counted;            /* the gate counts this request against token_hash */
	int submission;               /* holds a submission's turn (http_submission_enter) */
	char token_hash[DIGEST_HEX_SIZE];
	struct json_scan scan;        /* of a JSON body as it streams in */
	int scan_failed;              /* the scan refused the body: discard the rest */
	long long received;
	size_t capacity;
	struct timespec started;      /* arrival, for the request's log line */
	int status;                   /* the status queued, once queued */
};

static const char *ended_name(enum MHD_RequestTerminationCode toe)
{
	switch (toe) {
	case MHD_REQUEST_TERMINATED_COMPLETED_OK: return NULL;
	case MHD_REQUEST_TERMINATED_WITH_ERROR: return "error";
	case MHD_REQUEST_TERMINATED_TIMEOUT_REACHED: return "timeout";
	case MHD_REQUEST_TERMINATED_DAEMON_SHUTDOWN: return "shutdown";
	case MHD_REQUEST_TERMINATED_READ_ERROR: return "read_error";
	case MHD_REQUEST_TERMINATED_CLIENT_ABORT: return "client_abort";
	default: return "other";
	}
}

/* The request's line in the server's log (log.h), when the request ends: its method, route
 * pattern ("-" when no route matched: a raw path or query string may hold anything, a token
 * included, so neither is ever logged), the status answered (none when the request ended before
 * an answer), milliseconds from its arrival to its end (a streamed answer's too), the
 * authenticated user ("-" without one), the client's address and, when it did not end normally,
 * how it ended. 5xx answers are warnings. --access-log gets the same line; the route-coverage
 * check reads it there. */
static void log_request(const struct exchange *x, enum MHD_RequestTerminationCode toe)
{
	const struct request *r = &x->req;
	struct timespec now;
	clock_gettime(CLOCK_MONOTONIC, &now);
	double ms = (double)(now.tv_sec - x->started.tv_sec) * 1e3 + (double)(now.tv_nsec - x->started.tv_nsec) * 1e-6;
	char client[INET6_ADDRSTRLEN] = "-";
	const union MHD_ConnectionInfo *info =
		MHD_get_connection_info(r->connection, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
	if (info && info->client_addr)
		getnameinfo(info->client_addr,
			    info->client_addr->sa_family == AF_INET6 ? sizeof(struct sockaddr_in6) : sizeof(struct sockaddr_in),
			    client, sizeof client, NULL, 0, NI_NUMERICHOST);
	struct log_line l;
	log_line_begin_request(&l, x->status >= 500 ? LOG_PRIO_WARNING : LOG_PRIO_INFO);
	log_line_str(&l, "method", r->method);
	log_line_str(&l, "route", r->route ? r->route->pattern : "-");
	if (x->queued)
		log_line_int(&l, "status", x->status);
	log_line_ms(&l, "duration_ms", ms);
	log_line_str(&l, "user", r->who.role ? r->who.name : "-");
	log_line_str(&l, "client", client);
	log_line_str(&l, "ended", ended_name(toe));
	log_line_end(&l);
}

/* ---- helpers for handlers ---- */

const char *http_header(struct request *r, const char *name)
{
	return MHD_lookup_connection_value(r->connection, MHD_HEADER_KIND, name);
}

static int hex_value(char c)
{
	if (c >= '0' && c <= '9')
		return c - '0';
	if (c >= 'a' && c <= 'f')
		return c - 'a' + 10;
	if (c >= 'A' && c <= 'F')
		return c - 'A' + 10;
	return -1;
}

int http_decode(const char *src, char *out, size_t size)
{
	size_t n = 0;
	for (const char *p = src; *p; p++) {
		int ch = (unsigned char)*p;
		if (ch == '%') {
			int hi = hex_value(p[1]), lo = hi < 0 ? -1 : hex_value(p[2]);
			if (lo < 0)
				return -1;
			ch = 16 * hi + lo;
			p += 2;
			if (ch == 0)
				return -1;
		}
		if (n + 1 >= size)
			return -1;
		out[n++] = (char)ch;
	}
	out[n] = '\0';
	return 0;
}

int http_query(struct request *r, const char *name, char *out, size_t size)
{
	const char *raw = MHD_lookup_connection_value(r->connection, MHD_GET_ARGUMENT_KIND, name);
	if (!raw)
		return 0;
	return http_decode(raw, out, size) == 0 ? 1 : -1;
}

static void reply_reset(struct reply *rep)
{
	free(rep->body);
	rep->body = NULL;
	if (rep->fd >= 0)
		close(rep->fd);
	rep->fd = -1;
	if (rep->stream && rep->stream_free)
		rep->stream_free(rep->stream_cls);
	rep->stream = NULL;
	rep->stream_length = 0;
	for (int i = 0; i < rep->header_count; i++) {
		free(rep->headers[i][0]);
		free(rep->headers[i][1]);
	}
	rep->header_count = 0;
	rep->status = 0;
}

void reply_header(struct request *r, const char *name, const char *value)
{
	struct reply *rep = &r->reply;
	if (rep->header_count == HTTP_HEADERS_MAX)
		return;
	rep->headers[rep->header_count][0] = strdup(name);
	rep->headers[rep->header_count][1] = strdup(value);
	rep->header_count++;
}

static int reply_has_header(struct request *r, const char *name)
{
	for (int i = 0; i < r->reply.header_count; i++)
		if (strcasecmp(r->reply.headers[i][0], name) == 0)
			return 1;
	return 0;
}

void reply_text(struct request *r, int status, const char *content_type, char *owned_text, size_t size)
{
	free(r->reply.body);
	r->reply.status = status;
	r->reply.body = owned_text;
	r->reply.size = size;
	r->reply.content_type = content_type;
}

void reply_json(struct request *r, int status, json_t *body)
{
	char *text = body ? json_dumps(body, JSON_COMPACT) : NULL;
	json_decref(body);
	if (!text) { /* only allocation fails here: the answer itself, or the tree it was made of */
		static const char out_of_memory[] = "{\"error\":{\"code\":\"unavailable\",\"message\":"
						    "\"the server is out of memory: retry later\",\"field\":null}}\n";
		char *copy = strdup(out_of_memory);
		reply_text(r, 503, "application/json", copy, copy ? strlen(copy) : 0);
		return;
	}
	size_t n = strlen(text);
	text[n] = '\n'; /* json_dumps leaves room only for the NUL: replace it, the reply has a length */
	reply_text(r, status, "application/json", text, n + 1);
}

void reply_error(struct request *r, struct api_error *err)
{
	json_t *e = json_pack("{s:s, s:s, s:o}", "code", api_code_name(err->code), "message", err->message, "field",
			      err->field[0] ? json_string(err->field) : json_null());
	if (err->problems)
		json_object_set(e, "problems", err->problems);
	api_error_release(err);
	if (err->code == API_LOG_GAP)
		json_object_set_new(e, "expected_offset", json_integer(err->expected_offset));
	reply_header(r, "Cache-Control", "no-store");
	/* the server's passing states (no memory, a failing or full disk) say when to try again */
	int status = api_code_status(err->code);
	if ((status == 503 || status == 507) && !reply_has_header(r, "Retry-After"))
		reply_header(r, "Retry-After", status == 507 ? "10" : "1");
	reply_json(r, status, json_pack("{s:o}", "error", e));
}

enum api_code reply_fail(struct request *r, enum api_code code, const char *field, const char *fmt, ...)
{
	struct api_error err = { 0 };
	err.code = code;
	snprintf(err.field, sizeof err.field, "%s", field);
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err.message, sizeof err.message, fmt, ap);
	va_end(ap);
	reply_error(r, &err);
	return code;
}

void reply_fd(struct request *r, int status, int fd, long long offset, long long size)
{
	r->reply.status = status;
	r->reply.fd = fd;
	r->reply.fd_offset = offset;
	r->reply.fd_size = size;
}

void reply_stream(struct request *r, int status, const char *content_type, stream_fn fn, void *cls,
		  void (*free_cls)(void *cls))
{
	r->reply.status = status;
	r->reply.content_type = content_type;
	r->reply.stream = fn;
	r->reply.stream_cls = cls;
	r->reply.stream_free = free_cls;
}

void reply_stream_sized(struct request *r, int status, const char *content_type, long long length, stream_fn fn,
			void *cls, void (*free_cls)(void *cls))
{
	reply_stream(r, status, content_type, fn, cls, free_cls);
	r->reply.stream_length = length;
}

/* ---- responses ---- */

static ssize_t stream_adapter(void *cls, uint64_t pos, char *buf, size_t max)
{
	struct reply *rep = cls;
	ssize_t n = rep->stream(rep->stream_cls, pos, buf, max);
	if (n == HTTP_STREAM_END)
		return MHD_CONTENT_READER_END_OF_STREAM;
	if (n < 0)
		return MHD_CONTENT_READER_END_WITH_ERROR;
	return n;
}

static void stream_release(void *cls)
{
	struct reply *rep = cls;
	if (rep->stream_free)
		rep->stream_free(rep->stream_cls);
	free(rep);
}

static enum MHD_Result queue_reply(struct exchange *x)
{
	struct request *r = &x->req;
	struct reply *rep = &r->reply;
	if (!rep->status)
		reply_fail(r, API_INTERNAL, "", "handler set no reply");
	struct MHD_Response *resp;
	if (rep->stream) {
		struct reply *moved = malloc(sizeof *moved);
		if (!moved) {
			front_door_answer_unavailable(x->http->door, x->door);
			return MHD_NO;
		}
		*moved = *rep;
		rep->stream = NULL; /* now owned by the response */
		uint64_t length = rep->stream_length > 0 ? (uint64_t)rep->stream_length : MHD_SIZE_UNKNOWN;
		resp = MHD_create_response_from_callback(length, STREAM_BLOCK, stream_adapter, moved, stream_release);
		if (!resp)
			stream_release(moved);
	} else if (rep->fd >= 0) {
		resp = MHD_create_response_from_fd_at_offset64((uint64_t)rep->fd_size, rep->fd,
							       (uint64_t)rep->fd_offset);
		if (resp)
			rep->fd = -1; /* closed by libmicrohttpd */
	} else {
		resp = MHD_create_response_from_buffer(rep->size, rep->body ? rep->body : (void *)"",
						       rep->body ? MHD_RESPMEM_MUST_FREE : MHD_RESPMEM_PERSISTENT);
		if (resp)
			rep->body = NULL;
	}
	if (!resp) {
		front_door_answer_unavailable(x->http->door, x->door);
		return MHD_NO;
	}
	if (rep->content_type)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, rep->content_type);
	for (int i = 0; i < rep->header_count; i++)
		MHD_add_response_header(resp, rep->headers[i][0], rep->headers[i][1]);
	enum MHD_Result ok = MHD_queue_response(r->connection, (unsigned)rep->status, resp);
	MHD_destroy_response(resp);
	metrics_count_request(r->srv->metrics, rep->status);
	x->status = rep->status;
	x->queued = 1;
	return ok;
}

int http_client_gone(struct request *r)
{
	const union MHD_ConnectionInfo *info =
		MHD_get_connection_info(r->connection, MHD_CONNECTION_INFO_CONNECTION_FD);
	if (!info)
		return 0;
	char byte;
	/* an orderly shutdown reads as 0 bytes; an open idle connection as EAGAIN */
	ssize_t n = recv(info->connect_fd, &byte, 1, MSG_PEEK | MSG_DONTWAIT);
	return n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR);
}

/* ---- routing ---- */

static int match(const char *pattern, const char *path, long long *id, char **name)
{
	const char *p = pattern, *u = path;
	while (*p) {
		if (*p != '{') {
			if (*p++ != *u++)
				return 0;
			continue;
		}
		size_t seg = strcspn(u, "/");
		if (strncmp(p, "{id}", 4) == 0) {
			if (seg == 0 || seg > 18 || u[0] == '0')
				return 0;
			long long v = 0;
			for (size_t i = 0; i < seg; i++) {
				if (u[i] < '0' || u[i] > '9')
					return 0;
				v = 10 * v + (u[i] - '0');
			}
			*id = v;
			u += seg;
			p += 4;
		} else if (strncmp(p, "{frame}", 7) == 0) { /* a frame's number: 0 or more, one element */
			if (seg == 0 || seg > 9 || (u[0] == '0' && seg > 1) || strspn(u, "0123456789") < seg)
				return 0;
			*name = strndup(u, seg);
			if (!*name)
				return 0;
			u += seg;
			p += 7;
		} else { /* {name}: the rest of the path */
			*name = strdup(u);
			return *name != NULL;
		}
	}
	if (*u == '\0')
		return 1;
	free(*name); /* a {frame} matched, and the path goes on */
	*name = NULL;
	return 0;
}

/* Finds the route; 0, or an error code after replying (404, 405). */
static int route_request(struct request *r)
{
	char allow[64] = "";
	for (size_t i = 0; i < ROUTE_COUNT; i++) {
		long long id = 0;
		char *name = NULL;
		if (!match(ROUTES[i].pattern, r->url, &id, &name))
			continue;
		const char *method = strcmp(r->method, "HEAD") == 0 ? "GET" : r->method;
		if (strcmp(ROUTES[i].method, method) == 0) {
			r->route = &ROUTES[i];
			r->id = id;
			r->name = name;
			return 0;
		}
		free(name);
		if (!strstr(allow, ROUTES[i].method)) {
			size_t n = strlen(allow);
			int get = strcmp(ROUTES[i].method, "GET") == 0;
			snprintf(allow + n, sizeof allow - n, "%s%s%s", n ? ", " : "", ROUTES[i].method, get ? ", HEAD" : "");
		}
	}
	if (allow[0]) {
		reply_header(r, "Allow", allow);
		return reply_fail(r, API_METHOD_NOT_ALLOWED, "", "method %s is not allowed on '%s' (allowed: %s)",
				  r->method, r->url, allow);
	}
	return reply_fail(r, API_NOT_FOUND, "", "no route '%s'", r->url);
}

static int authenticate(struct exchange *x)
{
	struct request *r = &x->req;
	if (!r->route->roles)
		return 0;
	const char *h = http_header(r, MHD_HTTP_HEADER_AUTHORIZATION);
	size_t skip = 7; /* "Bearer " */
	if (!h || strncasecmp(h, "Bearer ", skip) != 0 || !h[skip]) {
		reply_header(r, "WWW-Authenticate", "Bearer realm=\"poro\"");
		return reply_fail(r, API_UNAUTHORIZED, "Authorization", "missing bearer token");
	}
	char hash[DIGEST_HEX_SIZE];
	digest_hex(h + skip, strlen(h + skip), hash);
	struct api_error err = { 0 };
	enum api_code rc = store_auth(r->srv->store, hash, &r->who, &err);
	if (rc == API_UNAUTHORIZED) {
		reply_header(r, "WWW-Authenticate", "Bearer realm=\"poro\", error=\"invalid_token\"");
		return reply_fail(r, API_UNAUTHORIZED, "Authorization", "invalid bearer token");
	}
	if (rc != API_OK) {
		reply_error(r, &err);
		return rc;
	}
	if (!(r->route->roles & r->who.role))
		return reply_fail(r, API_FORBIDDEN, "Authorization", "role '%s' may not use %s %s",
				  role_name(r->who.role), r->method, r->route->pattern);
	int limit;
	if (request_gate_enter(x->http->gate, hash, r->who.role, &limit) != 0) {
		reply_header(r, "Retry-After", "1");
		return reply_fail(r, API_TOO_MANY_REQUESTS, "Authorization",
				  "the token of '%s' already has %d requests in progress, its limit", r->who.name, limit);
	}
	memcpy(x->token_hash, hash, sizeof hash);
	x->token_counted = 1;
	return 0;
}

static long long body_limit(struct request *r)
{
	long long json_max = r->srv->cfg.max_body_bytes;
	switch (r->route->body) {
	case BODY_UPLOAD:
		return r->srv->cfg.max_upload_bytes;
	case BODY_CASE:
		return json_max;
	case BODY_LOG:
		return json_max < LOG_BODY_MAX ? json_max : LOG_BODY_MAX;
	default:
		return json_max < SMALL_BODY_MAX ? json_max : SMALL_BODY_MAX;
	}
}

static struct json_limits body_json_limits(struct request *r)
{
	if (r->route->body == BODY_CASE)
		return (struct json_limits){ .max_depth = CASE_DEPTH_MAX, .max_values = r->srv->cfg.max_body_values,
					     .max_token_bytes = CASE_TOKEN_MAX };
	return r->route->body == BODY_LOG ? LOG_JSON : SMALL_JSON;
}

static int check_length(struct request *r)
{
	const char *cl = http_header(r, MHD_HTTP_HEADER_CONTENT_LENGTH);
	r->content_length = cl ? strtoll(cl, NULL, 10) : -1;
	if (r->content_length > body_limit(r))
		return reply_fail(r, API_TOO_LARGE, "", "request body of %lld bytes exceeds the limit of %lld bytes",
				  r->content_length, body_limit(r));
	return 0;
}

/* First call for a request: everything decided from the headers alone. */
static enum MHD_Result begin(struct exchange *x)
{
	struct request *r = &x->req;
	int refused = route_request(r) || authenticate(x) || check_length(r);
	/* the body (even of a refused request, which is read and discarded) must arrive in time */
	int uploads = r->route && r->route->body == BODY_UPLOAD;
	front_door_request_started(x->http->door, x->door, uploads ? 0 : r->srv->cfg.body_timeout_seconds);
	if (refused) {
		x->refused = 1;
		return queue_reply(x);
	}
	if (r->route->body != BODY_UPLOAD) {
		struct json_limits limits = body_json_limits(r);
		json_scan_init(&x->scan, &limits);
	}
	if (r->route->upload_begin) {
		x->upload_started = 1;
		r->route->upload_begin(r);
		if (r->reply.status) {
			x->refused = 1;
			return queue_reply(x);
		}
	}
	return MHD_YES;
}

/* A piece of the body: kept (JSON, after the scan), streamed (uploads) or discarded. A discarded
 * JSON body is read to its end, however long, so that the client gets its answer: the front door
 * cuts it at the body deadline. A discarded upload is read only up to DRAIN_FACTOR times its limit
 * (the connection is then closed): it holds a worker token and could go on at full speed. */
static int take_data(struct exchange *x, const char *data, size_t size)
{
	struct request *r = &x->req;
	int upload = r->route && r->route->body == BODY_UPLOAD;
	x->received += (long long)size;
	if (x->refused || x->too_large || x->upload_failed || x->scan_failed || x->out_of_memory)
		return upload && x->received > DRAIN_FACTOR * body_limit(r) + (1 << 20) ? -1 : 0;
	if (x->received > body_limit(r)) {
		x->too_large = 1;
		return 0;
	}
	if (upload) {
		if (r->route->upload_data(r, data, size) != 0)
			x->upload_failed = 1;
		return 0;
	}
	if (json_scan_feed(&x->scan, data, size) != 0) {
		x->scan_failed = 1;
		free(r->body);
		r->body = NULL;
		r->body_size = 0;
		return 0;
	}
	if (r->body_size + size + 1 > x->capacity) {
		size_t want = r->body_size + size + 1;
		x->capacity = want > 2 * x->capacity ? want : 2 * x->capacity;
		char *grown = realloc(r->body, x->capacity);
		if (!grown) {
			x->out_of_memory = 1;
			return 0;
		}
		r->body = grown;
	}
	memcpy(r->body + r->body_size, data, size);
	r->body_size += size;
	r->body[r->body_size] = '\0';
	return 0;
}

int http_submission_enter(struct request *r)
{
	struct exchange *x = (struct exchange *)r; /* req is the exchange's first member */
	int running;
	if (request_gate_submission_enter(x->http->gate, &running) != 0) {
		reply_header(r, "Retry-After", "1");
		reply_fail(r, API_UNAVAILABLE, "", "the server is checking %d submissions, its limit, and none "
			   "ended within %d s: retry later", running, SUBMISSION_WAIT_SECONDS);
		return -1;
	}
	x->submission = 1;
	return 0;
}

void http_submission_leave(struct request *r)
{
	struct exchange *x = (struct exchange *)r;
	if (x->submission)
		request_gate_submission_leave(x->http->gate);
	x->submission = 0;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *connection, const char *url, const char *method,
				  const char *version, const char *upload_data, size_t *upload_data_size,
				  void **con_cls)
{
	struct exchange *x = *con_cls;
	if (!x) {
		x = calloc(1, sizeof *x);
		if (!x) {
			const union MHD_ConnectionInfo *info =
				MHD_get_connection_info(connection, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
			front_door_answer_unavailable(((struct http *)cls)->door, info ? info->socket_context : NULL);
			return MHD_NO;
		}
		*con_cls = x;
		clock_gettime(CLOCK_MONOTONIC, &x->started);
		x->http = cls;
		const union MHD_ConnectionInfo *info =
			MHD_get_connection_info(connection, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
		x->door = info ? info->socket_context : NULL;
		x->req.srv = x->http->srv;
		x->req.connection = connection;
		x->req.url = url;
		x->req.method = method;
		x->req.reply.fd = -1;
		return begin(x);
	}
	if (*upload_data_size) {
		int rc = take_data(x, upload_data, *upload_data_size);
		*upload_data_size = 0;
		return rc == 0 ? MHD_YES : MHD_NO;
	}
	if (x->queued)
		return MHD_YES;
	front_door_request_handling(x->http->door, x->door);
	struct request *r = &x->req;
	if (x->too_large) {
		reply_reset(&r->reply);
		reply_fail(r, API_TOO_LARGE, "", "request body exceeds the limit of %lld bytes", body_limit(r));
	} else if (x->scan_failed) {
		int syntax = x->scan.verdict == JSON_SCAN_SYNTAX;
		reply_fail(r, syntax ? API_INVALID_JSON : API_BODY_TOO_COMPLEX, "", "request body %s: %s",
			   syntax ? "is not valid JSON" : "is beyond this route's limits", x->scan.error);
	} else if (x->out_of_memory) {
		reply_header(r, "Retry-After", "1");
		reply_fail(r, API_UNAVAILABLE, "", "no memory for a request body of %lld bytes: retry later", x->received);
	} else if (!x->upload_failed) {
		if (r->route->upload_end)
			r->route->upload_end(r);
		else
			r->route->handle(r);
	}
	return queue_reply(x);
}

static void on_completed(void *cls, struct MHD_Connection *connection, void **con_cls,
			 enum MHD_RequestTerminationCode toe)
{
	struct exchange *x = *con_cls;
	if (!x)
		return;
	log_request(x, toe);
	if (x->upload_started && x->req.route->upload_abort)
		x->req.route->upload_abort(&x->req);
	if (x->token_counted)
		request_gate_leave(x->http->gate, x->token_hash);
	front_door_request_ended(x->http->door, x->door);
	reply_reset(&x->req.reply);
	free(x->req.body);
	free(x->req.name);
	int large = x->req.route && x->req.route->body != BODY_UPLOAD && x->received >= TRIM_AFTER_BYTES;
	free(x);
	*con_cls = NULL;
	/* the tree of a large body is freed in thousands of small pieces that glibc keeps for reuse:
	 * give them back, or the server's memory stays at its peak (and new threads may find no
	 * address space for their stacks) */
	if (large)
		malloc_trim(0);
}

/* The identity: decoding is done per path element (see the top of this file). */
static size_t no_unescape(void *cls, struct MHD_Connection *c, char *s)
{
	return strlen(s);
}

/* ---- engine ---- */

/* libmicrohttpd took (or let go of) a connection the front door handed over. */
static void on_connection(void *cls, struct MHD_Connection *connection, void **socket_context,
			  enum MHD_ConnectionNotificationCode code)
{
	struct http *h = cls;
	if (code == MHD_CONNECTION_NOTIFY_STARTED) {
		const union MHD_ConnectionInfo *info =
			MHD_get_connection_info(connection, MHD_CONNECTION_INFO_CONNECTION_FD);
		*socket_context = info ? front_door_connection_started(h->door, info->connect_fd) : NULL;
	} else {
		front_door_connection_closed(h->door, *socket_context);
		*socket_context = NULL;
	}
}

/* libmicrohttpd's own error messages (MHD_USE_ERROR_LOG) go to the server's log as warnings. */
static void engine_log(void *cls, const char *fmt, va_list ap)
{
	char text[LOG_LINE_MAX];
	vsnprintf(text, sizeof text, fmt, ap);
	text[strcspn(text, "\n")] = '\0';
	log_say(LOG_PRIO_WARNING, "libmicrohttpd: %s", text);
}

/* The front door's hand-over: libmicrohttpd closes the socket itself when it refuses it. */
static int admit(void *cls, int fd, const struct sockaddr *addr, socklen_t addr_len)
{
	struct http *h = cls;
	return MHD_add_connection(h->daemon, fd, addr, addr_len) == MHD_YES ? 0 : -1;
}

/* The HTTPS listener of --tls-listen (docs/operations.md, "TLS"): libmicrohttpd with GnuTLS, on a
 * socket of its own. The front door cannot read an encrypted head, so these connections skip it:
 * libmicrohttpd's own limits stand in (connections in all, per client address, a silent
 * connection's timeout), and the per-token limits and body checks of this file apply as on the
 * plain listener. 0 (nothing to do without --tls-listen), or -1 with msg set. */
static int start_tls(struct http *h, char *msg, size_t msg_size)
{
	const struct server_config *cfg = &h->srv->cfg;
	if (tls_files_load(cfg, &h->tls_cert, &h->tls_key, msg, msg_size) != 0)
		return -1;
	if (!h->tls_cert)
		return 0;
	int fd = listen_socket_open(cfg->tls_listen, "--tls-listen", "https", 0, TLS_LISTEN_BACKLOG, h->tls_url,
				    sizeof h->tls_url, msg, msg_size);
	if (fd < 0)
		return -1;
	unsigned flags = MHD_USE_THREAD_PER_CONNECTION | MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_POLL |
			 MHD_USE_ITC | MHD_USE_ERROR_LOG | MHD_USE_TLS;
	h->tls_daemon = MHD_start_daemon(
		flags, 0, NULL, NULL, on_request, h, MHD_OPTION_EXTERNAL_LOGGER, engine_log, NULL,
		MHD_OPTION_LISTEN_SOCKET, fd, MHD_OPTION_HTTPS_MEM_CERT, h->tls_cert, MHD_OPTION_HTTPS_MEM_KEY,
		h->tls_key, MHD_OPTION_CONNECTION_LIMIT, (unsigned)(cfg->max_connections + cfg->max_worker_connections),
		MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)cfg->max_connections_per_client,
		MHD_OPTION_NOTIFY_COMPLETED, on_completed, h, MHD_OPTION_UNESCAPE_CALLBACK, no_unescape, NULL,
		MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)CONNECTION_TIMEOUT_SECONDS, MHD_OPTION_CONNECTION_MEMORY_LIMIT,
		(size_t)CONNECTION_MEMORY, MHD_OPTION_THREAD_STACK_SIZE, (size_t)THREAD_STACK_BYTES, MHD_OPTION_END);
	if (!h->tls_daemon) {
		close(fd);
		snprintf(msg, msg_size, "cannot serve TLS on --tls-listen '%s' with --tls-cert '%s' and --tls-key '%s' "
			 "(the log says why)", cfg->tls_listen, cfg->tls_cert, cfg->tls_key);
		return -1;
	}
	return 0;
}

const char *http_tls_url(void *http)
{
	return ((struct http *)http)->tls_url;
}

void *http_start(struct server *srv, char *url, size_t url_size, char *msg, size_t msg_size)
{
	struct http *h = calloc(1, sizeof *h);
	if (!h) {
		snprintf(msg, msg_size, "out of memory");
		return NULL;
	}
	h->srv = srv;
	int connections = srv->cfg.max_connections + srv->cfg.max_worker_connections;
	h->gate = request_gate_create(srv->cfg.max_requests_per_token, srv->cfg.max_requests_per_worker_token,
				      srv->cfg.max_concurrent_submissions, connections);
	if (!h->gate) {
		snprintf(msg, msg_size, "out of memory");
		http_stop(h);
		return NULL;
	}
	/* no listening socket: connections come from the front door. The engine's own connection
	 * limit sits above the front door's budgets, so it never refuses one the front door admitted.
	 * The logger comes first: libmicrohttpd reports problems with the options after it through it. */
	unsigned flags = MHD_USE_THREAD_PER_CONNECTION | MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_POLL |
			 MHD_USE_ITC | MHD_USE_ERROR_LOG | MHD_USE_NO_LISTEN_SOCKET;
	h->daemon = MHD_start_daemon(
		flags, 0, NULL, NULL, on_request, h, MHD_OPTION_EXTERNAL_LOGGER, engine_log, NULL,
		MHD_OPTION_CONNECTION_LIMIT, (unsigned)(connections + 64), MHD_OPTION_NOTIFY_COMPLETED, on_completed, h,
		MHD_OPTION_NOTIFY_CONNECTION, on_connection, h, MHD_OPTION_UNESCAPE_CALLBACK, no_unescape, NULL,
		MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)CONNECTION_TIMEOUT_SECONDS, MHD_OPTION_CONNECTION_MEMORY_LIMIT,
		(size_t)CONNECTION_MEMORY, MHD_OPTION_THREAD_STACK_SIZE, (size_t)THREAD_STACK_BYTES, MHD_OPTION_END);
	if (!h->daemon) {
		snprintf(msg, msg_size, "cannot start the HTTP engine");
		http_stop(h);
		return NULL;
	}
	h->door = front_door_start(srv, admit, h, url, url_size, msg, msg_size);
	if (!h->door || start_tls(h, msg, msg_size) != 0) {
		http_stop(h);
		return NULL;
	}
	return h;
}

void http_quiesce(void *http)
{
	struct http *h = http;
	front_door_quiesce(h->door);
	if (h->tls_daemon) {
		MHD_socket fd = MHD_quiesce_daemon(h->tls_daemon);
		if (fd != MHD_INVALID_SOCKET)
			close(fd);
	}
}

void http_stop(void *http)
{
	struct http *h = http;
	if (!h)
		return;
	front_door_quiesce(h->door);
	if (h->tls_daemon)
		MHD_stop_daemon(h->tls_daemon);
	if (h->daemon)
		MHD_stop_daemon(h->daemon);
	free(h->tls_cert);
	free(h->tls_key);
	front_door_destroy(&h->door);
	request_gate_destroy(&h->gate);
	free(h);
}
