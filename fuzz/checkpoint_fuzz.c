/*
 * checkpoint_fuzz.c - libFuzzer target: the checkpoint reader (solver/output/checkpoint.c), which
 * a worker runs on the checkpoint.h5 it downloads to resume a job (poro-solve run --resume).
 *
 * Each input is taken as a checkpoint.h5 of tests/fault/tiny_column.json (its path in FUZZ_CASE,
 * set by fuzz/run.sh): the case is loaded once, a simulation is created from it for each input,
 * the checkpoint loaded, and when it loads, two steps are taken, so that a state the loader let in
 * (sizes, indices, per-point values) is also used. A refusal must come with a message; a loaded
 * state must step without a crash (a step may still fail with a message: values the loader cannot
 * judge, such as a negative porosity, are the physics' to refuse).
 *
 * Seeds: checkpoint.h5 files written by poro-solve on that case (fuzz/run.sh).
 */
#include "case.h"
#include "checkpoint.h"
#include "poro.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static struct case_spec *spec;
static char path[300];

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	const char *case_path = getenv("FUZZ_CASE");
	struct poro_error err = { 0 };
	if (!case_path || case_load_file(case_path, &spec, &err) != PORO_OK) {
		fprintf(stderr, "checkpoint_fuzz: set FUZZ_CASE to tests/fault/tiny_column.json: %s\n", err.message);
		exit(2);
	}
	const char *base = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
	snprintf(path, sizeof path, "%s/poro-checkpoint-fuzz-%d.h5", base, (int)getpid());
	return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	FILE *f = fopen(path, "wb");
	if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0)
		abort();
	struct sim *s = NULL;
	struct poro_error err = { 0 };
	if (sim_create(&s, spec, &err) != PORO_OK) {
		fprintf(stderr, "checkpoint_fuzz: the case does not create a simulation: %s\n", err.message);
		abort();
	}
	if (checkpoint_load(s, path) != PORO_OK) {
		if (sim_error(s)->message[0] == '\0')
			abort();
	} else {
		for (int i = 0; i < 2 && !sim_done(s); i++)
			if (sim_step(s) != PORO_OK)
				break;
	}
	sim_destroy(&s);
	unlink(path);
	return 0;
}
