/*
 * probes.c - the `poro-solve probes` child of a job, see probes.h. The child is started with the
 * solver's own launcher (child.c: process group, RLIMIT_AS, one thread) and polled: its output pipe
 * is non-blocking and read as it comes, so a child that writes much cannot block on a full pipe.
 */
#define _GNU_SOURCE
#include "probes.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "child.h"
#include "worker.h"

void probes_init(struct probes_run *p)
{
	memset(p, 0, sizeof *p);
	p->fd = -1;
}

/* Reads what the child wrote so far; the tail beyond PROBES_MESSAGE_MAX is dropped. */
static void read_output(struct probes_run *p)
{
	char buf[4096];
	ssize_t n;
	while (p->fd >= 0 && (n = read(p->fd, buf, sizeof buf)) != 0) {
		if (n < 0) {
			if (errno == EINTR)
				continue;
			return;   /* EAGAIN: nothing more for now */
		}
		size_t room = sizeof p->message - 1 - p->message_len;
		size_t take = (size_t)n < room ? (size_t)n : room;
		memcpy(p->message + p->message_len, buf, take);
		p->message_len += take;
		p->message[p->message_len] = '\0';
	}
}

static void release(struct probes_run *p)
{
	if (p->fd >= 0)
		close(p->fd);
	p->fd = -1;
	p->pid = 0;
}

void probes_stop(struct probes_run *p)
{
	if (p->pid <= 0)
		return;
	child_signal(p->pid, SIGKILL);
	int status;
	while (waitpid(p->pid, &status, 0) < 0 && errno == EINTR)
		;
	release(p);
}

int probes_start(struct probes_run *p, const char *dir, const char *result, long long id, int attempt, char *err,
		 size_t err_size)
{
	probes_stop(p);
	p->message_len = 0;
	p->message[0] = '\0';
	/* what an earlier extraction left must not pass for this one's (probes_poll's callers stage
	 * what is there after a failure too) */
	static const char *const outputs[] = { PROBES_OUT, PROBES_FRAMES_BIN, PROBES_FRAMES_INDEX };
	for (size_t i = 0; i < sizeof outputs / sizeof *outputs; i++) {
		char path[4400];
		snprintf(path, sizeof path, "%s/%s", dir, outputs[i]);
		unlink(path);
	}
	char job[32], attempt_text[32];
	snprintf(job, sizeof job, "%lld", id);
	snprintf(attempt_text, sizeof attempt_text, "%d", attempt);
	char *argv[] = { worker_opt.solver, "probes", (char *)result, "--job", job, "--attempt", attempt_text, "--out",
			 PROBES_OUT, "--frames", PROBES_FRAMES_DIR, NULL };
	struct child_spec spec = { .dir = dir, .argv = argv, .memory_limit_mb = worker_opt.memory_limit_mb, .threads = 1,
				   .secret = worker_opt.token };
	int fd;
	if (child_start(&spec, &p->pid, &fd, err, err_size) < 0) {
		p->pid = 0;
		return -1;
	}
	fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
	p->fd = fd;
	p->started = worker_now();
	return 0;
}

/* The last line of what the child printed, for a one-line reason. */
static const char *last_line(struct probes_run *p)
{
	while (p->message_len && (p->message[p->message_len - 1] == '\n' || p->message[p->message_len - 1] == ' '))
		p->message[--p->message_len] = '\0';
	const char *nl = strrchr(p->message, '\n');
	return nl ? nl + 1 : p->message;
}

enum probes_state probes_poll(struct probes_run *p, double now, char *err, size_t err_size)
{
	if (p->pid <= 0)
		return PROBES_NONE;
	read_output(p);
	int status;
	if (!child_reap(p->pid, &status)) {
		if (now - p->started < PROBES_SECONDS)
			return PROBES_RUNNING;
		probes_stop(p);
		snprintf(err, err_size, "poro-solve probes did not finish within %.0f s and was killed", PROBES_SECONDS);
		return PROBES_FAILED;
	}
	read_output(p);
	release(p);
	if (WIFEXITED(status) && WEXITSTATUS(status) == 0)
		return PROBES_DONE;
	const char *said = last_line(p);
	if (WIFEXITED(status))
		snprintf(err, err_size, "poro-solve probes exited with status %d%s%s", WEXITSTATUS(status),
			 said[0] ? ": " : "", said);
	else
		snprintf(err, err_size, "poro-solve probes was killed by signal %d (%s)", WTERMSIG(status),
			 strsignal(WTERMSIG(status)));
	return PROBES_FAILED;
}
