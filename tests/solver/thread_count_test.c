/*
 * thread_count_test.c - a run is the same bit for bit whatever the thread count.
 *
 * A job's result must not depend on how many threads the worker gave it: a user who reruns a case
 * on another host, or with another `threads`, gets the same numbers. The reduced loose landslide
 * (double point, consistent projection, Nor-Sand) is stepped side by side on one and on two
 * threads, through the elastic gravity ramp (4,167 steps at this size) and 240 steps into the
 * plastic slide, and every point's position, velocity, stress and pore pressure is compared for
 * exact equality at every step. Before the pressure solve held its BLAS to one thread
 * (spd_solve.c) the two runs differed at the first step (nodal pressure increments by 2e-14 Pa),
 * and at paper size the slide then ran out 0.352 m on one thread and 0.324 m on two
 * (docs/performance.md, "Threads"). The stress update, threaded over the points, runs elastic,
 * resets its reference at the ramp's end and returns Nor-Sand plastically here.
 *
 * Then several points are broken so that their stress update fails, and the step's error must be
 * the lowest-numbered failing point's, on one thread as on two (the threaded loop updates every
 * point and keeps each thread's first failure; semi_implicit.c).
 */
#include <omp.h>
#include <string.h>

#include "../harness.h"
#include "../verify/slope_case.h"
#include "case.h"
#include "poro.h"
#include "sim_internal.h"

#define CASE_FILE "tests/cases/landslide_loose_double_point.json"
#define STEPS 4407   /* the ramp ends at step 4,167 */

static void run_long(json_t *doc, void *user)
{
	(void)user;
	slope_case_set(doc, "time", "end", json_real(10.0));
	json_object_del(doc, "checkpoint");
}

/* Number of entries of a and b (count each) that differ in any bit. */
static long differing(const double *a, const double *b, idx_t count)
{
	long n = 0;
	for (idx_t i = 0; i < count; i++)
		n += memcmp(a + i, b + i, sizeof(double)) != 0;
	return n;
}

static long differing_points(const struct particles *a, const struct particles *b, int with_stress)
{
	if (a->n != b->n)
		return -1;
	long n = differing(a->x, b->x, 2 * a->n) + differing(a->v, b->v, 2 * a->n) +
		 differing(a->pressure, b->pressure, a->n);
	if (with_stress)
		n += differing(a->stress, b->stress, 4 * a->n);
	return n;
}

/* Points whose stress update must fail, in no particular order, each with its own negative
 * out-of-plane elastic stretch Be_zz = -(q + 1), which the failure message prints ("non-positive
 * stretch (..., -(q + 1)), ..."): the message says which point was reported. */
static const idx_t broken[] = { 1000, 341, 702, 1100, 301 };
#define LOWEST_BROKEN_MARK "-302)"   /* point 301 */

/* Breaks the points above and takes one step: it must fail in the stress update. */
static enum poro_status step_with_broken_points(struct sim *s)
{
	for (size_t i = 0; i < sizeof broken / sizeof broken[0]; i++)
		s->soil.Be[4 * broken[i] + 3] = -(double)(broken[i] + 1);
	return sim_step(s);
}

int main(void)
{
	struct case_spec *c1 = NULL, *c2 = NULL;
	struct sim *one = NULL, *two = NULL;
	int ok = !slope_case_create(CASE_FILE, 0.05, 2, run_long, NULL, &c1, &one) &&
		 !slope_case_create(CASE_FILE, 0.05, 2, run_long, NULL, &c2, &two);
	CHECK(ok, "thread_count_cases_load", "cannot create the reduced landslide");
	long first_step = -1, differences = 0;
	const int threads = omp_get_max_threads();
	for (long k = 1; ok && k <= STEPS && first_step < 0; k++) {
		omp_set_num_threads(1);
		ok = sim_step(one) == PORO_OK;
		omp_set_num_threads(2);
		ok = ok && sim_step(two) == PORO_OK;
		differences = differing_points(&one->soil, &two->soil, 1) + differing_points(&one->water, &two->water, 0);
		if (differences)
			first_step = k;
	}
	omp_set_num_threads(threads);
	CHECK(ok, "thread_count_runs_step", "a step failed: %s / %s", one ? sim_error(one)->message : "",
	      two ? sim_error(two)->message : "");
	CHECK(ok && first_step < 0, "thread_count_one_and_two_threads_bit_identical",
	      "%ld point values differ at step %ld", differences, first_step);
	if (ok) {
		omp_set_num_threads(1);
		const enum poro_status st1 = step_with_broken_points(one);
		omp_set_num_threads(2);
		const enum poro_status st2 = step_with_broken_points(two);
		omp_set_num_threads(threads);
		const char *m1 = sim_error(one)->message, *m2 = sim_error(two)->message;
		CHECK(st1 == PORO_ESOLVER && st2 == PORO_ESOLVER && !strcmp(m1, m2) && strstr(m1, LOWEST_BROKEN_MARK),
		      "thread_count_stress_failure_reports_the_lowest_point",
		      "status %d / %d, messages '%s' / '%s', want the point marked %s", st1, st2, m1, m2,
		      LOWEST_BROKEN_MARK);
	}
	sim_destroy(&one);
	sim_destroy(&two);
	case_destroy(&c1);
	case_destroy(&c2);
	HARNESS_EXIT();
}
