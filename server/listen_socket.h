/*
 * listen_socket.h - binding a listening TCP socket from a "HOST:PORT" flag (--listen,
 * --tls-listen), and the rule that plain HTTP stays on loopback (docs/operations.md, "TLS").
 *
 * Why the rule: every request carries a bearer token, and a worker's token lets its holder take
 * and finish anyone's jobs; over plain HTTP on a network those tokens cross in clear text. So a
 * plain listener on an address that is not loopback (127.0.0.0/8, ::1) is refused unless the
 * operator says otherwise (--allow-plain-http=1: a TLS-terminating proxy in front, or a network
 * trusted as a whole). A wildcard address (0.0.0.0, ::) is not loopback.
 */
#ifndef PORO_LISTEN_SOCKET_H
#define PORO_LISTEN_SOCKET_H

#include <stddef.h>

/* Binds and listens on listen_at ("HOST:PORT", "[V6]:PORT"; port 0 picks a free one), non-blocking
 * and close-on-exec. flag names the option in messages ("--listen"). With plain_only_loopback set,
 * an address that is not loopback is refused. url gets "SCHEME://HOST:PORT" with the port bound.
 * Returns the socket, or -1 with a message naming the flag and what is wrong. */
int listen_socket_open(const char *listen_at, const char *flag, const char *scheme, int plain_only_loopback,
		       int backlog, char *url, size_t url_size, char *msg, size_t msg_size);

#endif
