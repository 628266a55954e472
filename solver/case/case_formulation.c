/*
 * case_formulation.c - the "formulation" section of a case and the checks that depend on its
 * scheme (case_formulation.h).
 *
 * The semi-implicit scheme (paper 000) takes the pressure-solve options (projection, free surface,
 * smoothing of Eq. 77, drag in the correction, the F-bar family, the position update); the
 * explicit scheme (paper 002) takes the strain-rate smoothing of Eqs. 26-27, the multi-field
 * pressure rate of Eqs. 28-34 and the drag's integration. Both take the shape functions, the
 * point velocity update and Nor-Sand's specific volume.
 */
#include "case_formulation.h"

#include <string.h>

#define DEFAULT_PRESSURE_STABILISATION_FACTOR 10.0 /* the strongest suppression measured without a
						      measurable leak (docs/numerics.md) */
#define DEFAULT_FREE_SURFACE_PENALTY_FACTOR 1e4 /* surface pressure held to about 1e-4 of the interior's,
						   the matrix still well conditioned for CHOLMOD */

static const struct case_range POSITIVE = { BOUND_OPEN, 0, BOUND_NONE, 0 };
static const struct case_range FRACTION = { BOUND_CLOSED, 0, BOUND_CLOSED, 1 };

/* Names of enum values, in enum order. */
static const char *const scheme_names[] = { "semi_implicit", "explicit", "implicit_upU", NULL };
static const char *const phases_names[] = { "double_point", "single_point", NULL };
static const char *const shape_names[] = { "linear", "quadratic_bspline", "cubic_bspline", "gimp", NULL };
static const char *const projection_names[] = { "laplacian", "consistent", NULL };
static const char *const pressure_stabilisation_names[] = { "none", "second_difference", NULL };
static const char *const free_surface_names[] = { "nodes", "interpolated", "weak", NULL };
static const char *const position_update_names[] = { "grid_velocity", "musl_displacement", NULL };
static const char *const velocity_update_names[] = { "flip", "apic", "aflip", NULL };
static const char *const specific_volume_names[] = { "point", "nodal_average", NULL };
static const char *const stabilisation_names[] = { "none", "fbar", "modified_fbar", "modified_fbar_cellwise",
						   NULL };
static const char *const smoothing_names[] = { "cell_average", "none", NULL };
static const char *const pressure_rate_names[] = { "multi_field", "none", NULL };
static const char *const basis_names[] = { "constant", "linear", NULL };
static const char *const drag_names[] = { "implicit", "explicit", NULL };
static const char *const bbar_names[] = { "none", "bbar", NULL };
static const char *const tangent_names[] = { "elastic", "consistent", NULL };
static const char *const recovery_names[] = { "mlsa_patch", "mlsa_nodal", "none", NULL };
static const char *const mass_matrix_names[] = { "consistent", "lumped", NULL };

#define DEFAULT_NEWMARK_BETA 0.25
#define DEFAULT_NEWMARK_GAMMA 0.5
#define DEFAULT_NEWTON_TOLERANCE 1e-10      /* |delta . r| against the first iteration's (spec-001 §4.2) */
#define DEFAULT_NEWTON_MAX_ITERATIONS 100
#define NEWTON_MAX_ITERATIONS_LIMIT 10000

/* The keys each scheme takes beside those every scheme takes, in scheme order. */
static const char *const common_keys[] = { "scheme", "phases", "shape", "flip_fraction", "velocity_update",
					   "specific_volume", NULL };
static const char *const *const scheme_keys[] = {
	(const char *const[]){ "pore_pressure_smoothing", "pressure_projection", "soil_stabilisation",
			       "drag_in_correction", "pressure_stabilisation", "pressure_stabilisation_factor",
			       "free_surface", "free_surface_penalty_factor", "position_update", NULL },
	(const char *const[]){ "strain_rate_smoothing", "pressure_rate_projection", "pressure_rate_basis", "drag",
			       NULL },
	(const char *const[]){ "soil_stabilisation", "newmark_beta", "newmark_gamma", "tangent", "newton_tolerance",
			       "newton_max_iterations", "pressure_recovery", "mass_matrix", NULL },
};
#define SCHEME_COUNT 3

void case_formulation_defaults(struct case_formulation *f)
{
	f->scheme = SCHEME_SEMI_IMPLICIT;
	f->phases = PHASES_DOUBLE_POINT;
	f->shape = SHAPE_QUADRATIC_BSPLINE;
	f->pore_pressure_smoothing = 1;
	f->flip_fraction = 1;
	f->velocity_update = VELOCITY_UPDATE_FLIP;
	f->drag_in_correction = 0;
	f->pressure_stabilisation = PRESSURE_STABILISATION_NONE;
	f->pressure_stabilisation_factor = DEFAULT_PRESSURE_STABILISATION_FACTOR;
	f->free_surface = FREE_SURFACE_NODES;
	f->free_surface_penalty_factor = DEFAULT_FREE_SURFACE_PENALTY_FACTOR;
	f->position_update = POSITION_UPDATE_GRID_VELOCITY;
	f->specific_volume = SPECIFIC_VOLUME_POINT;
	f->strain_rate_smoothing = STRAIN_RATE_SMOOTHING_CELL_AVERAGE;
	f->pressure_rate_projection = PRESSURE_RATE_MULTI_FIELD;
	f->pressure_rate_basis = PRESSURE_RATE_BASIS_CONSTANT;
	f->drag = DRAG_IMPLICIT;
	f->newmark_beta = DEFAULT_NEWMARK_BETA;
	f->newmark_gamma = DEFAULT_NEWMARK_GAMMA;
	f->tangent = NEWTON_TANGENT_ELASTIC;
	f->newton_tolerance = DEFAULT_NEWTON_TOLERANCE;
	f->newton_max_iterations = DEFAULT_NEWTON_MAX_ITERATIONS;
	f->pressure_recovery = PRESSURE_RECOVERY_MLSA_PATCH;
	f->mass_matrix = MASS_MATRIX_CONSISTENT;
}

/* A choice read into an enum: the chosen index, or fallback when absent or invalid. */
static int choice_or(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		     enum case_need need, const char *const *names, int fallback)
{
	int value = fallback;
	case_read_choice(r, obj, base, key, need, names, &value);
	return value;
}

static int listed(const char *const *keys, const char *key)
{
	for (; *keys; keys++)
		if (!strcmp(*keys, key))
			return 1;
	return 0;
}

/* Refuses the keys of the other schemes ("applies to the X scheme only"), and keys no scheme takes. */
static void check_formulation_keys(struct case_reader *r, const json_t *o, enum case_scheme scheme)
{
	const char *all[64];
	int n = 0;
	for (const char *const *k = common_keys; *k; k++)
		all[n++] = *k;
	for (int s = 0; s < SCHEME_COUNT; s++)
		for (const char *const *k = scheme_keys[s]; *k; k++)
			all[n++] = *k;
	all[n] = NULL;
	case_check_keys(r, o, "/formulation", all);
	for (int s = 0; s < SCHEME_COUNT; s++) {
		if (s == (int)scheme)
			continue;
		for (const char *const *k = scheme_keys[s]; *k; k++) {
			if (!case_has_key(o, *k) || listed(scheme_keys[scheme], *k))
				continue;
			char pointer[CASE_POINTER_MAX];
			case_pointer_key(pointer, "/formulation", *k);
			case_problem(r, pointer, "applies to the \"%s\" scheme only, not to \"%s\"", scheme_names[s],
				     scheme_names[scheme]);
		}
	}
}

static void read_semi_implicit(struct case_reader *r, const json_t *o, const char *p, struct case_formulation *f)
{
	case_read_bool(r, o, p, "pore_pressure_smoothing", CASE_OPTIONAL, &f->pore_pressure_smoothing);
	case_read_bool(r, o, p, "drag_in_correction", CASE_OPTIONAL, &f->drag_in_correction);
	f->pressure_projection = choice_or(r, o, p, "pressure_projection", CASE_OPTIONAL, projection_names,
					   f->pressure_projection);
	f->soil_stabilisation = choice_or(r, o, p, "soil_stabilisation", CASE_OPTIONAL, stabilisation_names,
					  f->soil_stabilisation);
	f->pressure_stabilisation = choice_or(r, o, p, "pressure_stabilisation", CASE_OPTIONAL,
					      pressure_stabilisation_names, f->pressure_stabilisation);
	case_read_number(r, o, p, "pressure_stabilisation_factor", CASE_OPTIONAL, &POSITIVE,
			 &f->pressure_stabilisation_factor);
	/* the penalty is written into the consistent projection's energy (pressure_stabilisation.c) */
	if (f->pressure_stabilisation != PRESSURE_STABILISATION_NONE && f->pressure_projection != PROJECTION_CONSISTENT)
		case_problem(r, "/formulation/pressure_stabilisation",
			     "\"%s\" needs /formulation/pressure_projection \"consistent\"",
			     pressure_stabilisation_names[f->pressure_stabilisation]);
	f->position_update = choice_or(r, o, p, "position_update", CASE_OPTIONAL, position_update_names,
				       f->position_update);
	f->free_surface = choice_or(r, o, p, "free_surface", CASE_OPTIONAL, free_surface_names, f->free_surface);
	case_read_number(r, o, p, "free_surface_penalty_factor", CASE_OPTIONAL, &POSITIVE,
			 &f->free_surface_penalty_factor);
	/* measured to spoil the Laplacian's Terzaghi column eightfold (docs/numerics.md, "Free surface") */
	if (f->free_surface != FREE_SURFACE_NODES && f->pressure_projection != PROJECTION_CONSISTENT)
		case_problem(r, "/formulation/free_surface", "\"%s\" needs /formulation/pressure_projection \"consistent\"",
			     free_surface_names[f->free_surface]);
}

static void read_explicit(struct case_reader *r, const json_t *o, const char *p, struct case_formulation *f)
{
	/* 002 §2: one set of points carries both phases, each with its own velocity */
	if (f->phases != PHASES_SINGLE_POINT)
		case_problem(r, "/formulation/phases", "the \"explicit\" scheme is single point (002 §2): "
			     "must be \"single_point\", got \"%s\"", phases_names[f->phases]);
	f->strain_rate_smoothing = choice_or(r, o, p, "strain_rate_smoothing", CASE_OPTIONAL, smoothing_names,
					     f->strain_rate_smoothing);
	f->pressure_rate_projection = choice_or(r, o, p, "pressure_rate_projection", CASE_OPTIONAL,
						pressure_rate_names, f->pressure_rate_projection);
	f->pressure_rate_basis = choice_or(r, o, p, "pressure_rate_basis", CASE_OPTIONAL, basis_names,
					   f->pressure_rate_basis);
	if (case_has_key(o, "pressure_rate_basis") && f->pressure_rate_projection == PRESSURE_RATE_NONE)
		case_problem(r, "/formulation/pressure_rate_basis", "needs /formulation/pressure_rate_projection "
			     "\"multi_field\"");
	f->drag = choice_or(r, o, p, "drag", CASE_OPTIONAL, drag_names, f->drag);
}

/* 001's Newmark parameters, kept where the average-acceleration family is unconditionally stable
 * for linear problems: gamma >= 1/2 and beta >= (gamma + 1/2)^2 / 4. */
static void read_implicit(struct case_reader *r, const json_t *o, const char *p, struct case_formulation *f)
{
	static const struct case_range POSITIVE_FRACTION = { BOUND_OPEN, 0, BOUND_CLOSED, 1 };
	static const struct case_range TOLERANCE = { BOUND_OPEN, 0, BOUND_OPEN, 1 };
	if (f->phases != PHASES_SINGLE_POINT)
		case_problem(r, "/formulation/phases", "the \"implicit_upU\" scheme is single point (001 §2): must be "
			     "\"single_point\", got \"%s\"", phases_names[f->phases]);
	/* the points' velocities follow Newmark's trapezoid on their accelerations (001 Eq. 11c) */
	if (f->velocity_update != VELOCITY_UPDATE_FLIP)
		case_problem(r, "/formulation/velocity_update", "the \"implicit_upU\" scheme moves its points' velocities "
			     "by Newmark (001 Eq. 11c): leave it out or \"flip\"");
	if (f->flip_fraction != 1)
		case_problem(r, "/formulation/flip_fraction", "the \"implicit_upU\" scheme moves its points' velocities by "
			     "Newmark (001 Eq. 11c), not FLIP blended with PIC: leave it out or 1");
	int bbar = 1;
	case_read_choice(r, o, p, "soil_stabilisation", CASE_OPTIONAL, bbar_names, &bbar);
	f->soil_stabilisation = bbar ? STABILISATION_BBAR : STABILISATION_NONE;
	/* the cell-centre sampling of 001 Eqs. 15-16 is written for uGIMP's domains */
	if (bbar && f->shape != SHAPE_GIMP)
		case_problem(r, "/formulation/soil_stabilisation", "\"bbar\" samples uGIMP at the cell centres "
			     "(001 Eqs. 12-16): needs /formulation/shape \"gimp\"");
	case_read_number(r, o, p, "newmark_gamma", CASE_OPTIONAL, &POSITIVE_FRACTION, &f->newmark_gamma);
	case_read_number(r, o, p, "newmark_beta", CASE_OPTIONAL, &POSITIVE_FRACTION, &f->newmark_beta);
	const double beta_min = 0.25 * (f->newmark_gamma + 0.5) * (f->newmark_gamma + 0.5);
	if (f->newmark_gamma < 0.5 || f->newmark_beta < beta_min - 1e-12)
		case_problem(r, "/formulation/newmark_beta", "with newmark_gamma %g must be at least %g (and gamma at "
			     "least 1/2) for the step to be stable at any dt", f->newmark_gamma, beta_min);
	f->tangent = choice_or(r, o, p, "tangent", CASE_OPTIONAL, tangent_names, f->tangent);
	case_read_number(r, o, p, "newton_tolerance", CASE_OPTIONAL, &TOLERANCE, &f->newton_tolerance);
	case_read_int(r, o, p, "newton_max_iterations", CASE_OPTIONAL, 1, NEWTON_MAX_ITERATIONS_LIMIT,
		      &f->newton_max_iterations);
	f->pressure_recovery = choice_or(r, o, p, "pressure_recovery", CASE_OPTIONAL, recovery_names,
					 f->pressure_recovery);
	f->mass_matrix = choice_or(r, o, p, "mass_matrix", CASE_OPTIONAL, mass_matrix_names, f->mass_matrix);
}

void case_read_formulation(struct case_reader *r, const json_t *root, struct case_formulation *f)
{
	const char *p = "/formulation";
	const json_t *o = case_read_object(r, root, "", "formulation", CASE_REQUIRED);
	if (!o)
		return;
	int scheme = -1;
	case_read_choice(r, o, p, "scheme", CASE_REQUIRED, scheme_names, &scheme);
	if (scheme >= 0)
		f->scheme = scheme;
	check_formulation_keys(r, o, f->scheme);
	/* Only paper 000's scheme has a double-point form: the others default to the one they take. */
	if (f->scheme != SCHEME_SEMI_IMPLICIT)
		f->phases = PHASES_SINGLE_POINT;
	f->phases = choice_or(r, o, p, "phases", CASE_OPTIONAL, phases_names, f->phases);
	f->shape = choice_or(r, o, p, "shape", CASE_OPTIONAL, shape_names, f->shape);
	case_read_number(r, o, p, "flip_fraction", CASE_OPTIONAL, &FRACTION, &f->flip_fraction);
	f->velocity_update = choice_or(r, o, p, "velocity_update", CASE_OPTIONAL, velocity_update_names,
				       f->velocity_update);
	if (f->velocity_update == VELOCITY_UPDATE_APIC && f->flip_fraction != 1)
		case_problem(r, "/formulation/flip_fraction", "blends FLIP with PIC and has no meaning with "
			     "/formulation/velocity_update \"apic\"");
	f->specific_volume = choice_or(r, o, p, "specific_volume", CASE_OPTIONAL, specific_volume_names,
				       f->specific_volume);
	if (scheme < 0)
		return;   /* the scheme's own keys were refused above as unknown to it */
	if (f->scheme == SCHEME_EXPLICIT)
		read_explicit(r, o, p, f);
	else if (f->scheme == SCHEME_IMPLICIT_UPU)
		read_implicit(r, o, p, f);
	else
		read_semi_implicit(r, o, p, f);
}

void case_check_scheme(struct case_reader *r, const struct case_spec *c)
{
	if (c->formulation.scheme == SCHEME_SEMI_IMPLICIT) {
		if (c->fluid.grain_bulk_modulus > 0)
			case_problem(r, "/fluid/grain_bulk_modulus", "applies to the \"implicit_upU\" scheme only");
		return;
	}
	const char *scheme = scheme_names[c->formulation.scheme];
	static const char *const face_names[] = { "left", "right", "bottom", "top" };
	if (c->fluid.cavitation_pressure < 0)
		case_problem(r, "/fluid/cavitation_pressure", "applies to the \"semi_implicit\" scheme only (the "
			     "\"%s\" scheme's pore fluid is linearly compressible)", scheme);
	if (c->gravity.water_attached)
		case_problem(r, "/gravity/water_attached", "applies to the \"semi_implicit\" scheme only");
	if (c->fluid.grain_bulk_modulus > 0 && c->formulation.scheme != SCHEME_IMPLICIT_UPU)
		case_problem(r, "/fluid/grain_bulk_modulus", "applies to the \"implicit_upU\" scheme only");
	if (c->gravity.loading_conductivity > 0)
		case_problem(r, "/gravity/loading_conductivity", "applies to the \"semi_implicit\" scheme only");
	for (int f = 0; f < FACE_COUNT; f++) {
		const struct case_boundary *b = &c->boundaries[f];
		char face[CASE_POINTER_MAX], pointer[CASE_POINTER_MAX];
		case_pointer_key(face, "/boundaries", face_names[f]);
		if (b->soil == CONSTRAINT_PLATE) {
			case_pointer_key(pointer, face, "soil");
			case_problem(r, pointer, "\"plate\" applies to the \"semi_implicit\" scheme only");
		}
		/* these schemes move the water itself (002 §3.1, 001 Eq. 2): a drained face whose water
		 * is held would pass no water */
		if (b->drainage == DRAINAGE_DRAINED && b->water != CONSTRAINT_FREE && b->water != CONSTRAINT_PLATE) {
			case_pointer_key(pointer, face, "drainage");
			case_problem(r, pointer, "\"drained\" needs \"water\": \"free\" on this face under the "
				     "\"%s\" scheme, which drains a face where its water moves freely", scheme);
		}
	}
}
