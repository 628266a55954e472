/*
 * tresca_softening_test.c - Tresca with linear softening of the cohesion (001 §4.2.1;
 * material_tresca_softening.c), small and finite strain.
 *
 * Oracles: the returned stress on the softened yield surface s1 - s3 = 2 c(eps_d^{n+1}); the
 * consistent tangent against central differences on the main plane and both edges, on both sides
 * of the kink at eps_p^r (material_check.h); objectivity; reversibility; the law itself against
 * its formula; and a sequence of plastic pure-shear steps whose cohesion must reach c_r exactly
 * at eps_p^r and stay there. The undrained triaxial path is element_test.c's.
 */
#include "material_check.h"

static struct material make(enum material_strain strain)
{
	struct case_material spec = {
		.model = MODEL_TRESCA_SOFTENING, .youngs_modulus = 1.0137e6, .poisson_ratio = 0.4875, .strain = strain,
		.peak_cohesion = 6.413e3, .residual_cohesion = 3.587e3, .residual_plastic_strain = 0.7513,
		.strength_reduction_factor = 1,
	};
	struct material m;
	material_init(&m, &spec);
	return m;
}

static void check_law(void)
{
	struct material m = make(STRAIN_SMALL);
	struct plastic_law a, b, c;
	tresca_softening_law(&m, 0.3001, &a);
	tresca_softening_law(&m, 0.7513, &b);
	tresca_softening_law(&m, 1.9, &c);
	double expect = 6.413e3 - (6.413e3 - 3.587e3) * 0.3001 / 0.7513;
	CHECK(rel_diff(a.c, expect, 1) <= 1e-15 && b.c == 3.587e3 && c.c == 3.587e3 && c.dc == 0 &&
	      a.sin_psi == 0, "tresca_softening_law_linear_to_residual", "c %.17g %.17g %.17g", a.c, b.c, c.c);
}

/* Simple shear in steps: the cohesion falls with eps_d and is c_r from eps_p^r on. */
static void check_reaches_residual(enum material_strain strain, const char *name)
{
	struct material m = make(strain);
	double stress[4] = { -5e4, -5e4, 0, -5e4 }, Be[4], state[STATE_MAX], plastic = 0;
	material_init_state(&m, stress, Be, state);
	double dF[4] = { 1, 2.37e-3, 0, 1 }, worst = 0, J = 1, at_residual = -1;
	struct poro_error err = {0};
	int steps = 0;
	for (; steps < 2000 && state[0] < 1.2 * m.residual_plastic_strain; steps++) {
		struct stress_update u = { .dF = dF, .J = J, .stress = stress, .Be = Be, .state = state,
					   .plastic_strain = &plastic };
		if (material_update(&m, &u, &err))
			break;
		if (plastic == 0)
			continue;
		struct plastic_law lw;
		double s[3], tau[4];
		for (int k = 0; k < 4; k++)
			tau[k] = stress[k] * J;
		sorted_principal(tau, s);
		tresca_softening_law(&m, state[0], &lw);
		worst = fmax(worst, fabs((s[0] - s[2]) - 2 * lw.c) / (2 * m.cohesion));
		if (at_residual < 0 && state[0] >= m.residual_plastic_strain)
			at_residual = (s[0] - s[2]) / 2;
	}
	printf("INFO %s: %d steps, |s1 - s3 - 2 c(eps_d)| / 2 c_p <= %.3g, (s1 - s3) / 2 at eps_p^r %.10g Pa "
	       "(c_r %.10g Pa)\n", name, steps, worst, at_residual, m.residual_cohesion);
	CHECK(worst <= 1e-10 && rel_diff(at_residual, m.residual_cohesion, 1) <= 1e-10, name,
	      "worst %.3g, at residual %.10g", worst, at_residual);
}

int main(void)
{
	unsigned regimes = 1u << RETURN_PLANE | 1u << RETURN_EDGE_12 | 1u << RETURN_EDGE_23 | 1u << RETURN_ELASTIC;
	for (int finite = 0; finite < 2; finite++) {
		struct material m = make(finite ? STRAIN_FINITE : STRAIN_SMALL);
		const char *tag = finite ? "finite" : "small";
		char name[96];
		snprintf(name, sizeof name, "tresca_softening_%s_on_yield_surface", tag);
		check_yield_surface(name, &m, tresca_softening_law, -4e-3, 3e-3, 1e-2, 1.1);
		snprintf(name, sizeof name, "tresca_softening_%s_tangent", tag);
		check_tangent(name, &m, tresca_softening_law, regimes, -4e-3, 3e-3, 1e-2, 1.1,
			      m.residual_plastic_strain);
		snprintf(name, sizeof name, "tresca_softening_%s_elastic_step_reversible", tag);
		check_reversible(name, &m, tresca_softening_law);
		snprintf(name, sizeof name, "tresca_softening_%s_reaches_residual_cohesion", tag);
		check_reaches_residual(m.strain, name);
		if (finite)
			check_objectivity("tresca_softening_finite_rotation_objective", &m, -4e-3, -1e-3, 1e-2);
	}
	check_law();
	HARNESS_EXIT();
}
