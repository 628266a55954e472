/*
 * main.c - the poro-server program: configuration from a file and flags (flags win), the
 * `token create|list|revoke` subcommands (token_cli.c), start-up (state directory locked and made
 * private, database, HTTP, reaper, the URL written atomically to STATE/server.url) and orderly
 * shutdown on SIGTERM or SIGINT: stop accepting, let in-flight requests finish (their writes
 * commit), end long-polls and followed logs, stop the writer, close the database, exit 0.
 *
 * The process runs under umask 077, so everything it creates (database, WAL, results, the URL
 * file) is its owner's alone; state_dir_restrict() takes away what older runs left open. SIGXFSZ
 * is ignored: a write past a file-size limit (RLIMIT_FSIZE) then fails with EFBIG, which SQLite
 * and the upload path report as an error answer, instead of killing the server.
 *
 * Every option is one row of OPTIONS: the flag name, which is also the key in the config file
 * ("name = value" lines, '#' comments), the field it sets, its default and its help text. The
 * command line is read by getopt_long (--opt=value or --opt value, abbreviations, "--"); --help
 * and --version print on stdout and exit 0, a bad command line or config file exits 2.
 */
#include "api.h"
#include "backup_cli.h"
#include "file_sweep.h"
#include "http.h"
#include "log.h"
#include "metrics.h"
#include "reaper.h"
#include "state_dir.h"
#include "store.h"
#include "token_cli.h"

#include "fs.h"

#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <malloc.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#define MALLOC_ARENAS 2

enum option_type { OPT_TEXT, OPT_INT, OPT_LONG };

struct option_def {
	const char *name;
	const char *arg;         /* the value's name in --help */
	enum option_type type;
	size_t offset;           /* in struct server_config */
	size_t size;             /* OPT_TEXT: buffer size */
	long long min, max;
	const char *help;
};

#define TEXT_OPT(n, a, f, h) { n, a, OPT_TEXT, offsetof(struct server_config, f), sizeof((struct server_config *)0)->f, 0, 0, h }
#define INT_OPT(n, f, lo, hi, h) { n, "N", OPT_INT, offsetof(struct server_config, f), 0, lo, hi, h }
#define LONG_OPT(n, f, lo, hi, h) { n, "N", OPT_LONG, offsetof(struct server_config, f), 0, lo, hi, h }

static const struct option_def OPTIONS[] = {
	TEXT_OPT("listen", "HOST:PORT", listen, "HOST:PORT to listen on; port 0 picks a free one (default 127.0.0.1:8080)"),
	TEXT_OPT("state", "DIR", state, "state directory: poro.db, files/, server.url (default ./var)"),
	INT_OPT("max-connections", max_connections, 1, 100000, "connections of users and clients without a token, one thread each (default 512)"),
	INT_OPT("max-worker-connections", max_worker_connections, 1, 100000, "connections of worker tokens on /v1/worker/ routes, kept apart (default 256)"),
	INT_OPT("max-connections-per-client", max_connections_per_client, 1, 100000, "user connections from one client address, waiting ones included (default 128)"),
	INT_OPT("max-waiting-connections", max_waiting_connections, 16, 1000000, "connections whose first request head has not arrived yet (default 4096)"),
	INT_OPT("header-timeout-seconds", header_timeout_seconds, 1, 3600, "a request head must arrive within this, and a connection may idle this long between requests (default 10)"),
	INT_OPT("body-timeout-seconds", body_timeout_seconds, 1, 86400, "a JSON request body must arrive within this (default 60)"),
	INT_OPT("max-requests-per-token", max_requests_per_token, 1, 100000, "requests in progress per user or admin token (default 32)"),
	INT_OPT("max-requests-per-worker-token", max_requests_per_worker_token, 1, 100000, "requests in progress per worker token (default 512)"),
	INT_OPT("max-concurrent-submissions", max_concurrent_submissions, 1, 1024, "submissions being validated at once (default 4)"),
	LONG_OPT("max-body-values", max_body_values, 1000, 1LL << 40, "JSON values, keys included, in a submission's body (default 500000)"),
	LONG_OPT("max-body-bytes", max_body_bytes, 1024, 1LL << 40, "largest JSON request body (default 4194304)"),
	LONG_OPT("max-upload-bytes", max_upload_bytes, 1, 1LL << 50, "largest uploaded file (default 4294967296)"),
	INT_OPT("lease-seconds", lease_seconds, 1, 86400, "lease length; each heartbeat renews it (default 30)"),
	INT_OPT("max-attempts", max_attempts, 1, 1000, "attempts before an infrastructure failure is final (default 5)"),
	INT_OPT("user-max-queued", user_max_queued, 1, 100000000, "default per-user cap on queued jobs (default 10000)"),
	INT_OPT("user-max-running", user_max_running, 0, 100000000, "default per-user cap on running jobs, 0 = unlimited (default 0)"),
	INT_OPT("max-backoff-seconds", max_backoff_seconds, 1, 86400, "cap of the retry backoff min(2^(attempt-1), cap) (default 60)"),
	INT_OPT("group-commit-max", group_commit_max, 1, 100000, "most write requests in one transaction (default 1024)"),
	INT_OPT("max-job-threads", max_job_threads, 1, 256, "most threads a job may ask for (default 64)"),
	TEXT_OPT("access-log", "FILE", access_log, "append the log's request lines (logfmt) to FILE too (default none)"),
	LONG_OPT("max-log-bytes", max_log_bytes, 65536, 1LL << 50, "log text kept per attempt: its first and last half (default 67108864)"),
	LONG_OPT("user-max-stored-bytes", user_max_stored_bytes, 0, 1LL << 60, "default per-user cap on stored bytes (cases, logs, files), 0 = unlimited (default 2147483648)"),
	TEXT_OPT("tls-listen", "HOST:PORT", tls_listen, "also serve HTTPS on HOST:PORT, for workers and users on other hosts (default none)"),
	TEXT_OPT("tls-cert", "FILE", tls_cert, "PEM certificate (chain) of --tls-listen"),
	TEXT_OPT("tls-key", "FILE", tls_key, "PEM private key of --tls-listen"),
	INT_OPT("allow-plain-http", allow_plain_http, 0, 1, "1: let --listen be an address other than loopback, tokens in clear text (default 0)"),
	INT_OPT("min-free-mb", min_free_mb, 0, 1 << 30, "/healthz is degraded below this free space on the state file system, MiB (default 64)"),
	TEXT_OPT("web-root", "DIR", web_root, "the dashboard's files (default BINDIR/../share/poro/web, else BINDIR/../web)"),
};
#define OPTION_COUNT (sizeof OPTIONS / sizeof OPTIONS[0])

static const struct server_config CONFIG_DEFAULTS = {
	.listen = "127.0.0.1:8080", .state = "./var", .max_connections = 512, .max_worker_connections = 256,
	.max_connections_per_client = 128, .max_waiting_connections = 4096, .header_timeout_seconds = 10,
	.body_timeout_seconds = 60, .max_requests_per_token = 32, .max_requests_per_worker_token = 512,
	.max_concurrent_submissions = 4, .max_body_values = 500000, .max_body_bytes = 4LL << 20,
	.max_upload_bytes = 4LL << 30, .lease_seconds = 30, .max_attempts = 5, .user_max_queued = 10000,
	.user_max_running = 0, .max_backoff_seconds = 60, .group_commit_max = 1024,
	.max_job_threads = 64,
	.max_log_bytes = 64LL << 20, .user_max_stored_bytes = 2LL << 30,
	.min_free_mb = 64,
};

static void usage(void)
{
	printf("usage: poro-server [--config=FILE] [--OPTION=VALUE ...]\n"
	       "       poro-server token create --state=DIR --user=NAME --role=user|worker|admin [--label=TEXT]\n"
	       "       poro-server token list --state=DIR\n"
	       "       poro-server token revoke --state=DIR --id=N\n"
	       "       poro-server backup --state=DIR --out=FILE     (online: the server may run)\n"
	       "       poro-server restore --state=DIR --from=FILE   (with the server stopped)\n\n"
	       "The HTTP job server of PoroMPM (docs/service.md). Every option may also be a line\n"
	       "'name = value' in the config file; options on the command line win over the file.\n"
	       "--opt=VALUE and --opt VALUE are the same.\n\n"
	       "options:\n  --config=FILE                          read options from FILE\n");
	for (size_t i = 0; i < OPTION_COUNT; i++) {
		char flag[64];
		snprintf(flag, sizeof flag, "--%s=%s", OPTIONS[i].name, OPTIONS[i].arg);
		printf("  %-38s %s\n", flag, OPTIONS[i].help);
	}
	printf("  %-38s %s\n  %-38s %s\n\n", "-h, --help", "this text", "--version", "print the version");
	printf("The log (stderr): one logfmt line per request, job state change and message; with the\n"
	       "systemd journal's priority prefix when stderr is the journal. SIGTERM or SIGINT stops the\n"
	       "server cleanly. Exit status: 0 after a signal, 1 when it cannot start, 2 for a bad command\n"
	       "line or configuration.\n");
}

/* Sets option name to value; 0, or -1 with the reason in why. */
static int set_option(struct server_config *cfg, const char *name, const char *value, char *why, size_t why_size)
{
	for (size_t i = 0; i < OPTION_COUNT; i++) {
		const struct option_def *o = &OPTIONS[i];
		if (strcmp(o->name, name) != 0)
			continue;
		char *field = (char *)cfg + o->offset;
		if (o->type == OPT_TEXT) {
			if (strlen(value) >= o->size || !value[0]) {
				snprintf(why, why_size, "value of '%s' is empty or too long", name);
				return -1;
			}
			memcpy(field, value, strlen(value) + 1);
			return 0;
		}
		char *end;
		errno = 0;
		long long v = strtoll(value, &end, 10);
		if (errno || end == value || *end || v < o->min || v > o->max) {
			snprintf(why, why_size, "'%s' must be an integer in %lld..%lld, got '%s'", name, o->min, o->max,
				 value);
			return -1;
		}
		if (o->type == OPT_INT)
			*(int *)(void *)field = (int)v;
		else
			*(long long *)(void *)field = v;
		return 0;
	}
	snprintf(why, why_size, "unknown option '%s'", name);
	return -1;
}

static char *trim(char *s)
{
	while (*s == ' ' || *s == '\t')
		s++;
	size_t n = strlen(s);
	while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\n' || s[n - 1] == '\r'))
		s[--n] = '\0';
	return s;
}

static int read_config(struct server_config *cfg, const char *path)
{
	FILE *f = fopen(path, "r");
	if (!f) {
		log_say(LOG_PRIO_ERR, "cannot open config file '%s': %s", path, strerror(errno));
		return -1;
	}
	char line[8192], where[SERVER_PATH_MAX + 32];
	int number = 0, rc = 0;
	while (rc == 0 && fgets(line, sizeof line, f)) {
		number++;
		char *s = trim(line);
		if (!*s || *s == '#')
			continue;
		char *eq = strchr(s, '=');
		snprintf(where, sizeof where, "%s:%d", path, number);
		if (!eq) {
			log_say(LOG_PRIO_ERR, "%s: expected 'name = value'", where);
			rc = -1;
			break;
		}
		*eq = '\0';
		char why[SERVER_MESSAGE_MAX];
		if ((rc = set_option(cfg, trim(s), trim(eq + 1), why, sizeof why)) != 0)
			log_say(LOG_PRIO_ERR, "%s: %s", where, why);
	}
	fclose(f);
	return rc;
}

/* A bad command line: the message, the hint; -1. */
static int bad_usage(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int bad_usage(const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	fprintf(stderr, "poro-server: ");
	vfprintf(stderr, fmt, ap);
	va_end(ap);
	fprintf(stderr, "\nTry 'poro-server --help' for more information.\n");
	return -1;
}

enum { LONG_CONFIG = 256, LONG_VERSION, LONG_FIRST_OPTION }; /* OPTIONS[i] is LONG_FIRST_OPTION + i */

/* getopt_long's table: every row of OPTIONS, --config, --help, --version. */
static void long_options(struct option *out)
{
	size_t n = 0;
	for (size_t i = 0; i < OPTION_COUNT; i++)
		out[n++] = (struct option){ OPTIONS[i].name, required_argument, NULL, LONG_FIRST_OPTION + (int)i };
	out[n++] = (struct option){ "config", required_argument, NULL, LONG_CONFIG };
	out[n++] = (struct option){ "help", no_argument, NULL, 'h' };
	out[n++] = (struct option){ "version", no_argument, NULL, LONG_VERSION };
	out[n] = (struct option){ NULL, 0, NULL, 0 };
}

/* The config file first (wherever --config appears), then the options over it: two passes of
 * getopt_long, so --opt=value, --opt value and unambiguous abbreviations all work (GNU habits).
 * --help and --version answer at once, exit 0. */
static int parse_args(struct server_config *cfg, int argc, char **argv)
{
	*cfg = CONFIG_DEFAULTS;
	struct option longs[OPTION_COUNT + 4];
	long_options(longs);
	opterr = 0; /* bad_usage says what getopt would, with the hint */
	for (int pass = 0; pass < 2; pass++) {
		optind = 0; /* GNU: start the scan afresh */
		int opt;
		while ((opt = getopt_long(argc, argv, ":h", longs, NULL)) != -1) {
			char why[SERVER_MESSAGE_MAX];
			if (opt == 'h') {
				usage();
				exit(0);
			} else if (opt == LONG_VERSION) {
				printf("poro-server %s\n", PORO_VERSION);
				exit(0);
			} else if (opt == ':') {
				return bad_usage("option '%s' needs a value", argv[optind - 1]);
			} else if (opt == '?') {
				return bad_usage("unknown option '%s'", argv[optind - 1]);
			} else if (opt == LONG_CONFIG) {
				if (pass == 0 && read_config(cfg, optarg) != 0)
					return -1;
			} else if (pass == 1 && set_option(cfg, OPTIONS[opt - LONG_FIRST_OPTION].name, optarg, why,
							   sizeof why) != 0) {
				return bad_usage("%s", why);
			}
		}
	}
	if (optind < argc)
		return bad_usage("unexpected argument '%s'", argv[optind]);
	return 0;
}

/* Makes the state directory, takes its lock (kept in *lock_fd for the life of the process), takes
 * group and other permissions away from what an older run left, and opens the database. */
static int open_state(struct server *srv, int *lock_fd)
{
	const char *state = srv->cfg.state;
	char msg[SERVER_MESSAGE_MAX], files[SERVER_PATH_MAX];
	if (fs_make_dirs(state) != 0 || fs_sync_parents(state, 1) != 0) {
		log_say(LOG_PRIO_ERR, "cannot create state directory '%s': %s", state, strerror(errno));
		return -1;
	}
	if ((*lock_fd = state_dir_lock(state, msg, sizeof msg)) < 0) {
		log_say(LOG_PRIO_ERR, "%s", msg);
		return -1;
	}
	state_dir_restrict(state);
	/* /healthz creates its probe file here, so files/ exists before the first upload */
	snprintf(files, sizeof files, "%s/files", state);
	if (fs_make_dirs(files) != 0 || fs_sync_parents(files, 1) != 0)
		log_say(LOG_PRIO_WARNING, "cannot create '%s': %s", files, strerror(errno));
	if (state_dir_open_store(&srv->cfg, srv, &srv->store, msg, sizeof msg) != 0) {
		log_say(LOG_PRIO_ERR, "%s", msg);
		return -1;
	}
	return 0;
}

/* Writes the URL to STATE/NAME (server.url, server-tls.url) through a temporary file and a rename. */
static int write_url(const char *state, const char *name, const char *url)
{
	char tmp[SERVER_PATH_MAX + 32], path[SERVER_PATH_MAX + 32];
	snprintf(tmp, sizeof tmp, "%s/%s.tmp", state, name);
	snprintf(path, sizeof path, "%s/%s", state, name);
	int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0600);
	if (fd < 0)
		return -1;
	size_t n = strlen(url);
	int ok = write(fd, url, n) == (ssize_t)n && write(fd, "\n", 1) == 1 && fsync(fd) == 0;
	ok = close(fd) == 0 && ok;
	return ok && rename(tmp, path) == 0 ? 0 : -1;
}

/* Each connection costs a descriptor, and the front door holds many waiting ones: take the hard
 * limit on descriptors as the soft one, as servers do (the default soft limit is often 1024). */
static void raise_descriptor_limit(void)
{
	struct rlimit nofile;
	if (getrlimit(RLIMIT_NOFILE, &nofile) == 0 && nofile.rlim_cur < nofile.rlim_max) {
		nofile.rlim_cur = nofile.rlim_max;
		setrlimit(RLIMIT_NOFILE, &nofile);
	}
}

/* Removes what interrupted uploads and interrupted deletions left in STATE/files, before the
 * first request (file_sweep.c); one line says what. */
static void sweep_files(struct server *srv)
{
	struct sweep_counts n;
	if (file_sweep_startup(srv->cfg.state, srv->store, &n) != 0) {
		log_say(LOG_PRIO_WARNING, "cannot sweep '%s/files': %s", srv->cfg.state, strerror(errno));
		return;
	}
	log_say(LOG_PRIO_INFO,
		"start-up sweep of '%s/files': removed temporary upload files: %lld (%lld bytes); "
		"directories of deleted jobs: %lld (%lld bytes); old versions of unfinished replacements put back: %lld, "
		"removed: %lld",
		srv->cfg.state, n.tmp_files, n.tmp_bytes, n.job_dirs, n.job_bytes, n.kept_restored, n.kept_dropped);
}

static int serve(struct server *srv)
{
	raise_descriptor_limit();
	/* glibc gives threads arenas of their own, each reserving 64 MB of address space that it never
	 * gives back; with hundreds of connection threads that is gigabytes reserved and memory kept
	 * after a burst. The server's threads mostly wait on the network and the disk, so two arenas
	 * cost no speed and keep what the server holds close to what it uses. */
	mallopt(M_ARENA_MAX, MALLOC_ARENAS);
	sigset_t signals;
	sigemptyset(&signals);
	sigaddset(&signals, SIGTERM);
	sigaddset(&signals, SIGINT);
	/* Blocked in every thread created from here on; main waits for them with sigwait. */
	pthread_sigmask(SIG_BLOCK, &signals, NULL);
	signal(SIGPIPE, SIG_IGN);
	int lock_fd = -1;
	if (open_state(srv, &lock_fd) != 0) {
		if (lock_fd >= 0)
			close(lock_fd);
		return 1;
	}
	store_set_commit_observer(srv->store, metrics_observe_commit, srv->metrics);
	sweep_files(srv);
	char url[512], msg[SERVER_MESSAGE_MAX];
	void *daemon = http_start(srv, url, sizeof url, msg, sizeof msg);
	if (!daemon) {
		log_say(LOG_PRIO_ERR, "%s", msg);
		store_close(&srv->store);
		close(lock_fd);
		return 1;
	}
	/* server-tls.url first: a script that waits for server.url then finds both */
	const char *tls_url = http_tls_url(daemon);
	if (tls_url[0] && write_url(srv->cfg.state, "server-tls.url", tls_url) != 0)
		log_say(LOG_PRIO_ERR, "cannot write '%s/server-tls.url': %s", srv->cfg.state, strerror(errno));
	if (write_url(srv->cfg.state, "server.url", url) != 0)
		log_say(LOG_PRIO_ERR, "cannot write '%s/server.url': %s", srv->cfg.state, strerror(errno));
	struct reaper *reaper = reaper_start(srv);
	printf("poro-server listening on %s\n", url);
	fflush(stdout);
	if (tls_url[0])
		log_say(LOG_PRIO_NOTICE, "listening on %s and %s (version %s, state directory '%s')", url, tls_url,
			PORO_VERSION, srv->cfg.state);
	else
		log_say(LOG_PRIO_NOTICE, "listening on %s (version %s, state directory '%s')", url, PORO_VERSION,
			srv->cfg.state);

	int sig = 0;
	sigwait(&signals, &sig);
	http_quiesce(daemon);
	pthread_mutex_lock(&srv->wake_lock);
	srv->stopping = 1;
	pthread_cond_broadcast(&srv->claim_cv);
	pthread_cond_broadcast(&srv->log_cv);
	pthread_mutex_unlock(&srv->wake_lock);
	reaper_stop(&reaper);
	http_stop(daemon);          /* waits for in-flight requests, whose writes commit first */
	store_close(&srv->store);   /* drains the writer, checkpoints, closes */
	close(lock_fd);             /* another server may take the state directory from here on */
	log_say(LOG_PRIO_NOTICE, "stopped on signal %d (%s)", sig, strsignal(sig));
	return 0;
}

int main(int argc, char **argv)
{
	umask(077);                 /* see the top of this file and state_dir.c */
	log_setup();
	signal(SIGXFSZ, SIG_IGN);
	if (argc >= 2 && strcmp(argv[1], "token") == 0)
		return token_command(argc, argv, &CONFIG_DEFAULTS);
	if (argc >= 2 && (strcmp(argv[1], "backup") == 0 || strcmp(argv[1], "restore") == 0))
		return backup_command(argc, argv, CONFIG_DEFAULTS.state);
	static struct server srv;
	if (parse_args(&srv.cfg, argc, argv) != 0)
		return 2;
	if (!srv.cfg.web_root[0])
		web_root_default(srv.cfg.web_root, sizeof srv.cfg.web_root);
	pthread_mutex_init(&srv.wake_lock, NULL);
	pthread_cond_init(&srv.claim_cv, NULL);
	pthread_cond_init(&srv.log_cv, NULL);
	srv.metrics = metrics_create();
	srv.access_log_fd = -1;
	if (srv.cfg.access_log[0] &&
	    (srv.access_log_fd = open(srv.cfg.access_log, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644)) < 0) {
		log_say(LOG_PRIO_ERR, "cannot open --access-log '%s': %s", srv.cfg.access_log, strerror(errno));
		return 2;
	}
	log_set_access_fd(srv.access_log_fd);
	if (!srv.metrics) {
		log_say(LOG_PRIO_ERR, "out of memory");
		return 1;
	}
	int rc = serve(&srv);
	metrics_destroy(&srv.metrics);
	if (srv.access_log_fd >= 0)
		close(srv.access_log_fd);
	return rc;
}
