/*
 * slope_case.h - loads one of the slope cases of 000 §5.3-5.4 (tests/cases/mc_slope_*.json,
 * landslide_*.json) at a reduced or the paper's size, for slope_test.c and landslide_test.c.
 */
#ifndef PORO_TEST_SLOPE_CASE_H
#define PORO_TEST_SLOPE_CASE_H

#include <stdio.h>

#include "case.h"
#include "poro.h"

/* Loads `file` with cell size h and ppc^2 points per cell, dt scaled with h (the case's CFL
 * number), lets adjust() change anything else, and creates the simulation. Returns 0 and fills
 * *c, *s; on failure prints an INFO line, frees what it made and returns -1. */
static inline int slope_case_create(const char *file, double h, int ppc, void (*adjust)(struct case_spec *, void *),
				    void *user, struct case_spec **c, struct sim **s)
{
	struct poro_error err = {0};
	*c = NULL, *s = NULL;
	int ok = !case_load_file(file, c, &err);
	if (ok) {
		(*c)->time.dt *= h / (*c)->grid.cell_size;   /* same CFL number */
		(*c)->grid.cell_size = h;
		(*c)->bodies[0].particles_per_cell = ppc;
		if (adjust)
			adjust(*c, user);
		ok = !sim_create(s, *c, &err);
	}
	if (!ok) {
		printf("INFO cannot run %s: %s\n", file, err.message);
		case_destroy(c);
		return -1;
	}
	return 0;
}

#endif
