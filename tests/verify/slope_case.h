/*
 * slope_case.h - loads one of the slope cases of 000 §5.3-5.4 (tests/cases/mc_slope_*.json,
 * landslide_*.json) at a reduced or the paper's size, for slope_test.c and landslide_test.c.
 *
 * The changes are made to the case's JSON before it is loaded, not to the loaded spec: the case
 * text is what a run stores in result.h5 (/case), and `poro-solve report` takes the grid and the
 * seeding from it (the columns of the soil-water gap, the crest's window, the tolerance above
 * the ground). A spec changed after loading would leave the paper's h in the stored case.
 */
#ifndef PORO_TEST_SLOPE_CASE_H
#define PORO_TEST_SLOPE_CASE_H

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>

#include "case.h"
#include "poro.h"

/* Sets doc[section][key] = value (value's reference taken), creating the section if missing. */
static inline void slope_case_set(json_t *doc, const char *section, const char *key, json_t *value)
{
	json_t *o = json_object_get(doc, section);
	if (!json_is_object(o))
		json_object_set_new(doc, section, o = json_object());
	json_object_set_new(o, key, value);
}

/* Loads `file` with cell size h and ppc^2 points per cell, dt scaled with h (the case's CFL
 * number), lets adjust() change anything else in the case's JSON, and creates the simulation.
 * Returns 0 and fills *c, *s; on failure prints an INFO line, frees what it made and returns -1. */
static inline int slope_case_create(const char *file, double h, int ppc, void (*adjust)(json_t *, void *),
				    void *user, struct case_spec **c, struct sim **s)
{
	struct poro_error err = {0};
	json_error_t jerr;
	char *text = NULL;
	*c = NULL, *s = NULL;
	json_t *doc = json_load_file(file, 0, &jerr);
	json_t *grid = json_object_get(doc, "grid"), *time = json_object_get(doc, "time");
	json_t *body = json_array_get(json_object_get(doc, "bodies"), 0);
	double h0 = json_number_value(json_object_get(grid, "cell_size"));
	int ok = doc && body && h0 > 0;
	if (ok) {
		double dt = json_number_value(json_object_get(time, "dt"));
		json_object_set_new(time, "dt", json_real(dt * (h / h0)));   /* same CFL number */
		json_object_set_new(grid, "cell_size", json_real(h));
		json_object_set_new(body, "particles_per_cell", json_integer(ppc));
		if (adjust)
			adjust(doc, user);
		text = json_dumps(doc, JSON_INDENT(1));   /* reals round-trip: 17 significant digits */
		ok = text && !case_load_string(text, c, &err) && !sim_create(s, *c, &err);
	}
	if (!ok) {
		printf("INFO cannot run %s: %s\n", file, doc ? err.message : jerr.text);
		sim_destroy(s);
		case_destroy(c);
	}
	free(text);
	json_decref(doc);
	return ok ? 0 : -1;
}

#endif
