/*
 * machine.c - the machine description of machine.h. The BLAS is found among the shared objects
 * loaded into the process (dl_iterate_phdr): Debian selects it through the libblas.so.3
 * alternative, so the real path (realpath) names the implementation, e.g.
 * /usr/lib/x86_64-linux-gnu/openblas-openmp/libblas.so.3 for OpenBLAS.
 */
#define _GNU_SOURCE
#include "machine.h"

#include <limits.h>
#include <link.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/utsname.h>
#include <unistd.h>

static void cpu_model(char *out, size_t size, const char *fallback)
{
	FILE *f = fopen("/proc/cpuinfo", "r");
	char line[512];
	snprintf(out, size, "%s", fallback);
	while (f && fgets(line, sizeof line, f)) {
		if (strncmp(line, "model name", 10))
			continue;
		const char *v = strchr(line, ':');
		if (!v)
			continue;
		v += 1 + strspn(v + 1, " \t");
		snprintf(out, size, "%.*s", (int)strcspn(v, "\n"), v);
		break;
	}
	if (f)
		fclose(f);
}

static int blas_of(struct dl_phdr_info *info, size_t size, void *data)
{
	(void)size;
	const char *name = info->dlpi_name, *base = name ? strrchr(name, '/') : NULL;
	base = base ? base + 1 : name;
	if (!base || !(strstr(base, "blas") || strstr(base, "mkl_rt")) || strstr(base, "cblas_") )
		return 0;
	char real[PATH_MAX];
	const char *path = realpath(name, real) ? real : name;
	snprintf(data, 256, "%.255s", path);
	return 1;   /* the first one found: the one the solver's calls resolve to */
}

void machine_describe(struct machine *m)
{
	struct utsname u;
	memset(m, 0, sizeof *m);
	int named = uname(&u) == 0;
	cpu_model(m->cpu_model, sizeof m->cpu_model, named ? u.machine : "unknown");
	cpu_set_t set;
	m->cores = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : (int)sysconf(_SC_NPROCESSORS_ONLN);
	long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
	m->memory_mb = pages > 0 && page > 0 ? (long)((double)pages * (double)page / (1 << 20)) : 0;
	if (named)
		snprintf(m->kernel, sizeof m->kernel, "%.20s %.64s %.32s", u.sysname, u.release, u.machine);
	else
		snprintf(m->kernel, sizeof m->kernel, "unknown");
#if defined(__clang__)
	snprintf(m->compiler, sizeof m->compiler, "clang %d.%d.%d", __clang_major__, __clang_minor__, __clang_patchlevel__);
#elif defined(__GNUC__)
	snprintf(m->compiler, sizeof m->compiler, "gcc %d.%d.%d", __GNUC__, __GNUC_MINOR__, __GNUC_PATCHLEVEL__);
#else
	snprintf(m->compiler, sizeof m->compiler, "unknown");
#endif
	snprintf(m->blas, sizeof m->blas, "none");
	dl_iterate_phdr(blas_of, m->blas);
	if (gethostname(m->host, sizeof m->host - 1) != 0)
		snprintf(m->host, sizeof m->host, "unknown");
}
