/*
 * jobs_element.c - submissions of single-element tests ("schema": "poro-element/1",
 * docs/element.md). The worker runs every job with `poro-solve run`, which takes an element case
 * as `poro-solve element` does and writes the result.h5 a success needs, so the server only has to
 * accept one: jobs_case_load() checks a submitted case with the loader its schema names.
 *
 * An element case is checked by the solver's element loader, on the text of the parsed tree; the
 * submission keeps no more of a checked case than its canonical text (and its warnings), so a
 * struct case_spec holding just those stands for it and goes through the same path as any case.
 */
#include "jobs_submit.h"

#include <stdlib.h>
#include <string.h>

#include "case.h"
#include "element.h"

/* 1 when the case's "schema" is the element schema. */
static int is_element(const json_t *case_spec)
{
	const char *schema = json_string_value(json_object_get(case_spec, "schema"));
	return schema && !strcmp(schema, ELEMENT_SCHEMA_VERSION);
}

enum poro_status jobs_case_load(const json_t *case_spec, struct case_spec **loaded, struct poro_error *err)
{
	*loaded = NULL;
	if (!is_element(case_spec))
		return case_load_json(case_spec, loaded, err);
	struct element_case *e = malloc(sizeof *e);
	char *text = json_dumps(case_spec, JSON_COMPACT);
	struct case_spec *c = calloc(1, sizeof *c);
	enum poro_status st = e && text && c ? element_case_load_string(text, e, err)
					     : poro_error_set(err, PORO_ENOMEM, "out of memory checking an element case");
	if (!st && !(c->json = json_dumps(case_spec, JSON_COMPACT | JSON_SORT_KEYS)))
		st = poro_error_set(err, PORO_ENOMEM, "out of memory checking an element case");
	if (!st) {
		memcpy(c->warnings, e->warnings, sizeof c->warnings);
		*loaded = c;
	} else {
		case_destroy(&c);
	}
	free(text);
	free(e);
	return st;
}
