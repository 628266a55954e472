/*
 * explicit_test.c - the explicit scheme (solver/schemes/explicit/) on the checks that come before
 * any paper example (spec-002 §10), and its time step (solver/stable_dt.c):
 *
 *  a. the fast wave speed against the undrained one it must exceed by a little, and its limits
 *     (K_f -> 0: the skeleton's own P-wave over rhō_s; no skeleton: the fluid's);
 *  b. the time step: the Terzaghi column of 002 §4.1.1 runs 5,000 steps at 0.9 and at 1.5 times
 *     h / c_fast, and fails within them at 3 times, the failure naming the step, the point and the
 *     time step as the likely cause (the measured limit, 2.0-2.1 h / c_fast on the column, the
 *     strip and the cyclic cases, is written in docs/numerics.md); the loader refuses a dt above
 *     h / c_fast naming the bound, and "auto" takes 0.9 of it;
 *  c. the drag: at a conductivity where the drag's own bound 2 / lambda is far below h / c_fast,
 *     formulation.drag "explicit" runs at 0.9 of it and fails at 1.5 times it, while the implicit
 *     nodal drag (the default) runs at 0.9 h / c_fast, 380 times the explicit bound at k = 1e-7 m/s;
 *  d. undrained loading: a column of conductivity 1e-9 m/s with a compressible fluid
 *     (K_f = 2e7 Pa) loaded over 0.1 s carries p = B q, B = (K_f / n) / (M + K_f / n), within 1%
 *     at mid-height (one-dimensional, incompressible grains);
 *  e. a run that goes unstable through sim_run stops with PORO_ESOLVER naming the step and the
 *     point, and every frame written to result.h5 is finite.
 */
#include <string.h>

#include "../case_file.h"
#include "../harness.h"
#include "case.h"
#include "poro.h"
#include "results_read.h"
#include "stable_dt.h"

#define CASES "tests/cases/"
#define COLUMN CASES "terzaghi_002.json"

/* Steps a fresh simulation of c `steps` times: 0 when every step passed, else the failing step
 * (its message in message[size]). */
static long run_steps(const struct case_spec *c, long steps, char *message, size_t size)
{
	struct poro_error err = {0};
	struct sim *s = NULL;
	message[0] = '\0';
	if (sim_create(&s, c, &err)) {
		snprintf(message, size, "%s", err.message);
		return -1;
	}
	long failed = 0;
	for (long k = 0; k < steps && !failed; k++)
		if (sim_step(s)) {
			failed = k + 1;
			snprintf(message, size, "%s", sim_error(s)->message);
		}
	sim_destroy(&s);
	return failed;
}

static void check_wave_speed(void)
{
	const double M = 1.0e7, rho_s = 2650, n = 0.3, rho_f = 1000, K_f = 2.2e9;
	const double c = stable_dt_fast_wave_speed(M, rho_s, n, rho_f, K_f);
	const double undrained = sqrt((M + K_f / n) / ((1 - n) * rho_s + n * rho_f));
	printf("INFO fast wave %.1f m/s, undrained %.1f m/s (ratio %.3f); skeleton alone %.2f m/s\n", c, undrained,
	       c / undrained, stable_dt_fast_wave_speed(M, rho_s, n, rho_f, 1e-6));
	CHECK(c > undrained && c < 1.25 * undrained, "fast_wave_a_little_above_undrained", "%.2f vs %.2f", c, undrained);
	CHECK(rel_diff(stable_dt_fast_wave_speed(M, rho_s, n, rho_f, 1e-6), sqrt(M / ((1 - n) * rho_s)), 0) < 1e-6,
	      "fast_wave_without_fluid_is_the_skeletons", "%.6g", stable_dt_fast_wave_speed(M, rho_s, n, rho_f, 1e-6));
}

static void check_time_step(void)
{
	static char message[PORO_ERROR_MESSAGE_MAX];
	struct case_spec *c = test_case_load(COLUMN);
	if (!c)
		return;
	struct stable_dt e;
	stable_dt_estimate(c, &e);
	printf("INFO column: h / c_fast = %.4g s (c_fast %.1f m/s), the case's dt %.3g s\n", e.cfl, e.wave_speed,
	       c->time.dt);
	const double factors[3] = {0.9, 1.5, 3.0};
	long failed[3];
	for (int i = 0; i < 3; i++) {
		c->time.dt = factors[i] * e.cfl;   /* past the loader for 1.5 and 3 */
		failed[i] = run_steps(c, 5000, message, sizeof message);
		printf("INFO column at %.1f h / c_fast: %s %ld%s%.300s\n", factors[i], failed[i] ? "failed at step" : "ran",
		       failed[i] ? failed[i] : 5000L, failed[i] ? ": " : " steps", message);
	}
	CHECK(failed[0] == 0 && failed[1] == 0, "explicit_column_runs_below_twice_the_critical_step",
	      "0.9: %ld, 1.5: %ld", failed[0], failed[1]);
	CHECK(failed[2] > 0 && strstr(message, "at step") && strstr(message, "soil point") &&
	      strstr(message, "likely cause: a time step near or above the stability limit"),
	      "explicit_column_fails_at_three_times_naming_the_time_step", "%.300s", message);
	case_destroy(&c);

	/* the loader: refused just above the bound, with it in the message; "auto" takes 0.9 of it */
	const char *dts[2] = {"1e-4", "\"auto\""};
	for (int i = 0; i < 2; i++) {
		FILE *f = fopen(COLUMN, "r");
		char text[8192];
		size_t len = f ? fread(text, 1, sizeof text - 1, f) : 0;
		if (f)
			fclose(f);
		text[len] = '\0';
		char *at = strstr(text, "\"dt\": 1.0e-5"), edited[8300];
		if (!at)
			break;
		snprintf(edited, sizeof edited, "%.*s\"dt\": %s%s", (int)(at - text), text, dts[i], at + strlen("\"dt\": 1.0e-5"));
		struct poro_error err = {0};
		struct case_spec *d = NULL;
		const enum poro_status st = case_load_string(edited, &d, &err);
		if (i == 0) {
			printf("INFO dt 1e-4 s: %.300s\n", err.message);
			CHECK(st == PORO_EINVAL && strstr(err.message, "/time/dt: must be at most") &&
			      strstr(err.message, "h / c_fast"), "explicit_dt_above_critical_refused_naming_it", "%s",
			      err.message);
		} else {
			CHECK(st == PORO_OK && d && d->time.dt_auto && rel_diff(d->time.dt, 0.9 * e.cfl, 0) < 1e-12,
			      "explicit_auto_dt_is_0.9_of_critical", "dt %.6g against %.6g", d ? d->time.dt : 0, 0.9 * e.cfl);
		}
		case_destroy(&d);
	}
}

static void check_drag(void)
{
	static char message[PORO_ERROR_MESSAGE_MAX];
	struct case_spec *c = test_case_load(COLUMN);
	if (!c)
		return;
	c->bodies[0].hydraulic_conductivity = 1e-7;
	c->formulation.drag = DRAG_EXPLICIT;
	struct stable_dt e;
	stable_dt_estimate(c, &e);
	printf("INFO k = 1e-7 m/s: 2 / lambda = %.4g s, h / c_fast = %.4g s\n", e.drag_step, e.wave_step);
	CHECK(e.drag_body == 0 && e.drag_step < 1e-2 * e.wave_step && e.cfl == e.drag_step,
	      "explicit_drag_bound_set_by_the_drag", "drag %.3g wave %.3g", e.drag_step, e.wave_step);
	c->time.dt = 0.9 * e.drag_step;
	const long below = run_steps(c, 3000, message, sizeof message);
	c->time.dt = 1.5 * e.drag_step;
	const long above = run_steps(c, 3000, message, sizeof message);
	printf("INFO explicit drag at 0.9 (2 / lambda): %s; at 1.5: failed at step %ld: %.200s\n",
	       below ? "failed" : "ran", above, message);
	CHECK(below == 0 && above > 0, "explicit_drag_stable_only_below_its_bound", "0.9: %ld, 1.5: %ld", below, above);
	c->formulation.drag = DRAG_IMPLICIT;
	stable_dt_estimate(c, &e);
	c->time.dt = 0.9 * e.wave_step;
	const long implicit = run_steps(c, 3000, message, sizeof message);
	CHECK(implicit == 0 && e.drag_body < 0, "implicit_drag_stable_far_above_the_explicit_bound", "%ld: %.200s",
	      implicit, message);
	case_destroy(&c);
}

static void check_undrained(void)
{
	struct case_spec *c = test_case_load(COLUMN);
	if (!c)
		return;
	const double K_f = 2e7, n = c->bodies[0].porosity, M = c->materials[0].youngs_modulus;   /* nu = 0 */
	const double q = -c->loads[0].traction[1], B = (K_f / n) / (M + K_f / n);
	c->bodies[0].hydraulic_conductivity = 1e-9;
	c->bodies[0].initial_pore_pressure = 0.0;
	c->fluid.bulk_modulus = K_f;
	c->loads[0].time_function = (struct case_time_function){.kind = TIME_RAMP, .ramp_time = 0.1};
	struct stable_dt e;
	stable_dt_estimate(c, &e);
	c->time.dt = 0.9 * e.cfl;
	struct poro_error err = {0};
	struct sim *s = NULL;
	int ok = !sim_create(&s, c, &err);
	double mean = 0.0;
	int samples = 0;
	/* the mid-height probe averaged over 0.15-0.25 s, after the ramp (the column rings with a period
	 * of about 4 H / c_undrained = 0.02 s) */
	while (ok && sim_time(s) < 0.25) {
		ok = !sim_step(s);
		if (sim_time(s) > 0.15)
			mean += sim_probe_value(s, 1), samples++;
	}
	if (!ok)
		printf("INFO undrained column failed: %s\n", sim_error(s)->message);
	mean /= samples > 0 ? samples : 1;
	printf("INFO undrained column (k = 1e-9 m/s, K_f = 2e7 Pa): p / q at mid-height %.5f, B = %.5f\n", mean / q, B);
	CHECK(ok && rel_diff(mean, B * q, 0) < 0.01, "explicit_undrained_pressure_is_B_q", "%.5f q against %.5f q",
	      mean / q, B);
	sim_destroy(&s);
	case_destroy(&c);
}

static void check_unstable_run_stops_clean(void)
{
	struct case_spec *c = test_case_load(COLUMN);
	if (!c)
		return;
	struct stable_dt e;
	stable_dt_estimate(c, &e);
	c->time.dt = 3.0 * e.cfl;
	c->time.end = 400 * c->time.dt;
	c->output.frame_interval = c->time.dt;   /* a frame every step, up to the failure */
	char dir[] = "/tmp/explicit_test_XXXXXX";
	struct poro_error err = {0};
	struct sim *s = NULL;
	if (!mkdtemp(dir) || sim_create(&s, c, &err)) {
		CHECK(0, "explicit_unstable_run_stops_clean", "setup failed: %s", err.message);
		case_destroy(&c);
		return;
	}
	const enum poro_status st = sim_run(s, dir, "test", NULL, NULL, NULL);
	const char *message = sim_error(s)->message;
	printf("INFO unstable run: status %d: %.300s\n", (int)st, message);
	char path[256];
	snprintf(path, sizeof path, "%s/result.h5", dir);
	struct results *r = NULL;
	long frames = 0, bad = 0;
	if (!results_open(&r, path, &err)) {
		frames = results_frame_count(r);
		for (long f = 0; f < frames; f++) {
			const char *names[] = {"x", "v", "stress", "pore_pressure"};
			for (int k = 0; k < 4; k++) {
				double *v = NULL;
				long rows = 0;
				int width = 1;
				if (results_frame_read(r, f, "soil", names[k], &v, &rows, &width, &err)) {
					bad++;
					continue;
				}
				for (long i = 0; i < rows * width; i++)
					bad += !isfinite(v[i]);
				free(v);
			}
		}
		results_close(&r);
	}
	printf("INFO unstable run: %ld frames in result.h5, %ld non-finite values\n", frames, bad);
	CHECK(st == PORO_ESOLVER && strstr(message, "at step") && strstr(message, "soil point") && frames > 1 && bad == 0,
	      "explicit_unstable_run_stops_clean", "status %d, %ld frames, %ld non-finite: %.200s", (int)st, frames, bad,
	      message);
	sim_destroy(&s);
	case_destroy(&c);
	snprintf(path, sizeof path, "rm -rf '%s'", dir);
	if (system(path) != 0)
		printf("INFO could not remove %s\n", dir);
}

int main(void)
{
	check_wave_speed();
	check_time_step();
	check_drag();
	check_undrained();
	check_unstable_run_stops_clean();
	HARNESS_EXIT();
}
