/*
 * case_material.c - the constitutive keys of a material object (case_material.h).
 *
 * Which keys a material takes depends on its model, so the model is read first and the keys are
 * checked against that model's list; when the model itself is missing or unknown, against the
 * union of all lists, so one mistake gives one line. Checks that involve two values (dilation
 * angle against friction angle, residual against peak cohesion, the softening rate against the
 * shear modulus) are made only when both values were read without a problem.
 *
 * Angles are read in degrees, as soil parameters are quoted (000 Table 3, 001 Table 3), and
 * converted by material_init(), which also applies the strength reduction factor (000 Eq. 91).
 */
#include "case_material.h"

#include <math.h>

#define KEYS_MAX 48                         /* longest key list, with the caller's own keys */

/* Softening no steeper than this multiple of the shear modulus G (Pa per unit deviatoric plastic
 * strain), so that the Tresca return has one solution: in triaxial compression (an edge of the
 * hexagon) the yield function of the return falls at 6 G - 4 H per unit multiplier, on the main
 * plane at 4 G - 4 H / sqrt(3); 1.5 G keeps both positive. */
#define SOFTENING_LIMIT 1.5

static const struct case_range POSITIVE = { BOUND_OPEN, 0, BOUND_NONE, 0 };
static const struct case_range NON_NEGATIVE = { BOUND_CLOSED, 0, BOUND_NONE, 0 };
static const struct case_range POISSON_RATIO = { BOUND_OPEN, -1, BOUND_OPEN, 0.5 };
static const struct case_range FRICTION_ANGLE = { BOUND_OPEN, 0, BOUND_OPEN, 90 };

static const char *const model_names[] = { "linear_elastic", "hencky", "mohr_coulomb", "tresca_softening",
					   "mohr_coulomb_dilation", "nor_sand", NULL };
static const char *const strain_names[] = { "finite", "small", NULL };

/* Keys of each model, in enum order; the last entry is the union. */
#define ELASTIC_KEYS "model", "youngs_modulus", "poisson_ratio"
#define NOR_SAND_KEYS "strain", "shear_modulus", "swelling_index", "compression_index",                  \
		      "reference_specific_volume", "critical_state_reference_pressure", "critical_stress_ratio", \
		      "yield_function_constant", "plastic_potential_constant", "hardening_coefficient",        \
		      "dilatancy_multiplier", "initial_specific_volume", "overconsolidation_ratio",            \
		      "initial_reference_pressure", "dilatancy_cutoff_start", "dilatancy_cutoff_end",          \
		      "gas_volume_ratio", "initial_yield_surface"
static const char *const *const model_keys[] = {
	(const char *const[]){ ELASTIC_KEYS, NULL },
	(const char *const[]){ ELASTIC_KEYS, NULL },
	(const char *const[]){ ELASTIC_KEYS, "strain", "cohesion", "friction_angle", "dilation_angle",
			       "strength_reduction_factor", NULL },
	(const char *const[]){ ELASTIC_KEYS, "strain", "peak_cohesion", "residual_cohesion",
			       "residual_plastic_strain", "strength_reduction_factor", NULL },
	(const char *const[]){ ELASTIC_KEYS, "strain", "cohesion", "friction_angle", "initial_dilation_angle",
			       "critical_dilation_angle", "dilation_evolution_parameter",
			       "strength_reduction_factor", NULL },
	(const char *const[]){ "model", NOR_SAND_KEYS, NULL },
	(const char *const[]){ ELASTIC_KEYS, "strain", "cohesion", "friction_angle", "dilation_angle",
			       "peak_cohesion", "residual_cohesion", "residual_plastic_strain",
			       "initial_dilation_angle", "critical_dilation_angle",
			       "dilation_evolution_parameter", "strength_reduction_factor", NOR_SAND_KEYS, NULL },
};

/* Writes the model's keys followed by extra into keys[KEYS_MAX]. */
static void join_keys(const char *const *model, const char *const *extra, const char **keys)
{
	int n = 0;
	for (; *model && n < KEYS_MAX - 1; model++)
		keys[n++] = *model;
	for (; extra && *extra && n < KEYS_MAX - 1; extra++)
		keys[n++] = *extra;
	keys[n] = NULL;
}

/* Reads an angle in degrees, -phi <= angle <= phi (lo = -phi) or 0 <= angle <= phi (lo = 0), where
 * phi is the friction angle when phi_ok, else only a range check against (-90, 90). */
static void read_dilation(struct case_reader *r, const json_t *o, const char *p, const char *key,
			  int symmetric, double phi, int phi_ok, double *out)
{
	char pointer[CASE_POINTER_MAX], got[CASE_NUMBER_SIZE], bound[CASE_NUMBER_SIZE];
	struct case_range wide = { symmetric ? BOUND_OPEN : BOUND_CLOSED, symmetric ? -90 : 0, BOUND_OPEN, 90 };
	if (!case_read_number(r, o, p, key, CASE_REQUIRED, &wide, out) || !phi_ok)
		return;
	if (*out <= phi && *out >= (symmetric ? -phi : 0))
		return;
	case_pointer_key(pointer, p, key);
	case_problem(r, pointer, "must be >= %s and <= friction_angle (%s), got %s",
		     symmetric ? "-friction_angle" : "0", case_format_number(bound, phi),
		     case_format_number(got, *out));
}

static void read_tresca(struct case_reader *r, const json_t *o, const char *p, int elastic_ok,
			struct case_material *m)
{
	char pointer[CASE_POINTER_MAX], a[CASE_NUMBER_SIZE], b[CASE_NUMBER_SIZE];
	int ok = case_read_number(r, o, p, "peak_cohesion", CASE_REQUIRED, &POSITIVE, &m->peak_cohesion);
	int residual_ok = case_read_number(r, o, p, "residual_cohesion", CASE_REQUIRED, &NON_NEGATIVE,
					   &m->residual_cohesion);
	if (ok && residual_ok && m->residual_cohesion > m->peak_cohesion) {
		case_pointer_key(pointer, p, "residual_cohesion");
		case_problem(r, pointer, "must be <= peak_cohesion (%s), got %s",
			     case_format_number(a, m->peak_cohesion), case_format_number(b, m->residual_cohesion));
		residual_ok = 0;
	}
	ok &= residual_ok;
	ok &= case_read_number(r, o, p, "residual_plastic_strain", CASE_REQUIRED, &POSITIVE,
			       &m->residual_plastic_strain);
	if (!ok || !elastic_ok)
		return;
	double G = m->youngs_modulus / (2.0 * (1.0 + m->poisson_ratio));
	double H = (m->peak_cohesion - m->residual_cohesion) / m->residual_plastic_strain;
	if (H < SOFTENING_LIMIT * G)
		return;
	case_pointer_key(pointer, p, "residual_plastic_strain");
	case_problem(r, pointer, "softening (peak_cohesion - residual_cohesion) / residual_plastic_strain = %s Pa "
		     "must be below %.3g times the shear modulus (%s Pa) for a unique return",
		     case_format_number(a, H), SOFTENING_LIMIT, case_format_number(b, G));
}

static void read_dilation_evolution(struct case_reader *r, const json_t *o, const char *p,
				    struct case_material *m)
{
	char pointer[CASE_POINTER_MAX], got[CASE_NUMBER_SIZE], negated[CASE_NUMBER_SIZE];
	double eta = 0;
	if (!case_read_number(r, o, p, "dilation_evolution_parameter", CASE_REQUIRED, NULL, &eta))
		return;
	if (eta >= 0) {
		m->dilation_evolution_parameter = eta;
		return;
	}
	/* 001 Table 3 lists -25 next to Eq. 17's exp(-eta eps): a decay needs eta > 0 here. */
	case_pointer_key(pointer, p, "dilation_evolution_parameter");
	case_problem(r, pointer, "must be >= 0 (the dilation angle decays as exp(-eta eps_d): for 001 Table 3's "
		     "%s give %s), got %s", case_format_number(got, eta), case_format_number(negated, -eta), got);
}

/* nor_sand (000 Table 6, App. B.1 and B.4). The elastic constants are G and kappa, not E and nu. */
static void read_nor_sand(struct case_reader *r, const json_t *o, const char *p, struct case_material *m)
{
	static const struct case_range SHAPE_CONSTANT = { BOUND_CLOSED, 0, BOUND_OPEN, 1 };
	static const struct case_range NON_POSITIVE = { BOUND_NONE, 0, BOUND_CLOSED, 0 };
	static const struct case_range SPECIFIC_VOLUME = { BOUND_OPEN, 1, BOUND_NONE, 0 };
	static const struct case_range AT_LEAST_ONE = { BOUND_CLOSED, 1, BOUND_NONE, 0 };
	char pointer[CASE_POINTER_MAX], a[CASE_NUMBER_SIZE], b[CASE_NUMBER_SIZE];
	m->critical_state_reference_pressure = 1e3;
	m->overconsolidation_ratio = 1;
	m->initial_reference_pressure = 2e3;
	m->dilatancy_cutoff_start = 1.0;
	m->dilatancy_cutoff_end = 1.5;
	m->gas_volume_ratio = 1.6;
	case_read_number(r, o, p, "shear_modulus", CASE_REQUIRED, &POSITIVE, &m->shear_modulus);
	case_read_number(r, o, p, "swelling_index", CASE_REQUIRED, &POSITIVE, &m->swelling_index);
	case_read_number(r, o, p, "compression_index", CASE_REQUIRED, &POSITIVE, &m->compression_index);
	case_read_number(r, o, p, "reference_specific_volume", CASE_REQUIRED, &SPECIFIC_VOLUME,
			 &m->reference_specific_volume);
	case_read_number(r, o, p, "critical_state_reference_pressure", CASE_OPTIONAL, &POSITIVE,
			 &m->critical_state_reference_pressure);
	case_read_number(r, o, p, "critical_stress_ratio", CASE_REQUIRED, &POSITIVE, &m->critical_stress_ratio);
	case_read_number(r, o, p, "yield_function_constant", CASE_REQUIRED, &SHAPE_CONSTANT,
			 &m->yield_function_constant);
	case_read_number(r, o, p, "plastic_potential_constant", CASE_REQUIRED, &SHAPE_CONSTANT,
			 &m->plastic_potential_constant);
	case_read_number(r, o, p, "hardening_coefficient", CASE_REQUIRED, &NON_NEGATIVE, &m->hardening_coefficient);
	case_read_number(r, o, p, "dilatancy_multiplier", CASE_REQUIRED, &NON_POSITIVE, &m->dilatancy_multiplier);
	case_read_number(r, o, p, "initial_specific_volume", CASE_REQUIRED, &SPECIFIC_VOLUME,
			 &m->initial_specific_volume);
	case_read_number(r, o, p, "overconsolidation_ratio", CASE_OPTIONAL, &AT_LEAST_ONE, &m->overconsolidation_ratio);
	case_read_number(r, o, p, "initial_reference_pressure", CASE_OPTIONAL, &POSITIVE,
			 &m->initial_reference_pressure);
	static const char *const surfaces[] = { "tip", "through_stress", NULL };
	case_read_choice(r, o, p, "initial_yield_surface", CASE_OPTIONAL, surfaces, &m->yield_surface_through_stress);
	case_read_number(r, o, p, "gas_volume_ratio", CASE_OPTIONAL,
			 &(struct case_range){ BOUND_OPEN, 1, BOUND_NONE, 0 }, &m->gas_volume_ratio);
	int ok = case_read_number(r, o, p, "dilatancy_cutoff_start", CASE_OPTIONAL, &NON_NEGATIVE,
				  &m->dilatancy_cutoff_start);
	ok &= case_read_number(r, o, p, "dilatancy_cutoff_end", CASE_OPTIONAL, &POSITIVE, &m->dilatancy_cutoff_end);
	if (ok && m->dilatancy_cutoff_end <= m->dilatancy_cutoff_start) {
		case_pointer_key(pointer, p, "dilatancy_cutoff_end");
		case_problem(r, pointer, "must be > dilatancy_cutoff_start (%s), got %s",
			     case_format_number(a, m->dilatancy_cutoff_start),
			     case_format_number(b, m->dilatancy_cutoff_end));
	}
}

/* Angles are in degrees. A friction angle above 0 and below RADIANS_SUSPECT reads as radians
 * (0.38, meant as 21.8 degrees, is a soil almost without friction): valid, but warned about. */
#define RADIANS_SUSPECT 1.6
#define RADIAN_IN_DEGREES 57.295779513082320877   /* 180 / pi */
static void warn_if_radians(struct case_reader *r, const char *p, const char *key, int ok, double degrees)
{
	if (!ok || !(degrees > 0.0 && degrees < RADIANS_SUSPECT))
		return;
	char where[CASE_POINTER_MAX], text[CASE_NUMBER_SIZE], as_degrees[CASE_NUMBER_SIZE];
	case_pointer_key(where, p, key);
	case_warn(r, where, "%s degrees is almost no friction; angles are in degrees: if %s is in radians, "
		  "write %s", case_format_number(text, degrees), text,
		  case_format_number(as_degrees, round(degrees * RADIAN_IN_DEGREES * 100.0) / 100.0));
}

void case_read_material_model(struct case_reader *r, const json_t *o, const char *p,
			      const char *const *extra_keys, struct case_material *m)
{
	const char *keys[KEYS_MAX];
	int model = MODEL_NOR_SAND + 1;   /* the union of all keys, until the model is known */
	m->strain = STRAIN_FINITE;
	m->strength_reduction_factor = 1;
	case_read_choice(r, o, p, "model", CASE_REQUIRED, model_names, &model);
	join_keys(model_keys[model], extra_keys, keys);
	case_check_keys(r, o, p, keys);
	if (model == MODEL_NOR_SAND) {
		int strain = STRAIN_FINITE;
		m->model = MODEL_NOR_SAND;
		case_read_choice(r, o, p, "strain", CASE_OPTIONAL, strain_names, &strain);
		m->strain = strain;
		read_nor_sand(r, o, p, m);
		return;
	}
	int elastic_ok = case_read_number(r, o, p, "youngs_modulus", CASE_REQUIRED, &POSITIVE, &m->youngs_modulus);
	elastic_ok &= case_read_number(r, o, p, "poisson_ratio", CASE_REQUIRED, &POISSON_RATIO, &m->poisson_ratio);
	if (model > MODEL_NOR_SAND)
		return;
	m->model = model;
	if (model == MODEL_LINEAR_ELASTIC || model == MODEL_HENCKY)
		return;
	int strain = STRAIN_FINITE;
	case_read_choice(r, o, p, "strain", CASE_OPTIONAL, strain_names, &strain);
	m->strain = strain;
	case_read_number(r, o, p, "strength_reduction_factor", CASE_OPTIONAL, &POSITIVE,
			 &m->strength_reduction_factor);
	if (model == MODEL_TRESCA_SOFTENING) {
		read_tresca(r, o, p, elastic_ok, m);
		return;
	}
	case_read_number(r, o, p, "cohesion", CASE_REQUIRED, &NON_NEGATIVE, &m->cohesion);
	int phi_ok = case_read_number(r, o, p, "friction_angle", CASE_REQUIRED, &FRICTION_ANGLE, &m->friction_angle);
	warn_if_radians(r, p, "friction_angle", phi_ok, m->friction_angle);
	if (model == MODEL_MOHR_COULOMB) {
		read_dilation(r, o, p, "dilation_angle", 0, m->friction_angle, phi_ok, &m->dilation_angle);
		return;
	}
	read_dilation(r, o, p, "initial_dilation_angle", 1, m->friction_angle, phi_ok, &m->initial_dilation_angle);
	read_dilation(r, o, p, "critical_dilation_angle", 1, m->friction_angle, phi_ok,
		      &m->critical_dilation_angle);
	read_dilation_evolution(r, o, p, m);
}
