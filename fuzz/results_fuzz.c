/*
 * results_fuzz.c - libFuzzer target: the result-file reader (solver/output/results_read.c) as the
 * worker and users run it: `poro-solve probes` (what the worker extracts for GET .../probes) and
 * `poro-solve report` on the input taken as a result.h5.
 *
 * poro-solve's own main is called in process (cli/poro_solve.c compiled with main renamed), so the
 * commands are exactly those the worker runs. A damaged file must end in an exit status and a
 * message, never a crash, a hang or a leak.
 *
 * Seeds: result.h5 files written by poro-solve (fuzz/run.sh runs tests/fault/tiny_column.json).
 * Inputs are mostly the HDF5 library's own format, which Debian's libhdf5 parses uninstrumented:
 * a crash inside libhdf5 on a damaged file is that library's (the worker runs the extraction in a
 * child process of its own for that reason, docs/service.md §3 "Probes"); fuzz/run.sh tells them
 * apart from crashes in PoroMPM's code by the frames of the stack.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int poro_solve_main(int argc, char **argv);
extern int optind;

static char dir[256];

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	const char *base = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
	snprintf(dir, sizeof dir, "%s/poro-results-fuzz-%d", base, (int)getpid());
	char cmd[300];
	snprintf(cmd, sizeof cmd, "mkdir -p %s", dir);
	if (system(cmd) != 0)
		abort();
	/* poro-solve prints its messages; thousands a second would drown the fuzzer's own lines */
	if (!getenv("FUZZ_VERBOSE") && !freopen("/dev/null", "w", stdout))
		abort();
	return 0;
}

static void run(char **argv, int argc)
{
	optind = 0; /* getopt_long starts afresh at every call */
	poro_solve_main(argc, argv);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	char path[300], out[300], csv[300];
	snprintf(path, sizeof path, "%s/result.h5", dir);
	snprintf(out, sizeof out, "%s/probes.json", dir);
	snprintf(csv, sizeof csv, "%s/report.csv", dir);
	FILE *f = fopen(path, "wb");
	if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0)
		abort();
	char *probes[] = { "poro-solve", "probes", path, "--job", "1", "--attempt", "0", "--out", out, NULL };
	run(probes, 9);
	char *report[] = { "poro-solve", "report", path, "--out", csv, "--line", "0.05,0,0.05,0.5,5", "--line-out",
			   out, NULL };
	run(report, 9);
	unlink(out);
	unlink(csv);
	return 0;
}
