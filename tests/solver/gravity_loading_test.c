/*
 * gravity_loading_test.c - the elastic gravity loading of 000 App. B.4 (gravity.elastic_loading)
 * on a Nor-Sand column (Table 6's Hostun parameters, OCR 1.7):
 *  - every step that ends within the gravity ramp is elastic: no point has plastic strain;
 *  - the first step after the ramp takes each point's state at the end of the ramp as its
 *    reference: p0 = the Kirchhoff mean pressure J p' (Eq. 111, compression positive) and the
 *    image pressure OCR p0 (1 - N)^((1 - N) / N) (Eq. 113), to 1e-12 relative, at every point that
 *    stays elastic in that step (a point whose K0 deviator puts it outside the new surface is
 *    returned to it and hardens, as the paper implies; those are counted);
 *  - a case asking for elastic loading without a ramp is refused, naming the key;
 *  - after a slower ramp (0.1 s, drained) the column carries its buoyant weight (sigma'_yy within 3%
 *    of gamma' H, the rest being the water's lag behind the ramp: 1.7% at 0.1 s, 0.7% at 0.3 s) and
 *    every point follows the uniaxial-strain closed form of the hyperelastic law (sigma'_xx to 1e-6
 *    of p0); the base then sits at q/p about 2, above M = 1. In the first plastic step
 *    initial_yield_surface "through_stress" keeps that stress (a change below one ramp step's load,
 *    equilibrium still within 3%) while the tip's surface (Eq. 113) drops the column out of
 *    equilibrium (by 41% of gamma' H), as in the landslides (docs/examples.md).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../harness.h"
#include "case.h"
#include "material.h"
#include "poro.h"

#define RAMP 0.01      /* s: 100 steps of 1e-4 s */
#define OCR 1.7
#define N_YIELD 0.1

static const char case_format[] =
	"{\"schema\": \"poro-case/1\", \"title\": \"Nor-Sand column under elastic gravity loading\","
	" \"formulation\": {\"scheme\": \"semi_implicit\", \"phases\": \"double_point\"},"
	" \"grid\": {\"origin\": [0.0, 0.0], \"extent\": [0.1, 0.55], \"cell_size\": 0.025},"
	" \"materials\": [{\"name\": \"hostun\", \"model\": \"nor_sand\", \"density\": 2650, \"shear_modulus\": 40e6,"
	"   \"swelling_index\": 0.002, \"compression_index\": 0.02, \"reference_specific_volume\": 1.892,"
	"   \"critical_stress_ratio\": 1.0, \"yield_function_constant\": %g, \"plastic_potential_constant\": 0.1,"
	"   \"hardening_coefficient\": 100, \"dilatancy_multiplier\": -2.0, \"initial_specific_volume\": 1.65,"
	"   \"overconsolidation_ratio\": %g%s}],"
	" \"bodies\": [{\"name\": \"column\", \"material\": \"hostun\", \"rectangle\": {\"min\": [0.0, 0.0],"
	"   \"max\": [0.1, 0.5]}, \"particles_per_cell\": 2, \"porosity\": 0.39, \"hydraulic_conductivity\": %g}],"
	" \"fluid\": {\"density\": 1000},"
	" \"gravity\": {\"acceleration\": [0.0, -9.81], \"ramp_time\": %g, \"elastic_loading\": true},"
	" \"boundaries\": {\"left\": {\"soil\": \"slip\", \"water\": \"slip\"},"
	"   \"right\": {\"soil\": \"slip\", \"water\": \"slip\"}, \"bottom\": {\"soil\": \"fixed\", \"water\": \"fixed\"}},"
	" \"time\": {\"dt\": 1e-4, \"end\": %g}}";

/* The state the ramp leaves, against closed forms. The column's walls slip and its base is fixed,
 * so every point is in uniaxial strain (F_xx = 1) and, once the water has drained, carries the
 * buoyant weight above it: sigma'_yy = -gamma' (H - y), gamma' = (1 - n)(rho_s - rho_w) g.
 * Nor-Sand's hyperelastic law in uniaxial Hencky strain eps (J = e^eps) then fixes the rest:
 *     J sigma'_yy = -p0 exp(-eps / kappa) + 4/3 G eps,   J sigma'_xx = -p0 exp(-eps / kappa) - 2/3 G eps,
 * with p0 the stress-free point's initial_reference_pressure (2 kPa). With G = 40 MPa against
 * K = p / kappa = 1 MPa the load goes almost wholly into shear: p' stays near p0 and q/p at the base
 * is about 2, twice M (docs/examples.md, "What the elastic loading leaves"). Then the first step with
 * plasticity: with "through_stress" the surface holds the loaded stress and the column stays in
 * equilibrium; with the tip (Eq. 113) the deep points are returned far inside and the column is no
 * longer carrying its weight. */
#define LOADED_RAMP 0.1          /* s: the water's lag behind the ramp is then about 2% of gamma' H */
#define LOADED_K 1e-2            /* m/s: c_v = k (K + 4/3 G) / gamma_w, about 55 m^2/s */
#define COLUMN_H 0.5             /* m, as in case_format */
#define BUOYANT_WEIGHT (0.61 * (2650.0 - 1000.0) * 9.81)   /* gamma', N/m^3, as in case_format */
#define P_START 2e3              /* Pa, initial_reference_pressure's default */
#define SHEAR_MODULUS 40e6
#define KAPPA 0.002
#define EQUILIBRIUM_TOLERANCE 0.03   /* of gamma' H: the lag, H^2 / (2 c_v T) = 2.3% */

/* sigma'_xx of a point in uniaxial strain whose sigma'_yy is syy (Newton on eps). */
static double uniaxial_sxx(double syy)
{
	double eps = 0.0;
	for (int it = 0; it < 50; it++) {
		double e = P_START * exp(-eps / KAPPA), J = exp(eps);
		double r = (-e + 4.0 / 3.0 * SHEAR_MODULUS * eps) / J - syy;
		double dr = (e / KAPPA + 4.0 / 3.0 * SHEAR_MODULUS) / J - (-e + 4.0 / 3.0 * SHEAR_MODULUS * eps) / J;
		eps -= r / dr;
		if (fabs(r) < 1e-12 * P_START)
			break;
	}
	return (-P_START * exp(-eps / KAPPA) - 2.0 / 3.0 * SHEAR_MODULUS * eps) / exp(eps);
}

/* Largest |sigma'_yy + gamma' (H - y)| / (gamma' H) over the column's points. */
static double equilibrium_error(const struct particles *p)
{
	double worst = 0.0;
	for (idx_t q = 0; q < p->n; q++)
		worst = fmax(worst, fabs(p->stress[4 * q + 1] + BUOYANT_WEIGHT * (COLUMN_H - p->x[2 * q + 1])));
	return worst / (BUOYANT_WEIGHT * COLUMN_H);
}

static void check_loaded_state_and_first_plastic_step(void)
{
	double equilibrium[2] = { 0, 0 }, after[2] = { 0, 0 }, change[2] = { 0, 0 }, worst_sxx = 0, base_eta = 0, base_k0 = 0;
	int ok = 1;
	for (int through = 0; through <= 1; through++) {
		char json[4096], extra[96];
		snprintf(extra, sizeof extra, ", \"initial_yield_surface\": \"%s\"", through ? "through_stress" : "tip");
		snprintf(json, sizeof json, case_format, N_YIELD, OCR, extra, LOADED_K, LOADED_RAMP, LOADED_RAMP + 2e-3);
		struct case_spec *c = NULL;
		struct sim *s = NULL;
		struct poro_error err = {0};
		ok &= !case_load_string(json, &c, &err) && !sim_create(&s, c, &err);
		const struct particles *p = ok ? sim_soil(s) : NULL;
		while (ok && sim_steps_taken(s) < lround(LOADED_RAMP / 1e-4))
			ok &= !sim_step(s);
		if (!ok) {
			printf("INFO loaded column (%s): %s\n", extra, s ? sim_error(s)->message : err.message);
			sim_destroy(&s);
			case_destroy(&c);
			break;
		}
		equilibrium[through] = equilibrium_error(p);
		double *loaded = malloc(sizeof(double) * 4 * (size_t)p->n), deepest = COLUMN_H;
		memcpy(loaded, p->stress, sizeof(double) * 4 * (size_t)p->n);
		for (idx_t q = 0; q < p->n; q++) {
			const double *sg = p->stress + 4 * q, pm = -(sg[0] + sg[1] + sg[3]) / 3.0;
			worst_sxx = fmax(worst_sxx, fabs(sg[0] - uniaxial_sxx(sg[1])) / P_START);
			if (p->x[2 * q + 1] < deepest)
				deepest = p->x[2 * q + 1], base_eta = fabs(sg[1] - sg[0]) / pm, base_k0 = sg[0] / sg[1];
		}
		ok &= !sim_step(s);
		after[through] = equilibrium_error(p);
		for (idx_t q = 0; q < 4 * p->n; q++)
			change[through] = fmax(change[through], fabs(p->stress[q] - loaded[q]) / P_START);
		free(loaded);
		sim_destroy(&s);
		case_destroy(&c);
	}
	printf("INFO loaded column: sigma'_yy from the weight within %.2f%% of gamma' H, sigma'_xx from the uniaxial "
	       "closed form within %.2g of p0; base q/p %.2f, K0 %.3f; first plastic step: largest stress change %.3g of "
	       "p0 and equilibrium %.1f%% (through_stress), %.3g and %.1f%% (tip)\n", 100 * equilibrium[1], worst_sxx,
	       base_eta, base_k0, change[1], 100 * after[1], change[0], 100 * after[0]);
	CHECK(ok && equilibrium[0] <= EQUILIBRIUM_TOLERANCE && equilibrium[1] <= EQUILIBRIUM_TOLERANCE,
	      "loaded_column_carries_its_weight", "%.3f, %.3f of gamma' H", equilibrium[0], equilibrium[1]);
	CHECK(ok && worst_sxx <= 1e-6, "loaded_column_follows_uniaxial_hyperelasticity", "%.3g of p0", worst_sxx);
	CHECK(ok && base_eta > 1.0, "loaded_column_base_above_critical_stress_ratio", "q/p %.3f, M 1", base_eta);
	/* a step's change of stress is held to what one step of the ramp added at the base */
	const double ramp_increment = BUOYANT_WEIGHT * COLUMN_H * 1e-4 / LOADED_RAMP / P_START;
	CHECK(ok && after[1] <= EQUILIBRIUM_TOLERANCE && change[1] <= ramp_increment, "through_stress_keeps_the_loaded_column",
	      "equilibrium %.3f, stress change %.3g of p0 (one ramp step %.3g)", after[1], change[1], ramp_increment);
	CHECK(ok && after[0] > 5 * EQUILIBRIUM_TOLERANCE, "tip_reset_leaves_the_column_out_of_equilibrium",
	      "equilibrium %.3f of gamma' H", after[0]);
}

int main(void)
{
	char json[4096];
	snprintf(json, sizeof json, case_format, N_YIELD, OCR, "", 1e-3, RAMP, RAMP + 2e-3);
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	int ok = !case_load_string(json, &c, &err) && !sim_create(&s, c, &err);
	CHECK(ok, "nor_sand_column_created", "%s", err.message);
	if (!ok)
		HARNESS_EXIT();
	const struct particles *p = sim_soil(s);
	const long ramp_steps = lround(RAMP / 1e-4);
	double worst_plastic = 0.0;
	while (ok && sim_steps_taken(s) < ramp_steps) {
		ok = !sim_step(s);
		for (idx_t q = 0; q < p->n; q++)
			worst_plastic = fmax(worst_plastic, fabs(p->plastic_strain[q]));
	}
	CHECK(ok, "ramp_runs", "%s", ok ? "" : sim_error(s)->message);
	CHECK(worst_plastic == 0.0, "no_plastic_strain_during_ramp", "largest plastic strain %.3e", worst_plastic);

	/* the state at the end of the ramp, then the first step after it */
	double *p_kirchhoff = malloc(sizeof(double) * (size_t)p->n);
	double deepest = 0.0;
	for (idx_t q = 0; q < p->n; q++) {
		const double *sg = p->stress + 4 * q, J = p->volume[q] / p->volume0[q];
		p_kirchhoff[q] = -J * (sg[0] + sg[1] + sg[3]) / 3.0;
		deepest = fmax(deepest, p_kirchhoff[q]);
	}
	printf("INFO gravity loading: mean effective stress at the end of the ramp up to %.1f Pa\n", deepest);
	CHECK(deepest > 1e3, "ramp_builds_effective_stress", "largest p' %.3g Pa", deepest);
	ok = ok && !sim_step(s);
	double worst_p0 = 0.0, worst_pi = 0.0;
	long elastic = 0;
	const double factor = OCR * pow(1.0 - N_YIELD, (1.0 - N_YIELD) / N_YIELD);   /* Eq. 113, N > 0 */
	for (idx_t q = 0; ok && q < p->n; q++) {
		const double *st = p->state + STATE_MAX * q;
		worst_p0 = fmax(worst_p0, fabs(st[NOR_SAND_REFERENCE_PRESSURE] - p_kirchhoff[q]) / p_kirchhoff[q]);
		if (p->plastic_strain[q] != 0.0)
			continue;
		elastic++;
		worst_pi = fmax(worst_pi, fabs(st[NOR_SAND_IMAGE_PRESSURE] - factor * st[NOR_SAND_REFERENCE_PRESSURE]) /
						  (factor * st[NOR_SAND_REFERENCE_PRESSURE]));
	}
	printf("INFO gravity loading: reference pressure vs J p' at the end of the ramp %.2e; image pressure vs "
	       "Eq. 113 %.2e at the %ld of %ld points elastic in the next step (relative)\n", worst_p0, worst_pi,
	       elastic, (long)p->n);
	CHECK(elastic >= 10, "image_pressure_check_has_points", "%ld of %ld elastic", elastic, (long)p->n);
	CHECK(ok && worst_p0 <= 1e-12, "reference_pressure_is_end_of_ramp_pressure", "%.3e", worst_p0);
	CHECK(ok && worst_pi <= 1e-12, "image_pressure_from_ocr_eq113", "%.3e", worst_pi);
	free(p_kirchhoff);
	sim_destroy(&s);
	case_destroy(&c);

	snprintf(json, sizeof json, case_format, N_YIELD, OCR, "", 1e-3, 0.0, 0.012);
	int st = case_load_string(json, &c, &err);
	CHECK(st == PORO_EINVAL && strstr(err.message, "/gravity/elastic_loading: "), "elastic_loading_without_ramp_refused",
	      "status %d: %s", st, err.message);
	case_destroy(&c);
	check_loaded_state_and_first_plastic_step();
	HARNESS_EXIT();
}
