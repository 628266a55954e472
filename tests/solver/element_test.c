/*
 * element_test.c - the single-element triaxial driver (element.c, element_case.c) with the
 * Mohr-Coulomb family, against closed forms.
 *
 * Drained triaxial compression holds the cell pressure p_c, so the Mohr-Coulomb peak is
 *     q_peak = (2 p_c sin(phi) + 2 c cos(phi)) / (1 - sin(phi))
 * at small strain. At finite strain the yield function acts on the Kirchhoff stress tau = J sigma
 * while the driver holds the Cauchy stress, so each plastic row must satisfy
 *     q = (2 p_c sin(phi) + 2 c cos(phi) / J) / (1 - sin(phi)),  J from the row.
 * Undrained (J = 1, psi = 0: p stays p_c): q = (6 p sin(phi) + 6 c cos(phi)) / (3 - sin(phi)).
 * With SRF = 2, c and phi are those of 000 Eq. 91. Tresca with softening, undrained: q = 2 c(eps_d)
 * on every plastic row, 2 c_r from eps_p^r on. Evolving dilation, drained: the dilation angle
 * column follows 001 Eq. 17 and, on the plateau where p and q are constant (no elastic strain
 * change), d eps_v / d eps_d = 6 sin(psi) / (3 - sin(psi)) with psi at the end of the step.
 */
#include "../harness.h"
#include "element.h"

static const double DEG = 0.017453292519943295769;

static int run(const char *json, struct element_result *r)
{
	struct element_case c;
	struct poro_error err = {0};
	if (element_case_load_string(json, &c, &err) || element_run(&c, r, &err)) {
		printf("INFO element failed: %s\n", err.message);
		return 0;
	}
	return 1;
}

static const char *drained_mc(char *buf, size_t n, const char *strain, double srf)
{
	snprintf(buf, n, "{\"schema\": \"poro-element/1\", \"material\": {\"model\": \"mohr_coulomb\", \"strain\": \"%s\","
		 " \"youngs_modulus\": 8.765e7, \"poisson_ratio\": 0.2871, \"cohesion\": 17.31e3, \"friction_angle\": 33.7,"
		 " \"dilation_angle\": 7.9, \"strength_reduction_factor\": %g}, \"test\": \"drained\","
		 " \"confining_pressure\": 123.4e3, \"axial_strain\": -0.1, \"steps\": 500}", strain, srf);
	return buf;
}

static void check_drained_peak(const char *strain, double srf)
{
	char json[1024], name[96];
	struct element_result r;
	snprintf(name, sizeof name, "element_mohr_coulomb_drained_%s_srf%g_peak", strain, srf);
	if (!run(drained_mc(json, sizeof json, strain, srf), &r)) {
		CHECK(0, name, "run failed");
		return;
	}
	double phi = atan(tan(33.7 * DEG) / srf), c = 17.31e3 / srf, pc = 123.4e3, s = sin(phi);
	double worst = 0, peak = 0, p_drift = 0;
	int plastic = 0;
	for (int i = 1; i < r.rows; i++) {
		const struct element_row *w = &r.row[i];
		/* lateral stresses held: dq = 3 dp */
		p_drift = fmax(p_drift, fabs((w->q - r.row[0].q) - 3 * (w->p - r.row[0].p)) / pc);
		if (w->outputs[0] == 0)
			continue;
		double J = strain[0] == 'f' ? w->J : 1.0;
		double want = (2 * pc * s + 2 * c * cos(phi) / J) / (1 - s);
		worst = fmax(worst, fabs(w->q - want) / want);
		peak = fmax(peak, w->q);
		plastic++;
	}
	printf("INFO %s: %d plastic rows, peak q %.10g Pa, largest |q - q_MC| / q_MC %.3g, |dq - 3 dp| / p_c %.3g\n",
	       name, plastic, peak, worst, p_drift);
	CHECK(plastic > 100 && worst <= 1e-6 && p_drift <= 1e-8, name, "%d plastic rows, error %.3g, drift %.3g",
	      plastic, worst, p_drift);
	element_result_release(&r);
}

static void check_undrained_mc(void)
{
	const char *json = "{\"schema\": \"poro-element/1\", \"material\": {\"model\": \"mohr_coulomb\","
			   " \"youngs_modulus\": 5.432e7, \"poisson_ratio\": 0.3127, \"cohesion\": 9.87e3,"
			   " \"friction_angle\": 27.3, \"dilation_angle\": 0}, \"test\": \"undrained\","
			   " \"confining_pressure\": 81.7e3, \"axial_strain\": -0.15, \"steps\": 300}";
	struct element_result r;
	if (!run(json, &r)) {
		CHECK(0, "element_mohr_coulomb_undrained_finite", "run failed");
		return;
	}
	double phi = 27.3 * DEG, s = sin(phi), worst = 0, dv = 0;
	int plastic = 0;
	for (int i = 1; i < r.rows; i++) {
		const struct element_row *w = &r.row[i];
		dv = fmax(dv, fabs(w->volumetric_strain));
		if (w->outputs[0] == 0)
			continue;
		double want = (6 * w->p * s + 6 * 9.87e3 * cos(phi)) / (3 - s);
		worst = fmax(worst, fabs(w->q - want) / want);
		worst = fmax(worst, fabs(w->p - 81.7e3) / 81.7e3);
		plastic++;
	}
	printf("INFO element_mohr_coulomb_undrained_finite: %d plastic rows, largest relative error in q and p %.3g,"
	       " |ln J| <= %.3g\n", plastic, worst, dv);
	CHECK(plastic > 100 && worst <= 1e-8 && dv <= 1e-12, "element_mohr_coulomb_undrained_finite",
	      "%d rows, error %.3g, ln J %.3g", plastic, worst, dv);
	element_result_release(&r);
}

static void check_tresca_undrained(const char *strain)
{
	char json[1024], name[96];
	snprintf(json, sizeof json, "{\"schema\": \"poro-element/1\", \"material\": {\"model\": \"tresca_softening\","
		 " \"strain\": \"%s\", \"youngs_modulus\": 1.013e6, \"poisson_ratio\": 0.49, \"peak_cohesion\": 6.41e3,"
		 " \"residual_cohesion\": 3.59e3, \"residual_plastic_strain\": 0.7517}, \"test\": \"undrained\","
		 " \"confining_pressure\": 51.3e3, \"axial_strain\": -0.95, \"steps\": 950}", strain);
	snprintf(name, sizeof name, "element_tresca_softening_undrained_%s_reaches_residual", strain);
	struct element_result r;
	if (!run(json, &r)) {
		CHECK(0, name, "run failed");
		return;
	}
	double worst = 0, first_residual = -1, slope = (6.41e3 - 3.59e3) / 0.7517;
	int plastic = 0;
	for (int i = 1; i < r.rows; i++) {
		const struct element_row *w = &r.row[i];
		double eps = w->outputs[0];
		if (eps == 0)
			continue;
		double c = eps < 0.7517 ? 6.41e3 - slope * eps : 3.59e3;
		double J = strain[0] == 'f' ? w->J : 1;
		worst = fmax(worst, fabs(w->q * J - 2 * c) / (2 * c));
		worst = fmax(worst, fabs(w->outputs[1] - c) / c);
		if (first_residual < 0 && eps >= 0.7517)
			first_residual = w->q / 2;
		plastic++;
	}
	printf("INFO %s: %d plastic rows, largest |q - 2 c(eps_d)| / 2c %.3g, q/2 once eps_d >= 0.7517: %.10g Pa\n",
	       name, plastic, worst, first_residual);
	CHECK(plastic > 100 && worst <= 1e-9 && rel_diff(first_residual, 3.59e3, 1) <= 1e-9, name,
	      "error %.3g, residual %.10g", worst, first_residual);
	element_result_release(&r);
}

static void check_dilation_drained(void)
{
	const char *json = "{\"schema\": \"poro-element/1\", \"material\": {\"model\": \"mohr_coulomb_dilation\","
			   " \"strain\": \"small\", \"youngs_modulus\": 1.037e6, \"poisson_ratio\": 0.3013,"
			   " \"cohesion\": 3.07e3, \"friction_angle\": 25.3, \"initial_dilation_angle\": -5.17,"
			   " \"critical_dilation_angle\": 0.83, \"dilation_evolution_parameter\": 24.7}, \"test\": \"drained\","
			   " \"confining_pressure\": 21.3e3, \"axial_strain\": -0.3, \"steps\": 600}";
	struct element_result r;
	if (!run(json, &r)) {
		CHECK(0, "element_mohr_coulomb_dilation_drained_eq17", "run failed");
		return;
	}
	double law = 0, flow = 0;
	int plateau = 0;
	for (int i = 1; i < r.rows; i++) {
		const struct element_row *w = &r.row[i], *v = &r.row[i - 1];
		double eps = w->outputs[0];
		double psi = 0.83 + (-5.17 - 0.83) * exp(-24.7 * eps);                  /* Eq. 17, degrees */
		law = fmax(law, fabs(w->outputs[1] - psi) / 5.17);
		if (v->outputs[0] == 0 || fabs(w->q - v->q) > 1e-9 * w->q)
			continue;                                                       /* not on the plateau */
		double s = sin(psi * DEG), ratio = (w->volumetric_strain - v->volumetric_strain) / (eps - v->outputs[0]);
		flow = fmax(flow, fabs(ratio - 6 * s / (3 - s)));
		plateau++;
	}
	printf("INFO element_mohr_coulomb_dilation_drained_eq17: dilation angle vs Eq. 17 %.3g (relative to 5.17 deg),"
	       " %d plateau steps, |d eps_v / d eps_d - 6 sin psi / (3 - sin psi)| <= %.3g\n", law, plateau, flow);
	CHECK(law <= 1e-12 && plateau > 100 && flow <= 1e-6, "element_mohr_coulomb_dilation_drained_eq17",
	      "law %.3g, %d plateau steps, flow %.3g", law, plateau, flow);
	element_result_release(&r);
}

/* Element cases are refused with JSON pointers, like simulation cases. */
static void check_invalid(const char *what, const char *json, const char *expect)
{
	struct element_case c;
	struct poro_error err = {0};
	enum poro_status st = element_case_load_string(json, &c, &err);
	char name[128];
	snprintf(name, sizeof name, "element_case_rejects_%s", what);
	CHECK(st == PORO_EINVAL && strstr(err.message, expect), name, "status %d, message '%s'", (int)st, err.message);
}

#define ELEMENT_HEAD "{\"schema\": \"poro-element/1\", \"test\": \"drained\", \"confining_pressure\": 1e5, " \
		     "\"axial_strain\": -0.1, \"steps\": 10, \"material\": "

int main(void)
{
	check_drained_peak("small", 1);
	check_drained_peak("small", 2);
	check_drained_peak("finite", 1);
	check_drained_peak("finite", 2);
	check_undrained_mc();
	check_tresca_undrained("small");
	check_tresca_undrained("finite");
	check_dilation_drained();
	check_invalid("friction_angle_90", ELEMENT_HEAD "{\"model\": \"mohr_coulomb\", \"youngs_modulus\": 1e7,"
		      " \"poisson_ratio\": 0.3, \"cohesion\": 1e4, \"friction_angle\": 90, \"dilation_angle\": 0}}",
		      "/material/friction_angle: must be > 0 and < 90, got 90");
	check_invalid("dilation_above_friction", ELEMENT_HEAD "{\"model\": \"mohr_coulomb\", \"youngs_modulus\": 1e7,"
		      " \"poisson_ratio\": 0.3, \"cohesion\": 1e4, \"friction_angle\": 30, \"dilation_angle\": 31}}",
		      "/material/dilation_angle: must be >= 0 and <= friction_angle (30), got 31");
	check_invalid("missing_cohesion", ELEMENT_HEAD "{\"model\": \"mohr_coulomb\", \"youngs_modulus\": 1e7,"
		      " \"poisson_ratio\": 0.3, \"friction_angle\": 30, \"dilation_angle\": 0}}",
		      "/material/cohesion: missing required key");
	check_invalid("negative_modulus", ELEMENT_HEAD "{\"model\": \"tresca_softening\", \"youngs_modulus\": -1e7,"
		      " \"poisson_ratio\": 0.3, \"peak_cohesion\": 1e4, \"residual_cohesion\": 5e3,"
		      " \"residual_plastic_strain\": 0.5}}", "/material/youngs_modulus: must be > 0, got -1e+07");
	check_invalid("residual_above_peak", ELEMENT_HEAD "{\"model\": \"tresca_softening\", \"youngs_modulus\": 1e7,"
		      " \"poisson_ratio\": 0.3, \"peak_cohesion\": 1e4, \"residual_cohesion\": 2e4,"
		      " \"residual_plastic_strain\": 0.5}}", "/material/residual_cohesion: must be <= peak_cohesion");
	check_invalid("negative_eta", ELEMENT_HEAD "{\"model\": \"mohr_coulomb_dilation\", \"youngs_modulus\": 1e7,"
		      " \"poisson_ratio\": 0.3, \"cohesion\": 3e3, \"friction_angle\": 25, \"initial_dilation_angle\": -5,"
		      " \"critical_dilation_angle\": 0, \"dilation_evolution_parameter\": -25}}",
		      "/material/dilation_evolution_parameter: must be >= 0");
	check_invalid("key_of_another_model", ELEMENT_HEAD "{\"model\": \"hencky\", \"youngs_modulus\": 1e7,"
		      " \"poisson_ratio\": 0.3, \"cohesion\": 1e4}}", "/material/cohesion: unknown key");
	check_invalid("zero_axial_strain", "{\"schema\": \"poro-element/1\", \"test\": \"drained\","
		      " \"confining_pressure\": 1e5, \"axial_strain\": 0, \"steps\": 10, \"material\": {\"model\":"
		      " \"hencky\", \"youngs_modulus\": 1e7, \"poisson_ratio\": 0.3}}", "/axial_strain: must not be 0");
	check_invalid("unknown_test", "{\"schema\": \"poro-element/1\", \"test\": \"cyclic\","
		      " \"confining_pressure\": 1e5, \"axial_strain\": -0.1, \"steps\": 10, \"material\": {\"model\":"
		      " \"hencky\", \"youngs_modulus\": 1e7, \"poisson_ratio\": 0.3}}", "/test: ");
	HARNESS_EXIT();
}
