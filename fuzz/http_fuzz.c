/*
 * http_fuzz.c - libFuzzer target: poro-server's whole request path, from the first byte on the
 * socket to the answer: the front door (head checks, admission), libmicrohttpd, routing,
 * authentication, body limits and JSON checks, every handler and the store (real SQLite).
 *
 * The server is poro-server itself: its main (server/main.c compiled with main renamed) runs in a
 * thread of this process, on 127.0.0.1 with a port the kernel picks and a state directory in
 * /dev/shm (fsync there costs nothing, so the fuzzer is not bound by a disk). Tokens of a user, a
 * worker and an admin are made first with `poro-server token create` (the same main).
 *
 * An input is the bytes a client sends on one connection: one request or several (pipelined).
 * Before sending, the placeholders @U@, @W@ and @A@ are replaced by the user's, the worker's and
 * the admin's tokens, so that mutations reach the handlers behind authentication. The connection
 * is then half-closed and the answer read until the server closes it (or 2 s pass: long polls
 * may hold a connection); the answer is not judged here: the server's sanitizers are the oracle
 * (a crash, a leak, undefined behaviour), and a server that stops answering is a hang, which the
 * next inputs would show as timeouts. Seeds: the files fuzz/http/NAME.http (requests of the API tests) and the
 * submissions fuzz/run.sh makes of tests/cases.
 *
 * Run with -close_fd_mask=3: the server's log line per request would otherwise fill the terminal.
 */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

int poro_server_main(int argc, char **argv);

#define READ_DEADLINE_MS 2000
#define TOKEN_MAX 128
#define CONNECT_TRIES_MS 30000

static char state[256];
static char tokens[3][TOKEN_MAX]; /* user, worker, admin */
static struct sockaddr_in server_addr;

static void *server_thread(void *arg)
{
	char *argv[] = { "poro-server", "--listen", "127.0.0.1:0", "--state", state, "--header-timeout-seconds", "1",
			 "--body-timeout-seconds", "2", "--max-body-bytes", "1048576", "--lease-seconds", "5",
			 "--max-backoff-seconds", "1", "--min-free-mb", "0", NULL };
	exit(poro_server_main(17, argv));
	return arg;
}

/* `poro-server token create` in process, its stdout caught in a file. */
static void make_token(const char *user, const char *role, char out[TOKEN_MAX])
{
	char path[300];
	snprintf(path, sizeof path, "%s.token", state);
	fflush(stdout);
	int saved = dup(1);
	FILE *f = fopen(path, "w+");
	if (!f || saved < 0 || dup2(fileno(f), 1) < 0)
		abort();
	char *argv[] = { "poro-server", "token", "create", "--state", state, "--user", (char *)user, "--role",
			 (char *)role, NULL };
	int rc = poro_server_main(9, argv);
	fflush(stdout);
	dup2(saved, 1);
	close(saved);
	rewind(f);
	if (rc != 0 || !fgets(out, TOKEN_MAX, f))
		abort();
	out[strcspn(out, "\n")] = '\0';
	fclose(f);
	unlink(path);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	const char *base = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
	snprintf(state, sizeof state, "%s/poro-http-fuzz-%d", base, (int)getpid());
	make_token("fuzz", "user", tokens[0]);
	make_token("fuzzworker", "worker", tokens[1]);
	make_token("fuzzadmin", "admin", tokens[2]);
	signal(SIGPIPE, SIG_IGN);
	pthread_t t;
	if (pthread_create(&t, NULL, server_thread, NULL) != 0)
		abort();
	pthread_detach(t);
	char url_path[300], url[256] = "";
	snprintf(url_path, sizeof url_path, "%s/server.url", state);
	for (int i = 0; i < 600 && !url[0]; i++) {
		FILE *f = fopen(url_path, "r");
		if (f) {
			if (!fgets(url, sizeof url, f))
				url[0] = '\0';
			fclose(f);
		}
		if (!url[0])
			nanosleep(&(struct timespec){ 0, 50000000 }, NULL);
	}
	int port = 0;
	if (sscanf(url, "http://127.0.0.1:%d", &port) != 1) {
		fprintf(stderr, "http_fuzz: the server did not start (state '%s')\n", state);
		abort();
	}
	server_addr.sin_family = AF_INET;
	server_addr.sin_port = htons((uint16_t)port);
	server_addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	return 0;
}

/* The input with @U@, @W@ and @A@ replaced by the tokens; *n gets its length. */
static char *expand(const uint8_t *data, size_t size, size_t *n)
{
	char *out = malloc(size * (TOKEN_MAX / 3 + 1) + 1);
	if (!out)
		return NULL;
	size_t j = 0;
	for (size_t i = 0; i < size; i++) {
		const char *tok = NULL;
		if (i + 2 < size && data[i] == '@' && data[i + 2] == '@')
			tok = data[i + 1] == 'U' ? tokens[0] : data[i + 1] == 'W' ? tokens[1] : data[i + 1] == 'A' ? tokens[2] : NULL;
		if (tok) {
			size_t k = strlen(tok);
			memcpy(out + j, tok, k);
			j += k;
			i += 2;
		} else {
			out[j++] = (char)data[i];
		}
	}
	*n = j;
	return out;
}

static long long now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (long long)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

/* A connection to the server. It is closed with a reset (SO_LINGER 0): hundreds of connections a
 * second closed the orderly way leave as many in TIME_WAIT, and the machine's ephemeral ports ran
 * out after 800,000 inputs. A connect that still fails for want of a port or of the server's
 * backlog is tried again for up to CONNECT_TRIES_MS; only a server that takes no connection for
 * that long is a finding (-1). */
static int connect_server(void)
{
	for (int waited = 0; waited < CONNECT_TRIES_MS; waited += 10) {
		int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
		if (fd < 0)
			return -1;
		struct linger abortive = { .l_onoff = 1, .l_linger = 0 };
		setsockopt(fd, SOL_SOCKET, SO_LINGER, &abortive, sizeof abortive);
		if (connect(fd, (struct sockaddr *)&server_addr, sizeof server_addr) == 0)
			return fd;
		int e = errno;
		close(fd);
		if (e != EADDRNOTAVAIL && e != ECONNREFUSED && e != EAGAIN && e != ETIMEDOUT) {
			errno = e;
			return -1;
		}
		nanosleep(&(struct timespec){ 0, 10000000 }, NULL);
	}
	return -1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	size_t n;
	char *req = expand(data, size, &n);
	if (!req)
		return 0;
	int fd = connect_server();
	if (fd < 0) {
		fprintf(stderr, "http_fuzz: the server does not take connections: %s\n", strerror(errno));
		abort();
	}
	size_t sent = 0;
	while (sent < n) {
		ssize_t w = send(fd, req + sent, n - sent, MSG_NOSIGNAL);
		if (w <= 0)
			break; /* the server closed early: a refusal */
		sent += (size_t)w;
	}
	shutdown(fd, SHUT_WR);
	char buf[16384];
	long long deadline = now_ms() + READ_DEADLINE_MS;
	for (;;) {
		long long left = deadline - now_ms();
		struct pollfd p = { .fd = fd, .events = POLLIN };
		if (left <= 0 || poll(&p, 1, (int)left) <= 0)
			break;
		if (recv(fd, buf, sizeof buf, 0) <= 0)
			break;
	}
	close(fd);
	free(req);
	return 0;
}
