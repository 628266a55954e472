/*
 * stable_dt.c - the schemes' stable time steps (stable_dt.h).
 *
 * Semi-implicit: dt_cfl = h / c_p, c_p = sqrt((K + 4G/3) / ((1 - n0) rho_s)), the smallest over
 * the bodies. The density is the soil's own mass per volume of mixture, (1 - n0) rho_s, the mass on
 * which the explicit effective stress acts at a node (Eq. 52 with the water's share moved by the
 * pressure and the drag, both implicit). It is the fastest case: where low permeability locks the
 * water to the soil the moving mass is the mixture's, (1 - n) rho_s + n rho_w, and the wave slower.
 * The measured limits (docs/numerics.md "Stable time step") are not those of the mixture: at low
 * permeability the Terzaghi column goes unstable at its drained top row, earlier than at high
 * permeability.
 *
 * Explicit (spec-002 §5.1): a plane compressional wave of amplitudes (U_s, U_f) in 002 Eqs. 9,
 * 16-17 without drag satisfies c^2 U = A U with
 *     A = [ (M + (1 - n)^2 K_f / n) / rhō_s    (1 - n) K_f / rhō_s ]
 *         [ (1 - n) K_f / rhō_f                K_f / rho_f         ],   rhō_s = (1 - n) rho_s, rhō_f = n rho_f,
 * and c_fast^2 is its larger eigenvalue, about 10% above the undrained speed
 * sqrt((M + K_f / n) / rho_sat). The drag only slows the waves, so h / c_fast bounds the explicit
 * update of both phases; with explicit drag the relative velocity also bounds it (stable_dt.h).
 *
 * The modulus is the elastic constrained modulus E (1 - nu) / ((1 + nu)(1 - 2 nu)) for the models
 * that take E and nu. Nor-Sand's bulk modulus p / kappa grows with the mean effective stress
 * (material_nor_sand.c), which is not known before the run; it is estimated at the largest
 * pressure gravity alone gives the body, the effective weight of its full height, p = (1 - n0)
 * (rho_s - rho_w) |g| H (K0 = 1, an upper bound for a column at rest; without rho_w for a dry
 * body), and never below the
 * pressure of a point that starts stress free (initial_reference_pressure). Loads on top of it
 * are not counted.
 */
#include "stable_dt.h"

#include <math.h>
#include <stdio.h>

#include "permeability.h"   /* CONDUCTIVITY_GRAVITY */

double stable_dt_effective_density(const struct case_spec *c, int i)
{
	const struct case_body *b = &c->bodies[i];
	const double rho_w = b->saturated ? c->fluid.density : 0.0;
	return (1.0 - b->porosity) * (c->materials[b->material].density - rho_w);
}

double stable_dt_modulus(const struct case_spec *c, int i)
{
	const struct case_body *b = &c->bodies[i];
	const struct case_material *m = &c->materials[b->material];
	if (m->model == MODEL_NOR_SAND) {
		const double g = hypot(c->gravity.acceleration[0], c->gravity.acceleration[1]);
		const double height = b->max[1] - b->min[1];
		const double effective = stable_dt_effective_density(c, i);
		const double p = fmax(m->initial_reference_pressure, fmax(effective, 0.0) * g * height);
		return p / m->swelling_index + 4.0 / 3.0 * m->shear_modulus;
	}
	const double E = m->youngs_modulus, nu = m->poisson_ratio;
	return E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
}

double stable_dt_fast_wave_speed(double M, double rho_s, double n, double rho_f, double K_f)
{
	const double rs = (1.0 - n) * rho_s, rf = n * rho_f;   /* apparent densities, 002 Eq. 1 */
	const double a = (M + (1.0 - n) * (1.0 - n) * K_f / n) / rs, b = (1.0 - n) * K_f / rs;
	const double c = (1.0 - n) * K_f / rf, d = K_f / rho_f;
	const double tr = a + d, det = a * d - b * c;
	return sqrt(0.5 * (tr + sqrt(fmax(tr * tr - 4.0 * det, 0.0))));
}

/* The semi-implicit scheme's skeleton CFL step of body i. */
static struct stable_dt skeleton_step(const struct case_spec *c, int i)
{
	const struct case_body *b = &c->bodies[i];
	const double modulus = stable_dt_modulus(c, i);
	const double density = (1.0 - b->porosity) * c->materials[b->material].density;
	const double speed = sqrt(modulus / density), step = c->grid.cell_size / speed;
	return (struct stable_dt){ .scheme = SCHEME_SEMI_IMPLICIT, .cfl = step, .wave_speed = speed,
				   .modulus = modulus, .density = density, .body = i, .wave_step = step,
				   .drag_step = INFINITY, .drag_body = -1 };
}

/* The explicit scheme's wave step of body i, and its drag step when the drag is explicit. */
static struct stable_dt coupled_step(const struct case_spec *c, int i, double *drag_step)
{
	const struct case_body *b = &c->bodies[i];
	const double rho_s = c->materials[b->material].density, n = b->porosity, rho_f = c->fluid.density;
	const double modulus = stable_dt_modulus(c, i);
	const double speed = stable_dt_fast_wave_speed(modulus, rho_s, n, rho_f, c->fluid.bulk_modulus);
	const double step = c->grid.cell_size / speed;
	*drag_step = INFINITY;
	if (c->formulation.drag == DRAG_EXPLICIT) {
		const double c_d = n * n * rho_f * CONDUCTIVITY_GRAVITY / b->hydraulic_conductivity;   /* Eq. 12 */
		*drag_step = 2.0 / (c_d * (1.0 / ((1.0 - n) * rho_s) + 1.0 / (n * rho_f)));
	}
	return (struct stable_dt){ .scheme = SCHEME_EXPLICIT, .cfl = step, .wave_speed = speed, .modulus = modulus,
				   .density = (1.0 - n) * rho_s, .body = i, .wave_step = step,
				   .drag_step = INFINITY, .drag_body = -1 };
}

void stable_dt_estimate(const struct case_spec *c, struct stable_dt *out)
{
	*out = (struct stable_dt){ .scheme = c->formulation.scheme, .cfl = INFINITY, .wave_step = INFINITY,
				   .drag_step = INFINITY, .body = -1, .drag_body = -1 };
	if (c->formulation.scheme == SCHEME_IMPLICIT_UPU)
		return;   /* Newmark's average acceleration: stable at any step (stable_dt.h) */
	for (int i = 0; i < c->body_count; i++) {
		double drag_step = INFINITY;
		const struct stable_dt e = c->formulation.scheme == SCHEME_EXPLICIT ? coupled_step(c, i, &drag_step)
									       : skeleton_step(c, i);
		if (e.wave_step < out->wave_step) {
			const double kept_drag = out->drag_step;
			const int kept_body = out->drag_body;
			*out = e;
			out->drag_step = kept_drag, out->drag_body = kept_body;
		}
		if (drag_step < out->drag_step)
			out->drag_step = drag_step, out->drag_body = i;
	}
	out->cfl = fmin(out->wave_step, out->drag_step);
}

double stable_dt_max(const struct stable_dt *e)
{
	return (e->scheme == SCHEME_EXPLICIT ? STABLE_DT_EXPLICIT_MAX_FACTOR : STABLE_DT_MAX_FACTOR) * e->cfl;
}

double stable_dt_recommended(const struct stable_dt *e)
{
	return (e->scheme == SCHEME_EXPLICIT ? STABLE_DT_EXPLICIT_RECOMMENDED_FACTOR : STABLE_DT_RECOMMENDED_FACTOR) *
	       e->cfl;
}

void stable_dt_describe(const struct stable_dt *e, const struct case_spec *c, char *text, size_t size)
{
	if (e->body < 0) {
		snprintf(text, size, "no body sets a bound");
		return;
	}
	if (e->scheme != SCHEME_EXPLICIT) {
		snprintf(text, size, "%.3g times the soil skeleton's CFL step h / c_p = %.3g s (c_p = sqrt((K + 4G/3) / "
			 "((1 - n) rho_s)) = %.4g m/s in body '%s')", STABLE_DT_MAX_FACTOR, e->cfl, e->wave_speed,
			 c->bodies[e->body].name);
		return;
	}
	int n = snprintf(text, size, "the explicit scheme's critical step: h / c_fast = %.3g s (c_fast = %.4g m/s, the "
			 "fast wave of the soil and its compressible pore fluid in body '%s')", e->wave_step,
			 e->wave_speed, c->bodies[e->body].name);
	if (e->drag_body >= 0 && n >= 0 && (size_t)n < size)
		snprintf(text + n, size - (size_t)n, " and 2 / lambda = %.3g s (the explicit drag's relative-velocity "
			 "decay in body '%s'; formulation.drag \"implicit\" has no such bound)", e->drag_step,
			 c->bodies[e->drag_body].name);
}
