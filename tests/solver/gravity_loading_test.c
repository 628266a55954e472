/*
 * gravity_loading_test.c - the elastic gravity loading of 000 App. B.4 (gravity.elastic_loading)
 * on a Nor-Sand column (Table 6's Hostun parameters, OCR 1.7):
 *  - every step that ends within the gravity ramp is elastic: no point has plastic strain;
 *  - the first step after the ramp takes each point's state at the end of the ramp as its
 *    reference: p0 = the Kirchhoff mean pressure J p' (Eq. 111, compression positive) and the
 *    image pressure OCR p0 (1 - N)^((1 - N) / N) (Eq. 113), to 1e-12 relative, at every point that
 *    stays elastic in that step (a point whose K0 deviator puts it outside the new surface is
 *    returned to it and hardens, as the paper implies; those are counted);
 *  - a case asking for elastic loading without a ramp is refused, naming the key.
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
	"   \"overconsolidation_ratio\": %g}],"
	" \"bodies\": [{\"name\": \"column\", \"material\": \"hostun\", \"rectangle\": {\"min\": [0.0, 0.0],"
	"   \"max\": [0.1, 0.5]}, \"particles_per_cell\": 2, \"porosity\": 0.39, \"hydraulic_conductivity\": 1e-3}],"
	" \"fluid\": {\"density\": 1000},"
	" \"gravity\": {\"acceleration\": [0.0, -9.81], \"ramp_time\": %g, \"elastic_loading\": true},"
	" \"boundaries\": {\"left\": {\"soil\": \"slip\", \"water\": \"slip\"},"
	"   \"right\": {\"soil\": \"slip\", \"water\": \"slip\"}, \"bottom\": {\"soil\": \"fixed\", \"water\": \"fixed\"}},"
	" \"time\": {\"dt\": 1e-4, \"end\": 0.012}}";

int main(void)
{
	char json[4096];
	snprintf(json, sizeof json, case_format, N_YIELD, OCR, RAMP);
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

	snprintf(json, sizeof json, case_format, N_YIELD, OCR, 0.0);
	int st = case_load_string(json, &c, &err);
	CHECK(st == PORO_EINVAL && strstr(err.message, "/gravity/elastic_loading: "), "elastic_loading_without_ramp_refused",
	      "status %d: %s", st, err.message);
	case_destroy(&c);
	HARNESS_EXIT();
}
