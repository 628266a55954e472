/*
 * stable_dt.c - the skeleton's CFL step of the semi-implicit scheme (stable_dt.h).
 *
 * dt_cfl = h / c_p, c_p = sqrt((K + 4G/3) / ((1 - n0) rho_s)), the smallest over the bodies.
 *
 * The density is the soil's own mass per volume of mixture, (1 - n0) rho_s, the mass on which the
 * explicit effective stress acts at a node (Eq. 52 with the water's share moved by the pressure and
 * the drag, both implicit). It is the fastest case: where low permeability locks the water to the
 * soil the moving mass is the mixture's, (1 - n) rho_s + n rho_w, and the wave slower. The measured
 * limits (docs/numerics.md "Stable time step") are not those of the mixture: at low permeability
 * the Terzaghi column goes unstable at its drained top row, earlier than at high permeability.
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

void stable_dt_estimate(const struct case_spec *c, struct stable_dt *out)
{
	*out = (struct stable_dt){ .cfl = INFINITY, .body = -1 };
	for (int i = 0; i < c->body_count; i++) {
		const struct case_body *b = &c->bodies[i];
		const double modulus = stable_dt_modulus(c, i);
		const double density = (1.0 - b->porosity) * c->materials[b->material].density;
		const double speed = sqrt(modulus / density);
		const double cfl = c->grid.cell_size / speed;
		if (cfl < out->cfl)
			*out = (struct stable_dt){ cfl, speed, modulus, density, i };
	}
}

double stable_dt_max(const struct stable_dt *e)
{
	return STABLE_DT_MAX_FACTOR * e->cfl;
}
