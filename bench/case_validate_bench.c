/*
 * case_validate_bench.c - microseconds per item to validate a case (case_load_string, the path of
 * `poro-solve validate`) against the length of its lists: probes of each kind, materials, bodies
 * and loads, at a tenth of the limit and at the limit (case.h). Linear validation shows as the
 * same figure at both sizes; the loader once compared every name with every earlier one, which
 * made the figure grow with the count (5.6 s for 40,000 probes). Printed, never asserted;
 * bench/run.sh runs it.
 *
 * The case is tests/cases/terzaghi.json with one list lengthened by copies of its first item
 * (renamed where names must be unique). Each figure is the best of REPEATS loads of the whole text
 * (parsing included), divided by the number of items.
 */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "case.h"

#define REPEATS 5
#define CASE_FILE "tests/cases/terzaghi.json"

static double now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The first item of a list, for the probe lists one of each kind. */
static json_t *item_of(const char *list, const char *kind)
{
	if (strcmp(list, "probes") != 0)
		return NULL;
	if (strcmp(kind, "pore_pressure") == 0)
		return json_pack("{s:s, s:s, s:[f, f]}", "name", "", "kind", kind, "point", 0.05, 0.5);
	if (strcmp(kind, "displacement") == 0)
		return json_pack("{s:s, s:s, s:[f, f], s:s}", "name", "", "kind", kind, "point", 0.05, 0.5, "component",
				 "y");
	return json_pack("{s:s, s:s, s:s, s:{s:[f, f], s:[f, f]}}", "name", "", "kind", "average", "field",
			 "stress_yy", "box", "min", 0.0, 0.0, "max", 0.1, 0.5);
}

/* The case text with list[] made n items long; NULL when the case cannot be read. */
static char *case_with(const char *list, const char *kind, int n)
{
	json_t *doc = json_load_file(CASE_FILE, 0, NULL);
	json_t *items = json_object_get(doc, list);
	if (!doc || !items) {
		json_decref(doc);
		return NULL;
	}
	json_t *model = item_of(list, kind);
	if (!model)
		model = json_deep_copy(json_array_get(items, 0));
	json_array_clear(items);
	for (int i = 0; i < n; i++) {
		json_t *copy = json_deep_copy(model);
		char name[32];
		snprintf(name, sizeof name, "item%d", i);
		/* the body the load names and the material the body names stay the first */
		if (json_object_get(copy, "name"))
			json_object_set_new(copy, "name", json_string(i == 0 && strcmp(list, "bodies") == 0 ? "column" :
								       i == 0 && strcmp(list, "materials") == 0 ? "soil" :
								       name));
		json_array_append_new(items, copy);
	}
	json_decref(model);
	char *text = json_dumps(doc, JSON_COMPACT);
	json_decref(doc);
	return text;
}

/* Best microseconds per item to load the case with n items; negative when it does not load. */
static double us_per_item(const char *list, const char *kind, int n)
{
	char *text = case_with(list, kind, n);
	double best = -1;
	for (int k = 0; text && k < REPEATS; k++) {
		struct case_spec *c = NULL;
		struct poro_error err = { 0 };
		double t0 = now();
		enum poro_status st = case_load_string(text, &c, &err);
		double t = now() - t0;
		case_destroy(&c);
		if (st != PORO_OK) {
			fprintf(stderr, "case_validate_bench: %s x %d: %s\n", list, n, err.message);
			break;
		}
		if (best < 0 || t < best)
			best = t;
	}
	free(text);
	return best < 0 ? best : 1e6 * best / n;
}

static void row(const char *label, const char *list, const char *kind, int limit)
{
	printf("%-26s %8.2f %8.2f   (%d and %d items)\n", label, us_per_item(list, kind, limit / 10),
	       us_per_item(list, kind, limit), limit / 10, limit);
}

int main(void)
{
	printf("validation, us per item (best of %d), at a tenth of the limit and at the limit:\n", REPEATS);
	printf("%-26s %8s %8s\n", "list", "tenth", "limit");
	row("probes, pore_pressure", "probes", "pore_pressure", CASE_PROBES_MAX);
	row("probes, displacement", "probes", "displacement", CASE_PROBES_MAX);
	row("probes, average", "probes", "average", CASE_PROBES_MAX);
	row("materials", "materials", "", CASE_MATERIALS_MAX);
	row("bodies", "bodies", "", CASE_BODIES_MAX);
	row("loads", "loads", "", CASE_LOADS_MAX);
	return 0;
}
