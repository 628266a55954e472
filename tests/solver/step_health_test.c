/*
 * step_health_test.c - a failed step names its likely cause, and a run of a small-strain model far
 * outside its range warns (solver/step_health.c), on the Terzaghi column (tests/cases/terzaghi*.json,
 * q = 10 kPa, H = 1 m, h = 0.025 m):
 *  - the load's strain estimate is q / E_oed (1e-3 for the Table 1 column);
 *  - a dt eight times the CFL step h / c_p, set past the loader's check, fails and the message names
 *    the time step as the likely cause, with the CFL step in it;
 *  - a column with E = 1e5 Pa (q / E_oed = 0.1) at the case's dt fails (a point thrown out of the
 *    grid at step 1,868), and the message says the time step is not the cause and that the
 *    material is soft for its load;
 *  - a single-point column with E = 1.5e5 Pa raises the small-strain warning (J reaches 0.9 at its
 *    top) and still runs; the Table 1 column raises none.
 */
#include <string.h>

#include "../case_file.h"
#include "../harness.h"
#include "case.h"
#include "poro.h"
#include "stable_dt.h"
#include "step_health.h"

#define CASES "tests/cases/"

/* Steps c up to steps times; returns the step that failed (0: none) and copies the message. */
static long run(const struct case_spec *c, long steps, char *message, size_t size, int *warned)
{
	struct sim *s = NULL;
	struct poro_error err = {0};
	long failed = 0;
	*warned = 0;
	message[0] = '\0';
	if (sim_create(&s, c, &err)) {
		snprintf(message, size, "%s", err.message);
		return -1;
	}
	for (long i = 1; i <= steps && !failed; i++)
		if (sim_step(s)) {
			failed = i;
			snprintf(message, size, "%s", sim_error(s)->message);
		}
	if (!failed && sim_warning(s))
		snprintf(message, size, "%s", sim_warning(s));
	*warned = sim_warning(s) != NULL;
	sim_destroy(&s);
	return failed;
}

static void test_load_strain(void)
{
	struct case_spec *c = test_case_load(CASES "terzaghi.json");
	int body = -1;
	const double strain = c ? step_health_load_strain(c, &body) : 0;
	CHECK(c && body == 0 && rel_diff(strain, 1e4 / 1e7, 1e-30) < 1e-12, "load strain of the Table 1 column is q / E_oed",
	      "%.6g (body %d)", strain, body);
	case_destroy(&c);
}

static void test_time_step_named(void)
{
	static char message[PORO_ERROR_MESSAGE_MAX];
	struct case_spec *c = test_case_load(CASES "terzaghi.json");
	if (!c)
		return;
	struct stable_dt e;
	stable_dt_estimate(c, &e);
	c->time.dt = 8 * e.cfl;   /* past the loader, which refuses it */
	int warned;
	const long failed = run(c, 400, message, sizeof message, &warned);
	printf("INFO dt = 8 h / c_p: failed at step %ld: %.400s\n", failed, message);
	char cfl[64];
	snprintf(cfl, sizeof cfl, "h / c_p = %.6g s", e.cfl);
	CHECK(failed > 0 && strstr(message, "likely cause: a time step near or above the stability limit") &&
	      strstr(message, cfl), "a step eight times the CFL step fails naming the time step", "%.300s", message);
	case_destroy(&c);
}

static void test_soft_material_named(void)
{
	static char message[PORO_ERROR_MESSAGE_MAX];
	struct case_spec *c = test_case_load(CASES "terzaghi.json");
	if (!c)
		return;
	c->materials[0].youngs_modulus = 1e5;
	int warned;
	const long failed = run(c, 3000, message, sizeof message, &warned);
	printf("INFO E = 1e5 Pa: failed at step %ld: %.600s\n", failed, message);
	/* the symptom itself (an inverted point, or a point thrown out of the grid) is not the point:
	 * the message must name what it follows from */
	CHECK(failed > 0 && strstr(message, "likely cause: not the time step") &&
	      strstr(message, "soft for its load") && strstr(message, "strain its skeleton by about 0.1 "),
	      "a column too soft for its load fails naming the material", "%.300s", message);
	case_destroy(&c);
}

static void test_small_strain_warning(void)
{
	static char message[PORO_ERROR_MESSAGE_MAX];
	struct case_spec *c = test_case_load(CASES "terzaghi_single_point.json");
	if (!c)
		return;
	int warned;
	long failed = run(c, 500, message, sizeof message, &warned);
	CHECK(!failed && !warned, "the Table 1 column raises no warning", "%.300s", message);
	c->materials[0].youngs_modulus = 1.5e5;
	failed = run(c, 2300, message, sizeof message, &warned);
	printf("INFO E = 1.5e5 Pa, single point: %s\n", message);
	CHECK(!failed && warned && strstr(message, "small-strain model is used beyond |J - 1| = 0.1"),
	      "a small-strain model beyond 10% volume change warns and runs", "failed at %ld: %.300s", failed, message);
	case_destroy(&c);
}

int main(void)
{
	test_load_strain();
	test_time_step_named();
	test_soft_material_named();
	test_small_strain_warning();
	HARNESS_EXIT();
}
