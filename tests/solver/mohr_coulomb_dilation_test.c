/*
 * mohr_coulomb_dilation_test.c - Mohr-Coulomb with the dilation angle of 001 Eq. 17
 * (material_mohr_coulomb_dilation.c), small and finite strain.
 *
 * Oracles: the returned stress on the yield surface; the consistent tangent against central
 * differences on the main plane, both edges and the apex (material_check.h; with psi depending on
 * eps_d the plane and edge returns are Newton iterations); objectivity; reversibility; the law
 * against Eq. 17; and the flow of a plastic main-plane step: the plastic strain increment must be
 * dgamma N(psi(eps_d^{n+1})) (backward Euler), checked through its volumetric to deviatoric ratio.
 */
#include "material_check.h"

static const double DEG = 0.017453292519943295769;   /* pi / 180 */

static struct material make(enum material_strain strain)
{
	struct case_material spec = {
		.model = MODEL_MOHR_COULOMB_DILATION, .youngs_modulus = 1.0313e6, .poisson_ratio = 0.2987,
		.strain = strain, .cohesion = 3.017e3, .friction_angle = 25.3, .initial_dilation_angle = -5.13,
		.critical_dilation_angle = 0.71, .dilation_evolution_parameter = 25.3, .strength_reduction_factor = 1,
	};
	struct material m;
	material_init(&m, &spec);
	return m;
}

static void check_law(void)
{
	struct material m = make(STRAIN_SMALL);
	struct plastic_law a, b;
	double eps = 0.0417, h = 1e-7;
	mohr_coulomb_dilation_law(&m, eps, &a);
	double psi = 0.71 * DEG + (-5.13 * DEG - 0.71 * DEG) * exp(-25.3 * eps);   /* Eq. 17 */
	mohr_coulomb_dilation_law(&m, eps + h, &b);
	double slope = b.sin_psi, low;
	mohr_coulomb_dilation_law(&m, eps - h, &b);
	low = b.sin_psi;
	CHECK(rel_diff(a.sin_psi, sin(psi), 1e-300) <= 1e-14 && rel_diff(a.dsin_psi, (slope - low) / (2 * h), 1e-300) <= 1e-7
	      && a.c == 3.017e3 && a.dc == 0, "mohr_coulomb_dilation_law_eq17", "sin psi %.17g want %.17g", a.sin_psi,
	      sin(psi));
}

/* Main-plane plastic step from a known trial: dev and volumetric plastic strain increments give
 * tr(N) / (sqrt(2/3) |dev N|) = 2 sin psi / ((2/3) sqrt(3 + sin^2 psi)) at psi(eps_d^{n+1}). */
static void check_flow(void)
{
	struct material m = make(STRAIN_SMALL);
	double worst = 0;
	int n = 0;
	for (int i = 0; i < 20000 && n < 50; i++) {
		double eps[4], stress[4], eps_d0 = rnd(0, 0.2), eps_d = eps_d0;
		random_trial(-4e-2, -1e-2, 2e-2, eps);
		if (regime_of(&m, mohr_coulomb_dilation_law, eps, eps_d0) != RETURN_PLANE)
			continue;
		update_from_trial(&m, eps, &eps_d, stress, NULL);
		/* plastic strain = trial elastic strain - returned elastic strain (principal, sorted) */
		double st[3], sr[3], tr = 0, k = m.lambda / (3 * m.lambda + 2 * m.mu), ep[3], trial[4];
		for (int a = 0; a < 4; a++)
			trial[a] = (a == 2 ? 0 : m.lambda * (eps[0] + eps[1] + eps[3])) + 2 * m.mu * eps[a];
		sorted_principal(trial, st);
		sorted_principal(stress, sr);
		for (int a = 0; a < 3; a++)
			ep[a] = ((st[a] - sr[a]) - k * ((st[0] + st[1] + st[2]) - (sr[0] + sr[1] + sr[2]))) / (2 * m.mu);
		tr = ep[0] + ep[1] + ep[2];
		double dev = 0;
		for (int a = 0; a < 3; a++)
			dev += (ep[a] - tr / 3) * (ep[a] - tr / 3);
		struct plastic_law lw;
		mohr_coulomb_dilation_law(&m, eps_d, &lw);
		double s = lw.sin_psi, want = 2 * s / ((2.0 / 3.0) * sqrt(3 + s * s));
		double got = tr / (sqrt(2.0 / 3.0) * sqrt(dev));
		worst = fmax(worst, fabs(got - want));
		worst = fmax(worst, fabs((eps_d - eps_d0) - sqrt(2.0 / 3.0) * sqrt(dev)) / (eps_d - eps_d0));
		n++;
	}
	printf("INFO mohr_coulomb_dilation_flow_follows_eq17: %d main-plane steps, largest error %.3g\n", n, worst);
	CHECK(n == 50 && worst <= 1e-8, "mohr_coulomb_dilation_flow_follows_eq17", "%d steps, error %.3g", n, worst);
}

int main(void)
{
	unsigned all = 1u << RETURN_PLANE | 1u << RETURN_EDGE_12 | 1u << RETURN_EDGE_23 | 1u << RETURN_APEX |
		       1u << RETURN_ELASTIC;
	for (int finite = 0; finite < 2; finite++) {
		struct material m = make(finite ? STRAIN_FINITE : STRAIN_SMALL);
		const char *tag = finite ? "finite" : "small";
		char name[96];
		snprintf(name, sizeof name, "mohr_coulomb_dilation_%s_on_yield_surface", tag);
		check_yield_surface(name, &m, mohr_coulomb_dilation_law, -4e-2, 1e-2, 3e-2, 0.2);
		snprintf(name, sizeof name, "mohr_coulomb_dilation_%s_tangent", tag);
		check_tangent(name, &m, mohr_coulomb_dilation_law, all, -4e-2, 1e-2, 3e-2, 0.2, 0);
		snprintf(name, sizeof name, "mohr_coulomb_dilation_%s_elastic_step_reversible", tag);
		check_reversible(name, &m, mohr_coulomb_dilation_law);
		if (finite)
			check_objectivity("mohr_coulomb_dilation_finite_rotation_objective", &m, -4e-2, -1e-2, 3e-2);
	}
	check_law();
	check_flow();
	HARNESS_EXIT();
}
