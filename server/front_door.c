/*
 * front_door.c - admission of connections ahead of libmicrohttpd (front_door.h).
 *
 * One thread runs a poll loop over the listening socket and the connections still waiting for
 * their first request head ("waiting"), and once per tick checks the deadlines of both the waiting
 * connections and the handed-over ones ("live"). Waiting connections belong to that thread alone.
 * Live records, the per-class counts and the per-address counts are shared with libmicrohttpd's
 * connection threads, which report a connection's life through the front_door_* hooks, and are
 * guarded by d->lock.
 *
 * Refusals are written straight to the socket as a complete HTTP/1.1 answer with the API's JSON
 * error and "Connection: close"; the socket is then half-closed and read until the client closes
 * or LINGER_SECONDS pass ("lingering close", RFC 9112 §9.6), so the client reads the answer instead
 * of a reset caused by the request bytes it had already sent.
 *
 * Addresses are counted by their 16-byte IPv6 form (IPv4 as ::ffff:a.b.c.d) in a key_counts table
 * made for as many keys as there can be connections, so it never fills.
 */
#define _GNU_SOURCE /* accept4, POLLRDHUP */
#include "front_door.h"
#include "listen_socket.h"

#include "log.h"
#include "metrics.h"
#include "request_head.h"
#include "store.h"

#include "digest.h"
#include "key_counts.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#define DOOR_TICK_MS 200              /* deadlines are checked this often */
#define LINGER_SECONDS 2.0            /* a refused connection is read this long before it is closed */
#define HANDOVER_GRACE_SECONDS 30.0   /* a hand-over the engine never confirmed is forgotten after this */
#define ACCEPTS_PER_ROUND 256         /* accept() calls before the waiting connections get a turn */
#define LISTEN_BACKLOG 1024
#define FD_RESERVE 64                 /* descriptors kept for the database, logs and files */

enum { SLOT_FREE, SLOT_HANDED, SLOT_LIVE };

struct waiting {
	int fd;
	int lingering;                /* refused: answered, half-closed, being read until it closes */
	double deadline;
	size_t seen;                  /* bytes of the head peeked so far */
	unsigned char key[16];
	struct sockaddr_storage addr;
	socklen_t addr_len;
};

struct door_conn {
	int fd;
	int state;                    /* SLOT_* */
	enum door_class cls;
	unsigned char key[16];
	int counted;                  /* counts against its address (user connections) */
	int in_request, shut;
	int requests;                 /* requests the engine started on it */
	double since;                 /* handed over, or idle since the end of the last request */
	double body_deadline;         /* 0: none */
};

struct front_door {
	struct server *srv;
	door_admit_fn admit;
	void *admit_cls;
	int listen_fd;
	int wake[2];                  /* a byte written to wake[1] ends the poll: quiesce */
	pthread_t thread;
	int thread_started;
	atomic_int stopping;

	struct waiting *waiting;      /* the thread's own */
	int waiting_count, waiting_max;
	struct pollfd *polls;

	pthread_mutex_t lock;         /* guards everything below */
	struct door_conn *conns;
	int conn_max;
	int live[DOOR_CLASS_COUNT], budget[DOOR_CLASS_COUNT];
	struct key_counts addresses;  /* connections per client address: waiting and live users */
	int waiting_now;              /* a copy of waiting_count for front_door_counts */
	long long refused, timed_out;

	char head[REQUEST_HEAD_MAX];  /* the thread's peek buffer */
};

static double now_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- per-address counts (under d->lock) ---- */

static void address_key(const struct sockaddr_storage *sa, unsigned char key[16])
{
	memset(key, 0, 16);
	if (sa->ss_family == AF_INET) {
		key[10] = key[11] = 0xff;
		memcpy(key + 12, &((const struct sockaddr_in *)sa)->sin_addr, 4);
	} else if (sa->ss_family == AF_INET6) {
		memcpy(key, &((const struct sockaddr_in6 *)sa)->sin6_addr, 16);
	}
}

static int address_count(struct front_door *d, const unsigned char key[16])
{
	return key_counts_get(&d->addresses, key);
}

/* The table holds as many keys as there can be connections, so adding never fails. */
static void address_add(struct front_door *d, const unsigned char key[16], int delta)
{
	key_counts_add(&d->addresses, key, delta);
}

/* ---- answers written by the front door itself ---- */

static const char *reason_phrase(int status)
{
	switch (status) {
	case 400: return "Bad Request";
	case 408: return "Request Timeout";
	case 413: return "Content Too Large";
	case 414: return "URI Too Long";
	case 429: return "Too Many Requests";
	case 431: return "Request Header Fields Too Large";
	case 501: return "Not Implemented";
	case 503: return "Service Unavailable";
	case 505: return "HTTP Version Not Supported";
	default: return "Error";
	}
}

static void stop_waiting(struct front_door *d, int i, int close_fd);

/* An answer of the front door's own in the server's log (log.h): a request line with no method,
 * route, user or duration, which are not known before the head is handed over, the error code and
 * by=front_door. The head itself is never logged: it may hold a token. */
static void log_answer(int fd, int status, enum api_code code)
{
	struct sockaddr_storage addr;
	socklen_t addr_len = sizeof addr;
	char client[INET6_ADDRSTRLEN] = "-";
	if (getpeername(fd, (struct sockaddr *)&addr, &addr_len) == 0)
		getnameinfo((struct sockaddr *)&addr, addr_len, client, sizeof client, NULL, 0, NI_NUMERICHOST);
	struct log_line l;
	log_line_begin_request(&l, status >= 500 ? LOG_PRIO_WARNING : LOG_PRIO_INFO);
	log_line_str(&l, "method", "-");
	log_line_str(&l, "route", "-");
	log_line_int(&l, "status", status);
	log_line_str(&l, "user", "-");
	log_line_str(&l, "client", client);
	log_line_str(&l, "code", api_code_name(code));
	log_line_str(&l, "by", "front_door");
	log_line_end(&l);
}

/* Writes a whole HTTP answer with the API's JSON error to fd and says the connection closes.
 * Allocates nothing, so it works when memory has run out: the message is escaped into a buffer on
 * the stack (the front door's messages are its own text, so nothing needs more than a backslash). */
static void write_answer(struct front_door *d, int fd, int status, enum api_code code, const char *message)
{
	char escaped[400], body[600], head[320];
	size_t n = 0;
	for (const char *m = message; *m && n + 2 < sizeof escaped; m++) {
		if (*m == '"' || *m == '\\')
			escaped[n++] = '\\';
		escaped[n++] = (unsigned char)*m < 0x20 ? ' ' : *m;
	}
	escaped[n] = '\0';
	int size = snprintf(body, sizeof body, "{\"error\":{\"code\":\"%s\",\"message\":\"%s\",\"field\":null}}\n",
			    api_code_name(code), escaped);
	int head_size = snprintf(head, sizeof head,
				 "HTTP/1.1 %d %s\r\nContent-Type: application/json\r\nContent-Length: %d\r\n"
				 "Cache-Control: no-store\r\nConnection: close\r\n%s\r\n",
				 status, reason_phrase(status), size,
				 status == 503 || status == 429 ? "Retry-After: 1\r\n" : "");
	/* a socket's send buffer holds far more than this answer; a short write only loses it */
	if (send(fd, head, (size_t)head_size, MSG_NOSIGNAL) == head_size)
		(void)send(fd, body, (size_t)size, MSG_NOSIGNAL);
	metrics_count_request(d->srv->metrics, status);
	log_answer(fd, status, code);
}

/* Answers a waiting connection with a JSON error and lingers, or closes it at once when the waiting
 * table is half full (under a flood, refusals must not crowd out the connections still to come). */
static void refuse(struct front_door *d, int i, int status, enum api_code code, const char *message)
{
	struct waiting *w = &d->waiting[i];
	write_answer(d, w->fd, status, code, message);
	pthread_mutex_lock(&d->lock);
	d->refused++;
	pthread_mutex_unlock(&d->lock);
	if (d->waiting_count > d->waiting_max / 2) {
		stop_waiting(d, i, 1);
		return;
	}
	shutdown(w->fd, SHUT_WR);
	if (!w->lingering) {
		pthread_mutex_lock(&d->lock);
		address_add(d, w->key, -1);
		pthread_mutex_unlock(&d->lock);
	}
	w->lingering = 1;
	w->deadline = now_seconds() + LINGER_SECONDS;
}

/* ---- waiting connections (the thread's own) ---- */

static void stop_waiting(struct front_door *d, int i, int close_fd)
{
	struct waiting *w = &d->waiting[i];
	if (!w->lingering) {
		pthread_mutex_lock(&d->lock);
		address_add(d, w->key, -1);
		pthread_mutex_unlock(&d->lock);
	}
	if (close_fd)
		close(w->fd);
	d->waiting[i] = d->waiting[--d->waiting_count];
}

static void accept_new(struct front_door *d)
{
	for (int n = 0; n < ACCEPTS_PER_ROUND && d->waiting_count < d->waiting_max; n++) {
		struct waiting *w = &d->waiting[d->waiting_count];
		memset(w, 0, sizeof *w);
		w->addr_len = sizeof w->addr;
		w->fd = accept4(d->listen_fd, (struct sockaddr *)&w->addr, &w->addr_len, SOCK_NONBLOCK | SOCK_CLOEXEC);
		if (w->fd < 0)
			return; /* EAGAIN: nothing more; EMFILE and the like: try again next tick */
		address_key(&w->addr, w->key);
		w->deadline = now_seconds() + d->srv->cfg.header_timeout_seconds;
		pthread_mutex_lock(&d->lock);
		int held = address_count(d, w->key);
		address_add(d, w->key, 1);
		pthread_mutex_unlock(&d->lock);
		int i = d->waiting_count++;
		if (held >= d->srv->cfg.max_connections_per_client) {
			char addr[INET6_ADDRSTRLEN] = "?", message[200];
			getnameinfo((struct sockaddr *)&w->addr, w->addr_len, addr, sizeof addr, NULL, 0, NI_NUMERICHOST);
			snprintf(message, sizeof message, "client '%s' already holds %d connections, the limit per client",
				 addr, held);
			refuse(d, i, 429, API_TOO_MANY_CONNECTIONS, message);
		}
	}
}

/* Whether the head's first request goes to the workers' class: a /v1/worker/ route with a valid
 * worker token. Anything else, or a token that does not check out, is a user connection. */
static enum door_class classify(struct front_door *d, const struct request_head *h)
{
	static const char prefix[] = "/v1/worker/";
	if (!h->bearer || h->target_len < sizeof prefix - 1 || memcmp(h->target, prefix, sizeof prefix - 1) != 0)
		return DOOR_USER;
	char hash[DIGEST_HEX_SIZE];
	digest_hex(h->bearer, h->bearer_len, hash);
	struct principal who = { 0 };
	struct api_error err = { 0 };
	int worker = store_auth_peek(d->srv->store, hash, &who, &err) == API_OK && who.role == ROLE_WORKER;
	return worker ? DOOR_WORKER : DOOR_USER;
}

static struct door_conn *free_slot(struct front_door *d)
{
	for (int i = 0; i < d->conn_max; i++)
		if (d->conns[i].state == SLOT_FREE)
			return &d->conns[i];
	return NULL;
}

static void release_slot(struct front_door *d, struct door_conn *c)
{
	d->live[c->cls]--;
	if (c->counted)
		address_add(d, c->key, -1);
	c->state = SLOT_FREE;
}

static void hand_over(struct front_door *d, int i, const struct request_head *h)
{
	static const char *const class_names[] = { "users", "workers" };
	struct waiting *w = &d->waiting[i];
	enum door_class cls = classify(d, h);
	pthread_mutex_lock(&d->lock);
	/* a record still waiting for the engine's word on this descriptor is stale: the engine closed
	 * that socket without telling, and the kernel has given its number to this one */
	for (int k = 0; k < d->conn_max; k++)
		if (d->conns[k].state == SLOT_HANDED && d->conns[k].fd == w->fd)
			release_slot(d, &d->conns[k]);
	struct door_conn *c = d->live[cls] < d->budget[cls] ? free_slot(d) : NULL;
	if (c) {
		*c = (struct door_conn){ .fd = w->fd, .state = SLOT_HANDED, .cls = cls, .counted = cls == DOOR_USER,
					 .since = now_seconds() };
		memcpy(c->key, w->key, 16);
		d->live[cls]++;
		if (!c->counted)
			address_add(d, w->key, -1);
		w->lingering = 1; /* its address count now belongs to the live record */
	}
	pthread_mutex_unlock(&d->lock);
	if (!c) {
		char message[200];
		snprintf(message, sizeof message, "all %d connections for %s are in use: retry shortly",
			 d->budget[cls], class_names[cls]);
		refuse(d, i, 503, API_UNAVAILABLE, message);
		return;
	}
	int one = 1;
	setsockopt(w->fd, SOL_SOCKET, SO_RCVLOWAT, &one, sizeof one);
	int fd = w->fd;
	struct sockaddr_storage addr = w->addr;
	socklen_t addr_len = w->addr_len;
	stop_waiting(d, i, 0);
	if (d->admit(d->admit_cls, fd, (struct sockaddr *)&addr, addr_len) != 0) {
		pthread_mutex_lock(&d->lock);
		if (c->state == SLOT_HANDED && c->fd == fd)
			release_slot(d, c);
		pthread_mutex_unlock(&d->lock);
	}
}

/* A waiting connection has news: more of its head, its end, or the end of a lingering read. */
static void read_waiting(struct front_door *d, int i, short revents)
{
	struct waiting *w = &d->waiting[i];
	if (w->lingering) {
		char sink[4096];
		ssize_t n = recv(w->fd, sink, sizeof sink, 0);
		if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR))
			stop_waiting(d, i, 1);
		return;
	}
	ssize_t n = recv(w->fd, d->head, sizeof d->head, MSG_PEEK);
	if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) {
		stop_waiting(d, i, 1);
		return;
	}
	if (n < 0)
		return;
	struct request_head h;
	struct head_refusal why;
	switch (request_head_parse(d->head, (size_t)n, &h, &why)) {
	case HEAD_OK:
		hand_over(d, i, &h);
		return;
	case HEAD_REFUSED:
		refuse(d, i, why.status, why.code, why.message);
		return;
	case HEAD_INCOMPLETE:
		break;
	}
	if ((size_t)n == w->seen && (revents & (POLLRDHUP | POLLHUP))) {
		stop_waiting(d, i, 1); /* the client stopped sending before its head was complete */
		return;
	}
	w->seen = (size_t)n;
	/* wake up again only when more than what is there has arrived */
	int more = (int)n + 1;
	setsockopt(w->fd, SOL_SOCKET, SO_RCVLOWAT, &more, sizeof more);
}

/* Deadlines: heads that did not arrive in time, lingering reads that are over, idle live
 * connections and JSON bodies that are too slow. */
static void check_deadlines(struct front_door *d, double now)
{
	for (int i = d->waiting_count - 1; i >= 0; i--) {
		struct waiting *w = &d->waiting[i];
		if (now < w->deadline)
			continue;
		if (w->lingering) {
			stop_waiting(d, i, 1);
			continue;
		}
		char message[160];
		snprintf(message, sizeof message, "no complete request head within %d s",
			 d->srv->cfg.header_timeout_seconds);
		pthread_mutex_lock(&d->lock);
		d->timed_out++;
		pthread_mutex_unlock(&d->lock);
		refuse(d, i, 408, API_REQUEST_TIMEOUT, message);
	}
	double idle_max = d->srv->cfg.header_timeout_seconds;
	pthread_mutex_lock(&d->lock);
	for (int i = 0; i < d->conn_max; i++) {
		struct door_conn *c = &d->conns[i];
		if (c->state == SLOT_HANDED && now - c->since > HANDOVER_GRACE_SECONDS) {
			release_slot(d, c); /* the engine refused it without telling: its socket is gone */
			continue;
		}
		if (c->state != SLOT_LIVE || c->shut)
			continue;
		int idle = !c->in_request && now - c->since > idle_max;
		int slow_body = c->in_request && c->body_deadline > 0 && now > c->body_deadline;
		if (idle || slow_body) {
			/* the engine's thread sees the end of the stream and closes the connection */
			shutdown(c->fd, SHUT_RDWR);
			c->shut = 1;
			d->timed_out++;
		}
	}
	pthread_mutex_unlock(&d->lock);
}

static void *door_main(void *arg)
{
	struct front_door *d = arg;
	double last_check = 0;
	while (!atomic_load(&d->stopping)) {
		int n = 0;
		d->polls[n++] = (struct pollfd){ .fd = d->wake[0], .events = POLLIN };
		int listening = d->waiting_count < d->waiting_max;
		d->polls[n++] = (struct pollfd){ .fd = listening ? d->listen_fd : -1, .events = POLLIN };
		for (int i = 0; i < d->waiting_count; i++)
			d->polls[n++] = (struct pollfd){ .fd = d->waiting[i].fd, .events = POLLIN | POLLRDHUP };
		int ready = poll(d->polls, (nfds_t)n, DOOR_TICK_MS);
		if (ready < 0 && errno != EINTR)
			break;
		if (atomic_load(&d->stopping))
			break;
		/* the waiting connections first, from the end, so removals do not move unvisited ones */
		for (int i = d->waiting_count - 1; ready > 0 && i >= 0; i--)
			if (d->polls[2 + i].revents)
				read_waiting(d, i, d->polls[2 + i].revents);
		if (ready > 0 && (d->polls[1].revents & POLLIN))
			accept_new(d);
		double now = now_seconds();
		if (now - last_check >= DOOR_TICK_MS * 1e-3) {
			check_deadlines(d, now);
			last_check = now;
		}
		pthread_mutex_lock(&d->lock);
		d->waiting_now = d->waiting_count;
		pthread_mutex_unlock(&d->lock);
	}
	for (int i = d->waiting_count - 1; i >= 0; i--)
		stop_waiting(d, i, 1);
	return NULL;
}

/* ---- start and stop ---- */

static int open_listener(struct front_door *d, char *url, size_t url_size, char *msg, size_t msg_size)
{
	const struct server_config *cfg = &d->srv->cfg;
	int fd = listen_socket_open(cfg->listen, "--listen", "http", !cfg->allow_plain_http, LISTEN_BACKLOG, url,
				    url_size, msg, msg_size);
	if (fd < 0)
		return -1;
	d->listen_fd = fd;
	return 0;
}

/* Waiting connections may use what descriptors the live ones and the database leave: each live
 * connection may hold a socket, a read connection of the database and a file being sent. */
static int waiting_capacity(const struct server_config *cfg, int conn_max)
{
	struct rlimit nofile;
	long avail = cfg->max_waiting_connections;
	if (getrlimit(RLIMIT_NOFILE, &nofile) == 0 && nofile.rlim_cur != RLIM_INFINITY) {
		long spare = (long)nofile.rlim_cur - FD_RESERVE - 3L * conn_max;
		if (spare < avail)
			avail = spare;
	}
	return avail < 16 ? 16 : (int)avail;
}

struct front_door *front_door_start(struct server *srv, door_admit_fn admit, void *admit_cls, char *url,
				    size_t url_size, char *msg, size_t msg_size)
{
	struct front_door *d = calloc(1, sizeof *d);
	if (!d) {
		snprintf(msg, msg_size, "out of memory");
		return NULL;
	}
	d->srv = srv;
	d->admit = admit;
	d->admit_cls = admit_cls;
	d->listen_fd = d->wake[0] = d->wake[1] = -1;
	d->budget[DOOR_USER] = srv->cfg.max_connections;
	d->budget[DOOR_WORKER] = srv->cfg.max_worker_connections;
	d->conn_max = d->budget[DOOR_USER] + d->budget[DOOR_WORKER];
	d->waiting_max = waiting_capacity(&srv->cfg, d->conn_max);
	pthread_mutex_init(&d->lock, NULL);
	d->conns = calloc((size_t)d->conn_max, sizeof *d->conns);
	d->waiting = calloc((size_t)d->waiting_max, sizeof *d->waiting);
	d->polls = calloc((size_t)d->waiting_max + 2, sizeof *d->polls);
	if (!d->conns || !d->waiting || !d->polls ||
	    key_counts_init(&d->addresses, 16, (size_t)(d->conn_max + d->waiting_max)) != 0 ||
	    pipe2(d->wake, O_CLOEXEC | O_NONBLOCK) != 0) {
		snprintf(msg, msg_size, "out of memory for %d connections", d->conn_max + d->waiting_max);
		front_door_destroy(&d);
		return NULL;
	}
	if (open_listener(d, url, url_size, msg, msg_size) != 0) {
		front_door_destroy(&d);
		return NULL;
	}
	if (pthread_create(&d->thread, NULL, door_main, d) != 0) {
		snprintf(msg, msg_size, "cannot start the front door's thread");
		front_door_destroy(&d);
		return NULL;
	}
	d->thread_started = 1;
	return d;
}

void front_door_quiesce(struct front_door *d)
{
	if (!d || !d->thread_started)
		return;
	atomic_store(&d->stopping, 1);
	ssize_t w = write(d->wake[1], "q", 1);
	(void)w;
	pthread_join(d->thread, NULL);
	d->thread_started = 0;
	if (d->listen_fd >= 0)
		close(d->listen_fd);
	d->listen_fd = -1;
}

void front_door_destroy(struct front_door **dp)
{
	struct front_door *d = dp ? *dp : NULL;
	if (!d)
		return;
	front_door_quiesce(d);
	if (d->listen_fd >= 0)
		close(d->listen_fd);
	for (int i = 0; i < 2; i++)
		if (d->wake[i] >= 0)
			close(d->wake[i]);
	pthread_mutex_destroy(&d->lock);
	free(d->conns);
	free(d->waiting);
	free(d->polls);
	key_counts_release(&d->addresses);
	free(d);
	*dp = NULL;
}

/* ---- hooks of the HTTP engine ---- */

struct door_conn *front_door_connection_started(struct front_door *d, int fd)
{
	struct door_conn *found = NULL;
	pthread_mutex_lock(&d->lock);
	for (int i = 0; i < d->conn_max && !found; i++)
		if (d->conns[i].state == SLOT_HANDED && d->conns[i].fd == fd)
			found = &d->conns[i];
	if (found) {
		found->state = SLOT_LIVE;
		found->since = now_seconds();
	}
	pthread_mutex_unlock(&d->lock);
	return found;
}

void front_door_connection_closed(struct front_door *d, struct door_conn *c)
{
	if (!c)
		return;
	/* Every connection was handed over with a complete, checked head, so the engine dropping one
	 * before its first request means it could not take it (no memory, no thread): the client gets
	 * a 503 rather than a reset. The engine closes the socket only after this hook. */
	if (c->state == SLOT_LIVE && c->requests == 0 && !c->shut)
		write_answer(d, c->fd, 503, API_UNAVAILABLE, "the server has no resources for another connection now: "
			     "retry shortly");
	pthread_mutex_lock(&d->lock);
	if (c->state != SLOT_FREE)
		release_slot(d, c);
	pthread_mutex_unlock(&d->lock);
}

void front_door_answer_unavailable(struct front_door *d, struct door_conn *c)
{
	if (!c)
		return;
	write_answer(d, c->fd, 503, API_UNAVAILABLE, "the server is out of memory: retry later");
	pthread_mutex_lock(&d->lock);
	c->shut = 1; /* answered: the engine closes it, and the close must not answer again */
	pthread_mutex_unlock(&d->lock);
}

void front_door_request_started(struct front_door *d, struct door_conn *c, int body_seconds)
{
	if (!c)
		return;
	pthread_mutex_lock(&d->lock);
	c->in_request = 1;
	c->requests++;
	c->body_deadline = body_seconds > 0 ? now_seconds() + body_seconds : 0;
	pthread_mutex_unlock(&d->lock);
}

void front_door_request_handling(struct front_door *d, struct door_conn *c)
{
	if (!c)
		return;
	pthread_mutex_lock(&d->lock);
	c->body_deadline = 0;
	pthread_mutex_unlock(&d->lock);
}

void front_door_request_ended(struct front_door *d, struct door_conn *c)
{
	if (!c)
		return;
	pthread_mutex_lock(&d->lock);
	c->in_request = 0;
	c->since = now_seconds();
	pthread_mutex_unlock(&d->lock);
}

void front_door_counts(struct front_door *d, struct door_counts *out)
{
	memset(out, 0, sizeof *out);
	if (!d)
		return;
	pthread_mutex_lock(&d->lock);
	for (int k = 0; k < DOOR_CLASS_COUNT; k++)
		out->live[k] = d->live[k];
	out->waiting = d->waiting_now;
	out->refused = d->refused;
	out->timed_out = d->timed_out;
	pthread_mutex_unlock(&d->lock);
}
