/*
 * mohr_coulomb_test.c - the Mohr-Coulomb model (material_mohr_coulomb.c with principal_return.c
 * and principal_update.c), small and finite strain.
 *
 * Oracles: the yield function of the returned stress (0 to YIELD_CHECK_TOLERANCE relative), the
 * consistent tangent against central differences (FD_STEP) on the main plane, both edges and the
 * apex, objectivity under a rigid rotation, reversibility of elastic steps (material_check.h);
 * the strength reduction of 000 Eq. 91 against its formula; the apex stress c cot(phi) in closed
 * form. The triaxial peak strength is tested through the element driver (element_test.c).
 */
#include "material_check.h"

static const double DEG = 0.017453292519943295769;   /* pi / 180 */

static struct material make(enum material_strain strain, double srf)
{
	struct case_material spec = {
		.model = MODEL_MOHR_COULOMB, .youngs_modulus = 2.385e7, .poisson_ratio = 0.3125, .strain = strain,
		.cohesion = 12.37e3, .friction_angle = 31.7, .dilation_angle = 9.3, .strength_reduction_factor = srf,
	};
	struct material m;
	material_init(&m, &spec);
	return m;
}

static void check_strength_reduction(void)
{
	struct material m = make(STRAIN_SMALL, 2.0), m1 = make(STRAIN_SMALL, 1.0);
	double phi = atan(tan(31.7 * DEG) / 2.0);
	CHECK(rel_diff(m.cohesion, 12.37e3 / 2.0, 1) <= 1e-15 && rel_diff(m.phi, phi, 1) <= 1e-15 &&
	      rel_diff(m.psi, 9.3 * DEG, 1) <= 1e-15 && m1.cohesion == 12.37e3,
	      "mohr_coulomb_strength_reduction_eq91", "c %.17g phi %.17g psi %.17g", m.cohesion, m.phi, m.psi);
	struct case_material spec = { .model = MODEL_MOHR_COULOMB, .youngs_modulus = 1e7, .poisson_ratio = 0.3,
				      .cohesion = 1e4, .friction_angle = 30, .dilation_angle = 25,
				      .strength_reduction_factor = 2 };
	struct material capped;
	material_init(&capped, &spec);
	CHECK(capped.psi == capped.phi, "mohr_coulomb_strength_reduction_caps_dilation",
	      "psi %.6g phi %.6g", capped.psi, capped.phi);
}

/* Hydrostatic tension beyond the apex returns to c cot(phi) in all three directions. */
static void check_apex(enum material_strain strain, const char *name)
{
	struct material m = make(strain, 1.0);
	double eps[4] = { 2.3e-3, 2.1e-3, 1.3e-4, 1.9e-3 }, stress[4], eps_d = 0.0123;
	update_from_trial(&m, eps, &eps_d, stress, NULL);
	double apex = m.cohesion * m.cos_phi / m.sin_phi, e = 0;
	e = fmax(fmax(fabs(stress[0] - apex), fabs(stress[1] - apex)), fmax(fabs(stress[3] - apex), fabs(stress[2])));
	CHECK(e <= 1e-12 * apex && eps_d > 0.0123, name, "stress (%.10g %.10g %.10g %.10g), apex %.10g",
	      stress[0], stress[1], stress[2], stress[3], apex);
}

int main(void)
{
	unsigned all = 1u << RETURN_PLANE | 1u << RETURN_EDGE_12 | 1u << RETURN_EDGE_23 | 1u << RETURN_APEX |
		       1u << RETURN_ELASTIC;
	for (int finite = 0; finite < 2; finite++) {
		struct material m = make(finite ? STRAIN_FINITE : STRAIN_SMALL, 1.0);
		const char *tag = finite ? "finite" : "small";
		char name[96];
		snprintf(name, sizeof name, "mohr_coulomb_%s_on_yield_surface", tag);
		check_yield_surface(name, &m, mohr_coulomb_law, -4e-3, 3e-3, 3e-3, 0.1);
		snprintf(name, sizeof name, "mohr_coulomb_%s_tangent", tag);
		check_tangent(name, &m, mohr_coulomb_law, all, -4e-3, 3e-3, 3e-3, 0.1, 0);
		snprintf(name, sizeof name, "mohr_coulomb_%s_elastic_step_reversible", tag);
		check_reversible(name, &m, mohr_coulomb_law);
		snprintf(name, sizeof name, "mohr_coulomb_%s_apex_closed_form", tag);
		check_apex(m.strain, name);
		if (finite)
			check_objectivity("mohr_coulomb_finite_rotation_objective", &m, -4e-3, -1e-3, 3e-3);
	}
	/* strength reduction: the reduced surface is the one returned to */
	struct material r = make(STRAIN_FINITE, 2.0);
	check_yield_surface("mohr_coulomb_srf2_on_reduced_yield_surface", &r, mohr_coulomb_law, -4e-3, 3e-3, 3e-3, 0.1);
	check_strength_reduction();
	HARNESS_EXIT();
}
