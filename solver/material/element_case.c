/*
 * element_case.c - loads a single-element case (element.h) from JSON, with the case loader's
 * typed reads (case_json.h) and material keys (case_material.h): every problem is one line
 * "JSON-pointer: message", and unknown keys are refused.
 */
#include <stdlib.h>
#include <string.h>

#include "case_json.h"
#include "case_metrics.h"
#include "case_material.h"
#include "element.h"

static const char *const schema_names[] = { ELEMENT_SCHEMA_VERSION, NULL };
static const char *const test_names[] = { "drained", "undrained", NULL };
static const char *const top_keys[] = { "$schema", "schema", "title", "material", "test", "confining_pressure",
					"axial_strain", "steps", "metrics", NULL };

static const struct case_range NON_NEGATIVE = { BOUND_CLOSED, 0, BOUND_NONE, 0 };
static const struct case_range STRAIN = { BOUND_OPEN, -1, BOUND_OPEN, 1 };
/* finite strain: ln(l / l0), bounded only to keep the stretch representable (l / l0 >= exp(-5)) */
static const struct case_range LOG_STRAIN = { BOUND_OPEN, -ELEMENT_LOG_STRAIN_MAX, BOUND_OPEN, ELEMENT_LOG_STRAIN_MAX };

static void read_element(struct case_reader *r, const json_t *root, struct element_case *c)
{
	int version, test = ELEMENT_DRAINED;
	const char *schema_location;
	case_check_keys(r, root, "", top_keys);
	/* the editor's schema (schemas/element.schema.json), as in a simulation case (case_load.c) */
	case_read_string(r, root, "", "$schema", CASE_OPTIONAL, &schema_location);
	case_read_choice(r, root, "", "schema", CASE_REQUIRED, schema_names, &version);
	case_read_short_text(r, root, "", "title", CASE_OPTIONAL, CASE_TITLE_MAX, c->title);
	const json_t *m = case_read_object(r, root, "", "material", CASE_REQUIRED);
	if (m)
		case_read_material_model(r, m, "/material", NULL, &c->material);
	case_read_choice(r, root, "", "test", CASE_REQUIRED, test_names, &test);
	c->test = test;
	case_read_number(r, root, "", "confining_pressure", CASE_REQUIRED, &NON_NEGATIVE, &c->confining_pressure);
	int finite = c->material.model != MODEL_LINEAR_ELASTIC && c->material.strain == STRAIN_FINITE;
	if (case_read_number(r, root, "", "axial_strain", CASE_REQUIRED, finite ? &LOG_STRAIN : &STRAIN,
			     &c->axial_strain) &&
	    c->axial_strain == 0)
		case_problem(r, "/axial_strain", "must not be 0");
	case_read_int(r, root, "", "steps", CASE_REQUIRED, 1, ELEMENT_STEPS_MAX, &c->steps);
	case_read_metrics(r, root, &c->metrics);
	if (!r->problem_count)
		case_check_element_metrics(r, c);
}

enum poro_status element_case_load_string(const char *json, struct element_case *c, struct poro_error *err)
{
	memset(c, 0, sizeof *c);
	struct case_reader r = { .err = err, .warnings = c->warnings };
	if (!json)
		return poro_error_set(err, PORO_EINVAL, "/: no JSON text");
	json_t *root = case_json_parse(&r, json);
	if (!root)
		return PORO_EINVAL;
	read_element(&r, root, c);
	case_json_free(root);
	if (r.out_of_memory)
		return poro_error_set(err, PORO_ENOMEM, "out of memory loading an element case");
	return r.problem_count ? PORO_EINVAL : PORO_OK;
}

enum poro_status element_case_load_file(const char *path, struct element_case *c, struct poro_error *err)
{
	char *text = NULL;
	enum poro_status st = case_read_text(path, &text, err);
	if (st)
		return st;
	st = element_case_load_string(text, c, err);
	free(text);
	return st;
}

int element_case_file_is_element(const char *path)
{
	char *text = NULL;
	const char *schema = NULL;
	struct case_reader r = {0};
	if (case_read_text(path, &text, NULL))
		return 0;
	json_t *root = case_json_parse(&r, text);
	int is = root && case_read_string(&r, root, "", "schema", CASE_OPTIONAL, &schema) &&
		 strcmp(schema, ELEMENT_SCHEMA_VERSION) == 0;
	case_json_free(root);
	free(text);
	return is;
}
