/*
 * front_door.h - admission of connections, ahead of libmicrohttpd (docs/service.md §1 "Admission").
 *
 * The front door owns the listening socket. A new connection waits here, in one poll loop, until
 * its first request head is complete; only then is it handed to libmicrohttpd, whose threads
 * (one per connection) therefore never wait on a client that has not sent a request. Here:
 *   - the head must arrive within --header-timeout-seconds (a slow or silent client gets 408);
 *   - it is checked (request_head.h): what libmicrohttpd would refuse with HTML is refused here
 *     with the API's JSON error;
 *   - each connection is placed in a class: "worker" when its first request is on /v1/worker/ with
 *     a valid worker token, "user" otherwise. Each class has its own budget of connections
 *     (--max-connections, --max-worker-connections), so clients without a token, or users, can never
 *     take the connections the workers need to claim, heartbeat and upload: the queue keeps moving;
 *   - a client address may hold at most --max-connections-per-client user connections (waiting
 *     ones included); over that it gets 429 too_many_connections.
 * After the hand-over the front door still watches each connection: between two requests (and
 * while the next head arrives) it may stay idle for at most the header timeout, and a JSON body must
 * arrive within --body-timeout-seconds; past that the socket is shut down and libmicrohttpd closes
 * it. Uploads, long polls, followed logs and downloads are not cut: they hold a token, and
 * per-token limits bound them (http.c).
 *
 * The peek: the head is read with MSG_PEEK, so libmicrohttpd later reads the same bytes; to wait for
 * more of a head without spinning, the socket's SO_RCVLOWAT is set past what is already there (Linux
 * honours it in poll for TCP) and reset at the hand-over.
 */
#ifndef PORO_FRONT_DOOR_H
#define PORO_FRONT_DOOR_H

#include <sys/socket.h>

#include "server.h"

enum door_class { DOOR_USER, DOOR_WORKER, DOOR_CLASS_COUNT };

struct front_door;
struct door_conn;

/* Hands a connection whose head is complete to the HTTP engine; 0, or -1 when it was refused (the
 * engine has closed the socket then). */
typedef int (*door_admit_fn)(void *cls, int fd, const struct sockaddr *addr, socklen_t addr_len);

/* Binds srv->cfg.listen (port 0 picks one) and starts the front door's thread. url gets
 * "http://HOST:PORT". NULL with msg set on failure. */
struct front_door *front_door_start(struct server *srv, door_admit_fn admit, void *admit_cls, char *url,
				    size_t url_size, char *msg, size_t msg_size);
/* Stops accepting: closes the listening socket and every connection still waiting for its head. */
void front_door_quiesce(struct front_door *d);
/* Joins the thread and frees everything; accepts NULL. Call after the HTTP engine has stopped. */
void front_door_destroy(struct front_door **d);

/* ---- the HTTP engine's view of a handed-over connection (called from http.c) ---- */
/* The engine took the connection on fd: the front door's record of it, or NULL if it has none. */
struct door_conn *front_door_connection_started(struct front_door *d, int fd);
void front_door_connection_closed(struct front_door *d, struct door_conn *c);
/* A request's head was parsed; its body must be in within body_seconds (0: no limit). */
void front_door_request_started(struct front_door *d, struct door_conn *c, int body_seconds);
/* The body is in: the handler runs, for as long as it needs. */
void front_door_request_handling(struct front_door *d, struct door_conn *c);
/* The engine cannot answer (no memory for even the answer): writes a 503 straight to the socket,
 * allocating nothing; the engine then closes the connection. */
void front_door_answer_unavailable(struct front_door *d, struct door_conn *c);
/* The request is answered: the connection is idle until its next head, within the header timeout. */
void front_door_request_ended(struct front_door *d, struct door_conn *c);

/* Connections per class and waiting heads, for /metrics and the tests. */
struct door_counts { int live[DOOR_CLASS_COUNT], waiting; long long refused, timed_out; };
void front_door_counts(struct front_door *d, struct door_counts *out);

#endif
