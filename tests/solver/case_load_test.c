/*
 * case_load_test.c - tests of the case loader (solver/case/case_load.c, solver/case/case_json.c).
 *
 * The oracle for a valid case is the document itself: every value read back must equal the value
 * written, and every omitted value its documented default. Bad inputs are made by editing a valid
 * document at a JSON pointer (with jansson, so each test states only what it breaks); each must be
 * refused with PORO_EINVAL, no case, and a message naming the pointer of the problem. Finally every
 * case shipped in tests/cases/ and the example of docs/case-spec.md must load.
 *
 * Files are found relative to the repository root, taken from __FILE__ (the Makefile compiles from
 * the root, so a relative __FILE__ means the tests run from there too).
 */
#include "case.h"
#include "case_json.h"   /* case_read_text */
#include "element.h"
#include "stable_dt.h"

#include <glob.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../harness.h"

/* Every required key, nothing optional. */
static const char *minimal_case =
	"{\"schema\": \"poro-case/1\","
	" \"formulation\": {\"scheme\": \"semi_implicit\"},"
	" \"grid\": {\"origin\": [-0.125, 0.25], \"extent\": [0.5, 1.25], \"cell_size\": 0.125},"
	" \"materials\": [{\"name\": \"sand\", \"model\": \"linear_elastic\", \"density\": 2650.5,"
	"   \"youngs_modulus\": 1.25e7, \"poisson_ratio\": 0.285}],"
	" \"bodies\": [{\"name\": \"column\", \"material\": \"sand\","
	"   \"rectangle\": {\"min\": [-0.125, 0.25], \"max\": [0.375, 1.125]},"
	"   \"particles_per_cell\": 2, \"porosity\": 0.385, \"hydraulic_conductivity\": 1.5e-4}],"
	" \"time\": {\"dt\": 2.5e-4, \"end\": 0.75}}";

/* Every section, with values other than the defaults. */
static const char *full_case =
	"{\"schema\": \"poro-case/1\", \"title\": \"two bodies\","
	" \"formulation\": {\"scheme\": \"semi_implicit\", \"phases\": \"single_point\","
	"   \"shape\": \"linear\","
	"   \"pore_pressure_smoothing\": false, \"flip_fraction\": 0.95},"
	" \"grid\": {\"origin\": [0, 0], \"extent\": [1.1, 0.7], \"cell_size\": 0.1},"
	" \"materials\": [{\"name\": \"sand\", \"model\": \"linear_elastic\", \"density\": 2650,"
	"     \"youngs_modulus\": 1e7, \"poisson_ratio\": 0},"
	"   {\"name\": \"clay-2\", \"model\": \"hencky\", \"density\": 2710.25, \"youngs_modulus\": 3.5e6,"
	"     \"poisson_ratio\": -0.125}],"
	" \"bodies\": [{\"name\": \"base\", \"material\": \"sand\","
	"     \"rectangle\": {\"min\": [0, 0], \"max\": [1.1, 0.3]},"
	"     \"particles_per_cell\": 3, \"porosity\": 0.3, \"hydraulic_conductivity\": 1e-3},"
	"   {\"name\": \"wedge\", \"material\": \"clay-2\","
	"     \"polygon\": [[0.2, 0.3], [0.9, 0.3], [0.45, 0.65]],"
	"     \"particles_per_cell\": 4, \"porosity\": 0.4125, \"hydraulic_conductivity\": 2.5e-7,"
	"     \"permeability_law\": \"kozeny_carman\"}],"
	" \"fluid\": {\"density\": 998.2, \"bulk_modulus\": 2.15e9},"
	" \"gravity\": {\"acceleration\": [0.5, -9.75], \"ramp_time\": 0.2},"
	" \"boundaries\": {\"left\": {\"soil\": \"slip\", \"water\": \"fixed\"},"
	"   \"bottom\": {\"soil\": \"fixed\", \"water\": \"fixed\", \"drainage\": \"drained\"},"
	"   \"top\": {\"drainage\": \"drained\"}},"
	" \"loads\": [{\"body\": \"wedge\", \"face\": \"top\", \"traction\": [0, -1e4]},"
	"   {\"body\": \"base\", \"face\": \"right\", \"from\": 0.05, \"to\": 0.25,"
	"     \"traction\": [-2.5e3, 0],"
	"     \"time_function\": {\"kind\": \"sinusoid\", \"frequency\": 2.5, \"amplitude\": 0.75,"
	"       \"mean\": 0.25, \"phase\": 0.3}},"
	"   {\"body\": \"base\", \"face\": \"top\", \"from\": 0, \"to\": 0.2, \"traction\": [0, -500],"
	"     \"time_function\": {\"kind\": \"ramp\", \"ramp_time\": 0.4}}],"
	" \"time\": {\"dt\": 1e-4, \"end\": 1.5},"
	" \"output\": {\"frame_interval\": 0.05, \"progress_interval\": 2.5},"
	" \"probes\": [{\"name\": \"p-mid\", \"kind\": \"pore_pressure\", \"point\": [0.55, 0.15]},"
	"   {\"name\": \"settlement\", \"kind\": \"displacement\", \"point\": [0.45, 0.65],"
	"     \"component\": \"y\"},"
	"   {\"name\": \"stress\", \"kind\": \"average\", \"field\": \"stress_xy\","
	"     \"box\": {\"min\": [0.1, 0.05], \"max\": [0.3, 0.25]}}]}";

/* A change to a document: the value (JSON text) to put at pointer, or NULL to delete it. */
struct edit {
	const char *pointer;
	const char *value;
};

/* The container and last token of pointer in doc; NULL if the path does not exist. */
static json_t *parent_of(json_t *doc, const char *pointer, char *last)
{
	char path[256];
	snprintf(path, sizeof path, "%s", pointer + 1);
	char *slash = strrchr(path, '/');
	snprintf(last, 256, "%s", slash ? slash + 1 : path);
	if (!slash)
		return doc;
	*slash = '\0';
	json_t *node = doc;
	for (char *token = strtok(path, "/"); node && token; token = strtok(NULL, "/"))
		node = json_is_array(node) ? json_array_get(node, strtoul(token, NULL, 10))
					   : json_object_get(node, token);
	return node;
}

/* The document base with edits applied, as a heap string (the caller frees it). */
static char *edited(const char *base, const struct edit *edits, int count)
{
	json_t *doc = json_loads(base, 0, NULL);
	for (int i = 0; doc && i < count; i++) {
		char last[256];
		json_t *parent = parent_of(doc, edits[i].pointer, last);
		json_t *value = edits[i].value ? json_loads(edits[i].value, JSON_DECODE_ANY, NULL) : NULL;
		if (json_is_array(parent) && value)
			json_array_set_new(parent, strtoul(last, NULL, 10), value);
		else if (json_is_array(parent))
			json_array_remove(parent, strtoul(last, NULL, 10));
		else if (value)
			json_object_set_new(parent, last, value);
		else
			json_object_del(parent, last);
	}
	char *text = json_dumps(doc, 0);
	json_decref(doc);
	return text;
}

/* Loads base with edits applied; expects refusal, no case, and each needle in the message. */
static void expect_invalid_edits(const char *name, const char *base, const struct edit *edits, int count,
				 const char *const *needles)
{
	char *text = edited(base, edits, count);
	struct case_spec *c = (struct case_spec *)1;
	struct poro_error err = { 0 };
	enum poro_status status = case_load_string(text, &c, &err);
	CHECK(status == PORO_EINVAL && c == NULL && err.code == PORO_EINVAL, name,
	      "status %d, case %p, message '%s'", status, (void *)c, err.message);
	for (int i = 0; needles[i]; i++) {
		char check[256];
		snprintf(check, sizeof check, "%s names '%s'", name, needles[i]);
		CHECK(strstr(err.message, needles[i]) != NULL, check, "message was '%s'", err.message);
	}
	case_destroy(&c);
	free(text);
}

/* Loads full_case with one edit (value NULL: delete); expects refusal and needle in the message. */
static void expect_invalid(const char *name, const char *pointer, const char *value, const char *needle)
{
	struct edit e = { pointer, value };
	const char *needles[] = { needle, NULL };
	expect_invalid_edits(name, full_case, &e, 1, needles);
}

/* Loads text, which must be valid; NULL (after a FAIL line) if not. */
static struct case_spec *load_valid(const char *name, const char *text)
{
	struct case_spec *c = NULL;
	struct poro_error err = { 0 };
	enum poro_status status = case_load_string(text, &c, &err);
	CHECK(status == PORO_OK && c != NULL, name, "status %d: %s", status, err.message);
	return c;
}

static void test_minimal_values(const struct case_spec *c)
{
	CHECK(c->grid.origin[0] == -0.125 && c->grid.origin[1] == 0.25 && c->grid.extent[0] == 0.5 &&
	      c->grid.extent[1] == 1.25 && c->grid.cell_size == 0.125, "minimal grid", "grid differs");
	const struct case_material *m = &c->materials[0];
	CHECK(c->material_count == 1 && strcmp(m->name, "sand") == 0 && m->model == MODEL_LINEAR_ELASTIC &&
	      m->density == 2650.5 && m->youngs_modulus == 1.25e7 && m->poisson_ratio == 0.285,
	      "minimal material", "material differs");
	const struct case_body *b = &c->bodies[0];
	CHECK(c->body_count == 1 && strcmp(b->name, "column") == 0 && b->material == 0 && !b->is_polygon &&
	      b->min[0] == -0.125 && b->min[1] == 0.25 && b->max[0] == 0.375 && b->max[1] == 1.125 &&
	      b->particles_per_cell == 2 && b->porosity == 0.385 && b->hydraulic_conductivity == 1.5e-4,
	      "minimal body", "body differs");
	CHECK(c->time.dt == 2.5e-4 && c->time.end == 0.75, "minimal time", "dt %g end %g", c->time.dt,
	      c->time.end);
	CHECK(c->json && strcmp(c->json, minimal_case) == 0, "minimal keeps its json text", "json differs");
}

static void test_minimal_defaults(const struct case_spec *c)
{
	const struct case_formulation *f = &c->formulation;
	CHECK(f->scheme == SCHEME_SEMI_IMPLICIT && f->phases == PHASES_DOUBLE_POINT &&
	      f->shape == SHAPE_QUADRATIC_BSPLINE && f->pore_pressure_smoothing == 1 && f->flip_fraction == 1,
	      "default formulation", "phases %d shape %d smoothing %d flip %g", f->phases, f->shape,
	      f->pore_pressure_smoothing, f->flip_fraction);
	CHECK(f->pressure_stabilisation == PRESSURE_STABILISATION_NONE && f->pressure_stabilisation_factor == 10,
	      "default pressure stabilisation", "kind %d factor %g", f->pressure_stabilisation,
	      f->pressure_stabilisation_factor);
	CHECK(f->free_surface == FREE_SURFACE_NODES && f->free_surface_penalty_factor == 1e4, "default free surface",
	      "kind %d factor %g", f->free_surface, f->free_surface_penalty_factor);
	CHECK(f->position_update == POSITION_UPDATE_GRID_VELOCITY, "default position update", "got %d",
	      f->position_update);
	CHECK(f->velocity_update == VELOCITY_UPDATE_FLIP, "default velocity update", "got %d", f->velocity_update);
	CHECK(f->specific_volume == SPECIFIC_VOLUME_POINT, "default specific volume", "got %d", f->specific_volume);
	CHECK(c->bodies[0].permeability_law == PERMEABILITY_CONSTANT, "default permeability law", "got %d",
	      c->bodies[0].permeability_law);
	CHECK(c->bodies[0].saturated == 1, "a body is saturated by default", "got %d", c->bodies[0].saturated);
	CHECK(c->fluid.density == 1000 && c->fluid.bulk_modulus == 2.2e9, "default fluid",
	      "density %g bulk modulus %g", c->fluid.density, c->fluid.bulk_modulus);
	const double *g = c->gravity.acceleration;
	CHECK(g[0] == 0 && g[1] == -9.81 && c->gravity.ramp_time == 0, "default gravity",
	      "got [%g, %g] ramp %g", g[0], g[1], c->gravity.ramp_time);
	int faces_ok = 1;
	for (int i = 0; i < FACE_COUNT; i++) {
		const struct case_boundary *b = &c->boundaries[i];
		faces_ok &= b->soil == CONSTRAINT_FREE && b->water == CONSTRAINT_FREE &&
			    b->drainage == DRAINAGE_IMPERMEABLE;
	}
	CHECK(faces_ok, "default boundaries", "a face is not free and impermeable");
	CHECK(c->output.frame_interval == 0 && c->output.progress_interval == 1, "default output",
	      "frame %g progress %g", c->output.frame_interval, c->output.progress_interval);
	CHECK(c->load_count == 0 && c->probe_count == 0 && c->title[0] == '\0', "default empty lists",
	      "loads %d probes %d title '%s'", c->load_count, c->probe_count, c->title);
}

static void test_minimal(void)
{
	struct case_spec *c = load_valid("minimal case loads", minimal_case);
	if (!c)
		return;
	test_minimal_values(c);
	test_minimal_defaults(c);
	case_destroy(&c);
	CHECK(c == NULL, "destroy clears the pointer", "pointer %p", (void *)c);
	case_destroy(&c);
	case_destroy(NULL);
}

static void test_full_bodies(const struct case_spec *c)
{
	const struct case_body *w = &c->bodies[1];
	CHECK(c->material_count == 2 && c->materials[1].model == MODEL_HENCKY &&
	      c->materials[1].poisson_ratio == -0.125, "full materials", "second material differs");
	CHECK(w->is_polygon && w->polygon_count == 3 && w->material == 1 && w->polygon[2][0] == 0.45 &&
	      w->polygon[2][1] == 0.65 && w->permeability_law == PERMEABILITY_KOZENY_CARMAN,
	      "full polygon body", "polygon body differs");
	const struct edit dry = { "/bodies/1/saturated", "false" };
	char *text = edited(full_case, &dry, 1);
	struct case_spec *d = load_valid("case with a dry body loads", text);
	CHECK(d && d->bodies[0].saturated && !d->bodies[1].saturated, "a dry body reads as such", "saturated %d and %d",
	      d ? d->bodies[0].saturated : -1, d ? d->bodies[1].saturated : -1);
	case_destroy(&d);
	free(text);
	CHECK(w->min[0] == 0.2 && w->min[1] == 0.3 && w->max[0] == 0.9 && w->max[1] == 0.65,
	      "polygon bounding box", "[%g, %g] to [%g, %g]", w->min[0], w->min[1], w->max[0], w->max[1]);
}

static void test_full_sections(const struct case_spec *c)
{
	CHECK(strcmp(c->title, "two bodies") == 0 && c->formulation.phases == PHASES_SINGLE_POINT &&
	      c->formulation.shape == SHAPE_LINEAR && !c->formulation.pore_pressure_smoothing &&
	      c->formulation.flip_fraction == 0.95, "full formulation", "formulation differs");
	CHECK(c->fluid.density == 998.2 && c->gravity.acceleration[0] == 0.5 && c->gravity.ramp_time == 0.2 &&
	      c->output.frame_interval == 0.05 && c->output.progress_interval == 2.5,
	      "full fluid, gravity and output", "a value differs");
	const struct case_boundary *b = c->boundaries;
	CHECK(b[FACE_LEFT].soil == CONSTRAINT_SLIP && b[FACE_LEFT].water == CONSTRAINT_FIXED &&
	      b[FACE_LEFT].drainage == DRAINAGE_IMPERMEABLE && b[FACE_RIGHT].soil == CONSTRAINT_FREE &&
	      b[FACE_BOTTOM].soil == CONSTRAINT_FIXED && b[FACE_BOTTOM].drainage == DRAINAGE_DRAINED &&
	      b[FACE_TOP].soil == CONSTRAINT_FREE && b[FACE_TOP].drainage == DRAINAGE_DRAINED,
	      "full boundaries with per-key defaults", "a face differs");
	const struct case_probe *p = c->probes;
	CHECK(c->probe_count == 3 && p[0].kind == PROBE_PORE_PRESSURE && p[0].point[0] == 0.55 &&
	      p[1].kind == PROBE_DISPLACEMENT && p[1].component == 1 && p[2].kind == PROBE_AVERAGE &&
	      p[2].field == FIELD_STRESS_XY && p[2].box_min[1] == 0.05 && p[2].box_max[0] == 0.3,
	      "full probes", "a probe differs");
}

static void test_full_loads(const struct case_spec *c)
{
	const struct case_load *l = c->loads;
	CHECK(c->load_count == 3 && l[0].body == 1 && l[0].face == FACE_TOP && l[0].traction[1] == -1e4 &&
	      l[0].time_function.kind == TIME_CONSTANT, "full loads", "a load differs");
	CHECK(l[0].from == 0.2 && l[0].to == 0.9, "load span defaults to the body's face",
	      "from %g to %g", l[0].from, l[0].to);
	CHECK(l[1].face == FACE_RIGHT && l[1].from == 0.05 && l[1].to == 0.25, "load span as given",
	      "from %g to %g", l[1].from, l[1].to);
	const struct case_time_function *s = &l[1].time_function, *ramp = &l[2].time_function;
	double t = 0.1375, want = 0.25 + 0.75 * sin(2 * 3.14159265358979323846 * 2.5 * t + 0.3);
	CHECK(s->kind == TIME_SINUSOID && rel_diff(case_time_function_value(s, t), want, 1e-300) < 1e-14,
	      "sinusoid value", "got %.17g want %.17g", case_time_function_value(s, t), want);
	CHECK(ramp->kind == TIME_RAMP && case_time_function_value(ramp, 0.1) == 0.25 &&
	      case_time_function_value(ramp, 0.4) == 1 && case_time_function_value(ramp, 2.75) == 1,
	      "ramp value", "got %g at 0.1", case_time_function_value(ramp, 0.1));
	CHECK(case_time_function_value(&(struct case_time_function){ .kind = TIME_CONSTANT }, 3.7) == 1,
	      "constant value", "not 1");
}

/* fluid.cavitation_pressure is read with its default cavitated bulk modulus, and without it the
 * water takes any tension (000). */
static void test_cavitation_keys(void)
{
	const struct edit e = { "/fluid/cavitation_pressure", "-9e4" };
	char *text = edited(full_case, &e, 1);
	struct case_spec *c = load_valid("cavitation keys", text);
	if (c)
		CHECK(c->fluid.cavitation_pressure == -9e4 && c->fluid.cavitated_bulk_modulus == 1e6,
		      "cavitation pressure with the default bulk modulus", "p_cav %g, K_c %g",
		      c->fluid.cavitation_pressure, c->fluid.cavitated_bulk_modulus);
	case_destroy(&c);
	free(text);
	c = load_valid("no cavitation", full_case);
	if (c)
		CHECK(c->fluid.cavitation_pressure == 0.0, "water without cavitation by default", "p_cav %g",
		      c->fluid.cavitation_pressure);
	case_destroy(&c);
}

static void test_full(void)
{
	struct case_spec *c = load_valid("full case loads", full_case);
	if (!c)
		return;
	test_full_bodies(c);
	test_full_sections(c);
	test_full_loads(c);
	case_destroy(&c);
}

static void test_malformed(void)
{
	const char *texts[] = { "{\"schema\": \"poro-case/1\",\n  \"time\": {\"dt\": }}", "", "[1, 2]",
				"{\"time\": 1, \"time\": 2}" };
	const char *needles[] = { "/: malformed JSON at line 2 column", "/: malformed JSON at line",
				  "/: expected an object, got array", "/: malformed JSON at line 1" };
	for (int i = 0; i < 4; i++) {
		char name[64];
		struct case_spec *c = (struct case_spec *)1;
		struct poro_error err = { 0 };
		snprintf(name, sizeof name, "malformed json %d refused", i);
		enum poro_status status = case_load_string(texts[i], &c, &err);
		int starts = strncmp(err.message, needles[i], strlen(needles[i])) == 0;
		CHECK(status == PORO_EINVAL && c == NULL && starts, name, "status %d message '%s'", status,
		      err.message);
	}
}

static void test_wrong_types(void)
{
	expect_invalid("string for a number", "/materials/0/youngs_modulus", "\"1e7\"",
		       "/materials/0/youngs_modulus: expected a number, got string");
	expect_invalid("object for an array", "/bodies", "{}", "/bodies: expected an array, got object");
	expect_invalid("number for a boolean", "/formulation/pore_pressure_smoothing", "1",
		       "/formulation/pore_pressure_smoothing: expected a boolean, got number");
	expect_invalid("null for a string", "/bodies/1/material", "null",
		       "/bodies/1/material: expected a string, got null");
	expect_invalid("three numbers for a vector", "/gravity/acceleration", "[0, -9.81, 0]",
		       "/gravity/acceleration: expected 2 numbers, got 3");
	expect_invalid("string in a vector", "/grid/origin/1", "\"0\"",
		       "/grid/origin/1: expected a number, got string");
	expect_invalid("number for saturated", "/bodies/1/saturated", "0",
		       "/bodies/1/saturated: expected a boolean, got number");
	{
		const struct edit e[] = { { "/bodies/1/saturated", "false" },
					  { "/formulation/pressure_projection", "\"consistent\"" } };
		const char *needles[] = { "/bodies/1/saturated: false needs /formulation/pressure_projection \"laplacian\"",
					  NULL };
		expect_invalid_edits("dry body with the consistent projection", full_case, e, 2, needles);
	}
	expect_invalid("fraction for an integer", "/bodies/0/particles_per_cell", "2.5",
		       "/bodies/0/particles_per_cell: expected an integer, got 2.5");
	expect_invalid("array item not an object", "/probes/1", "7",
		       "/probes/1: expected an object, got number");
	expect_invalid("unknown enum value", "/boundaries/left/soil", "\"glued\"",
		       "/boundaries/left/soil: must be one of 'free', 'slip', 'fixed', 'plate', got 'glued'");
	expect_invalid("wrong schema version", "/schema", "\"poro-case/2\"",
		       "/schema: must be one of 'poro-case/1'");
}

static void test_out_of_range(void)
{
	expect_invalid("dt zero", "/time/dt", "0", "/time/dt: must be > 0, got 0");
	expect_invalid("dt negative", "/time/dt", "-2.5e-4", "/time/dt: must be > 0, got -0.00025");
	expect_invalid("dt above end", "/time/dt", "2.5", "/time/dt: must be <= /time/end (1.5), got 2.5");
	expect_invalid("porosity one", "/bodies/1/porosity", "1",
		       "/bodies/1/porosity: must be > 0 and < 1, got 1");
	expect_invalid("porosity above one", "/bodies/0/porosity", "1.25",
		       "/bodies/0/porosity: must be > 0 and < 1");
	expect_invalid("youngs modulus zero", "/materials/0/youngs_modulus", "0",
		       "/materials/0/youngs_modulus: must be > 0, got 0");
	expect_invalid("youngs modulus negative", "/materials/1/youngs_modulus", "-3.5e6",
		       "/materials/1/youngs_modulus: must be > 0, got -3.5e+06");
	expect_invalid("poisson ratio one half", "/materials/0/poisson_ratio", "0.5",
		       "/materials/0/poisson_ratio: must be > -1 and < 0.5, got 0.5");
	expect_invalid("poisson ratio 0.7", "/materials/0/poisson_ratio", "0.7",
		       "/materials/0/poisson_ratio: must be > -1 and < 0.5, got 0.7");
	expect_invalid("flip fraction above one", "/formulation/flip_fraction", "1.05",
		       "/formulation/flip_fraction: must be >= 0 and <= 1, got 1.05");
	expect_invalid("pressure stabilisation without the consistent projection", "/formulation/pressure_stabilisation",
		       "\"second_difference\"",
		       "/formulation/pressure_stabilisation: \"second_difference\" needs /formulation/pressure_projection "
		       "\"consistent\"");
	expect_invalid("unknown pressure stabilisation", "/formulation/pressure_stabilisation", "\"smooth\"",
		       "/formulation/pressure_stabilisation: must be one of 'none', 'second_difference', got 'smooth'");
	expect_invalid("pressure stabilisation factor zero", "/formulation/pressure_stabilisation_factor", "0",
		       "/formulation/pressure_stabilisation_factor: must be > 0, got 0");
	{
		const struct edit e[] = { { "/formulation/pressure_projection", "\"consistent\"" },
					  { "/formulation/pressure_stabilisation", "\"second_difference\"" },
					  { "/formulation/pressure_stabilisation_factor", "2.385" } };
		char *text = edited(full_case, e, 3);
		struct case_spec *c = load_valid("pressure stabilisation with the consistent projection", text);
		CHECK(c && c->formulation.pressure_stabilisation == PRESSURE_STABILISATION_SECOND_DIFFERENCE &&
		      c->formulation.pressure_stabilisation_factor == 2.385, "pressure stabilisation read",
		      "kind %d factor %g", c ? (int)c->formulation.pressure_stabilisation : -1,
		      c ? c->formulation.pressure_stabilisation_factor : 0.0);
		case_destroy(&c);
		free(text);
	}
	expect_invalid("interpolated free surface without the consistent projection", "/formulation/free_surface",
		       "\"interpolated\"",
		       "/formulation/free_surface: \"interpolated\" needs /formulation/pressure_projection \"consistent\"");
	expect_invalid("unknown free surface", "/formulation/free_surface", "\"cells\"",
		       "/formulation/free_surface: must be one of 'nodes', 'interpolated', 'weak', got 'cells'");
	expect_invalid("weak free surface without the consistent projection", "/formulation/free_surface",
		       "\"weak\"",
		       "/formulation/free_surface: \"weak\" needs /formulation/pressure_projection \"consistent\"");
	expect_invalid("free surface penalty factor negative", "/formulation/free_surface_penalty_factor", "-1e4",
		       "/formulation/free_surface_penalty_factor: must be > 0, got -10000");
	{
		const struct edit e[] = { { "/formulation/pressure_projection", "\"consistent\"" },
					  { "/formulation/free_surface", "\"interpolated\"" },
					  { "/formulation/free_surface_penalty_factor", "385.2" } };
		char *text = edited(full_case, e, 3);
		struct case_spec *c = load_valid("interpolated free surface with the consistent projection", text);
		CHECK(c && c->formulation.free_surface == FREE_SURFACE_INTERPOLATED &&
		      c->formulation.free_surface_penalty_factor == 385.2, "free surface read", "kind %d factor %g",
		      c ? (int)c->formulation.free_surface : -1, c ? c->formulation.free_surface_penalty_factor : 0.0);
		case_destroy(&c);
		free(text);
	}
	{
		const struct edit e[] = { { "/formulation/pressure_projection", "\"consistent\"" },
					  { "/formulation/free_surface", "\"weak\"" } };
		char *text = edited(full_case, e, 2);
		struct case_spec *c = load_valid("weak free surface with the consistent projection", text);
		CHECK(c && c->formulation.free_surface == FREE_SURFACE_WEAK, "weak free surface read", "kind %d",
		      c ? (int)c->formulation.free_surface : -1);
		case_destroy(&c);
		free(text);
	}
	expect_invalid("unknown specific volume", "/formulation/specific_volume", "\"cell_average\"",
		       "/formulation/specific_volume: must be one of 'point', 'nodal_average', got 'cell_average'");
	{
		const struct edit e[] = { { "/formulation/specific_volume", "\"nodal_average\"" } };
		char *text = edited(full_case, e, 1);
		struct case_spec *c = load_valid("specific volume from the nodal average of J", text);
		CHECK(c && c->formulation.specific_volume == SPECIFIC_VOLUME_NODAL_AVERAGE, "specific volume read",
		      "got %d", c ? (int)c->formulation.specific_volume : -1);
		case_destroy(&c);
		free(text);
	}
	expect_invalid("unknown position update", "/formulation/position_update", "\"particle_velocity\"",
		       "/formulation/position_update: must be one of 'grid_velocity', 'musl_displacement', "
		       "got 'particle_velocity'");
	expect_invalid("position update not a string", "/formulation/position_update", "2",
		       "/formulation/position_update: expected a string, got number");
	{
		const struct edit e[] = { { "/formulation/position_update", "\"musl_displacement\"" } };
		char *text = edited(full_case, e, 1);
		struct case_spec *c = load_valid("position update by the MUSL displacement", text);
		CHECK(c && c->formulation.position_update == POSITION_UPDATE_MUSL_DISPLACEMENT, "position update read",
		      "got %d", c ? (int)c->formulation.position_update : -1);
		case_destroy(&c);
		free(text);
	}
	expect_invalid("unknown velocity update", "/formulation/velocity_update", "\"mls\"",
		       "/formulation/velocity_update: must be one of 'flip', 'apic', 'aflip', got 'mls'");
	expect_invalid("apic with a flip fraction", "/formulation/velocity_update", "\"apic\"",
		       "/formulation/flip_fraction: blends FLIP with PIC and has no meaning with "
		       "/formulation/velocity_update \"apic\"");
	{
		const struct edit e[] = { { "/formulation/velocity_update", "\"apic\"" },
					  { "/formulation/flip_fraction", "1" } };
		char *text = edited(full_case, e, 2);
		struct case_spec *c = load_valid("velocity update by APIC", text);
		CHECK(c && c->formulation.velocity_update == VELOCITY_UPDATE_APIC, "velocity update read", "got %d",
		      c ? (int)c->formulation.velocity_update : -1);
		case_destroy(&c);
		free(text);
	}
	{   /* AFLIP blends like FLIP, so it takes a flip fraction */
		const struct edit e[] = { { "/formulation/velocity_update", "\"aflip\"" },
					  { "/formulation/flip_fraction", "0.983" } };
		char *text = edited(full_case, e, 2);
		struct case_spec *c = load_valid("velocity update by AFLIP with a flip fraction", text);
		CHECK(c && c->formulation.velocity_update == VELOCITY_UPDATE_AFLIP &&
		      c->formulation.flip_fraction == 0.983, "aflip and its flip fraction read", "got %d, %g",
		      c ? (int)c->formulation.velocity_update : -1, c ? c->formulation.flip_fraction : -1.0);
		case_destroy(&c);
		free(text);
	}
	expect_invalid("particles per cell 9", "/bodies/0/particles_per_cell", "9",
		       "/bodies/0/particles_per_cell: must be >= 1 and <= 8, got 9");
	expect_invalid("extent not a multiple", "/grid/extent/0", "1.15",
		       "/grid/extent/0: must be a positive multiple of /grid/cell_size");
	expect_invalid("too few cells", "/grid/extent/1", "0.2",
		       "/grid/extent/1: must span at least 3 cells");
	expect_invalid("polygon of two vertices", "/bodies/1/polygon", "[[0.2, 0.3], [0.9, 0.3]]",
		       "/bodies/1/polygon: must have 3 to 64 vertices, got 2");
	expect_invalid("polygon without area", "/bodies/1/polygon", "[[0.2, 0.3], [0.4, 0.4], [0.6, 0.5]]",
		       "/bodies/1/polygon: must enclose a non-zero area");
	expect_invalid("rectangle upside down", "/bodies/0/rectangle/max", "[1.1, -0.3]",
		       "/bodies/0/rectangle/max: must be greater than min");
	expect_invalid("load from above to", "/loads/1/to", "0.01", "/loads/1/to: must be greater than from");
	expect_invalid("load off its face", "/loads/2/to", "1.25",
		       "/loads/2: from and to must lie on the top face of body 'base'");
	expect_invalid("ramp time zero", "/loads/2/time_function/ramp_time", "0",
		       "/loads/2/time_function/ramp_time: must be > 0");
	expect_invalid("cavitation pressure zero", "/fluid/cavitation_pressure", "0",
		       "/fluid/cavitation_pressure: must be < 0, got 0");
	expect_invalid("cavitated bulk modulus negative", "/fluid/cavitated_bulk_modulus", "-1e6",
		       "/fluid/cavitated_bulk_modulus: must be > 0");
	expect_invalid("cavitated bulk modulus without cavitation", "/fluid/cavitated_bulk_modulus", "1e6",
		       "/fluid/cavitated_bulk_modulus: needs /fluid/cavitation_pressure");
	{
		const struct edit e[] = { { "/fluid/cavitation_pressure", "-1e5" },
					  { "/formulation/pressure_projection", "\"consistent\"" },
					  { "/formulation/free_surface", "\"weak\"" } };
		const char *needles[] = { "/fluid/cavitation_pressure: needs /formulation/free_surface \"nodes\"",
					  NULL };
		expect_invalid_edits("cavitation with the weak free surface", full_case, e, 3, needles);
	}
	expect_invalid("title too long", "/title",
		       "\"" "0123456789012345678901234567890123456789012345678901234567890123456789"
		       "0123456789012345678901234567890123456789012345678901234567890123456789"
		       "0123456789012345678901234567890123456789012345678901234567890123456789"
		       "0123456789012345678901234567890123456789012345678901234567890123456789" "\"",
		       "/title: must be at most 255 characters long, got 280");
}

static void test_unknown_keys(void)
{
	expect_invalid("unknown top-level key", "/foo", "1", "/foo: unknown key");
	expect_invalid("unknown grid key", "/grid/cells", "[11, 7]", "/grid/cells: unknown key");
	expect_invalid("unknown face key", "/boundaries/left/flux", "0",
		       "/boundaries/left/flux: unknown key");
	expect_invalid("unknown boundary face", "/boundaries/front", "{}", "/boundaries/front: unknown key");
	expect_invalid("key of another time function kind", "/loads/2/time_function/frequency", "2",
		       "/loads/2/time_function/frequency: unknown key");
	expect_invalid("key of another probe kind", "/probes/0/component", "\"x\"",
		       "/probes/0/component: unknown key");
	expect_invalid("key escaped in the pointer", "/materials/0/a~b", "1",
		       "/materials/0/a~0b: unknown key");
}

/* "$schema" names the JSON Schema for editors (case.schema.json, element.schema.json): any string, in a simulation
 * case and in an element case alike; anything else is refused. It was an unknown key. */
static void test_schema_location(void)
{
	static const char *element =
		"{\"$schema\": \"../../schemas/element.schema.json\", \"schema\": \"poro-element/1\","
		" \"material\": {\"model\": \"linear_elastic\", \"youngs_modulus\": 2.5e7, \"poisson_ratio\": 0.25},"
		" \"test\": \"drained\", \"confining_pressure\": 1.25e5, \"axial_strain\": -0.0125, \"steps\": 10}";
	const struct edit e = { "/$schema", "\"https://example.org/poro/case.schema.json\"" };
	char *text = edited(minimal_case, &e, 1);
	struct case_spec *c = load_valid("case with $schema loads", text);
	case_destroy(&c);
	free(text);
	expect_invalid("$schema not a string", "/$schema", "3", "/$schema: expected a string, got number");
	struct element_case ec;
	struct poro_error err = { 0 };
	enum poro_status st = element_case_load_string(element, &ec, &err);
	CHECK(st == PORO_OK, "element case with $schema loads", "status %d: %s", st, err.message);
	const struct edit bad = { "/$schema", "{}" };
	text = edited(element, &bad, 1);
	st = element_case_load_string(text, &ec, &err);
	CHECK(st == PORO_EINVAL && strstr(err.message, "/$schema: expected a string, got object"),
	      "element case with a $schema object refused", "status %d: %s", st, err.message);
	free(text);
}

static void test_references_and_geometry(void)
{
	expect_invalid("body outside the grid", "/bodies/0/rectangle/max", "[1.1, 0.75]",
		       "/bodies/0: body lies outside the grid");
	expect_invalid("polygon outside the grid", "/bodies/1/polygon/2", "[-0.05, 0.65]",
		       "/bodies/1: body lies outside the grid");
	expect_invalid("unknown material", "/bodies/1/material", "\"clay\"",
		       "/bodies/1/material: unknown material 'clay'");
	expect_invalid("unknown body in a load", "/loads/0/body", "\"roof\"",
		       "/loads/0/body: unknown body 'roof'");
	expect_invalid("probe point outside the grid", "/probes/1/point", "[0.45, 0.71]",
		       "/probes/1/point: point lies outside the grid");
	expect_invalid("probe box outside the grid", "/probes/2/box/min", "[-0.1, 0.05]",
		       "/probes/2/box: box lies outside the grid");
	expect_invalid("both rectangle and polygon", "/bodies/0/polygon", "[[0, 0], [1, 0], [0, 0.2]]",
		       "/bodies/0: must have exactly one of 'rectangle' and 'polygon', got both");
	expect_invalid("neither rectangle nor polygon", "/bodies/1/polygon", NULL,
		       "/bodies/1: must have exactly one of 'rectangle' and 'polygon', got neither");
	expect_invalid("bad name characters", "/materials/1/name", "\"clay 2\"",
		       "/materials/1/name: must contain only letters, digits, '_' and '-', got 'clay 2'");
	expect_invalid("no bodies", "/bodies", "[]", "/bodies: must list at least one body");
}

static void test_missing_required(void)
{
	expect_invalid("missing dt", "/time/dt", NULL, "/time/dt: missing required key");
	expect_invalid("missing schema", "/schema", NULL, "/schema: missing required key");
	expect_invalid("missing grid", "/grid", NULL, "/grid: missing required key");
	expect_invalid("missing scheme", "/formulation/scheme", NULL,
		       "/formulation/scheme: missing required key");
	expect_invalid("missing porosity", "/bodies/1/porosity", NULL,
		       "/bodies/1/porosity: missing required key");
	expect_invalid("missing sinusoid amplitude", "/loads/1/time_function/amplitude", NULL,
		       "/loads/1/time_function/amplitude: missing required key");
	expect_invalid("missing probe component", "/probes/1/component", NULL,
		       "/probes/1/component: missing required key");
	expect_invalid("missing probe box", "/probes/2/box", NULL, "/probes/2/box: missing required key");
}

static void test_duplicates(void)
{
	expect_invalid("duplicate material", "/materials/1/name", "\"sand\"",
		       "/materials/1/name: duplicate material name 'sand'");
	expect_invalid("duplicate body", "/bodies/1/name", "\"base\"",
		       "/bodies/1/name: duplicate body name 'base'");
	expect_invalid("duplicate probe", "/probes/2/name", "\"p-mid\"",
		       "/probes/2/name: duplicate probe name 'p-mid'");
}

static void test_many_errors(void)
{
	const struct edit edits[] = {
		{ "/time/dt", "-1" },
		{ "/materials/0/poisson_ratio", "0.7" },
		{ "/bodies/1/material", "\"clay\"" },
		{ "/grid/extent/0", "1.05" },
		{ "/foo", "true" },
	};
	const char *needles[] = { "/time/dt: must be > 0",
				  "/materials/0/poisson_ratio: must be > -1 and < 0.5",
				  "/bodies/1/material: unknown material 'clay'",
				  "/grid/extent/0: must be a positive multiple", "/foo: unknown key", NULL };
	expect_invalid_edits("five errors at once", full_case, edits, 5, needles);

	char *text = edited(full_case, edits, 5);
	struct case_spec *c = NULL;
	struct poro_error err = { 0 };
	case_load_string(text, &c, &err);
	int lines = 1;
	for (const char *s = err.message; *s; s++)
		lines += *s == '\n';
	CHECK(lines == 5 && err.message[strlen(err.message) - 1] != '.', "one line per error",
	      "%d lines: '%s'", lines, err.message);
	free(text);
}

static void test_unreadable_file(void)
{
	struct case_spec *c = (struct case_spec *)1;
	struct poro_error err = { 0 };
	enum poro_status status = case_load_file("/nonexistent/poro/case.json", &c, &err);
	const char *want = "cannot open '/nonexistent/poro/case.json': No such file or directory";
	CHECK(status == PORO_EIO && c == NULL && strcmp(err.message, want) == 0,
	      "unreadable file", "status %d message '%s'", status, err.message);
}

/* The repository root, from __FILE__ ("" when compiled with a relative path from the root). */
static void repository_root(char *root, size_t size)
{
	const char *suffix = "tests/solver/case_load_test.c";
	size_t n = strlen(__FILE__) - strlen(suffix);
	snprintf(root, size, "%.*s", (int)n, __FILE__);
}

/* A simulation case, or an element case (element.h) by its schema. */
static void load_file_ok(const char *name, const char *path)
{
	struct case_spec *c = NULL;
	struct poro_error err = { 0 };
	if (element_case_file_is_element(path)) {
		struct element_case e;
		enum poro_status st = element_case_load_file(path, &e, &err);
		CHECK(st == PORO_OK, name, "%s: %s", path, err.message);
		return;
	}
	enum poro_status status = case_load_file(path, &c, &err);
	CHECK(status == PORO_OK && c != NULL, name, "%s: %s", path, err.message);
	case_destroy(&c);
}

/* Every .json file in tests/cases/; when there are none yet, the minimal case written to a temporary file. */
static void test_shipped_cases(const char *root)
{
	char pattern[512];
	glob_t found;
	snprintf(pattern, sizeof pattern, "%stests/cases/*.json", root);
	if (glob(pattern, 0, NULL, &found) == 0) {
		for (size_t i = 0; i < found.gl_pathc; i++) {
			char name[600];
			snprintf(name, sizeof name, "case file %s loads", found.gl_pathv[i]);
			load_file_ok(name, found.gl_pathv[i]);
		}
		globfree(&found);
		return;
	}
	char path[] = "/tmp/case_load_test_XXXXXX";
	int fd = mkstemp(path);
	FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
	CHECK(f != NULL, "temporary case file written", "cannot create '%s'", path);
	if (!f)
		return;
	fputs(minimal_case, f);
	fclose(f);
	load_file_ok("temporary case file loads", path);
	unlink(path);
}

/* The first ```json block of docs/case-spec.md, the complete example, must load. */
static void test_documented_example(const char *root)
{
	char path[512], *text = NULL;
	snprintf(path, sizeof path, "%sdocs/case-spec.md", root);
	FILE *f = fopen(path, "r");
	size_t length = 0;
	if (f) {
		text = calloc(1, 1 << 16);
		length = text ? fread(text, 1, (1 << 16) - 1, f) : 0;
		fclose(f);
	}
	char *start = text && length ? strstr(text, "```json\n") : NULL;
	char *end = start ? strstr(start + 8, "\n```") : NULL;
	CHECK(end != NULL, "documented example found", "no ```json block in '%s'", path);
	if (end) {
		*end = '\0';
		struct case_spec *c = load_valid("documented example loads", start + 8);
		CHECK(c && c->body_count == 1 && c->probe_count == 1 && c->load_count == 1 &&
		      c->boundaries[FACE_BOTTOM].soil == CONSTRAINT_SLIP && c->grid.cell_size == 0.025,
		      "documented example is the Terzaghi column", "a value differs");
		case_destroy(&c);
	}
	free(text);
}

/* boundaries.<face>.soil "plate" (solver/schemes/semi_implicit/plate.c): the plate's keys are read, and what cannot be a
 * rigid impermeable plate is refused with the key named. */
static void test_plate(void)
{
	const char *plate = "{\"soil\": \"plate\", \"water\": \"plate\", \"plate\": {\"force\": 2.5e4, "
			    "\"time_function\": {\"kind\": \"ramp\", \"ramp_time\": 0.35}}}";
	const struct edit e[] = { { "/boundaries/top", plate }, { "/boundaries/left", "{\"soil\": \"slip\"}" },
				  { "/boundaries/bottom", "{\"soil\": \"slip\"}" } };
	char *text = edited(full_case, e, 3);
	struct case_spec *c = load_valid("plate case loads", text);
	if (c) {
		const struct case_boundary *b = &c->boundaries[FACE_TOP];
		CHECK(b->soil == CONSTRAINT_PLATE && b->water == CONSTRAINT_PLATE && b->plate.force == 2.5e4 &&
		      b->plate.time_function.kind == TIME_RAMP && b->plate.time_function.ramp_time == 0.35 &&
		      c->boundaries[FACE_BOTTOM].plate.force == 0.0, "plate keys read",
		      "soil %d water %d force %g ramp %g", b->soil, b->water, b->plate.force,
		      b->plate.time_function.ramp_time);
	}
	case_destroy(&c);
	free(text);
	const struct {
		const char *name, *pointer, *value, *needle;
	} bad[] = {
		{ "plate without its force", "/boundaries/top/plate", "{}", "/boundaries/top/plate/force: missing required key" },
		{ "plate without its object", "/boundaries/top/plate", NULL, "/boundaries/top/plate: missing required key" },
		{ "plate with an unknown key", "/boundaries/top/plate/mass", "1", "/boundaries/top/plate/mass: unknown key" },
		{ "plate letting water through", "/boundaries/top/water", "\"free\"",
		  "/boundaries/top/water: must be \"plate\" under a plate" },
		{ "water plate without a soil plate", "/boundaries/top/soil", "\"slip\"",
		  "/boundaries/top/water: \"plate\" needs the soil to be \"plate\"" },
		{ "fixed corner beside a plate", "/boundaries/left/soil", "\"fixed\"",
		  "/boundaries/left: cannot be \"fixed\" beside the plate on the top face" },
		{ "drained plate", "/boundaries/top/drainage", "\"drained\"",
		  "/boundaries/top/drainage: must be \"impermeable\" under a plate" },
		{ "plate with the consistent projection", "/formulation/pressure_projection", "\"consistent\"",
		  "/boundaries/top: a plate needs formulation.pressure_projection \"laplacian\"" },
	};
	for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
		struct edit all[4] = { e[0], e[1], e[2], { bad[i].pointer, bad[i].value } };
		const char *needles[] = { bad[i].needle, NULL };
		expect_invalid_edits(bad[i].name, full_case, all, 4, needles);
	}
	const struct edit stray[] = { { "/boundaries/right", "{\"soil\": \"slip\", \"plate\": {\"force\": 1}}" } };
	const char *needles[] = { "/boundaries/right/plate: needs \"soil\": \"plate\" on the same face", NULL };
	expect_invalid_edits("plate object on a face without a plate", full_case, stray, 1, needles);
}

/* The skeleton's CFL step (solver/stable_dt.c): a dt above STABLE_DT_MAX_FACTOR times it is refused
 * with the bound in the message, a dt below it loads, and the check waits for the rest of the case
 * to be right. The full case's stiffest body is 'base': E = 1e7 Pa, nu = 0, n = 0.3, rho_s = 2650
 * kg/m^3, h = 0.1 m, so c_p = sqrt(1e7 / 1855) m/s. */
static void test_stable_dt(const char *root)
{
	const double c_p = sqrt(1e7 / ((1 - 0.3) * 2650)), cfl = 0.1 / c_p;
	char needle[400], dt_text[32];
	snprintf(needle, sizeof needle, "/time/dt: must be at most %.3g s, %.3g times the soil skeleton's CFL step "
		 "h / c_p = %.3g s (c_p = sqrt((K + 4G/3) / ((1 - n) rho_s)) = %.4g m/s in body 'base'), got 0.005",
		 STABLE_DT_MAX_FACTOR * cfl, STABLE_DT_MAX_FACTOR, cfl, c_p);
	expect_invalid("dt a few times the CFL step", "/time/dt", "0.005", needle);
	snprintf(dt_text, sizeof dt_text, "%.6g", 0.95 * STABLE_DT_MAX_FACTOR * cfl);
	{
		const struct edit e = { "/time/dt", dt_text };
		char *text = edited(full_case, &e, 1);
		struct case_spec *c = load_valid("dt just below the refusal bound loads", text);
		case_destroy(&c);
		free(text);
	}
	{
		/* one mistake, one line: a bad Poisson ratio leaves the bound (which follows from it) unchecked */
		const struct edit e[] = { { "/time/dt", "0.005" }, { "/materials/0/poisson_ratio", "0.7" } };
		char *text = edited(full_case, e, 2);
		struct case_spec *c = NULL;
		struct poro_error err = { 0 };
		enum poro_status st = case_load_string(text, &c, &err);
		CHECK(st == PORO_EINVAL && !strstr(err.message, "/time/dt") && strstr(err.message, "poisson_ratio"),
		      "dt bound not checked on a case with other problems", "%s", err.message);
		free(text);
	}
	/* Nor-Sand: K = p / kappa at the buoyant weight of the body's height, plus 4G/3 */
	char path[512];
	snprintf(path, sizeof path, "%stests/cases/landslide_dense_double_point.json", root);
	struct case_spec *c = NULL;
	struct poro_error err = { 0 };
	if (case_load_file(path, &c, &err) == PORO_OK) {
		struct stable_dt e;
		stable_dt_estimate(c, &e);
		const struct case_body *b = &c->bodies[0];
		const struct case_material *m = &c->materials[b->material];
		const double p = (1 - b->porosity) * (m->density - c->fluid.density) * 9.81 * (b->max[1] - b->min[1]);
		const double M = fmax(p, m->initial_reference_pressure) / m->swelling_index + 4.0 / 3.0 * m->shear_modulus;
		CHECK(e.body == 0 && rel_diff(e.modulus, M, 1) < 1e-9 &&
		      rel_diff(e.cfl, c->grid.cell_size / sqrt(M / ((1 - b->porosity) * m->density)), 1e-30) < 1e-9,
		      "nor-sand CFL step from p / kappa + 4G/3", "modulus %.6g against %.6g, cfl %.6g", e.modulus, M,
		      e.cfl);
		CHECK(c->time.dt < stable_dt_max(&e), "the dense landslide's dt is below the bound", "dt %.6g, bound %.6g",
		      c->time.dt, stable_dt_max(&e));
	} else {
		CHECK(0, "nor-sand CFL step from p / kappa + 4G/3", "%s", err.message);
	}
	case_destroy(&c);
}

/* The explicit scheme's keys (case_formulation.c): each refused with its pointer, and a valid
 * explicit case read with every key (002 §4.1's column, cases/terzaghi_002.json). */
static void test_explicit_scheme(const char *root)
{
	char path[512];
	snprintf(path, sizeof path, "%stests/cases/terzaghi_002.json", root);
	char *base = NULL;
	struct poro_error err = {0};
	if (case_read_text(path, &base, &err)) {
		CHECK(0, "explicit case readable", "%s", err.message);
		return;
	}
	const struct {
		const char *name, *pointer, *value, *needle;
	} bad[] = {
		{"explicit scheme is single point", "/formulation/phases", "\"double_point\"",
		 "/formulation/phases: the \"explicit\" scheme is single point"},
		{"semi-implicit key under explicit", "/formulation/drag_in_correction", "true",
		 "/formulation/drag_in_correction: applies to the \"semi_implicit\" scheme only, not to \"explicit\""},
		{"unknown smoothing", "/formulation/strain_rate_smoothing", "\"cell\"",
		 "/formulation/strain_rate_smoothing: must be one of 'cell_average', 'none'"},
		{"unknown drag", "/formulation/drag", "\"lumped\"", "/formulation/drag: must be one of"},
		{"basis without projection", "/formulation/pressure_rate_basis", "\"linear\"", NULL},
		{"dt neither number nor auto", "/time/dt", "\"fast\"",
		 "/time/dt: expected a number or \"auto\", got \"fast\""},
		{"dt above the critical step", "/time/dt", "1e-4", "h / c_fast"},
		{"initial pore pressure not a number", "/bodies/0/initial_pore_pressure", "\"1e4\"",
		 "/bodies/0/initial_pore_pressure: expected a number, got string"},
		{"sinusoid start before 0", "/loads/0/time_function",
		 "{\"kind\": \"sinusoid\", \"frequency\": 2.5, \"amplitude\": 1, \"start\": -0.1}",
		 "/loads/0/time_function/start: must be >= 0"},
		{"drained face with held water", "/boundaries/bottom", "{\"soil\": \"fixed\", \"water\": \"slip\", "
		 "\"drainage\": \"drained\"}", "/boundaries/bottom/drainage: \"drained\" needs \"water\": \"free\""},
		{"plate under explicit", "/boundaries/top", "{\"soil\": \"plate\", \"water\": \"plate\", "
		 "\"plate\": {\"force\": 1000}}", "/boundaries/top/soil: \"plate\" applies to the \"semi_implicit\" scheme only"},
		{"cavitation under explicit", "/fluid/cavitation_pressure", "-1e5",
		 "/fluid/cavitation_pressure: applies to the \"semi_implicit\" scheme only"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
		struct edit e[2] = {{bad[i].pointer, bad[i].value}, {"/formulation/pressure_rate_projection", "\"none\""}};
		const char *needles[] = {bad[i].needle ? bad[i].needle
						       : "/formulation/pressure_rate_basis: needs /formulation/pressure_rate_projection",
					 NULL};
		expect_invalid_edits(bad[i].name, base, e, bad[i].needle ? 1 : 2, needles);
	}
	/* an explicit key under the semi-implicit scheme */
	const struct edit semi[] = {{"/formulation", "{\"scheme\": \"semi_implicit\", \"phases\": \"single_point\", "
				     "\"drag\": \"explicit\"}"}};
	const char *semi_needle[] = {"/formulation/drag: applies to the \"explicit\" scheme only, not to \"semi_implicit\"",
				     NULL};
	expect_invalid_edits("explicit key under semi-implicit", base, semi, 1, semi_needle);
	const struct edit all[] = {{"/formulation", "{\"scheme\": \"explicit\", \"phases\": \"single_point\", "
				    "\"shape\": \"gimp\", \"strain_rate_smoothing\": \"none\", \"pressure_rate_projection\": "
				    "\"multi_field\", \"pressure_rate_basis\": \"linear\", \"drag\": \"explicit\", "
				    "\"flip_fraction\": 0.95}"}, {"/time/dt", "\"auto\""}};
	char *text = edited(base, all, 2);
	struct case_spec *c = load_valid("explicit case with every key", text);
	CHECK(c && c->formulation.scheme == SCHEME_EXPLICIT && c->formulation.shape == SHAPE_GIMP &&
	      c->formulation.strain_rate_smoothing == STRAIN_RATE_SMOOTHING_NONE &&
	      c->formulation.pressure_rate_projection == PRESSURE_RATE_MULTI_FIELD &&
	      c->formulation.pressure_rate_basis == PRESSURE_RATE_BASIS_LINEAR && c->formulation.drag == DRAG_EXPLICIT &&
	      c->time.dt_auto && c->time.dt > 0 && c->bodies[0].initial_pore_pressure == 1e4,
	      "explicit keys read", "case %p", (void *)c);
	case_destroy(&c);
	free(text);
	free(base);
}

/* The implicit u-p-U scheme's keys (case_formulation.c): each refused with its pointer, and a
 * valid implicit case read with every key (cases/terzaghi_001.json). */
static void test_implicit_scheme(const char *root)
{
	char path[512];
	snprintf(path, sizeof path, "%stests/cases/terzaghi_001.json", root);
	char *base = NULL;
	struct poro_error err = {0};
	if (case_read_text(path, &base, &err)) {
		CHECK(0, "implicit case readable", "%s", err.message);
		return;
	}
	const struct {
		const char *name, *pointer, *value, *needle;
	} bad[] = {
		{"implicit scheme is single point", "/formulation/phases", "\"double_point\"",
		 "/formulation/phases: the \"implicit_upU\" scheme is single point"},
		{"explicit key under implicit", "/formulation/drag", "\"implicit\"",
		 "/formulation/drag: applies to the \"explicit\" scheme only, not to \"implicit_upU\""},
		{"APIC under implicit", "/formulation/velocity_update", "\"apic\"",
		 "/formulation/velocity_update: the \"implicit_upU\" scheme moves its points' velocities by Newmark"},
		{"PIC blend under implicit", "/formulation/flip_fraction", "0.5",
		 "/formulation/flip_fraction: the \"implicit_upU\" scheme moves its points' velocities by Newmark"},
		{"F-bar under implicit", "/formulation/soil_stabilisation", "\"fbar\"",
		 "/formulation/soil_stabilisation: must be one of 'none', 'bbar'"},
		{"Newmark beta below stability", "/formulation/newmark_beta", "0.2",
		 "/formulation/newmark_beta: with newmark_gamma 0.5 must be at least 0.25"},
		{"Newmark gamma above 1", "/formulation/newmark_gamma", "1.5", "/formulation/newmark_gamma: must be"},
		{"tolerance of 1", "/formulation/newton_tolerance", "1", "/formulation/newton_tolerance: must be"},
		{"no iterations", "/formulation/newton_max_iterations", "0", "/formulation/newton_max_iterations: must be"},
		{"unknown recovery", "/formulation/pressure_recovery", "\"spr\"",
		 "/formulation/pressure_recovery: must be one of 'mlsa_patch', 'mlsa_nodal', 'none'"},
		{"unknown mass matrix", "/formulation/mass_matrix", "\"diagonal\"",
		 "/formulation/mass_matrix: must be one of 'consistent', 'lumped'"},
		{"auto dt under implicit", "/time/dt", "\"auto\"", "/time/dt: \"auto\" has no meaning for the \"implicit_upU\""},
		{"B-bar without uGIMP", "/formulation/shape", "\"linear\"",
		 "/formulation/soil_stabilisation: \"bbar\" samples uGIMP at the cell centres"},
		{"grain bulk modulus not positive", "/fluid/grain_bulk_modulus", "0", "/fluid/grain_bulk_modulus: must be"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
		struct edit e[1] = {{bad[i].pointer, bad[i].value}};
		const char *needles[] = {bad[i].needle, NULL};
		expect_invalid_edits(bad[i].name, base, e, 1, needles);
	}
	const struct edit semi[] = {{"/formulation", "{\"scheme\": \"semi_implicit\", \"newmark_beta\": 0.3}"}};
	const char *semi_needle[] = {"/formulation/newmark_beta: applies to the \"implicit_upU\" scheme only", NULL};
	expect_invalid_edits("implicit key under semi-implicit", base, semi, 1, semi_needle);
	const struct edit grain[] = {{"/formulation", "{\"scheme\": \"semi_implicit\"}"},
				     {"/fluid/grain_bulk_modulus", "1e10"}};
	const char *grain_needle[] = {"/fluid/grain_bulk_modulus: applies to the \"implicit_upU\" scheme only", NULL};
	expect_invalid_edits("grain bulk modulus under semi-implicit", base, grain, 2, grain_needle);
	const struct edit all[] = {{"/formulation", "{\"scheme\": \"implicit_upU\", \"phases\": \"single_point\", "
				    "\"shape\": \"gimp\", \"soil_stabilisation\": \"bbar\", \"newmark_beta\": 0.3025, "
				    "\"newmark_gamma\": 0.6, \"tangent\": \"consistent\", \"newton_tolerance\": 1e-8, "
				    "\"newton_max_iterations\": 20, \"pressure_recovery\": \"mlsa_nodal\", "
				    "\"mass_matrix\": \"lumped\"}"}, {"/fluid/grain_bulk_modulus", "1e10"}};
	char *text = edited(base, all, 2);
	struct case_spec *c = load_valid("implicit case with every key", text);
	const struct case_formulation *f = c ? &c->formulation : NULL;
	CHECK(c && f->scheme == SCHEME_IMPLICIT_UPU && f->soil_stabilisation == STABILISATION_BBAR &&
	      f->newmark_beta == 0.3025 && f->newmark_gamma == 0.6 && f->tangent == NEWTON_TANGENT_CONSISTENT &&
	      f->newton_tolerance == 1e-8 && f->newton_max_iterations == 20 &&
	      f->pressure_recovery == PRESSURE_RECOVERY_MLSA_NODAL && f->mass_matrix == MASS_MATRIX_LUMPED &&
	      c->fluid.grain_bulk_modulus == 1e10, "implicit keys read", "case %p", (void *)c);
	case_destroy(&c);
	free(text);
	/* without phases the scheme's single point is the default */
	const struct edit bare[] = {{"/formulation", "{\"scheme\": \"implicit_upU\", \"shape\": \"gimp\"}"}};
	text = edited(base, bare, 1);
	c = load_valid("implicit case without phases", text);
	CHECK(c && c->formulation.phases == PHASES_SINGLE_POINT && c->formulation.soil_stabilisation == STABILISATION_BBAR,
	      "implicit defaults: single point, B-bar", "case %p", (void *)c);
	case_destroy(&c);
	free(text);
	free(base);
}

int main(void)
{
	char root[256];
	repository_root(root, sizeof root);
	test_minimal();
	test_full();
	test_cavitation_keys();
	test_plate();
	test_malformed();
	test_wrong_types();
	test_out_of_range();
	test_unknown_keys();
	test_schema_location();
	test_references_and_geometry();
	test_missing_required();
	test_duplicates();
	test_many_errors();
	test_unreadable_file();
	test_shipped_cases(root);
	test_documented_example(root);
	test_stable_dt(root);
	test_explicit_scheme(root);
	test_implicit_scheme(root);
	HARNESS_EXIT();
}
