/*
 * main.c - poro-worker's command line, signals and slot threads.
 *
 *   poro-worker --server URL --token-file FILE [--slots N (1)] [--threads N (online CPUs)]
 *               [--work DIR (./var/work)] [--solver PATH] [--memory-limit-mb N]
 *               [--checkpoint-wall SECONDS (60)] [--lease-renew SECONDS] [--name NAME]
 *               [--keep-work yes|no (no)] [--help] [--version]
 *
 * Options are parsed by getopt_long, so GNU habits hold: --opt=value or --opt value, unambiguous
 * abbreviations, "--" ends the options. --help prints the help text on stdout and exits 0;
 * a bad command line says what is wrong and exits 2.
 *
 * The token comes from --token-file, else PORO_TOKEN, else the config file read by the CLI; the
 * URL from --server, else PORO_SERVER. --token TOKEN still works but puts the token in every
 * user's process list: the worker says so and overwrites its copy in argv at once, which shortens
 * the exposure but cannot undo it. A token file readable by group or others is refused, as ssh
 * refuses such a private key: a file anyone can read leaks the token as surely as argv does, and
 * refusing says how to fix it where a warning would scroll by. PORO_TOKEN is removed from the
 * environment once read, so no child (the solver, the probes of its version) inherits it.
 *
 * --threads is the worker's thread budget: each slot offers max(1, N / slots) threads in its
 * claims and runs a solver with at most that many (job.c). --memory-limit-mb defaults to
 * WORKER_MEMORY_SHARE of physical memory divided by the slots; 0 (asked for) means no limit. Both
 * appear in the worker's start line.
 *
 * The solver defaults to poro-solve next to this binary, else the first on PATH. SIGTERM or
 * SIGINT drains: no new claims, running jobs finish, exit 0. A second one stops the solvers (their
 * jobs are reported as infrastructure failures and re-queued) and the worker exits. The signals
 * are blocked in every thread and taken synchronously here with sigtimedwait, so no handler runs
 * inside library code. Exit status: 0 after a drain, 1 when the server refused the token, 2 for a
 * bad command line.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "client_config.h"
#include "http_client.h"
#include "worker.h"
#include "fs.h"

struct worker_options worker_opt;
atomic_int worker_draining;
atomic_int worker_stopping;
atomic_int worker_fatal;
static atomic_int slots_running;
static pthread_mutex_t say_lock = PTHREAD_MUTEX_INITIALIZER;

void worker_say(const char *fmt, ...)
{
	char stamp[32];
	struct timespec ts;
	struct tm tm;
	clock_gettime(CLOCK_REALTIME, &ts);
	gmtime_r(&ts.tv_sec, &tm);
	strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", &tm);
	va_list ap;
	va_start(ap, fmt);
	pthread_mutex_lock(&say_lock);
	printf("%s.%03ldZ poro-worker: ", stamp, ts.tv_nsec / 1000000);
	vprintf(fmt, ap);
	putchar('\n');
	fflush(stdout);
	pthread_mutex_unlock(&say_lock);
	va_end(ap);
}

double worker_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int worker_retire_due(double now, double fraction)
{
	return worker_opt.end_at > 0 && now >= worker_opt.end_at - fraction * (double)worker_opt.retire_margin;
}

long worker_seconds_left(double now)
{
	if (worker_opt.end_at <= 0)
		return -1;
	double left = worker_opt.end_at - (double)worker_opt.retire_margin - now;
	return left > 0 ? (long)left : 0;
}

void worker_sleep(double seconds, int wake_on_drain)
{
	double end = worker_now() + seconds;
	while (worker_now() < end && !atomic_load(&worker_stopping) && !(wake_on_drain && atomic_load(&worker_draining)))
		usleep(20000);
}

#define TOKEN_FILE_MAX 4096      /* bytes read of a token file: a token and a newline */
#define THREADS_MAX 4096
#define MEMORY_DEFAULT (-1L)     /* memory_limit_mb before the default is computed */

/* The options, in the order --help lists them: getopt_long's table and the help text. */
enum {
	OPT_SERVER = 256,
	OPT_TOKEN,
	OPT_TOKEN_FILE,
	OPT_SLOTS,
	OPT_THREADS,
	OPT_WORK,
	OPT_SOLVER,
	OPT_MEMORY,
	OPT_CHECKPOINT_WALL,
	OPT_LEASE_RENEW,
	OPT_NAME,
	OPT_KEEP_WORK,
	OPT_CA_FILE,
	OPT_ALLOW_PLAIN_HTTP,
	OPT_LIFETIME,
	OPT_RETIRE_MARGIN,
	OPT_IDLE_EXIT,
	OPT_VERSION
};
static const struct option OPTIONS[] = {
	{ "server", required_argument, NULL, OPT_SERVER },
	{ "token-file", required_argument, NULL, OPT_TOKEN_FILE },
	{ "token", required_argument, NULL, OPT_TOKEN },
	{ "slots", required_argument, NULL, OPT_SLOTS },
	{ "threads", required_argument, NULL, OPT_THREADS },
	{ "work", required_argument, NULL, OPT_WORK },
	{ "solver", required_argument, NULL, OPT_SOLVER },
	{ "memory-limit-mb", required_argument, NULL, OPT_MEMORY },
	{ "checkpoint-wall", required_argument, NULL, OPT_CHECKPOINT_WALL },
	{ "lease-renew", required_argument, NULL, OPT_LEASE_RENEW },
	{ "name", required_argument, NULL, OPT_NAME },
	{ "keep-work", required_argument, NULL, OPT_KEEP_WORK },
	{ "ca-file", required_argument, NULL, OPT_CA_FILE },
	{ "allow-plain-http", no_argument, NULL, OPT_ALLOW_PLAIN_HTTP },
	{ "lifetime", required_argument, NULL, OPT_LIFETIME },
	{ "retire-margin", required_argument, NULL, OPT_RETIRE_MARGIN },
	{ "idle-exit", required_argument, NULL, OPT_IDLE_EXIT },
	{ "help", no_argument, NULL, 'h' },
	{ "version", no_argument, NULL, OPT_VERSION },
	{ NULL, 0, NULL, 0 },
};

static void help(void)
{
	printf("usage: poro-worker --server=URL --token-file=FILE [OPTION...]\n\n"
	       "Claims PoroMPM jobs from poro-server over HTTP, runs each with poro-solve in a directory of\n"
	       "its own and sends its log, progress, files and outcome back (docs/service.md).\n\n"
	       "options (--opt=VALUE or --opt VALUE):\n"
	       "  --server=URL             the server (default: $PORO_SERVER, else the poro CLI's config file)\n"
	       "  --token-file=FILE        the worker token, first line of FILE, which must be private to its\n"
	       "                           owner (chmod 600); default: $PORO_TOKEN, else the config file\n"
	       "  --token=TOKEN            the token itself: shown to every user in the process list; avoid\n"
	       "  --slots=N                jobs run at once (default 1)\n"
	       "  --threads=N              threads of the whole worker, shared among the slots (default: online CPUs)\n"
	       "  --work=DIR               job directories go under DIR (default ./var/work)\n"
	       "  --solver=PATH            poro-solve to run (default: the one beside this program, else PATH)\n"
	       "  --memory-limit-mb=N      address space of one solver, MB; 0 = none (default: 3/4 of physical\n"
	       "                           memory divided by the slots)\n"
	       "  --checkpoint-wall=S      a checkpoint every S seconds of wall time; 0 = none (default 60)\n"
	       "  --lease-renew=S          heartbeat every S seconds (default: a third of the lease, at most 1 s)\n"
	       "  --name=NAME              the worker's id in claims, heartbeats and metrics (default HOST:PID)\n"
	       "  --keep-work=yes|no       keep each job's directory after the job (default no)\n"
	       "  --ca-file=FILE           PEM certificate authorities to verify an https server against\n"
	       "                           (default: $PORO_CA_FILE, else the system's)\n"
	       "  --allow-plain-http       allow an http:// server that is not on loopback: the token crosses\n"
	       "                           the network in clear text (default: refused)\n"
	       "  --lifetime=S             the worker's allocation ends S seconds from its start (a Slurm\n"
	       "                           pilot's time limit): it claims only jobs whose wall time fits\n"
	       "                           what is left, and hands running jobs back with a checkpoint\n"
	       "                           --retire-margin seconds before the end (default: no end)\n"
	       "  --retire-margin=S        (default 60)\n"
	       "  --idle-exit=S            exit after S seconds without a job; 0 = never (default 0)\n"
	       "  -h, --help               this text\n"
	       "  --version                print the version\n\n"
	       "SIGTERM or SIGINT drains (no new jobs; running ones finish); a second one stops the solvers and\n"
	       "hands their jobs back. Exit status: 0 after a drain, 1 when the server refused the token,\n"
	       "2 for a bad command line.\n");
}

/* A bad command line: the message, the hint, status 2. */
static int bad_usage(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int bad_usage(const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	fprintf(stderr, "poro-worker: ");
	vfprintf(stderr, fmt, ap);
	va_end(ap);
	fprintf(stderr, "\nTry 'poro-worker --help' for more information.\n");
	return 2;
}

/* Reads the token from the first line of path into out; refuses a file others may read. */
static int read_token_file(const char *path, char *out, size_t size)
{
	FILE *f = fopen(path, "r");
	struct stat st;
	if (!f || fstat(fileno(f), &st) != 0) {
		fprintf(stderr, "poro-worker: cannot read token file '%s': %s\n", path, strerror(errno));
		if (f)
			fclose(f);
		return -1;
	}
	if (!S_ISREG(st.st_mode) || (st.st_mode & 077)) {
		fprintf(stderr, "poro-worker: token file '%s' is %s (mode %04o): make it private to its owner "
				"(chmod 600 '%s')\n", path, S_ISREG(st.st_mode) ? "readable by group or others" : "not a regular file",
			(unsigned)(st.st_mode & 07777), path);
		fclose(f);
		return -1;
	}
	char line[TOKEN_FILE_MAX];
	int ok = fgets(line, sizeof line, f) != NULL;
	fclose(f);
	line[ok ? strcspn(line, "\r\n") : 0] = '\0';
	if (!line[0] || strlen(line) >= size) {
		fprintf(stderr, "poro-worker: token file '%s' has no token on its first line\n", path);
		return -1;
	}
	snprintf(out, size, "%s", line);
	return 0;
}

/* The default memory limit of one solver, MB: WORKER_MEMORY_SHARE of physical memory over the
 * slots, or 0 in an AddressSanitizer build, whose shadow memory reserves terabytes of address
 * space that no RLIMIT_AS could allow (the sanitizer tests run such a solver). */
static long default_memory_limit_mb(long physical_mb)
{
#ifdef __SANITIZE_ADDRESS__
	return 0;
#else
	long share = (long)(WORKER_MEMORY_SHARE * (double)physical_mb / worker_opt.slots);
	return share > 0 ? share : 0;
#endif
}

static long physical_mb;          /* physical memory, MB, when the memory limit is the default */
static int memory_defaulted;      /* 1: memory_limit_mb is the default, not --memory-limit-mb */

static int parse_long(const char *s, long lo, long hi, long *out)
{
	char *end;
	errno = 0;
	long v = strtol(s, &end, 10);
	if (errno || *end || end == s || v < lo || v > hi)
		return -1;
	*out = v;
	return 0;
}

/* An absolute version of path (which need not exist yet). */
static void absolute(const char *path, char *out, size_t size)
{
	char cwd[PATH_MAX];
	if (path[0] == '/' || !getcwd(cwd, sizeof cwd))
		snprintf(out, size, "%s", path);
	else
		if (snprintf(out, size, "%s/%s", cwd, path) >= (int)size)
			snprintf(out, size, "%s", path);
}

/* --solver, else poro-solve next to this binary, else the first poro-solve on PATH. */
static int find_solver(const char *given, char *out, size_t size)
{
	if (given) {
		absolute(given, out, size);
		return access(out, X_OK);
	}
	char self[PATH_MAX];
	ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
	if (n > 0) {
		self[n] = '\0';
		char *slash = strrchr(self, '/');
		if (slash) {
			*slash = '\0';
			if (snprintf(out, size, "%s/poro-solve", self) < (int)size && access(out, X_OK) == 0)
				return 0;
		}
	}
	const char *path = getenv("PATH");
	char *copy = strdup(path ? path : "/usr/local/bin:/usr/bin:/bin");
	int rc = -1;
	for (char *save = NULL, *dir = strtok_r(copy, ":", &save); dir && rc; dir = strtok_r(NULL, ":", &save)) {
		if (snprintf(out, size, "%s/poro-solve", *dir ? dir : ".") < (int)size && access(out, X_OK) == 0) {
			char tmp[PATH_MAX];
			absolute(out, tmp, sizeof tmp);
			snprintf(out, size, "%s", tmp);
			rc = 0;
		}
	}
	free(copy);
	return rc;
}

/* Asks the solver its version, and which option (if any) takes a wall-time checkpoint interval:
 * its usage text names it. The current poro-solve knows "--checkpoint-wall"; "--checkpoint-every"
 * is accepted as the older spelling. */
static void probe_solver(void)
{
	char cmd[PATH_MAX + 32], line[512];
	snprintf(worker_opt.solver_version, sizeof worker_opt.solver_version, "unknown");
	snprintf(cmd, sizeof cmd, "'%s' version 2>/dev/null", worker_opt.solver);
	FILE *p = popen(cmd, "r");
	if (p) {
		if (fgets(line, sizeof line, p)) {
			line[strcspn(line, "\n")] = '\0';
			const char *v = strncmp(line, "poro-solve ", 11) ? line : line + 11;
			snprintf(worker_opt.solver_version, sizeof worker_opt.solver_version, "%.100s", v);
		}
		pclose(p);
	}
	snprintf(cmd, sizeof cmd, "'%s' 2>&1", worker_opt.solver);
	p = popen(cmd, "r");
	if (!p)
		return;
	while (fgets(line, sizeof line, p)) {
		if (strstr(line, "--checkpoint-wall"))
			worker_opt.checkpoint_flag = "--checkpoint-wall";
		else if (!worker_opt.checkpoint_flag && strstr(line, "--checkpoint-every"))
			worker_opt.checkpoint_flag = "--checkpoint-every";
	}
	pclose(p);
}

/* An integer option's value in lo..hi into *out: 0, or 2 after saying what is wrong. */
static int int_option(const char *name, const char *value, long lo, long hi, long *out)
{
	if (parse_long(value, lo, hi, out) == 0)
		return 0;
	return bad_usage("--%s must be an integer in %ld..%ld, got '%s'", name, lo, hi, value);
}

static int parse_flags(int argc, char **argv)
{
	const char *solver = NULL, *work = "var/work", *name = NULL, *token_file = NULL, *ca_file = NULL;
	int allow_plain = 0;
	long lifetime = 0;
	worker_opt.retire_margin = WORKER_RETIRE_MARGIN;
	long v, budget = 0;
	int rc = 0, opt, index = 0;
	worker_opt.slots = 1;
	worker_opt.checkpoint_wall = 60;
	worker_opt.memory_limit_mb = MEMORY_DEFAULT;
	opterr = 0; /* getopt's own messages lack the hint; bad_usage says it all */
	while (rc == 0 && (opt = getopt_long(argc, argv, ":h", OPTIONS, &index)) != -1) {
		const char *o = OPTIONS[index].name;
		switch (opt) {
		case OPT_SERVER: snprintf(worker_opt.server, sizeof worker_opt.server, "%s", optarg); break;
		case OPT_TOKEN:
			snprintf(worker_opt.token, sizeof worker_opt.token, "%s", optarg);
			memset(optarg, 'x', strlen(optarg)); /* out of /proc/PID/cmdline from now on */
			fprintf(stderr, "poro-worker: warning: --token shows the token to every user of this machine "
					"in the process list; use --token-file FILE or PORO_TOKEN\n");
			break;
		case OPT_TOKEN_FILE: token_file = optarg; break;
		case OPT_SLOTS:
			if ((rc = int_option(o, optarg, 1, 1024, &v)) == 0)
				worker_opt.slots = (int)v;
			break;
		case OPT_THREADS: rc = int_option(o, optarg, 1, THREADS_MAX, &budget); break;
		case OPT_WORK: work = optarg; break;
		case OPT_SOLVER: solver = optarg; break;
		case OPT_MEMORY: rc = int_option(o, optarg, 0, 1L << 30, &worker_opt.memory_limit_mb); break;
		case OPT_CHECKPOINT_WALL: rc = int_option(o, optarg, 0, 1L << 30, &worker_opt.checkpoint_wall); break;
		case OPT_LEASE_RENEW:
			if ((rc = int_option(o, optarg, 1, 86400, &v)) == 0)
				worker_opt.lease_renew = (double)v;
			break;
		case OPT_NAME: name = optarg; break;
		case OPT_KEEP_WORK:
			if (strcmp(optarg, "yes") && strcmp(optarg, "no"))
				rc = bad_usage("--keep-work must be yes or no, got '%s'", optarg);
			worker_opt.keep_work = !strcmp(optarg, "yes");
			break;
		case OPT_CA_FILE: ca_file = optarg; break;
		case OPT_ALLOW_PLAIN_HTTP: allow_plain = 1; break;
		case OPT_LIFETIME: rc = int_option(o, optarg, 1, 1L << 30, &lifetime); break;
		case OPT_RETIRE_MARGIN: rc = int_option(o, optarg, 1, 1L << 30, &worker_opt.retire_margin); break;
		case OPT_IDLE_EXIT: rc = int_option(o, optarg, 0, 1L << 30, &worker_opt.idle_exit); break;
		case 'h': help(); exit(0);
		case OPT_VERSION: printf("poro-worker %s\n", PORO_VERSION); exit(0);
		case ':': rc = bad_usage("option '%s' needs a value", argv[optind - 1]); break;
		default: rc = bad_usage("unknown option '%s'", argv[optind - 1]); break;
		}
	}
	if (rc)
		return rc;
	if (lifetime > 0 && lifetime <= worker_opt.retire_margin)
		return bad_usage("--lifetime (%ld s) must be longer than --retire-margin (%ld s)", lifetime,
				 worker_opt.retire_margin);
	if (lifetime > 0)
		worker_opt.end_at = worker_now() + (double)lifetime;
	if (optind < argc)
		return bad_usage("unexpected argument '%s'", argv[optind]);
	if (token_file && worker_opt.token[0]) {
		fprintf(stderr, "poro-worker: give either --token or --token-file, not both\n");
		return 2;
	}
	if (token_file && read_token_file(token_file, worker_opt.token, sizeof worker_opt.token) != 0)
		return 2;
	char err[1200] = "";
	struct client_config cfg = { .allow_plain_http = allow_plain };
	snprintf(cfg.ca_file, sizeof cfg.ca_file, "%s", ca_file ? ca_file : "");
	snprintf(cfg.server, sizeof cfg.server, "%s", worker_opt.server);
	snprintf(cfg.token, sizeof cfg.token, "%s", worker_opt.token);
	if (client_config_load(&cfg, err, sizeof err) < 0) {
		fprintf(stderr, "poro-worker: %s\n", err);
		return 2;
	}
	snprintf(worker_opt.server, sizeof worker_opt.server, "%s", cfg.server);
	snprintf(worker_opt.token, sizeof worker_opt.token, "%s", cfg.token);
	unsetenv("PORO_TOKEN"); /* read: no child inherits it (child.c also strips it) */
	if (!worker_opt.server[0] || !worker_opt.token[0]) {
		fprintf(stderr, "poro-worker: no server URL or token (--server/--token, PORO_SERVER/PORO_TOKEN)\n");
		return 2;
	}
	if (client_config_check_server(&cfg, err, sizeof err) != 0) {
		fprintf(stderr, "poro-worker: %s\n", err);
		return 2;
	}
	snprintf(worker_opt.ca_file, sizeof worker_opt.ca_file, "%s", cfg.ca_file);
	if (find_solver(solver, worker_opt.solver, sizeof worker_opt.solver) < 0) {
		fprintf(stderr, "poro-worker: cannot find an executable poro-solve%s%s\n", solver ? " at " : "",
			solver ? solver : "");
		return 2;
	}
	absolute(work, worker_opt.work, sizeof worker_opt.work);
	gethostname(worker_opt.host, sizeof worker_opt.host - 1);
	if (name)
		snprintf(worker_opt.name, sizeof worker_opt.name, "%s", name);
	else
		snprintf(worker_opt.name, sizeof worker_opt.name, "%.200s:%d", worker_opt.host, (int)getpid());
	long cpus = sysconf(_SC_NPROCESSORS_ONLN);
	worker_opt.thread_budget = budget > 0 ? (int)budget : cpus > 0 ? (int)cpus : 1;
	worker_opt.threads = worker_opt.thread_budget / worker_opt.slots;
	if (worker_opt.threads < 1)
		worker_opt.threads = 1;
	if (worker_opt.memory_limit_mb == MEMORY_DEFAULT) {
		long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
		physical_mb = pages > 0 && page > 0 ? (long)((double)pages * (double)page / (1 << 20)) : 0;
		worker_opt.memory_limit_mb = default_memory_limit_mb(physical_mb);
		memory_defaulted = 1;
	}
	return 0;
}

/* "memory limit N MB per solver (how it was chosen)" for the start line. */
static void describe_memory(char *out, size_t size)
{
	if (memory_defaulted) {
		if (worker_opt.memory_limit_mb > 0)
			snprintf(out, size, "memory limit %ld MB per solver (default: %.0f%% of %ld MB physical / %d slot%s)",
				 worker_opt.memory_limit_mb, 100 * WORKER_MEMORY_SHARE, physical_mb, worker_opt.slots,
				 worker_opt.slots == 1 ? "" : "s");
		else
			snprintf(out, size, "no memory limit (default of this build: AddressSanitizer needs the address space)");
	} else if (worker_opt.memory_limit_mb > 0) {
		snprintf(out, size, "memory limit %ld MB per solver (--memory-limit-mb)", worker_opt.memory_limit_mb);
	} else {
		snprintf(out, size, "no memory limit (--memory-limit-mb 0)");
	}
}

static void *slot_thread(void *arg)
{
	slot_main(arg);
	atomic_fetch_sub(&slots_running, 1);
	return NULL;
}

int main(int argc, char **argv)
{
	int rc = parse_flags(argc, argv);
	if (rc)
		return rc;
	if (fs_make_dirs(worker_opt.work) < 0) {
		fprintf(stderr, "poro-worker: cannot create '%s': %s\n", worker_opt.work, strerror(errno));
		return 2;
	}
	probe_solver();
	if (http_global_init() < 0) {
		fprintf(stderr, "poro-worker: cannot initialise libcurl\n");
		return 1;
	}
	http_global_ca_file(worker_opt.ca_file);
	signal(SIGPIPE, SIG_IGN);
	sigset_t set;
	sigemptyset(&set);
	sigaddset(&set, SIGTERM);
	sigaddset(&set, SIGINT);
	pthread_sigmask(SIG_BLOCK, &set, NULL);
	char memory[256];
	describe_memory(memory, sizeof memory);
	worker_say("%s serving %s with %d slot%s of %d thread%s (--threads %d), %s, solver %s (%s), work %s",
		   worker_opt.name, worker_opt.server, worker_opt.slots, worker_opt.slots == 1 ? "" : "s",
		   worker_opt.threads, worker_opt.threads == 1 ? "" : "s", worker_opt.thread_budget, memory,
		   worker_opt.solver, worker_opt.solver_version, worker_opt.work);
	pthread_t *threads = calloc((size_t)worker_opt.slots, sizeof *threads);
	int started = 0;
	for (int i = 0; threads && i < worker_opt.slots; i++) {
		atomic_fetch_add(&slots_running, 1);
		if (pthread_create(&threads[i], NULL, slot_thread, (void *)(size_t)i)) {
			atomic_fetch_sub(&slots_running, 1);
			break;
		}
		started++;
	}
	int terms = 0;
	struct timespec tick = {0, 200000000};
	while (atomic_load(&slots_running) > 0) {
		int sig = sigtimedwait(&set, NULL, &tick);
		if (sig != SIGTERM && sig != SIGINT)
			continue;
		if (++terms == 1) {
			worker_say("draining: no new jobs, running jobs finish (signal again to stop them)");
			atomic_store(&worker_draining, 1);
		} else {
			worker_say("stopping: terminating running solvers");
			atomic_store(&worker_stopping, 1);
		}
	}
	for (int i = 0; i < started; i++)
		pthread_join(threads[i], NULL);
	free(threads);
	http_global_cleanup();
	worker_say("exiting");
	return atomic_load(&worker_fatal) ? 1 : 0;
}
