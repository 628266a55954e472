/*
 * case_load.c - loads a case spec (case.h) from JSON and validates it completely.
 *
 * The document is read section by section in the order of schemas/case.schema.json, through the
 * typed reads of case_json.h, straight into a zeroed struct case_spec that already holds every
 * default. A problem never stops the reading: each is recorded as "JSON-pointer: message" and the
 * next value is read, so the caller gets all of them at once. Only a case with no problem at all is
 * returned; otherwise it is destroyed here.
 *
 * Checks that involve two values (extent against cell size, dt against end, a body or probe
 * against the grid, a load span against its body's face) are made only when both values were read
 * without a problem, so one mistake gives one line, not a cascade. Name references (a body's
 * material, a load's body) are resolved against the items read before them, which is why
 * materials come before bodies and bodies before loads.
 *
 * Geometric tolerances are relative to the grid extent (CASE_GRID_TOLERANCE), so a body that ends
 * exactly on the grid edge, written with decimal rounding, still lies inside. The regions
 * themselves (boxes, polygons) are read in case_region.c.
 *
 * The cost of a check is linear in the document: names go into hash tables as they are read
 * (struct case_names), a list longer than its limit (case.h) is refused whole without reading its
 * items, and the work a case implies (grid cells, material points, time steps, frames,
 * checkpoints) is checked against its limit as soon as the values it follows from are known.
 */
#include "case.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_json.h"
#include "case_metrics.h"
#include "case_formulation.h"
#include "case_material.h"
#include "case_region.h"
#include "stable_dt.h"

/* Defaults of optional values (documented in schemas/case.schema.json and docs/case-spec.md). */
#define DEFAULT_FLUID_DENSITY 1000.0      /* kg/m^3, water */
#define DEFAULT_FLUID_BULK_MODULUS 2.2e9  /* Pa, water */
#define DEFAULT_CAVITATED_BULK_MODULUS 1e6 /* Pa: cavitation.c, docs/numerics.md "Cavitation" */
#define DEFAULT_GRAVITY_Y -9.81           /* m/s^2 */
#define DEFAULT_PROGRESS_INTERVAL 1.0     /* s of wall time */

/* Limits. */
/* Cells per direction: room for the B-splines' edge treatment (shape.h) and the semi-implicit
 * scheme's pressure stencils; uGIMP's support fits in 2, which the explicit and implicit schemes take (002
 * §4.1's column is 2 cells wide). */
#define GRID_CELLS_MIN 3
#define GRID_CELLS_MIN_NARROW 2
#define PARTICLES_PER_CELL_MIN 1
#define PARTICLES_PER_CELL_MAX 8

static const struct case_range POSITIVE = { BOUND_OPEN, 0, BOUND_NONE, 0 };
static const struct case_range NON_NEGATIVE = { BOUND_CLOSED, 0, BOUND_NONE, 0 };
static const struct case_range POROSITY = { BOUND_OPEN, 0, BOUND_OPEN, 1 };
static const struct case_range NEGATIVE = { BOUND_NONE, 0, BOUND_OPEN, 0 };

/* Names of enum values, in enum order. */
static const char *const schema_names[] = { CASE_SCHEMA_VERSION, NULL };
static const char *const permeability_law_names[] = { "constant", "kozeny_carman", "volume_ratio",
							       "volume_ratio_squared", NULL };
static const char *const constraint_names[] = { "free", "slip", "fixed", "plate", NULL };
static const char *const drainage_names[] = { "impermeable", "drained", NULL };
static const char *const face_names[] = { "left", "right", "bottom", "top", NULL };
static const char *const time_function_names[] = { "constant", "ramp", "sinusoid", NULL };
static const char *const probe_kind_names[] = { "pore_pressure", "displacement", "average", NULL };
static const char *const probe_field_names[] = { "pore_pressure", "stress_xx", "stress_yy", "stress_xy",
						 "displacement_x", "displacement_y", NULL };
static const char *const component_names[] = { "x", "y", NULL };

/* Keys allowed in each object. */
static const char *const top_keys[] = { "$schema", "schema", "title", "formulation", "grid", "materials", "bodies",
					"fluid", "gravity", "boundaries", "loads", "time", "output",
					"probes", "checkpoint", "metrics", NULL };
static const char *const grid_keys[] = { "origin", "extent", "cell_size", NULL };
/* A material's own keys; its model's keys are checked by case_read_material_model(). */
static const char *const material_keys[] = { "name", "density", NULL };
static const char *const body_keys[] = { "name", "material", "rectangle", "polygon", "particles_per_cell",
					 "porosity", "hydraulic_conductivity", "permeability_law", "saturated",
					 "initial_pore_pressure", NULL };
static const char *const fluid_keys[] = { "density", "bulk_modulus", "grain_bulk_modulus", "cavitation_pressure",
					  "cavitated_bulk_modulus", NULL };
static const char *const gravity_keys[] = { "acceleration", "ramp_time", "elastic_loading", "loading_conductivity",
						"water_attached", NULL };
static const char *const face_boundary_keys[] = { "soil", "water", "drainage", "plate", NULL };
static const char *const plate_keys[] = { "force", "time_function", NULL };
static const char *const load_keys[] = { "body", "face", "from", "to", "traction", "time_function", NULL };
static const char *const time_keys[] = { "dt", "end", NULL };
static const char *const output_keys[] = { "frame_interval", "progress_interval", NULL };
static const char *const checkpoint_keys[] = { "interval", NULL };
/* Keys of a time function and of a probe depend on its kind; the last entry is the union, used
 * when the kind itself is missing or wrong. */
static const char *const *const time_function_keys[] = {
	(const char *const[]){ "kind", NULL },
	(const char *const[]){ "kind", "ramp_time", NULL },
	(const char *const[]){ "kind", "frequency", "amplitude", "mean", "phase", "start", NULL },
	(const char *const[]){ "kind", "ramp_time", "frequency", "amplitude", "mean", "phase", "start", NULL },
};
static const char *const *const probe_keys[] = {
	(const char *const[]){ "name", "kind", "point", NULL },
	(const char *const[]){ "name", "kind", "point", "component", NULL },
	(const char *const[]){ "name", "kind", "field", "box", NULL },
	(const char *const[]){ "name", "kind", "point", "component", "field", "box", NULL },
};

/* A choice read into an enum: the chosen index, or fallback when absent or invalid. */
static int read_choice_or(struct case_reader *r, const json_t *obj, const char *base, const char *key,
			  enum case_need need, const char *const *names, int fallback)
{
	int value = fallback;
	case_read_choice(r, obj, base, key, need, names, &value);
	return value;
}

/* Zeroed array of n items for a case list; NULL for none or on failure (then noted in r). */
static void *alloc_items(struct case_reader *r, size_t n, size_t size)
{
	if (n == 0)
		return NULL;
	void *items = n <= INT_MAX ? calloc(n, size) : NULL;
	if (!items)
		r->out_of_memory = 1;
	return items;
}

/* Adds item i's name (when it was read) to names, and records "LIST/i/name: duplicate KIND name
 * 'NAME', also at LIST/earlier" when an earlier item has it. */
static void check_unique(struct case_reader *r, struct case_names *names, const char *list, int i,
			 const char *kind, const char *name)
{
	char item[CASE_POINTER_MAX], pointer[CASE_POINTER_MAX];
	int earlier = name[0] ? case_names_add(r, names, name, i) : -1;
	if (earlier < 0)
		return;
	case_pointer_index(item, list, (size_t)i);
	case_pointer_key(pointer, item, "name");
	case_problem(r, pointer, "duplicate %s name '%s', also at %s/%d", kind, name, list, earlier);
}

static void read_header(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	int version;
	const char *schema_location;
	/* "$schema" names the JSON Schema for editors (VS Code and others validate and complete
	 * against it); the solver only checks that it is a string */
	case_read_string(r, root, "", "$schema", CASE_OPTIONAL, &schema_location);
	case_read_choice(r, root, "", "schema", CASE_REQUIRED, schema_names, &version);
	case_read_short_text(r, root, "", "title", CASE_OPTIONAL, CASE_TITLE_MAX, c->title);
}

/* Checks that extent[d] is a whole number, at least `least` (GRID_CELLS_MIN...), of cells. */
static int check_cell_count(struct case_reader *r, const struct case_grid *g, int d, int least)
{
	char pointer[CASE_POINTER_MAX], h[CASE_NUMBER_SIZE], got[CASE_NUMBER_SIZE];
	case_pointer_index(pointer, "/grid/extent", (size_t)d);
	double cells = round(g->extent[d] / g->cell_size);
	if (fabs(g->extent[d] - cells * g->cell_size) > CASE_GRID_TOLERANCE * g->extent[d] || cells < 1) {
		case_problem(r, pointer, "must be a positive multiple of /grid/cell_size (%s), got %s",
			     case_format_number(h, g->cell_size), case_format_number(got, g->extent[d]));
		return 0;
	}
	if (cells < least) {
		case_problem(r, pointer, "must span at least %d cells of /grid/cell_size, got %.0f",
			     least, cells);
		return 0;
	}
	return 1;
}

/* Returns 1 when the grid is complete and valid, so bodies and probes can be checked against it. */
static int read_grid(struct case_reader *r, const json_t *root, const struct case_formulation *form,
		     struct case_grid *g)
{
	const char *p = "/grid";
	const json_t *o = case_read_object(r, root, "", "grid", CASE_REQUIRED);
	if (!o)
		return 0;
	case_check_keys(r, o, p, grid_keys);
	int ok = case_read_vec2(r, o, p, "origin", CASE_REQUIRED, NULL, g->origin);
	int extent_ok = case_read_vec2(r, o, p, "extent", CASE_REQUIRED, &POSITIVE, g->extent);
	int cell_size_ok = case_read_number(r, o, p, "cell_size", CASE_REQUIRED, &POSITIVE, &g->cell_size);
	if (extent_ok && cell_size_ok) {
		const int least = form->shape == SHAPE_GIMP && form->scheme != SCHEME_SEMI_IMPLICIT ? GRID_CELLS_MIN_NARROW
												: GRID_CELLS_MIN;
		extent_ok &= check_cell_count(r, g, 0, least);
		extent_ok &= check_cell_count(r, g, 1, least);
	}
	/* checked before anything is sized from the grid; each direction is then below 2^31 too */
	if (extent_ok && cell_size_ok)
		extent_ok = case_check_limit(r, p, "have", "cells", round(g->extent[0] / g->cell_size) *
					     round(g->extent[1] / g->cell_size), CASE_CELLS_MAX);
	return ok && extent_ok && cell_size_ok;
}

static void read_material(struct case_reader *r, const json_t *o, const char *p, struct case_material *m)
{
	case_read_name(r, o, p, "name", CASE_REQUIRED, m->name, sizeof m->name);
	case_read_material_model(r, o, p, material_keys, m);
	case_read_number(r, o, p, "density", CASE_REQUIRED, &POSITIVE, &m->density);
}

/* Returns 1 when the list was there to be read, so names can be looked up in it. */
static int read_materials(struct case_reader *r, const json_t *root, struct case_spec *c,
			  struct case_names *names)
{
	size_t n;
	const json_t *a = case_read_list(r, root, "", "materials", CASE_REQUIRED, CASE_MATERIALS_MAX, "materials", &n);
	if (a && n == 0)
		case_problem(r, "/materials", "must list at least one material");
	if (!a || !(c->materials = alloc_items(r, n, sizeof *c->materials)))
		return a != NULL;
	c->material_count = (int)n;
	for (int i = 0; i < c->material_count; i++) {
		char p[CASE_POINTER_MAX];
		struct case_material *m = &c->materials[i];
		case_pointer_index(p, "/materials", (size_t)i);
		if (!case_expect_object(r, case_array_item(a, (size_t)i), p))
			continue;
		read_material(r, case_array_item(a, (size_t)i), p, m);
		check_unique(r, names, "/materials", i, "material", m->name);
	}
	return 1;
}

/* Resolves the material name of a body to an index; -1 when unknown, or when the list could not
 * be read (materials NULL: its problem is already recorded, and one line per body would repeat it). */
static int read_material_ref(struct case_reader *r, const json_t *o, const char *p,
			     const struct case_names *materials)
{
	char pointer[CASE_POINTER_MAX], shown[CASE_QUOTE_SIZE];
	const char *name;
	if (!case_read_string(r, o, p, "material", CASE_REQUIRED, &name))
		return -1;
	int index = materials ? case_names_find(materials, name) : -1;
	if (index < 0 && materials) {
		case_pointer_key(pointer, p, "material");
		case_problem(r, pointer, "unknown material '%s'", case_quote(shown, name));
	}
	return index;
}

/* Returns 1 when the body's region and particles_per_cell were read, so its points can be counted. */
static int read_body(struct case_reader *r, const json_t *o, const char *p, const struct case_spec *c,
		     int grid_ok, const struct case_names *materials, struct case_body *b)
{
	case_check_keys(r, o, p, body_keys);
	case_read_name(r, o, p, "name", CASE_REQUIRED, b->name, sizeof b->name);
	b->material = read_material_ref(r, o, p, materials);
	int seeded = case_read_region(r, o, p, b);
	if (seeded && grid_ok)
		case_check_inside_grid(r, p, "body", &c->grid, b->min, b->max);
	seeded &= case_read_int(r, o, p, "particles_per_cell", CASE_REQUIRED, PARTICLES_PER_CELL_MIN,
				PARTICLES_PER_CELL_MAX, &b->particles_per_cell);
	case_read_number(r, o, p, "porosity", CASE_REQUIRED, &POROSITY, &b->porosity);
	case_read_number(r, o, p, "hydraulic_conductivity", CASE_REQUIRED, &POSITIVE,
			 &b->hydraulic_conductivity);
	b->permeability_law = read_choice_or(r, o, p, "permeability_law", CASE_OPTIONAL,
					     permeability_law_names, b->permeability_law);
	case_read_number(r, o, p, "initial_pore_pressure", CASE_OPTIONAL, NULL, &b->initial_pore_pressure);
	b->saturated = 1;
	if (case_read_bool(r, o, p, "saturated", CASE_OPTIONAL, &b->saturated) && !b->saturated &&
	    c->formulation.pressure_projection != PROJECTION_LAPLACIAN) {
		/* measured with the Laplacian only: the consistent projection's low-permeability options
		 * diverged on a dry fill (docs/numerics.md, "Dry bodies") */
		char pointer[CASE_POINTER_MAX];
		case_pointer_key(pointer, p, "saturated");
		case_problem(r, pointer, "false needs /formulation/pressure_projection \"laplacian\": a dry body's "
			     "contact is verified with it alone");
	}
	if (!b->saturated && c->formulation.scheme != SCHEME_SEMI_IMPLICIT) {
		/* the other schemes' single-point water rides on every soil point */
		char pointer[CASE_POINTER_MAX];
		case_pointer_key(pointer, p, "saturated");
		case_problem(r, pointer, "false applies to the \"semi_implicit\" scheme only");
	}
	if (!b->saturated && b->initial_pore_pressure != 0.0) {
		char pointer[CASE_POINTER_MAX];
		case_pointer_key(pointer, p, "initial_pore_pressure");
		case_problem(r, pointer, "a dry body (\"saturated\": false) has no pore water to hold a pressure");
	}
	return seeded;
}

/* Returns 1 when the list was there to be read (materials NULL: the materials' list was not). */
static int read_bodies(struct case_reader *r, const json_t *root, struct case_spec *c, int grid_ok,
		       const struct case_names *materials, struct case_names *names)
{
	size_t n;
	const json_t *a = case_read_list(r, root, "", "bodies", CASE_REQUIRED, CASE_BODIES_MAX, "bodies", &n);
	if (a && n == 0)
		case_problem(r, "/bodies", "must list at least one body");
	if (!a || !(c->bodies = alloc_items(r, n, sizeof *c->bodies)))
		return a != NULL;
	c->body_count = (int)n;
	double points = 0, vertices = 0;
	for (int i = 0; i < c->body_count; i++) {
		char p[CASE_POINTER_MAX];
		struct case_body *b = &c->bodies[i];
		b->material = -1;
		case_pointer_index(p, "/bodies", (size_t)i);
		if (!case_expect_object(r, case_array_item(a, (size_t)i), p))
			continue;
		if (read_body(r, case_array_item(a, (size_t)i), p, c, grid_ok, materials, b) && grid_ok)
			points += case_body_points(&c->grid, b);
		vertices += b->polygon_count;
		check_unique(r, names, "/bodies", i, "body", b->name);
	}
	case_check_limit(r, "/bodies", "have", "polygon vertices in all", vertices, CASE_POLYGON_VERTICES_MAX);
	case_check_limit(r, "/bodies", "seed", "material points (area / cell_size^2 x particles_per_cell^2)",
			 points, CASE_POINTS_MAX);
	return 1;
}

static void read_fluid(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	const json_t *o = case_read_object(r, root, "", "fluid", CASE_OPTIONAL);
	if (!o)
		return;
	case_check_keys(r, o, "/fluid", fluid_keys);
	case_read_number(r, o, "/fluid", "density", CASE_OPTIONAL, &POSITIVE, &c->fluid.density);
	case_read_number(r, o, "/fluid", "bulk_modulus", CASE_OPTIONAL, &POSITIVE, &c->fluid.bulk_modulus);
	case_read_number(r, o, "/fluid", "grain_bulk_modulus", CASE_OPTIONAL, &POSITIVE, &c->fluid.grain_bulk_modulus);
	case_read_number(r, o, "/fluid", "cavitation_pressure", CASE_OPTIONAL, &NEGATIVE,
			 &c->fluid.cavitation_pressure);
	case_read_number(r, o, "/fluid", "cavitated_bulk_modulus", CASE_OPTIONAL, &POSITIVE,
			 &c->fluid.cavitated_bulk_modulus);
	const int cavitates = case_has_key(o, "cavitation_pressure");
	if (!cavitates && case_has_key(o, "cavitated_bulk_modulus"))
		case_problem(r, "/fluid/cavitated_bulk_modulus", "needs /fluid/cavitation_pressure");
	/* measured with the nodal condition only (docs/numerics.md, "Cavitation") */
	if (cavitates && c->formulation.free_surface != FREE_SURFACE_NODES)
		case_problem(r, "/fluid/cavitation_pressure", "needs /formulation/free_surface \"nodes\"");
}

static void read_gravity(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	const json_t *o = case_read_object(r, root, "", "gravity", CASE_OPTIONAL);
	if (!o)
		return;
	case_check_keys(r, o, "/gravity", gravity_keys);
	case_read_vec2(r, o, "/gravity", "acceleration", CASE_OPTIONAL, NULL, c->gravity.acceleration);
	case_read_number(r, o, "/gravity", "ramp_time", CASE_OPTIONAL, &NON_NEGATIVE, &c->gravity.ramp_time);
	case_read_bool(r, o, "/gravity", "elastic_loading", CASE_OPTIONAL, &c->gravity.elastic_loading);
	if (c->gravity.elastic_loading && !(c->gravity.ramp_time > 0))
		case_problem(r, "/gravity/elastic_loading", "needs a gravity ramp_time > 0: the elastic loading lasts "
			     "as long as the ramp");
	case_read_number(r, o, "/gravity", "loading_conductivity", CASE_OPTIONAL, &POSITIVE,
			 &c->gravity.loading_conductivity);
	case_read_bool(r, o, "/gravity", "water_attached", CASE_OPTIONAL, &c->gravity.water_attached);
	if ((c->gravity.loading_conductivity > 0 || c->gravity.water_attached) && !(c->gravity.ramp_time > 0))
		case_problem(r, c->gravity.water_attached ? "/gravity/water_attached" : "/gravity/loading_conductivity",
			     "needs a gravity ramp_time > 0: it acts while gravity ramps up");
}

static void read_time_function(struct case_reader *r, const json_t *o, const char *base,
			       struct case_time_function *tf);

/* The rigid plate of a face whose soil is "plate" (solver/schemes/semi_implicit/plate.c): its "plate" object, required
 * there and refused elsewhere. The plate is impermeable: the water's constraint is "plate" too,
 * moving with it. */
static void read_plate(struct case_reader *r, const json_t *face, const char *p, struct case_boundary *b)
{
	char pointer[CASE_POINTER_MAX];
	const int soil = b->soil == CONSTRAINT_PLATE;
	case_pointer_key(pointer, p, "water");
	if (b->water == CONSTRAINT_PLATE && !soil)
		case_problem(r, pointer, "\"plate\" needs the soil to be \"plate\" on the same face");
	else if (soil && b->water != CONSTRAINT_PLATE)
		case_problem(r, pointer, "must be \"plate\" under a plate (it is impermeable: the water moves "
			     "with it), got \"%s\"", constraint_names[b->water]);
	const json_t *o = case_read_object(r, face, p, "plate", soil ? CASE_REQUIRED : CASE_OPTIONAL);
	case_pointer_key(pointer, p, "plate");
	if (o && !soil) {
		case_problem(r, pointer, "needs \"soil\": \"plate\" on the same face");
		return;
	}
	if (!o)
		return;
	if (b->drainage == DRAINAGE_DRAINED) {
		char drainage[CASE_POINTER_MAX];
		case_pointer_key(drainage, p, "drainage");
		case_problem(r, drainage, "must be \"impermeable\" under a plate (no water passes it)");
	}
	case_check_keys(r, o, pointer, plate_keys);
	case_read_number(r, o, pointer, "force", CASE_REQUIRED, NULL, &b->plate.force);
	read_time_function(r, o, pointer, &b->plate.time_function);
}

/* A plate's nodes share one normal velocity, so a neighbouring face may not fix that component at
 * the corner they share ("fixed" there would hold the whole plate). The plate's velocity is solved
 * with the pressure through the Laplacian's right-hand side (plate.c); the consistent projection
 * leaves wall components out of its system, so it is refused with a plate. */
static void check_plates(struct case_reader *r, const struct case_spec *c)
{
	const struct case_boundary *faces = c->boundaries;
	for (int f = 0; f < FACE_COUNT; f++) {
		if (faces[f].soil != CONSTRAINT_PLATE)
			continue;
		if (c->formulation.pressure_projection != PROJECTION_LAPLACIAN) {
			char pointer[CASE_POINTER_MAX];
			case_pointer_key(pointer, "/boundaries", face_names[f]);
			case_problem(r, pointer, "a plate needs formulation.pressure_projection \"laplacian\"");
		}
		const int first = f < FACE_BOTTOM ? FACE_BOTTOM : FACE_LEFT;   /* the faces across the plate */
		for (int g = first; g < first + 2; g++) {
			if (faces[g].soil != CONSTRAINT_FIXED && faces[g].water != CONSTRAINT_FIXED)
				continue;
			char pointer[CASE_POINTER_MAX];
			case_pointer_key(pointer, "/boundaries", face_names[g]);
			case_problem(r, pointer, "cannot be \"fixed\" beside the plate on the %s face: their corner "
				     "would hold the plate (use \"slip\")", face_names[f]);
		}
	}
}

static void read_boundaries(struct case_reader *r, const json_t *root, struct case_boundary *faces)
{
	const json_t *o = case_read_object(r, root, "", "boundaries", CASE_OPTIONAL);
	if (!o)
		return;
	case_check_keys(r, o, "/boundaries", face_names);
	for (int f = 0; f < FACE_COUNT; f++) {
		char p[CASE_POINTER_MAX];
		struct case_boundary *b = &faces[f];
		const json_t *face = case_read_object(r, o, "/boundaries", face_names[f], CASE_OPTIONAL);
		if (!face)
			continue;
		case_pointer_key(p, "/boundaries", face_names[f]);
		case_check_keys(r, face, p, face_boundary_keys);
		b->soil = read_choice_or(r, face, p, "soil", CASE_OPTIONAL, constraint_names, b->soil);
		b->water = read_choice_or(r, face, p, "water", CASE_OPTIONAL, constraint_names, b->water);
		b->drainage = read_choice_or(r, face, p, "drainage", CASE_OPTIONAL, drainage_names,
					     b->drainage);
		read_plate(r, face, p, b);
	}
}

static void read_time_function(struct case_reader *r, const json_t *o, const char *base,
			       struct case_time_function *tf)
{
	char p[CASE_POINTER_MAX];
	const json_t *t = case_read_object(r, o, base, "time_function", CASE_OPTIONAL);
	if (!t)
		return;
	case_pointer_key(p, base, "time_function");
	int kind = TIME_SINUSOID + 1;         /* the union of all keys, until the kind is known */
	case_read_choice(r, t, p, "kind", CASE_REQUIRED, time_function_names, &kind);
	case_check_keys(r, t, p, time_function_keys[kind]);
	if (kind > TIME_SINUSOID)
		return;
	tf->kind = kind;
	if (kind == TIME_RAMP)
		case_read_number(r, t, p, "ramp_time", CASE_REQUIRED, &POSITIVE, &tf->ramp_time);
	if (kind != TIME_SINUSOID)
		return;
	case_read_number(r, t, p, "frequency", CASE_REQUIRED, &POSITIVE, &tf->frequency);
	case_read_number(r, t, p, "amplitude", CASE_REQUIRED, NULL, &tf->amplitude);
	case_read_number(r, t, p, "mean", CASE_OPTIONAL, NULL, &tf->mean);
	case_read_number(r, t, p, "phase", CASE_OPTIONAL, NULL, &tf->phase);
	case_read_number(r, t, p, "start", CASE_OPTIONAL, &NON_NEGATIVE, &tf->start);
}

/* Reads from/to, defaulting to the whole face of the body's bounding box (body and face valid),
 * and checks from < to and that the span lies on that face. */
static void read_load_span(struct case_reader *r, const json_t *o, const char *p, const struct case_spec *c,
			   int known, struct case_load *l)
{
	char pointer[CASE_POINTER_MAX], a[CASE_NUMBER_SIZE], b[CASE_NUMBER_SIZE], got[CASE_NUMBER_SIZE];
	const struct case_body *body = known ? &c->bodies[l->body] : NULL;
	if (body && !(body->min[0] < body->max[0] && body->min[1] < body->max[1]))
		body = NULL;                  /* its region was refused: no face to default to or check */
	int axis = l->face == FACE_LEFT || l->face == FACE_RIGHT; /* along the face: y for left/right */
	double lo = body ? body->min[axis] : 0, hi = body ? body->max[axis] : 0;
	l->from = lo;
	l->to = hi;
	int from_given = case_has_key(o, "from"), to_given = case_has_key(o, "to");
	int ok = case_read_number(r, o, p, "from", CASE_OPTIONAL, NULL, &l->from) || !from_given;
	ok &= case_read_number(r, o, p, "to", CASE_OPTIONAL, NULL, &l->to) || !to_given;
	if (!ok || (!body && !(from_given && to_given)))
		return;
	case_pointer_key(pointer, p, "to");
	if (!(l->from < l->to)) {
		case_problem(r, pointer, "must be greater than from (%s), got %s",
			     case_format_number(a, l->from), case_format_number(got, l->to));
		return;
	}
	double slack = CASE_GRID_TOLERANCE * c->grid.extent[axis];
	if (body && (l->from < lo - slack || l->to > hi + slack))
		case_problem(r, p, "from and to must lie on the %s face of body '%s', from %s to %s",
			     face_names[l->face], body->name, case_format_number(a, lo),
			     case_format_number(b, hi));
}

static void read_load(struct case_reader *r, const json_t *o, const char *p, const struct case_spec *c,
		      const struct case_names *bodies, struct case_load *l)
{
	char pointer[CASE_POINTER_MAX], shown[CASE_QUOTE_SIZE];
	const char *name;
	int face;
	case_check_keys(r, o, p, load_keys);
	l->body = -1;
	if (case_read_string(r, o, p, "body", CASE_REQUIRED, &name)) {
		l->body = bodies ? case_names_find(bodies, name) : -1;   /* NULL: the bodies' list was not read */
		case_pointer_key(pointer, p, "body");
		if (l->body < 0 && bodies)
			case_problem(r, pointer, "unknown body '%s'", case_quote(shown, name));
	}
	int face_ok = case_read_choice(r, o, p, "face", CASE_REQUIRED, face_names, &face);
	if (face_ok)
		l->face = face;
	case_read_vec2(r, o, p, "traction", CASE_REQUIRED, NULL, l->traction);
	read_time_function(r, o, p, &l->time_function);
	read_load_span(r, o, p, c, l->body >= 0 && face_ok, l);
}

static void read_loads(struct case_reader *r, const json_t *root, struct case_spec *c,
		       const struct case_names *bodies)
{
	size_t n;
	const json_t *a = case_read_list(r, root, "", "loads", CASE_OPTIONAL, CASE_LOADS_MAX, "loads", &n);
	if (!a || !(c->loads = alloc_items(r, n, sizeof *c->loads)))
		return;
	c->load_count = (int)n;
	for (int i = 0; i < c->load_count; i++) {
		char p[CASE_POINTER_MAX];
		case_pointer_index(p, "/loads", (size_t)i);
		if (case_expect_object(r, case_array_item(a, (size_t)i), p))
			read_load(r, case_array_item(a, (size_t)i), p, c, bodies, &c->loads[i]);
	}
}

/* Returns 1 when dt and end were read and fit, so the frames and checkpoints can be counted. */
static int read_time(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	char end[CASE_NUMBER_SIZE], dt[CASE_NUMBER_SIZE];
	const json_t *o = case_read_object(r, root, "", "time", CASE_REQUIRED);
	if (!o)
		return 0;
	case_check_keys(r, o, "/time", time_keys);
	int ok = case_read_number_or_word(r, o, "/time", "dt", CASE_REQUIRED, &POSITIVE, "auto", &c->time.dt,
					  &c->time.dt_auto);
	ok &= case_read_number(r, o, "/time", "end", CASE_REQUIRED, &POSITIVE, &c->time.end);
	if (ok && c->time.dt_auto && c->formulation.scheme == SCHEME_IMPLICIT_UPU) {
		case_problem(r, "/time/dt", "\"auto\" has no meaning for the \"implicit_upU\" scheme, stable at any "
			     "step: choose dt by the accuracy wanted");
		return 0;
	}
	if (ok && c->time.dt_auto) {
		/* the scheme's recommended step, known once everything it follows from was read */
		struct stable_dt e;
		stable_dt_estimate(c, &e);
		if (r->problem_count || e.body < 0)
			return 0;
		c->time.dt = fmin(stable_dt_recommended(&e), c->time.end);
	}
	if (ok && c->time.dt > c->time.end) {
		case_problem(r, "/time/dt", "must be <= /time/end (%s), got %s",
			     case_format_number(end, c->time.end), case_format_number(dt, c->time.dt));
		return 0;
	}
	return ok && case_check_limit(r, "/time/end", "take", "steps of /time/dt", c->time.end / c->time.dt,
				      CASE_STEPS_MAX);
}

/* The scheme's stable step (stable_dt.h), checked once everything it follows from (grid, materials,
 * bodies, fluid, gravity, time) was read without a problem. */
static void check_stable_dt(struct case_reader *r, const struct case_spec *c)
{
	char dt[CASE_NUMBER_SIZE];
	struct stable_dt e;
	stable_dt_estimate(c, &e);
	if (e.body < 0 || !(c->time.dt > stable_dt_max(&e)))
		return;
	char bound[STABLE_DT_DESCRIPTION_SIZE];
	stable_dt_describe(&e, c, bound, sizeof bound);
	case_problem(r, "/time/dt", "must be at most %.3g s, %s, got %s (or write \"auto\")", stable_dt_max(&e), bound,
		     case_format_number(dt, c->time.dt));
}

/* How many times something due every interval of simulated time happens in a run: at most once a
 * step (run.c), whatever the interval. */
static double events_in_run(const struct case_spec *c, double interval)
{
	return fmin(c->time.end / interval, ceil(c->time.end / c->time.dt));
}

static void read_output(struct case_reader *r, const json_t *root, struct case_spec *c, int time_ok)
{
	const json_t *o = case_read_object(r, root, "", "output", CASE_OPTIONAL);
	if (!o)
		return;
	case_check_keys(r, o, "/output", output_keys);
	if (case_read_number(r, o, "/output", "frame_interval", CASE_OPTIONAL, &NON_NEGATIVE,
			     &c->output.frame_interval) && c->output.frame_interval > 0 && time_ok)
		case_check_limit(r, "/output/frame_interval", "give", "frames over /time/end",
				 events_in_run(c, c->output.frame_interval), CASE_FRAMES_MAX);
	case_read_number(r, o, "/output", "progress_interval", CASE_OPTIONAL, &POSITIVE,
			 &c->output.progress_interval);
}

/* {"interval": s of simulated time}: absent means no checkpoints (interval 0). */
static void read_checkpoint(struct case_reader *r, const json_t *root, struct case_spec *c, int time_ok)
{
	const json_t *o = case_read_object(r, root, "", "checkpoint", CASE_OPTIONAL);
	if (!o)
		return;
	case_check_keys(r, o, "/checkpoint", checkpoint_keys);
	if (case_read_number(r, o, "/checkpoint", "interval", CASE_REQUIRED, &POSITIVE, &c->checkpoint.interval) &&
	    time_ok)
		case_check_limit(r, "/checkpoint/interval", "give", "checkpoints over /time/end",
				 events_in_run(c, c->checkpoint.interval), CASE_CHECKPOINTS_MAX);
}

static void read_probe(struct case_reader *r, const json_t *o, const char *p, const struct case_spec *c,
		       int grid_ok, struct case_probe *probe)
{
	char pointer[CASE_POINTER_MAX];
	int kind = PROBE_AVERAGE + 1;         /* the union of all keys, until the kind is known */
	case_read_name(r, o, p, "name", CASE_REQUIRED, probe->name, sizeof probe->name);
	case_read_choice(r, o, p, "kind", CASE_REQUIRED, probe_kind_names, &kind);
	case_check_keys(r, o, p, probe_keys[kind]);
	if (kind > PROBE_AVERAGE)
		return;
	probe->kind = kind;
	if (kind == PROBE_AVERAGE) {
		probe->field = read_choice_or(r, o, p, "field", CASE_REQUIRED, probe_field_names,
					      probe->field);
		case_pointer_key(pointer, p, "box");
		if (case_read_box(r, o, p, "box", probe->box_min, probe->box_max) && grid_ok)
			case_check_inside_grid(r, pointer, "box", &c->grid, probe->box_min, probe->box_max);
		return;
	}
	case_pointer_key(pointer, p, "point");
	if (case_read_vec2(r, o, p, "point", CASE_REQUIRED, NULL, probe->point) && grid_ok)
		case_check_inside_grid(r, pointer, "point", &c->grid, probe->point, probe->point);
	if (kind == PROBE_DISPLACEMENT)
		probe->component = read_choice_or(r, o, p, "component", CASE_REQUIRED, component_names, 0);
}

static void read_probes(struct case_reader *r, const json_t *root, struct case_spec *c, int grid_ok)
{
	size_t n;
	struct case_names names;
	const json_t *a = case_read_list(r, root, "", "probes", CASE_OPTIONAL, CASE_PROBES_MAX, "probes", &n);
	if (!a || !(c->probes = alloc_items(r, n, sizeof *c->probes)))
		return;
	c->probe_count = (int)n;
	case_names_init(r, &names);
	for (int i = 0; i < c->probe_count; i++) {
		char p[CASE_POINTER_MAX];
		struct case_probe *probe = &c->probes[i];
		case_pointer_index(p, "/probes", (size_t)i);
		if (!case_expect_object(r, case_array_item(a, (size_t)i), p))
			continue;
		read_probe(r, case_array_item(a, (size_t)i), p, c, grid_ok, probe);
		check_unique(r, &names, "/probes", i, "probe", probe->name);
	}
	case_names_release(&names);
}

static void set_defaults(struct case_spec *c)
{
	case_formulation_defaults(&c->formulation);
	c->fluid.density = DEFAULT_FLUID_DENSITY;
	c->fluid.bulk_modulus = DEFAULT_FLUID_BULK_MODULUS;
	c->fluid.cavitated_bulk_modulus = DEFAULT_CAVITATED_BULK_MODULUS;
	c->gravity.acceleration[0] = 0;
	c->gravity.acceleration[1] = DEFAULT_GRAVITY_Y;
	c->gravity.ramp_time = 0;
	for (int f = 0; f < FACE_COUNT; f++) {
		c->boundaries[f].soil = CONSTRAINT_FREE;
		c->boundaries[f].water = CONSTRAINT_FREE;
		c->boundaries[f].drainage = DRAINAGE_IMPERMEABLE;
	}
	c->output.frame_interval = 0;
	c->output.progress_interval = DEFAULT_PROGRESS_INTERVAL;
}

static void read_case(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	case_check_keys(r, root, "", top_keys);
	read_header(r, root, c);
	case_read_formulation(r, root, &c->formulation);
	int grid_ok = read_grid(r, root, &c->formulation, &c->grid);
	struct case_names materials, bodies;
	case_names_init(r, &materials);
	case_names_init(r, &bodies);
	int materials_read = read_materials(r, root, c, &materials);
	int bodies_read = read_bodies(r, root, c, grid_ok, materials_read ? &materials : NULL, &bodies);
	case_names_release(&materials);
	read_fluid(r, root, c);
	read_gravity(r, root, c);
	read_boundaries(r, root, c->boundaries);
	check_plates(r, c);
	case_check_scheme(r, c);
	read_loads(r, root, c, bodies_read ? &bodies : NULL);
	case_names_release(&bodies);
	int time_ok = read_time(r, root, c);
	read_output(r, root, c, time_ok);
	read_probes(r, root, c, grid_ok);
	read_checkpoint(r, root, c, time_ok);
	case_read_metrics(r, root, &c->metrics);
	if (!r->problem_count)
		case_check_metrics(r, c);
	if (!r->problem_count && time_ok)
		check_stable_dt(r, c);
}

/* Reads the document root into a new case; its JSON text is text, or root in canonical form when
 * text is NULL. */
static enum poro_status load_root(struct case_reader *r, const json_t *root, const char *text,
				  struct case_spec **out)
{
	struct case_spec *c = calloc(1, sizeof *c);
	if (c) {
		set_defaults(c);
		r->warnings = c->warnings;
		read_case(r, root, c);
		r->warnings = NULL;
	}
	if (c && !r->out_of_memory && !r->problem_count && !(c->json = text ? strdup(text) : case_json_text(root)))
		r->out_of_memory = 1;
	if (!c || r->out_of_memory) {
		case_destroy(&c);
		return poro_error_set(r->err, PORO_ENOMEM, "out of memory loading a case");
	}
	if (r->problem_count) {
		case_destroy(&c);
		return PORO_EINVAL;
	}
	*out = c;
	return PORO_OK;
}

enum poro_status case_load_string(const char *json, struct case_spec **out, struct poro_error *err)
{
	struct case_reader r = { .err = err };
	*out = NULL;
	if (!json)
		return poro_error_set(err, PORO_EINVAL, "/: no JSON text");
	json_t *root = case_json_parse(&r, json);
	if (!root)
		return PORO_EINVAL;
	enum poro_status status = load_root(&r, root, json, out);
	case_json_free(root);
	return status;
}

enum poro_status case_load_json(const json_t *root, struct case_spec **out, struct poro_error *err)
{
	struct case_reader r = { .err = err };
	*out = NULL;
	if (!case_json_root(&r, root))
		return PORO_EINVAL;
	return load_root(&r, root, NULL, out);
}

enum poro_status case_read_text(const char *path, char **text, struct poro_error *err)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return poro_error_set(err, PORO_EIO, "cannot open '%s': %s", path, strerror(errno));
	size_t capacity = 4096, n = 0;
	char *buffer = malloc(capacity);
	while (buffer) {
		n += fread(buffer + n, 1, capacity - 1 - n, f);
		if (n < capacity - 1 || ferror(f))
			break;
		char *bigger = realloc(buffer, capacity *= 2);
		if (!bigger)
			free(buffer);
		buffer = bigger;
	}
	int failed = ferror(f), saved_errno = errno;
	fclose(f);
	if (!buffer)
		return poro_error_set(err, PORO_ENOMEM, "out of memory reading '%s'", path);
	if (failed) {
		free(buffer);
		return poro_error_set(err, PORO_EIO, "cannot read '%s': %s", path, strerror(saved_errno));
	}
	buffer[n] = '\0';
	if (strlen(buffer) != n) {
		free(buffer);
		return poro_error_set(err, PORO_EINVAL, "/: malformed JSON: '%s' contains a NUL byte", path);
	}
	*text = buffer;
	return PORO_OK;
}

enum poro_status case_load_file(const char *path, struct case_spec **out, struct poro_error *err)
{
	char *text = NULL;
	*out = NULL;
	enum poro_status status = case_read_text(path, &text, err);
	if (status != PORO_OK)
		return status;
	status = case_load_string(text, out, err);
	free(text);
	return status;
}

void case_destroy(struct case_spec **c)
{
	if (!c || !*c)
		return;
	free((*c)->materials);
	free((*c)->bodies);
	free((*c)->loads);
	free((*c)->probes);
	free((*c)->json);
	free(*c);
	*c = NULL;
}

double case_time_function_value(const struct case_time_function *f, double t)
{
	static const double two_pi = 6.283185307179586476925286766559;
	switch (f->kind) {
	case TIME_CONSTANT:
		return 1;
	case TIME_RAMP:
		/* A ramp of zero length is a step; validated cases always have ramp_time > 0. */
		return f->ramp_time > 0 ? fmin(t / f->ramp_time, 1) : 1;
	case TIME_SINUSOID:
		if (t < f->start)
			return 0;   /* the load has not begun */
		return f->mean + f->amplitude * sin(two_pi * f->frequency * (t - f->start) + f->phase);
	}
	return 1;
}
