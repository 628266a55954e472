/*
 * child.c - fork/exec of the solver with its limits, see child.h. The pipe is created with
 * O_CLOEXEC so that a solver started by another slot never inherits this one's write end (which
 * would keep this job's pipe open after its solver has exited).
 *
 * The solver dies with its worker: right after fork the child asks the kernel for SIGKILL when
 * its parent goes (prctl PR_SET_PDEATHSIG), then checks that the parent has not already gone
 * between fork and prctl (getppid() no longer the pid recorded before fork), and exits if so.
 * Linux sends the death signal when the *thread* that forked exits, not only the process: here
 * that is the slot thread, which runs the job from fork to reaping (job_run) and only then claims
 * the next one, so the signal can come only after the solver has ended, or with the worker's
 * death, which is the point. A worker killed with -9 thus takes its solvers with it; the lease
 * then expires and the job resumes elsewhere from its last uploaded checkpoint.
 */
#define _GNU_SOURCE
#include "child.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

/* Exit status of a child whose worker died before it could exec (nobody reads it). */
#define CHILD_ORPHANED 126

extern char **environ;

/* The solver's threads wait for work passively (sleep) unless the worker's own environment says
 * otherwise. libgomp's default spins between parallel regions, and where solvers share the cores
 * (several slots, or other work on a shared node) the spinning threads take the cores the working
 * ones need: two 2-thread landslides side by side on the 2-core development machine took 3.4 to
 * 4.5 times as long spinning as passive. Alone on its cores a solver is about as fast either way
 * (docs/performance.md, "Threads"). */
static char wait_policy[] = "OMP_WAIT_POLICY=passive";

/* Variables the solver never gets: the worker's token (also dropped wherever else it appears). */
static int withheld(const char *entry, const char *secret)
{
	return !strncmp(entry, "OMP_NUM_THREADS=", 16) || !strncmp(entry, "PORO_TOKEN=", 11) ||
	       (secret && secret[0] && strstr(entry, secret));
}

/* environ without OMP_NUM_THREADS and what withheld() names, plus OMP_NUM_THREADS=threads, plus
 * wait_policy when environ has no OMP_WAIT_POLICY; NULL when out of memory. The strings are
 * environ's own, env_omp and wait_policy. */
static char **child_environment(int threads, const char *secret, char *env_omp, size_t size)
{
	size_t n = 0;
	while (environ[n])
		n++;
	char **env = calloc(n + 3, sizeof *env);
	if (!env)
		return NULL;
	size_t k = 0;
	int has_wait_policy = 0;
	for (size_t i = 0; i < n; i++) {
		if (withheld(environ[i], secret))
			continue;
		has_wait_policy |= !strncmp(environ[i], "OMP_WAIT_POLICY=", 16);
		env[k++] = environ[i];
	}
	snprintf(env_omp, size, "OMP_NUM_THREADS=%d", threads > 0 ? threads : 1);
	env[k++] = env_omp;
	if (!has_wait_policy)
		env[k++] = wait_policy;
	env[k] = NULL;
	return env;
}

int child_start(const struct child_spec *spec, pid_t *pid, int *out_fd, char *err, size_t err_size)
{
	int fds[2];
	char omp[64];
	static const char exec_failed[] = "poro-worker: cannot execute the solver\n";
	if (pipe2(fds, O_CLOEXEC) < 0) {
		snprintf(err, err_size, "cannot create a pipe: %s", strerror(errno));
		return -1;
	}
	char **env = child_environment(spec->threads, spec->secret, omp, sizeof omp);
	if (!env) {
		close(fds[0]);
		close(fds[1]);
		snprintf(err, err_size, "out of memory");
		return -1;
	}
	struct rlimit as = {RLIM_INFINITY, RLIM_INFINITY};
	if (spec->memory_limit_mb > 0)
		as.rlim_cur = as.rlim_max = (rlim_t)spec->memory_limit_mb << 20;
	size_t note_len = spec->note ? strlen(spec->note) : 0;
	pid_t parent = getpid();
	pid_t p = fork();
	if (p < 0) {
		snprintf(err, err_size, "cannot fork: %s", strerror(errno));
		close(fds[0]);
		close(fds[1]);
		free(env);
		return -1;
	}
	if (p == 0) {
		prctl(PR_SET_PDEATHSIG, SIGKILL);
		if (getppid() != parent)
			_exit(CHILD_ORPHANED); /* the worker died before prctl: nobody would supervise the solver */
		sigset_t none;
		sigemptyset(&none);
		sigprocmask(SIG_SETMASK, &none, NULL);
		signal(SIGPIPE, SIG_DFL);
		setpgid(0, 0);
		int in = open("/dev/null", O_RDONLY);
		if (in >= 0)
			dup2(in, 0);
		dup2(fds[1], 1);
		dup2(fds[1], 2);
		if (note_len) {
			ssize_t w = write(1, spec->note, note_len);
			(void)w;
		}
		if (spec->memory_limit_mb > 0)
			setrlimit(RLIMIT_AS, &as);
		if (chdir(spec->dir) == 0)
			execve(spec->argv[0], spec->argv, env);
		ssize_t w = write(2, exec_failed, sizeof exec_failed - 1);
		(void)w;
		_exit(CHILD_EXEC_FAILED);
	}
	/* Also in the parent, so that a signal sent right after fork reaches the group. */
	setpgid(p, p);
	close(fds[1]);
	free(env);
	*pid = p;
	*out_fd = fds[0];
	return 0;
}

void child_signal(pid_t pid, int sig)
{
	if (pid > 0)
		kill(-pid, sig);
}

int child_reap(pid_t pid, int *status)
{
	for (;;) {
		pid_t r = waitpid(pid, status, WNOHANG);
		if (r == pid)
			return 1;
		if (r < 0 && errno == EINTR)
			continue;
		if (r < 0) {
			/* not our child any more (already reaped): report it as killed */
			*status = SIGKILL;
			return 1;
		}
		return 0;
	}
}
