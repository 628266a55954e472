/*
 * machine.h - the machine a run's timings belong to, as the process that measured them sees it:
 * the processor, the processors this process may run on, the memory, the kernel, and how the
 * solver was built (compiler) and which BLAS it loaded. Written into metrics.json and result.h5's
 * /metrics (metrics.h); the job service derives the machine fingerprint from these fields (all but
 * the host name: two identical machines compare, docs/benchmarks.md "Machines"), so timings are
 * only ever compared with timings of the same kind of machine and build.
 */
#ifndef PORO_MACHINE_H
#define PORO_MACHINE_H

struct machine {
	char cpu_model[128];    /* /proc/cpuinfo "model name", else uname's machine */
	int cores;              /* processors this process may run on (sched_getaffinity), which a
				   taskset or a cgroup's cpuset narrows */
	long memory_mb;         /* physical memory, MiB */
	char kernel[128];       /* "Linux 6.1.0-18-amd64 x86_64" (uname) */
	char compiler[128];     /* the compiler the solver was built with ("gcc 12.2.0") */
	char blas[256];         /* the BLAS library loaded, by its real path, or "none" */
	char host[128];         /* host name; not part of the fingerprint */
};

/* Fills m for this process; what cannot be read is "unknown" (or 0). */
void machine_describe(struct machine *m);

#endif
