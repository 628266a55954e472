/*
 * child.h - the solver process of one job: started with fork and execve in the job's directory,
 * in its own process group (so a signal reaches every process it may start), with stdout and
 * stderr on one pipe, stdin from /dev/null, RLIMIT_AS from --memory-limit-mb and OMP_NUM_THREADS
 * set to the threads it runs with. It dies with the worker (SIGKILL by PR_SET_PDEATHSIG), so a
 * worker killed with -9 leaves no solver behind, and it inherits no token: PORO_TOKEN and every
 * variable holding the worker's token are left out of its environment. Nothing but
 * async-signal-safe calls runs between fork and exec, since the worker is multi-threaded: argv
 * and the environment are built beforehand.
 */
#ifndef PORO_CHILD_H
#define PORO_CHILD_H

#include <sys/types.h>

/* Exit status of a child whose exec failed; the worker reports it as a failure to start. */
#define CHILD_EXEC_FAILED 127

struct child_spec {
	const char *dir;        /* working directory */
	char *const *argv;      /* argv[0] is the absolute path of the program */
	long memory_limit_mb;   /* RLIMIT_AS, 0: unchanged */
	int threads;            /* OMP_NUM_THREADS */
	const char *note;       /* a line written to the output pipe before exec (the job's log), or NULL */
	const char *secret;     /* environment entries containing this text are dropped, or NULL */
};

/* Starts the child. Returns 0 with its pid (= its process group) and the read end of its output
 * pipe (close-on-exec), or -1 with a message in err. */
int child_start(const struct child_spec *spec, pid_t *pid, int *out_fd, char *err, size_t err_size);

/* Sends sig to the child's whole process group; no-op for pid <= 0. */
void child_signal(pid_t pid, int sig);

/* Reaps the child without blocking: 1 with its wait status when it has ended, 0 while it runs. */
int child_reap(pid_t pid, int *status);

#endif
