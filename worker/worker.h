/*
 * worker.h - what the parts of poro-worker share: its options, the drain and stop flags set by
 * signals, the event printer and the clock. poro-worker claims jobs from poro-server over HTTP,
 * runs each as a poro-solve child process and sends log, progress, files and the outcome back
 * (docs/service.md §2, §3 "Workers", §5). The files: main.c (flags, signals, slot threads),
 * slot.c (the claim loop of one slot), job.c (one running job), child.c (the solver process),
 * log_pump.c (the solver's output), job_files.c (checkpoint download and uploads), probes.c (the
 * probes.json of each uploaded result, by a `poro-solve probes` child), backoff.c (retry delays). The worker keeps no state that matters: losing it loses at most the work since
 * the job's last uploaded checkpoint.
 */
#ifndef PORO_WORKER_H
#define PORO_WORKER_H

#include <stdatomic.h>

/* Grace between SIGTERM and SIGKILL to a solver's process group, seconds. */
#define WORKER_KILL_GRACE 5.0
/* Long-poll length of a claim, seconds (the server allows 0..60). */
#define WORKER_CLAIM_WAIT 20
/* Log chunks go out at most this often while output arrives, seconds: a follower sees a solver
 * line within about this plus the server's wake-up (make bench measures it; the aim is < 0.5 s),
 * and a chatty solver costs the server at most 1 / WORKER_LOG_INTERVAL requests a second. */
#define WORKER_LOG_INTERVAL 0.1
/* Largest log chunk in one request, bytes (the server refuses bodies over 4 MiB). */
#define WORKER_LOG_CHUNK (256 * 1024)
/* Heartbeats go out every lease_seconds / 3, but at least this often, seconds: a cancel is
 * answered on a heartbeat, so the solver gets its SIGTERM within this delay (it stops within a
 * step; SIGKILL follows WORKER_KILL_GRACE later if it does not), well inside the 5 s a cancelled
 * solver may take to disappear. One request a second per running job is nothing for the server. */
#define WORKER_HEARTBEAT_MAX 1.0
/* How long the final log, uploads and finish of a job are retried before the worker gives up,
 * seconds; and the shorter limit after a second SIGTERM. */
#define WORKER_FINISH_PATIENCE 300.0
#define WORKER_STOP_PATIENCE 10.0
/* Default --retire-margin, seconds: time for a checkpoint, its upload and the finish before the
 * allocation ends (a large run's checkpoint may take tens of seconds to write and send). */
#define WORKER_RETIRE_MARGIN 60

/* Default memory limit of a solver: this fraction of physical memory, divided among the slots.
 * The rest is left to the worker, the page cache and whatever else the machine runs; a solver
 * that needs more fails with a clear message instead of pushing the machine into swap or the
 * kernel's OOM killer. */
#define WORKER_MEMORY_SHARE 0.75

struct worker_options {
	char server[1024];       /* base URL */
	char token[512];         /* worker token */
	char ca_file[1024];      /* PEM certificate authorities for an https server, "" for the system's */
	int slots;               /* jobs run at once */
	char work[4096];         /* absolute directory holding job-<id>-<attempt>/ */
	char solver[4096];       /* absolute path of poro-solve */
	long memory_limit_mb;    /* RLIMIT_AS of a solver, 0: none (default: WORKER_MEMORY_SHARE of
				  * physical memory divided by the slots); claims state it (slot.c) */
	long checkpoint_wall;    /* seconds of wall time between checkpoints given to the solver, 0: none */
	const char *checkpoint_flag; /* the solver's option for it, NULL when the solver has none */
	double lease_renew;      /* heartbeat interval override, seconds, 0: from the lease */
	int keep_work;           /* 1: keep each job's directory after it ends (--keep-work yes) */
	char name[256];          /* "host:pid" unless --name */
	char host[256];
	int thread_budget;       /* --threads: hardware threads of the whole worker (default: online CPUs) */
	int threads;             /* threads each slot offers in its claims and gives a solver at most:
				  * max(1, thread_budget / slots) */
	char solver_version[128];
	double end_at;           /* worker_now() at which the allocation ends (--lifetime), 0: never */
	long retire_margin;      /* seconds before end_at at which running jobs are handed back */
	long idle_exit;          /* a slot that has had no job this many seconds ends, 0: never */
};

extern struct worker_options worker_opt;
extern atomic_int worker_draining; /* first SIGTERM: claim nothing more (aborts a long-poll) */
extern atomic_int worker_stopping; /* second SIGTERM: stop the solvers, report infrastructure */
extern atomic_int worker_fatal;    /* the server refused the worker's token: exit 1 */

/* Prints one event line "poro-worker: ..." with a UTC time stamp to stdout (thread-safe). */
void worker_say(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* Monotonic seconds. */
double worker_now(void);

/* Sleeps for seconds, in short steps, returning early when worker_stopping is set, or when
 * worker_draining is set and wake_on_drain is non-zero. */
void worker_sleep(double seconds, int wake_on_drain);

/* With --lifetime: 1 once fewer than fraction * retire_margin seconds are left of the allocation
 * (1.0: time to hand running jobs back and claim no more). 0 without a lifetime. */
int worker_retire_due(double now, double fraction);
/* Seconds of the allocation a new job may still use (until end_at - retire_margin), at least 0;
 * -1 without --lifetime. */
long worker_seconds_left(double now);

/* The claim loop of one slot; arg is the slot's index cast to a pointer. */
void *slot_main(void *arg);

/* Exclusive jobs (slot.c; docs/benchmarks.md "Exclusive jobs"): 1 when a claimed job may start
 * its solver now, and then it counts as running: an exclusive job when no other job runs, any
 * other job when no exclusive job runs or waits. slot_finished(exclusive) when it has ended. */
int slot_try_start(int exclusive);
void slot_finished(int exclusive);

#endif
