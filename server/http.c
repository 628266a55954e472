/*
 * http.c - the HTTP front end on libmicrohttpd (the only file that includes microhttpd.h): the
 * route table, authentication and roles, request-body limits, and replies (http.h).
 *
 * Threads: MHD_USE_THREAD_PER_CONNECTION, so a long-poll claim or a followed log blocks only its
 * own connection. A request goes through: route match (404, or 405 with Allow), bearer token
 * (401 with WWW-Authenticate), role (403), Content-Length against the limit (413 before any byte
 * of the body is read), then the body is accumulated (JSON routes, limit enforced again while
 * streaming chunked bodies: the rest is discarded and 413 answered) or streamed to the route's
 * upload callbacks, and finally the handler runs.
 *
 * The URL is not unescaped by libmicrohttpd (UNESCAPE_CALLBACK is the identity): path elements
 * and query values are decoded here and in handlers, one element at a time, so an encoded slash
 * or NUL can never change how a path splits.
 */
#include "api.h"
#include "http.h"
#include "metrics.h"
#include "store.h"

#include "digest.h"

#include <arpa/inet.h>
#include <microhttpd.h>
#include <netdb.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <time.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#define USER_ROLES (ROLE_USER | ROLE_ADMIN)
#define DRAIN_FACTOR 4                    /* bytes discarded after a 413 before closing: x limit */
#define CONNECTION_TIMEOUT_SECONDS 120    /* idle keep-alive connections */
#define STREAM_BLOCK 16384

static const struct route ROUTES[] = {
	{ "POST", "/v1/jobs", USER_ROLES, jobs_submit, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs", USER_ROLES, jobs_list, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs/{id}", USER_ROLES, jobs_show, 0, 0, 0, 0 },
	{ "POST", "/v1/jobs/{id}/cancel", USER_ROLES, jobs_cancel, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs/{id}/log", USER_ROLES, logs_get, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs/{id}/files/{name}", USER_ROLES, files_get, 0, 0, 0, 0 },
	{ "GET", "/v1/jobs/{id}/probes", USER_ROLES, jobs_probes, 0, 0, 0, 0 },
	{ "POST", "/v1/worker/claim", ROLE_WORKER, worker_claim, 0, 0, 0, 0 },
	{ "POST", "/v1/worker/jobs/{id}/heartbeat", ROLE_WORKER, worker_heartbeat, 0, 0, 0, 0 },
	{ "POST", "/v1/worker/jobs/{id}/log", ROLE_WORKER, worker_log, 0, 0, 0, 0 },
	{ "POST", "/v1/worker/jobs/{id}/finish", ROLE_WORKER, worker_finish, 0, 0, 0, 0 },
	{ "PUT", "/v1/worker/jobs/{id}/files/{name}", ROLE_WORKER, NULL, files_upload_begin, files_upload_data,
	  files_upload_end, files_upload_abort },
	{ "GET", "/v1/worker/jobs/{id}/files/{name}", ROLE_WORKER, worker_file_get, 0, 0, 0, 0 },
	{ "GET", "/healthz", 0, admin_healthz, 0, 0, 0, 0 },
	{ "GET", "/metrics", ROLE_WORKER | ROLE_ADMIN, admin_metrics, 0, 0, 0, 0 },
	{ "POST", "/v1/users", ROLE_ADMIN, admin_users_create, 0, 0, 0, 0 },
	{ "POST", "/v1/tokens", ROLE_ADMIN, admin_tokens_create, 0, 0, 0, 0 },
	{ "GET", "/v1/tokens", USER_ROLES, admin_tokens_list, 0, 0, 0, 0 },
	{ "DELETE", "/v1/tokens/{id}", USER_ROLES, admin_tokens_revoke, 0, 0, 0, 0 },
};
#define ROUTE_COUNT (sizeof ROUTES / sizeof ROUTES[0])

/* Per-request state beyond struct request. */
struct exchange {
	struct request req;
	int queued;                   /* a response was queued */
	int refused;                  /* replied before the body: discard what comes */
	int too_large;
	int upload_failed;            /* upload_data replied: discard the rest */
	int upload_started;
	long long received;
	size_t capacity;
	struct timespec started;      /* arrival, for the access log */
};

/* One line per answered request to --access-log: "METHOD ROUTE STATUS MILLISECONDS", ROUTE the
 * pattern of docs/service.md (the raw path when no route matched), so tests can check that every
 * route of schemas/openapi.yaml was exercised. One write(2) on an O_APPEND descriptor per line,
 * so lines from concurrent connections do not interleave. */
static void access_log(const struct exchange *x, int status)
{
	const struct request *r = &x->req;
	if (r->srv->access_log_fd < 0)
		return;
	struct timespec now;
	clock_gettime(CLOCK_MONOTONIC, &now);
	double ms = (double)(now.tv_sec - x->started.tv_sec) * 1e3 + (double)(now.tv_nsec - x->started.tv_nsec) * 1e-6;
	char line[600];
	int n = snprintf(line, sizeof line, "%s %s %d %.3f\n", r->method, r->route ? r->route->pattern : r->url,
			 status, ms);
	if (n > 0 && (size_t)n < sizeof line && write(r->srv->access_log_fd, line, (size_t)n) < 0) {
		/* a lost log line must not fail the request */
	}
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
	if (!text) {
		reply_text(r, 500, "application/json", strdup("{\"error\":{\"code\":\"internal\",\"message\":"
							      "\"cannot encode the answer\",\"field\":null}}"), 0);
		r->reply.size = strlen(r->reply.body);
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
	reply_json(r, api_code_status(err->code), json_pack("{s:o}", "error", e));
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
		if (!moved)
			return MHD_NO;
		*moved = *rep;
		rep->stream = NULL; /* now owned by the response */
		resp = MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, STREAM_BLOCK, stream_adapter, moved,
							 stream_release);
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
	if (!resp)
		return MHD_NO;
	if (rep->content_type)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, rep->content_type);
	for (int i = 0; i < rep->header_count; i++)
		MHD_add_response_header(resp, rep->headers[i][0], rep->headers[i][1]);
	enum MHD_Result ok = MHD_queue_response(r->connection, (unsigned)rep->status, resp);
	MHD_destroy_response(resp);
	metrics_count_request(r->srv->metrics, rep->status);
	access_log(x, rep->status);
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
		} else { /* {name}: the rest of the path */
			*name = strdup(u);
			return *name != NULL;
		}
	}
	return *u == '\0';
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
		if (strcmp(ROUTES[i].method, r->method) == 0) {
			r->route = &ROUTES[i];
			r->id = id;
			r->name = name;
			return 0;
		}
		free(name);
		if (!strstr(allow, ROUTES[i].method)) {
			size_t n = strlen(allow);
			snprintf(allow + n, sizeof allow - n, "%s%s", n ? ", " : "", ROUTES[i].method);
		}
	}
	if (allow[0]) {
		reply_header(r, "Allow", allow);
		return reply_fail(r, API_METHOD_NOT_ALLOWED, "", "method %s is not allowed on '%s' (allowed: %s)",
				  r->method, r->url, allow);
	}
	return reply_fail(r, API_NOT_FOUND, "", "no route '%s'", r->url);
}

static int authenticate(struct request *r)
{
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
	return 0;
}

static long long body_limit(struct request *r)
{
	return r->route->upload_data ? r->srv->cfg.max_upload_bytes : r->srv->cfg.max_body_bytes;
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
	if (route_request(r) || authenticate(r) || check_length(r)) {
		x->refused = 1;
		return queue_reply(x);
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

static int take_data(struct exchange *x, const char *data, size_t size)
{
	struct request *r = &x->req;
	x->received += (long long)size;
	if (x->refused || x->too_large || x->upload_failed)
		return x->received > DRAIN_FACTOR * body_limit(r) + (1 << 20) ? -1 : 0;
	if (x->received > body_limit(r)) {
		x->too_large = 1;
		return 0;
	}
	if (r->route->upload_data) {
		if (r->route->upload_data(r, data, size) != 0)
			x->upload_failed = 1;
		return 0;
	}
	if (r->body_size + size + 1 > x->capacity) {
		size_t want = r->body_size + size + 1;
		x->capacity = want > 2 * x->capacity ? want : 2 * x->capacity;
		char *grown = realloc(r->body, x->capacity);
		if (!grown)
			return -1;
		r->body = grown;
	}
	memcpy(r->body + r->body_size, data, size);
	r->body_size += size;
	r->body[r->body_size] = '\0';
	return 0;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *connection, const char *url, const char *method,
				  const char *version, const char *upload_data, size_t *upload_data_size,
				  void **con_cls)
{
	struct exchange *x = *con_cls;
	if (!x) {
		x = calloc(1, sizeof *x);
		if (!x)
			return MHD_NO;
		*con_cls = x;
		clock_gettime(CLOCK_MONOTONIC, &x->started);
		x->req.srv = cls;
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
	struct request *r = &x->req;
	if (x->too_large) {
		reply_reset(&r->reply);
		reply_fail(r, API_TOO_LARGE, "", "request body exceeds the limit of %lld bytes", body_limit(r));
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
	if (x->upload_started && x->req.route->upload_abort)
		x->req.route->upload_abort(&x->req);
	reply_reset(&x->req.reply);
	free(x->req.body);
	free(x->req.name);
	free(x);
	*con_cls = NULL;
}

/* The identity: decoding is done per path element (see the top of this file). */
static size_t no_unescape(void *cls, struct MHD_Connection *c, char *s)
{
	return strlen(s);
}

/* ---- daemon ---- */

static int split_listen(const char *listen, char *host, size_t host_size, char *port, size_t port_size)
{
	const char *colon = strrchr(listen, ':');
	if (!colon || !colon[1])
		return -1;
	const char *h = listen;
	size_t n = (size_t)(colon - listen);
	if (n >= 2 && h[0] == '[' && h[n - 1] == ']') {
		h++;
		n -= 2;
	}
	if (n == 0 || n >= host_size || strlen(colon + 1) >= port_size)
		return -1;
	memcpy(host, h, n);
	host[n] = '\0';
	snprintf(port, port_size, "%s", colon + 1);
	return 0;
}

void *http_start(struct server *srv, char *url, size_t url_size, char *msg, size_t msg_size)
{
	char host[256], port[16];
	if (split_listen(srv->cfg.listen, host, sizeof host, port, sizeof port) != 0) {
		snprintf(msg, msg_size, "invalid --listen '%s': expected HOST:PORT", srv->cfg.listen);
		return NULL;
	}
	struct addrinfo hints = { .ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM, .ai_flags = AI_PASSIVE };
	struct addrinfo *ai = NULL;
	int gai = getaddrinfo(host, port, &hints, &ai);
	if (gai != 0) {
		snprintf(msg, msg_size, "cannot resolve --listen '%s': %s", srv->cfg.listen, gai_strerror(gai));
		return NULL;
	}
	unsigned flags = MHD_USE_THREAD_PER_CONNECTION | MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_POLL |
			 MHD_USE_ITC | MHD_USE_ERROR_LOG;
	if (ai->ai_family == AF_INET6)
		flags |= MHD_USE_IPv6;
	struct MHD_Daemon *d = MHD_start_daemon(
		flags, 0, NULL, NULL, on_request, srv, MHD_OPTION_SOCK_ADDR, ai->ai_addr,
		MHD_OPTION_CONNECTION_LIMIT, (unsigned)srv->cfg.max_connections, MHD_OPTION_NOTIFY_COMPLETED,
		on_completed, srv, MHD_OPTION_UNESCAPE_CALLBACK, no_unescape, NULL, MHD_OPTION_CONNECTION_TIMEOUT,
		(unsigned)CONNECTION_TIMEOUT_SECONDS, MHD_OPTION_END);
	freeaddrinfo(ai);
	if (!d) {
		snprintf(msg, msg_size, "cannot listen on '%s' (address in use or not available)", srv->cfg.listen);
		return NULL;
	}
	const union MHD_DaemonInfo *info = MHD_get_daemon_info(d, MHD_DAEMON_INFO_LISTEN_FD);
	struct sockaddr_storage bound;
	socklen_t len = sizeof bound;
	int actual = 0;
	if (info && getsockname(info->listen_fd, (struct sockaddr *)&bound, &len) == 0)
		actual = ntohs(bound.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&bound)->sin6_port
							   : ((struct sockaddr_in *)&bound)->sin_port);
	int v6 = strchr(host, ':') != NULL;
	snprintf(url, url_size, "http://%s%s%s:%d", v6 ? "[" : "", host, v6 ? "]" : "", actual);
	return d;
}

void http_quiesce(void *daemon)
{
	MHD_socket fd = MHD_quiesce_daemon(daemon);
	if (fd != MHD_INVALID_SOCKET)
		close(fd);
}

void http_stop(void *daemon)
{
	if (daemon)
		MHD_stop_daemon(daemon);
}
