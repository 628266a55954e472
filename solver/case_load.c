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
 * Geometric tolerances are relative to the grid extent (GRID_TOLERANCE), so a body that ends
 * exactly on the grid edge, written with decimal rounding, still lies inside.
 */
#include "case.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_json.h"
#include "case_material.h"

/* Defaults of optional values (documented in schemas/case.schema.json and docs/case-spec.md). */
#define DEFAULT_FLUID_DENSITY 1000.0      /* kg/m^3, water */
#define DEFAULT_FLUID_BULK_MODULUS 2.2e9  /* Pa, water */
#define DEFAULT_CAVITATED_BULK_MODULUS 1e6 /* Pa: cavitation.c, docs/numerics.md "Cavitation" */
#define DEFAULT_GRAVITY_Y -9.81           /* m/s^2 */
#define DEFAULT_PROGRESS_INTERVAL 1.0     /* s of wall time */
#define DEFAULT_PRESSURE_STABILISATION_FACTOR 10.0 /* the strongest suppression measured without a
						      measurable leak (docs/numerics.md) */
#define DEFAULT_FREE_SURFACE_PENALTY_FACTOR 1e4 /* surface pressure held to about 1e-4 of the interior's,
						   the matrix still well conditioned for CHOLMOD */

/* Limits. */
#define GRID_CELLS_MIN 3                  /* cells per direction: room for a quadratic B-spline */
#define GRID_TOLERANCE 1e-9               /* relative: extent/cell_size integrality, inside-grid tests */
#define POLYGON_VERTICES_MIN 3
#define POLYGON_AREA_TOLERANCE 1e-12      /* |area| / bounding-box area below this counts as zero */
#define PARTICLES_PER_CELL_MIN 1
#define PARTICLES_PER_CELL_MAX 8
#define REGION_SIZE (4 * CASE_NUMBER_SIZE + 16) /* "[x0, y0] to [x1, y1]" */
#define TITLE_MAX (sizeof ((struct case_spec *)0)->title - 1) /* bytes */

static const struct case_range POSITIVE = { BOUND_OPEN, 0, BOUND_NONE, 0 };
static const struct case_range NON_NEGATIVE = { BOUND_CLOSED, 0, BOUND_NONE, 0 };
static const struct case_range FRACTION = { BOUND_CLOSED, 0, BOUND_CLOSED, 1 };
static const struct case_range POROSITY = { BOUND_OPEN, 0, BOUND_OPEN, 1 };
static const struct case_range NEGATIVE = { BOUND_NONE, 0, BOUND_OPEN, 0 };

/* Names of enum values, in enum order. */
static const char *const schema_names[] = { CASE_SCHEMA_VERSION, NULL };
static const char *const scheme_names[] = { "semi_implicit", NULL };
static const char *const phases_names[] = { "double_point", "single_point", NULL };
static const char *const shape_names[] = { "linear", "quadratic_bspline", "cubic_bspline", NULL };
static const char *const projection_names[] = { "laplacian", "consistent", NULL };
static const char *const pressure_stabilisation_names[] = { "none", "second_difference", NULL };
static const char *const free_surface_names[] = { "nodes", "interpolated", "weak", NULL };
static const char *const position_update_names[] = { "grid_velocity", "musl_displacement", NULL };
static const char *const velocity_update_names[] = { "flip", "apic", "aflip", NULL };
static const char *const specific_volume_names[] = { "point", "nodal_average", NULL };
static const char *const stabilisation_names[] = { "none", "fbar", "modified_fbar", "modified_fbar_cellwise",
							   NULL };
static const char *const permeability_law_names[] = { "constant", "kozeny_carman", "volume_ratio",
							       "volume_ratio_squared", NULL };
static const char *const constraint_names[] = { "free", "slip", "fixed", NULL };
static const char *const drainage_names[] = { "impermeable", "drained", NULL };
static const char *const face_names[] = { "left", "right", "bottom", "top", NULL };
static const char *const time_function_names[] = { "constant", "ramp", "sinusoid", NULL };
static const char *const probe_kind_names[] = { "pore_pressure", "displacement", "average", NULL };
static const char *const probe_field_names[] = { "pore_pressure", "stress_xx", "stress_yy", "stress_xy",
						 "displacement_x", "displacement_y", NULL };
static const char *const component_names[] = { "x", "y", NULL };

/* Keys allowed in each object. */
static const char *const top_keys[] = { "schema", "title", "formulation", "grid", "materials", "bodies",
					"fluid", "gravity", "boundaries", "loads", "time", "output",
					"probes", "checkpoint", NULL };
static const char *const formulation_keys[] = { "scheme", "phases", "shape", "pore_pressure_smoothing",
						"flip_fraction", "pressure_projection", "soil_stabilisation",
						"drag_in_correction", "pressure_stabilisation",
						"pressure_stabilisation_factor", "free_surface",
						"free_surface_penalty_factor", "position_update", "velocity_update",
						"specific_volume", NULL };
static const char *const grid_keys[] = { "origin", "extent", "cell_size", NULL };
/* A material's own keys; its model's keys are checked by case_read_material_model(). */
static const char *const material_keys[] = { "name", "density", NULL };
static const char *const body_keys[] = { "name", "material", "rectangle", "polygon", "particles_per_cell",
					 "porosity", "hydraulic_conductivity", "permeability_law", NULL };
static const char *const box_keys[] = { "min", "max", NULL };
static const char *const fluid_keys[] = { "density", "bulk_modulus", "cavitation_pressure",
					  "cavitated_bulk_modulus", NULL };
static const char *const gravity_keys[] = { "acceleration", "ramp_time", "elastic_loading", "loading_conductivity",
						"water_attached", NULL };
static const char *const face_boundary_keys[] = { "soil", "water", "drainage", NULL };
static const char *const load_keys[] = { "body", "face", "from", "to", "traction", "time_function", NULL };
static const char *const time_keys[] = { "dt", "end", NULL };
static const char *const output_keys[] = { "frame_interval", "progress_interval", NULL };
static const char *const checkpoint_keys[] = { "interval", NULL };
/* Keys of a time function and of a probe depend on its kind; the last entry is the union, used
 * when the kind itself is missing or wrong. */
static const char *const *const time_function_keys[] = {
	(const char *const[]){ "kind", NULL },
	(const char *const[]){ "kind", "ramp_time", NULL },
	(const char *const[]){ "kind", "frequency", "amplitude", "mean", "phase", NULL },
	(const char *const[]){ "kind", "ramp_time", "frequency", "amplitude", "mean", "phase", NULL },
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

static int find_material(const struct case_spec *c, int count, const char *name)
{
	for (int i = 0; i < count; i++)
		if (c->materials[i].name[0] && strcmp(c->materials[i].name, name) == 0)
			return i;
	return -1;
}

static int find_body(const struct case_spec *c, int count, const char *name)
{
	for (int i = 0; i < count; i++)
		if (c->bodies[i].name[0] && strcmp(c->bodies[i].name, name) == 0)
			return i;
	return -1;
}

static int find_probe(const struct case_spec *c, int count, const char *name)
{
	for (int i = 0; i < count; i++)
		if (c->probes[i].name[0] && strcmp(c->probes[i].name, name) == 0)
			return i;
	return -1;
}

/* Records "LIST/i/name: duplicate KIND name 'NAME', also at LIST/earlier" if earlier >= 0. */
static void check_unique(struct case_reader *r, const char *list, int i, const char *kind, const char *name,
			 int earlier)
{
	char item[CASE_POINTER_MAX], pointer[CASE_POINTER_MAX];
	if (earlier < 0)
		return;
	case_pointer_index(item, list, (size_t)i);
	case_pointer_key(pointer, item, "name");
	case_problem(r, pointer, "duplicate %s name '%s', also at %s/%d", kind, name, list, earlier);
}

/* 1 when the box [min, max] lies within the grid, up to GRID_TOLERANCE of its extent. */
static int inside_grid(const struct case_grid *g, const double min[2], const double max[2])
{
	for (int d = 0; d < 2; d++) {
		double slack = GRID_TOLERANCE * g->extent[d];
		if (min[d] < g->origin[d] - slack || max[d] > g->origin[d] + g->extent[d] + slack)
			return 0;
	}
	return 1;
}

/* Writes "[x, y]" for a point (min == max), else "[x0, y0] to [x1, y1]", into dst[REGION_SIZE]. */
static const char *format_region(char *dst, const double min[2], const double max[2])
{
	char a[CASE_NUMBER_SIZE], b[CASE_NUMBER_SIZE], c[CASE_NUMBER_SIZE], d[CASE_NUMBER_SIZE];
	int n = snprintf(dst, REGION_SIZE, "[%s, %s]", case_format_number(a, min[0]),
			 case_format_number(b, min[1]));
	if (min[0] != max[0] || min[1] != max[1])
		snprintf(dst + n, REGION_SIZE - (size_t)n, " to [%s, %s]", case_format_number(c, max[0]),
			 case_format_number(d, max[1]));
	return dst;
}

/* Records "pointer: WHAT lies outside the grid: ..." unless [min, max] is inside it. */
static void check_inside_grid(struct case_reader *r, const char *pointer, const char *what,
			      const struct case_grid *g, const double min[2], const double max[2])
{
	if (inside_grid(g, min, max))
		return;
	char region[REGION_SIZE], grid[REGION_SIZE];
	double top[2] = { g->origin[0] + g->extent[0], g->origin[1] + g->extent[1] };
	case_problem(r, pointer, "%s lies outside the grid: %s, grid %s", what,
		     format_region(region, min, max), format_region(grid, g->origin, top));
}

/* Reads {"min": [x, y], "max": [x, y]} with min < max in both directions. */
static int read_box(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		    double min[2], double max[2])
{
	char pointer[CASE_POINTER_MAX];
	const json_t *box = case_read_object(r, obj, base, key, CASE_REQUIRED);
	if (!box)
		return 0;
	case_pointer_key(pointer, base, key);
	case_check_keys(r, box, pointer, box_keys);
	int ok = case_read_vec2(r, box, pointer, "min", CASE_REQUIRED, NULL, min);
	ok &= case_read_vec2(r, box, pointer, "max", CASE_REQUIRED, NULL, max);
	if (ok && !(min[0] < max[0] && min[1] < max[1])) {
		char max_pointer[CASE_POINTER_MAX];
		case_pointer_key(max_pointer, pointer, "max");
		case_problem(r, max_pointer, "must be greater than min in both x and y");
		return 0;
	}
	return ok;
}

static void read_header(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	int version;
	const char *title;
	case_read_choice(r, root, "", "schema", CASE_REQUIRED, schema_names, &version);
	if (!case_read_string(r, root, "", "title", CASE_OPTIONAL, &title))
		return;
	size_t length = strlen(title);
	if (length > TITLE_MAX)
		case_problem(r, "/title", "must be at most %zu bytes long, got %zu", TITLE_MAX, length);
	else
		memcpy(c->title, title, length + 1);
}

static void read_formulation(struct case_reader *r, const json_t *root, struct case_formulation *f)
{
	const char *p = "/formulation";
	const json_t *o = case_read_object(r, root, "", "formulation", CASE_REQUIRED);
	if (!o)
		return;
	case_check_keys(r, o, p, formulation_keys);
	f->scheme = read_choice_or(r, o, p, "scheme", CASE_REQUIRED, scheme_names, f->scheme);
	f->phases = read_choice_or(r, o, p, "phases", CASE_OPTIONAL, phases_names, f->phases);
	f->shape = read_choice_or(r, o, p, "shape", CASE_OPTIONAL, shape_names, f->shape);
	case_read_bool(r, o, p, "pore_pressure_smoothing", CASE_OPTIONAL, &f->pore_pressure_smoothing);
	case_read_bool(r, o, p, "drag_in_correction", CASE_OPTIONAL, &f->drag_in_correction);
	case_read_number(r, o, p, "flip_fraction", CASE_OPTIONAL, &FRACTION, &f->flip_fraction);
	f->velocity_update = read_choice_or(r, o, p, "velocity_update", CASE_OPTIONAL, velocity_update_names,
					    f->velocity_update);
	if (f->velocity_update == VELOCITY_UPDATE_APIC && f->flip_fraction != 1)
		case_problem(r, "/formulation/flip_fraction", "blends FLIP with PIC and has no meaning with "
			     "/formulation/velocity_update \"apic\"");
	f->pressure_projection = read_choice_or(r, o, p, "pressure_projection", CASE_OPTIONAL, projection_names,
						f->pressure_projection);
	f->soil_stabilisation = read_choice_or(r, o, p, "soil_stabilisation", CASE_OPTIONAL, stabilisation_names,
					       f->soil_stabilisation);
	f->pressure_stabilisation = read_choice_or(r, o, p, "pressure_stabilisation", CASE_OPTIONAL,
						   pressure_stabilisation_names, f->pressure_stabilisation);
	case_read_number(r, o, p, "pressure_stabilisation_factor", CASE_OPTIONAL, &POSITIVE,
			 &f->pressure_stabilisation_factor);
	/* the penalty is written into the consistent projection's energy (pressure_stabilisation.c) */
	if (f->pressure_stabilisation != PRESSURE_STABILISATION_NONE && f->pressure_projection != PROJECTION_CONSISTENT)
		case_problem(r, "/formulation/pressure_stabilisation",
			     "\"%s\" needs /formulation/pressure_projection \"consistent\"",
			     pressure_stabilisation_names[f->pressure_stabilisation]);
	f->position_update = read_choice_or(r, o, p, "position_update", CASE_OPTIONAL, position_update_names,
					    f->position_update);
	f->specific_volume = read_choice_or(r, o, p, "specific_volume", CASE_OPTIONAL, specific_volume_names,
					    f->specific_volume);
	f->free_surface = read_choice_or(r, o, p, "free_surface", CASE_OPTIONAL, free_surface_names, f->free_surface);
	case_read_number(r, o, p, "free_surface_penalty_factor", CASE_OPTIONAL, &POSITIVE,
			 &f->free_surface_penalty_factor);
	/* measured to spoil the Laplacian's Terzaghi column eightfold (docs/numerics.md, "Free surface") */
	if (f->free_surface != FREE_SURFACE_NODES && f->pressure_projection != PROJECTION_CONSISTENT)
		case_problem(r, "/formulation/free_surface", "\"%s\" needs /formulation/pressure_projection \"consistent\"",
			     free_surface_names[f->free_surface]);
}

/* Checks that extent[d] is a whole number, at least GRID_CELLS_MIN, of cells. */
static int check_cell_count(struct case_reader *r, const struct case_grid *g, int d)
{
	char pointer[CASE_POINTER_MAX], h[CASE_NUMBER_SIZE], got[CASE_NUMBER_SIZE];
	case_pointer_index(pointer, "/grid/extent", (size_t)d);
	double cells = round(g->extent[d] / g->cell_size);
	if (fabs(g->extent[d] - cells * g->cell_size) > GRID_TOLERANCE * g->extent[d] || cells < 1) {
		case_problem(r, pointer, "must be a positive multiple of /grid/cell_size (%s), got %s",
			     case_format_number(h, g->cell_size), case_format_number(got, g->extent[d]));
		return 0;
	}
	if (cells < GRID_CELLS_MIN) {
		case_problem(r, pointer, "must span at least %d cells of /grid/cell_size, got %.0f",
			     GRID_CELLS_MIN, cells);
		return 0;
	}
	return 1;
}

/* Returns 1 when the grid is complete and valid, so bodies and probes can be checked against it. */
static int read_grid(struct case_reader *r, const json_t *root, struct case_grid *g)
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
		extent_ok &= check_cell_count(r, g, 0);
		extent_ok &= check_cell_count(r, g, 1);
	}
	return ok && extent_ok && cell_size_ok;
}

static void read_material(struct case_reader *r, const json_t *o, const char *p, struct case_material *m)
{
	case_read_name(r, o, p, "name", CASE_REQUIRED, m->name, sizeof m->name);
	case_read_material_model(r, o, p, material_keys, m);
	case_read_number(r, o, p, "density", CASE_REQUIRED, &POSITIVE, &m->density);
}

static void read_materials(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	size_t n;
	const json_t *a = case_read_array(r, root, "", "materials", CASE_REQUIRED, &n);
	if (a && n == 0)
		case_problem(r, "/materials", "must list at least one material");
	if (!a || !(c->materials = alloc_items(r, n, sizeof *c->materials)))
		return;
	c->material_count = (int)n;
	for (int i = 0; i < c->material_count; i++) {
		char p[CASE_POINTER_MAX];
		struct case_material *m = &c->materials[i];
		case_pointer_index(p, "/materials", (size_t)i);
		if (!case_expect_object(r, case_array_item(a, (size_t)i), p))
			continue;
		read_material(r, case_array_item(a, (size_t)i), p, m);
		check_unique(r, "/materials", i, "material", m->name, find_material(c, i, m->name));
	}
}

/* Resolves the material name of a body to an index; -1 when unknown. */
static int read_material_ref(struct case_reader *r, const json_t *o, const char *p, const struct case_spec *c)
{
	char pointer[CASE_POINTER_MAX], shown[CASE_QUOTE_SIZE];
	const char *name;
	if (!case_read_string(r, o, p, "material", CASE_REQUIRED, &name))
		return -1;
	int index = find_material(c, c->material_count, name);
	if (index < 0) {
		case_pointer_key(pointer, p, "material");
		case_problem(r, pointer, "unknown material '%s'", case_quote(shown, name));
	}
	return index;
}

/* Twice the signed area of a polygon (shoelace formula). */
static double polygon_area2(const double (*v)[2], int n)
{
	double sum = 0;
	for (int i = 0, j = n - 1; i < n; j = i++)
		sum += v[j][0] * v[i][1] - v[i][0] * v[j][1];
	return sum;
}

static void bounding_box(struct case_body *b)
{
	for (int d = 0; d < 2; d++) {
		b->min[d] = b->max[d] = b->polygon[0][d];
		for (int i = 1; i < b->polygon_count; i++) {
			b->min[d] = fmin(b->min[d], b->polygon[i][d]);
			b->max[d] = fmax(b->max[d], b->polygon[i][d]);
		}
	}
}

static int read_polygon(struct case_reader *r, const json_t *o, const char *p, struct case_body *b)
{
	char pointer[CASE_POINTER_MAX], vertex[CASE_POINTER_MAX];
	size_t n;
	const json_t *a = case_read_array(r, o, p, "polygon", CASE_REQUIRED, &n);
	if (!a)
		return 0;
	case_pointer_key(pointer, p, "polygon");
	if (n < POLYGON_VERTICES_MIN || n > CASE_POLYGON_MAX) {
		case_problem(r, pointer, "must have %d to %d vertices, got %zu", POLYGON_VERTICES_MIN,
			     CASE_POLYGON_MAX, n);
		return 0;
	}
	int ok = 1;
	for (size_t i = 0; i < n; i++) {
		case_pointer_index(vertex, pointer, i);
		ok &= case_value_vec2(r, case_array_item(a, i), vertex, NULL, b->polygon[i]);
	}
	if (!ok)
		return 0;
	b->is_polygon = 1;
	b->polygon_count = (int)n;
	bounding_box(b);
	double box_area = (b->max[0] - b->min[0]) * (b->max[1] - b->min[1]);
	if (!(fabs(0.5 * polygon_area2(b->polygon, b->polygon_count)) > POLYGON_AREA_TOLERANCE * box_area)) {
		case_problem(r, pointer, "must enclose a non-zero area");
		return 0;
	}
	return 1;
}

/* Reads the body's region: exactly one of "rectangle" and "polygon". */
static int read_region(struct case_reader *r, const json_t *o, const char *p, struct case_body *b)
{
	int rectangle = case_has_key(o, "rectangle"), polygon = case_has_key(o, "polygon");
	if (rectangle == polygon) {
		case_problem(r, p, "must have exactly one of 'rectangle' and 'polygon', got %s",
			     rectangle ? "both" : "neither");
		return 0;
	}
	if (polygon)
		return read_polygon(r, o, p, b);
	return read_box(r, o, p, "rectangle", b->min, b->max);
}

static void read_body(struct case_reader *r, const json_t *o, const char *p, const struct case_spec *c,
		      int grid_ok, struct case_body *b)
{
	case_check_keys(r, o, p, body_keys);
	case_read_name(r, o, p, "name", CASE_REQUIRED, b->name, sizeof b->name);
	b->material = read_material_ref(r, o, p, c);
	if (read_region(r, o, p, b) && grid_ok)
		check_inside_grid(r, p, "body", &c->grid, b->min, b->max);
	case_read_int(r, o, p, "particles_per_cell", CASE_REQUIRED, PARTICLES_PER_CELL_MIN,
		      PARTICLES_PER_CELL_MAX, &b->particles_per_cell);
	case_read_number(r, o, p, "porosity", CASE_REQUIRED, &POROSITY, &b->porosity);
	case_read_number(r, o, p, "hydraulic_conductivity", CASE_REQUIRED, &POSITIVE,
			 &b->hydraulic_conductivity);
	b->permeability_law = read_choice_or(r, o, p, "permeability_law", CASE_OPTIONAL,
					     permeability_law_names, b->permeability_law);
}

static void read_bodies(struct case_reader *r, const json_t *root, struct case_spec *c, int grid_ok)
{
	size_t n;
	const json_t *a = case_read_array(r, root, "", "bodies", CASE_REQUIRED, &n);
	if (a && n == 0)
		case_problem(r, "/bodies", "must list at least one body");
	if (!a || !(c->bodies = alloc_items(r, n, sizeof *c->bodies)))
		return;
	c->body_count = (int)n;
	for (int i = 0; i < c->body_count; i++) {
		char p[CASE_POINTER_MAX];
		struct case_body *b = &c->bodies[i];
		b->material = -1;
		case_pointer_index(p, "/bodies", (size_t)i);
		if (!case_expect_object(r, case_array_item(a, (size_t)i), p))
			continue;
		read_body(r, case_array_item(a, (size_t)i), p, c, grid_ok, b);
		check_unique(r, "/bodies", i, "body", b->name, find_body(c, i, b->name));
	}
}

static void read_fluid(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	const json_t *o = case_read_object(r, root, "", "fluid", CASE_OPTIONAL);
	if (!o)
		return;
	case_check_keys(r, o, "/fluid", fluid_keys);
	case_read_number(r, o, "/fluid", "density", CASE_OPTIONAL, &POSITIVE, &c->fluid.density);
	case_read_number(r, o, "/fluid", "bulk_modulus", CASE_OPTIONAL, &POSITIVE, &c->fluid.bulk_modulus);
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
}

/* Reads from/to, defaulting to the whole face of the body's bounding box (body and face valid),
 * and checks from < to and that the span lies on that face. */
static void read_load_span(struct case_reader *r, const json_t *o, const char *p, const struct case_spec *c,
			   int known, struct case_load *l)
{
	char pointer[CASE_POINTER_MAX], a[CASE_NUMBER_SIZE], b[CASE_NUMBER_SIZE], got[CASE_NUMBER_SIZE];
	const struct case_body *body = known ? &c->bodies[l->body] : NULL;
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
	double slack = GRID_TOLERANCE * c->grid.extent[axis];
	if (body && (l->from < lo - slack || l->to > hi + slack))
		case_problem(r, p, "from and to must lie on the %s face of body '%s', from %s to %s",
			     face_names[l->face], body->name, case_format_number(a, lo),
			     case_format_number(b, hi));
}

static void read_load(struct case_reader *r, const json_t *o, const char *p, const struct case_spec *c,
		      struct case_load *l)
{
	char pointer[CASE_POINTER_MAX], shown[CASE_QUOTE_SIZE];
	const char *name;
	int face;
	case_check_keys(r, o, p, load_keys);
	l->body = -1;
	if (case_read_string(r, o, p, "body", CASE_REQUIRED, &name)) {
		l->body = find_body(c, c->body_count, name);
		case_pointer_key(pointer, p, "body");
		if (l->body < 0)
			case_problem(r, pointer, "unknown body '%s'", case_quote(shown, name));
	}
	int face_ok = case_read_choice(r, o, p, "face", CASE_REQUIRED, face_names, &face);
	if (face_ok)
		l->face = face;
	case_read_vec2(r, o, p, "traction", CASE_REQUIRED, NULL, l->traction);
	read_time_function(r, o, p, &l->time_function);
	read_load_span(r, o, p, c, l->body >= 0 && face_ok, l);
}

static void read_loads(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	size_t n;
	const json_t *a = case_read_array(r, root, "", "loads", CASE_OPTIONAL, &n);
	if (!a || !(c->loads = alloc_items(r, n, sizeof *c->loads)))
		return;
	c->load_count = (int)n;
	for (int i = 0; i < c->load_count; i++) {
		char p[CASE_POINTER_MAX];
		case_pointer_index(p, "/loads", (size_t)i);
		if (case_expect_object(r, case_array_item(a, (size_t)i), p))
			read_load(r, case_array_item(a, (size_t)i), p, c, &c->loads[i]);
	}
}

static void read_time(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	char end[CASE_NUMBER_SIZE], dt[CASE_NUMBER_SIZE];
	const json_t *o = case_read_object(r, root, "", "time", CASE_REQUIRED);
	if (!o)
		return;
	case_check_keys(r, o, "/time", time_keys);
	int ok = case_read_number(r, o, "/time", "dt", CASE_REQUIRED, &POSITIVE, &c->time.dt);
	ok &= case_read_number(r, o, "/time", "end", CASE_REQUIRED, &POSITIVE, &c->time.end);
	if (ok && c->time.dt > c->time.end)
		case_problem(r, "/time/dt", "must be <= /time/end (%s), got %s",
			     case_format_number(end, c->time.end), case_format_number(dt, c->time.dt));
}

static void read_output(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	const json_t *o = case_read_object(r, root, "", "output", CASE_OPTIONAL);
	if (!o)
		return;
	case_check_keys(r, o, "/output", output_keys);
	case_read_number(r, o, "/output", "frame_interval", CASE_OPTIONAL, &NON_NEGATIVE,
			 &c->output.frame_interval);
	case_read_number(r, o, "/output", "progress_interval", CASE_OPTIONAL, &POSITIVE,
			 &c->output.progress_interval);
}

/* {"interval": s of simulated time}: absent means no checkpoints (interval 0). */
static void read_checkpoint(struct case_reader *r, const json_t *root, struct case_spec *c)
{
	const json_t *o = case_read_object(r, root, "", "checkpoint", CASE_OPTIONAL);
	if (!o)
		return;
	case_check_keys(r, o, "/checkpoint", checkpoint_keys);
	case_read_number(r, o, "/checkpoint", "interval", CASE_REQUIRED, &POSITIVE, &c->checkpoint.interval);
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
		if (read_box(r, o, p, "box", probe->box_min, probe->box_max) && grid_ok)
			check_inside_grid(r, pointer, "box", &c->grid, probe->box_min, probe->box_max);
		return;
	}
	case_pointer_key(pointer, p, "point");
	if (case_read_vec2(r, o, p, "point", CASE_REQUIRED, NULL, probe->point) && grid_ok)
		check_inside_grid(r, pointer, "point", &c->grid, probe->point, probe->point);
	if (kind == PROBE_DISPLACEMENT)
		probe->component = read_choice_or(r, o, p, "component", CASE_REQUIRED, component_names, 0);
}

static void read_probes(struct case_reader *r, const json_t *root, struct case_spec *c, int grid_ok)
{
	size_t n;
	const json_t *a = case_read_array(r, root, "", "probes", CASE_OPTIONAL, &n);
	if (!a || !(c->probes = alloc_items(r, n, sizeof *c->probes)))
		return;
	c->probe_count = (int)n;
	for (int i = 0; i < c->probe_count; i++) {
		char p[CASE_POINTER_MAX];
		struct case_probe *probe = &c->probes[i];
		case_pointer_index(p, "/probes", (size_t)i);
		if (!case_expect_object(r, case_array_item(a, (size_t)i), p))
			continue;
		read_probe(r, case_array_item(a, (size_t)i), p, c, grid_ok, probe);
		check_unique(r, "/probes", i, "probe", probe->name, find_probe(c, i, probe->name));
	}
}

static void set_defaults(struct case_spec *c)
{
	c->formulation.scheme = SCHEME_SEMI_IMPLICIT;
	c->formulation.phases = PHASES_DOUBLE_POINT;
	c->formulation.shape = SHAPE_QUADRATIC_BSPLINE;
	c->formulation.pore_pressure_smoothing = 1;
	c->formulation.flip_fraction = 1;
	c->formulation.velocity_update = VELOCITY_UPDATE_FLIP;
	c->formulation.drag_in_correction = 0;
	c->formulation.pressure_stabilisation = PRESSURE_STABILISATION_NONE;
	c->formulation.pressure_stabilisation_factor = DEFAULT_PRESSURE_STABILISATION_FACTOR;
	c->formulation.free_surface = FREE_SURFACE_NODES;
	c->formulation.free_surface_penalty_factor = DEFAULT_FREE_SURFACE_PENALTY_FACTOR;
	c->formulation.position_update = POSITION_UPDATE_GRID_VELOCITY;
	c->formulation.specific_volume = SPECIFIC_VOLUME_POINT;
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
	read_formulation(r, root, &c->formulation);
	int grid_ok = read_grid(r, root, &c->grid);
	read_materials(r, root, c);
	read_bodies(r, root, c, grid_ok);
	read_fluid(r, root, c);
	read_gravity(r, root, c);
	read_boundaries(r, root, c->boundaries);
	read_loads(r, root, c);
	read_time(r, root, c);
	read_output(r, root, c);
	read_probes(r, root, c, grid_ok);
	read_checkpoint(r, root, c);
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
	struct case_spec *c = calloc(1, sizeof *c);
	if (c) {
		set_defaults(c);
		read_case(&r, root, c);
	}
	case_json_free(root);
	if (c && !r.out_of_memory && !r.problem_count && !(c->json = strdup(json)))
		r.out_of_memory = 1;
	if (!c || r.out_of_memory) {
		case_destroy(&c);
		return poro_error_set(err, PORO_ENOMEM, "out of memory loading a case");
	}
	if (r.problem_count) {
		case_destroy(&c);
		return PORO_EINVAL;
	}
	*out = c;
	return PORO_OK;
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
		return f->mean + f->amplitude * sin(two_pi * f->frequency * t + f->phase);
	}
	return 1;
}
