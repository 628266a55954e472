/*
 * listen_socket.c - a listening socket from a HOST:PORT flag, and the loopback rule for plain
 * HTTP (listen_socket.h).
 */
#include "listen_socket.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netdb.h>
#include <netinet/in.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

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

static int is_loopback(const struct sockaddr *a)
{
	if (a->sa_family == AF_INET)
		return (ntohl(((const struct sockaddr_in *)(const void *)a)->sin_addr.s_addr) >> 24) == 127;
	if (a->sa_family == AF_INET6)
		return IN6_IS_ADDR_LOOPBACK(&((const struct sockaddr_in6 *)(const void *)a)->sin6_addr);
	return 0;
}

int listen_socket_open(const char *listen_at, const char *flag, const char *scheme, int plain_only_loopback,
		       int backlog, char *url, size_t url_size, char *msg, size_t msg_size)
{
	char host[256], port[16];
	if (split_listen(listen_at, host, sizeof host, port, sizeof port) != 0) {
		snprintf(msg, msg_size, "invalid %s '%s': expected HOST:PORT", flag, listen_at);
		return -1;
	}
	struct addrinfo hints = { .ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM, .ai_flags = AI_PASSIVE };
	struct addrinfo *ai = NULL;
	int gai = getaddrinfo(host, port, &hints, &ai);
	if (gai != 0) {
		snprintf(msg, msg_size, "cannot resolve %s '%s': %s", flag, listen_at, gai_strerror(gai));
		return -1;
	}
	if (plain_only_loopback && !is_loopback(ai->ai_addr)) {
		snprintf(msg, msg_size, "refusing plain HTTP on %s '%s', which is not a loopback address: tokens would "
			 "cross the network in clear text; serve it with --tls-listen, --tls-cert and --tls-key, or "
			 "set --allow-plain-http=1 (a TLS proxy in front)", flag, listen_at);
		freeaddrinfo(ai);
		return -1;
	}
	int fd = socket(ai->ai_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
	int one = 1;
	if (fd >= 0)
		setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
	if (fd < 0 || bind(fd, ai->ai_addr, ai->ai_addrlen) != 0 || listen(fd, backlog) != 0) {
		snprintf(msg, msg_size, "cannot listen on %s '%s': %s", flag, listen_at, strerror(errno));
		if (fd >= 0)
			close(fd);
		freeaddrinfo(ai);
		return -1;
	}
	freeaddrinfo(ai);
	struct sockaddr_storage bound;
	socklen_t len = sizeof bound;
	int actual = 0;
	if (getsockname(fd, (struct sockaddr *)&bound, &len) == 0)
		actual = ntohs(bound.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&bound)->sin6_port
							   : ((struct sockaddr_in *)&bound)->sin_port);
	int v6 = strchr(host, ':') != NULL;
	snprintf(url, url_size, "%s://%s%s%s:%d", scheme, v6 ? "[" : "", host, v6 ? "]" : "", actual);
	return fd;
}
