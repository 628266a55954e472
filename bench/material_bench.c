/*
 * material_bench.c - nanoseconds per stress update of each constitutive model (material.h),
 * elastic and plastic steps separately, small and finite strain, with and without the consistent
 * tangent. Printed, never asserted; bench/run.sh runs it. Nor-Sand (000 Table 6 parameters) starts
 * its elastic steps from an overconsolidated state and its plastic ones from OCR = 1.
 *
 * Each timed update starts from the same point state (restored by a copy of 16 doubles, included
 * in the figure) and applies the same dF: a small in-plane shear-and-compression increment from a
 * state well inside the yield surface (elastic), or a large one from a state on it (plastic, a
 * return to the main plane). POINTS states, drawn with different rotations, are cycled through
 * so branch prediction does not learn one path.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "material.h"

#define REPEATS 2000000
#define POINTS 64

struct point { double stress[4], Be[4], state[STATE_MAX], plastic_strain; };

static double now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* ns per update from the states start[] with increments dF[], and how many updates were plastic. */
static double time_updates(const struct material *m, const struct point *start, double (*dF)[4], int tangent,
			   int *plastic)
{
	struct point p;
	double T[16], sink = 0;
	struct poro_error err = {0};
	*plastic = 0;
	double t0 = now();
	for (int i = 0; i < REPEATS; i++) {
		int k = i % POINTS;
		p = start[k];
		struct stress_update u = { .dF = dF[k], .J = 1.0, .stress = p.stress, .Be = p.Be, .state = p.state,
					   .plastic_strain = &p.plastic_strain, .tangent = tangent ? T : NULL };
		material_update(m, &u, &err);
		sink += p.stress[0];
		*plastic += p.plastic_strain > start[k].plastic_strain;
	}
	double ns = (now() - t0) / REPEATS * 1e9;
	if (sink == 42.0)
		printf(" ");
	return ns;
}

/* POINTS states at the isotropic stress -p0 (Be to match) and rotated increments of size a. */
static void make_states(const struct material *m, double a, struct point *start, double (*dF)[4])
{
	for (int k = 0; k < POINTS; k++) {
		struct point *p = &start[k];
		memset(p, 0, sizeof *p);
		double th = 0.1 + 3.0 * k / POINTS, c = cos(th), s = sin(th);
		p->stress[0] = -1.1e5, p->stress[1] = -0.9e5, p->stress[3] = -1.0e5;
		material_init_state(m, p->stress, p->Be, p->state);
		/* dF = I + R diag(-a, 0.3 a) R^T + a small spin */
		double e1 = -a, e2 = 0.3 * a;
		dF[k][0] = 1 + c * c * e1 + s * s * e2;
		dF[k][3] = 1 + s * s * e1 + c * c * e2;
		dF[k][1] = c * s * (e1 - e2) + 1e-4;
		dF[k][2] = c * s * (e1 - e2) - 1e-4;
	}
}

static void bench(const char *label, const struct case_material *spec)
{
	struct material m;
	struct point start[POINTS];
	double dF[POINTS][4];
	material_init(&m, spec);
	int kinds = spec->model == MODEL_LINEAR_ELASTIC || spec->model == MODEL_HENCKY ? 1 : 2;
	for (int plastic_step = 0; plastic_step < kinds; plastic_step++) {
		/* nor_sand: elastic steps from an overconsolidated state (OCR 4), plastic ones from OCR 1 */
		struct case_material variant = *spec;
		variant.overconsolidation_ratio = plastic_step ? 1.0 : 4.0;
		if (spec->model == MODEL_NOR_SAND)
			material_init(&m, &variant);
		make_states(&m, plastic_step ? 2e-2 : 1e-5, start, dF);
		for (int tangent = 0; tangent < 2; tangent++) {
			int plastic;
			double ns = time_updates(&m, start, dF, tangent, &plastic);
			printf("%-34s %-8s %-12s %7.1f ns per update  (%d%% plastic)\n", label,
			       plastic_step ? "plastic" : "elastic", tangent ? "+ tangent" : "no tangent", ns,
			       (int)(100.0 * plastic / REPEATS + 0.5));
		}
	}
}

int main(void)
{
	struct case_material base = { .youngs_modulus = 1e8, .poisson_ratio = 0.3, .cohesion = 2e4,
				      .friction_angle = 30, .dilation_angle = 5, .peak_cohesion = 2e4,
				      .residual_cohesion = 1e4, .residual_plastic_strain = 0.5,
				      .initial_dilation_angle = -5, .critical_dilation_angle = 0,
				      .dilation_evolution_parameter = 25, .strength_reduction_factor = 1,
				      /* nor_sand: 000 Table 6 (Hostun sand), v0 = 1.7 */
				      .shear_modulus = 40e6, .swelling_index = 0.002, .compression_index = 0.02,
				      .reference_specific_volume = 1.892, .critical_state_reference_pressure = 1e3,
				      .critical_stress_ratio = 1.0, .yield_function_constant = 0.1,
				      .plastic_potential_constant = 0.1, .hardening_coefficient = 100,
				      .dilatancy_multiplier = -2.0, .initial_specific_volume = 1.7,
				      .overconsolidation_ratio = 1, .initial_reference_pressure = 2e3,
				      .dilatancy_cutoff_start = 1.0, .dilatancy_cutoff_end = 1.5, .gas_volume_ratio = 1.6 };
	static const struct { enum material_model model; enum material_strain strain; const char *label; } models[] = {
		{ MODEL_LINEAR_ELASTIC, STRAIN_SMALL, "linear_elastic" },
		{ MODEL_HENCKY, STRAIN_FINITE, "hencky" },
		{ MODEL_MOHR_COULOMB, STRAIN_SMALL, "mohr_coulomb small" },
		{ MODEL_MOHR_COULOMB, STRAIN_FINITE, "mohr_coulomb finite" },
		{ MODEL_TRESCA_SOFTENING, STRAIN_SMALL, "tresca_softening small" },
		{ MODEL_TRESCA_SOFTENING, STRAIN_FINITE, "tresca_softening finite" },
		{ MODEL_MOHR_COULOMB_DILATION, STRAIN_SMALL, "mohr_coulomb_dilation small" },
		{ MODEL_MOHR_COULOMB_DILATION, STRAIN_FINITE, "mohr_coulomb_dilation finite" },
		{ MODEL_NOR_SAND, STRAIN_SMALL, "nor_sand small" },
		{ MODEL_NOR_SAND, STRAIN_FINITE, "nor_sand finite" },
	};
	for (size_t i = 0; i < sizeof models / sizeof models[0]; i++) {
		struct case_material spec = base;
		spec.model = models[i].model;
		spec.strain = models[i].strain;
		bench(models[i].label, &spec);
	}
	return 0;
}
